//! `magsep bench brownian` and `magsep chart brownian-cost`: throughput of the brownian
//! pipeline and the cost and accuracy of its hydrodynamic mobilities.
//!
//! * [`bench_brownian`]: (a) particle-steps per second of the full pipeline
//!   (`Simulation::from_scene` + `step()`) for 10⁴ saturated 75 nm spheres with dipole forces
//!   (cut-off 30 radii), Mie contacts, a uniform 1 T field, no fibres, free draining, at
//!   volume fraction 1e-3, fixed and adaptive stepping, on rayon pools of 1 and 2 threads,
//!   with the mean number of dipole neighbours; (b) seconds per step of the mobility work
//!   (`Mobility::new` + one `noise` + one `apply`) of Cholesky, TEA and Krylov against N,
//!   with the fitted cost exponent per method.
//! * [`chart_brownian_cost`]: error of the Brownian covariance ‖B Bᵀ − μ‖_F / ‖μ‖_F against
//!   the cost of one step (prepare + noise) for each method, at two volume fractions.
//!
//! Both have variants with explicit sizes ([`bench_brownian_with`],
//! [`chart_brownian_cost_with`]) for tests.

mod cost;
mod hi;
mod lammps_case;
mod pipeline;

use std::path::Path;

use magsep_systems::brownian::hydro::MobilityMethod;
use serde_json::{Value, json};

use crate::studies::bench::{BenchError, emit, log_slope};

pub use cost::{CostChartSizes, CostPoint, cost_points};
pub use hi::{
    MobilityStepTime, product_error, random_configuration, time_mobility_step,
    time_mobility_step_with,
};
pub use lammps_case::lammps_mirror_scene;
pub use pipeline::{PipelineRate, free_draining_scene, mean_neighbours, pipeline_rate};

/// Particle radius of every benchmark \[m\].
pub const RADIUS: f64 = 75e-9;
/// Saturated moment of the pipeline benchmark [A m²].
pub const MOMENT: f64 = 0.87e-16;
/// Viscosity of water [Pa s].
pub const VISCOSITY: f64 = 1e-3;
/// Volume fraction of the pipeline benchmark.
pub const PIPELINE_VOLUME_FRACTION: f64 = 1e-3;
/// Volume fraction of the HI cost benchmark.
pub const HI_VOLUME_FRACTION: f64 = 1e-2;
/// Dipole cut-off of the pipeline benchmark [mean radii of a pair].
pub const DIPOLE_CUTOFF: f64 = 30.0;
/// Time step of the pipeline benchmark \[s\].
pub const TIME_STEP: f64 = 1e-6;
/// Krylov tolerance of the HI cost benchmark (the scene default).
pub const KRYLOV_TOLERANCE: f64 = 1e-6;
/// Product tolerance of the spectral Ewald rows.
pub const SPECTRAL_EWALD_TOLERANCE: f64 = 1e-4;
/// Krylov tolerance of the spectral Ewald rows (covariance accuracy of order 1e-3).
pub const SPECTRAL_KRYLOV_TOLERANCE: f64 = 1e-3;
/// LAMMPS's Brownian integrator with dipoles, particle-steps per second per core (the goal
/// figure the pipeline rate is compared with).
pub const LAMMPS_REFERENCE_PER_CORE: f64 = 1.1e6;

/// An equivalent LAMMPS input (reduced units, σ = 2R = 1, k_B T = 1): 10⁴ spheres at volume
/// fraction 1e-3 (box edge 173.6 σ), WCA core, point dipoles along x with the coupling of
/// the benchmark (λ = μ₀m²/(4π(2R)³k_BT) ≈ 54.5, so μ* = √λ ≈ 7.38), dipole cut-off 30 R =
/// 15 σ, time step giving the same Brownian displacement per step (√(2D dt) = 0.016 σ).
/// Not run by the benchmark: Debian's `lammps` 20220106 lacks the BROWNIAN package
/// (`fix brownian/sphere`), although it has `pair_style lj/cut/dipole/cut`.
pub const LAMMPS_INPUT: &str = "\
units           lj
atom_style      hybrid sphere dipole
dimension       3
boundary        p p p
region          box block 0 173.6 0 173.6 0 173.6
create_box      1 box
create_atoms    1 random 10000 12345 NULL overlap 1.0 maxtry 100
set             type 1 diameter 1.0
set             type 1 dipole 7.38 0.0 0.0
pair_style      lj/cut/dipole/cut 1.122462 15.0
pair_coeff      * * 1.0 1.0
pair_modify     shift yes
neighbor        1.0 bin
neigh_modify    every 1 delay 0 check yes
fix             1 all brownian/sphere 1.0 4928459 gamma_t 1.0 gamma_r 3.0
timestep        1.28e-4
thermo          1000
run             200
run             2000
";

/// Sizes of [`bench_brownian_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct BrownianBenchSizes {
    /// Particles of the pipeline benchmark.
    pub pipeline_n: usize,
    /// Steps before timing.
    pub warmup_steps: usize,
    /// Wall time of stepping per measurement \[s\] (at least 3 steps).
    pub pipeline_seconds: f64,
    /// Rayon pool sizes.
    pub threads: Vec<usize>,
    /// Particle numbers of the HI cost benchmark.
    pub hi_sizes: Vec<usize>,
    /// Mobility methods of the HI cost benchmark.
    pub hi_methods: Vec<MobilityMethod>,
    /// Particle numbers of the spectral Ewald rows (each at every thread count).
    pub spectral_sizes: Vec<usize>,
    /// Lattice cells per side of the LAMMPS-mirror case (`ncell³` particles; 0: not run).
    pub mirror_ncell: usize,
}

impl BrownianBenchSizes {
    /// The full benchmark: N = 10⁴, ~3 s per measurement, HI at N = 100, 1000, 3000.
    pub fn full() -> Self {
        Self {
            pipeline_n: 10_000,
            warmup_steps: 3,
            pipeline_seconds: 3.0,
            threads: vec![1, 2],
            hi_sizes: vec![100, 1000, 3000],
            hi_methods: vec![
                MobilityMethod::Cholesky,
                MobilityMethod::Tea,
                MobilityMethod::Krylov,
            ],
            spectral_sizes: vec![1000, 10_000],
            mirror_ncell: 22,
        }
    }

    /// The CI smoke run: N = 2000, 0.5 s per measurement, HI at N = 100, 300.
    pub fn quick() -> Self {
        Self {
            pipeline_n: 2000,
            warmup_steps: 2,
            pipeline_seconds: 0.5,
            hi_sizes: vec![100, 300],
            spectral_sizes: vec![300],
            ..Self::full()
        }
    }
}

/// Repetitions of the HI timing at `n` particles (one at the largest sizes).
fn hi_reps(n: usize) -> usize {
    match n {
        0..=200 => 5,
        201..=1000 => 2,
        _ => 1,
    }
}

/// The 1-minute load average (Linux `/proc/loadavg`; NaN elsewhere): the machine is shared,
/// so a rate is only as good as the load it was measured under.
fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// The scene name of a method (`free_draining`, `cholesky`, `tea`, `krylov`).
pub fn method_name(m: MobilityMethod) -> &'static str {
    match m {
        MobilityMethod::FreeDraining => "free_draining",
        MobilityMethod::Cholesky => "cholesky",
        MobilityMethod::Tea => "tea",
        MobilityMethod::Krylov => "krylov",
        MobilityMethod::SpectralEwald => "spectral_ewald",
    }
}

/// `magsep bench brownian [--json] [--quick]`.
///
/// # Errors
/// [`BenchError::Runtime`] when a scene cannot be built or run, or a mobility fails.
pub fn bench_brownian(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let sizes = if quick {
        BrownianBenchSizes::quick()
    } else {
        BrownianBenchSizes::full()
    };
    bench_brownian_with(&sizes, as_json).map(|_| ())
}

/// The benchmark at explicit sizes; prints every row (JSON line or table row) and returns them.
///
/// # Errors
/// As [`bench_brownian`].
pub fn bench_brownian_with(
    sizes: &BrownianBenchSizes,
    as_json: bool,
) -> Result<Vec<Value>, BenchError> {
    let mut rows = Vec::new();
    let n = sizes.pipeline_n;
    let edge = pipeline::box_edge(n, RADIUS, PIPELINE_VOLUME_FRACTION);
    let mut last_positions = Vec::new();
    // (a) the full pipeline, free draining, dipoles
    for control in ["fixed", "adaptive", "multirate"] {
        let scene_text = free_draining_scene(n, control, 1);
        let scene = crate::scene::parse_scene(&scene_text, &Default::default())
            .map_err(|e| BenchError::Runtime(format!("bench scene: {e}")))?;
        for &threads in &sizes.threads {
            let (r, x) =
                pipeline_rate(&scene, threads, sizes.warmup_steps, sizes.pipeline_seconds)?;
            emit(
                &mut rows,
                as_json,
                json!({
                    "name": format!("brownian_free_draining_dipoles_{control}"),
                    "bench": "brownian",
                    "case": "free_draining_dipoles",
                    "step_control": control,
                    "threads": threads,
                    "n": n,
                    "volume_fraction": PIPELINE_VOLUME_FRACTION,
                    "box_edge_m": edge,
                    "dt_s": TIME_STEP,
                    "steps": r.steps,
                    "wall_time_s": r.seconds,
                    "particle_steps_per_s": r.particle_steps_per_s,
                    "particle_steps_per_s_per_thread": r.particle_steps_per_s / threads as f64,
                    "substeps_per_step": r.substeps_per_step,
                    "particle_substeps_per_step": r.particle_substeps_per_step,
                    "force_evaluations_per_step": r.force_evaluations_per_step,
                    "lammps_reference_per_core": LAMMPS_REFERENCE_PER_CORE,
                    "load_average_1min": load_average(),
                }),
            )?;
            last_positions = x;
        }
    }
    mirror_rows(sizes, as_json, &mut rows)?;
    let rc = DIPOLE_CUTOFF * RADIUS;
    let initial = pipeline::initial_positions(n, 1)?;
    emit(
        &mut rows,
        as_json,
        json!({
            "name": "brownian_dipole_neighbours",
            "bench": "brownian",
            "case": "dipole_neighbours",
            "n": n,
            "cutoff_m": rc,
            "mean_neighbours_start": mean_neighbours(&initial, rc),
            "mean_neighbours_end": mean_neighbours(&last_positions, rc),
            "bulk_expectation": PIPELINE_VOLUME_FRACTION * DIPOLE_CUTOFF.powi(3),
        }),
    )?;
    // (b) cost of the mobility work of one step
    let threads = rayon::current_num_threads();
    for &method in &sizes.hi_methods {
        let mut pts = Vec::new();
        for &hn in &sizes.hi_sizes {
            let x = random_configuration(hn, RADIUS, HI_VOLUME_FRACTION, 7 + hn as u64);
            let t = time_mobility_step(
                method,
                &x,
                &vec![RADIUS; hn],
                VISCOSITY,
                KRYLOV_TOLERANCE,
                hi_reps(hn),
            )?;
            pts.push((hn as f64, t.total_s));
            emit(
                &mut rows,
                as_json,
                t.with_fields(
                    json!({
                        "name": format!("brownian_hi_{}", method_name(method)),
                        "bench": "brownian",
                        "case": "hi",
                        "method": method_name(method),
                        "n": hn,
                        "threads": threads,
                        "volume_fraction": HI_VOLUME_FRACTION,
                    }),
                    hi_reps(hn),
                ),
            )?;
        }
        if pts.len() >= 2 {
            emit(
                &mut rows,
                as_json,
                json!({
                    "name": format!("brownian_hi_exponent_{}", method_name(method)),
                    "bench": "brownian",
                    "case": "hi_exponent",
                    "method": method_name(method),
                    "sizes": sizes.hi_sizes,
                    "exponent": log_slope(&pts),
                }),
            )?;
        }
    }
    spectral_rows(sizes, as_json, &mut rows)?;
    Ok(rows)
}

/// (c) the matrix-free spectral Ewald mobility at [`SPECTRAL_EWALD_TOLERANCE`] and
/// [`SPECTRAL_KRYLOV_TOLERANCE`], at every size and thread count, with its product error
/// against the direct RPY sum.
fn spectral_rows(
    sizes: &BrownianBenchSizes,
    as_json: bool,
    rows: &mut Vec<Value>,
) -> Result<(), BenchError> {
    use magsep_systems::brownian::hydro::MobilityOptions;
    let options = MobilityOptions {
        krylov_tolerance: SPECTRAL_KRYLOV_TOLERANCE,
        ewald_tolerance: SPECTRAL_EWALD_TOLERANCE,
        ..MobilityOptions::default()
    };
    let method = MobilityMethod::SpectralEwald;
    for &hn in &sizes.spectral_sizes {
        let x = random_configuration(hn, RADIUS, HI_VOLUME_FRACTION, 7 + hn as u64);
        let radii = vec![RADIUS; hn];
        let error = product_error(method, &x, &radii, VISCOSITY, options)?;
        for &threads in &sizes.threads {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| BenchError::Runtime(format!("thread pool: {e}")))?;
            let t = pool.install(|| {
                time_mobility_step_with(method, &x, &radii, VISCOSITY, options, hi_reps(hn))
            })?;
            emit(
                rows,
                as_json,
                t.with_fields(
                    json!({
                        "name": "brownian_hi_spectral_ewald",
                        "bench": "brownian",
                        "case": "hi_spectral",
                        "method": method_name(method),
                        "n": hn,
                        "threads": threads,
                        "volume_fraction": HI_VOLUME_FRACTION,
                        "ewald_tolerance": SPECTRAL_EWALD_TOLERANCE,
                        "krylov_tolerance": SPECTRAL_KRYLOV_TOLERANCE,
                        "product_error": error,
                        "ewald": t.ewald,
                        "load_average_1min": load_average(),
                    }),
                    hi_reps(hn),
                ),
            )?;
        }
    }
    Ok(())
}

/// The LAMMPS-mirror rows (the configuration of anchor-bench `lammps_bd.sh`, see
/// [`lammps_mirror_scene`]) at `sizes.mirror_ncell` and `sizes.threads`.
fn mirror_rows(
    sizes: &BrownianBenchSizes,
    as_json: bool,
    rows: &mut Vec<Value>,
) -> Result<(), BenchError> {
    if sizes.mirror_ncell > 0 {
        let text = lammps_mirror_scene(sizes.mirror_ncell, 1)?;
        let scene = crate::scene::parse_scene(&text, &Default::default())
            .map_err(|e| BenchError::Runtime(format!("mirror scene: {e}")))?;
        let mirror_n = sizes.mirror_ncell.pow(3);
        for &threads in &sizes.threads {
            let (r, _) =
                pipeline_rate(&scene, threads, sizes.warmup_steps, sizes.pipeline_seconds)?;
            emit(
                rows,
                as_json,
                json!({
                    "name": "brownian_lammps_mirror",
                    "bench": "brownian",
                    "case": "lammps_mirror",
                    "threads": threads,
                    "n": mirror_n,
                    "reduced_density": lammps_case::REDUCED_DENSITY,
                    "dipole_cutoff_sigma": lammps_case::CUTOFF_SIGMA,
                    "core": "Mie(12,6) = WCA, epsilon = kT",
                    "dt_s": lammps_case::dt_and_moment().0,
                    "steps": r.steps,
                    "wall_time_s": r.seconds,
                    "particle_steps_per_s": r.particle_steps_per_s,
                    "particle_steps_per_s_per_thread": r.particle_steps_per_s / threads as f64,
                    "peer": {"impl": "lammps", "case": "bd_dipoles", "threads": 1,
                             "metric": "particle_steps_per_s"},
                    "differs": "moments held along the field (no rotation); unbounded domain",
                    "load_average_1min": load_average(),
                }),
            )?;
        }
    }
    Ok(())
}

/// `magsep bench brownian-peer`: only the LAMMPS-mirror rows (22³ = 10 648 particles, 1 and 2
/// threads, ~3 s each; `quick`: 6³, 0.5 s), for running right beside the peer.
///
/// # Errors
/// As [`bench_brownian`].
pub fn bench_brownian_peer(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let mut sizes = BrownianBenchSizes::full();
    if quick {
        sizes.mirror_ncell = 6;
        sizes.pipeline_seconds = 0.5;
    }
    mirror_rows(&sizes, as_json, &mut Vec::new())
}

/// `magsep chart brownian-cost --out DIR [--quick]`: writes `DIR/brownian_mobility_cost.svg`
/// and `DIR/brownian_mobility_cost.json`, prints a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] for I/O or a failing mobility.
pub fn chart_brownian_cost(out: &Path, quick: bool) -> Result<(), BenchError> {
    let sizes = if quick {
        CostChartSizes::quick()
    } else {
        CostChartSizes::full()
    };
    let summary = chart_brownian_cost_with(out, &sizes)?;
    crate::studies::bench::say(summary)
}

/// The cost chart at explicit sizes; returns the summary printed by [`chart_brownian_cost`].
///
/// # Errors
/// As [`chart_brownian_cost`].
pub fn chart_brownian_cost_with(out: &Path, sizes: &CostChartSizes) -> Result<Value, BenchError> {
    cost::write_chart(out, sizes)
}
