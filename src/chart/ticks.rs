//! Axis ranges, "nice" tick positions and tick label formatting.
//!
//! Everything here works in *transformed* coordinates: the value itself on a
//! linear axis, `log10(value)` on a logarithmic one.

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
}

/// Transforms a data value for a linear or log axis.
pub(crate) fn transform(log: bool, v: f64) -> Option<f64> {
    if log {
        (v > 0.0 && v.is_finite()).then(|| v.log10())
    } else {
        (v.is_finite() && v.abs() <= MAX_LINEAR).then_some(v)
    }
}

/// Chooses the visible range from transformed data values and an optional
/// explicit range given in data units.
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
        if new_hi - new_lo > 1e-12 * new_lo.abs().max(new_hi.abs()) && new_hi > new_lo {
            (lo, hi) = (new_lo, new_hi);
        } else if let (Some(a), Some(b)) = (a, b) {
            // Explicit but degenerate (min == max): centre on it.
            (lo, hi) = expand_degenerate((a + b) / 2.0, log);
        }
    }
    Axis { log, lo, hi }
}

fn auto_range(values: &[f64], log: bool) -> (f64, f64) {
    let mut it = values.iter().copied().filter(|v| v.is_finite());
    let Some(first) = it.next() else {
        return (0.0, 1.0);
    };
    let (min, max) = it.fold((first, first), |(a, b), v| (a.min(v), b.max(v)));
    let span = max - min;
    if !(span > 1e-12 * min.abs().max(max.abs()) && span > 1e-290) {
        return expand_degenerate((min + max) / 2.0, log);
    }
    (min - 0.05 * span, max + 0.05 * span)
}

fn expand_degenerate(c: f64, log: bool) -> (f64, f64) {
    if log {
        (c - 0.5, c + 0.5)
    } else if c == 0.0 {
        (-1.0, 1.0)
    } else {
        let d = (0.1 * c.abs()).max(1e-290);
        (c - d, c + d)
    }
}

/// A labelled tick at a transformed position.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tick {
    pub pos: f64,
    pub label: String,
}

/// Labelled major ticks and unlabelled minor ticks (transformed positions).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Ticks {
    pub major: Vec<Tick>,
    pub minor: Vec<f64>,
}

/// Ticks for an axis with at most `max_n` labels; `minor` enables the
/// 2..9 minor ticks of log axes.
pub(crate) fn axis_ticks(axis: &Axis, max_n: usize, minor: bool) -> Ticks {
    if axis.log {
        log_ticks(axis.lo, axis.hi, max_n, minor)
    } else {
        linear_ticks(axis.lo, axis.hi, max_n)
    }
}

fn pow10(k: i32) -> f64 {
    10f64.powi(k)
}

/// `m * 10^k` computed so that e.g. `3 * 10^-1` is exactly `0.3`.
fn scaled(m: f64, k: i32) -> f64 {
    if k < 0 { m / pow10(-k) } else { m * pow10(k) }
}

/// Linear ticks at multiples of 1, 2 or 5 x 10^k: the finest such step that
/// gives at most `max_n` ticks in `[lo, hi]`.
pub(crate) fn linear_ticks(lo: f64, hi: f64, max_n: usize) -> Ticks {
    let max_n = max_n.clamp(2, 50) as f64;
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        let label = if lo.is_finite() {
            format_plain(lo, 6)
        } else {
            String::new()
        };
        let major = if lo.is_finite() {
            vec![Tick { pos: lo, label }]
        } else {
            Vec::new()
        };
        return Ticks {
            major,
            minor: Vec::new(),
        };
    }
    let span = hi - lo;
    let k0 = (span / max_n).log10().floor().clamp(-330.0, 330.0) as i32;
    // Candidate steps m x 10^k in increasing order, with their tick counts.
    let mut steps = Vec::new();
    for k in (k0 - 1)..=(k0 + 2) {
        for m in [1.0, 2.0, 5.0] {
            let step = scaled(m, k);
            if step > 0.0 && step.is_finite() {
                let first = (lo / step - 1e-9).ceil();
                let count = (hi / step + 1e-9).floor() - first + 1.0;
                steps.push((m, k, first, count));
            }
        }
    }
    // The finest step giving at most `max_n` ticks; if that leaves fewer
    // than 4 of a generous 8 or more, one step finer may give up to 2 more.
    let Some(mut idx) = steps.iter().position(|s| s.3 <= max_n) else {
        return Ticks::default();
    };
    if max_n >= 8.0 && steps[idx].3 < 4.0 && idx > 0 && steps[idx - 1].3 <= max_n + 2.0 {
        idx -= 1;
    }
    let (m, k, first, count) = steps[idx];
    let step = scaled(m, k);
    let sci = !(1e-3..1e5).contains(&lo.abs().max(hi.abs()));
    let major = (0..count.max(0.0) as usize)
        .map(|j| {
            let i = first + j as f64;
            let v = if k < 0 {
                i * m / pow10(-k)
            } else {
                i * m * pow10(k)
            };
            let v = if v.abs() < step * 1e-6 { 0.0 } else { v };
            let label = if sci {
                format_sci(v, k)
            } else {
                format_plain(v, (-k).max(0) as usize)
            };
            Tick { pos: v, label }
        })
        .collect();
    Ticks {
        major,
        minor: Vec::new(),
    }
}

/// `v` with `decimals` digits after the point, no negative zero.
fn format_plain(v: f64, decimals: usize) -> String {
    let s = format!("{:.*}", decimals.min(17), v);
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// Scientific label like `1.5e6` for a tick on a grid of step ~10^k.
fn format_sci(v: f64, k: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".to_string();
    }
    let mut e = v.abs().log10().floor() as i32;
    let mut digits = (e - k).clamp(0, 15) as usize;
    let mut mant = format!("{:.*}", digits, v / scaled(1.0, e));
    if mant.trim_start_matches('-').starts_with("10") {
        e += 1;
        digits = (e - k).clamp(0, 15) as usize;
        mant = format!("{:.*}", digits, v / scaled(1.0, e));
    }
    if mant.contains('.') {
        mant = mant.trim_end_matches('0').trim_end_matches('.').to_string();
    }
    format!("{mant}e{e}")
}

/// Label for `10^k`: plain from 0.01 to 1000, `1e-3` / `1e4` style outside.
pub(crate) fn format_decade(k: i32) -> String {
    match k {
        -2..=3 => format_plain(scaled(1.0, k), (-k).max(0) as usize),
        _ => format!("1e{k}"),
    }
}

/// Label for `m * 10^k` with integer `m` in 1..=9.
fn format_mantissa(m: u32, k: i32) -> String {
    if m == 1 {
        format_decade(k)
    } else if (-3..=4).contains(&k) {
        format_plain(scaled(f64::from(m), k), (-k).max(0) as usize)
    } else {
        format!("{m}e{k}")
    }
}

/// Log ticks for the exponent range `[lo, hi]`: labelled decades (every
/// d-th decade when there are too many), or, for ranges spanning less than
/// two decade marks, labelled 1..9 / 1-2-5 multiples or linear ticks.
pub(crate) fn log_ticks(lo: f64, hi: f64, max_n: usize, minor: bool) -> Ticks {
    let max_n = max_n.clamp(2, 50);
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Ticks::default();
    }
    let (lo, hi) = (lo.max(-400.0), hi.min(400.0));
    let eps = 1e-9 * (hi - lo);
    let inside = |t: f64| t >= lo - eps && t <= hi + eps;
    let kmin = (lo - eps).ceil() as i32;
    let kmax = (hi + eps).floor() as i32;
    let decades = (kmax - kmin + 1).max(0) as usize;

    if decades >= 2 {
        let mut stride = 1;
        for d in [1, 2, 3, 4, 5, 10, 20, 25, 50, 100, 200] {
            stride = d;
            if (kmin..=kmax).filter(|k| k % d == 0).count() <= max_n {
                break;
            }
        }
        let mut labelled: Vec<i32> = (kmin..=kmax).filter(|k| k % stride == 0).collect();
        if labelled.len() < 2 {
            labelled = vec![kmin, kmax];
        }
        let mut major: Vec<Tick> = labelled
            .iter()
            .map(|&k| Tick {
                pos: f64::from(k),
                label: format_decade(k),
            })
            .collect();
        // Only two decade marks: also label the 2x and 5x multiples if room.
        let extra: Vec<Tick> = ((lo.floor() as i32)..=(hi.ceil() as i32))
            .flat_map(|k| [2, 5].map(|m| (m, k)))
            .filter(|&(m, k)| inside(f64::from(k) + f64::from(m).log10()))
            .map(|(m, k)| Tick {
                pos: f64::from(k) + f64::from(m).log10(),
                label: format_mantissa(m, k),
            })
            .collect();
        if decades == 2 && major.len() + extra.len() <= max_n {
            major.extend(extra);
            major.sort_by(|a, b| a.pos.total_cmp(&b.pos));
        }
        let mut minor_ticks = Vec::new();
        if stride == 1 && minor && hi - lo <= 30.0 {
            for k in (lo.floor() as i32)..=(hi.ceil() as i32) {
                for m in 2..=9 {
                    let t = f64::from(k) + f64::from(m).log10();
                    if inside(t) && major.iter().all(|tick| (tick.pos - t).abs() > eps) {
                        minor_ticks.push(t);
                    }
                }
            }
        } else if stride > 1 && decades <= 200 {
            minor_ticks = (kmin..=kmax)
                .filter(|k| !labelled.contains(k))
                .map(f64::from)
                .collect();
        }
        return Ticks {
            major,
            minor: minor_ticks,
        };
    }

    // Less than two decade marks: label multiples within the decade(s).
    let multiples = |ms: &[u32]| -> Vec<(f64, u32, i32)> {
        let mut v = Vec::new();
        for k in (lo.floor() as i32 - 1)..=(hi.ceil() as i32) {
            for &m in ms {
                let t = f64::from(k) + f64::from(m).log10();
                if inside(t) {
                    v.push((t, m, k));
                }
            }
        }
        v
    };
    let all = multiples(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
    let to_tick = |&(t, m, k): &(f64, u32, i32)| Tick {
        pos: t,
        label: format_mantissa(m, k),
    };
    if all.len() >= 2 && all.len() <= max_n {
        return Ticks {
            major: all.iter().map(to_tick).collect(),
            minor: Vec::new(),
        };
    }
    let main = multiples(&[1, 2, 5]);
    if main.len() >= 2 {
        let minor_ticks = all
            .iter()
            .filter(|(_, m, _)| ![1, 2, 5].contains(m))
            .map(|&(t, _, _)| t)
            .collect();
        return Ticks {
            major: main.iter().map(to_tick).collect(),
            minor: minor_ticks,
        };
    }
    // Very narrow range: linear ticks in data units, placed logarithmically.
    let lin = linear_ticks(10f64.powf(lo), 10f64.powf(hi), max_n);
    let major: Vec<Tick> = lin
        .major
        .into_iter()
        .filter(|t| t.pos > 0.0)
        .map(|t| Tick {
            pos: t.pos.log10(),
            label: t.label,
        })
        .collect();
    let minor_ticks = all
        .iter()
        .map(|&(t, _, _)| t)
        .filter(|t| major.iter().all(|m| (m.pos - t).abs() > eps))
        .collect();
    Ticks {
        major,
        minor: minor_ticks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(t: &Ticks) -> Vec<&str> {
        t.major.iter().map(|t| t.label.as_str()).collect()
    }

    fn values(t: &Ticks) -> Vec<f64> {
        t.major.iter().map(|t| t.pos).collect()
    }

    #[test]
    fn linear_nice_steps() {
        assert_eq!(
            labels(&linear_ticks(0.0, 1.0, 8)),
            ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]
        );
        assert_eq!(
            labels(&linear_ticks(-0.4, 10.4, 8)),
            ["0", "2", "4", "6", "8", "10"]
        );
        assert_eq!(
            labels(&linear_ticks(0.0, 3.0, 8)),
            ["0.0", "0.5", "1.0", "1.5", "2.0", "2.5", "3.0"]
        );
        assert_eq!(
            labels(&linear_ticks(-3.0, 3.0, 8)),
            ["-3", "-2", "-1", "0", "1", "2", "3"]
        );
        assert_eq!(values(&linear_ticks(0.0, 1.0, 3)), [0.0, 0.5, 1.0]);
        // Every step is 1, 2 or 5 x 10^k and the count stays in range.
        for (lo, hi) in [
            (0.0, 1.0),
            (-7.3, 2.2),
            (1e-6, 3e-6),
            (1234.0, 98765.0),
            (0.91, 1.002),
        ] {
            let t = linear_ticks(lo, hi, 8);
            assert!(
                (4..=8).contains(&t.major.len()),
                "{lo}..{hi}: {:?}",
                labels(&t)
            );
            let step = t.major[1].pos - t.major[0].pos;
            let mant = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0].iter().any(|m| (mant - m).abs() < 1e-6),
                "step {step}"
            );
            assert!(t.major.iter().all(|t| t.pos >= lo && t.pos <= hi));
        }
        // Where 1-2-5 steps jump from 3 to 9 ticks, 9 wins (if allowed).
        assert_eq!(linear_ticks(-0.8, 0.8, 8).major.len(), 9);
        assert_eq!(linear_ticks(-0.8, 0.8, 6).major.len(), 3);
    }

    #[test]
    fn linear_labels_scientific_and_exact() {
        assert_eq!(
            labels(&linear_ticks(0.0, 3e6, 4)),
            ["0", "1e6", "2e6", "3e6"]
        );
        assert_eq!(
            labels(&linear_ticks(1e6, 2e6, 6)),
            ["1e6", "1.2e6", "1.4e6", "1.6e6", "1.8e6", "2e6"]
        );
        assert_eq!(
            labels(&linear_ticks(0.0, 4e-4, 5)),
            ["0", "1e-4", "2e-4", "3e-4", "4e-4"]
        );
        assert_eq!(
            labels(&linear_ticks(0.25, 0.35, 3)),
            ["0.25", "0.30", "0.35"]
        );
        assert_eq!(format_sci(9.999_999_999e5, 5), "1e6");
        assert_eq!(format_sci(-2.5e-7, -8), "-2.5e-7");
    }

    #[test]
    fn linear_degenerate() {
        assert_eq!(linear_ticks(1.0, 1.0, 8).major.len(), 1);
        assert!(linear_ticks(f64::NAN, 1.0, 8).major.is_empty());
        assert!(linear_ticks(0.0, f64::INFINITY, 8).major.len() <= 1);
        let tiny = linear_ticks(1.0, 1.0 + 1e-9, 8);
        assert!(tiny.major.len() >= 2);
    }

    #[test]
    fn log_decades_and_minors() {
        let t = log_ticks(-3.2, 2.1, 8, true);
        assert_eq!(labels(&t), ["1e-3", "0.01", "0.1", "1", "10", "100"]);
        assert_eq!(values(&t), [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0]);
        // 2..9 minors in each visible decade.
        assert!(t.minor.iter().any(|&m| (m - 2f64.log10()).abs() < 1e-12));
        assert!(t.minor.iter().all(|&m| (-3.2..=2.1).contains(&m)));
        assert_eq!(t.minor.len(), 3 + 8 * 5); // 7e-4..9e-4, then 2..9 x 1e-3..10
        assert!(log_ticks(-3.2, 2.1, 8, false).minor.is_empty());
    }

    #[test]
    fn log_many_decades_are_thinned() {
        let t = log_ticks(-30.5, 30.5, 8, true);
        assert!(t.major.len() <= 8 && t.major.len() >= 2);
        assert!(labels(&t).contains(&"1"));
        assert!(labels(&t).contains(&"1e10"));
        let w = log_ticks(-300.0, 300.0, 6, true);
        assert!(w.major.len() <= 6 && w.major.len() >= 2);
    }

    #[test]
    fn log_narrow_ranges() {
        // 2..8: no decade mark at all -> 1..9 multiples.
        let t = log_ticks(2f64.log10(), 8f64.log10(), 8, true);
        assert_eq!(labels(&t), ["2", "3", "4", "5", "6", "7", "8"]);
        // 0.15 .. 9.5 with few labels: 1-2-5.
        let t = log_ticks(0.15f64.log10(), 9.5f64.log10(), 6, true);
        assert_eq!(labels(&t), ["0.2", "0.5", "1", "2", "5"]);
        // 1.01 .. 1.05: linear labels.
        let t = log_ticks(1.01f64.log10(), 1.05f64.log10(), 8, true);
        assert!(t.major.len() >= 2);
        assert!(labels(&t).iter().all(|l| l.starts_with("1.0")));
        assert!(log_ticks(1.0, 1.0, 8, true).major.is_empty());
    }

    #[test]
    fn decade_labels() {
        let l: Vec<String> = (-4..=5).map(format_decade).collect();
        assert_eq!(
            l,
            [
                "1e-4", "1e-3", "0.01", "0.1", "1", "10", "100", "1000", "1e4", "1e5"
            ]
        );
        assert_eq!(format_mantissa(2, -5), "2e-5");
        assert_eq!(format_mantissa(5, -3), "0.005");
        assert_eq!(format_mantissa(3, 4), "30000");
    }

    #[test]
    fn ranges() {
        let a = resolve_axis(&[0.0, 10.0], false, None);
        assert_eq!((a.lo, a.hi), (-0.5, 10.5));
        let a = resolve_axis(&[], false, None);
        assert_eq!((a.lo, a.hi), (0.0, 1.0));
        let a = resolve_axis(&[3.0, 3.0], false, None);
        assert!(a.lo < 3.0 && a.hi > 3.0);
        let a = resolve_axis(&[0.0], false, None);
        assert_eq!((a.lo, a.hi), (-1.0, 1.0));
        let a = resolve_axis(&[1.0], true, None);
        assert_eq!((a.lo, a.hi), (0.5, 1.5));
        let a = resolve_axis(&[0.0, 1.0], false, Some((5.0, -5.0)));
        assert_eq!((a.lo, a.hi), (-5.0, 5.0));
        let a = resolve_axis(&[0.0, 1.0], false, Some((f64::NAN, 2.0)));
        assert_eq!((a.lo, a.hi), (-0.05, 2.0));
        let a = resolve_axis(&[0.0, 2.0], true, Some((-1.0, 1000.0)));
        assert_eq!((a.lo, a.hi), (-0.1, 3.0));
        let a = resolve_axis(&[0.0, 1.0], false, Some((4.0, 4.0)));
        assert!(a.lo < 4.0 && a.hi > 4.0);
    }
}
