//! The particle-fluid pipeline's run summary (JSON), replay of separation-error curves, and
//! its stability diagnostics.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::fluid::channel::systems::ChannelLiquid;
use magsep_systems::fluid::config::{HistoryChoice, Integrator, ParticleFluidConfig};
use magsep_systems::fluid::observe::{SeparationCurve, separation_scale};
use magsep_systems::fluid::spheroid_systems::SpheroidFluid;
use serde_json::{Value, json};

/// Per-particle details are listed for runs of at most this many particles.
pub const DETAIL_LIMIT: usize = 20;

/// The explicit scheme's history amplification factor
/// `r = 18 √(ρ_f μ Δt/π)/((ρ_p + ½ρ_f) d)` and the drag limit `2 τ_eff` \[s\] of a sphere
/// (D-002-2, docs/references.md): the forward-Euler step diverges once `0.76 r ≳ 1 − Δt/(2τ_eff)`.
pub fn explicit_stability(cfg: &ParticleFluidConfig, diameter: f64, density: f64) -> (f64, f64) {
    let (rho, mu) = (cfg.liquid.density, cfg.liquid.viscosity);
    let r = 18.0 * (rho * mu * cfg.dt / std::f64::consts::PI).sqrt()
        / ((density + 0.5 * rho) * diameter);
    let tau_eff = (density + 0.5 * rho) * diameter * diameter / (18.0 * mu);
    (r, 2.0 * tau_eff)
}

/// Every `k`-th element so that at most `max` remain (the last one always kept).
fn thin(v: &[f64], max: usize) -> Vec<f64> {
    if v.len() <= max {
        return v.to_vec();
    }
    let k = v.len().div_ceil(max);
    let mut out: Vec<f64> = v.iter().step_by(k).copied().collect();
    if !(v.len() - 1).is_multiple_of(k) {
        out.push(*v.last().unwrap_or(&f64::NAN));
    }
    out
}

/// The separation-error part of a summary.
pub fn separation_json(curve: &SeparationCurve) -> Value {
    let groups: Vec<Value> = curve
        .group_densities
        .iter()
        .zip(&curve.groups)
        .map(|(rho, e)| json!({"density": rho, "final_error": e.last(), "error": thin(e, 200)}))
        .collect();
    json!({
        "times": thin(&curve.times, 200),
        "error": thin(&curve.total, 200),
        "final_error": curve.total.last(),
        "time_to_0.02": curve.time_to(0.02),
        "groups": groups,
    })
}

/// Summary of a particle-fluid world.
pub fn run_summary(world: &World, seed: u64, wall_time_s: f64) -> Value {
    let Some(cfg) = world.get_resource::<ParticleFluidConfig>() else {
        return json!({"pipeline": "particle_fluid", "error": "no configuration"});
    };
    let clock = world.resource::<StepClock>();
    let stats = world
        .get_resource::<ParticleFluidStats>()
        .cloned()
        .unwrap_or_default();
    let mut rows: Vec<_> = world
        .iter_entities()
        .filter_map(|e| {
            Some((
                *e.get::<ParticleId>()?,
                e.get::<Position>()?.0,
                e.get::<Velocity>()?.0,
                *e.get::<InertialBody>()?,
                *e.get::<Levitation>()?,
            ))
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    let n = rows.len();
    let t_end = clock.time();
    let scale = separation_scale(cfg);
    let mut warnings: Vec<String> = Vec::new();
    // stability of the explicit scheme, per distinct (d, ρ_p)
    let mut seen: Vec<(f64, f64)> = Vec::new();
    for r in &rows {
        let key = (r.3.diameter, r.3.density);
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        let (amp, dt_max) = explicit_stability(cfg, key.0, key.1);
        if cfg.integrator == Integrator::Explicit
            && ((cfg.terms.history && 0.76 * amp >= 1.0 - cfg.dt / dt_max) || cfg.dt >= dt_max)
        {
            warnings.push(format!(
                "explicit scheme beyond its stability limit for d = {} m, rho_p = {}: history factor r = {amp:.3}, 2 tau_eff = {dt_max:.3e} s (use integrator = \"implicit\")",
                key.0, key.1
            ));
        }
    }
    if stats.max_reynolds > 800.0 {
        warnings.push(format!(
            "Reynolds number reached {:.0}, beyond the Schiller-Naumann range (800)",
            stats.max_reynolds
        ));
    }
    if stats.capped_steps > 0 {
        warnings.push(format!(
            "{} steps hit the collision-event cap (resting piles?); their leftover overlaps were projected away",
            stats.capped_steps
        ));
    }
    let (lo, hi) = cfg.magnet.valid_range();
    let outside = rows
        .iter()
        .filter(|r| {
            let y = cfg.magnet_y(r.1.z);
            y < lo || y > hi
        })
        .count();
    if outside > 0 {
        warnings.push(format!(
            "{outside} particles are outside the magnet model's range (inside a magnet?)"
        ));
    }
    let particles: Vec<Value> = if n <= DETAIL_LIMIT {
        rows.iter()
            .map(|r| {
                let settled = r.4.last_outside < t_end;
                json!({
                    "id": r.0.0,
                    "diameter": r.3.diameter,
                    "density": r.3.density,
                    "position": r.1.to_array(),
                    "velocity": r.2.to_array(),
                    "equilibrium_height": finite(r.4.equilibrium_height),
                    "levitation_time": if settled { json!(r.4.last_outside) } else { Value::Null },
                })
            })
            .collect()
    } else {
        Vec::new()
    };
    let settled = rows
        .iter()
        .filter(|r| r.4.equilibrium_height.is_finite() && r.4.last_outside < t_end)
        .count();
    let history = match cfg.history {
        HistoryChoice::Full => json!({"kind": "full"}),
        HistoryChoice::Window { window, tail } => {
            json!({"kind": "window", "window": window, "tail": tail})
        }
    };
    let steps = clock.step;
    json!({
        "pipeline": "particle_fluid",
        "seed": seed,
        "particles": n,
        "steps": steps,
        "time_step": cfg.dt,
        "simulated_time": t_end,
        "terms_used": terms_used(world, cfg),
        "integrator": cfg.integrator,
        "drag_law": cfg.drag_law,
        "history": if cfg.terms.history { history } else { Value::Null },
        "liquid": cfg.liquid,
        "liquid_solver": liquid_json(world, cfg),
        "magnet": cfg.magnet,
        "mid_plane": cfg.mid_plane,
        "sorting_range": cfg.magnet.sorting_range(&cfg.liquid, cfg.gravity),
        "max_density_gradient": cfg.magnet.max_density_gradient(&cfg.liquid, cfg.gravity),
        "separation_scale": scale,
        "settled_particles": settled,
        "particle_details": particles,
        "separation": world.get_resource::<SeparationCurve>().map(separation_json),
        "collisions": stats,
        "max_reynolds": stats.max_reynolds,
        "warnings": warnings,
        "wall_time_s": wall_time_s,
        "particle_steps_per_s": if wall_time_s > 0.0 { (n as f64 * steps as f64) / wall_time_s } else { 0.0 },
    })
}

/// The simulated liquid: options, grid, final state (`null` without one).
fn liquid_json(world: &World, cfg: &ParticleFluidConfig) -> Value {
    let Some(solver) = cfg.solver else {
        return Value::Null;
    };
    let Some(l) = world.get_resource::<ChannelLiquid>() else {
        // one-way: the liquid stays at rest and is not solved
        return json!({ "options": solver, "solved": false });
    };
    let u = l.solver.velocity();
    let max_speed = (0..u[0].len())
        .map(|n| (u[0][n] * u[0][n] + u[1][n] * u[1][n] + u[2][n] * u[2][n]).sqrt())
        .fold(0.0, f64::max);
    json!({
        "options": solver,
        "solved": true,
        "time": l.solver.time(),
        "steps": l.solver.steps(),
        "max_speed": finite(max_speed),
        "max_divergence": finite(l.solver.divergence_max()),
        "cfl": finite(l.solver.cfl()),
        "mean_velocity": l.solver.mean_velocity().to_array().map(finite),
        "last_feedback_force": l.last_feedback.to_array().map(finite),
    })
}

fn finite(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}

/// The terms switched on that can act on the scene's particles: lift, pitching torque and
/// magnetic torque act on spheroids only (the pipeline registers them only then).
fn terms_used(world: &World, cfg: &ParticleFluidConfig) -> Vec<&'static str> {
    let spheroids = world.iter_entities().any(|e| e.contains::<SpheroidFluid>());
    cfg.active_terms()
        .into_iter()
        .filter(|t| spheroids || !SPHEROID_ONLY_TERMS.contains(t))
        .collect()
}

/// Terms that act on spheroids only.
const SPHEROID_ONLY_TERMS: [&str; 3] = ["lift", "pitching_torque", "magnetic_torque"];
