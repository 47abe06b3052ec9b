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
//! For a relative patch size ε in (0, 0.5], the space is tiled by nested cubic lattices of
//! spacing h_L = 2^L (cells ⌊p/h_L⌋, the cells of a level inside those of every coarser one).
//! A particle at p uses the coarsest level whose cell centre q_L(p) satisfies
//! h_L ≤ ε d(q_L), with d the distance to the nearest fibre (clamped below at `floor`, the
//! particle's radius), so h_L is between about ε d / 2 and 1.8 ε d. The level depends only on
//! the cell (the conditions at p's level and above are those of its cells), and
//!
//!   B(p) ≈ B(q) + ∇B(q) (p − q),   ∇B(p) ≈ ∇B(q),
//!
//! with B(q), ∇B(q) the exact field ([`crate::field::total_field_gradient`]). |p − q| ≤ (√3/2) h
//! ≤ 1.6 ε d(p), so the gradient (and with it the force on a saturated moment) has a relative
//! error of order ε and B of order ε², where the field's length scale is at least d (true
//! outside a cylinder: its field is smooth away from the surface, the edges included). Over
//! random points 80 nm to 200 µm from a thesis cylinder, rim and mantle included, the worst
//! relative errors measured are 0.6 ε in ∇B and 0.023 ε² in B (`patch_error_is_of_order_eps`).
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

/// Spacing 2^(level − 1023) \[m\] of lattice level `level` (a biased binary exponent).
#[inline]
fn spacing(level: u64) -> f64 {
    f64::from_bits(level << 52)
}

/// The cell of `p` at `level`: its indices ⌊p/h⌋ and its centre (None when p/h does not fit
/// an i64).
#[inline]
fn cell(p: DVec3, level: u64) -> Option<([i64; 3], DVec3)> {
    let h = spacing(level);
    let r = (p / h).floor();
    if !r.is_finite() || r.abs().max_element() >= 4.0e18 {
        return None;
    }
    let key = [r.x as i64, r.y as i64, r.z as i64];
    Some((key, (r + DVec3::splat(0.5)) * h))
}

/// The patch of `p` (see the module docs): (level, cell indices, anchor), where `dist(q)` is
/// the distance \[m\] from a point to the fibres (already bounded below by the particle
/// radius). None when ε·dist(p) is not a positive normal number or p is out of range.
pub fn lattice_node(
    p: DVec3,
    eps: f64,
    dist: impl Fn(DVec3) -> f64,
) -> Option<(u64, [i64; 3], DVec3)> {
    // no level coarser than ε d(p)/(1 − 0.87 ε) ≤ 1.77 ε d(p) can qualify, and every level
    // finer than ε d(p)/(1 + 0.87 ε) does: start at the coarsest candidate, refine
    let s = 1.77 * eps * dist(p);
    if !(s.is_normal() && s > 0.0) {
        return None;
    }
    let mut level = (s.to_bits() >> 52) & 0x7ff;
    loop {
        let (key, anchor) = cell(p, level)?;
        if spacing(level) <= eps * dist(anchor) || level <= 1 {
            return Some((level, key, anchor));
        }
        level -= 1;
    }
}

/// Distance \[m\] from `p` to the nearest of `sources` (infinite without sources).
pub fn fibre_distance(sources: &[CylinderSource], p: DVec3) -> f64 {
    sources
        .iter()
        .map(|s| s.distance(p))
        .fold(f64::INFINITY, f64::min)
}

/// The patched field at `p` (see the module docs), reusing `slot` when `p` is in the same
/// cell: then no distance is computed at all (the cells nest, so the level of a point depends
/// only on its cell). `floor` \[m\] bounds distances from below (the particle radius: a centre
/// is never closer). Falls back to the exact field where no lattice exists.
pub fn patched_field(
    sources: &[CylinderSource],
    b_ext: DVec3,
    tol: f64,
    eps: f64,
    floor: f64,
    p: DVec3,
    slot: &mut Option<Patch>,
) -> FieldGradient {
    let hit = slot.filter(|s| cell(p, s.level).is_some_and(|(key, _)| key == s.key));
    let patch = match hit {
        Some(s) => s,
        None => {
            let dist = |q: DVec3| fibre_distance(sources, q).max(floor);
            let Some((level, key, anchor)) = lattice_node(p, eps, dist) else {
                return total_field_gradient(sources, b_ext, p, tol);
            };
            let s = Patch {
                level,
                key,
                anchor,
                field: total_field_gradient(sources, b_ext, anchor, tol),
            };
            *slot = Some(s);
            s
        }
    };
    FieldGradient {
        b: patch.field.b + patch.field.grad_b * (p - patch.anchor),
        grad_b: patch.field.grad_b,
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

    /// The level is the coarsest whose cell centre satisfies h ≤ ε d(centre), p lies in its
    /// cell, and every point of that cell gets the same patch (the memo's premise).
    #[test]
    fn the_patch_is_the_coarsest_qualifying_cell_and_depends_only_on_the_cell() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        let centre = DVec3::new(3e-4, -2e-4, 1e-4);
        let dist = |q: DVec3| (q - centre).length().max(1e-8);
        for _ in 0..2000 {
            let p = centre + DVec3::new(rng.random(), rng.random(), rng.random()) * 1e-3;
            let eps = rng.random_range(1e-4..0.5);
            let (level, key, q) = lattice_node(p, eps, dist).unwrap();
            let h = spacing(level);
            assert!(h <= eps * dist(q), "h {h} eps d {}", eps * dist(q));
            for coarser in level + 1..level + 4 {
                let (_, qc) = cell(p, coarser).unwrap();
                assert!(
                    spacing(coarser) > eps * dist(qc),
                    "level {coarser} qualifies too"
                );
            }
            assert!((p - q).abs().max_element() <= h / 2.0);
            assert_eq!((key[0] as f64 + 0.5) * h, q.x);
            let other = q + DVec3::new(rng.random(), rng.random(), rng.random()) * h
                - DVec3::splat(0.5 * h);
            assert_eq!(lattice_node(other, eps, dist), Some((level, key, q)));
        }
        assert!(lattice_node(DVec3::ONE, 0.0, |_| 1.0).is_none());
        assert!(lattice_node(DVec3::ONE, 1e-3, |_| f64::INFINITY).is_none());
        assert!(lattice_node(DVec3::splat(1e30), 1e-3, |_| 1e-9).is_none());
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
                let gn = exact
                    .grad_b
                    .to_cols_array()
                    .iter()
                    .map(|v| v * v)
                    .sum::<f64>();
                let diff = (approx.grad_b - exact.grad_b).to_cols_array();
                eg = eg.max((diff.iter().map(|v| v * v).sum::<f64>() / gn).sqrt());
                // the memo is reused at the same point and gives the same value
                let again = patched_field(&src, b_ext, 1e-12, eps, 75e-9, p, &mut slot);
                assert_eq!(again, approx);
            }
            worst.push((eb, eg));
        }
        let ((b2, g2), (b3, g3)) = (worst[0], worst[1]);
        // measured: gradient 0.57 ε and 0.55 ε, B 0.023 ε² and 0.022 ε²
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
