//! Layout and drawing of one chart panel.

use std::fmt::Write as _;

use super::data::{self, Mapper, Rect, Trace};
use super::legend::{self, Legend};
use super::svg::{self, DASH, MARKER_R, escape_xml, num, text_width};
use super::ticks::{self, Axis, Tick, Ticks};
use super::{Chart, LegendPosition};

/// Font size of a figure's overall title.
pub(crate) const FS_FIGURE_TITLE: f64 = 16.0;
pub(crate) const FS_TITLE: f64 = 14.0;
pub(crate) const FS_LABEL: f64 = 12.0;
pub(crate) const FS_TICK: f64 = 11.0;
pub(crate) const TICK_LEN: f64 = 5.0;
const MINOR_LEN: f64 = 3.0;
/// Space kept right of the plot frame (for the last x tick label).
const RIGHT: f64 = 16.0;

/// Do the major tick labels fit along an axis of `len` pixels?
fn labels_fit(majors: &[Tick], axis: &Axis, len: f64, horizontal: bool) -> bool {
    majors.windows(2).all(|w| {
        let gap = ((axis.frac(w[1].pos) - axis.frac(w[0].pos)) * len).abs();
        if horizontal {
            let widths = text_width(&w[0].label, FS_TICK) + text_width(&w[1].label, FS_TICK);
            gap >= widths / 2.0 + 8.0
        } else {
            gap >= FS_TICK * 1.6
        }
    })
}

/// The densest ticks (at most 8 labels) whose labels do not overlap.
fn choose_ticks(axis: &Axis, len: f64, horizontal: bool) -> Ticks {
    let minor = axis.log && len / (axis.hi - axis.lo) >= 40.0;
    for n in (2..=8).rev() {
        let t = ticks::axis_ticks(axis, n, minor);
        if labels_fit(&t.major, axis, len, horizontal) {
            return t;
        }
    }
    // Still crowded: keep every k-th label, demote the rest to minor ticks.
    let t = ticks::axis_ticks(axis, 2, minor);
    for stride in 2..=t.major.len().max(2) {
        let (keep, drop): (Vec<_>, Vec<_>) = t
            .major
            .iter()
            .cloned()
            .enumerate()
            .partition(|(i, _)| i % stride == 0);
        let keep: Vec<Tick> = keep.into_iter().map(|(_, t)| t).collect();
        if keep.len() <= 1 || labels_fit(&keep, axis, len, horizontal) {
            let mut minor = t.minor.clone();
            minor.extend(drop.into_iter().map(|(_, t)| t.pos));
            return Ticks { major: keep, minor };
        }
    }
    t
}

/// Pixel mapping, ticks and legend placement of one panel.
struct Layout {
    m: Mapper,
    xt: Ticks,
    yt: Ticks,
    legend: Option<(Legend, Rect)>,
}

/// Plot rectangle and x ticks for a given left margin and space `reserve`d
/// right of the plot; widens the right margin if the last x label sticks out.
fn horizontal(
    xa: Axis,
    ya: Axis,
    left: f64,
    top: f64,
    plot_h: f64,
    w: f64,
    reserve: f64,
) -> (Mapper, Ticks) {
    let mut right = RIGHT + reserve;
    let mut plot_w = (w - left - right).max(10.0);
    let mut xt = choose_ticks(&xa, plot_w, true);
    if let Some(last) = xt.major.last() {
        let end = xa.frac(last.pos) * plot_w + text_width(&last.label, FS_TICK) / 2.0;
        if end - plot_w > RIGHT - 4.0 {
            right = end - plot_w + 4.0 + reserve;
            plot_w = (w - left - right).max(10.0);
            xt = choose_ticks(&xa, plot_w, true);
        }
    }
    let m = Mapper {
        plot: Rect::new(left, top, plot_w, plot_h),
        xa,
        ya,
    };
    (m, xt)
}

fn layout(chart: &Chart, traces: &[Trace], xa: Axis, ya: Axis, w: f64, h: f64) -> Layout {
    let top = if chart.title.trim().is_empty() {
        14.0
    } else {
        24.0 + FS_TITLE
    };
    let x_label_h = if chart.x_label.trim().is_empty() {
        0.0
    } else {
        8.0 + FS_LABEL
    };
    let bottom = TICK_LEN + 4.0 + FS_TICK + x_label_h + 10.0;
    let plot_h = (h - top - bottom).max(10.0);
    let yt = choose_ticks(&ya, plot_h, false);
    let y_labels_w = yt
        .major
        .iter()
        .map(|t| text_width(&t.label, FS_TICK))
        .fold(0.0, f64::max);
    let y_label_w = if chart.y_label.trim().is_empty() {
        0.0
    } else {
        FS_LABEL + 8.0
    };
    let left = 8.0 + y_label_w + y_labels_w + 4.0 + TICK_LEN;

    let max_text = (0.35 * w).max(80.0);
    let mut legend = match chart.legend {
        LegendPosition::Hidden => None,
        _ => Legend::new(traces, h, max_text),
    };
    let mut outside = chart.legend == LegendPosition::Outside;
    loop {
        let reserve = match (&legend, outside) {
            (Some(l), true) => l.w + 16.0,
            _ => 0.0,
        };
        let (m, xt) = horizontal(xa, ya, left, top, plot_h, w, reserve);
        let Some(l) = legend.take() else {
            return Layout {
                m,
                xt,
                yt,
                legend: None,
            };
        };
        let rect = if outside {
            Some(Rect::new(m.plot.x1 + 12.0, top, l.w, l.h))
        } else if chart.legend != LegendPosition::Auto {
            Some(l.corner(chart.legend, &m.plot))
        } else {
            let (clear, least) = l.corners(traces, &m);
            // Otherwise outside, names shortened so the plot keeps 45% of the width.
            let room = w
                - left
                - RIGHT
                - 16.0
                - 0.45 * w
                - (2.0 * legend::PAD + legend::SAMPLE + legend::GAP);
            if clear.is_some() {
                clear
            } else if room < 60.0 {
                Some(least)
            } else {
                outside = true;
                legend = Legend::new(traces, h, room.min(max_text));
                None
            }
        };
        if let Some(r) = rect {
            return Layout {
                m,
                xt,
                yt,
                legend: Some((l, r)),
            };
        }
    }
}

/// Renders `chart` into a `w` x `h` area with its origin at (0, 0).
/// `id` must be unique within the document (used for the clip path).
pub(crate) fn render_chart(chart: &Chart, w: f64, h: f64, id: &str, out: &mut String) {
    let (traces, xlog, ylog) = data::prepare(chart);
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for t in &traces {
        for &(x, y) in t.runs.iter().flatten() {
            xs.push(x);
            ys.push(y);
        }
        for &(_, lo, hi) in &t.errs {
            ys.extend(lo);
            ys.push(hi);
        }
    }
    let xa = ticks::resolve_axis(&xs, xlog, chart.x_range);
    let ya = ticks::resolve_axis(&ys, ylog, chart.y_range);
    let lay = layout(chart, &traces, xa, ya, w, h);
    let p = lay.m.plot;
    let _ = writeln!(
        out,
        "<defs><clipPath id=\"{id}-clip\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath></defs>",
        num(p.x0),
        num(p.y0),
        num(p.x1 - p.x0),
        num(p.y1 - p.y0)
    );
    draw_grid(out, &lay, xlog || ylog);
    draw_data(out, id, &traces, &lay.m);
    draw_markers(out, &traces, &lay.m);
    draw_axes(out, &lay);
    draw_labels(out, chart, &p, w, h);
    if xs.is_empty() {
        let (cx, cy) = ((p.x0 + p.x1) / 2.0, (p.y0 + p.y1) / 2.0);
        svg::text(
            out,
            cx,
            cy,
            FS_LABEL,
            "middle",
            " fill-opacity=\"0.6\"",
            "no data",
        );
    }
    if let Some((l, r)) = &lay.legend {
        l.draw(out, &traces, *r);
    }
}

fn draw_grid(out: &mut String, lay: &Layout, any_log: bool) {
    let (m, p) = (&lay.m, &lay.m.plot);
    let mut minor = String::new();
    let mut major = String::new();
    for &t in &lay.xt.minor {
        let _ = write!(minor, "M{} {}V{}", num(m.px(t)), num(p.y0), num(p.y1));
    }
    for &t in &lay.yt.minor {
        let _ = write!(minor, "M{} {}H{}", num(p.x0), num(m.py(t)), num(p.x1));
    }
    for t in &lay.xt.major {
        let _ = write!(major, "M{} {}V{}", num(m.px(t.pos)), num(p.y0), num(p.y1));
    }
    for t in &lay.yt.major {
        let _ = write!(major, "M{} {}H{}", num(p.x0), num(m.py(t.pos)), num(p.x1));
    }
    if any_log {
        svg::path(out, &minor, "#f0f0f0", 0.6, None);
    }
    svg::path(out, &major, "#dddddd", 0.8, None);
}

/// Lines and error bars, clipped to the plot; reference lines first.
fn draw_data(out: &mut String, id: &str, traces: &[Trace], m: &Mapper) {
    let p = &m.plot;
    // Clip geometry ourselves too, so far-away points keep their direction
    // and coordinates stay small.
    let bounds = Rect {
        x0: p.x0 - 5.0,
        y0: p.y0 - 5.0,
        x1: p.x1 + 5.0,
        y1: p.y1 + 5.0,
    };
    let _ = writeln!(
        out,
        "<g clip-path=\"url(#{id}-clip)\" fill=\"none\" stroke-linejoin=\"round\" stroke-linecap=\"round\">"
    );
    let ordered = traces
        .iter()
        .filter(|t| t.reference)
        .chain(traces.iter().filter(|t| !t.reference));
    for t in ordered {
        let color = escape_xml(&t.color);
        if t.line {
            let mut d = String::new();
            for run in &t.runs {
                let mut pen: Option<(f64, f64)> = None;
                for seg in run.windows(2) {
                    let Some((a, b)) = bounds.clip(m.pt(seg[0]), m.pt(seg[1])) else {
                        pen = None;
                        continue;
                    };
                    if pen != Some(a) {
                        let _ = write!(d, "M{} {}", num(a.0), num(a.1));
                    }
                    let _ = write!(d, "L{} {}", num(b.0), num(b.1));
                    pen = Some(b);
                }
            }
            let width = if t.reference { 1.3 } else { 1.8 };
            svg::path(out, &d, &color, width, t.dashed.then_some(DASH));
        }
        let mut d = String::new();
        for e in &t.errs {
            let (x, lo, hi) = m.err_ends(e);
            if !(bounds.x0..=bounds.x1).contains(&x) {
                continue;
            }
            let y_lo = lo.unwrap_or(p.y1 + 2.0).clamp(bounds.y0, bounds.y1);
            let _ = write!(
                d,
                "M{} {}V{}",
                num(x),
                num(y_lo),
                num(hi.clamp(bounds.y0, bounds.y1))
            );
            for y in lo
                .into_iter()
                .chain([hi])
                .filter(|y| (p.y0..=p.y1).contains(y))
            {
                let _ = write!(d, "M{} {}H{}", num(x - 3.0), num(y), num(x + 3.0));
            }
        }
        svg::path(out, &d, &color, 1.1, None);
    }
    out.push_str("</g>\n");
}

/// Markers (and dots for isolated points of line styles) at visible points;
/// not clipped, so markers on the frame stay whole.
fn draw_markers(out: &mut String, traces: &[Trace], m: &Mapper) {
    for t in traces {
        let mut body = String::new();
        for run in &t.runs {
            for &pt in run.iter().filter(|&&pt| m.visible(pt)) {
                let (x, y) = m.pt(pt);
                match t.marker {
                    Some(shape) => svg::marker(&mut body, shape, x, y, MARKER_R),
                    None if run.len() == 1 && t.line => svg::marker(&mut body, 0, x, y, 3.0),
                    None => {}
                }
            }
        }
        svg::marker_group(out, &escape_xml(&t.color), &body);
    }
}

/// Frame, tick marks and tick labels.
fn draw_axes(out: &mut String, lay: &Layout) {
    let (m, p) = (&lay.m, &lay.m.plot);
    let _ = writeln!(
        out,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444444\" stroke-width=\"1\"/>",
        num(p.x0),
        num(p.y0),
        num(p.x1 - p.x0),
        num(p.y1 - p.y0)
    );
    let mut major = String::new();
    let mut minor = String::new();
    for t in &lay.xt.major {
        let _ = write!(
            major,
            "M{} {}v{}",
            num(m.px(t.pos)),
            num(p.y1),
            num(TICK_LEN)
        );
    }
    for t in &lay.yt.major {
        let _ = write!(
            major,
            "M{} {}h{}",
            num(p.x0),
            num(m.py(t.pos)),
            num(-TICK_LEN)
        );
    }
    for &t in &lay.xt.minor {
        let _ = write!(minor, "M{} {}v{}", num(m.px(t)), num(p.y1), num(MINOR_LEN));
    }
    for &t in &lay.yt.minor {
        let _ = write!(minor, "M{} {}h{}", num(p.x0), num(m.py(t)), num(-MINOR_LEN));
    }
    svg::path(out, &major, "#444444", 1.0, None);
    svg::path(out, &minor, "#444444", 0.7, None);
    let y = p.y1 + TICK_LEN + 4.0 + FS_TICK / 2.0;
    for t in &lay.xt.major {
        svg::text(out, m.px(t.pos), y, FS_TICK, "middle", "", &t.label);
    }
    let x = p.x0 - TICK_LEN - 4.0;
    for t in &lay.yt.major {
        svg::text(out, x, m.py(t.pos), FS_TICK, "end", "", &t.label);
    }
}

/// Centre `c` moved so that a text of half-width `half` stays in `[0, len]`.
fn keep_inside(c: f64, half: f64, len: f64) -> f64 {
    c.min(len - 8.0 - half).max(8.0 + half)
}

/// Axis labels and the title.
fn draw_labels(out: &mut String, chart: &Chart, p: &Rect, w: f64, h: f64) {
    let x_label = chart.x_label.trim();
    if !x_label.is_empty() {
        let label = svg::truncate_to_width(x_label, w - 16.0, FS_LABEL);
        let cx = keep_inside((p.x0 + p.x1) / 2.0, text_width(&label, FS_LABEL) / 2.0, w);
        let y = p.y1 + TICK_LEN + 4.0 + FS_TICK + 8.0 + FS_LABEL / 2.0;
        svg::text(out, cx, y, FS_LABEL, "middle", "", &label);
    }
    let y_label = chart.y_label.trim();
    if !y_label.is_empty() {
        let label = svg::truncate_to_width(y_label, h - 16.0, FS_LABEL);
        let cy = keep_inside((p.y0 + p.y1) / 2.0, text_width(&label, FS_LABEL) / 2.0, h);
        let cx = 8.0 + FS_LABEL / 2.0;
        // The baseline offset in `svg::text` turns into a horizontal shift
        // after rotation, which centres the glyphs on `cx`.
        let rot = format!(" transform=\"rotate(-90 {} {})\"", num(cx), num(cy));
        svg::text(out, cx, cy, FS_LABEL, "middle", &rot, &label);
    }
    let title = chart.title.trim();
    if !title.is_empty() {
        let title = svg::truncate_to_width(title, w - 16.0, FS_TITLE);
        let cx = keep_inside((p.x0 + p.x1) / 2.0, text_width(&title, FS_TITLE) / 2.0, w);
        let bold = " font-weight=\"bold\"";
        svg::text(
            out,
            cx,
            14.0 + FS_TITLE / 2.0,
            FS_TITLE,
            "middle",
            bold,
            &title,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_never_overlap() {
        let axes = [
            Axis {
                log: false,
                lo: -0.05,
                hi: 1.05,
            },
            Axis {
                log: false,
                lo: -1.234e7,
                hi: 9.87e8,
            },
            Axis {
                log: false,
                lo: 0.999_999,
                hi: 1.000_001,
            },
            Axis {
                log: true,
                lo: -3.2,
                hi: 2.1,
            },
            Axis {
                log: true,
                lo: -15.3,
                hi: 0.2,
            },
            Axis {
                log: true,
                lo: -300.0,
                hi: 300.0,
            },
            Axis {
                log: true,
                lo: 0.3,
                hi: 0.9,
            },
        ];
        for axis in &axes {
            for len in [10.0, 40.0, 80.0, 150.0, 300.0, 600.0, 1200.0] {
                for horizontal in [true, false] {
                    let t = choose_ticks(axis, len, horizontal);
                    assert!(t.major.len() <= 10, "{axis:?}");
                    assert!(
                        t.major.len() <= 1 || labels_fit(&t.major, axis, len, horizontal),
                        "{axis:?} {len} {horizontal}: {:?}",
                        t.major
                    );
                }
            }
            // A typical axis gets at least 4 labels.
            assert!(
                choose_ticks(axis, 400.0, false).major.len() >= 4,
                "{axis:?}"
            );
        }
    }

    #[test]
    fn segment_clipping() {
        let r = Rect::new(0.0, 0.0, 10.0, 10.0);
        assert_eq!(
            r.clip((1.0, 1.0), (2.0, 2.0)),
            Some(((1.0, 1.0), (2.0, 2.0)))
        );
        assert_eq!(
            r.clip((-10.0, 5.0), (20.0, 5.0)),
            Some(((0.0, 5.0), (10.0, 5.0)))
        );
        assert_eq!(r.clip((-1.0, -1.0), (-2.0, 20.0)), None);
        let ((x0, y0), (x1, y1)) = r.clip((5.0, 5.0), (5.0 + 1e12, 5.0 + 2e12)).unwrap();
        assert_eq!((x0, y0), (5.0, 5.0));
        assert!((x1 - 7.5).abs() < 1e-9 && (y1 - 10.0).abs() < 1e-9);
        assert!(r.hits_segment((-5.0, 5.0), (5.0, -5.0)));
        assert!(!r.hits_segment((-5.0, 4.0), (4.0, -5.0)));
    }
}
