//! Spheroid–spheroid (and spheroid–sphere) common-normal contact and the closed-form
//! spheroid–plane contact (see the parent module header for the method and its choices).

use glam::{DMat3, DQuat, DVec3};

use super::{PosedSpheroid, outer};
use crate::collision::toi::{ContactGeometry, Plane};
use crate::geometry::superquadric::{self, ContactOptions, Superquadric};

/// Result of [`spheroid_contact`].
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::{PosedSpheroid, Spheroid, spheroid_contact};
/// let disc = Spheroid::new(1.0, 0.1);
/// let a = PosedSpheroid::new(disc, DVec3::ZERO, DQuat::IDENTITY);
/// let b = PosedSpheroid::new(disc, DVec3::new(0.0, 0.0, 0.25), DQuat::IDENTITY);
/// let c = spheroid_contact(&a, &b, None).unwrap();
/// assert!((c.geometry.gap - 0.05).abs() < 1e-12 && (c.geometry.normal - DVec3::Z).length() < 1e-9);
/// assert!(c.converged);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpheroidContact {
    /// Normal (a→b), lever arms to the midpoint of the witness points, signed gap \[m\].
    pub geometry: ContactGeometry,
    /// Witness point on *a* relative to its centre (support point along the normal) \[m\].
    pub witness_a: DVec3,
    /// Witness point on *b* relative to its centre (support point along minus the normal) \[m\].
    pub witness_b: DVec3,
    /// Whether the Newton iteration converged (otherwise the superquadric GJK/EPA fallback or
    /// the best iterate is returned).
    pub converged: bool,
    /// Newton iterations spent.
    pub iterations: u32,
}

/// Value, gradient and Hessian (over R³) of the separating-axis function at a unit `u`.
struct Eval {
    f: f64,
    g: DVec3,
    h: DMat3,
}

/// `−h(u)`, its gradient and Hessian added to `ev` for one body.
fn add_body(ev: &mut Eval, body: &PosedSpheroid, u: DVec3) {
    let mu = body.shape_times(u);
    let s = u.dot(mu).max(0.0).sqrt();
    if s <= 0.0 {
        ev.f = f64::NAN;
        return;
    }
    let a2 = body.shape.equatorial * body.shape.equatorial;
    let k = body.shape.polar * body.shape.polar - a2;
    let m = DMat3::from_diagonal(DVec3::splat(a2)) + outer(body.axis, body.axis) * k;
    ev.f -= s;
    ev.g -= mu / s;
    ev.h -= (m - outer(mu, mu) / (s * s)) / s;
}

/// The separating-axis function alone.
fn value(a: &PosedSpheroid, b: &PosedSpheroid, d: DVec3, u: DVec3) -> f64 {
    u.dot(d) - a.support_value(u) - b.support_value(u)
}

fn eval(a: &PosedSpheroid, b: &PosedSpheroid, d: DVec3, u: DVec3) -> Eval {
    let mut ev = Eval {
        f: u.dot(d),
        g: d,
        h: DMat3::ZERO,
    };
    add_body(&mut ev, a, u);
    add_body(&mut ev, b, u);
    ev
}

/// Newton ascent of `f` on the unit sphere from `seed`; returns the last iterate, its
/// evaluation, whether it converged and the iterations used.
fn ascend(
    a: &PosedSpheroid,
    b: &PosedSpheroid,
    d: DVec3,
    seed: DVec3,
    scale: f64,
) -> Option<(DVec3, Eval, bool, u32)> {
    const MAX_ITERATIONS: u32 = 60;
    let mut u = seed.try_normalize()?;
    let mut ev = eval(a, b, d, u);
    if !ev.f.is_finite() {
        return None;
    }
    let tol = 1e-12 * scale;
    let floor = 1e-9 * scale;
    let mut radius = 0.5;
    for it in 0..MAX_ITERATIONS {
        let (t1, t2) = u.any_orthonormal_pair();
        let g = (t1.dot(ev.g), t2.dot(ev.g));
        let gnorm = (g.0 * g.0 + g.1 * g.1).sqrt();
        if gnorm <= tol {
            return Some((u, ev, true, it));
        }
        let ht1 = ev.h * t1;
        let ht2 = ev.h * t2;
        let (mut a11, a12, mut a22) = (t1.dot(ht1) - ev.f, t1.dot(ht2), t2.dot(ht2) - ev.f);
        // largest eigenvalue of the 2×2 tangent Hessian; shift it below −floor (ascent direction)
        let mean = 0.5 * (a11 + a22);
        let lam_max = mean + (0.25 * (a11 - a22) * (a11 - a22) + a12 * a12).sqrt();
        if lam_max > -floor {
            a11 -= lam_max + floor;
            a22 -= lam_max + floor;
        }
        let det = a11 * a22 - a12 * a12;
        if !(det > 0.0 && det.is_finite()) {
            return Some((u, ev, false, it));
        }
        // ξ = −A⁻¹ g
        let mut xi = (
            -(a22 * g.0 - a12 * g.1) / det,
            -(-a12 * g.0 + a11 * g.1) / det,
        );
        let mut len = (xi.0 * xi.0 + xi.1 * xi.1).sqrt();
        if len > radius {
            xi = (xi.0 * radius / len, xi.1 * radius / len);
            len = radius;
        }
        let mut accepted = None;
        for _ in 0..40 {
            let Some(un) = (u + t1 * xi.0 + t2 * xi.1).try_normalize() else {
                break;
            };
            let fnew = value(a, b, d, un);
            if fnew.is_finite() && fnew >= ev.f - 1e-15 * scale {
                accepted = Some((un, eval(a, b, d, un)));
                break;
            }
            xi = (xi.0 * 0.25, xi.1 * 0.25);
            len *= 0.25;
            radius = len;
        }
        let Some((un, evn)) = accepted else {
            // no ascent possible: stationary to rounding
            return Some((u, ev, gnorm <= 1e-9 * scale, it + 1));
        };
        if len >= radius * 0.999 {
            radius = (2.0 * radius).min(1.5);
        }
        u = un;
        ev = evn;
        if len < 1e-15 {
            let conv = eval_tangent_norm(&ev, u) <= 1e-9 * scale;
            return Some((u, ev, conv, it + 1));
        }
    }
    let conv = eval_tangent_norm(&ev, u) <= 1e-9 * scale;
    Some((u, ev, conv, MAX_ITERATIONS))
}

fn eval_tangent_norm(ev: &Eval, u: DVec3) -> f64 {
    (ev.g - u * ev.g.dot(u)).length()
}

fn finish(
    a: &PosedSpheroid,
    b: &PosedSpheroid,
    u: DVec3,
    gap: f64,
    converged: bool,
    iterations: u32,
) -> SpheroidContact {
    let wa = a.support_point(u);
    let wb = -b.support_point(u);
    let pa = a.centre + wa;
    let pb = b.centre + wb;
    let mid = (pa + pb) * 0.5;
    SpheroidContact {
        geometry: ContactGeometry {
            normal: u,
            r_a: mid - a.centre,
            r_b: mid - b.centre,
            gap,
        },
        witness_a: wa,
        witness_b: wb,
        converged,
        iterations,
    }
}

/// Contact of spheroid (or sphere) *a* with *b*: common normal from *a* to *b*, signed gap
/// (negative: penetration depth), witness points and the common contact point.
///
/// `warm` is a previous normal of the pair (a warm start); `None` for invalid shapes or
/// non-finite poses. See the module header for the method; [`SpheroidContact`] has an example.
/// The centres are taken as given (pass a minimum image for periodic domains).
pub fn spheroid_contact(
    a: &PosedSpheroid,
    b: &PosedSpheroid,
    warm: Option<DVec3>,
) -> Option<SpheroidContact> {
    if !(a.is_valid() && b.is_valid()) {
        return None;
    }
    let d = b.centre - a.centre;
    let scale = a.shape.bounding_radius() + b.shape.bounding_radius();
    let toward = |e: DVec3| if e.dot(d) < 0.0 { -e } else { e };
    let mut seeds: [(f64, DVec3); 4] = [(f64::NEG_INFINITY, DVec3::ZERO); 4];
    let mut count = 0;
    for s in [
        warm,
        d.try_normalize(),
        Some(toward(a.axis)),
        Some(toward(b.axis)),
    ]
    .into_iter()
    .flatten()
    {
        let Some(u) = s.try_normalize() else { continue };
        let f = value(a, b, d, u);
        if f.is_finite() {
            seeds[count] = (f, u);
            count += 1;
        }
    }
    if count == 0 {
        let u = if d.length() > 0.0 { d } else { DVec3::Z };
        seeds[0] = (0.0, u.normalize_or(DVec3::Z));
        count = 1;
    }
    let seeds = &mut seeds[..count];
    seeds.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut spent = 0;
    let mut best: Option<(DVec3, f64)> = None;
    for &(_, seed) in seeds.iter() {
        let Some((u, ev, converged, it)) = ascend(a, b, d, seed, scale) else {
            continue;
        };
        spent += it;
        let near_side = u.dot(d) >= -1e-12 * d.length();
        if converged && near_side {
            return Some(finish(a, b, u, ev.f, true, spent));
        }
        if near_side && best.is_none_or(|(_, f)| ev.f > f) {
            best = Some((u, ev.f));
        }
    }
    // fallback: the superquadric GJK/EPA + Newton contact
    let sq = |p: &PosedSpheroid| Superquadric {
        semi_axes: DVec3::new(p.shape.equatorial, p.shape.equatorial, p.shape.polar),
        exponents: DVec3::splat(2.0),
    };
    let qa = DQuat::from_rotation_arc(DVec3::Z, a.axis);
    let qb = DQuat::from_rotation_arc(DVec3::Z, b.axis);
    let opts = ContactOptions {
        gap_cutoff: f64::INFINITY,
        ..ContactOptions::default()
    };
    let r = superquadric::contact(&sq(a), a.centre, qa, &sq(b), b.centre, qb, &opts, None);
    if r.overlap.is_finite() && r.normal.is_finite() && !r.is_fallback() {
        let u = r.normal;
        return Some(finish(a, b, u, value(a, b, d, u), true, spent));
    }
    best.map(|(u, f)| finish(a, b, u, f, false, spent))
}

/// Contact of a spheroid (body *a*) with a wall (body *b*), closed form: the normal is `−n_w`,
/// the lever arm of *a* runs to its deepest point `−E⁻¹ n_w/√(n_wᵀE⁻¹n_w)`, the gap is
/// `n_w·(x − x_w) − √(n_wᵀE⁻¹n_w)`; the wall's lever arm is the contact point relative to the
/// plane's reference point.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::{PosedSpheroid, Spheroid, spheroid_plane_contact};
/// use magsep_systems::collision::toi::Plane;
/// // a disc standing on its rim, 0.5 m above the floor
/// let disc = PosedSpheroid::new(Spheroid::new(1.0, 0.1), DVec3::new(0.0, 0.0, 1.5),
///                               DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2));
/// let c = spheroid_plane_contact(&disc, &Plane::new(DVec3::ZERO, DVec3::Z));
/// assert!((c.gap - 0.5).abs() < 1e-12 && (c.r_a + DVec3::Z).length() < 1e-12);
/// ```
pub fn spheroid_plane_contact(a: &PosedSpheroid, plane: &Plane) -> ContactGeometry {
    let n = plane.normal;
    let s = a.support_value(n);
    let r_a = -a.shape_times(n) / s;
    ContactGeometry {
        normal: -n,
        r_a,
        r_b: a.centre + r_a - plane.point,
        gap: plane.signed_distance(a.centre) - s,
    }
}
