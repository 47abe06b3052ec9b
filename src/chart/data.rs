//! Data preparation (transformed coordinates, skipped points) and the
//! pixel mapping of a plot area.

use super::ticks::{self, Axis};
use super::{Chart, PALETTE, Style};

/// Colour of reference lines without an explicit colour.
pub(super) const REF_COLOR: &str = "#555555";

/// A series or reference line prepared in transformed coordinates.
pub(super) struct Trace {
    pub name: String,
    pub color: String,
    /// Reference line (drawn first, thinner, listed last in the legend).
    pub reference: bool,
    pub line: bool,
    pub dashed: bool,
    /// Marker shape index, `None` for no markers.
    pub marker: Option<usize>,
    /// Runs of consecutive plottable points (a skipped point breaks a run).
    pub runs: Vec<Vec<(f64, f64)>>,
    /// Error bars: x, lower end (`None`: below a log axis), upper end.
    pub errs: Vec<(f64, Option<f64>, f64)>,
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
            let (Some(tx), Some(_)) = (ticks::transform(xlog, x), ticks::transform(ylog, y)) else {
                continue;
            };
            if !(e.is_finite() && e > 0.0) {
                continue;
            }
            if let Some(hi) = ticks::transform(ylog, y + e) {
                errs.push((tx, ticks::transform(ylog, y - e), hi));
            }
        }
        traces.push(Trace {
            name: s.name.clone(),
            color: s
                .color
                .clone()
                .unwrap_or_else(|| PALETTE[i % PALETTE.len()].to_string()),
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
            color: l.color.clone().unwrap_or_else(|| REF_COLOR.to_string()),
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

/// Pixel rectangle `[x0, x1] x [y0, y1]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    pub fn new(x: f64, y: f64, w: f64, h: f64) -> Self {
        Rect {
            x0: x,
            y0: y,
            x1: x + w,
            y1: y + h,
        }
    }

    pub fn contains(&self, (x, y): (f64, f64), margin: f64) -> bool {
        x >= self.x0 - margin
            && x <= self.x1 + margin
            && y >= self.y0 - margin
            && y <= self.y1 + margin
    }

    /// The part of segment `p`-`q` inside the rectangle (Liang-Barsky).
    pub fn clip(&self, p: (f64, f64), q: (f64, f64)) -> Option<((f64, f64), (f64, f64))> {
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (a, b) in [
            (-dx, p.0 - self.x0),
            (dx, self.x1 - p.0),
            (-dy, p.1 - self.y0),
            (dy, self.y1 - p.1),
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

    /// Does the segment `p`-`q` touch the rectangle?
    pub fn hits_segment(&self, p: (f64, f64), q: (f64, f64)) -> bool {
        self.clip(p, q).is_some()
    }
}

/// Maps transformed coordinates to pixels inside the plot rectangle.
pub(super) struct Mapper {
    pub plot: Rect,
    pub xa: Axis,
    pub ya: Axis,
}

impl Mapper {
    pub fn px(&self, tx: f64) -> f64 {
        let v = self.plot.x0 + self.xa.frac(tx) * (self.plot.x1 - self.plot.x0);
        v.clamp(-1e12, 1e12)
    }

    pub fn py(&self, ty: f64) -> f64 {
        let v = self.plot.y1 - self.ya.frac(ty) * (self.plot.y1 - self.plot.y0);
        v.clamp(-1e12, 1e12)
    }

    pub fn pt(&self, (tx, ty): (f64, f64)) -> (f64, f64) {
        (self.px(tx), self.py(ty))
    }

    pub fn visible(&self, (tx, ty): (f64, f64)) -> bool {
        let (fx, fy) = (self.xa.frac(tx), self.ya.frac(ty));
        (-1e-9..=1.0 + 1e-9).contains(&fx) && (-1e-9..=1.0 + 1e-9).contains(&fy)
    }

    pub fn err_ends(&self, &(tx, lo, hi): &(f64, Option<f64>, f64)) -> (f64, Option<f64>, f64) {
        let x = self.px(tx);
        (x, lo.map(|t| self.py(t)), self.py(hi))
    }
}
