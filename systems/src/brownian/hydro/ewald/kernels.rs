//! Closed forms of the Ewald-split Stokeslet S(r) = I/r + r r/r³ and of its Laplacian
//! L(r) = ∇²S = 2(I − 3r̂r̂)/r³ (unit prefactor: multiply by 1/(8πη)).
//!
//! Every kernel is returned as a pair (A, B) with K = A I + B r̂r̂. With E = erf(αr),
//! C = erfc(αr), g = e^{−α²r²}, G_α(r) = α³ e^{−α²r²}/π^{3/2} (Fourier transform e^{−k²/4α²}):
//!
//! * Gaussian-smoothed Stokeslet S∗G_α: A = E/r + E/(2α²r³) − g/(α√π r²),
//!   B = E/r − 3E/(2α²r³) + 3g/(α√π r²) (from S = (I∇² − ∇∇) r and the radial mean of r over
//!   a Gaussian, ψ = (r + 1/(2α²r)) E + g/(α√π)).
//! * Smoothed Laplacian L∗G_α = −2∇∇(E/r) − 8πG_α I: A = −2E′/r² + 2E/r³ − 8πG_α,
//!   B = 4α²E′ + 6E′/r² − 6E/r³, E′ = 2αg/√π.
//! * Hasimoto real-space remainder of the Stokeslet, S − (1 − ∇²/4ξ²)(S∗G_ξ):
//!   A = C/r − 2ξg/√π, B = C/r + 2ξg/√π (Hasimoto 1959).
//! * Real-space remainder of the Laplacian, L − L∗G_ξ = −2∇∇(C/r) + 8πG_ξ I:
//!   A = 2C/r³ + 4ξg/(√π r²) + 8ξ³g/√π, B = −6C/r³ − 12ξg/(√π r²) − 8ξ³g/√π.
//!
//! Near r = 0 the smoothed kernels cancel catastrophically, so for αr < [`SERIES_BELOW`] their
//! Taylor series to O(r⁴) are used (truncation O((αr)⁶) < 1e-10 relative):
//! S∗G_α: A = (280α − 112α³r² + 36α⁵r⁴)/(105√π), B = (56α³r² − 24α⁵r⁴)/(105√π);
//! L∗G_α: A = (−560α³ + 672α⁵r² − 360α⁷r⁴)/(105√π), B = (−112α⁵r² + 80α⁷r⁴)/(35√π).
//! All formulas were derived symbolically and are checked in the tests against each other
//! (remainder + smoothed = exact) and against the series.

use std::f64::consts::PI;

/// Below this αr the smoothed kernels use their Taylor series.
pub(crate) const SERIES_BELOW: f64 = 0.02;

const SQRT_PI: f64 = 1.772_453_850_905_516;

/// erfc(x) (statrs, Boost-derived rational approximations, ~1e-16 relative).
#[inline]
fn erfc(x: f64) -> f64 {
    statrs::function::erf::erfc(x)
}

#[inline]
fn erf(x: f64) -> f64 {
    statrs::function::erf::erf(x)
}

/// (A, B) of the Gaussian-smoothed Stokeslet S∗G_α at distance `r` ≥ 0.
pub(crate) fn smoothed_stokeslet(r: f64, alpha: f64) -> (f64, f64) {
    let x = alpha * r;
    if x < SERIES_BELOW {
        let (a2, r2) = (alpha * alpha, r * r);
        let c = alpha / (105.0 * SQRT_PI);
        let a = c * (280.0 - 112.0 * a2 * r2 + 36.0 * a2 * a2 * r2 * r2);
        let b = c * (56.0 * a2 * r2 - 24.0 * a2 * a2 * r2 * r2);
        return (a, b);
    }
    let e = erf(x);
    let g = (-x * x).exp();
    let r2 = r * r;
    let t1 = e / r;
    let t3 = e / (2.0 * alpha * alpha * r2 * r);
    let tg = g / (alpha * SQRT_PI * r2);
    (t1 + t3 - tg, t1 - 3.0 * t3 + 3.0 * tg)
}

/// (A, B) of the Gaussian-smoothed Laplacian L∗G_α at distance `r` ≥ 0.
pub(crate) fn smoothed_laplacian(r: f64, alpha: f64) -> (f64, f64) {
    let x = alpha * r;
    let a2 = alpha * alpha;
    if x < SERIES_BELOW {
        let r2 = r * r;
        let c = alpha * a2 / SQRT_PI;
        let a = c * (-560.0 + 672.0 * a2 * r2 - 360.0 * a2 * a2 * r2 * r2) / 105.0;
        let b = c * (-112.0 * a2 * r2 + 80.0 * a2 * a2 * r2 * r2) / 35.0;
        return (a, b);
    }
    let e = erf(x);
    let g = (-x * x).exp();
    let ep = 2.0 * alpha * g / SQRT_PI;
    let r2 = r * r;
    let r3 = r2 * r;
    let gauss = alpha * a2 * g / (PI * SQRT_PI);
    (
        -2.0 * ep / r2 + 2.0 * e / r3 - 8.0 * PI * gauss,
        4.0 * a2 * ep + 6.0 * ep / r2 - 6.0 * e / r3,
    )
}

/// (A, B) of the Hasimoto real-space remainder of the Stokeslet at `r` > 0 (ξ = 0: S itself).
#[cfg(test)]
pub(crate) fn real_stokeslet(r: f64, xi: f64) -> (f64, f64) {
    let x = xi * r;
    let c = erfc(x) / r;
    let g = 2.0 * xi * (-x * x).exp() / SQRT_PI;
    (c - g, c + g)
}

/// (A, B) of the real-space remainder of the Laplacian at `r` > 0 (ξ = 0: L itself).
#[cfg(test)]
pub(crate) fn real_laplacian(r: f64, xi: f64) -> (f64, f64) {
    let x = xi * r;
    let r2 = r * r;
    let c3 = erfc(x) / (r2 * r);
    let g = (-x * x).exp() * xi / SQRT_PI;
    let t2 = g / r2;
    let t0 = g * xi * xi;
    (
        2.0 * c3 + 4.0 * t2 + 8.0 * t0,
        -6.0 * c3 - 12.0 * t2 - 8.0 * t0,
    )
}

/// (A, B) of the full wave-space Stokeslet kernel (1 − ∇²/4ξ²)(S∗G_ξ) used by the
/// Hasimoto split with spreading/gathering, with the Gaussian of the middle factor `alpha`
/// and the polynomial factor of `xi`: S∗G_α − L∗G_α/(4ξ²).
pub(crate) fn wave_stokeslet(r: f64, alpha: f64, xi: f64) -> (f64, f64) {
    let (sa, sb) = smoothed_stokeslet(r, alpha);
    let (la, lb) = smoothed_laplacian(r, alpha);
    let q = 1.0 / (4.0 * xi * xi);
    (sa - q * la, sb - q * lb)
}

/// (A, B) of the real-space RPY remainder S_R + (s/6) L_R at `r` > 0, s = a_i² + a_j²
/// (one erfc and one exponential for both kernels).
pub(crate) fn real_rpy(r: f64, xi: f64, s: f64) -> (f64, f64) {
    let x = xi * r;
    let c1 = erfc(x) / r;
    let ex = (-x * x).exp();
    let g = 2.0 * xi * ex / SQRT_PI;
    let r2 = r * r;
    let c3 = c1 / r2;
    let gl = ex * xi / SQRT_PI;
    let t2 = gl / r2;
    let t0 = gl * xi * xi;
    let q = s / 6.0;
    (
        c1 - g + q * (2.0 * c3 + 4.0 * t2 + 8.0 * t0),
        c1 + g - q * (6.0 * c3 + 12.0 * t2 + 8.0 * t0),
    )
}

/// Far-field (non-overlapping) RPY pair tensor in units of 1/(8πη):
/// S + (a_i² + a_j²)/6 · L = (1 + s/(3r²))/r I + (1 − s/r²)/r r̂r̂, s = a_i² + a_j².
pub(crate) fn far_rpy(r: f64, s: f64) -> (f64, f64) {
    let q = s / (r * r);
    ((1.0 + q / 3.0) / r, (1.0 - q) / r)
}
