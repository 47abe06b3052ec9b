//! Parameters of the spectral Ewald product chosen from a requested relative tolerance τ.
//!
//! With Λ = ln(1/τ) + 1, and margins found necessary in the tests (errors measured against
//! the dense product fell 2–30× below τ for τ = 1e-2 … 1e-8 with them, and exceeded τ by up
//! to 60× without):
//!
//! * real-space cut-off: ξ r_c = √(Λ + 1.5); the neglected remainder is ≈ (2ξr_c/√π)
//!   e^{−ξ²r_c²} relative to S(r_c) (both real-space kernels are erfc/Gaussian-damped);
//! * grid spacing: (π/h)²/(4ξ²) = Λ_g = Λ + 1.5 ln Λ + 1.5, so the Hasimoto factor
//!   (1 + k²/4ξ²)e^{−k²/4ξ²} at the grid's Nyquist wavenumber π/h is ≈ Λ_g e^{−Λ_g} ≤ e^{−Λ}
//!   (wave-space truncation; the polynomial factor is why Λ_g > Λ);
//! * Gaussian split η (spreading and gathering each carry e^{−ηk²/8ξ²}, the middle kernel
//!   e^{−(1−η)k²/4ξ²}): a spread wavenumber k' aliases onto k = k' − 2π/h; the product of the
//!   spreading factor at k', the kernel and the gathering factor at k is largest at
//!   k = η π/h, where it is e^{−2η(1−η/2)Λ_g}. η solves 2η(1−η/2)Λ_g = Λ + δ with the margin
//!   δ = 0.5 + 0.07Λ (`alias_margin`; η ≈ 0.47 / 0.50 / 0.54 / 0.58 at
//!   τ = 1e-2 / 1e-4 / 1e-6 / 1e-8): the smallest η with this margin, because the support grows
//!   as √η. The fixed η = 0.6 used before had δ = 1.9–2.6 and gave errors 2–30× below τ with
//!   a support one point wider at τ = 1e-4 (11 instead of 10); measured errors with δ = 1.2
//!   were τ/6 … τ/1.03 (the last at τ = 1e-8, hence δ growing with Λ). The middle kernel,
//!   sampled in real space, aliases as e^{−4(1−η)Λ_g} ≪ e^{−Λ};
//! * spreading support P points per dimension with half-width w = √(ηΛ/2)/ξ:
//!   the truncated Gaussian tail is e^{−2ξ²w²/η} = e^{−Λ}; P = ⌈2w/h⌉, placed
//!   symmetrically about the particle (first index ⌊t − P/2 + 1⌋, t the position in grid
//!   units), so that the first point left out on either side is at least Ph/2 ≥ w away. The
//!   rule used before, ⌈2w/h⌉ + 2, left out only points ≥ w + h away (tail e^{−1.6Λ} at
//!   τ = 1e-4) and cost (10/8)³ ≈ 2× the spreading and gathering work; measured errors
//!   against the dense and direct products with both rules are in the `support_error_probe`
//!   test.
//!
//! The cut-off r_c itself is free: it trades real-space pairs against grid points. It is
//! chosen by minimising a cost model (nanoseconds per pair and per grid point log n, estimated
//! on the development machine) over a geometric ladder of cut-offs; when the direct sum (ξ = 0,
//! no grid, all pairs) is cheaper it is used. Grids above [`MAX_FFT`] per side and pair lists
//! above [`MAX_PAIR_BLOCKS`] are never chosen (an error instead of running out of memory); the
//! direct sum, streamed without storage (module `direct`), is bounded by the same number of
//! pairs (a time limit: N ≤ 7071).

use glam::DVec3;

/// Margin δ (in e-folds) of the spreading aliasing e^{−2η(1−η/2)Λ_g} below e^{−Λ}.
pub(crate) fn alias_margin(lam: f64) -> f64 {
    0.5 + 0.07 * lam
}

/// The Gaussian split η: 2η(1 − η/2)Λ_g = Λ + δ ([`alias_margin`]), at most 0.9.
fn split(lam: f64, lam_g: f64) -> f64 {
    let c = ((lam + alias_margin(lam)) / lam_g).min(0.99);
    (1.0 - (1.0 - c).sqrt()).min(0.9)
}

/// Largest FFT length per side (memory: about 100 n³ bytes while preparing the kernel).
pub const MAX_FFT: usize = 320;

/// Largest number of stored pair blocks (20 bytes each).
pub const MAX_PAIR_BLOCKS: f64 = 5e7;

/// Smallest accepted tolerance (below it rounding in the FFTs dominates).
pub const MIN_TOLERANCE: f64 = 1e-12;
/// Largest accepted tolerance.
pub const MAX_TOLERANCE: f64 = 0.1;

/// The Ewald parameters of one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Params {
    /// requested relative tolerance
    pub tolerance: f64,
    /// Ewald splitting parameter ξ \[1/m\] (0: direct sum, no grid)
    pub xi: f64,
    /// real-space cut-off \[m\] (infinite for the direct sum)
    pub cutoff: f64,
    /// grid spacing \[m\]
    pub h: f64,
    /// spreading support in points per dimension
    pub support: usize,
    /// Gaussian parameter of the middle kernel, ξ/√(1 − η) \[1/m\]
    pub alpha: f64,
    /// Gaussian split η between spreading/gathering and the middle kernel
    pub split: f64,
    /// grid points per dimension holding particles (the FFT grid is `fft_n` ≥ 2 `m`)
    pub m: usize,
    /// FFT length per dimension (zero padding to ≥ 2 m: aperiodic convolution)
    pub fft_n: usize,
    /// grid origin \[m\]
    pub origin: DVec3,
}

/// Smallest 2^a 3^b 5^c ≥ `n` (fast FFT lengths).
pub(crate) fn good_size(n: usize) -> usize {
    let mut k = n.max(2);
    loop {
        let mut r = k;
        for p in [2, 3, 5] {
            while r.is_multiple_of(p) {
                r /= p;
            }
        }
        if r == 1 {
            return k;
        }
        k += 1;
    }
}

/// Λ = ln(1/τ) + 1.
fn lambda(tolerance: f64) -> f64 {
    (1.0 / tolerance).ln() + 1.0
}

/// Bounding box (lo, hi).
fn bounds(positions: &[DVec3]) -> (DVec3, DVec3) {
    positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

impl Params {
    /// Parameters for a given cut-off (`None` or a cut-off reaching across the whole
    /// configuration: direct sum). The cut-off is raised to at least 2 max(a) so that every
    /// overlapping pair is in the real-space list.
    pub fn with_cutoff(
        tolerance: f64,
        cutoff: Option<f64>,
        positions: &[DVec3],
        radii: &[f64],
    ) -> Self {
        Self::with_cutoff_support(tolerance, cutoff, positions, radii, 0)
    }

    /// As [`Params::with_cutoff`] with the support widened by `extra` points beyond
    /// ⌈2w/h⌉ (the probes of the error against the support).
    pub fn with_cutoff_support(
        tolerance: f64,
        cutoff: Option<f64>,
        positions: &[DVec3],
        radii: &[f64],
        extra: usize,
    ) -> Self {
        let a_max = radii.iter().fold(0.0_f64, |m, a| m.max(*a));
        let (lo, hi) = bounds(positions);
        let extent = if positions.is_empty() {
            0.0
        } else {
            (hi - lo).max_element()
        };
        let direct = Self {
            tolerance,
            xi: 0.0,
            cutoff: f64::INFINITY,
            h: 0.0,
            support: 0,
            alpha: 0.0,
            split: 0.0,
            m: 0,
            fft_n: 0,
            origin: lo,
        };
        let Some(rc) = cutoff else { return direct };
        let rc = rc.max(2.0 * a_max * (1.0 + 1e-12));
        if !(rc.is_finite() && rc > 0.0) || rc >= extent * 3f64.sqrt() {
            return direct;
        }
        let lam = lambda(tolerance);
        let (lr, lg, ls) = (lam + 1.5, lam + 1.5 * lam.ln() + 1.5, lam);
        let xi = lr.sqrt() / rc;
        let h = std::f64::consts::PI / (2.0 * xi * lg.sqrt());
        let split = split(lam, lg);
        let w = (split * ls / 2.0).sqrt() / xi;
        // centred support of P points: the first point left out on either side is at least
        // P h/2 ≥ w from the particle (weight ≤ e^{−Λ})
        let support = (2.0 * w / h).ceil() as usize + extra;
        // a support starting at ⌊t − P/2 + 1⌋ (t the position in grid units from the origin)
        // needs t ≥ P/2 − 1 and m ≥ t + P/2 + 1: margin P/2 (one point spare below) and
        // m = ⌈extent/h + P⌉ + 1 (the smallest grid, hence the smallest FFT length)
        let margin = support as f64 / 2.0 * h;
        let m = ((extent + 2.0 * margin) / h).ceil() as usize + 1;
        Self {
            tolerance,
            xi,
            cutoff: rc,
            h,
            support,
            alpha: xi / (1.0 - split).sqrt(),
            split,
            m,
            fft_n: good_size(2 * m),
            origin: lo - DVec3::splat(margin),
        }
    }

    /// True for the direct sum (no grid).
    pub fn is_direct(&self) -> bool {
        self.xi == 0.0
    }

    /// True if the grid and the pair list fit the memory limits ([`MAX_FFT`],
    /// [`MAX_PAIR_BLOCKS`]) for `pairs` estimated pair blocks.
    fn fits(&self, pairs: f64) -> bool {
        self.fft_n <= MAX_FFT && pairs <= MAX_PAIR_BLOCKS
    }

    /// Parameters minimising the cost model over cut-offs r_c = 2 max(a) · 1.25^k (k ≥ 2) among those
    /// that fit the memory limits; `None` when none does (a configuration far too spread out
    /// for one grid and too large for the direct sum).
    /// `products` is the expected number of products per prepared configuration.
    pub fn choose(
        tolerance: f64,
        positions: &[DVec3],
        radii: &[f64],
        products: f64,
    ) -> Option<Self> {
        let n = positions.len() as f64;
        let (lo, hi) = bounds(positions);
        let a_max = radii.iter().fold(0.0_f64, |m, a| m.max(*a));
        let mono = radii.windows(2).all(|w| w[0] == w[1]);
        let fields = if mono { 6.0 } else { 12.0 };
        let volume = if positions.is_empty() {
            1.0
        } else {
            (hi - lo).max(DVec3::splat(2.0 * a_max)).element_product()
        };
        let density = n / volume;
        // nanoseconds (2-core development machine): pair set-up with erfc/exp, stored pair
        // product, streamed direct pair (evaluated in every product, nothing stored: 5.6×
        // cheaper than the stored direct pairs' 40 ns set-up + 14 products at 8 ns, measured
        // by `direct_product_timing`), FFT per point·log2(points) and field,
        // spreading+gathering per particle, support point and field. The kernel's transform
        // is cached across steps.
        let (pair_setup, pair_apply, direct_pair, fft_unit, spread) = (150.0, 8.0, 1.9, 1.0, 1.0);
        let cost_of = |p: &Params| -> f64 {
            if p.is_direct() {
                return n * n * products * direct_pair;
            }
            let pairs =
                (n * density * 4.0 / 3.0 * std::f64::consts::PI * p.cutoff.powi(3)).min(n * n);
            let g = (p.fft_n as f64).powi(3);
            let per = pairs * pair_apply
                + 0.6 * fields * fft_unit * g * g.log2()
                + 2.0 * n * (p.support as f64).powi(3) * spread * fields / 2.0;
            pairs * pair_setup + products * per
        };
        let pairs_of = |p: &Params| {
            (n * density * 4.0 / 3.0 * std::f64::consts::PI * p.cutoff.powi(3)).min(n * n)
        };
        // the streamed direct sum stores nothing, but its pairs are bounded like a stored
        // list's (above 5e7 pairs one product takes ~0.1 s and a grid is always cheaper)
        let direct = Self::with_cutoff(tolerance, None, positions, radii);
        let mut best = (n * n <= MAX_PAIR_BLOCKS).then_some(direct);
        let mut best_cost = best.as_ref().map_or(f64::INFINITY, &cost_of);
        // the ladder starts at 2 max(a)·1.25² (smaller cut-offs need very fine grids)
        let mut rc = 2.0 * a_max * 1.25 * 1.25;
        for _ in 0..60 {
            let p = Self::with_cutoff(tolerance, Some(rc), positions, radii);
            if p.is_direct() {
                break;
            }
            let c = cost_of(&p);
            if p.fits(pairs_of(&p)) && c < best_cost {
                best = Some(p);
                best_cost = c;
            }
            rc *= 1.25;
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every particle's centred support (first index ⌊t − (P − 1)/2 + 0.5⌋, as `wave`
    /// places it) lies inside the m³ grid without clamping, for the corners of the
    /// configuration, at several tolerances and cut-offs.
    #[test]
    fn every_support_fits_the_grid_unclamped() {
        let a = 1e-7;
        let mut positions: Vec<DVec3> = (0..200)
            .map(|k| {
                let u = |s: usize| ((k * s + 17) % 97) as f64 / 96.0;
                DVec3::new(u(31), u(57), u(73)) * 40.0 * a
            })
            .collect();
        positions.push(DVec3::ZERO);
        positions.push(DVec3::splat(40.0 * a));
        let radii = vec![a; positions.len()];
        let mut checked = 0;
        for tol in [1e-2, 1e-4, 1e-6, 1e-10] {
            for rc in [3.0 * a, 5.0 * a, 9.0 * a] {
                let p = Params::with_cutoff(tol, Some(rc), &positions, &radii);
                assert!(!p.is_direct());
                let s = p.support as f64;
                for x in &positions {
                    let t = (*x - p.origin) / p.h;
                    for k in 0..3 {
                        let m0 = (t[k] - (s - 1.0) / 2.0 + 0.5).floor();
                        assert!(m0 >= 0.0, "tol {tol} rc {rc}: start {m0}");
                        assert!(
                            m0 + s <= p.m as f64,
                            "tol {tol} rc {rc}: {m0} + {s} > {}",
                            p.m
                        );
                        checked += 1;
                    }
                }
                assert!(p.fft_n >= 2 * p.m);
            }
        }
        assert_eq!(checked, 4 * 3 * 202 * 3);
    }
}
