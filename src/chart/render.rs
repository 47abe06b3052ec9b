//! Layout and drawing of one chart panel with plotters.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::{self, Axis, PlotAxis, Ticks, text_width};
use super::data::{self, Trace};
use super::legend::{self, Legend, Placement};
use super::style::{
    DASH, FRAME, FS_LABEL, FS_TICK, FS_TITLE, INK, MARKER_R, TITLE_LINE_H, bold, clean, font,
    marker_offsets, title_lines,
};
use super::{Chart, LegendPosition};

/// Result of a plotters drawing call on backend `DB`.
pub(crate) type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Tick mark length, px.
pub(crate) const TICK_LEN: i32 = 5;
/// Space kept right of the plot frame (for the last x tick label), px.
const RIGHT: f64 = 16.0;

/// Panel geometry: title band, label areas and plot size, px.
struct Layout {
    title_h: f64,
    /// The title, wrapped to the panel's width (at most [`TITLE_LINES`] lines).
    title_lines: Vec<String>,
    x_area: f64,
    y_area: f64,
    plot_w: f64,
    xt: Ticks,
    yt: Ticks,
    legend: Option<(Legend, Placement)>,
}

/// Vertical and horizontal layout of `chart` in a `w` x `h` panel, with the
/// legend placed (avoiding the data when automatic).
fn layout(chart: &Chart, traces: &[Trace], xa: &Axis, ya: &Axis, w: f64, h: f64) -> Layout {
    let has = |s: &str| !s.trim().is_empty();
    let title_lines = title_lines(&chart.title, w - 16.0);
    let title_h = match title_lines.len() {
        0 => 12.0,
        n => 16.0 + FS_TITLE + (n - 1) as f64 * TITLE_LINE_H,
    };
    let x_area = f64::from(TICK_LEN)
        + 6.0
        + FS_TICK
        + if has(&chart.x_label) {
            8.0 + FS_LABEL
        } else {
            0.0
        }
        + 6.0;
    let plot_h = (h - title_h - x_area).max(10.0);
    let yt = axis::choose_ticks(ya, plot_h, false, FS_TICK);
    let y_labels = yt
        .major
        .iter()
        .map(|t| text_width(&t.1, FS_TICK))
        .fold(0.0, f64::max);
    let y_area =
        8.0 + if has(&chart.y_label) {
            FS_LABEL + 10.0
        } else {
            0.0
        } + y_labels
            + 6.0
            + f64::from(TICK_LEN);
    let width_for = |reserve: f64| (w - y_area - RIGHT - reserve).max(10.0);
    let max_text = (0.35 * w).max(80.0);
    let mut legend = match chart.legend {
        LegendPosition::Hidden => None,
        _ => Legend::new(traces, plot_h, max_text),
    };
    let mut placement = match chart.legend {
        LegendPosition::Outside => Placement::Outside,
        LegendPosition::TopLeft => Placement::Corner(SeriesLabelPosition::UpperLeft),
        LegendPosition::BottomRight => Placement::Corner(SeriesLabelPosition::LowerRight),
        LegendPosition::BottomLeft => Placement::Corner(SeriesLabelPosition::LowerLeft),
        _ => Placement::Corner(SeriesLabelPosition::UpperRight),
    };
    if let (Some(l), LegendPosition::Auto) = (&legend, chart.legend) {
        let (clear, least) = l.corners(traces, xa, ya, width_for(0.0), plot_h);
        let room = w - y_area - RIGHT - 16.0 - 0.45 * w - legend::SAMPLE_AREA;
        placement = match clear {
            Some(c) => Placement::Corner(c),
            None if room < 60.0 => Placement::Corner(least),
            None => {
                legend = Legend::new(traces, plot_h, room.min(max_text));
                Placement::Outside
            }
        };
    }
    let reserve = match (&legend, &placement) {
        (Some(l), Placement::Outside) => l.w + 16.0,
        _ => 0.0,
    };
    let plot_w = width_for(reserve);
    Layout {
        title_lines,
        title_h,
        x_area,
        y_area,
        plot_w,
        xt: axis::choose_ticks(xa, plot_w, true, FS_TICK),
        yt,
        legend: legend.map(|l| (l, placement)),
    }
}

/// Draws `chart` on `area` (one panel).
pub(crate) fn draw_chart<DB: DrawingBackend>(
    chart: &Chart,
    area: &DrawingArea<DB, Shift>,
) -> Drawn<DB> {
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (f64::from(w), f64::from(h));
    let (traces, xlog, ylog) = data::prepare(chart);
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for t in &traces {
        for &(x, y) in t.runs.iter().flatten() {
            xs.push(x);
            ys.push(y);
        }
        for &(_, lo, _, hi) in &t.errs {
            ys.extend(lo);
            ys.push(hi);
        }
    }
    let xa = axis::resolve_axis(&xs, xlog, chart.x_range);
    let ya = axis::resolve_axis(&ys, ylog, chart.y_range);
    let lay = layout(chart, &traces, &xa, &ya, w, h);

    let (title_area, body) = area.split_vertically(lay.title_h as i32);
    for (k, line) in lay.title_lines.iter().enumerate() {
        let style = bold(FS_TITLE)
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let y = 10.0 + FS_TITLE / 2.0 + k as f64 * TITLE_LINE_H;
        title_area.draw(&Text::new(
            line.as_str(),
            ((w / 2.0) as i32, y as i32),
            style,
        ))?;
    }
    let main_w = lay.y_area + lay.plot_w + RIGHT;
    let (main, side) = body.split_horizontally(main_w as i32);
    let x_axis = PlotAxis::new(&xa, &lay.xt);
    let y_axis = PlotAxis::new(&ya, &lay.yt);
    let mut ctx = ChartBuilder::on(&main)
        .margin_right(RIGHT as i32)
        .x_label_area_size(lay.x_area as i32)
        .y_label_area_size(lay.y_area as i32)
        .build_cartesian_2d(x_axis, y_axis)?;
    let x_fmt = |v: &f64| axis::label_of(&xa, &lay.xt, *v);
    let y_fmt = |v: &f64| axis::label_of(&ya, &lay.yt, *v);
    ctx.configure_mesh()
        .x_desc(clean(&chart.x_label))
        .y_desc(clean(&chart.y_label))
        .axis_desc_style(font(FS_LABEL).color(&INK))
        .label_style(font(FS_TICK).color(&INK))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .x_labels(lay.xt.major.len().max(2))
        .y_labels(lay.yt.major.len().max(2))
        .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
        .light_line_style(RGBColor(0xf0, 0xf0, 0xf0))
        .axis_style(FRAME)
        .set_all_tick_mark_size(TICK_LEN)
        .draw()?;
    let corner = |a: &Axis, f: f64| a.data(a.lo + f * (a.hi - a.lo));
    ctx.plotting_area().draw(&Rectangle::new(
        [
            (corner(&xa, 0.0), corner(&ya, 0.0)),
            (corner(&xa, 1.0), corner(&ya, 1.0)),
        ],
        FRAME.stroke_width(1),
    ))?;
    draw_traces(&mut ctx, &traces, &xa, &ya)?;
    if xs.is_empty() {
        let style = font(FS_LABEL)
            .color(&INK.mix(0.6))
            .pos(Pos::new(HPos::Center, VPos::Center));
        let mid = (corner(&xa, 0.5), corner(&ya, 0.5));
        ctx.plotting_area()
            .draw(&Text::new("no data", mid, style))?;
    }
    match lay.legend {
        Some((l, Placement::Corner(pos))) => l.draw(&mut ctx, &traces, pos)?,
        Some((l, Placement::Outside)) => {
            let mut side_ctx = ChartBuilder::on(&side).margin_left(8).build_cartesian_2d(
                RangedCoordf64::from(0.0..1.0),
                RangedCoordf64::from(0.0..1.0),
            )?;
            l.draw(&mut side_ctx, &traces, SeriesLabelPosition::UpperLeft)?;
        }
        None => {}
    }
    Ok(())
}

/// Reference lines first, then the series: lines (clipped to the visible
/// range), error bars and markers.
fn draw_traces<DB: DrawingBackend>(
    ctx: &mut ChartContext<'_, DB, Cartesian2d<PlotAxis, PlotAxis>>,
    traces: &[Trace],
    xa: &Axis,
    ya: &Axis,
) -> Drawn<DB> {
    let to_data = |(x, y): (f64, f64)| (xa.data(x), ya.data(y));
    let ordered = traces
        .iter()
        .filter(|t| t.reference)
        .chain(traces.iter().filter(|t| !t.reference));
    for t in ordered {
        let style = ShapeStyle::from(t.color).stroke_width(if t.reference { 1 } else { 2 });
        if t.line {
            for run in &t.runs {
                for poly in data::clip_run(xa, ya, run) {
                    let pts = poly.into_iter().map(to_data);
                    if t.dashed {
                        ctx.draw_series(DashedLineSeries::new(pts, DASH.0, DASH.1, style))?;
                    } else {
                        ctx.draw_series(LineSeries::new(pts, style))?;
                    }
                }
            }
        }
        let bars = t
            .errs
            .iter()
            .filter(|e| (-1e-9..=1.0 + 1e-9).contains(&xa.frac(e.0)));
        let bars: Vec<_> = bars
            .filter_map(|&(x, lo, y, hi)| {
                let lo = lo.unwrap_or(ya.lo).clamp(ya.lo, ya.hi);
                let (y, hi) = (y.clamp(ya.lo, ya.hi), hi.clamp(ya.lo, ya.hi));
                let bar_style = ShapeStyle::from(t.color).stroke_width(1);
                let (x, lo, y, hi) = (xa.data(x), ya.data(lo), ya.data(y), ya.data(hi));
                (hi > lo).then(|| ErrorBar::new_vertical(x, lo, y, hi, bar_style, 6))
            })
            .collect();
        ctx.draw_series(bars)?;
        let mut marks = Vec::new();
        for run in &t.runs {
            let shown = run
                .iter()
                .filter(|&&p| data::visible(xa, ya, p))
                .map(|&p| to_data(p));
            match t.marker {
                Some(_) => marks.extend(shown),
                None if run.len() == 1 && t.line => marks.extend(shown),
                None => {}
            }
        }
        let fill = t.color.filled();
        match t.marker {
            Some(shape) if shape % 5 != 0 => {
                let outline = marker_offsets(shape);
                let poly = |p| EmptyElement::at(p) + Polygon::new(outline.clone(), fill);
                ctx.draw_series(marks.into_iter().map(poly))?;
            }
            Some(_) => {
                ctx.draw_series(marks.into_iter().map(|p| Circle::new(p, MARKER_R, fill)))?;
            }
            None => {
                ctx.draw_series(marks.into_iter().map(|p| Circle::new(p, 3, fill)))?;
            }
        }
    }
    Ok(())
}
