//! Sample statistics shared by the pipelines' summaries and the studies' charts: means,
//! standard deviations and 95 % confidence intervals. A low module (it imports nothing of
//! the crate), so that `pipelines` and `studies` both use it without an import cycle.
//!
//! Means and standard deviations come from `statrs`; the interval's t quantile is `statrs`'
//! Student-t inverse CDF. A mean of no values and a standard deviation of fewer than two are
//! undefined: `None` (JSON `null`), never 0, so that a summary cannot report a statistic of
//! nothing as a measured zero.

use statrs::statistics::Statistics;

/// The mean of `xs`, `None` when `xs` is empty.
pub fn mean(xs: &[f64]) -> Option<f64> {
    (!xs.is_empty()).then(|| xs.mean())
}

/// The mean of `xs` (`None` when empty) and its sample standard deviation (n − 1 in the
/// denominator; `None` for fewer than two values). `statrs` computes both; it gives NaN
/// where these give `None`.
pub fn mean_sd(xs: &[f64]) -> (Option<f64>, Option<f64>) {
    (mean(xs), (xs.len() >= 2).then(|| xs.std_dev()))
}

/// The mean of `ys` (the plain sum over n: NaN for no values) and the half-width of its
/// 95 % confidence interval, t_{0.975, n−1} s / √n with the sample variance s² (n − 1 in the
/// denominator) and `statrs`' Student-t quantile, by the packing analysis's
/// [`mean_interval_95`](magsep_systems::analysis::confinement::mean_interval_95); `None` for
/// fewer than two values (one value has no interval).
///
/// ```
/// use magsep::stats::mean_ci95;
/// let (m, h) = mean_ci95(&[0.5, 0.7, 0.6]);
/// assert!((m - 0.6).abs() < 1e-12);
/// assert!((h.unwrap() - 4.302_652_729_749_46 * 0.1 / 3f64.sqrt()).abs() < 1e-9);
/// assert_eq!(mean_ci95(&[3.0]), (3.0, None));
/// ```
pub fn mean_ci95(ys: &[f64]) -> (f64, Option<f64>) {
    // the one sample-mean interval of the project: the packing analysis's
    match magsep_systems::analysis::confinement::mean_interval_95(ys) {
        Some(m) => (m.mean, Some(m.half_width)),
        None => (ys.iter().sum::<f64>() / ys.len() as f64, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_nothing_is_none_not_zero() {
        assert_eq!(mean(&[]), None);
        assert_eq!(mean(&[2.0, 4.0]), Some(3.0));
    }

    #[test]
    fn sd_needs_two_values() {
        assert_eq!(mean_sd(&[]), (None, None));
        assert_eq!(mean_sd(&[1.5]), (Some(1.5), None));
        let (m, sd) = mean_sd(&[1.0, 3.0]);
        assert_eq!(m, Some(2.0));
        assert!((sd.unwrap() - 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn the_interval_needs_two_values_and_uses_the_t_quantile() {
        let (m, h) = mean_ci95(&[]);
        assert!(m.is_nan() && h.is_none());
        assert_eq!(mean_ci95(&[0.25]), (0.25, None));
        // n = 2: t(0.975, 1) = 12.706 204 736; s of [0, 2] is sqrt(2), so s / sqrt(2) = 1
        let (m, h) = mean_ci95(&[0.0, 2.0]);
        assert_eq!(m, 1.0);
        assert!((h.unwrap() - 12.706_204_736_174_7).abs() < 1e-9);
    }
}
