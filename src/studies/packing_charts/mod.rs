//! `magsep chart cylinder | wedge | superballs`: the confinement and shape studies of thesis 000
//! (ch. 2 figs. 2.10-2.16, ch. 4 figs. 4.5-4.6) as SVG charts with a JSON summary.
//!
//! Sizes are reduced from the thesis's (N = 500, 5 runs; superballs N = 750) to finish in
//! about half an hour on two cores: 120 particles and 2 runs per point (superballs 60), stated
//! in every chart's title. `--quick` runs a smoke version.
//!
//! Every point is the mean of independent runs (seeds 1..=runs) with a Student-t 95 % interval.
//! Periodic reference runs of the same shapes give phi_periodic and \<C\>_periodic for the
//! rescaled measures phi* and \<C\>* ([T000 §2.4]). Runs go in parallel over rayon;
//! each run is single-threaded and deterministic. The wedge sweep hands every run of every
//! point to rayon in one pass ([`points`], largest packings first), so no core idles while a
//! point's slowest run finishes and more than `runs` cores are used; the results are those
//! of the points computed one by one (tested).

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
    /// Contact-solver fall-backs over evaluations (NaN when none was evaluated).
    pub fallback_rate: f64,
    /// Wall time \[s\].
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
        // a rate over no evaluations is undefined: NaN (JSON null), not 0
        fallback_rate: r.contact_fallbacks as f64 / r.contact_evaluations as f64,
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

/// One configuration of a sweep: the arguments of [`point_with`].
#[derive(Debug, Clone)]
pub struct PointSpec {
    /// What was varied, for the summary.
    pub label: String,
    /// Particles (raised by [`particles_for`]).
    pub n: usize,
    /// Particle shape (D = 1 units).
    pub shape: Shape,
    /// Container.
    pub container: ContainerSpec,
    /// Initial packing fraction.
    pub phi0: f64,
    /// Runs (seeds 1..=runs).
    pub runs: u64,
    /// Overlap-removal scheme.
    pub scheme: OverlapRemovalScheme,
}

impl PointSpec {
    /// A FIRE configuration (what [`point`] runs).
    pub fn fire(
        label: String,
        n: usize,
        shape: Shape,
        container: ContainerSpec,
        phi0: f64,
        runs: u64,
    ) -> Self {
        Self {
            label,
            n,
            shape,
            container,
            phi0,
            runs,
            scheme: OverlapRemovalScheme::Fire,
        }
    }
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
    let spec = PointSpec {
        label,
        n,
        shape,
        container: container.clone(),
        phi0,
        runs,
        scheme,
    };
    let mut p = points(std::slice::from_ref(&spec))?;
    p.pop()
        .ok_or_else(|| BenchError::Runtime("no point computed".into()))
}

/// The points of `specs`, with the runs of all points in one parallel pass: a thread that
/// finishes a run takes the next one of any point (the largest packings first), so no core
/// waits for the slowest run of a point, and up to (points x runs) cores are used instead of
/// `runs`. Each run is single-threaded and deterministic, so every point is the one
/// [`point_with`] computes alone (tested).
pub fn points(specs: &[PointSpec]) -> Result<Vec<Point>, BenchError> {
    let sizes: Vec<usize> = specs
        .iter()
        .map(|s| particles_for(&s.container, s.shape, s.n))
        .collect();
    let mut jobs: Vec<(usize, u64)> = specs
        .iter()
        .enumerate()
        .flat_map(|(k, s)| (1..=s.runs).map(move |seed| (k, seed)))
        .collect();
    // longest first (cost grows with N): a long run started last would idle the other cores
    jobs.sort_by_key(|&(k, seed)| (std::cmp::Reverse(sizes[k]), k, seed));
    let done: Vec<RunMeasures> = jobs
        .par_iter()
        .with_max_len(1)
        .map(|&(k, seed)| {
            let s = &specs[k];
            // one thread per run: the runs fill the cores
            magsep_systems::par::on_one_thread(|| {
                measure(sizes[k], s.shape, &s.container, s.phi0, seed, s.scheme)
            })
        })
        .collect::<Result<_, _>>()?;
    let mut runs: Vec<Vec<(u64, RunMeasures)>> = vec![Vec::new(); specs.len()];
    for (&(k, seed), r) in jobs.iter().zip(done) {
        runs[k].push((seed, r));
    }
    Ok(specs
        .iter()
        .zip(sizes)
        .zip(runs)
        .map(|((s, n), mut r)| {
            r.sort_by_key(|(seed, _)| *seed);
            reduce(
                format!("{} (N = {n})", s.label),
                r.into_iter().map(|x| x.1).collect(),
            )
        })
        .collect())
}

/// Runs of one configuration (in seed order) reduced to estimates.
fn reduce(label: String, results: Vec<RunMeasures>) -> Point {
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
    Point {
        label,
        phi: est(|r| r.phi),
        contacts: est(|r| r.contacts),
        nematic: est(|r| r.nematic),
        aligned: est(|r| r.aligned),
        cubatic: est(|r| r.cubatic),
        runs: results,
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The runs of several points in one parallel pass give each point exactly as computed
    /// alone (the reference: [`measure`] seed by seed, serially).
    #[test]
    fn points_in_one_pass_equal_points_alone() {
        let specs = [
            PointSpec::fire(
                "spheres".into(),
                24,
                rod(1.0),
                ContainerSpec::PeriodicBox {},
                0.05,
                2,
            ),
            PointSpec::fire(
                "rods".into(),
                16,
                rod(2.0),
                ContainerSpec::PeriodicBox {},
                0.05,
                3,
            ),
        ];
        let together = points(&specs).unwrap();
        assert_eq!(together.len(), specs.len());
        for (s, p) in specs.iter().zip(&together) {
            assert_eq!(p.runs.len() as u64, s.runs);
            for (seed, r) in (1..=s.runs).zip(&p.runs) {
                let alone = measure(s.n, s.shape, &s.container, s.phi0, seed, s.scheme).unwrap();
                assert_eq!(
                    r.phi.to_bits(),
                    alone.phi.to_bits(),
                    "{} seed {seed}",
                    s.label
                );
                assert_eq!(r.contacts.to_bits(), alone.contacts.to_bits());
                assert_eq!(r.nematic.to_bits(), alone.nematic.to_bits());
            }
        }
        // the seeds differ: the runs of a point are not copies
        assert_ne!(together[0].runs[0].phi, together[0].runs[1].phi);
    }
}
