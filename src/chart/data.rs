//! Data preparation: transformed coordinates, skipped points, clipping to
//! the visible range.

use super::axis::{self as ticks, Axis};
use super::style::{REF_COLOR, parse_color};
use super::{Chart, PALETTE, Style};
use plotters::style::RGBColor;

/// A series or reference line prepared in transformed coordinates.
pub(super) struct Trace {
    pub name: String,
    pub color: RGBColor,
    /// Reference line (drawn first, thinner, listed last in the legend).
    pub reference: bool,
    pub line: bool,
    pub dashed: bool,
    /// Marker shape index, `None` for no markers.
    pub marker: Option<usize>,
    /// Runs of consecutive plottable points (a skipped point breaks a run).
    pub runs: Vec<Vec<(f64, f64)>>,
    /// Error bars: x, lower end (`None`: below a log axis), centre, upper end.
    pub errs: Vec<(f64, Option<f64>, f64, f64)>,
}

/// Whether a log axis is still usable: some finite point has a positive
/// coordinate, an explicit positive range was given, or there is no data.
fn effective_log(
    chart: &Chart,
    want: bool,
    coord: fn(&(f64, f64)) -> f64,
    range: Option<(f64, f64)>,
) -> bool {
    if !want {
        return false;
    }
    if range.is_some_and(|(a, b)| a > 0.0 && b > 0.0 && a.is_finite() && b.is_finite()) {
        return true;
    }
    let mut finite = chart
        .series
        .iter()
        .flat_map(|s| &s.points)
        .chain(chart.lines.iter().flat_map(|l| &l.points))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .peekable();
    finite.peek().is_none() || finite.any(|p| coord(p) > 0.0)
}

/// Splits points into runs of consecutive plottable points (transformed).
fn runs_of(points: &[(f64, f64)], xlog: bool, ylog: bool) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![Vec::new()];
    for &(x, y) in points {
        match (ticks::transform(xlog, x), ticks::transform(ylog, y)) {
            (Some(tx), Some(ty)) => runs.last_mut().map_or((), |r| r.push((tx, ty))),
            _ if runs.last().is_some_and(|r| !r.is_empty()) => runs.push(Vec::new()),
            _ => {}
        }
    }
    runs.retain(|r| !r.is_empty());
    runs
}

/// Prepares all series (first) and reference lines (after) of `chart`,
/// deciding which requested log axes are usable; returns `(traces, xlog, ylog)`.
pub(super) fn prepare(chart: &Chart) -> (Vec<Trace>, bool, bool) {
    let xlog = effective_log(chart, chart.x_log, |p| p.0, chart.x_range);
    let ylog = effective_log(chart, chart.y_log, |p| p.1, chart.y_range);
    let mut traces = Vec::new();
    for (i, s) in chart.series.iter().enumerate() {
        let mut errs = Vec::new();
        for (&(x, y), &e) in s.points.iter().zip(s.y_err.iter().flatten()) {
            let (Some(tx), Some(ty)) = (ticks::transform(xlog, x), ticks::transform(ylog, y))
            else {
                continue;
            };
            if !(e.is_finite() && e > 0.0) {
                continue;
            }
            if let Some(hi) = ticks::transform(ylog, y + e) {
                errs.push((tx, ticks::transform(ylog, y - e), ty, hi));
            }
        }
        traces.push(Trace {
            name: s.name.clone(),
            color: s
                .color
                .as_deref()
                .and_then(parse_color)
                .or_else(|| parse_color(PALETTE[i % PALETTE.len()]))
                .unwrap_or(REF_COLOR),
            reference: false,
            line: s.style.has_line(),
            dashed: s.style == Style::Dashed,
            marker: s.style.has_markers().then_some(i % 5),
            runs: runs_of(&s.points, xlog, ylog),
            errs,
        });
    }
    for l in &chart.lines {
        traces.push(Trace {
            name: l.name.clone(),
            color: l
                .color
                .as_deref()
                .and_then(parse_color)
                .unwrap_or(REF_COLOR),
            reference: true,
            line: true,
            dashed: l.dashed,
            marker: None,
            runs: runs_of(&l.points, xlog, ylog),
            errs: Vec::new(),
        });
    }
    (traces, xlog, ylog)
}

/// Clips the segment `p`-`q` (transformed coordinates) to the visible
/// rectangle of `xa` x `ya` (Liang-Barsky). Plotters clamps points outside
/// the plot to its edge, which would bend the line, so segments are cut here.
pub(super) fn clip(
    xa: &Axis,
    ya: &Axis,
    p: (f64, f64),
    q: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (a, b) in [
        (-dx, p.0 - xa.lo),
        (dx, xa.hi - p.0),
        (-dy, p.1 - ya.lo),
        (dy, ya.hi - p.1),
    ] {
        if a == 0.0 {
            if b < 0.0 {
                return None;
            }
        } else {
            let t = b / a;
            if a < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    let at = |t: f64| (p.0 + t * dx, p.1 + t * dy);
    Some((
        if t0 > 0.0 { at(t0) } else { p },
        if t1 < 1.0 { at(t1) } else { q },
    ))
}

/// The visible parts of a run as polylines (transformed coordinates).
pub(super) fn clip_run(xa: &Axis, ya: &Axis, run: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut pen: Option<(f64, f64)> = None;
    for seg in run.windows(2) {
        let Some((a, b)) = clip(xa, ya, seg[0], seg[1]) else {
            pen = None;
            continue;
        };
        match out.last_mut() {
            Some(line) if pen == Some(a) => line.push(b),
            _ => out.push(vec![a, b]),
        }
        pen = Some(b);
    }
    out
}

/// Is the transformed point inside the visible range (with a little slack)?
pub(super) fn visible(xa: &Axis, ya: &Axis, (x, y): (f64, f64)) -> bool {
    let ok = |f: f64| (-1e-9..=1.0 + 1e-9).contains(&f);
    ok(xa.frac(x)) && ok(ya.frac(y))
}
