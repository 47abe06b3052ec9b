//! Single-particle overlap-removal moves of the mechanical contraction method.
//!
//! **Revised scheme** (thesis 000, ch. 3, eqs. 3.2-3.13). Maximising the overlap-removal rate
//! s_i = sum_j (v + w x r_c,ij) . n_ij under the kinetic-energy constraint
//! c = m v.v/2 + w.I w/2 gives
//!   v = -F / (lambda m),  w = I^-1 T / lambda,  F = sum n_ij,  T = sum n_ij x r_c,ij,
//!   lambda = sqrt((F.F/m + T.I^-1 T) / (2c)),
//! and the move x += delta_min dt v, rotation by |w| delta_min dt about w.
//! Choices: n_ij is i's outward normal towards j (so v points away from j); c = 1, density 1,
//! lengths in units of D (the thesis's units); erratum E-000-4: w is a lab-frame vector, so the
//! rotation is applied on the left, q <- r(w) q (the printed R_t r is only right for a
//! body-frame w); erratum E-000-3 (c = 1/2, not 2, recovers eq. 2.6) does not matter here since only
//! dt sqrt(c) enters.
//!
//! **Original scheme** (Williams-Philipse, thesis ch. 2, eqs. 2.4-2.10). With the unnormalised
//! separation vector k_sep = -k (from j's axis point to i's: erratum E-000-2 fixes this direction),
//! v = sum delta k_sep, and the axis rate w_a = (1/xi) sum delta l (k_sep.e_x) e_x + (...) e_y
//! (equivalently the part of sum delta l k_sep normal to the axis, divided by xi), step
//! dt_i = beta min_j delta_j / ((v + l_j w_a) . k_sep_j / |k_sep_j|) over contacts with a
//! positive rate, x += dt_i v, e_z <- normalise(e_z + dt_i w_a). eq. 2.7's lambda = 1/2 is
//! irrelevant since dt_i scales as 1/|rate|. xi defaults to I_xy of eq. 2.3 with m = 1
//! (erratum E-000-12). Particles whose contacts all have non-positive rates are not moved (E-000-13).
//!
//! The two random-direction variants of Fig. 3.4 (random w direction; random v and w
//! directions, magnitudes kept) are provided for the overlap-decay study only.

use glam::{DMat3, DQuat, DVec3};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

use super::contact::PairContact;
use super::state::{Body, BodyKind};

/// One overlapping contact of the moving particle, in the form the move rules need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveContact {
    /// Overlap delta > 0 / D.
    pub overlap: f64,
    /// i's outward unit normal towards j.
    pub normal: DVec3,
    /// Axis vector k from i's closest axis point to j's / D.
    pub k: DVec3,
    /// Position of i's closest axis point along its axis / D.
    pub s: f64,
    /// i's contact point relative to its centre / D (lab frame).
    pub rc: DVec3,
}

impl From<&PairContact> for MoveContact {
    fn from(c: &PairContact) -> Self {
        Self {
            overlap: c.overlap,
            normal: c.normal,
            k: c.k,
            s: c.s,
            rc: c.rc_i,
        }
    }
}

/// Which rule moves an overlapping particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MoveRule {
    /// Thesis ch. 3 with step factor `dt` (c = 1).
    Revised {
        /// Delta t of eq. 3.9.
        dt: f64,
    },
    /// Thesis ch. 2 with `beta` and `xi` (None: per-particle I_xy with m = 1).
    Original {
        /// beta of eq. 2.10.
        beta: f64,
        /// xi of eq. 2.6 / D^2.
        xi: Option<f64>,
    },
    /// Collective FIRE minimisation of the overlap energy (see `fire`); not a
    /// single-particle rule: [`overlap_removal_move`] returns None for it.
    Fire,
    /// Fig. 3.4 variant (c): revised, random direction of w (same magnitude).
    RevisedRandomRotation {
        /// Delta t.
        dt: f64,
    },
    /// Fig. 3.4 variant (d): revised, random directions of v and w (same magnitudes).
    RevisedRandomBoth {
        /// Delta t.
        dt: f64,
    },
}

/// A rigid displacement: translation and rotation (applied on the left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Displacement {
    /// Translation / D.
    pub dx: DVec3,
    /// Lab-frame rotation.
    pub rotation: DQuat,
}

fn random_unit(rng: &mut impl Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
        );
        let n = v.length();
        if n > 1e-12 {
            return v / n;
        }
    }
}

/// The revised rule's velocities (v, w) for contacts `cs` (before the delta_min dt scaling).
/// Returns None when the contact normals cancel (lambda = 0).
pub fn revised_velocities(
    body: &Body,
    orientation: DQuat,
    cs: &[MoveContact],
) -> Option<(DVec3, DVec3)> {
    let mut f = DVec3::ZERO;
    let mut t = DVec3::ZERO;
    for c in cs {
        f += c.normal;
        t += c.normal.cross(c.rc);
    }
    let m = body.volume;
    // I^-1 t = R (I_body^-1 (R^T t)): two matrix-vector products, not the matrix R I^-1 R^T
    let rot = DMat3::from_quat(orientation);
    let it = rot * (body.inertia.recip() * (rot.transpose() * t));
    let lambda = ((f.dot(f) / m + t.dot(it)) / 2.0).sqrt();
    if lambda.is_nan() || lambda <= 1e-300 {
        return None;
    }
    Some((-f / (lambda * m), it / lambda))
}

/// The move of a particle with `body` and `orientation` that overlaps the contacts `cs`
/// (all with overlap > 0). Returns None if the rule does not move it.
pub fn overlap_removal_move(
    rule: MoveRule,
    body: &Body,
    orientation: DQuat,
    cs: &[MoveContact],
    rng: &mut impl Rng,
) -> Option<Displacement> {
    if cs.is_empty() {
        return None;
    }
    let delta_min = cs.iter().map(|c| c.overlap).fold(f64::INFINITY, f64::min);
    match rule {
        MoveRule::Revised { dt }
        | MoveRule::RevisedRandomRotation { dt }
        | MoveRule::RevisedRandomBoth { dt } => {
            let (mut v, mut w) = revised_velocities(body, orientation, cs)?;
            let axisymmetric_rod = matches!(body.kind, BodyKind::Rod) && body.half_length > 0.0;
            if matches!(
                rule,
                MoveRule::RevisedRandomRotation { .. } | MoveRule::RevisedRandomBoth { .. }
            ) {
                let mut dir = random_unit(rng);
                if axisymmetric_rod {
                    // spin about the rod's own axis moves nothing: keep w normal to the axis
                    let a = orientation * DVec3::Z;
                    dir = (dir - dir.dot(a) * a).normalize_or_zero();
                }
                w = dir * w.length();
            }
            if matches!(rule, MoveRule::RevisedRandomBoth { .. }) {
                v = random_unit(rng) * v.length();
            }
            let scale = delta_min * dt;
            let wn = w.length();
            let rotation = if wn > 0.0 {
                DQuat::from_axis_angle(w / wn, wn * scale)
            } else {
                DQuat::IDENTITY
            };
            Some(Displacement {
                dx: v * scale,
                rotation,
            })
        }
        MoveRule::Fire => None,
        MoveRule::Original { beta, xi } => {
            let axis = orientation * DVec3::Z;
            let xi = xi.unwrap_or(body.xi_default);
            let mut v = DVec3::ZERO;
            let mut b = DVec3::ZERO;
            for c in cs {
                let ksep = -c.k;
                v += c.overlap * ksep;
                b += c.overlap * c.s * ksep;
            }
            // components of sum(delta l k_sep) along e_x and e_y: the part normal to the axis
            let wa = if body.half_length > 0.0 {
                (b - b.dot(axis) * axis) / xi
            } else {
                DVec3::ZERO
            };
            let mut best = f64::INFINITY;
            for c in cs {
                let ksep = -c.k;
                let kl = ksep.length();
                if kl <= 0.0 {
                    continue;
                }
                let rate = (v + c.s * wa).dot(ksep) / kl;
                if rate > 0.0 {
                    best = best.min(c.overlap / rate);
                }
            }
            if !best.is_finite() {
                return None;
            }
            let step = beta * best;
            let new_axis = (axis + step * wa).normalize_or_zero();
            let rotation = if new_axis == DVec3::ZERO {
                DQuat::IDENTITY
            } else {
                DQuat::from_rotation_arc(axis, new_axis)
            };
            Some(Displacement {
                dx: v * step,
                rotation,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use magsep_components::shape::Shape;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn revised_single_contact_energy_constraint_and_separation() {
        let body = Body::from_shape(
            &Shape::Spherocylinder {
                radius: 0.5,
                half_length: 2.0,
            },
            1.0,
        );
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let c = MoveContact {
            overlap: 0.05,
            normal: n,
            k: n * 0.95,
            s: 1.3,
            rc: 1.3 * (q * DVec3::Z) + 0.5 * n,
        };
        let (v, w) = revised_velocities(&body, q, &[c]).unwrap();
        // kinetic-energy constraint c = 1 (eq. 3.4) to 1e-12
        let rot = DMat3::from_quat(q);
        let inertia = rot * DMat3::from_diagonal(body.inertia) * rot.transpose();
        let energy = 0.5 * body.volume * v.dot(v) + 0.5 * w.dot(inertia * w);
        assert!((energy - 1.0).abs() < 1e-12, "{energy}");
        // the contact point recedes from j: (v + w x r_c) . n < 0
        let rc = c.s * (q * DVec3::Z) + body.radius * n;
        assert!((v + w.cross(rc)).dot(n) < 0.0);
        // step length bound |dx| <= delta_min dt sqrt(2c/m)
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let d =
            overlap_removal_move(MoveRule::Revised { dt: 0.1 }, &body, q, &[c], &mut rng).unwrap();
        assert!(d.dx.length() <= 0.05 * 0.1 * (2.0 / body.volume).sqrt() * (1.0 + 1e-12));
    }

    #[test]
    fn original_scheme_moves_half_way_for_a_sphere_pair() {
        // two unit-diameter spheres with overlap 0.1: beta = 1/2 moves i by delta/2 away from j
        let body = Body::from_shape(&Shape::Sphere { radius: 0.5 }, 1.0);
        let k = DVec3::new(0.9, 0.0, 0.0);
        let c = MoveContact {
            overlap: 0.1,
            normal: DVec3::X,
            k,
            s: 0.0,
            rc: 0.5 * DVec3::X,
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let d = overlap_removal_move(
            MoveRule::Original {
                beta: 0.5,
                xi: None,
            },
            &body,
            DQuat::IDENTITY,
            &[c],
            &mut rng,
        )
        .unwrap();
        assert!((d.dx - DVec3::new(-0.05, 0.0, 0.0)).length() < 1e-15);
    }
}
