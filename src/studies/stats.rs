//! Statistics for the studies' JSON summaries and chart titles. The means, standard deviations
//! and intervals live in [`crate::stats`] (shared with the pipelines); they are re-exported
//! here.

pub use crate::stats::{mean, mean_sd};

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
    fn titles_count_runs_in_good_english() {
        assert_eq!(runs_per_point(1, true), "1 run per point (no intervals)");
        assert_eq!(runs_per_point(3, true), "3 runs per point (95 % intervals)");
        assert_eq!(runs_per_point(2, false), "2 runs per point");
    }
}
