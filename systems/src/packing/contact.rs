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
/// window).
#[inline]
pub(crate) fn solver_options() -> ContactOptions {
    ContactOptions {
        gap_cutoff: 0.05,
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
