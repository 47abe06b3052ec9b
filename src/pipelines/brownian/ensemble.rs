//! Independent replicates of a brownian scene (`runs = 30`), run in parallel.
//!
//! Replicate 0 uses the run's seed (so a single run and replicate 0 of an ensemble are the
//! same trajectory); replicate k > 0 uses a SplitMix64 mix of (seed, k). Each replicate runs
//! its schedule on one thread and the replicates share the rayon pool, so the result is the
//! same for any thread count.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use magsep_components::prelude::*;
use magsep_systems::rng::splitmix64;
use rayon::prelude::*;
use serde_json::Value;

use super::summary::{RunResult, StartRegions, run_result, summary_of};
use crate::scene::Scene;
use crate::sim::{RunOptions, SimError, Simulation};

/// Seed of replicate `k` of a run with `seed`.
///
/// ```
/// use magsep::brownian::ensemble::replicate_seed;
/// assert_eq!(replicate_seed(7, 0), 7);
/// assert_ne!(replicate_seed(7, 1), replicate_seed(7, 2));
/// ```
pub fn replicate_seed(seed: u64, k: u64) -> u64 {
    if k == 0 {
        return seed;
    }
    let mut s = seed ^ k.wrapping_mul(0xA076_1D64_78BD_642F);
    splitmix64(&mut s)
}

/// Run `runs` replicates of `scene` (recording only replicate 0) and summarise them.
/// `progress` is called with the number of steps just completed (from any thread).
///
/// # Errors
/// The first replicate's [`SimError`] in replicate order.
pub fn run_ensemble(
    scene: &Scene,
    runs: u64,
    options: &RunOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Value, SimError> {
    let started = Instant::now();
    let seed = options
        .seed
        .or(scene.simulation.as_ref().map(|s| s.seed))
        .unwrap_or(0);
    let one = |k: u64| -> Result<(RunResult, Option<(StartRegions, BrownianConfig)>), SimError> {
        let opts = RunOptions {
            seed: Some(replicate_seed(seed, k)),
            record: if k == 0 { options.record.clone() } else { None },
            pipeline: options.pipeline.clone(),
            single_threaded: options.single_threaded || runs > 1,
            resume_from: None,
            plugins: options.plugins.clone(),
        };
        let mut sim = Simulation::from_scene(scene, opts)?;
        let last = AtomicU64::new(0);
        sim.run(|w| {
            let s = w.resource::<StepClock>().step;
            if s % 100 == 0 {
                progress(s - last.swap(s, Ordering::Relaxed));
            }
        })?;
        let w = &sim.app.world;
        progress(w.resource::<StepClock>().step - last.load(Ordering::Relaxed));
        let meta = (k == 0).then(|| {
            (
                w.get_resource::<StartRegions>()
                    .cloned()
                    .unwrap_or_default(),
                w.resource::<BrownianConfig>().clone(),
            )
        });
        Ok((run_result(w, sim.seed), meta))
    };
    let results: Vec<_> = (0..runs).into_par_iter().map(one).collect();
    let mut out = Vec::with_capacity(results.len());
    let mut meta = None;
    for r in results {
        let (result, m) = r?;
        if m.is_some() {
            meta = m;
        }
        out.push(result);
    }
    let (regions, config) = meta.expect("replicate 0 ran");
    Ok(summary_of(
        &out,
        &regions,
        &config,
        started.elapsed().as_secs_f64(),
    ))
}
