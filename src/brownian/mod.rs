//! The brownian pipeline's facade: summaries of runs and ensembles, replay of capture curves.

pub mod chart;
pub mod ensemble;
pub mod replay;
pub mod stats;
pub mod summary;
pub mod sweep;

pub use ensemble::run_ensemble;
pub use summary::{RunResult, StartRegions, run_result, run_summary, summary_of};
