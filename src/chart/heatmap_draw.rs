//! Layout and drawing of a [`Heatmap`] with plotters: cells as rectangles,
//! contours as paths, a colour bar as a second plotters chart.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{Grid, Heatmap, chains, colour_t, march, viridis};
use crate::chart::axis::{self, Axis, PlotAxis, Ticks, text_width};
use crate::chart::render::{Drawn, TICK_LEN};
use crate::chart::style::{
    FRAME, FS_LABEL, FS_TICK, FS_TITLE, INK, TITLE_LINE_H, bold, clean, fit, font, sample_dashed,
    sample_solid, title_lines,
};

/// Colour bar width and its distance from the plot, px.
const BAR_W: f64 = 14.0;
const BAR_GAP: f64 = 14.0;
/// Fill of cells without data (non-finite, missing, non-positive on a log scale).
pub(super) const NO_DATA: RGBColor = RGBColor(0xdd, 0xdd, 0xdd);
/// Fill of masked cells.
pub(super) const MASKED: RGBColor = RGBColor(0x55, 0x55, 0x55);
/// Stroke colour of contour lines.
pub(super) const CONTOUR: RGBColor = RGBColor(0x11, 0x11, 0x11);
/// Dash patterns `(on, off)` px of successive contour levels (cycled).
const DASHES: [Option<(u32, u32)>; 4] = [None, Some((7, 4)), Some((2, 4)), Some((12, 4))];
/// Plot aspect ratios beyond this factor are clamped (keeps plots usable).
const MAX_ASPECT: f64 = 20.0;
/// Colour steps of the colour bar.
const BAR_STEPS: usize = 64;

/// Plot rectangle (px), label area sizes and ticks of the plot and bar.
struct Layout {
    x0: f64,
    y0: f64,
    pw: f64,
    ph: f64,
    y_area: f64,
    x_area: f64,
    bar_area: f64,
    xt: Ticks,
    yt: Ticks,
    ct: Ticks,
}

impl Heatmap {
    /// The title wrapped to a `w` px document (see [`title_lines`]).
    fn title_lines(&self, w: f64) -> Vec<String> {
        title_lines(&self.title, w - 16.0)
    }

    /// Plot rectangle (centred, keeping the data aspect ratio), colour bar
    /// and ticks for a `w` x `h` px document.
    fn layout(&self, g: &Grid, ca: &Axis, w: f64, h: f64) -> Layout {
        let has = |s: &str| !s.trim().is_empty();
        let top = match self.title_lines(w).len() {
            0 => 14.0,
            n => 24.0 + FS_TITLE + (n - 1) as f64 * TITLE_LINE_H,
        };
        let x_area = f64::from(TICK_LEN)
            + 6.0
            + FS_TICK
            + if has(&self.x_label) {
                8.0 + FS_LABEL
            } else {
                0.0
            }
            + 4.0;
        let ah = (h - top - x_area - 6.0).max(10.0);
        let max_w = |t: &Ticks| {
            t.major
                .iter()
                .map(|t| text_width(&t.1, FS_TICK))
                .fold(0.0, f64::max)
        };
        let y_lab = if has(&self.y_label) {
            FS_LABEL + 10.0
        } else {
            0.0
        };
        let y_area = 8.0
            + y_lab
            + max_w(&axis::choose_ticks(&g.ya, ah, false, FS_TICK))
            + 6.0
            + f64::from(TICK_LEN);
        let c_lab = if has(&self.colour_label) {
            10.0 + FS_LABEL
        } else {
            0.0
        };
        let bar_area = f64::from(TICK_LEN)
            + 6.0
            + max_w(&axis::choose_ticks(ca, ah, false, FS_TICK))
            + c_lab
            + 8.0;
        let aw = (w - y_area - BAR_GAP - BAR_W - bar_area).max(10.0);
        let r = ((g.xa.hi - g.xa.lo) / (g.ya.hi - g.ya.lo)).clamp(1.0 / MAX_ASPECT, MAX_ASPECT);
        let (pw, ph) = if aw / ah > r {
            (ah * r, ah)
        } else {
            (aw, aw / r)
        };
        let (pw, ph) = (pw.max(10.0), ph.max(10.0));
        Layout {
            x0: y_area + (aw - pw) / 2.0,
            y0: top + (ah - ph) / 2.0,
            pw,
            ph,
            y_area,
            x_area,
            bar_area,
            xt: axis::choose_ticks(&g.xa, pw, true, FS_TICK),
            yt: axis::choose_ticks(&g.ya, ph, false, FS_TICK),
            ct: axis::choose_ticks(ca, ph, false, FS_TICK),
        }
    }
}

/// Draws `hm` on `root` (see [`Heatmap::to_svg`]).
pub(super) fn draw<DB: DrawingBackend>(hm: &Heatmap, root: &DrawingArea<DB, Shift>) -> Drawn<DB> {
    let (w, h) = root.dim_in_pixel();
    let g = hm.grid();
    let ca = hm.colour_axis(&g);
    let lay = hm.layout(&g, &ca, f64::from(w), f64::from(h));
    let px = |v: f64| v.round() as i32;
    // the title's lines above the plot, the last where a one-line title sits
    let lines = hm.title_lines(f64::from(w));
    let n = lines.len();
    for (k, text) in lines.into_iter().enumerate() {
        let half = text_width(&text, FS_TITLE) / 2.0;
        let cx = (lay.x0 + lay.pw / 2.0)
            .min(f64::from(w) - 8.0 - half)
            .max(8.0 + half);
        let cy = lay.y0 - 10.0 - FS_TITLE / 2.0 - (n - 1 - k) as f64 * TITLE_LINE_H;
        let style = bold(FS_TITLE)
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(text, (px(cx), px(cy)), style))?;
    }
    let main = root.clone().shrink(
        (px(lay.x0 - lay.y_area), px(lay.y0)),
        (px(lay.y_area + lay.pw), px(lay.ph + lay.x_area)),
    );
    let mut ctx = ChartBuilder::on(&main)
        .x_label_area_size(px(lay.x_area))
        .y_label_area_size(px(lay.y_area))
        .build_cartesian_2d(PlotAxis::new(&g.xa, &lay.xt), PlotAxis::new(&g.ya, &lay.yt))?;
    let x_fmt = |v: &f64| axis::label_of(&g.xa, &lay.xt, *v);
    let y_fmt = |v: &f64| axis::label_of(&g.ya, &lay.yt, *v);
    ctx.configure_mesh()
        .disable_mesh()
        .x_desc(clean(&hm.x_label))
        .y_desc(clean(&hm.y_label))
        .axis_desc_style(font(FS_LABEL).color(&INK))
        .label_style(font(FS_TICK).color(&INK))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .axis_style(FRAME)
        .set_all_tick_mark_size(TICK_LEN)
        .draw()?;
    let any_colour = draw_cells(&mut ctx, &g, &ca)?;
    let frame = [(g.xa.lo, g.ya.lo), (g.xa.hi, g.ya.hi)];
    ctx.plotting_area()
        .draw(&Rectangle::new(frame, FRAME.stroke_width(1)))?;
    hm.draw_contours(&mut ctx, &g)?;
    if !any_colour {
        let style = font(FS_LABEL)
            .color(&INK.mix(0.6))
            .pos(Pos::new(HPos::Center, VPos::Center));
        let mid = ((g.xa.lo + g.xa.hi) / 2.0, (g.ya.lo + g.ya.hi) / 2.0);
        ctx.plotting_area()
            .draw(&Text::new("no data", mid, style))?;
    }
    let has_no_data =
        g.v.iter()
            .zip(&g.masked)
            .any(|(v, &m)| !m && colour_t(&ca, *v).is_none());
    hm.draw_legend(&mut ctx, lay.pw, lay.ph, has_no_data)?;
    let bar = root.clone().shrink(
        (px(lay.x0 + lay.pw + BAR_GAP), px(lay.y0)),
        (px(BAR_W + lay.bar_area), px(lay.ph)),
    );
    hm.draw_bar(&bar, &ca, &lay)
}

impl Heatmap {
    /// Contours: a white halo under a dark line, chained into polylines.
    fn draw_contours<DB: DrawingBackend>(
        &self,
        ctx: &mut ChartContext<'_, DB, Cartesian2d<PlotAxis, PlotAxis>>,
        g: &Grid,
    ) -> Drawn<DB> {
        let halo = WHITE.mix(0.7).stroke_width(4);
        for (k, (level, _)) in self.contours.iter().enumerate() {
            let line = CONTOUR.stroke_width(2);
            for (chain, closed) in chains(&march(g, *level)) {
                let mut pts: Vec<(f64, f64)> =
                    chain.iter().map(|&e| g.edge_point(e, *level)).collect();
                if closed {
                    pts.extend(pts.first().copied());
                }
                ctx.plotting_area()
                    .draw(&PathElement::new(pts.clone(), halo))?;
                match DASHES[k % DASHES.len()] {
                    None => ctx.plotting_area().draw(&PathElement::new(pts, line))?,
                    Some((on, off)) => ctx
                        .draw_series(DashedLineSeries::new(pts, on, off, line))
                        .map(|_| ())?,
                }
            }
        }
        Ok(())
    }

    /// Legend (contour labels, "no data" swatch) in the top-right plot corner.
    fn draw_legend<'a, DB: DrawingBackend + 'a>(
        &self,
        ctx: &mut ChartContext<'a, DB, Cartesian2d<PlotAxis, PlotAxis>>,
        pw: f64,
        ph: f64,
        has_no_data: bool,
    ) -> Drawn<DB> {
        let mut rows: Vec<(Option<usize>, String)> = self
            .contours
            .iter()
            .enumerate()
            .filter(|(_, (_, l))| !l.trim().is_empty())
            .map(|(k, (_, l))| (Some(k), fit(l, 0.45 * pw, FS_TICK)))
            .collect();
        if has_no_data {
            rows.push((None, "no data".to_string()));
        }
        rows.truncate(((ph - 24.0) / (FS_TICK * 1.6)).floor().max(0.0) as usize);
        if rows.is_empty() {
            return Ok(());
        }
        for (k, name) in rows {
            let anno = ctx.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            anno.label(name);
            match k {
                Some(k) => {
                    let style = CONTOUR.stroke_width(2);
                    match DASHES[k % DASHES.len()] {
                        None => anno.legend(move |at| EmptyElement::at(at) + sample_solid(style)),
                        Some(d) => {
                            anno.legend(move |at| EmptyElement::at(at) + sample_dashed(style, d))
                        }
                    };
                }
                None => {
                    anno.legend(|at| {
                        let swatch = [(0, -4), (24, 4)];
                        EmptyElement::at(at)
                            + Rectangle::new(swatch, NO_DATA.filled())
                            + Rectangle::new(swatch, RGBColor(0x99, 0x99, 0x99))
                    });
                }
            }
        }
        ctx.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .margin(6)
            .legend_area_size(32)
            .label_font(font(FS_TICK).color(&INK))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(0x99, 0x99, 0x99))
            .draw()
    }

    /// Colour bar: colour steps, contour level marks, ticks and label.
    fn draw_bar<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        ca: &Axis,
        lay: &Layout,
    ) -> Drawn<DB> {
        let mut bar = ChartBuilder::on(area)
            .right_y_label_area_size(lay.bar_area.round() as i32)
            .build_cartesian_2d(RangedCoordf64::from(0.0..1.0), PlotAxis::new(ca, &lay.ct))?;
        let c_fmt = |v: &f64| axis::label_of(ca, &lay.ct, *v);
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(clean(&self.colour_label))
            .axis_desc_style(font(FS_LABEL).color(&INK))
            .label_style(font(FS_TICK).color(&INK))
            .y_label_formatter(&c_fmt)
            .axis_style(FRAME)
            .set_all_tick_mark_size(TICK_LEN)
            .draw()?;
        let step = (ca.hi - ca.lo) / BAR_STEPS as f64;
        bar.draw_series((0..BAR_STEPS).map(|k| {
            let (t0, t1) = (ca.lo + k as f64 * step, ca.lo + (k + 1) as f64 * step);
            let colour = viridis((k as f64 + 0.5) / BAR_STEPS as f64);
            Rectangle::new([(0.0, ca.data(t0)), (1.0, ca.data(t1))], colour.filled())
        }))?;
        for (level, _) in &self.contours {
            if let Some(t) = axis::transform(ca.log, *level).filter(|t| (ca.lo..=ca.hi).contains(t))
            {
                let y = ca.data(t);
                bar.plotting_area().draw(&PathElement::new(
                    vec![(0.0, y), (1.0, y)],
                    CONTOUR.stroke_width(2),
                ))?;
            }
        }
        let frame = [(0.0, ca.data(ca.lo)), (1.0, ca.data(ca.hi))];
        bar.plotting_area()
            .draw(&Rectangle::new(frame, FRAME.stroke_width(1)))
    }
}

/// Cell rectangles, runs of equal colour in a row merged (colours are
/// quantised to 256 levels). Returns whether any cell got a colour.
fn draw_cells<DB: DrawingBackend>(
    ctx: &mut ChartContext<'_, DB, Cartesian2d<PlotAxis, PlotAxis>>,
    g: &Grid,
    ca: &Axis,
) -> Result<bool, DrawingAreaErrorKind<DB::ErrorType>> {
    let fill = |k: usize| -> Option<u8> {
        colour_t(ca, g.v[k])
            .map(|t| (t * 255.0).round() as u8)
            .filter(|_| !g.masked[k])
    };
    let mut any = false;
    let mut cells = Vec::new();
    for j in 0..g.ny {
        let (y0, y1) = (g.y0 + j as f64 * g.dy, g.y0 + (j + 1) as f64 * g.dy);
        let mut i = 0;
        while i < g.nx {
            let at = j * g.nx + i;
            let (f, masked) = (fill(at), g.masked[at]);
            let mut k = i + 1;
            while k < g.nx && fill(j * g.nx + k) == f && g.masked[j * g.nx + k] == masked {
                k += 1;
            }
            let colour = match f {
                Some(q) => viridis(f64::from(q) / 255.0),
                None if masked => MASKED,
                None => NO_DATA,
            };
            any |= f.is_some();
            let (x0, x1) = (g.x0 + i as f64 * g.dx, g.x0 + k as f64 * g.dx);
            cells.push(Rectangle::new([(x0, y0), (x1, y1)], colour.filled()));
            i = k;
        }
    }
    ctx.draw_series(cells)?;
    Ok(any)
}
