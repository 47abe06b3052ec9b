//! The self-induced velocity of a two-way coupled point particle, and its correction.
//!
//! A point particle that feeds its force back through a filter of the size of the particle
//! disturbs the liquid it then samples: the filter average of the liquid velocity contains
//! the particle's own (regularised) Stokeslet, so the slip, and with it the drag, is
//! underestimated. The thesis applies no correction. magsep offers the quasi-steady
//! correction in the spirit of Balachandar, Liu & Lakhote (2019) and Horwitz & Mani (2016):
//! estimate the self-induced velocity from the particle's own feedback force through the
//! steady Stokes response of the *same* filter, and subtract it from the sampled velocity:
//!
//! `u_undisturbed = ū − u_self`, `u_self = M · F_fluid` with `F_fluid = −F_2w`
//!
//! (the force on the liquid), where `M` [m/(N s)] is the filter average of the velocity that
//! the filter-spread unit force induces in unbounded Stokes flow (Oseen tensor `G`):
//!
//! `M = 1/(8πμ V²) ∫_box ∫_box (I/r + r r/r³) dV dV' = 1/(8πμ V²) ∫ (I/r + r r/r³) A(r) d³r`
//!
//! with `V = 8 h_x h_y h_z` and the box overlap `A(r) = Π_k max(0, 2h_k − |r_k|)`. M is
//! diagonal. The integral is evaluated by splitting the octant `[0, 2h]³` into the three
//! pyramids over its far faces: along a ray the integrand is a polynomial times a
//! homogeneous function, so 3-point Gauss in the ray and an n×n Gauss rule on each face give
//! spectral accuracy. Limits: the correction neglects the walls, the periodic images and
//! unsteadiness (the disturbance is assumed developed), which is why it is quasi-steady; it is
//! accurate when the grid resolves the filter box (a few nodes across).

use glam::DVec3;
use std::f64::consts::PI;

use crate::field::demag::gauss_legendre_01;

/// Face rule points per direction (the face integrands are smooth: 24 points give ~1e-12).
const FACE_POINTS: usize = 24;

/// `Σ_faces ∫_face w(s, axis) (I + s s/r²)/r dA` over the three far faces of the octant box
/// `[0, e]³` (face `axis` at `s_axis = e_axis`), by an n × n Gauss rule: the diagonal of the
/// pyramid integrals of the Oseen tensor's homogeneous kernel, weighted by `w`.
fn face_sum(e: DVec3, w: impl Fn(DVec3, usize) -> f64) -> DVec3 {
    let face = gauss_legendre_01(FACE_POINTS);
    let mut sum = DVec3::ZERO;
    for axis in 0..3 {
        let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
        for &(u, wu) in &face {
            for &(v, wv) in &face {
                let mut s = DVec3::ZERO;
                s[axis] = e[axis];
                s[p] = u * e[p];
                s[q] = v * e[q];
                let r = s.length();
                let g = (DVec3::ONE + s * s / (r * r)) / r;
                sum += g * (w(s, axis) * wu * wv * e[p] * e[q]);
            }
        }
    }
    sum
}

/// Diagonal of the self-mobility `M` [m/(N s)] of a top-hat box of half-widths `half` \[m\] in a
/// liquid of dynamic viscosity `viscosity` [Pa s] (see the module docs). Zero for a
/// degenerate box or a non-positive viscosity.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::channel::self_induced::self_mobility;
/// // a cube: isotropic
/// let m = self_mobility(DVec3::splat(1e-3), 1e-3);
/// assert!((m.x - m.z).abs() < 1e-12 * m.x && m.x > 0.0);
/// ```
pub fn self_mobility(half: DVec3, viscosity: f64) -> DVec3 {
    if !(half.min_element() > 0.0 && half.is_finite() && viscosity > 0.0) {
        return DVec3::ZERO;
    }
    let l = 2.0 * half;
    let ray = gauss_legendre_01(3);
    // ∫_0^1 t A(t s) dt along the ray (a quartic in t: 3-point Gauss is exact), times the
    // pyramid's height l_axis
    let sum = face_sum(l, |s, axis| {
        let radial: f64 = ray
            .iter()
            .map(|&(t, wt)| {
                let a = (l - t * s).max(DVec3::ZERO);
                wt * t * a.x * a.y * a.z
            })
            .sum();
        radial * l[axis]
    });
    let volume = l.x * l.y * l.z;
    sum * 8.0 / (8.0 * PI * viscosity * volume * volume)
}

/// The steady Stokes velocity [m/s] at the centre of a box of half-widths `half` over which
/// `force` \[N\] is spread uniformly (Oseen tensor integrated over the box; the classical value
/// for a cube of side σ is `∫ 1/r dV = 2.38008 σ²`). Used to check [`self_mobility`]'s
/// quadrature and for the point value of the regularised Stokeslet.
pub fn centre_velocity(half: DVec3, viscosity: f64, force: DVec3) -> DVec3 {
    if !(half.min_element() > 0.0 && half.is_finite() && viscosity > 0.0) {
        return DVec3::ZERO;
    }
    // pyramid over each face, homogeneous degree −1: ∫ = (h/2) ∫_face g dA
    let sum = face_sum(half, |_, axis| 0.5 * half[axis]);
    let volume = 8.0 * half.x * half.y * half.z;
    // 8 octants; u = F/(8πμV) ∫ (I/r + rr/r³)
    force * sum * 8.0 / (8.0 * PI * viscosity * volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_potential_matches_the_classical_constant() {
        // ∫_cube 1/r dV = 2.380077... σ² (unit cube centred at the origin); with the r r/r³
        // term the cube's centre velocity is (4/3) ∫ 1/r / (8πμ V) F
        let sigma = 2.0;
        let u = centre_velocity(DVec3::splat(0.5 * sigma), 1.0, DVec3::X);
        let expected = 4.0 / 3.0 * 2.380_077_380_7 * sigma * sigma / (8.0 * PI * sigma.powi(3));
        assert!(
            (u.x - expected).abs() < 1e-7 * expected,
            "{} {}",
            u.x,
            expected
        );
    }

    #[test]
    fn mobility_scales_inversely_with_size_and_viscosity_and_is_below_the_centre_value() {
        let h = DVec3::new(1e-3, 2e-3, 1.5e-3);
        let m = self_mobility(h, 2e-3);
        let m2 = self_mobility(2.0 * h, 4e-3);
        assert!(((m / m2) - DVec3::splat(4.0)).abs().max_element() < 1e-10);
        // averaging over the box lowers the (centre-peaked) velocity
        let c = centre_velocity(h, 2e-3, DVec3::ONE);
        assert!(m.x < c.x && m.y < c.y && m.z < c.z);
        // elongated boxes are more mobile along their long axis
        assert!(m.y > m.x);
        assert_eq!(self_mobility(DVec3::ZERO, 1.0), DVec3::ZERO);
    }

    #[test]
    fn mobility_converges_spectrally_against_a_brute_force_double_integral() {
        // Monte-Carlo-free check: midpoint double sum over two boxes with the singular pairs
        // regularised is slow; instead compare with the Fourier form for a cube,
        // M = (2/3) 1/(μ (2π)³) ∫ ŝ(k)² / k² d³k, ŝ the box's Fourier transform, by a radial
        // quadrature of the angular average computed on a fine spherical grid.
        let h = 0.5;
        let m = self_mobility(DVec3::splat(h), 1.0).x;
        let sinc = |x: f64| if x.abs() < 1e-12 { 1.0 } else { x.sin() / x };
        let gl = gauss_legendre_01(24);
        let ga = gauss_legendre_01(40);
        let mut total = 0.0;
        // k from 0 to 400 in panels of 2; the integrand decays like k^-6 on average
        let panels: Vec<(f64, f64)> = (0..200)
            .map(|p| (2.0 * p as f64, 2.0 * p as f64 + 2.0))
            .collect();
        for (a, b) in panels {
            for &(t, wt) in &gl {
                let k = a + (b - a) * t;
                // angular average of Π sinc²(k_i h) over the sphere (Gauss in cosθ and φ)
                let mut ang = 0.0;
                for &(ct, wc) in &ga {
                    let c = 2.0 * ct - 1.0;
                    let st = (1.0 - c * c).sqrt();
                    for &(ph, wp) in &ga {
                        let phi = 2.0 * PI * ph;
                        let kx = k * st * phi.cos();
                        let ky = k * st * phi.sin();
                        let kz = k * c;
                        let s = sinc(kx * h) * sinc(ky * h) * sinc(kz * h);
                        ang += wc * wp * s * s;
                    }
                }
                // ∫ d³k f/k² = 4π ∫ dk <f>
                total += wt * (b - a) * 4.0 * PI * ang;
            }
        }
        let fourier = 2.0 / 3.0 * total / (2.0 * PI).powi(3);
        assert!((m - fourier).abs() < 2e-3 * fourier, "{m} vs {fourier}");
    }
}
