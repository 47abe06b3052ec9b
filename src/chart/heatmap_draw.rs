//! Layout and drawing of a [`Heatmap`].

use std::fmt::Write as _;

use super::{Grid, Heatmap, VIRIDIS, chains, colour_t, march, viridis};
use crate::chart::data::{Mapper, Rect};
use crate::chart::svg::{self, DASH, num, text_width};
use crate::chart::ticks::{self, Axis, Tick, Ticks};

// the line chart's type sizes and tick length
use crate::chart::legend::FS_LEGEND;
use crate::chart::render::{FS_LABEL, FS_TICK, FS_TITLE, TICK_LEN};
/// Colour bar width and its distance from the plot.
const BAR_W: f64 = 14.0;
const BAR_GAP: f64 = 14.0;
/// Fill of cells without data (non-finite, missing, non-positive on a log scale).
pub(super) const NO_DATA: &str = "#dddddd";
/// Fill of masked cells.
pub(super) const MASKED: &str = "#555555";
/// Stroke colour of contour lines.
const CONTOUR: &str = "#111111";
/// Dash patterns of successive contour levels (cycled).
const DASHES: [Option<&str>; 4] = [None, Some(DASH), Some("2 3"), Some("9 3 2 3")];
/// Plot aspect ratios beyond this factor are clamped (keeps plots usable).
const MAX_ASPECT: f64 = 20.0;

/// Renders `hm` as a standalone SVG document (see [`Heatmap::to_svg`]).
pub(super) fn render(hm: &Heatmap, width: f64, height: f64) -> String {
    let w = svg::sanitize_size(width, 640.0);
    let h = svg::sanitize_size(height, 480.0);
    let g = hm.grid();
    let ca = hm.colour_axis(&g);
    let lay = hm.layout(&g, ca, w, h);
    let mut out = String::new();
    svg::open_document(&mut out, w, h);
    let any_colour = draw_cells(&mut out, &g, &lay.m, ca);
    let has_no_data =
        g.v.iter()
            .zip(&g.masked)
            .any(|(v, &m)| !m && colour_t(ca, *v).is_none());
    hm.draw_contours(&mut out, &g, &lay.m);
    draw_axes(&mut out, &lay);
    hm.draw_bar(&mut out, &lay);
    hm.draw_labels(&mut out, &lay, w);
    hm.draw_legend(&mut out, &lay.m.plot, has_no_data);
    if !any_colour {
        let p = &lay.m.plot;
        let (cx, cy) = ((p.x0 + p.x1) / 2.0, (p.y0 + p.y1) / 2.0);
        svg::text(
            &mut out,
            cx,
            cy,
            FS_LABEL,
            "middle",
            " fill-opacity=\"0.6\"",
            "no data",
        );
    }
    out.push_str("</svg>\n");
    out
}

impl Heatmap {
    /// Plot rectangle (centred, keeping the data aspect ratio), colour bar
    /// and ticks for a `w` x `h` document.
    fn layout(&self, g: &Grid, ca: Axis, w: f64, h: f64) -> Layout {
        let has = |s: &str| !s.trim().is_empty();
        let top = if has(&self.title) {
            24.0 + FS_TITLE
        } else {
            14.0
        };
        let x_label_h = if has(&self.x_label) {
            8.0 + FS_LABEL
        } else {
            0.0
        };
        let bottom = TICK_LEN + 4.0 + FS_TICK + x_label_h + 10.0;
        let ah = (h - top - bottom).max(10.0);
        let max_w = |t: &Ticks| {
            t.major
                .iter()
                .map(|t| text_width(&t.label, FS_TICK))
                .fold(0.0, f64::max)
        };
        let y_lab = if has(&self.y_label) {
            FS_LABEL + 8.0
        } else {
            0.0
        };
        let left = 8.0 + y_lab + max_w(&fit_ticks(&g.ya, ah, false)) + 4.0 + TICK_LEN;
        let c_lab = if has(&self.colour_label) {
            8.0 + FS_LABEL
        } else {
            0.0
        };
        let right =
            BAR_GAP + BAR_W + TICK_LEN + 4.0 + max_w(&fit_ticks(&ca, ah, false)) + c_lab + 10.0;
        let aw = (w - left - right).max(10.0);
        let r = ((g.xa.hi - g.xa.lo) / (g.ya.hi - g.ya.lo)).clamp(1.0 / MAX_ASPECT, MAX_ASPECT);
        let (pw, ph) = if aw / ah > r {
            (ah * r, ah)
        } else {
            (aw, aw / r)
        };
        let (pw, ph) = (pw.max(10.0), ph.max(10.0));
        let plot = Rect::new(left + (aw - pw) / 2.0, top + (ah - ph) / 2.0, pw, ph);
        Layout {
            m: Mapper {
                plot,
                xa: g.xa,
                ya: g.ya,
            },
            xt: fit_ticks(&g.xa, pw, true),
            yt: fit_ticks(&g.ya, ph, false),
            ct: fit_ticks(&ca, ph, false),
            ca,
            bar: Rect::new(plot.x1 + BAR_GAP, plot.y0, BAR_W, ph),
        }
    }

    /// Contour paths: a white halo under a dark line, chained into polylines.
    fn draw_contours(&self, out: &mut String, g: &Grid, m: &Mapper) {
        if self.contours.is_empty() {
            return;
        }
        out.push_str("<g fill=\"none\" stroke-linejoin=\"round\" stroke-linecap=\"round\">\n");
        for (k, (level, _)) in self.contours.iter().enumerate() {
            let mut d = String::new();
            for (chain, closed) in chains(&march(g, *level)) {
                for (n, &e) in chain.iter().enumerate() {
                    let (x, y) = m.pt(g.edge_point(e, *level));
                    let _ = write!(d, "{}{} {}", if n == 0 { 'M' } else { 'L' }, num(x), num(y));
                }
                if closed {
                    d.push('Z');
                }
            }
            if d.is_empty() {
                continue;
            }
            let dash = DASHES[k % DASHES.len()]
                .map(|s| format!(" stroke-dasharray=\"{s}\""))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "<path class=\"contour-halo\" d=\"{d}\" stroke=\"#ffffff\" stroke-opacity=\"0.7\" stroke-width=\"3.4\"/>"
            );
            let _ = writeln!(
                out,
                "<path class=\"contour\" d=\"{d}\" stroke=\"{CONTOUR}\" stroke-width=\"1.5\"{dash}/>"
            );
        }
        out.push_str("</g>\n");
    }

    /// Colour bar (gradient), its ticks and labels, and contour level marks.
    fn draw_bar(&self, out: &mut String, lay: &Layout) {
        let b = &lay.bar;
        out.push_str("<defs><linearGradient id=\"hm-cbar\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">");
        for k in 0..VIRIDIS.len() {
            let t = k as f64 / (VIRIDIS.len() - 1) as f64;
            let _ = write!(
                out,
                "<stop offset=\"{}\" stop-color=\"{}\"/>",
                num(t),
                viridis(t)
            );
        }
        out.push_str("</linearGradient></defs>\n");
        rect(out, b, " fill=\"url(#hm-cbar)\"");
        let py = |t: f64| b.y1 - lay.ca.frac(t).clamp(0.0, 1.0) * (b.y1 - b.y0);
        let mut marks = String::new();
        for (level, _) in &self.contours {
            if let Some(t) = ticks::transform(lay.ca.log, *level)
                .filter(|&t| (lay.ca.lo..=lay.ca.hi).contains(&t))
            {
                let _ = write!(marks, "M{} {}h{}", num(b.x0), num(py(t)), num(BAR_W));
            }
        }
        svg::path(out, &marks, CONTOUR, 1.5, None);
        rect(out, b, FRAME);
        let mut d = String::new();
        for t in &lay.ct.major {
            let _ = write!(d, "M{} {}h{}", num(b.x1), num(py(t.pos)), num(TICK_LEN));
        }
        svg::path(out, &d, "#444444", 1.0, None);
        let mut d = String::new();
        for &t in &lay.ct.minor {
            let _ = write!(d, "M{} {}h3", num(b.x1), num(py(t)));
        }
        svg::path(out, &d, "#444444", 0.7, None);
        let lx = b.x1 + TICK_LEN + 4.0;
        for t in &lay.ct.major {
            svg::text(out, lx, py(t.pos), FS_TICK, "start", "", &t.label);
        }
        let label = self.colour_label.trim();
        if !label.is_empty() {
            let label = svg::truncate_to_width(label, (b.y1 - b.y0).max(40.0), FS_LABEL);
            let lw = lay
                .ct
                .major
                .iter()
                .map(|t| text_width(&t.label, FS_TICK))
                .fold(0.0, f64::max);
            let (cx, cy) = (lx + lw + 8.0 + FS_LABEL / 2.0, (b.y0 + b.y1) / 2.0);
            let rot = format!(" transform=\"rotate(-90 {} {})\"", num(cx), num(cy));
            svg::text(out, cx, cy, FS_LABEL, "middle", &rot, &label);
        }
    }

    /// Title and axis labels, positioned relative to the plot.
    fn draw_labels(&self, out: &mut String, lay: &Layout, w: f64) {
        let p = &lay.m.plot;
        let x_label = self.x_label.trim();
        if !x_label.is_empty() {
            let label = svg::truncate_to_width(x_label, w - 16.0, FS_LABEL);
            let y = p.y1 + TICK_LEN + 4.0 + FS_TICK + 8.0 + FS_LABEL / 2.0;
            svg::text(out, (p.x0 + p.x1) / 2.0, y, FS_LABEL, "middle", "", &label);
        }
        let y_label = self.y_label.trim();
        if !y_label.is_empty() {
            let label = svg::truncate_to_width(y_label, (p.y1 - p.y0).max(40.0), FS_LABEL);
            let lw = lay
                .yt
                .major
                .iter()
                .map(|t| text_width(&t.label, FS_TICK))
                .fold(0.0, f64::max);
            let (cx, cy) = (
                p.x0 - TICK_LEN - 4.0 - lw - 8.0 - FS_LABEL / 2.0,
                (p.y0 + p.y1) / 2.0,
            );
            let rot = format!(" transform=\"rotate(-90 {} {})\"", num(cx), num(cy));
            svg::text(out, cx, cy, FS_LABEL, "middle", &rot, &label);
        }
        let title = self.title.trim();
        if !title.is_empty() {
            let title = svg::truncate_to_width(title, w - 16.0, FS_TITLE);
            let half = text_width(&title, FS_TITLE) / 2.0;
            let cx = ((p.x0 + p.x1) / 2.0).min(w - 8.0 - half).max(8.0 + half);
            let bold = " font-weight=\"bold\"";
            svg::text(
                out,
                cx,
                p.y0 - 10.0 - FS_TITLE / 2.0,
                FS_TITLE,
                "middle",
                bold,
                &title,
            );
        }
    }

    /// Legend (contour labels, "no data" swatch) in the top-right plot corner.
    fn draw_legend(&self, out: &mut String, p: &Rect, has_no_data: bool) {
        const PAD: f64 = 6.0;
        const ROW: f64 = FS_LEGEND * 1.5;
        const SAMPLE: f64 = 24.0;
        let max_text = 0.45 * (p.x1 - p.x0);
        let mut rows: Vec<(Option<usize>, String)> = self
            .contours
            .iter()
            .enumerate()
            .filter(|(_, (_, l))| !l.trim().is_empty())
            .map(|(k, (_, l))| {
                (
                    Some(k),
                    svg::truncate_to_width(l.trim(), max_text, FS_LEGEND),
                )
            })
            .collect();
        if has_no_data {
            rows.push((None, "no data".to_string()));
        }
        let max_rows = ((p.y1 - p.y0 - 16.0 - 2.0 * PAD) / ROW).floor().max(0.0) as usize;
        rows.truncate(max_rows);
        if rows.is_empty() {
            return;
        }
        let text_w = rows
            .iter()
            .map(|(_, s)| text_width(s, FS_LEGEND))
            .fold(0.0, f64::max);
        let (bw, bh) = (
            3.0 * PAD + SAMPLE + text_w,
            2.0 * PAD + rows.len() as f64 * ROW,
        );
        let (x, y) = (p.x1 - 8.0 - bw, p.y0 + 8.0);
        out.push_str("<g>\n");
        let white =
            " fill=\"#ffffff\" fill-opacity=\"0.85\" stroke=\"#999999\" stroke-width=\"0.8\"";
        rect(out, &Rect::new(x, y, bw, bh), white);
        for (n, (k, name)) in rows.iter().enumerate() {
            let cy = y + PAD + (n as f64 + 0.5) * ROW;
            match k {
                Some(k) => {
                    let d = format!("M{} {}h{}", num(x + PAD), num(cy), num(SAMPLE));
                    svg::path(out, &d, CONTOUR, 1.5, DASHES[k % DASHES.len()]);
                }
                None => {
                    let grey =
                        format!(" fill=\"{NO_DATA}\" stroke=\"#999999\" stroke-width=\"0.6\"");
                    rect(out, &Rect::new(x + PAD, cy - 4.0, SAMPLE, 8.0), &grey);
                }
            }
            svg::text(
                out,
                x + 2.0 * PAD + SAMPLE,
                cy,
                FS_LEGEND,
                "start",
                "",
                name,
            );
        }
        out.push_str("</g>\n");
    }
}

/// Cell rectangles, runs of equal colour in a row merged (colours are
/// quantised to 256 levels). Returns whether any cell got a colour.
fn draw_cells(out: &mut String, g: &Grid, m: &Mapper, ca: Axis) -> bool {
    let round = |v: f64| (v * 100.0).round() / 100.0;
    let xe: Vec<f64> = (0..=g.nx)
        .map(|i| round(m.px(g.x0 + i as f64 * g.dx)))
        .collect();
    let ye: Vec<f64> = (0..=g.ny)
        .map(|j| round(m.py(g.y0 + j as f64 * g.dy)))
        .collect();
    let fill = |i: usize, j: usize| -> Option<u8> {
        let k = j * g.nx + i;
        colour_t(ca, g.v[k])
            .map(|t| (t * 255.0).round() as u8)
            .filter(|_| !g.masked[k])
    };
    let mut any = false;
    out.push_str("<g shape-rendering=\"crispEdges\">\n");
    for j in 0..g.ny {
        let (y0, y1) = (ye[j].min(ye[j + 1]), ye[j].max(ye[j + 1]));
        let mut i = 0;
        while i < g.nx {
            let (f, masked) = (fill(i, j), g.masked[j * g.nx + i]);
            let mut k = i + 1;
            while k < g.nx && fill(k, j) == f && g.masked[j * g.nx + k] == masked {
                k += 1;
            }
            let colour = match f {
                Some(q) => viridis(f64::from(q) / 255.0),
                None if masked => MASKED.to_string(),
                None => NO_DATA.to_string(),
            };
            any |= f.is_some();
            let (x0, x1) = (xe[i].min(xe[k]), xe[i].max(xe[k]));
            rect(
                out,
                &Rect { x0, y0, x1, y1 },
                &format!(" fill=\"{colour}\""),
            );
            i = k;
        }
    }
    out.push_str("</g>\n");
    any
}

/// Pixel mapping of the plot, ticks of both axes and the colour bar.
struct Layout {
    m: Mapper,
    xt: Ticks,
    yt: Ticks,
    ct: Ticks,
    ca: Axis,
    bar: Rect,
}

/// The densest ticks (at most 8 labels) whose labels do not overlap along
/// an axis of `len` pixels.
fn fit_ticks(axis: &Axis, len: f64, horizontal: bool) -> Ticks {
    let fits = |majors: &[Tick]| {
        majors.windows(2).all(|w| {
            let gap = ((axis.frac(w[1].pos) - axis.frac(w[0].pos)) * len).abs();
            if horizontal {
                gap >= (text_width(&w[0].label, FS_TICK) + text_width(&w[1].label, FS_TICK)) / 2.0
                    + 8.0
            } else {
                gap >= FS_TICK * 1.6
            }
        })
    };
    let minor = axis.log && len / (axis.hi - axis.lo) >= 40.0;
    (3..=8)
        .rev()
        .map(|n| ticks::axis_ticks(axis, n, minor))
        .find(|t| fits(&t.major))
        .unwrap_or_else(|| ticks::axis_ticks(axis, 2, minor))
}

/// Frame, tick marks and tick labels of the plot.
fn draw_axes(out: &mut String, lay: &Layout) {
    let (m, p) = (&lay.m, &lay.m.plot);
    rect(out, p, FRAME);
    let mut d = String::new();
    for t in &lay.xt.major {
        let _ = write!(d, "M{} {}v{}", num(m.px(t.pos)), num(p.y1), num(TICK_LEN));
    }
    for t in &lay.yt.major {
        let _ = write!(d, "M{} {}h{}", num(p.x0), num(m.py(t.pos)), num(-TICK_LEN));
    }
    svg::path(out, &d, "#444444", 1.0, None);
    let y = p.y1 + TICK_LEN + 4.0 + FS_TICK / 2.0;
    for t in &lay.xt.major {
        svg::text(out, m.px(t.pos), y, FS_TICK, "middle", "", &t.label);
    }
    for t in &lay.yt.major {
        svg::text(
            out,
            p.x0 - TICK_LEN - 4.0,
            m.py(t.pos),
            FS_TICK,
            "end",
            "",
            &t.label,
        );
    }
}

/// Style of the plot and colour bar frames.
const FRAME: &str = " fill=\"none\" stroke=\"#444444\" stroke-width=\"1\"";

/// Appends a `<rect>` covering `r`; `extra` (starting with a space) goes
/// into the tag verbatim.
fn rect(out: &mut String, r: &Rect, extra: &str) {
    let _ = writeln!(
        out,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"{extra}/>",
        num(r.x0),
        num(r.y0),
        num(r.x1 - r.x0),
        num(r.y1 - r.y0)
    );
}
