//! `magsep bench` and `magsep chart`: measured speed and accuracy-against-cost of the packing
//! kernels. Benchmarks time whole runs and single sweeps with `std::time::Instant`; they never
//! run inside unit tests.

use std::path::Path;
use std::time::Instant;

use magsep_components::packing::{OverlapRemovalScheme, PackingConfig, VolumeStepRule};
use magsep_components::shape::Shape;
use magsep_systems::analysis::{contact_numbers, nematic_order};
use magsep_systems::packing::compress::{DriverParams, compression_step, initial_status};
use magsep_systems::packing::fire::overlap_forces;
use magsep_systems::packing::insert::random_insertion;
use magsep_systems::packing::neighbour::NeighbourList;
use magsep_systems::packing::removal::overlap_scan;
use magsep_systems::packing::state::{Body, PackingState};
use magsep_systems::packing::systems::{MCM_SKIN, state_from_si};

use crate::pipelines::packing::ContainerSpec;
use crate::pipelines::packing::geometry::start_container;
use magsep_systems::rng::{DRIVER_STREAM, particle_stream};
use serde_json::{Value, json};

use crate::chart::{Chart, Figure, Line, Series, Style, write_svg};

/// Errors of `bench` and `chart`.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// Unknown target or bad option (exit 2).
    #[error("{0}")]
    Input(String),
    /// Failure while running (exit 1).
    #[error("{0}")]
    Runtime(String),
    /// Standard output is closed or full (exit 1; quietly for a closed pipe).
    #[error("cannot write to standard output: {0}")]
    Stdout(std::io::Error),
}

/// Result of one packing run on dense data.
#[derive(Debug, Clone)]
pub struct PackingRun {
    /// Final packing fraction.
    pub packing_fraction: f64,
    /// Extrapolated mean contact number.
    pub contact_number: f64,
    /// Nematic order of the rods.
    pub nematic_order: f64,
    /// Accepted compression steps.
    pub steps: u64,
    /// Single-particle moves (FIRE: iterations x N).
    pub attempts: u64,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// Pair contacts evaluated.
    pub contact_evaluations: u64,
    /// Of which the superquadric solver fell back to GJK/EPA.
    pub contact_fallbacks: u64,
    /// Final state (reduced units), wrapped.
    pub state: PackingState,
}

/// A monodisperse run: `n` particles of `shape` (reduced units, D = 1) with `config`,
/// stopped at jamming or when the packing fraction exceeds `stop_at`.
pub fn packing_run(
    n: usize,
    shape: Shape,
    config: &PackingConfig,
    seed: u64,
    stop_at: f64,
) -> Result<PackingRun, BenchError> {
    packing_run_in(
        n,
        shape,
        config,
        seed,
        stop_at,
        &ContainerSpec::PeriodicBox {},
    )
}

/// [`packing_run`] in the container `spec` (SI lengths = reduced units here, D = 1).
pub fn packing_run_in(
    n: usize,
    shape: Shape,
    config: &PackingConfig,
    seed: u64,
    stop_at: f64,
    spec: &ContainerSpec,
) -> Result<PackingRun, BenchError> {
    let bodies: Vec<Body> = (0..n).map(|_| Body::from_shape(&shape, 1.0)).collect();
    let vp: f64 = bodies.iter().map(|b| b.volume).sum();
    let container = start_container(spec, vp, config.initial_packing_fraction);
    let empty = state_from_si(&container, &[], &[], &[], 1.0);
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(seed, i)).collect();
    let t0 = Instant::now();
    let mut state = random_insertion(&bodies, empty, &mut rngs)
        .map_err(|e| BenchError::Runtime(e.to_string()))?;
    let p = DriverParams::from_config(config, 1.0);
    let mut list = NeighbourList::new(MCM_SKIN);
    let mut rng = particle_stream(seed, DRIVER_STREAM);
    let mut st = initial_status(&p, &state);
    while st.stopped.is_none() && st.packing_fraction < stop_at {
        compression_step(&p, &mut st, &mut state, &mut list, &mut rng);
    }
    let wall = t0.elapsed().as_secs_f64();
    state.wrap_all();
    let cn = contact_numbers(&state);
    let axes: Vec<_> = (0..n)
        .filter(|&i| state.bodies[i].half_length > 0.0)
        .map(|i| state.axis(i))
        .collect();
    Ok(PackingRun {
        packing_fraction: state.packing_fraction(),
        contact_number: cn.extrapolated,
        nematic_order: nematic_order(&axes),
        steps: st.compression_steps,
        attempts: st.attempts,
        wall_time_s: wall,
        contact_evaluations: st.contact_evaluations,
        contact_fallbacks: st.contact_fallbacks,
        state,
    })
}

/// Spheres of diameter 1 at packing fraction `phi` (random insertion), with their list.
fn loose_spheres(
    n: usize,
    phi: f64,
    seed: u64,
) -> Result<(PackingState, NeighbourList), BenchError> {
    let bodies: Vec<Body> = (0..n)
        .map(|_| Body::from_shape(&Shape::Sphere { radius: 0.5 }, 1.0))
        .collect();
    let vp: f64 = bodies.iter().map(|b| b.volume).sum();
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(seed, i)).collect();
    let mut state = random_insertion(
        &bodies,
        PackingState::periodic_cube((vp / phi).cbrt()),
        &mut rngs,
    )
    .map_err(|e| BenchError::Runtime(e.to_string()))?;
    let mut list = NeighbourList::new(MCM_SKIN);
    list.build(&mut state);
    Ok((state, list))
}

/// Writes `text` and a newline to standard output and flushes it: a closed or full standard
/// output is [`BenchError::Stdout`], never a panic.
///
/// # Errors
/// [`BenchError::Stdout`].
pub fn say(text: impl std::fmt::Display) -> Result<(), BenchError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}")
        .and_then(|()| out.flush())
        .map_err(BenchError::Stdout)
}

/// Print one measurement (JSON line or a table row) and keep it.
///
/// # Errors
/// [`BenchError::Stdout`].
pub(crate) fn emit(rows: &mut Vec<Value>, as_json: bool, row: Value) -> Result<(), BenchError> {
    if as_json {
        say(&row)?;
    } else {
        let name = row["name"].as_str().unwrap_or("");
        let figures: Vec<String> = row
            .as_object()
            .map(|o| {
                o.iter()
                    .filter(|(k, _)| *k != "name")
                    .map(|(k, v)| format!("{k}={v}"))
                    .collect()
            })
            .unwrap_or_default();
        say(format!("{name:<32} {}", figures.join("  ")))?;
    }
    rows.push(row);
    Ok(())
}

/// Least-squares slope of log(y) against log(x).
pub fn log_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0.ln(), a.1 + p.1.ln()));
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + p.0.ln().powi(2), a.1 + p.0.ln() * p.1.ln())
    });
    (n * sxy - sx * sy) / (n * sxx - sx * sx)
}

/// The benchmarks of `magsep bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchKind {
    /// Packing to jamming and the cost of a sweep against N.
    Packing,
    /// The cylinder field kernel.
    Field,
    /// Brownian dynamics without and with hydrodynamics.
    Brownian,
    /// Brownian dynamics on the configuration of the LAMMPS peer only (`lammps_mirror` rows).
    BrownianPeer,
    /// The history force and the particle-fluid pipeline.
    ParticleFluid,
    /// The channel-flow solver of the coupled liquid and the coupling per particle.
    Fluid,
    /// Framework overhead: wall time per step of a simple particle-fluid scene against N.
    Overhead,
    /// Recording overhead of each pipeline's representative scene at its `record.every`.
    Recording,
    /// Only the dense settling bed rows of `particle-fluid` (10⁴ spheres with collisions).
    SettlingBed,
}

/// The charts of `magsep chart`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ChartKind {
    /// Packing fraction against wall time; shape trends.
    Packing,
    /// Spherocylinders in hard cylinders.
    Cylinder,
    /// Spherocylinders in hard wedges.
    Wedge,
    /// Superballs.
    Superballs,
    /// Superquadric contact: failures and cost.
    SqContact,
    /// Field accuracy against cost.
    Field,
    /// Brownian capture curves.
    Brownian,
    /// Brownian mobilities: error against cost.
    BrownianCost,
    /// Single-sphere levitation.
    Levitation,
    /// The Basset history method.
    History,
    /// Binary collisions.
    Collisions,
    /// Many-particle density separation.
    Separation,
    /// Flat particles (spheroids): levitation, orientation, force budget, separation.
    Flakes,
    /// Binary collisions of 1:2 spheroids: delays against the impact factor.
    FlakeCollisions,
    /// Models of the 1:10 spheroid's drag, lift and torque: error against cost.
    SpheroidModel,
    /// The two-way coupled liquid: settling against the grid, separation one-way against two-way.
    Coupling,
    /// The channel solver: accuracy against cost, stability of the time step.
    LiquidSolver,
}

/// `magsep bench KIND [--json] [--quick]`.
///
/// # Errors
/// [`BenchError`] of the benchmark.
pub fn bench(what: BenchKind, as_json: bool, quick: bool) -> Result<(), BenchError> {
    match what {
        BenchKind::Field => return crate::studies::bench_field::bench_field(as_json, quick),
        BenchKind::Brownian => {
            return crate::studies::bench_brownian::bench_brownian(as_json, quick);
        }
        BenchKind::BrownianPeer => {
            return crate::studies::bench_brownian::bench_brownian_peer(as_json, quick);
        }
        BenchKind::ParticleFluid => {
            return crate::studies::fluid_charts::bench_particle_fluid(as_json, quick);
        }
        BenchKind::Fluid => return crate::studies::liquid::bench::bench_fluid(as_json, quick),
        BenchKind::Overhead => {
            return crate::studies::bench_overhead::bench_overhead(as_json, quick);
        }
        BenchKind::Recording => {
            return crate::studies::bench_overhead::bench_recording(as_json, quick);
        }
        BenchKind::SettlingBed => {
            return crate::studies::fluid_charts::bench_settling_bed(as_json, quick);
        }
        BenchKind::Packing => {}
    }
    let threads = rayon::current_num_threads();
    let mut rows = Vec::new();
    let (n_small, n_large) = if quick { (100, 1000) } else { (500, 10_000) };
    // 1. spheres to the jammed state: the shipped scene through the scene pipeline
    let (summary, wall) = crate::studies::bench_scene::spheres_scene_run(n_small)?;
    let attempts = summary["attempts"].as_f64().unwrap_or(f64::NAN);
    emit(
        &mut rows,
        as_json,
        json!({"name": "packing_spheres_to_jamming", "particles": n_small, "threads": 1, "wall_time_s": wall, "attempts_per_s": attempts / wall, "packing_fraction": summary["packing_fraction"], "mean_contact_number": summary["mean_contact_number"], "steps": summary["compression_steps"], "path": "scene"}),
    )?;
    // 1b. superballs (thesis size, revised scheme) through the scene pipeline, 1 and 2 threads
    let (n_sb, sb_steps) = if quick { (100, 60) } else { (750, 300) };
    let mut sb_phi = Vec::new();
    for t in [1, 2] {
        let (summary, wall) = crate::studies::bench_scene::superballs_scene_run(n_sb, sb_steps, t)?;
        let attempts = summary["attempts"].as_f64().unwrap_or(f64::NAN);
        sb_phi.push(summary["packing_fraction"].clone());
        emit(
            &mut rows,
            as_json,
            json!({"name": "packing_superballs_steps", "particles": n_sb, "threads": t, "steps": sb_steps, "wall_time_s": wall, "attempts_per_s": attempts / wall, "packing_fraction": summary["packing_fraction"], "contact_evaluations": summary["contact_evaluations"], "same_as_one_thread": sb_phi[0] == summary["packing_fraction"], "path": "scene"}),
        )?;
    }
    let cfg = PackingConfig::defaults_for(n_small, 1.0);
    // 2. rods of aspect ratio 5 to the jammed state
    let rod = Shape::Spherocylinder {
        radius: 0.5,
        half_length: 2.0,
    };
    let r = packing_run(n_small, rod, &cfg, 1, f64::INFINITY)?;
    emit(
        &mut rows,
        as_json,
        json!({"name": "packing_rods_aspect5_to_jamming", "particles": n_small, "threads": 1, "wall_time_s": r.wall_time_s, "attempts_per_s": r.attempts as f64 / r.wall_time_s, "packing_fraction": r.packing_fraction, "steps": r.steps}),
    )?;
    // 3. many spheres to phi = 0.55 (the dense end costs most; this bounds the run time)
    let cfg_l = PackingConfig::defaults_for(n_large, 1.0);
    let r = packing_run(n_large, Shape::Sphere { radius: 0.5 }, &cfg_l, 1, 0.55)?;
    emit(
        &mut rows,
        as_json,
        json!({"name": "packing_spheres_to_phi_0.55", "particles": n_large, "threads": 1, "wall_time_s": r.wall_time_s, "attempts_per_s": r.attempts as f64 / r.wall_time_s, "packing_fraction": r.packing_fraction, "steps": r.steps}),
    )?;
    // 4. cost of one sweep against N (phi = 0.35, overlaps created by a 1 % compression)
    let sizes: &[usize] = if quick {
        &[250, 1000, 4000]
    } else {
        &[500, 2000, 8000, 32_000]
    };
    let mut fire_pts = Vec::new();
    let mut scan_pts = Vec::new();
    for &n in sizes {
        let (mut state, mut list) = loose_spheres(n, 0.35, 2)?;
        let reps = (200_000 / n).max(3);
        let mut f = vec![glam::DVec3::ZERO; n];
        let mut t = vec![glam::DVec3::ZERO; n];
        let t0 = Instant::now();
        for _ in 0..reps {
            std::hint::black_box(overlap_forces(&state, &mut list, &mut f, &mut t));
        }
        let per_force = t0.elapsed().as_secs_f64() / reps as f64;
        let mut flags = Vec::new();
        let t0 = Instant::now();
        for _ in 0..reps {
            std::hint::black_box(overlap_scan(&state, &mut list, 1e-4, &mut flags));
        }
        let per_scan = t0.elapsed().as_secs_f64() / reps as f64;
        let t0 = Instant::now();
        let builds = reps.min(20);
        for _ in 0..builds {
            list.build(&mut state);
        }
        let per_build = t0.elapsed().as_secs_f64() / builds as f64;
        fire_pts.push((n as f64, per_force));
        scan_pts.push((n as f64, per_scan + per_build / 10.0));
        emit(
            &mut rows,
            as_json,
            json!({"name": "packing_sweep_cost", "particles": n, "threads": 1, "fire_iteration_s": per_force, "overlap_scan_s": per_scan, "neighbour_build_s": per_build}),
        )?;
    }
    emit(
        &mut rows,
        as_json,
        json!({"name": "packing_sweep_cost_exponent", "threads": 1, "fire_iteration_exponent": log_slope(&fire_pts), "overlap_scan_exponent": log_slope(&scan_pts), "sizes": sizes}),
    )?;
    let _ = threads;
    Ok(())
}

/// `magsep chart KIND --out DIR [--quick]`.
///
/// # Errors
/// [`BenchError::Runtime`] for I/O or a failed run.
pub fn chart(what: ChartKind, out: &Path, quick: bool) -> Result<(), BenchError> {
    use crate::studies::{fluid_charts as fc, packing_charts as pc};
    match what {
        ChartKind::BrownianCost => {
            return crate::studies::bench_brownian::chart_brownian_cost(out, quick);
        }
        ChartKind::Brownian => return crate::studies::brownian_chart::chart_brownian(out, quick),
        ChartKind::Cylinder => return pc::chart_cylinder(out, quick),
        ChartKind::Wedge => return pc::chart_wedge(out, quick),
        ChartKind::Superballs => return pc::chart_superballs(out, quick),
        ChartKind::Levitation => return fc::chart_levitation(out, quick),
        ChartKind::History => return fc::chart_history(out, quick),
        ChartKind::Collisions => return fc::chart_collisions(out, quick),
        ChartKind::Separation => return fc::chart_separation(out, quick),
        ChartKind::Flakes => return fc::chart_flakes(out, quick),
        ChartKind::FlakeCollisions => return fc::chart_flake_collisions(out, quick),
        ChartKind::Coupling => return crate::studies::liquid::chart::chart_coupling(out, quick),
        ChartKind::LiquidSolver => {
            return crate::studies::liquid::solver_chart::chart_liquid_solver(out, quick);
        }
        ChartKind::SpheroidModel => return fc::chart_spheroid_model(out, quick),
        ChartKind::SqContact => {
            std::fs::create_dir_all(out)
                .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
            let study = crate::studies::sq_study::run_sq_contact_study(quick);
            let summary = crate::studies::sq_study::write_sq_study(&study, out)
                .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
            return say(summary);
        }
        ChartKind::Field => {
            let rows = crate::studies::bench_field::chart_field(out, quick)?;
            return say(
                json!({"charts": [out.join("field_error_vs_cost.svg").display().to_string()], "points": rows}),
            );
        }
        ChartKind::Packing => {}
    }
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let sphere = Shape::Sphere { radius: 0.5 };
    let n = if quick { 60 } else { 200 };
    // 1. speed against accuracy: final phi against wall time
    let variants: Vec<(&str, OverlapRemovalScheme, VolumeStepRule, Vec<u64>)> = vec![
        (
            "FIRE, adaptive dV",
            OverlapRemovalScheme::Fire,
            VolumeStepRule::Adaptive,
            vec![500, 2000, 20_000],
        ),
        (
            "FIRE, fixed dV",
            OverlapRemovalScheme::Fire,
            VolumeStepRule::Fixed,
            vec![2000, 20_000],
        ),
        (
            "revised, adaptive dV",
            OverlapRemovalScheme::Revised,
            VolumeStepRule::Adaptive,
            vec![50, 200, 1000],
        ),
        (
            "revised, fixed dV",
            OverlapRemovalScheme::Revised,
            VolumeStepRule::Fixed,
            vec![50, 200],
        ),
        (
            "original, adaptive dV",
            OverlapRemovalScheme::Original,
            VolumeStepRule::Adaptive,
            vec![50, 200, 1000],
        ),
        (
            "original, fixed dV",
            OverlapRemovalScheme::Original,
            VolumeStepRule::Fixed,
            vec![50, 200],
        ),
    ];
    let mut speed = Chart::new(format!("Spheres, N = {n}: final packing fraction against cost (labels: attempts per particle per step)"))
        .x_label("wall time, one thread [s]")
        .y_label("final packing fraction")
        .x_log(true);
    let mut summary = Vec::new();
    for (name, scheme, rule, budgets) in variants {
        let budgets: Vec<u64> = if quick {
            budgets.into_iter().take(2).collect()
        } else {
            budgets
        };
        let mut pts = Vec::new();
        for b in budgets {
            let mut cfg = PackingConfig::defaults_for(n, 1.0);
            cfg.scheme = scheme;
            cfg.volume_step_rule = rule;
            cfg.max_attempts = b * n as u64;
            let r = packing_run(n, sphere, &cfg, 1, f64::INFINITY)?;
            eprintln!(
                "{name} budget {b}N: phi {:.4} in {:.2} s",
                r.packing_fraction, r.wall_time_s
            );
            summary.push(json!({"variant": name, "budget_per_particle": b, "packing_fraction": r.packing_fraction, "wall_time_s": r.wall_time_s}));
            pts.push((r.wall_time_s, r.packing_fraction));
        }
        let style = if name.contains("fixed") {
            Style::Dashed
        } else {
            Style::LineMarkers
        };
        speed = speed.series(Series::new(name, pts).style(style));
    }
    speed = speed.line(
        Line::from_fn("random close packing 0.64", 1e-3, 1e4, 2, true, |_| 0.64).dashed(true),
    );
    let p1 = out.join("packing_speed_accuracy.svg");
    write_svg(&p1, &speed.to_svg(900.0, 560.0)).map_err(|e| BenchError::Runtime(e.to_string()))?;
    // 2. phi and <C> against the aspect ratio, with the random contact equation
    let ratios: Vec<f64> = if quick {
        vec![1.0, 1.5, 3.0, 10.0]
    } else {
        vec![
            1.0, 1.2, 1.4, 1.6, 2.0, 3.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0,
        ]
    };
    let nr = if quick { 60 } else { 200 };
    let (mut phi, mut cn, mut s) = (Vec::new(), Vec::new(), Vec::new());
    for &l in &ratios {
        let shape = if l == 1.0 {
            sphere
        } else {
            Shape::Spherocylinder {
                radius: 0.5,
                half_length: 0.5 * (l - 1.0),
            }
        };
        let mut cfg = PackingConfig::defaults_for(nr, 1.0);
        if l >= 50.0 {
            cfg.initial_packing_fraction = 0.005;
        } else if l >= 10.0 {
            cfg.initial_packing_fraction = 0.01;
        }
        let r = packing_run(nr, shape, &cfg, 1, f64::INFINITY)?;
        eprintln!(
            "aspect ratio {l}: phi {:.4}, <C> {:.2}, S {:.3} in {:.1} s",
            r.packing_fraction, r.contact_number, r.nematic_order, r.wall_time_s
        );
        summary.push(json!({"aspect_ratio": l, "packing_fraction": r.packing_fraction, "mean_contact_number": r.contact_number, "nematic_order": r.nematic_order, "wall_time_s": r.wall_time_s}));
        phi.push((l, r.packing_fraction));
        cn.push((l, r.contact_number));
        s.push((l, r.nematic_order));
    }
    let fig = Figure::new(format!("Spherocylinders, N = {nr}, periodic"), 2)
        .panel(
            Chart::new("packing fraction")
                .x_label("aspect ratio (L + D) / D")
                .y_label("phi")
                .x_log(true)
                .series(Series::new("MCM (FIRE)", phi))
                .line(
                    Line::from_fn(
                        "random contact: phi = 5 / (aspect - 1)",
                        3.0,
                        30.0,
                        40,
                        true,
                        |x| 5.0 / (x - 1.0),
                    )
                    .dashed(true),
                ),
        )
        .panel(
            Chart::new("mean contact number and nematic order")
                .x_label("aspect ratio (L + D) / D")
                .y_label("<C> (extrapolated), S")
                .x_log(true)
                .series(Series::new("<C>", cn))
                .series(Series::new("nematic order S", s).style(Style::Markers))
                .line(
                    Line::from_fn("random contact: <C> = 10", 10.0, 30.0, 2, true, |_| 10.0)
                        .dashed(true),
                )
                .line(
                    Line::from_fn("isostatic spheres: 6", 1.0, 1.5, 2, true, |_| 6.0).dashed(true),
                ),
        );
    let p2 = out.join("packing_aspect_ratio.svg");
    write_svg(&p2, &fig.to_svg(560.0, 420.0)).map_err(|e| BenchError::Runtime(e.to_string()))?;
    say(json!({"charts": [p1.display().to_string(), p2.display().to_string()], "runs": summary}))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_slope_recovers_power_laws() {
        let pts: Vec<(f64, f64)> = [1.0, 10.0, 100.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.3)))
            .collect();
        assert!((log_slope(&pts) - 1.3).abs() < 1e-12);
    }

    #[test]
    fn removal_budget_of_fire_counts_iterations_times_n() {
        let (mut state, mut list) = loose_spheres(50, 0.3, 1).unwrap();
        state.scale(glam::DVec3::splat(0.9));
        let mut cfg = PackingConfig::defaults_for(50, 1.0);
        cfg.max_attempts = 50 * 3;
        let p = DriverParams::from_config(&cfg, 1.0);
        let mut rng = particle_stream(1, 1);
        let out =
            magsep_systems::packing::compress::run_removal(&p, &mut state, &mut list, &mut rng);
        assert!(out.attempts <= 150 && out.attempts % 50 == 0);
    }
}
