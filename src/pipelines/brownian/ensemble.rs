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
use crate::sim::{RunOptions, SimError, Simulation, StopFlag, mark_interrupted, partial};

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

/// What one replicate left: its result and, for replicate 0, the ensemble's configuration;
/// or why it failed.
struct Replicate {
    result: Option<RunResult>,
    meta: Option<ReplicateMeta>,
    error: Option<SimError>,
}

/// What the summary takes from replicate 0's world: the force keys, the plugins' summary keys,
/// the start regions and the configuration.
type ReplicateMeta = (
    serde_json::Map<String, Value>,
    serde_json::Map<String, Value>,
    StartRegions,
    BrownianConfig,
);

/// Run `runs` replicates of `scene` (recording only replicate 0) and summarise them.
/// `progress` is called with the number of steps just completed (from any thread).
///
/// Every replicate polls `options.stop` between steps; once it is set no further replicate
/// starts (replicate 0 always runs: its world gives the ensemble's configuration), and the
/// summary is computed from what ran (the capture curves up to the fewest steps any
/// replicate made), marked `"interrupted": true`, `"interrupted_by"` and `"runs_requested"`.
/// A failing replicate stops the others at once.
///
/// # Errors
/// The first replicate's [`SimError`] in replicate order, as [`SimError::Partial`] with the
/// summary of what ran when replicate 0 got as far as its first step.
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
    // The replicates' flag: set by the caller's, or by a failing replicate.
    let stop = options
        .stop
        .as_ref()
        .map(StopFlag::child)
        .unwrap_or_default();
    let one = |k: u64| -> Option<Replicate> {
        if k > 0 && stop.is_stopped() {
            return None;
        }
        let opts = RunOptions {
            seed: Some(replicate_seed(seed, k)),
            record: if k == 0 { options.record.clone() } else { None },
            pipeline: options.pipeline.clone(),
            single_threaded: options.single_threaded || runs > 1,
            executor: options.executor,
            // only replicate 0 is recorded: the others start afresh from their seeds
            resume_from: if k == 0 {
                options.resume_from.clone()
            } else {
                None
            },
            plugins: options.plugins.clone(),
            stop: Some(stop.clone()),
            forces_unread: options.forces_unread,
        };
        let failed = |e: SimError| {
            stop.request_stop(format!("replicate {k} failed"));
            Some(e)
        };
        let mut sim = match Simulation::from_scene(scene, opts) {
            Ok(sim) => sim,
            Err(e) => {
                return Some(Replicate {
                    result: None,
                    meta: None,
                    error: failed(e),
                });
            }
        };
        let last = AtomicU64::new(0);
        let ran = sim.run(|w| {
            let s = w.resource::<StepClock>().step;
            if s % 100 == 0 {
                progress(s - last.swap(s, Ordering::Relaxed));
            }
        });
        let w = &sim.app.world;
        progress(w.resource::<StepClock>().step - last.load(Ordering::Relaxed));
        let meta = (k == 0).then(|| {
            let mut forces = serde_json::Map::new();
            crate::sim::force_keys(w, &mut forces);
            (
                forces,
                crate::sim::plugin_summary_keys(w),
                w.get_resource::<StartRegions>()
                    .cloned()
                    .unwrap_or_default(),
                w.resource::<BrownianConfig>().clone(),
            )
        });
        Some(Replicate {
            result: Some(run_result(w, sim.seed)),
            meta,
            error: ran.err().and_then(|e| failed(e.into_cause())),
        })
    };
    let replicates: Vec<_> = (0..runs).into_par_iter().map(one).collect();
    let mut out = Vec::with_capacity(replicates.len());
    let mut meta = None;
    let mut error = None;
    for r in replicates.into_iter().flatten() {
        if error.is_none() {
            error = r.error;
        }
        if r.meta.is_some() {
            meta = r.meta;
        }
        out.extend(r.result);
    }
    let Some((forces, extras, regions, config)) = meta else {
        return Err(error.unwrap_or(SimError::NothingToRun));
    };
    let mut summary = summary_of(&out, &regions, &config, started.elapsed().as_secs_f64());
    if let Value::Object(map) = &mut summary {
        for (k, v) in forces {
            map.entry(k).or_insert(v);
        }
        // the plugins' summary keys: the run's own when it is the only one, else replicate
        // 0's under `replicate_0` (a plugin's key need not be a mean over replicates)
        if runs > 1 && !extras.is_empty() {
            map.insert("replicate_0".into(), Value::Object(extras));
        } else {
            crate::sim::merge_plugin_keys(map, extras);
        }
    }
    let complete = out.len() as u64 == runs && out.iter().all(|r| r.steps >= config.steps);
    let interrupted = match &error {
        Some(_) => Some("error".to_string()),
        None if complete => None,
        None => Some(stop.reason().unwrap_or_else(|| "stop requested".into())),
    };
    if let Some(reason) = interrupted {
        mark_interrupted(&mut summary, &reason);
        summary["runs_requested"] = runs.into();
    }
    match error {
        Some(e) => Err(partial(e, summary)),
        None => Ok(summary),
    }
}
