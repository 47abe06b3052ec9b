//! The spheroid rows of `magsep bench particle-fluid` (timings, never assertions):
//!
//! * `particle_fluid_flakes`: particle-steps per second of the whole pipeline on the thesis's
//!   many-particle channel (`scenes/flakes_case4.toml`: 1104 particles of d_e = 4 mm, quick:
//!   220) for spheres (w = 1) and flakes of w = 0.5 and 0.1, without and with collisions, over
//!   the first steps after injection (the bands are dense, so collisions are busy).
//! * `spheroid_contact_query`: nanoseconds per spheroid-spheroid contact query (minimum
//!   distance, normal and contact point) for random 1:2 and 1:10 pairs near contact.

use std::time::Instant;

use serde_json::{Value, json};

use super::levitation::runtime;
use crate::scene::{Registry, parse_scene};
use crate::sim::{RunOptions, Simulation};
use crate::studies::bench::{BenchError, emit};

const MANY: &str = include_str!("../../../scenes/flakes_case4.toml");

/// The pipeline rows.
pub(super) fn flake_rows(
    rows: &mut Vec<Value>,
    as_json: bool,
    quick: bool,
) -> Result<(), BenchError> {
    let (phi, steps) = if quick { (0.002, 40u64) } else { (0.01, 300) };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    for w in [1.0, 0.5, 0.1] {
        for collisions in [false, true] {
            let text = MANY
                .replace("aspect_ratio = 0.5", &format!("aspect_ratio = {w}"))
                .replace(
                    "volume_fraction = 0.01 ",
                    &format!("volume_fraction = {phi} "),
                )
                .replace(
                    "terms = { collisions = false }",
                    &format!("terms = {{ collisions = {collisions} }}"),
                );
            let scene = parse_scene(&text, &Registry::default()).map_err(runtime)?;
            let mut sim = Simulation::from_scene(&scene, RunOptions::default()).map_err(runtime)?;
            let start = Instant::now();
            for _ in 0..steps {
                sim.step();
            }
            let wall = start.elapsed().as_secs_f64();
            let s = sim.summary();
            let n = s["particles"].as_u64().unwrap_or(0);
            emit(
                rows,
                as_json,
                json!({"name": "particle_fluid_flakes", "aspect_ratio": w,
                       "collisions": collisions, "threads": threads, "particles": n,
                       "steps": steps, "wall_time_s": wall,
                       "particle_steps_per_s": (n * steps) as f64 / wall.max(1e-12),
                       "collision_counts": s["collisions"]}),
            )?;
        }
    }
    Ok(())
}

/// The contact-query rows.
pub(super) fn contact_rows(
    rows: &mut Vec<Value>,
    as_json: bool,
    quick: bool,
) -> Result<(), BenchError> {
    use magsep_systems::collision::spheroid::time_contact_queries;
    let n = if quick { 2_000 } else { 100_000 };
    for w in [1.0, 0.5, 0.1] {
        let t = time_contact_queries(n, w, 1);
        emit(
            rows,
            as_json,
            json!({"name": "spheroid_contact_query", "aspect_ratio": w, "threads": 1,
                   "queries": t.queries,
                   "cold_ns_per_query": t.cold_seconds_per_query * 1e9,
                   "warm_ns_per_query": t.warm_seconds_per_query * 1e9,
                   "cold_newton_iterations": t.cold_iterations,
                   "not_converged": t.not_converged}),
        )?;
    }
    Ok(())
}
