//! Order at hard walls: the fraction of wall-aligned particles and orientation-density
//! histograms ([T000 §2.2.5, §2.5, Figs. 2.6, 2.15]).
//!
//! # f_align
//!
//! A particle is *near* a wall when its centre lies within Delta of it (signed distance
//! 0 <= ... <= Delta inside the container; Delta = 1 D by default, the thesis's Delta = 2R).
//! It is *aligned* with that wall when its axis lies tangential within 4 degrees:
//! |u . n| <= sin(4 deg), with n the wall's outward normal (cylinder: the horizontal radial
//! direction at the particle's centre). f_align = aligned / near.
//!
//! Three counts are returned. `pooled` counts (particle, wall) pairs over all walls: the
//! thesis's measure, in which a particle near two planes (the wedge's corners) is counted
//! twice but can be aligned with only one of them, so f_align is underestimated in small
//! wedges ([T000 §2.5], a limitation the thesis names). `per_wall` gives the same split by plane, which has no such
//! cross-talk (the remedy the thesis suggests). `particles` counts each near-wall particle once, aligned
//! if aligned with at least one wall it is near.
//!
//! # Orientation histograms
//!
//! Axes are headless (u ~ -u). The polar angle is measured from the periodic axis z and
//! folded to cos(theta) = |u_z| in [0, 1]; the azimuth is that of the axis' xy projection
//! measured from x and folded to phi = atan2(|u_y|, |u_x|) in [0, 90 deg], the acute angle
//! between the projection and the x axis. The fold identifies phi, -phi, 180 - phi and
//! 180 + phi (head-tail symmetry and the mirror y -> -y). In a wedge, particles aligned with
//! the bottom sit at phi = 0, along the slope at phi = alpha (the thesis's 9 deg example,
//! [T000 §2.5, Fig. 2.15]), in the back plane (yz) at phi = 90 deg, and along z at cos(theta) = 1 (all three
//! planes contain z; the thesis assigns the back to cos(theta) = 1, erratum E-000-27 treats this as
//! uncertain). An axis along z has phi = 0. Both upper limits are closed: cos(theta) = 1 and
//! phi = 90 deg fall in the last bins. Isotropic axes have a uniform density in
//! (cos(theta), phi), so [`OrientationHistogram::density`] is normalised to 1 for them.

use glam::DVec3;

use crate::packing::state::PackingState;
use crate::packing::walls::{WallId, WallKind, wall_distance, wall_ids, wall_normal};

/// The thesis's near-wall layer Delta / D (= 2R).
pub const WALL_LAYER: f64 = 1.0;

/// The thesis's alignment tolerance, 4 degrees (radians).
pub const ALIGNMENT_ANGLE: f64 = 4.0 * std::f64::consts::PI / 180.0;

/// Near-wall and aligned counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AlignmentCount {
    /// Particles (or particle-wall pairs) with the centre within the layer.
    pub near: usize,
    /// Of those, the aligned ones.
    pub aligned: usize,
}

impl AlignmentCount {
    /// aligned / near (`None` if no particle is near).
    ///
    /// ```
    /// use magsep_systems::analysis::wall_order::AlignmentCount;
    /// assert_eq!(AlignmentCount { near: 4, aligned: 3 }.fraction(), Some(0.75));
    /// assert_eq!(AlignmentCount::default().fraction(), None);
    /// ```
    pub fn fraction(&self) -> Option<f64> {
        (self.near > 0).then(|| self.aligned as f64 / self.near as f64)
    }
}

/// Wall alignment of a packing.
#[derive(Debug, Clone, PartialEq)]
pub struct WallAlignment {
    /// Per wall, in [`wall_ids`] order.
    pub per_wall: Vec<(WallId, AlignmentCount)>,
    /// (particle, wall) pairs over all walls: the thesis's f_align.
    pub pooled: AlignmentCount,
    /// Each near-wall particle once, aligned if aligned with any wall it is near.
    pub particles: AlignmentCount,
}

/// Wall alignment of particles with centres `positions` and unit axes `axes`, near-wall
/// layer `layer` / D (thesis: [`WALL_LAYER`]) and tolerance `max_angle` (radians) (thesis:
/// [`ALIGNMENT_ANGLE`]). Periodic containers give empty counts.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::analysis::wall_order::{ALIGNMENT_ANGLE, WALL_LAYER, wall_alignment};
/// use magsep_systems::packing::walls::WallKind;
/// // one rod lying on the floor of a slab, one standing on it, one in the middle
/// let pos = [DVec3::new(1.0, 1.0, 0.5), DVec3::new(2.0, 2.0, 0.9), DVec3::new(2.0, 2.0, 5.0)];
/// let axes = [DVec3::X, DVec3::Z, DVec3::X];
/// let w = wall_alignment(WallKind::Slab, DVec3::new(4.0, 4.0, 10.0), &pos, &axes,
///     WALL_LAYER, ALIGNMENT_ANGLE);
/// assert_eq!(w.pooled.fraction(), Some(0.5));
/// ```
pub fn wall_alignment(
    kind: WallKind,
    edges: DVec3,
    positions: &[DVec3],
    axes: &[DVec3],
    layer: f64,
    max_angle: f64,
) -> WallAlignment {
    let ids = wall_ids(kind);
    let mut per_wall: Vec<(WallId, AlignmentCount)> = ids
        .iter()
        .map(|&w| (w, AlignmentCount::default()))
        .collect();
    let mut particles = AlignmentCount::default();
    let tol = max_angle.sin();
    for (&x, &u) in positions.iter().zip(axes) {
        let (mut near, mut aligned) = (false, false);
        for (w, count) in per_wall.iter_mut() {
            if wall_distance(kind, edges, *w, x) > layer {
                continue;
            }
            let is_aligned = u.dot(wall_normal(kind, edges, *w, x)).abs() <= tol;
            count.near += 1;
            count.aligned += usize::from(is_aligned);
            near = true;
            aligned |= is_aligned;
        }
        particles.near += usize::from(near);
        particles.aligned += usize::from(aligned);
    }
    let pooled = per_wall
        .iter()
        .fold(AlignmentCount::default(), |acc, (_, c)| AlignmentCount {
            near: acc.near + c.near,
            aligned: acc.aligned + c.aligned,
        });
    WallAlignment {
        per_wall,
        pooled,
        particles,
    }
}

/// The thesis's f_align of a packing: [`wall_alignment`] of its rods (half length > 0) with
/// Delta = [`WALL_LAYER`] and [`ALIGNMENT_ANGLE`], pooled over walls; 0 if no rod is near a
/// wall (or there are no walls).
///
/// ```
/// use magsep_systems::analysis::wall_order::aligned_fraction;
/// use magsep_systems::packing::state::PackingState;
/// assert_eq!(aligned_fraction(&PackingState::periodic_cube(5.0)), 0.0);
/// ```
pub fn aligned_fraction(state: &PackingState) -> f64 {
    let (positions, axes): (Vec<DVec3>, Vec<DVec3>) = (0..state.len())
        .filter(|&i| state.bodies[i].half_length > 0.0)
        .map(|i| (state.positions[i], state.axis(i)))
        .unzip();
    wall_alignment(
        state.walls,
        state.edges,
        &positions,
        &axes,
        WALL_LAYER,
        ALIGNMENT_ANGLE,
    )
    .pooled
    .fraction()
    .unwrap_or(0.0)
}

/// Folded (cos(theta), phi (radians)) of a headless axis (module header).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::analysis::wall_order::folded_angles;
/// let a = 0.3f64;
/// let (c, phi) = folded_angles(-DVec3::new(a.cos(), a.sin(), 0.0));
/// assert!(c == 0.0 && (phi - a).abs() < 1e-15);
/// ```
pub fn folded_angles(axis: DVec3) -> (f64, f64) {
    let u = axis.normalize_or_zero();
    (u.z.abs().min(1.0), u.y.abs().atan2(u.x.abs()))
}

/// A 2-D histogram of folded orientations.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationHistogram {
    /// Bin edges in cos(theta), from 0 to 1.
    pub cos_theta_edges: Vec<f64>,
    /// Bin edges in phi (radians), from 0 to pi/2.
    pub phi_edges: Vec<f64>,
    /// Counts, row-major: `counts[i * phi_bins + j]` for cos bin i and phi bin j.
    pub counts: Vec<u64>,
    /// Number of axes binned.
    pub total: u64,
}

impl OrientationHistogram {
    /// Number of phi bins.
    pub fn phi_bins(&self) -> usize {
        self.phi_edges.len() - 1
    }

    /// Count in cos bin `i` and phi bin `j`.
    pub fn count(&self, i: usize, j: usize) -> u64 {
        self.counts[i * self.phi_bins() + j]
    }

    /// Probability density relative to isotropic orientations (1 everywhere for a uniform
    /// distribution; zeros if empty), same layout as `counts`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::analysis::wall_order::orientation_histogram;
    /// let h = orientation_histogram(&[DVec3::Z, DVec3::X], 2, 3);
    /// // z: cos(theta) = 1, phi = 0; x: cos(theta) = 0, phi = 0; 6 cells, 2 axes
    /// assert_eq!(h.density(), vec![3.0, 0.0, 0.0, 3.0, 0.0, 0.0]);
    /// ```
    pub fn density(&self) -> Vec<f64> {
        let cells = self.counts.len() as f64;
        let total = self.total.max(1) as f64;
        self.counts
            .iter()
            .map(|&c| c as f64 * cells / total)
            .collect()
    }
}

/// Histogram of the folded orientations of `axes` with `cos_bins` x `phi_bins` equal bins
/// (each at least 1).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::analysis::wall_order::orientation_histogram;
/// let h = orientation_histogram(&[DVec3::Z, DVec3::new(1.0, 1.0, 0.0)], 4, 2);
/// assert_eq!(h.count(3, 0), 1); // along z: cos(theta) = 1, phi = 0
/// assert_eq!(h.count(0, 1), 1); // along the diagonal: cos 0, phi = 45 deg (last bin)
/// ```
pub fn orientation_histogram(
    axes: &[DVec3],
    cos_bins: usize,
    phi_bins: usize,
) -> OrientationHistogram {
    let (nc, np) = (cos_bins.max(1), phi_bins.max(1));
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut counts = vec![0u64; nc * np];
    for &u in axes {
        let (c, phi) = folded_angles(u);
        let i = ((c * nc as f64) as usize).min(nc - 1);
        let j = ((phi / half_pi * np as f64) as usize).min(np - 1);
        counts[i * np + j] += 1;
    }
    OrientationHistogram {
        cos_theta_edges: (0..=nc).map(|i| i as f64 / nc as f64).collect(),
        phi_edges: (0..=np).map(|j| half_pi * j as f64 / np as f64).collect(),
        counts,
        total: axes.len() as u64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::packing::walls::{cylinder_edges, wedge_edges};
    use crate::rng::particle_stream;
    use rand::RngExt;
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
        let z = 2.0 * rng.random::<f64>() - 1.0;
        let phi = std::f64::consts::TAU * rng.random::<f64>();
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    #[test]
    fn corner_particles_show_the_double_counting_artefact() {
        let alpha = 30f64.to_radians();
        let (k, e) = (WallKind::Wedge { alpha }, wedge_edges(alpha, 10.0, 4.0));
        // near bottom and back at once, lying along x: aligned with the bottom only
        let corner = DVec3::new(9.5, 0.5, 2.0);
        // near the slope only, along the slope
        let slope_dir = DVec3::new(alpha.cos(), alpha.sin(), 0.0);
        let on_slope = DVec3::new(5.0, 5.0 * alpha.tan() - 0.6, 1.0);
        // in the back plane along y, near the back only
        let back = DVec3::new(9.6, 1.2, 3.0);
        let w = wall_alignment(
            k,
            e,
            &[corner, on_slope, back],
            &[DVec3::X, slope_dir, DVec3::Y],
            WALL_LAYER,
            ALIGNMENT_ANGLE,
        );
        let per: Vec<_> = w
            .per_wall
            .iter()
            .map(|(_, c)| (c.near, c.aligned))
            .collect();
        assert_eq!(per, vec![(1, 1), (2, 1), (1, 1)]); // bottom, back, slope
        assert_eq!((w.pooled.near, w.pooled.aligned), (4, 3));
        assert_eq!((w.particles.near, w.particles.aligned), (3, 3));
    }

    #[test]
    fn cylinder_uses_the_radial_normal_and_the_angle_threshold() {
        let (k, e) = (WallKind::Cylinder { radius: 3.0 }, cylinder_edges(3.0, 5.0));
        let a = 0.7f64;
        let radial = DVec3::new(a.cos(), a.sin(), 0.0);
        let x = DVec3::new(3.0, 3.0, 1.0) + 2.5 * radial;
        let tangent = DVec3::Z.cross(radial);
        let tilt = |deg: f64| {
            let t = deg.to_radians();
            tangent * t.cos() + radial * t.sin()
        };
        let axes = [DVec3::Z, tangent, radial, tilt(3.9), tilt(4.1)];
        let w = wall_alignment(k, e, &[x; 5], &axes, WALL_LAYER, ALIGNMENT_ANGLE);
        assert_eq!((w.pooled.near, w.pooled.aligned), (5, 3));
        // outside the layer: not counted
        let inner = DVec3::new(3.0, 3.0, 1.0) + 1.9 * radial;
        let w = wall_alignment(k, e, &[inner], &[DVec3::Z], WALL_LAYER, ALIGNMENT_ANGLE);
        assert_eq!(w.pooled, AlignmentCount::default());
        let w = wall_alignment(WallKind::Periodic, e, &[x], &[DVec3::Z], 1.0, 0.1);
        assert!(w.per_wall.is_empty() && w.particles.fraction().is_none());
    }

    #[test]
    fn isotropic_axes_are_aligned_with_probability_sin_4_degrees() {
        // u . n is uniform on [-1, 1] for isotropic u: P(|u . n| <= sin a) = sin a
        let mut rng = particle_stream(31, 0);
        let e = DVec3::new(10.0, 10.0, 10.0);
        let n = 200_000;
        let pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(5.0, 5.0, 0.5 * rng.random::<f64>()))
            .collect();
        let axes: Vec<DVec3> = (0..n).map(|_| unit(&mut rng)).collect();
        let w = wall_alignment(WallKind::Box, e, &pos, &axes, WALL_LAYER, ALIGNMENT_ANGLE);
        let p = ALIGNMENT_ANGLE.sin();
        let f = w.particles.fraction().unwrap();
        let sigma = (p * (1.0 - p) / n as f64).sqrt();
        assert!((f - p).abs() < 5.0 * sigma, "{f} vs {p}");
        assert_eq!(w.particles.near, n);
    }

    #[test]
    fn isotropic_axes_give_a_uniform_density() {
        let mut rng = particle_stream(32, 0);
        let n = 180_000;
        let axes: Vec<DVec3> = (0..n).map(|_| unit(&mut rng)).collect();
        let h = orientation_histogram(&axes, 10, 9);
        assert_eq!(h.total, n as u64);
        assert_eq!(h.counts.iter().sum::<u64>(), n as u64);
        let expected = n as f64 / 90.0;
        let tol = 5.0 / expected.sqrt(); // 5 sigma relative
        for d in h.density() {
            assert!((d - 1.0).abs() < tol, "{d}");
        }
        assert!((h.phi_edges[9] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn folding_maps_wedge_alignments_to_the_thesis_angles() {
        let alpha = 9f64.to_radians();
        let slope = DVec3::new(alpha.cos(), alpha.sin(), 0.0);
        for s in [1.0, -1.0] {
            let (c, phi) = folded_angles(s * slope);
            assert!(c == 0.0 && (phi - alpha).abs() < 1e-15);
            let (c, phi) = folded_angles(s * DVec3::new(1.0, 0.0, 0.5));
            assert!((c - 0.5 / 1.25f64.sqrt()).abs() < 1e-15 && phi == 0.0);
            let (_, phi) = folded_angles(s * DVec3::new(0.0, 1.0, 0.5));
            assert!((phi - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        }
        // mirror y -> -y and 180 - phi fold onto phi
        for v in [
            DVec3::new(0.8, -0.3, 0.1),
            DVec3::new(-0.8, 0.3, 0.1),
            DVec3::new(-0.8, -0.3, -0.1),
        ] {
            assert_eq!(folded_angles(v), folded_angles(DVec3::new(0.8, 0.3, 0.1)));
        }
    }
}
