//! Ensemble statistics: means with 95 % confidence intervals.

use magsep_systems::analysis::confinement::student_t_95;

/// t quantile for a 95 % two-sided interval with `df` degrees of freedom (infinite for 0),
/// exact (`statrs` inverse CDF, see [`student_t_95`]).
///
/// ```
/// use magsep::brownian::stats::t_quantile_95;
/// assert!((t_quantile_95(2) - 4.302_652_729_749_46).abs() < 1e-8);
/// ```
pub fn t_quantile_95(df: usize) -> f64 {
    student_t_95(df)
}

/// A mean with its 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Estimate {
    /// Mean.
    pub mean: f64,
    /// Lower end of the 95 % interval.
    pub lo: f64,
    /// Upper end of the 95 % interval.
    pub hi: f64,
}

/// Mean of per-run values with a Student-t interval (runs are independent replicates; the
/// particles within one run are not, as dipoles and hydrodynamics couple them), by the shared
/// [`crate::stats::mean_ci95`].
///
/// ```
/// use magsep::brownian::stats::mean_interval;
/// let e = mean_interval(&[0.5, 0.7, 0.6]);
/// assert!((e.mean - 0.6).abs() < 1e-12);
/// assert!((e.hi - e.mean - 4.302_652_729_749_46 * 0.1 / 3f64.sqrt()).abs() < 1e-9);
/// ```
pub fn mean_interval(values: &[f64]) -> Estimate {
    // the mean of no runs is undefined (NaN, JSON null), not 0; one run has no interval
    match crate::stats::mean_ci95(values) {
        (mean, Some(half)) => Estimate {
            mean,
            lo: mean - half,
            hi: mean + half,
        },
        (mean, None) => Estimate {
            mean,
            lo: f64::NAN,
            hi: f64::NAN,
        },
    }
}

/// Wilson score interval of a binomial fraction `k / n` (one run: particles as trials).
///
/// ```
/// use magsep::brownian::stats::wilson;
/// let e = wilson(0, 100);
/// assert_eq!(e.lo, 0.0);
/// assert!(e.hi > 0.03 && e.hi < 0.04);
/// ```
pub fn wilson(k: u64, n: u64) -> Estimate {
    if n == 0 {
        return Estimate {
            mean: f64::NAN,
            lo: f64::NAN,
            hi: f64::NAN,
        };
    }
    let (k, n) = (k as f64, n as f64);
    let z = 1.959_964;
    let p = k / n;
    let d = 1.0 + z * z / n;
    let c = (p + z * z / (2.0 * n)) / d;
    let h = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / d;
    Estimate {
        mean: p,
        lo: (c - h).max(0.0),
        hi: (c + h).min(1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_no_runs_is_nan_not_zero() {
        let e = mean_interval(&[]);
        assert!(e.mean.is_nan() && e.lo.is_nan() && e.hi.is_nan());
        let one = mean_interval(&[0.25]);
        assert_eq!(one.mean, 0.25);
        assert!(one.lo.is_nan() && one.hi.is_nan());
    }

    #[test]
    fn interval_covers_the_mean_at_the_nominal_rate() {
        // Bernoulli(0.3) means of 20 draws, 2000 experiments: coverage near 95 %
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut covered = 0;
        for _ in 0..2000 {
            let runs: Vec<f64> = (0..10)
                .map(|_| (0..20).filter(|_| next() < 0.3).count() as f64 / 20.0)
                .collect();
            let e = mean_interval(&runs);
            if e.lo <= 0.3 && 0.3 <= e.hi {
                covered += 1;
            }
        }
        let rate = covered as f64 / 2000.0;
        assert!((0.93..=0.97).contains(&rate), "{rate}");
    }
}
