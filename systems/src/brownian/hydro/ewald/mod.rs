//! Matrix-free RPY mobility product in an unbounded fluid by free-space spectral Ewald
//! summation: v = μF in O(N log N) for a fixed tolerance, used by
//! [`MobilityMethod::SpectralEwald`](super::MobilityMethod::SpectralEwald) for both the drift
//! and (through Lanczos, [`super::krylov`]) the Brownian noise.
//!
//! # Equations
//! For non-overlapping pairs the polydisperse RPY block (Zuk et al. 2014) is
//! μ_ij = (1/8πη)[S(r) + (a_i²+a_j²)/6 · L(r)], S = I/r + r r/r³ (Stokeslet),
//! L = ∇²S = 2(I − 3r̂r̂)/r³, so the far-field velocity is
//! u_i = (1/8πη)[(S∗f)_i + (a_i²/6)(L∗f)_i + (L∗(a²f))_i/6] — two source densities f and a²f.
//! Both kernels are split (Ewald):
//! * Stokeslet: Hasimoto's split, wave part Ŝ(k)(1 + k²/4ξ²)e^{−k²/4ξ²}, real part
//!   (erfc(ξr)/r − 2ξe^{−ξ²r²}/√π) I + (erfc(ξr)/r + 2ξe^{−ξ²r²}/√π) r̂r̂;
//! * Laplacian: plain Gaussian split, wave part L̂(k)e^{−k²/4ξ²}, real part
//!   −2∇∇(erfc(ξr)/r) + 8πG_ξ I (L = −2∇∇(1/r) − 8πδI is harmonic away from 0, so the Gaussian
//!   split leaves an exponentially decaying remainder);
//!
//! (closed forms in `kernels`). The real parts are summed over pairs closer than r_c
//! (`near`, cell list); overlapping pairs r ≤ a_i + a_j get the exact Zuk overlap block
//! minus the wave part added by the grid; the self block is I/(6πηa_i) minus the grid's
//! self-interaction. The wave parts are computed on a grid (`wave`): Gaussian spreading of
//! f and a²f (P³ points each), an aperiodic convolution with the smooth middle kernel
//! sampled in real space and transformed by zero-padded FFTs (`fft3`), and Gaussian gathering.
//!
//! # Free space
//! Spectral Ewald is usually periodic. Here the middle kernel carries part of the Gaussian,
//! so it is smooth and known in closed form in real space; sampling it and convolving on a
//! grid zero-padded to twice the particles' region gives the aperiodic (free-space) discrete
//! convolution exactly (Hockney & Eastwood's method). The Vico–Greengard–Ferrando truncated
//! Green's function, used by af Klinteberg, Shamshirgar & Tornberg (2017) for the same
//! purpose, is needed when the kernel is only known in Fourier space; with the real-space
//! closed form it is not, and no oversampled precomputation is required. The only errors are
//! the Ewald truncations (real-space cut-off, Fourier resolution, Gaussian support) and the
//! aliasing of the sampled Gaussians and kernel, all of order e^{−Λ}, Λ = ln(1/τ) + 1 (see
//! [`params`]). No periodic images exist: translating all particles leaves v unchanged to
//! rounding (tested).
//!
//! # Accuracy and cost
//! Relative error ‖v − μ_RPY F‖/‖μ_RPY F‖ ≤ τ (the requested `ewald_tolerance`, 1e-12 … 0.1),
//! checked against the dense product in the tests for random polydisperse configurations with
//! overlaps. Cost per product O(N n_c + n³ log n + N P³) with n_c the neighbours within r_c
//! and n ≈ 2 D/h + 2P grid points per side (D the configuration's extent); the cut-off is
//! chosen by a cost model ([`params`]), so for dilute systems the grid grows with the volume,
//! not with N. Preparation (pair blocks and the kernel's transform) is done once per
//! configuration. When the cost model picks the direct sum (small or compact systems, e.g.
//! N = 1000 at φ = 0.01) nothing is stored: every product streams all pairs (`direct`,
//! vectorised, O(N²) flops, O(N) memory).
//!
//! # Towards positively split Ewald (PSE) noise
//! The noise currently takes μ^{1/2}w by Lanczos over the whole product. PSE (Fiore, Balboa
//! Usabiaga, Donev & Swan, J. Chem. Phys. 146, 124116 (2017)) would write
//! μ^{1/2}w = μ_real^{1/2}w₁ + μ_wave^{1/2}w₂, needing both parts positive semidefinite.
//! For equal radii a the wave part here has the transform Ŝ(k)e^{−k²/4ξ²}(1 + k²/4ξ² − a²k²/3)
//! (semidefinite for ξa ≤ √3/2) and the real part Ŝ(k)[sinc²(ka) − e^{−x}(1 + x − a²k²/3)],
//! x = k²/4ξ², which is not positive for every ξ (most negative value relative to k → 0:
//! −4e-4 at ξa = 0.5, −2.6e-6 at 0.4, −2.6e-11 at 0.3, near ka = π; Fiore et al. put sinc² in
//! the wave part instead). So at ξa ≤ 0.3 (the cost model picks ξa ≈ 0.1 at φ = 0.01) the
//! existing split is positive (tested: `tests_pse`); for unequal radii the two-density wave
//! part is indefinite. What is missing is a direct sampler of μ_wave: sampling the grid field
//! by circulant embedding (white noise on the n³ FFT grid, times a 3×3 factor of the kernel's
//! spectrum) is *not* exact in free space, because the DFT of the real-space-sampled,
//! truncated Stokeslet is indefinite at the lowest wavenumbers (−2.5 % of its largest
//! eigenvalue on a 40³ grid; the sample covariance came out ≈ 20 % off). Periodic PSE does not
//! have this problem; a free-space sampler needs a positive embedding of the 1/r tail.
//!
//! # Determinism
//! Every stage is parallel over independent rows, grid planes or FFT lines, each summed in a
//! fixed order, so results are bitwise identical for every rayon thread count.
//!
//! # Units and assumptions
//! SI: positions, radii \[m\], viscosity [Pa s], forces \[N\], velocities [m/s]. Unbounded
//! fluid, translational RPY (as the dense methods).

pub(crate) mod direct;
pub(crate) mod fft3;
pub(crate) mod kernels;
pub(crate) mod near;
pub mod params;
pub(crate) mod simd;
pub(crate) mod wave;

use glam::DVec3;

use super::HydroError;
use direct::Direct;
use near::Near;
use params::Params;
use wave::Wave;

/// Expected products per prepared configuration (drift + Krylov noise) for the cost model.
const PRODUCTS_PER_STEP: f64 = 12.0;

/// The prepared matrix-free RPY operator of one configuration.
#[derive(Debug)]
pub(crate) struct SpectralEwald {
    params: Params,
    real: Real,
    wave: Option<Wave>,
}

/// The pair part: a stored cut-off list with the grid, or the streamed direct sum.
#[derive(Debug)]
enum Real {
    Near(Near),
    Direct(Direct),
}

impl SpectralEwald {
    /// Prepares the operator at tolerance `tolerance` with the cut-off chosen by the cost
    /// model. Inputs must already be validated (finite, positive radii and viscosity).
    pub fn new(
        positions: &[DVec3],
        radii: &[f64],
        viscosity: f64,
        tolerance: f64,
    ) -> Result<Self, HydroError> {
        check_tolerance(tolerance)?;
        let params = Params::choose(tolerance, positions, radii, PRODUCTS_PER_STEP).ok_or(
            HydroError::InvalidInput(
                "configuration too spread out for the spectral Ewald grid and too large for \
                 the direct sum",
            ),
        )?;
        Ok(Self::with_params(params, positions, radii, viscosity))
    }

    /// As [`SpectralEwald::new`] with an explicit real-space cut-off \[m\] (`None`: direct sum).
    #[cfg(test)]
    pub fn with_cutoff(
        positions: &[DVec3],
        radii: &[f64],
        viscosity: f64,
        tolerance: f64,
        cutoff: Option<f64>,
    ) -> Result<Self, HydroError> {
        check_tolerance(tolerance)?;
        let params = Params::with_cutoff(tolerance, cutoff, positions, radii);
        Ok(Self::with_params(params, positions, radii, viscosity))
    }

    /// As [`SpectralEwald::with_cutoff`] with the Gaussian support widened by `extra` points
    /// (the probe of the error against the support).
    #[cfg(test)]
    pub fn with_cutoff_support(
        positions: &[DVec3],
        radii: &[f64],
        viscosity: f64,
        tolerance: f64,
        cutoff: Option<f64>,
        extra: usize,
    ) -> Result<Self, HydroError> {
        check_tolerance(tolerance)?;
        let params = Params::with_cutoff_support(tolerance, cutoff, positions, radii, extra);
        Ok(Self::with_params(params, positions, radii, viscosity))
    }

    fn with_params(params: Params, positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let real = if params.is_direct() {
            Real::Direct(Direct::new(positions, radii, viscosity))
        } else {
            Real::Near(Near::new(&params, positions, radii, viscosity))
        };
        let wave = (!params.is_direct() && !positions.is_empty()).then(|| {
            Wave::new(
                &params,
                positions,
                radii,
                1.0 / (8.0 * std::f64::consts::PI * viscosity),
            )
        });
        Self { params, real, wave }
    }

    /// The wave-space operator (None for the direct sum), for the tests.
    #[cfg(test)]
    pub fn wave(&self) -> Option<&Wave> {
        self.wave.as_ref()
    }

    /// out = μ x for flat 3N vectors.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        match &self.real {
            Real::Near(near) => near.apply(x, out),
            Real::Direct(direct) => direct.apply(x, out),
        }
        if let Some(w) = &self.wave {
            w.apply_add(x, out);
        }
    }

    /// out = μ_real x, the pair part alone (μ − μ_wave; the whole μ for the direct sum).
    #[cfg(test)]
    pub fn apply_real(&self, x: &[f64], out: &mut [f64]) {
        match &self.real {
            Real::Near(near) => near.apply(x, out),
            Real::Direct(direct) => direct.apply(x, out),
        }
    }

    /// Summary of the parameters: (ξ [1/m], r_c \[m\], FFT length per side, support P,
    /// stored pair blocks).
    pub fn summary(&self) -> EwaldSummary {
        EwaldSummary {
            xi: self.params.xi,
            cutoff: self.params.cutoff,
            grid: self.params.fft_n,
            support: self.params.support,
            pair_blocks: match &self.real {
                Real::Near(near) => near.pairs(),
                Real::Direct(direct) => direct.pairs(),
            },
        }
    }
}

/// Parameters a spectral Ewald mobility was prepared with (for benchmarks and reports).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EwaldSummary {
    /// Ewald splitting parameter ξ [1/m] (0: direct sum)
    pub xi: f64,
    /// real-space cut-off \[m\] (infinite for the direct sum)
    pub cutoff: f64,
    /// FFT length per side (0 for the direct sum)
    pub grid: usize,
    /// Gaussian support P (points per side)
    pub support: usize,
    /// real-space pair blocks of the operator (each pair counted twice, once per row, and
    /// stored once; for the direct sum only the overlapping pairs, the others are evaluated
    /// on the fly)
    pub pair_blocks: usize,
}

/// Tolerance in [`params::MIN_TOLERANCE`, `params::MAX_TOLERANCE`].
fn check_tolerance(t: f64) -> Result<(), HydroError> {
    if t.is_finite() && (params::MIN_TOLERANCE..=params::MAX_TOLERANCE).contains(&t) {
        Ok(())
    } else {
        Err(HydroError::InvalidInput(
            "ewald_tolerance must be in [1e-12, 0.1]",
        ))
    }
}
