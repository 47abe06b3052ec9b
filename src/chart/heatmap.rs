//! Heatmaps (colour maps) of gridded data, with contour lines.
//!
//! A [`Heatmap`] draws a grid of cell values in plotters' viridis colour map with
//! a colour bar, optional iso-lines ([`Heatmap::contour`], by marching
//! squares on the cell-centre grid; plotters has no contouring, so that
//! kernel stays here) and an optional mask for cells without
//! meaningful data (e.g. the inside of a magnet). Like [`Chart`](super::Chart)
//! it never panics and renders deterministically.

use std::collections::HashMap;
use std::fmt;

use plotters::style::RGBColor;
use plotters::style::colors::colormaps::ViridisRGB;

use super::axis::{self as ticks, Axis};

#[path = "heatmap_draw.rs"]
mod draw;

/// Viridis colour (plotters' colour map) at `t` in `[0, 1]` (clamped; NaN
/// gives the low end).
fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    ViridisRGB::get_color(t)
}

/// How cell values map to colours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ColourScale {
    /// Colour linear in the value (default).
    #[default]
    Linear,
    /// Colour linear in `log10(value)`; non-positive values are drawn as
    /// "no data" (light grey).
    Log,
}

/// A colour map of gridded values with colour bar and contour lines. Build
/// with [`Heatmap::new`] and the chained setters, render with
/// [`Heatmap::to_svg`].
///
/// ```
/// use magsep::chart::{ColourScale, Heatmap};
///
/// let n = 40;
/// let values: Vec<Vec<f64>> = (0..n)
///     .map(|j| (0..n).map(|i| (i * i + j * j) as f64).collect())
///     .collect();
/// let svg = Heatmap::new("|B| map", (0.0, 1.0), (0.0, 1.0), values)
///     .x_label("x [m]")
///     .y_label("y [m]")
///     .colour_label("|B| [T]")
///     .scale(ColourScale::Log)
///     .contour(400.0, "capture limit")
///     .mask(|x, y| x * x + y * y < 0.01)
///     .to_svg(640.0, 480.0);
/// assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
/// ```
pub struct Heatmap {
    title: String,
    x_label: String,
    y_label: String,
    colour_label: String,
    x_range: (f64, f64),
    y_range: (f64, f64),
    values: Vec<Vec<f64>>,
    scale: ColourScale,
    range: Option<(f64, f64)>,
    contours: Vec<(f64, String)>,
    mask: Option<Box<dyn Fn(f64, f64) -> bool>>,
}

impl fmt::Debug for Heatmap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Heatmap")
            .field("title", &self.title)
            .field("x_range", &self.x_range)
            .field("y_range", &self.y_range)
            .field("rows", &self.values.len())
            .field("scale", &self.scale)
            .field("range", &self.range)
            .field("contours", &self.contours)
            .field("mask", &self.mask.is_some())
            .finish_non_exhaustive()
    }
}

impl Heatmap {
    /// A heatmap of `values` over `x_range` x `y_range`.
    ///
    /// `values[j][i]` is the value at x = x_min + (i + 0.5) * dx,
    /// y = y_min + (j + 0.5) * dy (row j = y index, j = 0 at the bottom),
    /// with `dx = (x_max - x_min) / nx`, `nx` the longest row length and
    /// `dy = (y_max - y_min) / ny`, `ny` the number of rows. Short rows are
    /// padded with "no data"; NaN, infinite and (linear scale) beyond
    /// ±1e100 values are "no data" too. A non-finite or empty range is
    /// replaced by the cell index range `0..n`.
    #[must_use]
    pub fn new(
        title: impl Into<String>,
        x_range: (f64, f64),
        y_range: (f64, f64),
        values: Vec<Vec<f64>>,
    ) -> Self {
        Heatmap {
            title: title.into(),
            x_label: String::new(),
            y_label: String::new(),
            colour_label: String::new(),
            x_range,
            y_range,
            values,
            scale: ColourScale::Linear,
            range: None,
            contours: Vec::new(),
            mask: None,
        }
    }

    /// Sets the x axis label (include units).
    #[must_use]
    pub fn x_label(mut self, s: impl Into<String>) -> Self {
        self.x_label = s.into();
        self
    }

    /// Sets the y axis label (include units).
    #[must_use]
    pub fn y_label(mut self, s: impl Into<String>) -> Self {
        self.y_label = s.into();
        self
    }

    /// Sets the colour bar label, e.g. `"|B| [T]"`.
    #[must_use]
    pub fn colour_label(mut self, s: impl Into<String>) -> Self {
        self.colour_label = s.into();
        self
    }

    /// Sets the colour scale (linear by default).
    #[must_use]
    pub fn scale(mut self, s: ColourScale) -> Self {
        self.scale = s;
        self
    }

    /// Fixes the colour range in data units; values outside get the end
    /// colours. A non-finite bound (or, on the log scale, a non-positive one)
    /// stays automatic: the extent of the finite (log: positive), unmasked
    /// values.
    #[must_use]
    pub fn range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }

    /// Adds iso-lines at `level` (data units), drawn as dark lines (dash
    /// pattern cycling with each call) and listed in the legend as `label`
    /// (an empty label keeps it out of the legend).
    #[must_use]
    pub fn contour(mut self, level: f64, label: impl Into<String>) -> Self {
        self.contours.push((level, label.into()));
        self
    }

    /// Draws cells whose centre `(x, y)` satisfies `f` in solid dark grey.
    /// Masked cells take no part in the colour range or the contours.
    #[must_use]
    pub fn mask(mut self, f: impl Fn(f64, f64) -> bool + 'static) -> Self {
        self.mask = Some(Box::new(f));
        self
    }

    /// The iso-line segments at `level` in data coordinates: marching
    /// squares over the cell centres with linear interpolation along the
    /// square edges (saddles resolved by the mean of the four corners).
    /// Squares touching a masked or "no data" cell produce nothing.
    #[must_use]
    pub fn contour_segments(&self, level: f64) -> Vec<((f64, f64), (f64, f64))> {
        let g = self.grid();
        march(&g, level)
            .into_iter()
            .map(|(a, b)| (g.edge_point(a, level), g.edge_point(b, level)))
            .collect()
    }

    /// Renders the heatmap as a standalone SVG document of `width` x
    /// `height` pixels (non-finite or tiny sizes are clamped). The plot area
    /// keeps the aspect ratio of the data ranges (clamped to 1:20).
    #[must_use]
    pub fn to_svg(&self, width: f64, height: f64) -> String {
        let w = super::sanitize_size(width, 640.0);
        let h = super::sanitize_size(height, 480.0);
        super::render_svg(w, h, |root| {
            let _ = draw::draw(self, root);
        })
    }

    /// Cell geometry and values (missing, non-finite and masked cells NaN).
    fn grid(&self) -> Grid {
        let ny = self.values.len();
        let nx = self.values.iter().map(Vec::len).max().unwrap_or(0);
        let (x0, x1) = sane_range(self.x_range, nx);
        let (y0, y1) = sane_range(self.y_range, ny);
        let (dx, dy) = ((x1 - x0) / nx.max(1) as f64, (y1 - y0) / ny.max(1) as f64);
        let mut v = Vec::with_capacity(nx * ny);
        let mut masked = Vec::with_capacity(nx * ny);
        for (j, row) in self.values.iter().enumerate() {
            let cy = y0 + (j as f64 + 0.5) * dy;
            for i in 0..nx {
                let cx = x0 + (i as f64 + 0.5) * dx;
                let m = self.mask.as_ref().is_some_and(|f| f(cx, cy));
                let val = row.get(i).copied().filter(|v| v.is_finite() && !m);
                v.push(val.unwrap_or(f64::NAN));
                masked.push(m);
            }
        }
        let xa = Axis {
            log: false,
            lo: x0.min(x1),
            hi: x0.max(x1),
        };
        let ya = Axis {
            log: false,
            lo: y0.min(y1),
            hi: y0.max(y1),
        };
        Grid {
            nx,
            ny,
            x0,
            dx,
            y0,
            dy,
            v,
            masked,
            xa,
            ya,
        }
    }

    /// Colour range in transformed units (`log10` for [`ColourScale::Log`]).
    fn colour_axis(&self, g: &Grid) -> Axis {
        let log = self.scale == ColourScale::Log;
        let mut it = g.v.iter().filter_map(|&v| ticks::transform(log, v));
        let auto = it
            .next()
            .map(|f| it.fold((f, f), |(a, b), t| (a.min(t), b.max(t))));
        let (mut lo, mut hi) = auto.unwrap_or((0.0, 1.0));
        if let Some((a, b)) = self.range {
            let (a, b) = (ticks::transform(log, a), ticks::transform(log, b));
            match (a, b) {
                (Some(a), Some(b)) => (lo, hi) = (a.min(b), a.max(b)),
                (Some(a), None) => lo = a,
                (None, Some(b)) => hi = b,
                (None, None) => {}
            }
        }
        if !(hi - lo > 1e-12 * lo.abs().max(hi.abs()) && hi - lo > 1e-290) {
            let c = (lo + hi) / 2.0;
            let d = if log || c == 0.0 { 0.5 } else { 0.1 * c.abs() };
            (lo, hi) = (c - d, c + d);
        }
        Axis { log, lo, hi }
    }
}

/// `(a, b)` if usable as an axis range, else the cell index range `0..n`.
fn sane_range((a, b): (f64, f64), n: usize) -> (f64, f64) {
    let ok = |v: f64| v.is_finite() && v.abs() <= ticks::MAX_LINEAR;
    if ok(a) && ok(b) && (b - a).abs() > 1e-12 * a.abs().max(b.abs()) && (b - a).abs() > 1e-290 {
        (a, b)
    } else {
        (0.0, n.max(1) as f64)
    }
}

/// Resolved cell grid; `v` is row-major (`j * nx + i`).
struct Grid {
    nx: usize,
    ny: usize,
    x0: f64,
    dx: f64,
    y0: f64,
    dy: f64,
    v: Vec<f64>,
    masked: Vec<bool>,
    xa: Axis,
    ya: Axis,
}

/// An edge between two neighbouring cell centres: `(vertical, i, j)` joins
/// `(i, j)` to `(i + 1, j)` (horizontal) or to `(i, j + 1)` (vertical).
type Edge = (bool, usize, usize);

impl Grid {
    fn at(&self, i: usize, j: usize) -> f64 {
        self.v[j * self.nx + i]
    }

    fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.x0 + (i as f64 + 0.5) * self.dx,
            self.y0 + (j as f64 + 0.5) * self.dy,
        )
    }

    /// Where the field crosses `level` on edge `e` (linear interpolation,
    /// always from the lower-index end so that shared edges agree exactly).
    fn edge_point(&self, (vertical, i, j): Edge, level: f64) -> (f64, f64) {
        let (i1, j1) = if vertical { (i, j + 1) } else { (i + 1, j) };
        let (a, b) = (self.at(i, j), self.at(i1, j1));
        let t = ((level - a) / (b - a)).clamp(0.0, 1.0);
        let t = if t.is_finite() { t } else { 0.5 };
        let ((xa, ya), (xb, yb)) = (self.centre(i, j), self.centre(i1, j1));
        (xa + t * (xb - xa), ya + t * (yb - ya))
    }
}

/// Marching squares: the contour segments at `level` as pairs of edges.
fn march(g: &Grid, level: f64) -> Vec<(Edge, Edge)> {
    let mut segs = Vec::new();
    if !level.is_finite() {
        return segs;
    }
    for j in 0..g.ny.saturating_sub(1) {
        for i in 0..g.nx.saturating_sub(1) {
            let c = [
                g.at(i, j),
                g.at(i + 1, j),
                g.at(i + 1, j + 1),
                g.at(i, j + 1),
            ];
            if c.iter().any(|v| v.is_nan()) {
                continue;
            }
            let case = c
                .iter()
                .enumerate()
                .fold(0, |acc, (k, &v)| acc | (usize::from(v > level) << k));
            // Sides: 0 bottom, 1 right, 2 top, 3 left.
            let side = |s: usize| -> Edge {
                match s {
                    0 => (false, i, j),
                    1 => (true, i + 1, j),
                    2 => (false, i, j + 1),
                    _ => (true, i, j),
                }
            };
            let centre_above = c.iter().sum::<f64>() / 4.0 > level;
            let pairs: &[(usize, usize)] = match case {
                1 | 14 => &[(3, 0)],
                2 | 13 => &[(0, 1)],
                3 | 12 => &[(3, 1)],
                4 | 11 => &[(1, 2)],
                6 | 9 => &[(0, 2)],
                7 | 8 => &[(2, 3)],
                5 if centre_above => &[(0, 1), (2, 3)],
                10 if !centre_above => &[(0, 1), (2, 3)],
                5 | 10 => &[(3, 0), (1, 2)],
                _ => &[],
            };
            segs.extend(pairs.iter().map(|&(a, b)| (side(a), side(b))));
        }
    }
    segs
}

/// Joins segments sharing an edge into polylines; `true` marks closed loops.
fn chains(segs: &[(Edge, Edge)]) -> Vec<(Vec<Edge>, bool)> {
    let mut at: HashMap<Edge, Vec<usize>> = HashMap::new();
    for (n, &(a, b)) in segs.iter().enumerate() {
        at.entry(a).or_default().push(n);
        at.entry(b).or_default().push(n);
    }
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut chain = vec![segs[start].0, segs[start].1];
        for forward in [true, false] {
            loop {
                let end = if forward {
                    chain[chain.len() - 1]
                } else {
                    chain[0]
                };
                let next = at[&end].iter().copied().find(|&n| !used[n]);
                let Some(n) = next else { break };
                used[n] = true;
                let other = if segs[n].0 == end {
                    segs[n].1
                } else {
                    segs[n].0
                };
                if forward {
                    chain.push(other);
                } else {
                    chain.insert(0, other);
                }
            }
        }
        let closed = chain.len() > 3 && chain[0] == chain[chain.len() - 1];
        if closed {
            chain.pop();
        }
        out.push((chain, closed));
    }
    out
}

/// Position of `v` on the colour axis in `[0, 1]`, `None` for "no data".
fn colour_t(ca: &Axis, v: f64) -> Option<f64> {
    ticks::transform(ca.log, v)
        .map(|t| ca.frac(t).clamp(0.0, 1.0))
        .filter(|t| t.is_finite())
}

#[cfg(test)]
#[path = "heatmap_tests.rs"]
mod tests;
