//! Studies built on the pipelines: benchmarks (`magsep bench`), charts of accuracy against
//! cost (`magsep chart`) and the sweeps behind them. Nothing in the library's core depends on
//! this module.

pub mod bench;
pub mod bench_brownian;
pub mod bench_field;
pub mod bench_overhead;
pub mod bench_scene;
pub mod brownian_chart;
pub mod brownian_sweep;
pub mod fluid_charts;
pub mod liquid;
pub mod packing_charts;
pub mod sq_study;
pub mod stats;
pub mod sweep;
