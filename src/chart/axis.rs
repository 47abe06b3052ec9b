//! Axis ranges, tick choice and labels, and the plotters coordinate that
//! maps an axis (linear or logarithmic) to pixels.
//!
//! Positions are kept in *transformed* coordinates: the value itself on a
//! linear axis, `log10(value)` on a logarithmic one. The pixel mapping is
//! plotters' own (`RangedCoordf64`, or `LogCoord` from `.log_scale()`);
//! tick positions are chosen here (plotters' linear key points, decades or
//! 1-2-5 multiples on log axes) because plotters' log key points leave an
//! axis spanning less than one decade without any tick.

use std::ops::Range;

use plotters::coord::combinators::{IntoLogRange, LogCoord};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;

/// Linear-axis values beyond this magnitude are treated as unplottable.
pub(crate) const MAX_LINEAR: f64 = 1e100;

/// A resolved axis: scale type and visible range in transformed coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Axis {
    pub log: bool,
    pub lo: f64,
    pub hi: f64,
}

impl Axis {
    /// Position of a transformed value in the range, 0 at `lo`, 1 at `hi`.
    pub fn frac(&self, t: f64) -> f64 {
        (t - self.lo) / (self.hi - self.lo)
    }

    /// Data value of a transformed coordinate.
    pub fn data(&self, t: f64) -> f64 {
        if self.log { 10f64.powf(t) } else { t }
    }
}

/// Transforms a data value for a linear or log axis (`None`: unplottable).
pub(crate) fn transform(log: bool, v: f64) -> Option<f64> {
    if log {
        (v > 0.0 && v.is_finite()).then(|| v.log10())
    } else {
        (v.is_finite() && v.abs() <= MAX_LINEAR).then_some(v)
    }
}

/// Chooses the visible range from transformed data values (padded by 5 %)
/// and an optional explicit range given in data units.
pub(crate) fn resolve_axis(values: &[f64], log: bool, explicit: Option<(f64, f64)>) -> Axis {
    let (mut lo, mut hi) = auto_range(values, log);
    if let Some((a, b)) = explicit {
        let (a, b) = (transform(log, a), transform(log, b));
        let (new_lo, new_hi) = match (a, b) {
            (Some(a), Some(b)) => (a.min(b), a.max(b)),
            (Some(a), None) => (a, hi),
            (None, Some(b)) => (lo, b),
            (None, None) => (lo, hi),
        };
        if wide_enough(new_lo, new_hi) {
            (lo, hi) = (new_lo, new_hi);
        } else if let (Some(a), Some(b)) = (a, b) {
            (lo, hi) = expand_degenerate((a + b) / 2.0, log);
        }
    }
    Axis { log, lo, hi }
}

/// Is `[lo, hi]` a usable (non-empty, resolvable in f64) range?
pub(crate) fn wide_enough(lo: f64, hi: f64) -> bool {
    hi > lo && hi - lo > 1e-12 * lo.abs().max(hi.abs()) && hi - lo > 1e-290
}

fn auto_range(values: &[f64], log: bool) -> (f64, f64) {
    let mut it = values.iter().copied().filter(|v| v.is_finite());
    let Some(first) = it.next() else {
        return (0.0, 1.0);
    };
    let (min, max) = it.fold((first, first), |(a, b), v| (a.min(v), b.max(v)));
    if !wide_enough(min, max) {
        return expand_degenerate((min + max) / 2.0, log);
    }
    let span = max - min;
    (min - 0.05 * span, max + 0.05 * span)
}

/// A range around a single value `c` (half a decade on a log axis).
pub(crate) fn expand_degenerate(c: f64, log: bool) -> (f64, f64) {
    if log {
        (c - 0.5, c + 0.5)
    } else if c == 0.0 {
        (-1.0, 1.0)
    } else {
        let d = (0.1 * c.abs()).max(1e-290);
        (c - d, c + d)
    }
}

/// Labelled major ticks (transformed position, label) and unlabelled minor
/// positions.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Ticks {
    pub major: Vec<(f64, String)>,
    pub minor: Vec<f64>,
}

/// Approximate rendered width of `s` in pixels at font size `px`
/// (generous, so that layouts never underestimate).
pub(crate) fn text_width(s: &str, px: f64) -> f64 {
    s.chars()
        .map(|c| match c {
            '.' | ',' | ':' | ';' | '|' | '\'' | ' ' | 'i' | 'l' | 'j' => 0.33,
            '-' | '(' | ')' | '[' | ']' | '/' | 'f' | 't' | 'r' | 'I' => 0.42,
            'm' | 'w' | 'M' | 'W' => 0.95,
            c if c.is_ascii_uppercase() => 0.74,
            c if (c as u32) >= 0x2E80 => 1.0,
            _ => 0.64,
        })
        .sum::<f64>()
        * px
}

/// The densest ticks (at most 8 labels) whose labels do not overlap along
/// an axis of `len` pixels at font size `px`.
pub(crate) fn choose_ticks(axis: &Axis, len: f64, horizontal: bool, px: f64) -> Ticks {
    let fits = |t: &Ticks| {
        t.major.windows(2).all(|w| {
            let gap = ((axis.frac(w[1].0) - axis.frac(w[0].0)) * len).abs();
            if horizontal {
                gap >= (text_width(&w[0].1, px) + text_width(&w[1].1, px)) / 2.0 + 8.0
            } else {
                gap >= px * 1.6
            }
        })
    };
    let minor = axis.log && len / (axis.hi - axis.lo) >= 40.0;
    for n in (2..=8).rev() {
        let t = axis_ticks(axis, n, minor);
        if fits(&t) {
            return t;
        }
    }
    // Still crowded: the first and last label only.
    let mut t = axis_ticks(axis, 2, minor);
    if t.major.len() > 2 {
        let last = t.major.len() - 1;
        let inner = t.major.drain(1..last).map(|m| m.0);
        t.minor.extend(inner);
    }
    t
}

/// Ticks with at most `max_n` labels; `minor` enables the 2..9 minor ticks
/// of log axes.
pub(crate) fn axis_ticks(axis: &Axis, max_n: usize, minor: bool) -> Ticks {
    if !(axis.lo.is_finite() && axis.hi.is_finite() && axis.hi > axis.lo) {
        return Ticks::default();
    }
    if axis.log {
        log_ticks(axis.lo.max(-300.0), axis.hi.min(300.0), max_n, minor)
    } else {
        Ticks {
            major: linear_ticks(axis.lo, axis.hi, max_n),
            minor: Vec::new(),
        }
    }
}

/// Plotters' 1-2-5 key points in `[lo, hi]`, labelled with the decimals
/// their spacing needs (scientific outside 1e-3..1e5).
fn linear_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<(f64, String)> {
    let coord = RangedCoordf64::from(lo..hi);
    let pts: Vec<f64> = coord
        .key_points(max_n.max(2))
        .into_iter()
        .filter(|v| v.is_finite())
        .collect();
    let step = pts
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    let k = if step.is_finite() && step > 0.0 {
        step.log10().floor() as i32
    } else {
        0
    };
    let sci = !(1e-3..1e5).contains(&lo.abs().max(hi.abs()));
    pts.into_iter()
        .map(|v| {
            let v = if step.is_finite() && v.abs() < step * 1e-6 {
                0.0
            } else {
                v
            };
            let label = if sci {
                format_sci(v, k)
            } else {
                format_plain(v, (-k).max(0) as usize)
            };
            (v, label)
        })
        .collect()
}

/// `v` with `decimals` digits after the point, no negative zero.
fn format_plain(v: f64, decimals: usize) -> String {
    let s = format!("{:.*}", decimals.min(17), v);
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// Scientific label like `1.5e6` for a value on a grid of step ~10^k.
fn format_sci(v: f64, k: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".to_string();
    }
    let e = v.abs().log10().floor() as i32;
    let digits = (e - k).clamp(0, 15) as usize;
    let mant = format!("{:.*}", digits, v / 10f64.powi(e));
    let mant = if mant.contains('.') {
        mant.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        mant
    };
    match mant.trim_start_matches('-') {
        "10" => format!("{}1e{}", if v < 0.0 { "-" } else { "" }, e + 1),
        _ => format!("{mant}e{e}"),
    }
}

/// Label for `m * 10^k` (integer `m` in 1..=9): plain for moderate
/// magnitudes, `1e-3` / `2e5` style otherwise.
pub(crate) fn format_mantissa(m: u32, k: i32) -> String {
    let plain = if m == 1 {
        (-2..=3).contains(&k)
    } else {
        (-3..=4).contains(&k)
    };
    if plain {
        format_plain(f64::from(m) * 10f64.powi(k), (-k).max(0) as usize)
    } else {
        format!("{m}e{k}")
    }
}

/// Log ticks for the exponent range `[lo, hi]`: labelled decades (every
/// d-th when there are too many), or, when fewer than two decade marks are
/// visible, 1..9 or 1-2-5 multiples, or linear ticks placed logarithmically.
fn log_ticks(lo: f64, hi: f64, max_n: usize, minor: bool) -> Ticks {
    let max_n = max_n.clamp(2, 50);
    let eps = 1e-9 * (hi - lo);
    let inside = |t: f64| t >= lo - eps && t <= hi + eps;
    let multiples = |ms: &[u32]| -> Vec<(f64, u32, i32)> {
        let k0 = lo.floor() as i32 - 1;
        (k0..=hi.ceil() as i32)
            .flat_map(|k| {
                ms.iter()
                    .map(move |&m| (f64::from(k) + f64::from(m).log10(), m, k))
            })
            .filter(|&(t, _, _)| inside(t))
            .collect()
    };
    let (kmin, kmax) = ((lo - eps).ceil() as i32, (hi + eps).floor() as i32);
    if kmax - kmin >= 1 {
        let stride = [1, 2, 3, 4, 5, 10, 20, 25, 50, 100, 200]
            .into_iter()
            .find(|&d| (kmin..=kmax).filter(|k| k % d == 0).count() <= max_n)
            .unwrap_or(200);
        let labelled: Vec<i32> = (kmin..=kmax).filter(|k| k % stride == 0).collect();
        let labelled = if labelled.len() < 2 {
            vec![kmin, kmax]
        } else {
            labelled
        };
        let major = labelled
            .iter()
            .map(|&k| (f64::from(k), format_mantissa(1, k)))
            .collect();
        let minor_ticks = if stride == 1 && minor && hi - lo <= 30.0 {
            multiples(&[2, 3, 4, 5, 6, 7, 8, 9])
                .into_iter()
                .map(|m| m.0)
                .collect()
        } else if stride > 1 {
            (kmin..=kmax)
                .filter(|k| !labelled.contains(k))
                .map(f64::from)
                .collect()
        } else {
            Vec::new()
        };
        return Ticks {
            major,
            minor: minor_ticks,
        };
    }
    let to_tick = |&(t, m, k): &(f64, u32, i32)| (t, format_mantissa(m, k));
    let all = multiples(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
    if (2..=max_n).contains(&all.len()) {
        return Ticks {
            major: all.iter().map(to_tick).collect(),
            minor: Vec::new(),
        };
    }
    let main = multiples(&[1, 2, 5]);
    if (2..=max_n).contains(&main.len()) {
        return Ticks {
            major: main.iter().map(to_tick).collect(),
            minor: Vec::new(),
        };
    }
    // Very narrow range: linear ticks in data units, placed logarithmically.
    let major = linear_ticks(10f64.powf(lo), 10f64.powf(hi), max_n)
        .into_iter()
        .filter(|t| t.0 > 0.0)
        .map(|(v, l)| (v.log10(), l))
        .collect();
    Ticks {
        major,
        minor: Vec::new(),
    }
}

/// How an [`Axis`] maps to pixels: plotters' linear or logarithmic coordinate.
enum Scale {
    Linear(RangedCoordf64),
    Log(LogCoord<f64>),
}

/// A plotters coordinate for one axis: the pixel mapping of its scale and
/// the chosen ticks as key points (bold: labelled; light: minor grid lines).
pub(crate) struct PlotAxis {
    scale: Scale,
    range: Range<f64>,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl PlotAxis {
    /// The coordinate of `axis` with `ticks` (transformed positions).
    pub fn new(axis: &Axis, ticks: &Ticks) -> Self {
        let range = axis.data(axis.lo)..axis.data(axis.hi);
        let scale = if axis.log {
            Scale::Log(range.clone().log_scale().into())
        } else {
            Scale::Linear(range.clone().into())
        };
        PlotAxis {
            scale,
            range,
            bold: ticks.major.iter().map(|t| axis.data(t.0)).collect(),
            light: ticks.minor.iter().map(|&t| axis.data(t)).collect(),
        }
    }
}

impl Ranged for PlotAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        match &self.scale {
            Scale::Linear(c) => c.map(value, limit),
            Scale::Log(c) => c.map(value, limit),
        }
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }
}

/// Tick label lookup for plotters' label formatter: the label of the tick
/// whose data value is `v` (plotters hands back the exact key point).
pub(crate) fn label_of(axis: &Axis, ticks: &Ticks, v: f64) -> String {
    ticks
        .major
        .iter()
        .find(|t| axis.data(t.0) == v)
        .map(|t| t.1.clone())
        .unwrap_or_default()
}

#[cfg(test)]
#[path = "axis_tests.rs"]
mod tests;
