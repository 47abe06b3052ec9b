//! Integration tests, one binary: every module below was a test file of its own. One
//! binary links the crate once, which keeps CI's build time and disk use down.

mod bad_recordings;
mod bad_scenes;
mod bench_brownian;
mod brownian_capture;
mod brownian_flow;
mod brownian_hydro;
mod brownian_pipeline;
mod brownian_replay;
mod cli;
mod cli_field;
mod common;
mod docs;
mod field_reference;
mod filter;
mod fluid_charts;
mod graceful_stop;
mod liquid;
mod memory_budget;
mod outputs;
mod overrides;
mod packing_validation;
mod packing_walls;
mod particle_fluid;
mod particle_fluid_collisions;
mod pipeline_framework;
mod scene_fuzz;
mod schedule;
mod signals;
mod spheroid_collisions;
mod spheroids;
mod sweep_curves;
mod sweep_memory;
mod sweep_signals;
mod sweeps;
