//! Legend layout, placement (avoiding the data) and drawing.

use std::fmt::Write as _;

use super::LegendPosition;
use super::data::{Mapper, Rect, Trace};
use super::svg::{self, DASH, MARKER_R, escape_xml, num, text_width};

/// Legend font size.
pub(crate) const FS_LEGEND: f64 = 11.0;
/// Inner padding of the legend box.
pub(super) const PAD: f64 = 6.0;
/// Height of one legend row.
const ROW: f64 = FS_LEGEND * 1.5;
/// Length of the line sample in front of each name.
pub(super) const SAMPLE: f64 = 26.0;
/// Gap between sample and name.
pub(super) const GAP: f64 = 6.0;
/// Distance between an inside legend and the plot frame.
const INSET: f64 = 8.0;

/// Legend rows (trace indices, then maybe a "+N more" row) and box size.
pub(super) struct Legend {
    rows: Vec<usize>,
    names: Vec<String>,
    pub w: f64,
    pub h: f64,
}

impl Legend {
    /// Lays out entries for every named trace, or `None` if there are none.
    /// Names are truncated to `max_text` pixels; rows beyond what fits in a
    /// chart of height `h` are summarised as "+N more".
    pub fn new(traces: &[Trace], h: f64, max_text: f64) -> Option<Legend> {
        let mut rows: Vec<usize> = (0..traces.len())
            .filter(|&i| !traces[i].name.trim().is_empty())
            .collect();
        if rows.is_empty() {
            return None;
        }
        let max_rows = (((h - 40.0 - 2.0 * PAD) / ROW).floor() as usize).max(2);
        let mut more = 0;
        if rows.len() > max_rows {
            more = rows.len() - (max_rows - 1);
            rows.truncate(max_rows - 1);
        }
        let mut names: Vec<String> = rows
            .iter()
            .map(|&i| svg::truncate_to_width(traces[i].name.trim(), max_text, FS_LEGEND))
            .collect();
        if more > 0 {
            names.push(format!("+{more} more"));
        }
        let text_w = names
            .iter()
            .map(|n| text_width(n, FS_LEGEND))
            .fold(0.0, f64::max);
        Some(Legend {
            w: 2.0 * PAD + SAMPLE + GAP + text_w,
            h: 2.0 * PAD + names.len() as f64 * ROW,
            rows,
            names,
        })
    }

    /// The box at an inside corner of `plot` (`Auto`, `Outside` and `Hidden`
    /// mean top-right here).
    pub fn corner(&self, pos: LegendPosition, plot: &Rect) -> Rect {
        let (l, r) = (plot.x0 + INSET, plot.x1 - INSET - self.w);
        let (t, b) = (plot.y0 + INSET, plot.y1 - INSET - self.h);
        let (x, y) = match pos {
            LegendPosition::TopLeft => (l, t),
            LegendPosition::BottomRight => (r, b),
            LegendPosition::BottomLeft => (l, b),
            _ => (r, t),
        };
        Rect::new(x, y, self.w, self.h)
    }

    /// Inside corners in order of preference (top-right, top-left,
    /// bottom-right, bottom-left): the first one covering no data if the
    /// legend fits inside at all, and the least crowded one.
    pub fn corners(&self, traces: &[Trace], m: &Mapper) -> (Option<Rect>, Rect) {
        let p = &m.plot;
        let fits = self.w + 2.0 * INSET <= p.x1 - p.x0 && self.h + 2.0 * INSET <= p.y1 - p.y0;
        let scored: Vec<(usize, Rect)> = [
            LegendPosition::TopRight,
            LegendPosition::TopLeft,
            LegendPosition::BottomRight,
            LegendPosition::BottomLeft,
        ]
        .into_iter()
        .map(|c| self.corner(c, p))
        .map(|r| (data_hits(traces, m, &r), r))
        .collect();
        let clear = scored.iter().find(|(n, _)| *n == 0).filter(|_| fits);
        let least = scored
            .iter()
            .min_by_key(|(n, _)| *n)
            .map_or(scored[0].1, |s| s.1);
        (clear.map(|s| s.1), least)
    }

    /// Draws the legend box at `r`.
    pub fn draw(&self, out: &mut String, traces: &[Trace], r: Rect) {
        let _ = writeln!(
            out,
            "<g><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#ffffff\" \
             fill-opacity=\"0.9\" stroke=\"#bbbbbb\" stroke-width=\"0.8\"/>",
            num(r.x0),
            num(r.y0),
            num(self.w),
            num(self.h)
        );
        for (row, name) in self.names.iter().enumerate() {
            let cy = r.y0 + PAD + ROW * (row as f64 + 0.5);
            let x0 = r.x0 + PAD;
            if let Some(t) = self.rows.get(row).and_then(|&i| traces.get(i)) {
                let color = escape_xml(&t.color);
                if t.line {
                    let d = format!("M{} {}H{}", num(x0), num(cy), num(x0 + SAMPLE));
                    let width = if t.reference { 1.3 } else { 1.8 };
                    svg::path(out, &d, &color, width, t.dashed.then_some(DASH));
                }
                if let Some(shape) = t.marker {
                    let mut body = String::new();
                    svg::marker(&mut body, shape, x0 + SAMPLE / 2.0, cy, MARKER_R);
                    svg::marker_group(out, &color, &body);
                }
            }
            svg::text(out, x0 + SAMPLE + GAP, cy, FS_LEGEND, "start", "", name);
        }
        out.push_str("</g>\n");
    }
}

/// Number of data features (segments, markers, error bars) touching `r`.
fn data_hits(traces: &[Trace], m: &Mapper, r: &Rect) -> usize {
    let mut hits = 0;
    for t in traces {
        for run in &t.runs {
            let pts: Vec<(f64, f64)> = run.iter().map(|&p| m.pt(p)).collect();
            if t.line {
                hits += pts
                    .windows(2)
                    .filter(|s| r.hits_segment(s[0], s[1]))
                    .count();
            }
            if t.marker.is_some() || (t.line && pts.len() == 1) {
                hits += pts.iter().filter(|&&p| r.contains(p, MARKER_R)).count();
            }
        }
        for e in &t.errs {
            let (x, lo, hi) = m.err_ends(e);
            hits += usize::from(r.hits_segment((x, lo.unwrap_or(m.plot.y1)), (x, hi)));
        }
    }
    hits
}
