//! Ensemble statistics: means with 95 % confidence intervals.

/// Two-sided 97.5 % quantiles of Student's t for 1..=30 degrees of freedom.
const T975: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

/// t quantile for a 95 % two-sided interval with `df` degrees of freedom (normal beyond 30,
/// within 2 % of the exact value).
pub fn t_quantile_95(df: usize) -> f64 {
    match df {
        0 => f64::INFINITY,
        1..=30 => T975[df - 1],
        d if d <= 60 => 2.042 - (2.042 - 2.000) * (d - 30) as f64 / 30.0,
        d if d <= 120 => 2.000 - (2.000 - 1.980) * (d - 60) as f64 / 60.0,
        _ => 1.96,
    }
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
/// particles within one run are not, as dipoles and hydrodynamics couple them).
///
/// ```
/// use magsep::brownian::stats::mean_interval;
/// let e = mean_interval(&[0.5, 0.7, 0.6]);
/// assert!((e.mean - 0.6).abs() < 1e-12);
/// assert!((e.hi - e.mean - 4.303 * 0.1 / 3f64.sqrt()).abs() < 1e-12);
/// ```
pub fn mean_interval(values: &[f64]) -> Estimate {
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n.max(1) as f64;
    if n < 2 {
        return Estimate {
            mean,
            lo: f64::NAN,
            hi: f64::NAN,
        };
    }
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let half = t_quantile_95(n - 1) * (var / n as f64).sqrt();
    Estimate {
        mean,
        lo: mean - half,
        hi: mean + half,
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
