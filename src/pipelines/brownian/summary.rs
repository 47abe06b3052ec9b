//! Results of brownian runs and their JSON summary (one run or an ensemble).

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use super::stats::{Estimate, mean_interval, wilson};

/// Start-region volume of each `[[particles]]` group \[m³\] (`None` for explicit points): the
/// weights of volume-weighted averages (a resource inserted at spawn).
#[derive(Resource, Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StartRegions(pub Vec<Option<f64>>);

/// What one run leaves for the summary (particles in `ParticleId` order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// Seed of the run.
    pub seed: u64,
    /// Completed steps.
    pub steps: u64,
    /// Time step \[s\].
    pub dt: f64,
    /// Group (`Species`) of each particle.
    pub species: Vec<u32>,
    /// Step during which each particle was captured.
    pub capture_steps: Vec<Option<u64>>,
    /// Whether each particle ends "Brownian" (thesis eq. 6.24: free, and its squared
    /// displacement from the start is below twice the free-diffusion value 2·6Dt).
    pub brownian: Vec<bool>,
    /// Stepper counters.
    pub stats: BrownianStats,
}

/// The Brownian criterion of thesis eq. 6.24, per particle: free, and its squared displacement
/// from the start after time `t` \[s\] below twice the free-diffusion value 2·6Dt,
/// `D = k_B T / (6 π η a)` for radius `a` \[m\]. `dx` \[m\] is the displacement; the mean
/// flow's advection `u t` is taken out of it (the criterion is about motion relative to the
/// liquid).
pub fn is_brownian(config: &BrownianConfig, a: f64, dx: DVec3, t: f64, captured: bool) -> bool {
    let d = config.kt() / (6.0 * std::f64::consts::PI * config.viscosity * a);
    let d2 = (dx - DVec3::from_array(config.flow) * t).length_squared();
    !captured && d2 < 2.0 * 6.0 * d * t
}

/// Gather the [`RunResult`] of a world after (or during) a brownian run.
pub fn run_result(world: &World, seed: u64) -> RunResult {
    let clock = *world.resource::<StepClock>();
    let config = world.resource::<BrownianConfig>();
    let t = clock.time();
    let mut rows: Vec<_> = world
        .iter_entities()
        .filter_map(|e| {
            Some((
                *e.get::<ParticleId>()?,
                e.get::<Species>()?.0,
                e.get::<Captured>()?.0,
                e.get::<Position>()?.0,
                e.get::<InitialPosition>()?.0,
                e.get::<Shape>()?.radius(),
            ))
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    let brownian = rows
        .iter()
        .map(|r| is_brownian(config, r.5, r.3 - r.4, t, r.2.is_some()))
        .collect();
    RunResult {
        seed,
        steps: clock.step,
        dt: clock.dt,
        species: rows.iter().map(|r| r.1).collect(),
        capture_steps: rows.iter().map(|r| r.2.map(|c| c.step)).collect(),
        brownian,
        stats: world
            .get_resource::<BrownianStats>()
            .cloned()
            .unwrap_or_default(),
    }
}

fn est(e: Estimate) -> Value {
    json!({"mean": e.mean, "lo": e.lo, "hi": e.hi})
}

/// The estimate of a per-run fraction `f(run) = k / n` (Wilson for one run).
fn fraction(results: &[RunResult], f: impl Fn(&RunResult) -> (u64, u64)) -> Estimate {
    if results.len() == 1 {
        let (k, n) = f(&results[0]);
        return wilson(k, n);
    }
    let v: Vec<f64> = results
        .iter()
        .map(|r| {
            let (k, n) = f(r);
            k as f64 / n.max(1) as f64
        })
        .collect();
    // a fraction's interval stays in [0, 1] (few runs give wide t intervals)
    let e = mean_interval(&v);
    Estimate {
        lo: e.lo.max(0.0),
        hi: e.hi.min(1.0),
        ..e
    }
}

/// Captured count among particles of `group` (all when `None`) by step `s`.
fn captured_by(r: &RunResult, group: Option<u32>, s: u64) -> (u64, u64) {
    let mut k = 0;
    let mut n = 0;
    for (c, g) in r.capture_steps.iter().zip(&r.species) {
        if group.is_none_or(|x| x == *g) {
            n += 1;
            if c.is_some_and(|c| c < s) {
                k += 1;
            }
        }
    }
    (k, n)
}

/// Sample steps of the capture curve: every `every` steps and the last.
pub fn curve_steps(steps: u64, every: u64) -> Vec<u64> {
    let mut v: Vec<u64> = (0..=steps).step_by(every.max(1) as usize).collect();
    if v.last() != Some(&steps) {
        v.push(steps);
    }
    v
}

/// The JSON summary of one or more runs of a scene with `groups` start regions.
pub fn summary_of(
    results: &[RunResult],
    regions: &StartRegions,
    config: &BrownianConfig,
    wall_time_s: f64,
) -> Value {
    let Some(first) = results.first() else {
        return json!({"pipeline": "brownian", "runs": 0});
    };
    let n = first.species.len();
    let steps = results.iter().map(|r| r.steps).min().unwrap_or(0);
    let ngroups = regions.0.len().max(1);
    let curve_at = curve_steps(steps, config.observe_every);
    let curve = |group: Option<u32>| {
        let pts: Vec<Estimate> = curve_at
            .iter()
            .map(|&s| fraction(results, |r| captured_by(r, group, s)))
            .collect();
        json!({
            "time_s": curve_at.iter().map(|&s| s as f64 * first.dt).collect::<Vec<_>>(),
            "captured_fraction": pts.iter().map(|e| e.mean).collect::<Vec<_>>(),
            "lo": pts.iter().map(|e| e.lo).collect::<Vec<_>>(),
            "hi": pts.iter().map(|e| e.hi).collect::<Vec<_>>(),
        })
    };
    let brownian_of = |group: Option<u32>| {
        fraction(results, |r| {
            let mut k = 0;
            let mut m = 0;
            for (b, g) in r.brownian.iter().zip(&r.species) {
                if group.is_none_or(|x| x == *g) {
                    m += 1;
                    k += u64::from(*b);
                }
            }
            (k, m)
        })
    };
    let mut groups = Vec::new();
    let mut weighted = Some((0.0, 0.0, 0.0));
    for g in 0..ngroups as u32 {
        let cap = fraction(results, |r| captured_by(r, Some(g), steps + 1));
        let brown = brownian_of(Some(g));
        let volume = regions.0.get(g as usize).copied().flatten();
        weighted = match (weighted, volume) {
            (Some((w, c, b)), Some(v)) => Some((w + v, c + v * cap.mean, b + v * brown.mean)),
            _ => None,
        };
        groups.push(json!({
            "group": g,
            "particles": first.species.iter().filter(|&&s| s == g).count(),
            "region_volume_m3": volume,
            "captured_fraction": est(cap),
            "brownian_fraction": est(brown),
            "capture_curve": curve(Some(g)),
        }));
    }
    let mut stats = BrownianStats::default();
    for r in results {
        let s = &r.stats;
        stats.substeps += s.substeps;
        stats.particle_substeps += s.particle_substeps;
        stats.rejections += s.rejections;
        stats.max_depth_reached = stats.max_depth_reached.max(s.max_depth_reached);
        stats.depth_limit_hits += s.depth_limit_hits;
        stats.force_evaluations += s.force_evaluations;
        stats.hard_core_sweeps += s.hard_core_sweeps;
        stats.krylov_iterations += s.krylov_iterations;
        stats.neighbour_list_builds += s.neighbour_list_builds;
        stats.mobility.clone_from(&s.mobility);
        stats.mobility_reason.clone_from(&s.mobility_reason);
    }
    let mut terms = vec!["field (|m| grad|B|)".to_string()];
    if let Some(c) = config.dipole_cutoff {
        terms.push(format!("dipole-dipole (cut-off {c} mean radii)"));
    }
    match config.contact {
        ContactModel::Mie { epsilon_kt, n, m } => {
            terms.push(format!("Mie({n}, {m}) contact, epsilon {epsilon_kt} kT"))
        }
        ContactModel::HardCore => terms.push("hard cores (overlap removal)".into()),
        ContactModel::None => {}
    }
    let mut warnings: Vec<String> = Vec::new();
    if stats.depth_limit_hits > 0 {
        warnings.push(format!(
            "{} sub-steps hit max_depth without meeting the tolerance: lower time_step or raise max_depth",
            stats.depth_limit_hits
        ));
    }
    let total_steps = (steps * results.len() as u64).max(1);
    let mut summary = json!({
        "pipeline": "brownian",
        "seed": first.seed,
        "runs": results.len(),
        "particles": n,
        "steps": steps,
        "dt_s": first.dt,
        "time_s": steps as f64 * first.dt,
        "mobility": {"method": stats.mobility, "reason": stats.mobility_reason},
        "forces": terms,
        "captured_interact": config.captured_interact,
        "step_control": config.step_control,
        "stepper": {
            "substeps_per_step": stats.substeps as f64 / total_steps as f64,
            "particle_substeps_per_step":
                stats.particle_substeps as f64 / (total_steps * (n as u64).max(1)) as f64,
            "rejections": stats.rejections,
            "force_evaluations": stats.force_evaluations,
            "max_depth_reached": stats.max_depth_reached,
            "depth_limit_hits": stats.depth_limit_hits,
            "hard_core_sweeps": stats.hard_core_sweeps,
            "krylov_iterations": stats.krylov_iterations,
            "neighbour_list_builds": stats.neighbour_list_builds,
        },
        "captured_fraction": est(fraction(results, |r| captured_by(r, None, steps + 1))),
        "volume_weighted_captured_fraction": weighted.filter(|w| w.0 > 0.0).map(|w| w.1 / w.0),
        "brownian_fraction": est(brownian_of(None)),
        "volume_weighted_brownian_fraction": weighted.filter(|w| w.0 > 0.0).map(|w| w.2 / w.0),
        "capture_curve": curve(None),
        "groups": groups,
        "warnings": warnings,
        "wall_time_s": wall_time_s,
    });
    // the mean flow's velocity [m/s], only where there is one (older summaries stay as they were)
    if config.flow != [0.0; 3] {
        summary["flow_velocity_m_s"] = json!(config.flow);
    }
    summary
}

/// Summary of the run in `world`.
pub fn run_summary(world: &World, seed: u64, wall_time_s: f64) -> Value {
    let regions = world
        .get_resource::<StartRegions>()
        .cloned()
        .unwrap_or_default();
    let config = world.resource::<BrownianConfig>();
    summary_of(&[run_result(world, seed)], &regions, config, wall_time_s)
}
