//! Means and standard deviations for the studies' JSON summaries. A mean of no values and a
//! standard deviation of fewer than two are undefined: they are `None` (JSON `null`), never 0,
//! so that a summary cannot report a statistic of nothing as a measured zero.

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

/// "`n` runs per point" for a chart title, singular for one, with "(95 % intervals)" only when
/// `intervals` and there are two runs or more (one run has no interval).
pub fn runs_per_point(n: u64, intervals: bool) -> String {
    match n {
        1 => "1 run per point (no intervals)".into(),
        n if intervals => format!("{n} runs per point (95 % intervals)"),
        n => format!("{n} runs per point"),
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
    fn titles_count_runs_in_good_english() {
        assert_eq!(runs_per_point(1, true), "1 run per point (no intervals)");
        assert_eq!(runs_per_point(3, true), "3 runs per point (95 % intervals)");
        assert_eq!(runs_per_point(2, false), "2 runs per point");
    }
}
