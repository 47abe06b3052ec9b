//! The mobility cost/accuracy chart: for each method, the relative error of the Brownian
//! displacement covariance ‖B Bᵀ − μ‖_F / ‖μ‖_F against the exact RPY mobility
//! (`covariance_error`) and the wall time of one step's stochastic work (prepare + one noise
//! draw), on random configurations at two volume fractions. Krylov and the matrix-free
//! spectral Ewald mobility are drawn at each of the tolerances (for spectral Ewald the product
//! and the Krylov tolerance are both set to it; at these small N its cost model may pick the
//! direct pair sum, recorded as `ewald_grid` = 0 in the JSON data).

use std::path::Path;
use std::time::Instant;

use magsep_systems::brownian::hydro::{
    HydroError, Mobility, MobilityMethod, MobilityOptions, covariance_error, rpy_matrix,
};
use serde::Serialize;
use serde_json::{Value, json};

use super::hi::{normal_vectors, prepare_and_draw, random_configuration};
use super::{RADIUS, VISCOSITY, method_name};
use crate::chart::{Chart, Figure, Series, Style, write_svg};
use crate::studies::bench::BenchError;

/// Where exact (Cholesky) errors are drawn on the log axis.
pub const ERROR_FLOOR: f64 = 1e-16;

/// Sizes of the cost chart.
#[derive(Debug, Clone, PartialEq)]
pub struct CostChartSizes {
    /// Particle numbers.
    pub sizes: Vec<usize>,
    /// Volume fractions (one panel each).
    pub volume_fractions: Vec<f64>,
    /// Krylov tolerances.
    pub krylov_tolerances: Vec<f64>,
    /// Time each cost measurement is repeated for, at least once \[s\].
    pub min_time: f64,
}

impl CostChartSizes {
    /// N = 50, 200, 500 at φ = 1e-2 and 5e-2; Krylov 1e-2 … 1e-8.
    pub fn full() -> Self {
        Self {
            sizes: vec![50, 200, 500],
            volume_fractions: vec![1e-2, 5e-2],
            krylov_tolerances: vec![1e-2, 1e-4, 1e-6, 1e-8],
            min_time: 0.2,
        }
    }

    /// N = 50, 100.
    pub fn quick() -> Self {
        Self {
            sizes: vec![50, 100],
            min_time: 0.05,
            ..Self::full()
        }
    }
}

/// One point of the chart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CostPoint {
    /// Volume fraction of the configuration.
    pub volume_fraction: f64,
    /// Particles.
    pub n: usize,
    /// `free_draining`, `cholesky`, `tea`, `krylov` or `spectral_ewald`.
    pub method: String,
    /// Krylov tolerance (None for the other methods).
    pub tolerance: Option<f64>,
    /// Prepare + one noise draw \[s\] (mean over the repetitions).
    pub cost_s: f64,
    /// ‖B Bᵀ − μ‖_F / ‖μ‖_F.
    pub error: f64,
    /// Error as drawn (at least `ERROR_FLOOR`).
    pub plotted_error: f64,
    /// Krylov iterations of one noise draw.
    pub krylov_iterations: usize,
    /// Spectral Ewald FFT length per side (0: direct sum or another method).
    pub ewald_grid: usize,
}

/// Mean cost [s] of prepare + one noise draw (repeated for `min_time`), the covariance
/// error and the Krylov iterations of `method` at `x`.
fn measure(
    method: MobilityMethod,
    tol: Option<f64>,
    x: &[glam::DVec3],
    radii: &[f64],
    w: &[glam::DVec3],
    error_of: &dyn Fn(&Mobility) -> Result<f64, HydroError>,
    min_time: f64,
) -> Result<(f64, f64, usize, usize), BenchError> {
    let options = MobilityOptions {
        krylov_tolerance: tol.unwrap_or(1e-6),
        ewald_tolerance: tol.unwrap_or(1e-6).clamp(1e-12, 0.1),
        ..MobilityOptions::default()
    };
    let t = Instant::now();
    let mut reps = 0usize;
    let mut sum = 0.0;
    let mob = loop {
        let (mob, prepare, noise) = prepare_and_draw(method, x, radii, VISCOSITY, options, w)?;
        sum += prepare + noise;
        reps += 1;
        if t.elapsed().as_secs_f64() >= min_time || reps >= 1000 {
            break mob;
        }
    };
    let error = error_of(&mob).map_err(|e| {
        BenchError::Runtime(format!(
            "covariance error of {method:?} at N = {}: {e}",
            x.len()
        ))
    })?;
    let grid = mob.ewald_summary().map_or(0, |s| s.grid);
    Ok((sum / reps as f64, error, mob.krylov_iterations(), grid))
}

/// Measure every method at every size and volume fraction.
///
/// # Errors
/// [`BenchError::Runtime`] when a mobility fails.
pub fn cost_points(sizes: &CostChartSizes) -> Result<Vec<CostPoint>, BenchError> {
    let mut variants: Vec<(MobilityMethod, Option<f64>)> = vec![
        (MobilityMethod::FreeDraining, None),
        (MobilityMethod::Cholesky, None),
        (MobilityMethod::Tea, None),
    ];
    variants.extend(
        sizes
            .krylov_tolerances
            .iter()
            .map(|&t| (MobilityMethod::Krylov, Some(t))),
    );
    variants.extend(
        sizes
            .krylov_tolerances
            .iter()
            .map(|&t| (MobilityMethod::SpectralEwald, Some(t))),
    );
    let mut points = Vec::new();
    for (k, &phi) in sizes.volume_fractions.iter().enumerate() {
        for &n in &sizes.sizes {
            let x = random_configuration(n, RADIUS, phi, 1000 * k as u64 + n as u64);
            let radii = vec![RADIUS; n];
            let exact = rpy_matrix(&x, &radii, VISCOSITY);
            let w = normal_vectors(n, 5);
            for &(method, tol) in &variants {
                match measure(
                    method,
                    tol,
                    &x,
                    &radii,
                    &w,
                    &|m| covariance_error(m, &exact),
                    sizes.min_time,
                ) {
                    Ok((cost_s, error, iterations, grid)) => {
                        let p = CostPoint {
                            volume_fraction: phi,
                            n,
                            method: method_name(method).into(),
                            tolerance: tol,
                            cost_s,
                            error,
                            plotted_error: error.max(ERROR_FLOOR),
                            krylov_iterations: iterations,
                            ewald_grid: grid,
                        };
                        eprintln!(
                            "phi {phi:.0e} N {n} {}{}: cost {:.3e} s, error {:.3e}",
                            p.method,
                            tol.map(|t| format!(" tol {t:.0e}")).unwrap_or_default(),
                            p.cost_s,
                            p.error
                        );
                        points.push(p);
                    }
                    // e.g. Krylov not converged on some column: leave the point out
                    Err(e) => eprintln!("phi {phi:.0e} N {n} {method:?} {tol:?}: skipped: {e}"),
                }
            }
        }
    }
    Ok(points)
}

/// The chart panel of one volume fraction.
fn panel(points: &[CostPoint], phi: f64, sizes: &[usize]) -> Chart {
    let mut chart = Chart::new(format!("volume fraction {phi:.0e}"))
        .x_label("cost of one step: prepare + noise [s]")
        .y_label("||B B^T - mu||_F / ||mu||_F")
        .x_log(true)
        .y_log(true);
    let of = |method: &str, n: Option<usize>| -> Vec<(f64, f64)> {
        points
            .iter()
            .filter(|p| p.volume_fraction == phi && p.method == method)
            .filter(|p| n.is_none_or(|n| p.n == n))
            .map(|p| (p.cost_s, p.plotted_error))
            .collect()
    };
    let label = sizes
        .iter()
        .map(|n| n.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    chart = chart
        .series(
            Series::new(
                format!("free draining (no HI), N = {label}"),
                of("free_draining", None),
            )
            .style(Style::LineMarkers),
        )
        .series(Series::new(format!("TEA, N = {label}"), of("tea", None)).style(Style::LineMarkers))
        .series(
            Series::new(
                format!("Cholesky (exact, drawn at >= {ERROR_FLOOR:.0e}), N = {label}"),
                of("cholesky", None),
            )
            .style(Style::LineMarkers),
        );
    for &n in sizes {
        chart = chart.series(
            Series::new(
                format!("Krylov, tol 1e-2..1e-8, N = {n}"),
                of("krylov", Some(n)),
            )
            .style(Style::LineMarkers),
        );
    }
    for &n in sizes {
        chart = chart.series(
            Series::new(
                format!("spectral Ewald (matrix-free), tol 1e-2..1e-8, N = {n}"),
                of("spectral_ewald", Some(n)),
            )
            .style(Style::LineMarkers),
        );
    }
    chart
}

/// Measure, write `brownian_mobility_cost.svg` and `.json` under `out`, return the summary.
///
/// # Errors
/// [`BenchError::Runtime`] for I/O or a failing mobility.
pub fn write_chart(out: &Path, sizes: &CostChartSizes) -> Result<Value, BenchError> {
    let points = cost_points(sizes)?;
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let mut fig = Figure::new(
        format!(
            "Brownian covariance error against cost (R = {:.0} nm, random configurations, {} threads)",
            RADIUS * 1e9,
            rayon::current_num_threads()
        ),
        sizes.volume_fractions.len().clamp(1, 2),
    );
    for &phi in &sizes.volume_fractions {
        fig = fig.panel(panel(&points, phi, &sizes.sizes));
    }
    let svg = out.join("brownian_mobility_cost.svg");
    write_svg(&svg, &fig.to_svg(640.0, 460.0))
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", svg.display())))?;
    let data = json!({
        "radius_m": RADIUS,
        "viscosity_pa_s": VISCOSITY,
        "threads": rayon::current_num_threads(),
        "sizes": sizes.sizes,
        "volume_fractions": sizes.volume_fractions,
        "krylov_tolerances": sizes.krylov_tolerances,
        "error_floor": ERROR_FLOOR,
        "points": points,
    });
    let path = out.join("brownian_mobility_cost.json");
    let text = serde_json::to_string_pretty(&data)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))?;
    std::fs::write(&path, text)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))?;
    let rows: Vec<Value> = points
        .iter()
        .map(|p| {
            json!({"phi": p.volume_fraction, "n": p.n, "method": p.method, "tolerance": p.tolerance,
                   "cost_s": p.cost_s, "error": p.error})
        })
        .collect();
    Ok(json!({
        "charts": [svg.display().to_string()],
        "data": path.display().to_string(),
        "points": rows,
    }))
}
