//! Throughput of the full brownian pipeline without hydrodynamic interactions: a scene of
//! saturated spheres with dipole forces in a uniform field, stepped through [`Simulation`]
//! on a rayon pool of a chosen size.
//!
//! The schedule runs on the single-threaded executor, so every system (and every rayon
//! parallel loop inside the force model) runs on the installed pool: the thread count is the
//! pool size and nothing else.

use std::time::Instant;

use glam::DVec3;
use magsep_components::prelude::{BrownianStats, Health};
use magsep_systems::brownian::cells::CellList;
use magsep_systems::brownian::systems::BrownianWorkspace;

use super::{DIPOLE_CUTOFF, MOMENT, PIPELINE_VOLUME_FRACTION, RADIUS, TIME_STEP};
use crate::scene::Scene;
use crate::sim::{RunOptions, Simulation};
use crate::studies::bench::BenchError;

/// Edge of the cube holding `n` spheres of `radius` at volume fraction `phi` [m].
pub fn box_edge(n: usize, radius: f64, phi: f64) -> f64 {
    (n as f64 * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3) / phi).cbrt()
}

/// Scene text: `n` spheres (R = 75 nm, saturated moment 0.87e-16 A m²) uniform in a cube
/// centred on the origin at volume fraction 1e-3, B = 1 T along x, no fibres, free draining,
/// Mie contact (default), dipole cut-off 30 radii, dt = 1e-6 s; step control `control`:
/// `fixed`, `adaptive` (the default) or `multirate`.
pub fn free_draining_scene(n: usize, control: &str, seed: u64) -> String {
    let h = 0.5 * box_edge(n, RADIUS, PIPELINE_VOLUME_FRACTION);
    let control = match control {
        "adaptive" => "",
        "multirate" => {
            "step_control = { kind = \"multirate\", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }\n"
        }
        _ => "step_control = { kind = \"fixed\" }\n",
    };
    format!(
        "[simulation]\n\
         pipeline = \"brownian\"\n\
         seed = {seed}\n\
         \n\
         [external_field]\n\
         flux_density = [1.0, 0.0, 0.0]\n\
         \n\
         [brownian]\n\
         time_step = {TIME_STEP:?}\n\
         duration = 1.0\n\
         mobility = \"free_draining\"\n\
         dipole_cutoff = {DIPOLE_CUTOFF:?}\n\
         {control}\
         \n\
         [[particles]]\n\
         count = {n}\n\
         shape = {{ kind = \"sphere\", radius = {RADIUS:?} }}\n\
         moment = {{ kind = \"saturated\", moment = {MOMENT:?} }}\n\
         placement = {{ kind = \"box\", min = [{m:?}, {m:?}, {m:?}], max = [{h:?}, {h:?}, {h:?}] }}\n",
        m = -h,
    )
}

/// One throughput measurement of the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineRate {
    /// Timed steps.
    pub steps: u64,
    /// Wall time of the timed steps \[s\].
    pub seconds: f64,
    /// Particles times steps per second of wall time.
    pub particle_steps_per_s: f64,
    /// Accepted sub-steps per step (1 fixed; 2 or more adaptive).
    pub substeps_per_step: f64,
    /// Sub-steps per particle and step (the multirate stepper's cost measure).
    pub particle_substeps_per_step: f64,
    /// Force evaluations inside the stepper per step (besides the ECS force systems).
    pub force_evaluations_per_step: f64,
}

/// Run `scene` on a rayon pool of `threads` threads: `warmup` steps, then steps for at least
/// `seconds` of wall time (at least 3 steps). Returns the rate and the final positions.
///
/// # Errors
/// [`BenchError::Runtime`] when the pool or the simulation cannot be built, or a step fails.
pub fn pipeline_rate(
    scene: &Scene,
    threads: usize,
    warmup: usize,
    seconds: f64,
) -> Result<(PipelineRate, Vec<DVec3>), BenchError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BenchError::Runtime(format!("thread pool: {e}")))?;
    pool.install(|| {
        let options = RunOptions {
            single_threaded: true,
            forces_unread: true,
            ..RunOptions::default()
        };
        let mut sim = Simulation::from_scene(scene, options)
            .map_err(|e| BenchError::Runtime(format!("bench simulation: {e}")))?;
        let n = sim
            .app
            .world
            .resource::<BrownianWorkspace>()
            .positions
            .len();
        for _ in 0..warmup {
            sim.step();
        }
        let s0 = sim.app.world.resource::<BrownianStats>().clone();
        let t = Instant::now();
        let mut steps = 0u64;
        while steps < 3 || t.elapsed().as_secs_f64() < seconds {
            sim.step();
            steps += 1;
        }
        let el = t.elapsed().as_secs_f64();
        if let Some(h) = sim.app.world.get_resource::<Health>()
            && h.is_failed()
        {
            return Err(BenchError::Runtime(format!(
                "bench simulation failed: {}",
                h.messages.join("; ")
            )));
        }
        let s1 = sim.app.world.resource::<BrownianStats>();
        let per = |a: u64, b: u64| (a - b) as f64 / steps as f64;
        let rate = PipelineRate {
            steps,
            seconds: el,
            particle_steps_per_s: (n as u64 * steps) as f64 / el,
            substeps_per_step: per(s1.substeps, s0.substeps),
            particle_substeps_per_step: per(s1.particle_substeps, s0.particle_substeps)
                / n.max(1) as f64,
            force_evaluations_per_step: per(s1.force_evaluations, s0.force_evaluations),
        };
        let x = sim
            .app
            .world
            .resource::<BrownianWorkspace>()
            .positions
            .clone();
        Ok((rate, x))
    })
}

/// Start positions of the pipeline scene with `n` particles and `seed` (spawned, not run).
///
/// # Errors
/// [`BenchError::Runtime`] when the scene cannot be built.
pub fn initial_positions(n: usize, seed: u64) -> Result<Vec<DVec3>, BenchError> {
    let scene =
        crate::scene::parse_scene(&free_draining_scene(n, "fixed", seed), &Default::default())
            .map_err(|e| BenchError::Runtime(format!("bench scene: {e}")))?;
    let sim = Simulation::from_scene(&scene, RunOptions::default())
        .map_err(|e| BenchError::Runtime(format!("bench simulation: {e}")))?;
    Ok(sim
        .app
        .world
        .resource::<BrownianWorkspace>()
        .positions
        .clone())
}

/// Mean number of other particles within `cutoff` \[m\] of a particle (0 for no particles).
pub fn mean_neighbours(x: &[DVec3], cutoff: f64) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let cells = CellList::build(x, cutoff, |_| true);
    let total: usize = (0..x.len())
        .map(|i| {
            let mut c = 0usize;
            cells.for_each_neighbour(x, i, cutoff, |_, _| c += 1);
            c
        })
        .sum();
    total as f64 / x.len() as f64
}
