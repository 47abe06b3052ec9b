//! `magsep chart cylinder | wedge | superballs`: the confinement and shape studies of thesis 000
//! (ch. 2 figs. 2.10-2.16, ch. 4 figs. 4.5-4.6) as SVG charts with a JSON summary.
//!
//! Sizes are reduced from the thesis's (N = 500, 5 runs; superballs N = 750) to finish in
//! about half an hour on two cores: 120 particles and 2 runs per point (superballs 60), stated
//! in every chart's title. `--quick` runs a smoke version.
//!
//! Every point is the mean of independent runs (seeds 1..=runs) with a Student-t 95 % interval.
//! Periodic reference runs of the same shapes give phi_periodic and <C>_periodic for the
//! rescaled measures phi* and <C>* ([T000 §2.4]). Runs go in parallel over rayon;
//! each run is single-threaded and deterministic.

mod sweeps;

pub use magsep_components::packing::OverlapRemovalScheme as Scheme;
pub use sweeps::{chart_cylinder, chart_superballs, chart_wedge};

use magsep_components::packing::{OverlapRemovalScheme, PackingConfig};
use magsep_components::shape::Shape;
use magsep_systems::analysis::cubatic::cubatic_order;
use magsep_systems::analysis::wall_order::aligned_fraction;
use rayon::prelude::*;
use serde::Serialize;

use crate::brownian::stats::{Estimate, mean_interval};
use crate::pipelines::packing::ContainerSpec;
use crate::studies::bench::{BenchError, packing_run_in};

/// The measures of one finished run.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RunMeasures {
    /// Packing fraction.
    pub phi: f64,
    /// Extrapolated mean contact number (particle-particle).
    pub contacts: f64,
    /// Nematic order S of the rods (0 without rods).
    pub nematic: f64,
    /// Wall-aligned fraction (NaN without walls or rods).
    pub aligned: f64,
    /// Cubatic order S_4 (superquadrics; NaN otherwise).
    pub cubatic: f64,
    /// Largest wall penetration / D after the run (<= tolerance).
    pub max_wall_penetration: f64,
    /// Contact-solver fall-backs over evaluations.
    pub fallback_rate: f64,
    /// Wall time [s].
    pub wall_time_s: f64,
}

/// One run of `n` particles of `shape` (D = 1 units) in `container`.
pub fn measure(
    n: usize,
    shape: Shape,
    container: &ContainerSpec,
    phi0: f64,
    seed: u64,
    scheme: OverlapRemovalScheme,
) -> Result<RunMeasures, BenchError> {
    let mut cfg = PackingConfig::defaults_for(n, 1.0);
    cfg.initial_packing_fraction = phi0;
    cfg.scheme = scheme;
    cfg.max_attempts = PackingConfig::default_max_attempts(scheme, n);
    let r = packing_run_in(n, shape, &cfg, seed, f64::INFINITY, container)?;
    let st = &r.state;
    let penetration = (0..st.len())
        .map(|i| st.wall_penetration(i))
        .fold(f64::NEG_INFINITY, f64::max);
    let has_rods = st.bodies.iter().any(|b| b.half_length > 0.0);
    let walled = st.walls != magsep_systems::packing::walls::WallKind::Periodic;
    let aligned = if has_rods && walled {
        aligned_fraction(st)
    } else {
        f64::NAN
    };
    let cubatic = if shape.is_superquadric() {
        cubatic_order(&st.orientations)
    } else {
        f64::NAN
    };
    Ok(RunMeasures {
        phi: r.packing_fraction,
        contacts: r.contact_number,
        nematic: r.nematic_order,
        aligned,
        cubatic,
        max_wall_penetration: penetration,
        fallback_rate: r.contact_fallbacks as f64 / (r.contact_evaluations.max(1) as f64),
        wall_time_s: r.wall_time_s,
    })
}

/// Runs of one configuration reduced to estimates.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// What was varied, for the summary.
    pub label: String,
    /// Per-run measures.
    pub runs: Vec<RunMeasures>,
    /// Packing fraction.
    pub phi: Estimate,
    /// Contact number.
    pub contacts: Estimate,
    /// Nematic order.
    pub nematic: Estimate,
    /// Wall-aligned fraction.
    pub aligned: Estimate,
    /// Cubatic order.
    pub cubatic: Estimate,
}

/// `runs` seeds of one configuration (FIRE), in parallel.
pub fn point(
    label: String,
    n: usize,
    shape: Shape,
    container: &ContainerSpec,
    phi0: f64,
    runs: u64,
) -> Result<Point, BenchError> {
    point_with(
        label,
        n,
        shape,
        container,
        phi0,
        runs,
        OverlapRemovalScheme::Fire,
    )
}

/// Largest particle count the sweeps use.
pub const MAX_PARTICLES: usize = 800;

/// The particle count for `container`: at least `n`, and enough that the compressed (periodic)
/// length ends near three particle lengths at phi ~ 0.55 (the thesis raised N for the same
/// reason, [T000 §2.2.6]: a compressed axis shorter than a particle makes a quasi-2-D, artificially
/// jammed layer), at most [`MAX_PARTICLES`].
pub fn particles_for(container: &ContainerSpec, shape: Shape, n: usize) -> usize {
    let area = match *container {
        ContainerSpec::Cylinder { radius } => std::f64::consts::PI * radius * radius,
        ContainerSpec::Wedge { angle, length } => 0.5 * length * length * angle.tan(),
        ContainerSpec::Slab { side } => side * side,
        ContainerSpec::PeriodicBox {} | ContainerSpec::ClosedBox {} => return n,
    };
    let length = 2.0 * magsep_systems::geometry::bounding_radius(&shape);
    let volume = magsep_systems::geometry::volume(&shape);
    let needed = (3.0 * length * area * 0.55 / volume).ceil() as usize;
    n.max(needed).min(MAX_PARTICLES)
}

/// [`point`] with the overlap-removal `scheme`.
pub fn point_with(
    label: String,
    n: usize,
    shape: Shape,
    container: &ContainerSpec,
    phi0: f64,
    runs: u64,
    scheme: OverlapRemovalScheme,
) -> Result<Point, BenchError> {
    let n = particles_for(container, shape, n);
    let label = format!("{label} (N = {n})");
    let results: Vec<RunMeasures> = (1..=runs)
        .into_par_iter()
        .map(|seed| measure(n, shape, container, phi0, seed, scheme))
        .collect::<Result<_, _>>()?;
    let est = |f: fn(&RunMeasures) -> f64| {
        let v: Vec<f64> = results.iter().map(f).collect();
        mean_interval(&v)
    };
    eprintln!(
        "{label}: phi {:.4} <C> {:.2} S {:.3} f_align {:.3} S4 {:.3} ({:.1} s per run)",
        est(|r| r.phi).mean,
        est(|r| r.contacts).mean,
        est(|r| r.nematic).mean,
        est(|r| r.aligned).mean,
        est(|r| r.cubatic).mean,
        est(|r| r.wall_time_s).mean
    );
    Ok(Point {
        label,
        phi: est(|r| r.phi),
        contacts: est(|r| r.contacts),
        nematic: est(|r| r.nematic),
        aligned: est(|r| r.aligned),
        cubatic: est(|r| r.cubatic),
        runs: results,
    })
}

/// A spherocylinder of aspect ratio `lambda` with D = 1 (a sphere for 1).
pub fn rod(lambda: f64) -> Shape {
    if lambda <= 1.0 {
        Shape::Sphere { radius: 0.5 }
    } else {
        Shape::Spherocylinder {
            radius: 0.5,
            half_length: 0.5 * (lambda - 1.0),
        }
    }
}

/// Half-width of an estimate's interval (0 for a single run).
pub fn half_width(e: &Estimate) -> f64 {
    let w = 0.5 * (e.hi - e.lo);
    if w.is_finite() { w } else { 0.0 }
}
