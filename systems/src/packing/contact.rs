//! Pair contacts of spheres and spherocylinders (a sphere is a rod of zero length), and the
//! adapter to the superquadric common-normal solver.
//!
//! The contact follows the common-normal principle (thesis 000, ch. 3): the closest points of
//! the two axis segments give k (from i's axis point to j's), the overlap
//! delta = R_i + R_j - |k| (erratum E-000-1: positive = overlap), the outward unit normal of i
//! n = k / |k| (pointing into j), and i's contact point relative to its centre
//! r_c = s u_i + R_i n.

use glam::{DQuat, DVec3};

use super::body::Body;
use crate::geometry::segment_closest;
use crate::geometry::superquadric::{self as sq, ContactOptions};

/// Contact of particle i with (an image of) particle j.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairContact {
    /// Overlap R_i + R_j - |k| (> 0: overlap; < 0: gap) / D.
    pub overlap: f64,
    /// Unit outward normal of i at the contact, pointing towards j.
    pub normal: DVec3,
    /// Axis vector k from i's closest axis point to j's / D.
    pub k: DVec3,
    /// Position of i's closest axis point along its axis (l_ij) / D.
    pub s: f64,
    /// Position of j's closest axis point along its axis / D.
    pub t: f64,
    /// i's contact point on its surface, relative to i's centre / D (lab frame).
    pub rc_i: DVec3,
    /// j's contact point on its surface, relative to j's centre / D (lab frame).
    pub rc_j: DVec3,
    /// The contact solver did not converge and this is its fallback estimate (superquadrics;
    /// counted and reported, never dropped).
    pub fallback: bool,
}

impl PairContact {
    /// A contact with a flat wall: overlap (penetration depth), the wall's outward normal at
    /// the deepest point, and the deepest point relative to the centre.
    pub fn wall(overlap: f64, normal: DVec3, rc: DVec3) -> Self {
        Self {
            overlap,
            normal,
            k: DVec3::ZERO,
            s: 0.0,
            t: 0.0,
            rc_i: rc,
            rc_j: rc + overlap * normal,
            fallback: false,
        }
    }
}

/// Contact between i (axis `u_i`, half length `h_i`, radius `r_i`) and j at relative
/// position `r = x_j - x_i` (the image already chosen).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::packing::contact::pair_contact;
/// let c = pair_contact(DVec3::Z, 0.0, 0.5, DVec3::new(0.9, 0.0, 0.0), DVec3::Z, 0.0, 0.5);
/// assert!((c.overlap - 0.1).abs() < 1e-15 && c.normal == DVec3::X);
/// ```
#[inline]
pub fn pair_contact(
    u_i: DVec3,
    h_i: f64,
    r_i: f64,
    r: DVec3,
    u_j: DVec3,
    h_j: f64,
    r_j: f64,
) -> PairContact {
    contact_from_closest(closest(u_i, h_i, r, u_j, h_j), u_i, r_i, u_j, r_j)
}

/// [`pair_contact`] when it overlaps, `None` when the closest points are certainly farther
/// apart than r_i + r_j (the overlap would be negative): a squared-distance test before the
/// square root and the contact frame. `Some` carries exactly [`pair_contact`]'s value.
#[inline]
pub fn pair_contact_if_close(
    u_i: DVec3,
    h_i: f64,
    r_i: f64,
    r: DVec3,
    u_j: DVec3,
    h_j: f64,
    r_j: f64,
) -> Option<PairContact> {
    let c = closest(u_i, h_i, r, u_j, h_j);
    let reach = r_i + r_j;
    // margin: sqrt(k2) then exceeds r_i + r_j despite round-off, so the overlap is < 0
    if c.k.length_squared() > reach * reach * (1.0 + 1e-12) {
        return None;
    }
    Some(contact_from_closest(c, u_i, r_i, u_j, r_j))
}

#[inline]
fn closest(
    u_i: DVec3,
    h_i: f64,
    r: DVec3,
    u_j: DVec3,
    h_j: f64,
) -> crate::geometry::SegmentClosest {
    if h_i == 0.0 && h_j == 0.0 {
        crate::geometry::SegmentClosest {
            k: r,
            s: 0.0,
            t: 0.0,
        }
    } else {
        segment_closest(u_i, h_i, r, u_j, h_j)
    }
}

#[inline]
fn contact_from_closest(
    c: crate::geometry::SegmentClosest,
    u_i: DVec3,
    r_i: f64,
    u_j: DVec3,
    r_j: f64,
) -> PairContact {
    let d = c.k.length();
    let normal = if d > 1e-300 {
        c.k / d
    } else {
        // Axes intersect: any direction normal to both axes separates them; fall back to a
        // fixed perpendicular for parallel or zero-length axes (measure-zero configurations).
        let n = u_i.cross(u_j);
        if n.length_squared() > 1e-24 {
            n.normalize()
        } else {
            u_i.any_orthonormal_vector()
        }
    };
    PairContact {
        overlap: r_i + r_j - d,
        normal,
        k: c.k,
        s: c.s,
        t: c.t,
        rc_i: c.s * u_i + r_i * normal,
        rc_j: c.t * u_j - r_j * normal,
        fallback: false,
    }
}

/// Contact of two bodies of which at least one is a superquadric (a sphere is treated as the
/// superquadric with exponents 2). Rods of nonzero length cannot meet superquadrics (scene
/// validation rejects such mixtures); they are approximated by their circumscribed
/// spheroid and flagged as a fallback. `warm` is the pair's cached Newton start, replaced by
/// this solution.
pub fn superquadric_contact(
    a: &Body,
    xa: DVec3,
    qa: DQuat,
    b: &Body,
    xb: DVec3,
    qb: DQuat,
    warm: &mut Option<sq::WarmStart>,
) -> PairContact {
    let (sa, sb) = (&a.contact_shape, &b.contact_shape);
    let r = sq::contact_prepared(sa, xa, qa, sb, xb, qb, &solver_options(), warm.as_ref());
    from_solver(r, a, b, warm)
}

/// The packing's options of the superquadric contact solver: the defaults, with gaps beyond
/// 0.05 D not computed exactly (far beyond the overlap tolerance and the contact-number
/// window), and a Newton tolerance of 1e-10 instead of 1e-12. After a move, a warm-started
/// solve takes one full step (of ~1e-5 to 1e-4 L, L the smallest semi-axis) and closes with a
/// chord step when that step's estimated error is below the tolerance; at 1e-12 one in five
/// of the packing's solves failed that test and took a second full step, at 1e-10 one in
/// fifty does (measured on the 750-superball scene to 4 000 compression steps). The overlaps
/// stay within ~5e-11 D (inside the bound test's round-off margin of 1e-10 D) and the normals
/// within 1e-9 (tested below), far below the overlap tolerance of 1e-4 D and the thesis's own
/// criterion |dq| < 1e-6.
#[inline]
pub(crate) fn solver_options() -> ContactOptions {
    ContactOptions {
        gap_cutoff: 0.05,
        tolerance: 1e-10,
        ..ContactOptions::default()
    }
}

/// The pair contact of a solver answer `r` for bodies `a`, `b`; its Newton start, if any,
/// replaces `warm`.
pub(crate) fn from_solver(
    r: sq::ContactResult,
    a: &Body,
    b: &Body,
    warm: &mut Option<sq::WarmStart>,
) -> PairContact {
    if r.warm.is_some() {
        *warm = r.warm;
    }
    PairContact {
        overlap: r.overlap,
        normal: r.normal,
        k: DVec3::ZERO,
        s: 0.0,
        t: 0.0,
        rc_i: r.rc_a,
        rc_j: r.rc_b,
        fallback: a.contact_approximate || b.contact_approximate || r.is_fallback(),
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};
    use rand::RngExt;

    use super::solver_options;
    use crate::geometry::superquadric::tests::{quat, rng, unit};
    use crate::geometry::superquadric::{
        ContactOptions, ContactStatus, PreparedShape, Superquadric, contact_prepared,
    };

    /// The packing's Newton tolerance (1e-10) against the solver's default (1e-12) on
    /// warm-started solves after packing-sized moves of superball pairs overlapping by about
    /// the overlap tolerance: the overlaps agree within 5e-11 D and the normals within 1e-9.
    /// (The saving is in the cost of the second iteration, a chord step instead of a full one,
    /// which the iteration count does not show.)
    #[test]
    fn the_packing_tolerance_keeps_contacts_within_the_bound_margin() {
        let mut r = rng(17);
        let tight = ContactOptions {
            tolerance: 1e-12,
            ..solver_options()
        };
        let mut compared = 0;
        for case in 0..400 {
            let s = Superquadric::superball(0.5, 2.5 + 2.0 * (case % 5) as f64 / 4.0);
            let p = PreparedShape::new(&s);
            let (qa, qb) = (quat(&mut r), quat(&mut r));
            let u = unit(&mut r);
            let reach = s.support_value(qa.conjugate() * u) + s.support_value(qb.conjugate() * -u);
            let xb = u * (reach - 1e-4);
            let cold = contact_prepared(&p, DVec3::ZERO, qa, &p, xb, qb, &tight, None);
            let Some(w) = cold.warm else { continue };
            // a move of the size the packing makes in its dense regime
            let step = r.random_range(1e-5..2e-4);
            let xb2 = xb + unit(&mut r) * step;
            let qb2 = (DQuat::from_scaled_axis(unit(&mut r) * step) * qb).normalize();
            let a = contact_prepared(
                &p,
                DVec3::ZERO,
                qa,
                &p,
                xb2,
                qb2,
                &solver_options(),
                Some(&w),
            );
            let b = contact_prepared(&p, DVec3::ZERO, qa, &p, xb2, qb2, &tight, Some(&w));
            assert_eq!(
                (a.status, b.status),
                (ContactStatus::Converged, ContactStatus::Converged)
            );
            assert!((a.overlap - b.overlap).abs() < 5e-11, "{a:?} {b:?}");
            assert!((a.normal - b.normal).length() < 1e-9, "{a:?} {b:?}");
            compared += 1;
        }
        assert!(compared > 300, "{compared}");
    }
}
