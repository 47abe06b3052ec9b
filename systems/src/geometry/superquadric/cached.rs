//! The contact of [`super::contact()`] for shapes whose constants are computed once
//! ([`PreparedShape`]): a packing evaluates millions of contacts between a handful of shapes,
//! and the per-call constants (validity, the powers of the support map and inside function,
//! the bounding radii with their `powf`) cost about a tenth of a warm-started call. The
//! answer is bit for bit that of [`super::contact()`] (tested on random poses in
//! `tests_cached.rs`): only where the constants come from differs.

use glam::{DQuat, DVec3};

use super::contact::{
    ContactOptions, ContactResult, WarmStart, far_apart, invalid, pose_setup, solve_pair,
};
use super::mass::bounding_radius_cheap;
use super::prepared::Prepared;
use super::shape::Superquadric;

/// A superquadric with the constants of its contact computed once.
///
/// ```
/// use magsep_systems::geometry::superquadric::{PreparedShape, Superquadric};
/// let p = PreparedShape::new(&Superquadric::superball(0.5, 3.0));
/// assert_eq!(p.shape(), Superquadric::superball(0.5, 3.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedShape {
    shape: Superquadric,
    prepared: Prepared,
    valid: bool,
    /// |a| (the box's circumscribed radius) \[m\].
    box_radius: f64,
    /// The cheap bounding radius of the contact's sphere reject \[m\].
    outer: f64,
    /// Smallest semi-axis \[m\].
    min_axis: f64,
}

impl PreparedShape {
    /// The constants of `shape` (an invalid shape is kept and gives
    /// [`super::ContactStatus::InvalidInput`] in every contact).
    pub fn new(shape: &Superquadric) -> Self {
        Self {
            shape: *shape,
            prepared: shape.prepared(),
            valid: shape.is_valid(),
            box_radius: shape.semi_axes.length(),
            outer: bounding_radius_cheap(shape.semi_axes, shape.exponents),
            min_axis: shape.semi_axes.min_element(),
        }
    }

    /// The shape.
    pub fn shape(&self) -> Superquadric {
        self.shape
    }
}

/// [`super::contact()`] of two prepared shapes: the same answer, bit for bit.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{
///     contact, contact_prepared, ContactOptions, PreparedShape, Superquadric,
/// };
/// let s = Superquadric::superball(1.0, 3.0);
/// let p = PreparedShape::new(&s);
/// let o = ContactOptions::default();
/// let x = DVec3::new(1.9, 0.1, 0.0);
/// let fast = contact_prepared(&p, DVec3::ZERO, DQuat::IDENTITY, &p, x, DQuat::IDENTITY, &o, None);
/// let reference = contact(&s, DVec3::ZERO, DQuat::IDENTITY, &s, x, DQuat::IDENTITY, &o, None);
/// assert_eq!(fast, reference);
/// ```
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn contact_prepared(
    a: &PreparedShape,
    xa: DVec3,
    qa: DQuat,
    b: &PreparedShape,
    xb: DVec3,
    qb: DQuat,
    opts: &ContactOptions,
    warm: Option<&WarmStart>,
) -> ContactResult {
    prepared_pair(a, xa, qa, b, xb, qb, opts, warm, true)
}

/// [`contact_prepared`] for a pair known to lie within the cut-off
/// c = max(`gap_cutoff`, `newton_band` L), for instance one whose [`overlap_upper_bound`]
/// is above -c: the separating-axis reject along the centre line, which cannot end the call
/// of such a pair (that bound is at least the true overlap, so not below -c), is skipped.
/// The answer is [`contact_prepared`]'s whenever that reject would not have ended the call;
/// for a pair that is in fact farther apart it is still a correct contact (computed by the
/// warm start or GJK instead of the reject). A packing calls it after its bound test, so a
/// pair near contact costs two support points less.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{
///     contact_prepared, contact_prepared_within, ContactOptions, PreparedShape, Superquadric,
/// };
/// let p = PreparedShape::new(&Superquadric::superball(0.5, 3.0));
/// let o = ContactOptions::default();
/// let (q, x) = (DQuat::from_rotation_z(0.3), DVec3::new(0.97, 0.05, 0.0));
/// let full = contact_prepared(&p, DVec3::ZERO, DQuat::IDENTITY, &p, x, q, &o, None);
/// let within = contact_prepared_within(&p, DVec3::ZERO, DQuat::IDENTITY, &p, x, q, &o, None);
/// assert_eq!(full, within);
/// ```
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn contact_prepared_within(
    a: &PreparedShape,
    xa: DVec3,
    qa: DQuat,
    b: &PreparedShape,
    xb: DVec3,
    qb: DQuat,
    opts: &ContactOptions,
    warm: Option<&WarmStart>,
) -> ContactResult {
    prepared_pair(a, xa, qa, b, xb, qb, opts, warm, false)
}

/// The two functions above; `centre_line`: try the centre-line reject.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn prepared_pair(
    a: &PreparedShape,
    xa: DVec3,
    qa: DQuat,
    b: &PreparedShape,
    xb: DVec3,
    qb: DQuat,
    opts: &ContactOptions,
    warm: Option<&WarmStart>,
    centre_line: bool,
) -> ContactResult {
    let finite = xa.is_finite() && xb.is_finite() && qa.is_finite() && qb.is_finite();
    if !(finite && a.valid && b.valid && qa.length() > 0.0 && qb.length() > 0.0) {
        return invalid();
    }
    // the bounding-sphere rejects before any rotation is computed
    let d = xb - xa;
    let dist = d.length();
    let box_bound = a.box_radius + b.box_radius;
    if dist > box_bound {
        return far_apart(d, dist, box_bound);
    }
    let outer = a.outer + b.outer;
    if dist > outer {
        return far_apart(d, dist, outer);
    }
    let inner = a.min_axis + b.min_axis;
    let scale = a.min_axis.min(b.min_axis);
    let s = pose_setup(a.prepared, b.prepared, scale, xa, qa, xb, qb);
    let bounds = (inner - dist, outer - dist);
    solve_pair(&s, dist, bounds, opts, warm, centre_line)
}

/// An upper bound of the overlap \[m\] that [`contact_prepared`] computes for the same poses
/// (the exact overlap, to the solver's accuracy): the separating-axis value
/// h_a(u) + h_b(-u) - d.u (h the support functions, d = x_b - x_a) along one unit direction u,
/// which bounds the minimum over all directions (the overlap) from above. u is a's outward
/// normal at the point `warm.s_a` (the pair's last solution: after a small move it is nearly
/// the present common normal, so the bound is tight to second order in the move), else the
/// centre line. Beyond the bounding spheres the bound is r_a + r_b - |d|. Invalid shapes or
/// poses give +infinity (no information).
///
/// A caller that needs only the contacts overlapping by more than some tolerance can skip the
/// solve when this bound is below it (less a round-off margin): the skipped pair's solved
/// overlap would be below the tolerance too.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::geometry::superquadric::{
///     contact_prepared, overlap_upper_bound, ContactOptions, PreparedShape, Superquadric,
/// };
/// let p = PreparedShape::new(&Superquadric::superball(0.5, 3.0));
/// let q = DQuat::from_rotation_z(0.3);
/// let x = DVec3::new(0.97, 0.05, 0.0);
/// let c = contact_prepared(&p, DVec3::ZERO, DQuat::IDENTITY, &p, x, q, &ContactOptions::default(), None);
/// let bound = overlap_upper_bound(&p, DVec3::ZERO, DQuat::IDENTITY, &p, x, q, c.warm.as_ref());
/// assert!(bound >= c.overlap - 1e-12 && bound <= c.overlap + 1e-12);
/// ```
#[inline]
pub fn overlap_upper_bound(
    a: &PreparedShape,
    xa: DVec3,
    qa: DQuat,
    b: &PreparedShape,
    xb: DVec3,
    qb: DQuat,
    warm: Option<&WarmStart>,
) -> f64 {
    let finite = xa.is_finite() && xb.is_finite() && qa.is_finite() && qb.is_finite();
    if !(finite && a.valid && b.valid && qa.length() > 0.0 && qb.length() > 0.0) {
        return f64::INFINITY;
    }
    let d = xb - xa;
    let dist = d.length();
    let outer = a.outer + b.outer;
    if dist > outer {
        return outer - dist;
    }
    let (qa, qb) = (qa.normalize(), qb.normalize());
    // u in a's body frame and in the lab: from the warm point the body-frame normal needs no
    // rotation there and back
    // (a match, not `Option::or_else`: the compiler kept that a call, with the pair's
    // vectors passed through memory, on the path of every bound)
    let from_warm = match warm {
        Some(w) if w.s_a.is_finite() => a.prepared.eval(w.s_a).grad.try_normalize(),
        _ => None,
    };
    let (ua, u) = match from_warm {
        Some(ua) => (ua, qa * ua),
        None => match d.try_normalize() {
            Some(u) => (qa.conjugate() * u, u),
            None => return f64::INFINITY,
        },
    };
    let ub = qb.conjugate() * -u;
    let bound = a.prepared.support_value(ua) + b.prepared.support_value(ub) - d.dot(u);
    if bound.is_nan() { f64::INFINITY } else { bound }
}
