//! Time of impact (TOI) of ballistically moving and rotating spheroids (thesis 002, §4.2.1.3:
//! within a step "the linear and angular velocities change only due to collisions").
//!
//! **Motion.** `x(t) = x₀ + v t`, `q(t) = exp(½ Ω t) q₀` with Ω constant (world frame), so the
//! symmetry axis rotates rigidly: `e(t) = Rot(Ω t) e₀`.
//!
//! **Method: separating-axis conservative advancement** (after Mirtich's conservative
//! advancement; the thesis bisects the pseudo-step until `|ΔTOI| < ε_t = 0.001 h` instead). At
//! the current time `t` the common-normal contact gives the gap `g`, the normal `u` and the
//! gap rate `ġ = u·(v_b + Ω_b×w_b − v_a − Ω_a×w_a)` (`w` the witness lever arms; the envelope
//! theorem makes this the exact derivative). For the *fixed* axis `u` the separating-axis
//! function `f_u(s) = u·d(s) − h_a(u, s) − h_b(u, s)` is a lower bound of the gap at every
//! time `s` (equal at `t`), and cheap to evaluate in closed form together with its rate: with
//! `p = u·e(s)`, `h = √(a² + k p²)` (`k = c² − a²`) and `ḣ = k p ṗ/h`, `ṗ = u·(Ω×e)`. Its rate
//! is bounded by `B_u = |u·(v_b − v_a)| + |u×Ω_a| R_a + |u×Ω_b| R_b` (`R` the bounding radii;
//! `ḣ = r·(u×Ω)` with `r` the support point) and its second derivative by
//! `A_u = Σ [|k| w⊥ (w⊥ + |Ω|) + R² w⊥²] / min(a, c)` (`w⊥ = |u×Ω|`; from
//! `ḧ = [k(ṗ² + p p̈) − ḣ²]/h`, `|ṗ| ≤ w⊥`, `|p̈| ≤ w⊥|Ω|`, `h ≥ min(a, c)`; translation is
//! linear). From a time `s` with `D = f_u(s) − level > 0` the step
//! `Δs = max(D/B_u, (ḟ_u + √(ḟ_u² + 2 A_u D))/A_u)` (the larger of the Lipschitz and the
//! second-order Taylor certificate) never jumps over a time where `f_u`, hence the gap, falls to
//! `level`; the second-order step keeps near-contact pairs that move apart or roll (small `D`,
//! `ḟ_u ≥ 0`) from crawling. Each outer iteration advances along `f_u` to `level` (at most 64
//! such steps), then recomputes the contact (warm-started):
//! * apart (`g > δ_hit`): `level = δ_hit/2`, so the true gap stays positive;
//! * in contact (`g ≤ δ_hit`) and approaching faster than `min_approach`: **impact at `t`**;
//! * in contact but not approaching (grazing, sliding, separating, or approaching slower than
//!   `min_approach`): `level = min(−δ_pen, g − δ_pen/100)`, i.e. the pair may sink to the
//!   penetration tolerance before the contact is re-examined; a pair already deeper (it started
//!   there, approaches slower than `min_approach`, or a sustained contact crept there) may sink
//!   by `δ_pen/100` per re-examination.
//!
//! **Tolerances** (`L` = the smallest semi-axis of the pair, the disc half-thickness for
//! flakes): contact band `δ_hit =` [`SPHEROID_CONTACT_TOLERANCE`]` · L`, penetration tolerance
//! `δ_pen =` [`SPHEROID_PENETRATION_TOLERANCE`]` · L`. Guarantee (up to the accuracy of the
//! contact solve): every contact that approaches faster than `min_approach` is reported, no later
//! than the first time its penetration exceeds `δ_pen`; an approaching impact is reported
//! with gap `≤ δ_hit`. A sustained contact (a sequence of impacts of one pair, e.g. a rocking
//! disc) can creep deeper by at most `δ_pen/100` per impact, so its penetration stays below
//! `δ_pen (1 + n/100)` after `n` impacts. No contact is missed however fast the rotation (the bound contains it) or
//! grazing the approach. The loop is capped at 20 000 contact evaluations (never reached in the
//! tests; then `None` is returned).
//!
//! A bounding-sphere test (analytic sphere TOI with the bounding radii) skips the time before the
//! bounding spheres can touch, and the centre line and both symmetry axes are tried as fixed
//! separating axes before any contact solve: if one certifies a gap above `δ_hit` for the whole
//! horizon the pair is dismissed at once (same answer, no Newton iteration). Spheroid–plane uses the same loop on the closed-form gap.

use glam::{DQuat, DVec3};

use super::contact::spheroid_contact;
use super::{PosedSpheroid, Spheroid};
use crate::collision::toi::{Ballistic, Plane, sphere_sphere_toi};

/// Contact band `δ_hit` in units of the smallest semi-axis of the pair [-].
pub const SPHEROID_CONTACT_TOLERANCE: f64 = 1e-3;
/// Penetration tolerance `δ_pen` in units of the smallest semi-axis of the pair [-].
pub const SPHEROID_PENETRATION_TOLERANCE: f64 = 1e-2;

const MAX_OUTER: u32 = 20_000;
const MAX_INNER: u32 = 64;

/// A predicted impact.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::collision::spheroid::Impact;
/// let i = Impact { time: 0.1, approach_speed: 2.0, normal: DVec3::Z };
/// assert!(i.approach_speed > 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact {
    /// Time from the start of the search \[s\].
    pub time: f64,
    /// Normal approach speed of the contact points, `−ġ` [m/s].
    pub approach_speed: f64,
    /// Contact normal from *a* to *b* at the impact [-].
    pub normal: DVec3,
}

/// Symmetry axis `e₀` rotated by `Ω t`.
fn axis_at(e0: DVec3, omega: DVec3, t: f64) -> DVec3 {
    let phi = omega * t;
    if phi == DVec3::ZERO {
        e0
    } else {
        DQuat::from_scaled_axis(phi) * e0
    }
}

/// Support value `h = √(a² + k p²)` (`p = u·e`) of a rotating spheroid along a fixed unit `u` and
/// its rate `ḣ = k p ṗ / h`, `ṗ = u·(Ω×e)`.
fn support_and_rate(shape: &Spheroid, e: DVec3, omega: DVec3, u: DVec3) -> (f64, f64) {
    let a2 = shape.equatorial * shape.equatorial;
    let k = shape.polar * shape.polar - a2;
    let p = u.dot(e);
    let h = (a2 + k * p * p).max(0.0).sqrt();
    let pdot = u.dot(omega.cross(e));
    (h, k * p * pdot / h)
}

/// Bounds `(B, A)` on `|ḣ|` and `|ḧ|` of a spheroid rotating at `Ω`, along the fixed unit `u`
/// (see the module header).
fn rate_bounds(shape: &Spheroid, omega: DVec3, u: DVec3) -> (f64, f64) {
    let w_perp = u.cross(omega).length();
    let w = omega.length();
    let r = shape.bounding_radius();
    let k = (shape.polar * shape.polar - shape.equatorial * shape.equatorial).abs();
    let accel = (k * w_perp * (w_perp + w) + r * r * w_perp * w_perp) / shape.min_semi_axis();
    (r * w_perp, accel)
}

/// Largest `τ` certified by value `dist = f − level > 0`, rate `rate = ḟ` and the bounds
/// `|ḟ| ≤ b`, `|f̈| ≤ acc`: the larger of the Lipschitz step `dist/b` and the positive root of
/// `dist + rate τ − acc τ²/2`.
fn safe_step(dist: f64, rate: f64, b: f64, acc: f64) -> f64 {
    let first = if b > 0.0 { dist / b } else { f64::INFINITY };
    let second = if acc > 0.0 {
        (rate + (rate * rate + 2.0 * acc * dist).max(0.0).sqrt()) / acc
    } else if rate < 0.0 {
        dist / -rate
    } else {
        f64::INFINITY
    };
    first.max(second)
}

/// The outer loop (see the module header). `contact(t, warm)` gives `(g, ġ, u)`, `fixed(u, s)`
/// the separating-axis function and its rate, `bounds(u)` the bounds `(B, A)` on its first and
/// second derivatives.
#[allow(clippy::too_many_arguments)]
fn advance(
    t0: f64,
    horizon: f64,
    min_approach: f64,
    delta_hit: f64,
    delta_pen: f64,
    warm: Option<DVec3>,
    mut contact: impl FnMut(f64, Option<DVec3>) -> Option<(f64, f64, DVec3)>,
    fixed: impl Fn(DVec3, f64) -> (f64, f64),
    bounds: impl Fn(DVec3) -> (f64, f64),
) -> Option<Impact> {
    let mut t = t0;
    let mut u = warm;
    for _ in 0..MAX_OUTER {
        let (g, gdot, n) = contact(t, u)?;
        if !(g.is_finite() && gdot.is_finite()) {
            return None;
        }
        u = Some(n);
        if g <= delta_hit && -gdot > min_approach {
            return Some(Impact {
                time: t,
                approach_speed: -gdot,
                normal: n,
            });
        }
        let level = if g > delta_hit {
            0.5 * delta_hit
        } else {
            (-delta_pen).min(g - 0.01 * delta_pen)
        };
        let (b, acc) = bounds(n);
        if !(b.is_finite() && acc.is_finite()) {
            return None;
        }
        let mut s = t;
        let (mut fs, mut rate) = fixed(n, s);
        for _ in 0..MAX_INNER {
            let step = safe_step(fs - level, rate, b, acc);
            if step.is_nan() || step <= 0.0 {
                break;
            }
            s += step;
            if s >= horizon {
                return None;
            }
            (fs, rate) = fixed(n, s);
            if !(fs.is_finite() && rate.is_finite()) {
                return None;
            }
            if fs - level <= 1e-3 * (g - level) {
                break;
            }
        }
        // guarantee progress against rounding
        let min_step = 1e-12 * horizon.max(f64::MIN_POSITIVE);
        t = s.max(t + min_step);
        if t > horizon {
            return None;
        }
    }
    None
}

/// Earliest impact within `[0, horizon]` \[s\] of spheroid `sa` (state `a`) with `sb` (state
/// `b`) approaching faster than `min_approach` [m/s]; positions must be minimum images of each
/// other. `warm` is a previous contact normal of the pair. `Some` with `time = 0` for a pair
/// already in contact and approaching. See the module header for the method and tolerances.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::{Spheroid, spheroid_pair_toi};
/// use magsep_systems::collision::toi::Ballistic;
/// // two 1:10 discs face to face, gap 0.3, closing at 1 m/s: impact near t = 0.3 s
/// let disc = Spheroid::new(1.0, 0.1);
/// let a = Ballistic::translating(DVec3::ZERO, DVec3::ZERO);
/// let b = Ballistic::translating(DVec3::new(0.0, 0.0, 0.5), -DVec3::Z);
/// let hit = spheroid_pair_toi(&disc, &a, &disc, &b, 1.0, 0.0, None).unwrap();
/// assert!((hit.time - 0.3).abs() <= 1e-4 && (hit.approach_speed - 1.0).abs() < 1e-9);
/// ```
#[allow(clippy::too_many_arguments)]
pub fn spheroid_pair_toi(
    sa: &Spheroid,
    a: &Ballistic,
    sb: &Spheroid,
    b: &Ballistic,
    horizon: f64,
    min_approach: f64,
    warm: Option<DVec3>,
) -> Option<Impact> {
    if !(sa.is_valid() && sb.is_valid() && horizon >= 0.0 && horizon.is_finite()) {
        return None;
    }
    let finite = |x: &Ballistic| {
        x.position.is_finite()
            && x.velocity.is_finite()
            && x.angular_velocity.is_finite()
            && x.orientation.is_finite()
    };
    if !(finite(a) && finite(b)) {
        return None;
    }
    let (ra, rb) = (sa.bounding_radius(), sb.bounding_radius());
    let l = sa.min_semi_axis().min(sb.min_semi_axis());
    let (delta_hit, delta_pen) = (
        SPHEROID_CONTACT_TOLERANCE * l,
        SPHEROID_PENETRATION_TOLERANCE * l,
    );
    let dx = b.position - a.position;
    let dv = b.velocity - a.velocity;
    let t0 = if dx.length() > ra + rb {
        sphere_sphere_toi(dx, dv, ra + rb, horizon)?
    } else {
        0.0
    };
    let (ea, eb) = (
        a.orientation.normalize() * DVec3::Z,
        b.orientation.normalize() * DVec3::Z,
    );
    let (wa, wb) = (a.angular_velocity, b.angular_velocity);
    let pose = |t: f64| {
        (
            PosedSpheroid {
                shape: *sa,
                centre: DVec3::ZERO,
                axis: axis_at(ea, wa, t),
            },
            PosedSpheroid {
                shape: *sb,
                centre: dx + dv * t,
                axis: axis_at(eb, wb, t),
            },
        )
    };
    let contact = |t: f64, warm: Option<DVec3>| {
        let (pa, pb) = pose(t);
        let c = spheroid_contact(&pa, &pb, warm)?;
        let n = c.geometry.normal;
        let gdot = n.dot(dv + wb.cross(c.witness_b) - wa.cross(c.witness_a));
        Some((c.geometry.gap, gdot, n))
    };
    let fixed = |u: DVec3, s: f64| {
        let (ha, hda) = support_and_rate(sa, axis_at(ea, wa, s), wa, u);
        let (hb, hdb) = support_and_rate(sb, axis_at(eb, wb, s), wb, u);
        (u.dot(dx + dv * s) - ha - hb, u.dot(dv) - hda - hdb)
    };
    let bounds = |u: DVec3| {
        let (ba, aa) = rate_bounds(sa, wa, u);
        let (bb, ab) = rate_bounds(sb, wb, u);
        (u.dot(dv).abs() + ba + bb, aa + ab)
    };
    // cheap exit without a contact solve: a fixed separating axis (centre line or a symmetry
    // axis) that certifies a gap above δ_hit for the whole horizon (the loop could not report
    // an impact either)
    let d0 = dx + dv * t0;
    let toward = |e: DVec3| if e.dot(d0) < 0.0 { -e } else { e };
    for u in [
        d0.try_normalize(),
        Some(toward(axis_at(ea, wa, t0))),
        Some(toward(axis_at(eb, wb, t0))),
    ]
    .into_iter()
    .flatten()
    {
        let (f, rate) = fixed(u, t0);
        let (b, acc) = bounds(u);
        if f > delta_hit && safe_step(f - delta_hit, rate, b, acc) >= horizon - t0 {
            return None;
        }
    }
    advance(
        t0,
        horizon,
        min_approach,
        delta_hit,
        delta_pen,
        warm,
        contact,
        fixed,
        bounds,
    )
}

/// Earliest impact within `[0, horizon]` \[s\] of spheroid `s` (state `a`) with a wall, approaching
/// faster than `min_approach` [m/s]; the normal of the impact is `−n_w` (from the particle to the
/// wall). Same method and tolerances as [`spheroid_pair_toi`], on the closed-form gap.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::collision::spheroid::{Spheroid, spheroid_plane_toi};
/// use magsep_systems::collision::toi::{Ballistic, Plane};
/// // a flat disc 0.4 above the floor (gap 0.3), spinning about x at 3 rad/s, falling at 1 m/s
/// let mut a = Ballistic::translating(DVec3::new(0.0, 0.0, 0.4), -DVec3::Z);
/// a.angular_velocity = DVec3::new(3.0, 0.0, 0.0);
/// let hit = spheroid_plane_toi(&Spheroid::new(1.0, 0.1), &a, &Plane::new(DVec3::ZERO, DVec3::Z), 1.0, 0.0);
/// assert!(hit.unwrap().time < 0.3); // the tilting rim arrives first
/// ```
pub fn spheroid_plane_toi(
    s: &Spheroid,
    a: &Ballistic,
    plane: &Plane,
    horizon: f64,
    min_approach: f64,
) -> Option<Impact> {
    let ok = s.is_valid()
        && horizon >= 0.0
        && horizon.is_finite()
        && a.position.is_finite()
        && a.velocity.is_finite()
        && a.angular_velocity.is_finite()
        && a.orientation.is_finite()
        && plane.normal.is_finite()
        && plane.point.is_finite();
    if !ok {
        return None;
    }
    let r = s.bounding_radius();
    let l = s.min_semi_axis();
    let (delta_hit, delta_pen) = (
        SPHEROID_CONTACT_TOLERANCE * l,
        SPHEROID_PENETRATION_TOLERANCE * l,
    );
    let n = plane.normal;
    let (x0, v, w) = (a.position, a.velocity, a.angular_velocity);
    let e0 = a.orientation.normalize() * DVec3::Z;
    let dist0 = plane.signed_distance(x0);
    let vn = v.dot(n);
    let t0 = if dist0 > r {
        if vn >= 0.0 {
            return None;
        }
        let t = (dist0 - r) / -vn;
        if t > horizon {
            return None;
        }
        t
    } else {
        0.0
    };
    let posed = |t: f64| PosedSpheroid {
        shape: *s,
        centre: x0 + v * t,
        axis: axis_at(e0, w, t),
    };
    let contact = |t: f64, _warm: Option<DVec3>| {
        let p = posed(t);
        let h = p.support_value(n);
        let r_a = -p.shape_times(n) / h;
        let g = plane.signed_distance(p.centre) - h;
        Some((g, n.dot(v + w.cross(r_a)), -n))
    };
    let fixed = |_u: DVec3, t: f64| {
        let (h, hdot) = support_and_rate(s, axis_at(e0, w, t), w, n);
        (plane.signed_distance(x0 + v * t) - h, vn - hdot)
    };
    let bounds = |_u: DVec3| {
        let (b, acc) = rate_bounds(s, w, n);
        (vn.abs() + b, acc)
    };
    advance(
        t0,
        horizon,
        min_approach,
        delta_hit,
        delta_pen,
        None,
        contact,
        fixed,
        bounds,
    )
}
