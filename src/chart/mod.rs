//! SVG charts drawn with the `plotters` crate (SVG backend, no fonts needed:
//! text is written as `<text>` elements for the viewer to render).
//!
//! Used by the `magsep chart ...` commands to draw accuracy-vs-cost and
//! physics curves. A [`Chart`] is one plot panel (title, axis labels, linear or
//! logarithmic axes, data [`Series`] and reference [`Line`]s, a legend); a
//! [`Figure`] arranges several charts in a grid. Both render to a standalone
//! SVG document with `to_svg`, which [`write_svg`] saves to disk. Log axes
//! use plotters' `.log_scale()`, error bars its `ErrorBar`, legends its
//! series labels; heatmaps ([`Heatmap`]) are drawn as plotters rectangles.
//!
//! Rendering never panics: non-finite points are skipped (breaking the line),
//! non-positive values are skipped on logarithmic axes (an axis falls back to
//! linear when no positive value is left), and empty or constant data get a
//! sensible default range. Output is deterministic: the same input always
//! produces the same bytes. Pixel positions are whole pixels (plotters'
//! backend coordinates are integers).
//!
//! ```
//! use magsep::chart::{Chart, Figure, Line, Series, Style};
//!
//! let chart = Chart::new("Error vs cost")
//!     .x_label("cost [s]")
//!     .y_label("relative error [-]")
//!     .x_log(true)
//!     .y_log(true)
//!     .series(
//!         Series::new("Euler & RK4", vec![(1.0, 1e-1), (10.0, 1e-2), (100.0, 1e-3)])
//!             .y_err(vec![2e-2, 2e-3, 2e-4]),
//!     )
//!     .series(Series::new("midpoint", vec![(2.0, 5e-2), (20.0, 5e-4)]).style(Style::Markers))
//!     .line(Line::new("O(1/N)", vec![(1.0, 0.2), (100.0, 0.002)]).dashed(true));
//! let svg = chart.to_svg(640.0, 420.0);
//! assert!(svg.starts_with("<svg"));
//! assert!(svg.contains("Euler &amp; RK4"));
//!
//! let figure = Figure::new("Convergence", 2).panel(chart.clone()).panel(chart);
//! assert!(figure.to_svg(480.0, 360.0).ends_with("</svg>\n"));
//! ```

#![warn(missing_docs)]

mod axis;
mod data;
mod heatmap;
mod legend;
mod render;
mod style;

#[cfg(test)]
mod tests;

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, IntoDrawingArea, SVGBackend, WHITE};
use plotters::style::Color;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub use heatmap::{ColourScale, Heatmap};

/// Clamps a requested image size (px) to something drawable.
fn sanitize_size(v: f64, default: f64) -> u32 {
    let v = if v.is_finite() && v > 0.0 {
        v.clamp(60.0, 20_000.0)
    } else {
        default
    };
    v.round() as u32
}

/// Runs `draw` on a white `w` x `h` px SVG canvas and returns the document.
/// A drawing error leaves the drawing incomplete but never panics.
fn render_svg(w: u32, h: u32, draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>)) -> String {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (w, h)).into_drawing_area();
        let _ = root.fill(&WHITE.to_rgba());
        draw(&root);
        let _ = root.present();
    }
    out
}

/// Default colour palette (Okabe-Ito, colour-blind friendly), in the order
/// series are coloured. Yellow is last because it is hard to see on white.
pub const PALETTE: [&str; 8] = [
    "#0072B2", // blue
    "#D55E00", // vermillion
    "#009E73", // bluish green
    "#CC79A7", // reddish purple
    "#E69F00", // orange
    "#56B4E9", // sky blue
    "#000000", // black
    "#F0E442", // yellow
];

/// How a [`Series`] is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Style {
    /// Solid line through the points.
    Line,
    /// Markers only (shape cycles with the series index).
    Markers,
    /// Solid line with markers (default).
    #[default]
    LineMarkers,
    /// Dashed line without markers.
    Dashed,
}

impl Style {
    fn has_line(self) -> bool {
        !matches!(self, Style::Markers)
    }

    fn has_markers(self) -> bool {
        matches!(self, Style::Markers | Style::LineMarkers)
    }
}

/// Where the legend is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LegendPosition {
    /// First inside corner (top-right, top-left, bottom-right, bottom-left)
    /// that covers no data; outside to the right if every corner does.
    #[default]
    Auto,
    /// Inside the plot area, top-right corner.
    TopRight,
    /// Inside the plot area, top-left corner.
    TopLeft,
    /// Inside the plot area, bottom-right corner.
    BottomRight,
    /// Inside the plot area, bottom-left corner.
    BottomLeft,
    /// Outside the plot area, to the right (the plot shrinks to make room).
    Outside,
    /// No legend.
    Hidden,
}

/// One data series: named points with a drawing style and optional
/// symmetric y error bars.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Legend entry; an empty name keeps the series out of the legend.
    pub name: String,
    /// Data points `(x, y)`, drawn in order. Non-finite points are skipped
    /// and break the line.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// Any SVG colour (`"#336699"`, `"red"`); `None` picks from [`PALETTE`].
    pub color: Option<String>,
    /// Symmetric error `e` per point, drawn from `y - e` to `y + e`
    /// (matched by index; missing, negative or non-finite entries draw no bar).
    pub y_err: Option<Vec<f64>>,
}

impl Series {
    /// A series drawn as [`Style::LineMarkers`] in the next palette colour.
    #[must_use]
    pub fn new(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points: points.into_iter().collect(),
            ..Series::default()
        }
    }

    /// Sets the drawing style.
    #[must_use]
    pub fn style(mut self, style: Style) -> Self {
        self.style = style;
        self
    }

    /// Sets an explicit SVG colour.
    #[must_use]
    pub fn color(mut self, color: impl Into<String>) -> Self {
        self.color = Some(color.into());
        self
    }

    /// Sets symmetric y error bars (one entry per point).
    #[must_use]
    pub fn y_err(mut self, errors: impl IntoIterator<Item = f64>) -> Self {
        self.y_err = Some(errors.into_iter().collect());
        self
    }
}

/// A reference line (theory curve, target value, scaling law), drawn in a
/// neutral colour underneath the data series.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Line {
    /// Legend entry; an empty name keeps the line out of the legend.
    pub name: String,
    /// Polyline vertices `(x, y)`; they also take part in auto-ranging.
    pub points: Vec<(f64, f64)>,
    /// Dashed instead of solid.
    pub dashed: bool,
    /// Any SVG colour; `None` means dark grey.
    pub color: Option<String>,
}

impl Line {
    /// A solid reference polyline.
    #[must_use]
    pub fn new(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Line {
            name: name.into(),
            points: points.into_iter().collect(),
            ..Line::default()
        }
    }

    /// A curve `y = f(x)` sampled at `samples` points (at least 2) between
    /// `x0` and `x1`, geometrically spaced when `log_spacing` is set and both
    /// ends are positive, evenly spaced otherwise.
    #[must_use]
    pub fn from_fn(
        name: impl Into<String>,
        x0: f64,
        x1: f64,
        samples: usize,
        log_spacing: bool,
        f: impl Fn(f64) -> f64,
    ) -> Self {
        let n = samples.clamp(2, 100_000);
        let geometric = log_spacing && x0 > 0.0 && x1 > 0.0;
        let points = (0..n).map(|i| {
            let t = i as f64 / (n - 1) as f64;
            let x = if geometric {
                (x0.ln() + t * (x1.ln() - x0.ln())).exp()
            } else {
                x0 + t * (x1 - x0)
            };
            (x, f(x))
        });
        Line::new(name, points)
    }

    /// Sets whether the line is dashed.
    #[must_use]
    pub fn dashed(mut self, dashed: bool) -> Self {
        self.dashed = dashed;
        self
    }

    /// Sets an explicit SVG colour.
    #[must_use]
    pub fn color(mut self, color: impl Into<String>) -> Self {
        self.color = Some(color.into());
        self
    }
}

/// One plot panel. Build with [`Chart::new`] and the chained setters, then
/// render with [`Chart::to_svg`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chart {
    /// Title above the plot (may be empty).
    pub title: String,
    /// X axis label, units included in the text (e.g. `"time [s]"`).
    pub x_label: String,
    /// Y axis label, units included in the text.
    pub y_label: String,
    /// Logarithmic x axis (falls back to linear if no positive x is left).
    pub x_log: bool,
    /// Logarithmic y axis (falls back to linear if no positive y is left).
    pub y_log: bool,
    /// Explicit x range `(min, max)`; a non-finite bound (or, on a log axis,
    /// a non-positive one) is chosen automatically.
    pub x_range: Option<(f64, f64)>,
    /// Explicit y range `(min, max)`, same rules as `x_range`.
    pub y_range: Option<(f64, f64)>,
    /// Data series, drawn in order and coloured from [`PALETTE`].
    pub series: Vec<Series>,
    /// Reference lines, drawn beneath the series.
    pub lines: Vec<Line>,
    /// Legend placement.
    pub legend: LegendPosition,
}

impl Chart {
    /// An empty chart with the given title and linear axes.
    #[must_use]
    pub fn new(title: impl Into<String>) -> Self {
        Chart {
            title: title.into(),
            ..Chart::default()
        }
    }

    /// Sets the x axis label (include units).
    #[must_use]
    pub fn x_label(mut self, label: impl Into<String>) -> Self {
        self.x_label = label.into();
        self
    }

    /// Sets the y axis label (include units).
    #[must_use]
    pub fn y_label(mut self, label: impl Into<String>) -> Self {
        self.y_label = label.into();
        self
    }

    /// Makes the x axis logarithmic (or linear).
    #[must_use]
    pub fn x_log(mut self, log: bool) -> Self {
        self.x_log = log;
        self
    }

    /// Makes the y axis logarithmic (or linear).
    #[must_use]
    pub fn y_log(mut self, log: bool) -> Self {
        self.y_log = log;
        self
    }

    /// Fixes the x range; pass `f64::NAN` for a bound to keep it automatic.
    #[must_use]
    pub fn x_range(mut self, min: f64, max: f64) -> Self {
        self.x_range = Some((min, max));
        self
    }

    /// Fixes the y range; pass `f64::NAN` for a bound to keep it automatic.
    #[must_use]
    pub fn y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }

    /// Appends a data series.
    #[must_use]
    pub fn series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Appends a reference line.
    #[must_use]
    pub fn line(mut self, line: Line) -> Self {
        self.lines.push(line);
        self
    }

    /// Sets the legend placement.
    #[must_use]
    pub fn legend(mut self, position: LegendPosition) -> Self {
        self.legend = position;
        self
    }

    /// Renders the chart as a standalone SVG document of `width` x `height`
    /// pixels (non-finite or tiny sizes are clamped to something drawable).
    #[must_use]
    pub fn to_svg(&self, width: f64, height: f64) -> String {
        let w = sanitize_size(width, 640.0);
        let h = sanitize_size(height, 420.0);
        render_svg(w, h, |root| {
            let _ = render::draw_chart(self, root);
        })
    }
}

/// Several [`Chart`] panels arranged in a grid, filled row by row, under an
/// optional overall title.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figure {
    /// Overall title (may be empty).
    pub title: String,
    /// Panels, filled row by row.
    pub panels: Vec<Chart>,
    /// Panels per row (0 is treated as 1).
    pub columns: usize,
}

impl Figure {
    /// An empty figure with `columns` panels per row.
    #[must_use]
    pub fn new(title: impl Into<String>, columns: usize) -> Self {
        Figure {
            title: title.into(),
            panels: Vec::new(),
            columns,
        }
    }

    /// Appends a panel.
    #[must_use]
    pub fn panel(mut self, chart: Chart) -> Self {
        self.panels.push(chart);
        self
    }

    /// Renders all panels, each `panel_width` x `panel_height` pixels, as one
    /// SVG document.
    #[must_use]
    pub fn to_svg(&self, panel_width: f64, panel_height: f64) -> String {
        let pw = sanitize_size(panel_width, 480.0);
        let ph = sanitize_size(panel_height, 360.0);
        let n = self.panels.len();
        let cols = self.columns.clamp(1, n.max(1));
        let rows = n.div_ceil(cols).max(1);
        let w = pw.saturating_mul(cols as u32);
        let lines = self.title_lines(f64::from(w));
        let title_h = match lines.len() {
            0 => 0,
            n => 34 + ((n - 1) as f64 * 1.25 * style::FS_FIGURE_TITLE) as u32,
        };
        let h = title_h + ph.saturating_mul(rows as u32);
        render_svg(w, h, |root| {
            let _ = self.draw(root, title_h, (rows, cols));
        })
    }

    /// The figure title wrapped to `w` px (at most three lines; none when empty).
    fn title_lines(&self, w: f64) -> Vec<String> {
        if self.title.trim().is_empty() {
            return Vec::new();
        }
        style::wrap(&self.title, w - 20.0, style::FS_FIGURE_TITLE, 3)
    }

    /// Draws the title into the top `title_h` px and the panels in a
    /// `rows` x `cols` grid below.
    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        title_h: u32,
        grid: (usize, usize),
    ) -> render::Drawn<DB> {
        let (title_area, panels) = root.split_vertically(title_h);
        if title_h > 0 {
            let w = f64::from(root.dim_in_pixel().0);
            let anchor = Pos::new(HPos::Center, VPos::Center);
            for (k, line) in self.title_lines(w).into_iter().enumerate() {
                let font = style::bold(style::FS_FIGURE_TITLE)
                    .color(&style::INK)
                    .pos(anchor);
                let y = 17.0 + k as f64 * 1.25 * style::FS_FIGURE_TITLE;
                let at = ((w / 2.0) as i32, y as i32);
                title_area.draw(&plotters::element::Text::new(line, at, font))?;
            }
        }
        for (panel, area) in self.panels.iter().zip(panels.split_evenly(grid)) {
            render::draw_chart(panel, &area)?;
        }
        Ok(())
    }
}

/// Writes `svg` to `path`, creating missing parent directories.
///
/// # Errors
///
/// Any I/O error from creating the directories or writing the file.
pub fn write_svg(path: &Path, svg: &str) -> std::io::Result<()> {
    if let Some(parent) = path.parent()
        && !parent.as_os_str().is_empty()
    {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(path, svg)
}
