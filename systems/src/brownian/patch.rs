//! Field patches: the fibres' field and gradient from a first-order Taylor expansion about
//! the nearest node of a cubic lattice whose spacing follows the distance to the fibres
//! (an opt-in approximation, scene key `brownian.field_patch`).
//!
//! # Why
//! A nanoparticle moves a few nanometres per step, while the field of a fibre changes on the
//! scale of the distance d to its surface (micrometres to millimetres). The exact field with
//! its gradient (elliptic integrals carried with dual numbers) is most of the cost of a
//! Brownian step near a fibre (about 70 % in thesis 000's ch. 6 concentration case), and it is
//! recomputed every step although it barely changes.
//!
//! # Scheme
//! For a relative patch size ε in (0, 0.5] and a particle at p, d = distance from p to the
//! nearest fibre (clamped below at `floor`, the particle's radius), the lattice spacing is
//! h = 2^⌊log₂(ε d)⌋ (so ε d / 2 < h ≤ ε d; the exponent is read from the bits, exact), the
//! anchor is q = h · round(p / h) (exact: h is a power of two), and
//!
//!   B(p) ≈ B(q) + ∇B(q) (p − q),   ∇B(p) ≈ ∇B(q),
//!
//! with B(q), ∇B(q) the exact field ([`crate::field::total_field_gradient`]). |p − q| ≤ √3 h/2
//! ≤ 0.87 ε d, so the gradient (and with it the force on a saturated moment) has a relative
//! error of order ε and B of order ε², where the field's length scale is at least d (true
//! outside a cylinder: its field is smooth away from the surface, the edges included). Over
//! random points 80 nm to 200 µm from a thesis cylinder, rim and mantle included, the worst
//! relative errors measured are 0.6 ε in ∇B and 0.02 ε² in B (`patch_error_is_of_order_eps`).
//!
//! The approximate field is a *function of position only*: it does not depend on the path,
//! the thread count, the step control or where a run was resumed, so runs stay bitwise
//! reproducible. The per-particle memo ([`FieldPatches`]) only saves re-evaluating the same
//! anchor; with it, a particle that stays on one patch costs no field evaluation at all.
//! The field is discontinuous across patch borders by O(ε²)|B| (and O(ε)|∇B| in the gradient),
//! which the step control sees as noise of that size.
//!
//! Not in thesis 000 (it evaluates the exact field every step); off by default.

use glam::DVec3;

use crate::field::{CylinderSource, FieldGradient, total_field_gradient};

/// One particle's memo: the anchor it last used and the exact field there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    /// Biased binary exponent of the lattice spacing.
    pub level: u64,
    /// Lattice indices of the anchor.
    pub key: [i64; 3],
    /// Anchor q \[m\].
    pub anchor: DVec3,
    /// Exact field and gradient at the anchor.
    pub field: FieldGradient,
}

/// Per-particle memos, cached across evaluations (in `ParticleId` order).
#[derive(Debug, Clone, Default)]
pub struct FieldPatches {
    /// One memo per particle (`None` before its first evaluation).
    pub slots: Vec<Option<Patch>>,
}

impl FieldPatches {
    /// Make room for `n` particles (new slots empty).
    pub fn ensure(&mut self, n: usize) {
        if self.slots.len() != n {
            self.slots.resize(n, None);
        }
    }
}

/// The lattice of `p` for patch size `eps` at distance `d` \[m\] from the fibres: (level,
/// indices, anchor). None when εd is not a positive normal number or p/h does not fit an i64.
pub fn lattice_node(p: DVec3, eps: f64, d: f64) -> Option<(u64, [i64; 3], DVec3)> {
    let s = eps * d;
    if !(s.is_normal() && s > 0.0) {
        return None;
    }
    let level = (s.to_bits() >> 52) & 0x7ff;
    let h = f64::from_bits(level << 52);
    let r = p / h;
    if !(r.abs().max_element() < 4.0e18) {
        return None;
    }
    let key = [r.x.round() as i64, r.y.round() as i64, r.z.round() as i64];
    let anchor = DVec3::new(key[0] as f64, key[1] as f64, key[2] as f64) * h;
    Some((level, key, anchor))
}

/// Distance \[m\] from `p` to the nearest of `sources` (infinite without sources).
pub fn fibre_distance(sources: &[CylinderSource], p: DVec3) -> f64 {
    sources
        .iter()
        .map(|s| s.distance(p))
        .fold(f64::INFINITY, f64::min)
}

/// The patched field at `p` (see the module docs), reusing `slot` when `p` is on the same
/// patch. `floor` \[m\] bounds d from below (the particle radius: a centre is never closer).
/// Falls back to the exact field where no lattice exists (εd not normal, p far out of range).
pub fn patched_field(
    sources: &[CylinderSource],
    b_ext: DVec3,
    tol: f64,
    eps: f64,
    floor: f64,
    p: DVec3,
    slot: &mut Option<Patch>,
) -> FieldGradient {
    let d = fibre_distance(sources, p).max(floor);
    let Some((level, key, anchor)) = lattice_node(p, eps, d) else {
        return total_field_gradient(sources, b_ext, p, tol);
    };
    let field = match slot {
        Some(s) if s.level == level && s.key == key => s.field,
        _ => {
            let field = total_field_gradient(sources, b_ext, anchor, tol);
            *slot = Some(Patch {
                level,
                key,
                anchor,
                field,
            });
            field
        }
    };
    FieldGradient {
        b: field.b + field.grad_b * (p - anchor),
        grad_b: field.grad_b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn cylinder() -> CylinderSource {
        CylinderSource::new(
            DVec3::ZERO,
            DVec3::Z,
            300e-6,
            6e-3,
            DVec3::new(0.0, 0.0, 985e3),
        )
    }

    #[test]
    fn the_lattice_spacing_is_a_power_of_two_between_half_and_all_of_eps_d() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        for _ in 0..1000 {
            let p = DVec3::new(rng.random(), rng.random(), rng.random()) * 1e-3;
            let (eps, d) = (rng.random_range(1e-4..0.5), rng.random_range(1e-9..1e-2));
            let (level, key, q) = lattice_node(p, eps, d).unwrap();
            let h = f64::from_bits(level << 52);
            assert!(h <= eps * d && h > eps * d / 2.0, "h {h} eps d {}", eps * d);
            assert!((p - q).abs().max_element() <= h / 2.0);
            assert_eq!(key[0] as f64 * h, q.x);
        }
        assert!(lattice_node(DVec3::ONE, 0.0, 1.0).is_none());
        assert!(lattice_node(DVec3::ONE, 1e-3, f64::INFINITY).is_none());
        assert!(lattice_node(DVec3::splat(1e30), 1e-3, 1e-9).is_none());
    }

    /// Worst relative error of B and ∇B against the exact field over random points between
    /// 75 nm and 200 µm from a thesis cylinder (the rim included), for two patch sizes; the
    /// gradient error must scale like ε and B's like ε² (and both be small).
    #[test]
    fn patch_error_is_of_order_eps() {
        let src = [cylinder()];
        let b_ext = DVec3::new(0.0, 0.0, 1.0);
        let mut worst = Vec::new();
        for eps in [1e-2, 1e-3] {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
            let (mut eb, mut eg) = (0.0_f64, 0.0_f64);
            for _ in 0..400 {
                // points above the end face near the rim, and beside the mantle
                let d = 10f64.powf(rng.random_range(-7.1..-3.7));
                let t = rng.random_range(0.0..std::f64::consts::TAU);
                let p = if rng.random_bool(0.5) {
                    let rho = rng.random_range(0.0..320e-6);
                    DVec3::new(rho * t.cos(), rho * t.sin(), 6e-3 + d)
                } else {
                    let z = rng.random_range(-6.2e-3..6.2e-3);
                    DVec3::new((300e-6 + d) * t.cos(), (300e-6 + d) * t.sin(), z)
                };
                let exact = total_field_gradient(&src, b_ext, p, 1e-12);
                let mut slot = None;
                let approx = patched_field(&src, b_ext, 1e-12, eps, 75e-9, p, &mut slot);
                eb = eb.max((approx.b - exact.b).length() / exact.b.length());
                let gn = exact.grad_b.to_cols_array().iter().map(|v| v * v).sum::<f64>();
                let diff = (approx.grad_b - exact.grad_b).to_cols_array();
                eg = eg.max((diff.iter().map(|v| v * v).sum::<f64>() / gn).sqrt());
                // the memo is reused at the same point and gives the same value
                let again = patched_field(&src, b_ext, 1e-12, eps, 75e-9, p, &mut slot);
                assert_eq!(again, approx);
            }
            worst.push((eb, eg));
        }
        let ((b2, g2), (b3, g3)) = (worst[0], worst[1]);
        // measured: gradient 0.61 ε and 0.51 ε, B 0.019 ε² and 0.019 ε²
        assert!(g2 < 1e-2 && g3 < 1e-3, "gradient errors {g2} {g3}");
        assert!(b2 < 0.1 * 1e-4 && b3 < 0.1 * 1e-6, "field errors {b2} {b3}");
        assert!(g2 / g3 > 5.0 && b2 / b3 > 30.0, "scaling {worst:?}");
    }

    #[test]
    fn the_patched_field_is_a_function_of_position_only() {
        let src = [cylinder()];
        let p = DVec3::new(250e-6, 10e-6, 6.05e-3);
        let mut fresh = None;
        let direct = patched_field(&src, DVec3::Z, 1e-10, 1e-3, 75e-9, p, &mut fresh);
        // a memo holding a neighbouring patch must not leak into p's value
        let mut stale = None;
        let near = p + DVec3::new(3e-8, 0.0, 0.0);
        patched_field(&src, DVec3::Z, 1e-10, 1e-3, 75e-9, near, &mut stale);
        let via = patched_field(&src, DVec3::Z, 1e-10, 1e-3, 75e-9, p, &mut stale);
        assert_eq!(direct, via);
        assert_ne!(stale, None);
    }
}
