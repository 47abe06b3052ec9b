//! Legend entries, placement (a corner clear of the data, else outside)
//! and drawing through plotters' series labels.

use plotters::coord::ranged1d::Ranged;
use plotters::prelude::*;

use super::axis::{Axis, text_width};
use super::data::{self, Trace};
use super::render::Drawn;
use super::style::{DASH, FS_TICK, INK, font, sample_dashed, sample_marker, sample_solid, wrap};

/// Inner margin of the legend box, px.
const MARGIN: f64 = 6.0;
/// Width plotters reserves for the line sample in front of each name, px.
const SAMPLE: f64 = 32.0;
/// Sample, margins and gap around the names, px.
pub(super) const SAMPLE_AREA: f64 = SAMPLE + 2.0 * MARGIN;
/// Height of one legend row, px.
const ROW: f64 = FS_TICK * 1.6;
/// Distance plotters keeps between an inside legend and the frame, px.
const INSET: f64 = 5.0;
/// Most lines an entry wraps to (the rest is shortened with an ellipsis): entries that
/// differ only at their end (two settings of one method) must not read alike.
const ENTRY_LINES: usize = 3;

/// Where the legend goes.
#[derive(Clone)]
pub(super) enum Placement {
    /// Inside the plot, at this corner.
    Corner(SeriesLabelPosition),
    /// Right of the plot.
    Outside,
}

/// Legend rows (trace index and the first line of its name; `None` for a wrapped name's
/// further lines and the "+N more" row) and box size, px.
pub(super) struct Legend {
    rows: Vec<(Option<usize>, String)>,
    pub w: f64,
    pub h: f64,
}

impl Legend {
    /// Entries for every named trace, or `None` if there are none. Names are
    /// wrapped at spaces to lines of `max_text` px (at most [`ENTRY_LINES`] per
    /// entry, the sample on the first); entries beyond the rows that fit in
    /// `plot_h` px are summarised as "+N more".
    pub fn new(traces: &[Trace], plot_h: f64, max_text: f64) -> Option<Legend> {
        let named: Vec<usize> = (0..traces.len())
            .filter(|&i| !traces[i].name.trim().is_empty())
            .collect();
        if named.is_empty() {
            return None;
        }
        let max_rows = (((plot_h - 2.0 * INSET - 2.0 * MARGIN) / ROW).floor() as usize).max(2);
        let lines: Vec<Vec<String>> = named
            .iter()
            .map(|&i| wrap(&traces[i].name, max_text, FS_TICK, ENTRY_LINES))
            .collect();
        let all = lines.iter().map(Vec::len).sum::<usize>() <= max_rows;
        // without room for all, one row is kept for "+N more"
        let budget = if all { max_rows } else { max_rows - 1 };
        let mut rows: Vec<(Option<usize>, String)> = Vec::new();
        let mut kept = 0;
        for (&i, entry) in named.iter().zip(&lines) {
            let room = budget - rows.len();
            let entry = if entry.len() <= room {
                entry.clone()
            } else if kept == 0 && room > 0 {
                // the first entry is shown, in the rows there are
                wrap(&traces[i].name, max_text, FS_TICK, room)
            } else {
                break;
            };
            for (k, line) in entry.into_iter().enumerate() {
                rows.push(((k == 0).then_some(i), line));
            }
            kept += 1;
        }
        if kept < named.len() {
            rows.push((None, format!("+{} more", named.len() - kept)));
        }
        let text_w = rows
            .iter()
            .map(|r| text_width(&r.1, FS_TICK))
            .fold(0.0, f64::max);
        Some(Legend {
            w: SAMPLE_AREA + text_w,
            h: 2.0 * MARGIN + rows.len() as f64 * ROW,
            rows,
        })
    }

    /// Inside corners in order of preference (top-right, top-left,
    /// bottom-right, bottom-left) for a `plot_w` x `plot_h` px plot: the
    /// first covering no data if the legend fits at all, and the least
    /// crowded one.
    pub fn corners(
        &self,
        traces: &[Trace],
        xa: &Axis,
        ya: &Axis,
        plot_w: f64,
        plot_h: f64,
    ) -> (Option<SeriesLabelPosition>, SeriesLabelPosition) {
        use SeriesLabelPosition::{LowerLeft, LowerRight, UpperLeft, UpperRight};
        let fits = self.w + 2.0 * INSET <= plot_w && self.h + 2.0 * INSET <= plot_h;
        let (fw, fh) = ((self.w + INSET) / plot_w, (self.h + INSET) / plot_h);
        let span = |a: &Axis, f0: f64, f1: f64| Axis {
            log: false,
            lo: a.lo + f0 * (a.hi - a.lo),
            hi: a.lo + f1 * (a.hi - a.lo),
        };
        let scored: Vec<(usize, SeriesLabelPosition)> = [
            (UpperRight, true, true),
            (UpperLeft, false, true),
            (LowerRight, true, false),
            (LowerLeft, false, false),
        ]
        .into_iter()
        .map(|(pos, right, top)| {
            let bx = if right {
                span(xa, 1.0 - fw, 1.0)
            } else {
                span(xa, 0.0, fw)
            };
            let by = if top {
                span(ya, 1.0 - fh, 1.0)
            } else {
                span(ya, 0.0, fh)
            };
            (data_hits(traces, &bx, &by), pos)
        })
        .collect();
        let clear = scored
            .iter()
            .find(|s| s.0 == 0)
            .filter(|_| fits)
            .map(|s| s.1.clone());
        let least = scored
            .iter()
            .min_by_key(|s| s.0)
            .map_or(UpperRight, |s| s.1.clone());
        (clear, least)
    }

    /// Attaches the entries to `ctx` and draws plotters' series labels at `pos`.
    pub fn draw<'a, DB: DrawingBackend + 'a, X, Y>(
        &self,
        ctx: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
        traces: &[Trace],
        pos: SeriesLabelPosition,
    ) -> Drawn<DB>
    where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        for (index, name) in &self.rows {
            let anno = ctx.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            anno.label(name.as_str());
            let Some(t) = index.and_then(|i| traces.get(i)) else {
                continue;
            };
            let color = t.color;
            let style = ShapeStyle::from(color).stroke_width(if t.reference { 1 } else { 2 });
            let at = EmptyElement::at;
            match (t.line, t.dashed, t.marker) {
                (false, _, m) => anno.legend(move |p| at(p) + sample_marker(m.unwrap_or(0), color)),
                (true, false, None) => anno.legend(move |p| at(p) + sample_solid(style)),
                (true, false, Some(k)) => {
                    anno.legend(move |p| at(p) + sample_solid(style) + sample_marker(k, color))
                }
                (true, true, None) => anno.legend(move |p| at(p) + sample_dashed(style, DASH)),
                (true, true, Some(k)) => anno
                    .legend(move |p| at(p) + sample_dashed(style, DASH) + sample_marker(k, color)),
            };
        }
        ctx.configure_series_labels()
            .position(pos)
            .margin(MARGIN as u32)
            .legend_area_size(SAMPLE as u32)
            .label_font(font(FS_TICK).color(&INK))
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(0xbb, 0xbb, 0xbb))
            .draw()
    }
}

/// Number of data features (segments, markers, error bars) inside the box
/// `bx` x `by` (transformed coordinates).
fn data_hits(traces: &[Trace], bx: &Axis, by: &Axis) -> usize {
    let mut hits = 0;
    for t in traces {
        for run in &t.runs {
            if t.line {
                hits += run
                    .windows(2)
                    .filter(|s| data::clip(bx, by, s[0], s[1]).is_some())
                    .count();
            }
            if t.marker.is_some() || (t.line && run.len() == 1) {
                hits += run.iter().filter(|&&p| data::visible(bx, by, p)).count();
            }
        }
        for &(x, lo, _, hi) in &t.errs {
            let lo = lo.unwrap_or(by.lo.min(hi));
            hits += usize::from(data::clip(bx, by, (x, lo), (x, hi)).is_some());
        }
    }
    hits
}
