//! Pair interactions of Brownian particles (thesis 000, §6.2-6.3).
//!
//! * Pseudo-hard spheres, Mie(n, m) shifted and truncated at its minimum (eq. 6.19):
//!   `U(r) = C ε [(σ/r)^n − (σ/r)^m] + ε` for `r < r_min = σ (n/m)^{1/(n−m)}`, else 0, with
//!   `C = n/(n−m) (n/m)^{m/(n−m)}` and the contact distance `σ = a_i + a_j` (2R for equal
//!   spheres; the thesis writes `2R`). For Mie(30, 15): C = 4, `r_min = 2^{1/15} σ = 1.0473 σ`
//!   (2.0946 R), `U(σ) = ε`.
//! * Point dipoles (eq. 6.21): `U = −μ0/(4π) [3 (r·m_i)(r·m_j)/r⁵ − m_i·m_j/r³]`; the force on
//!   `i` with `r = x_i − x_j` (eq. 6.23 written out, D-000-6):
//!   `F_i = 3μ0/(4π r⁵) [(m_i·r) m_j + (m_j·r) m_i + (m_i·m_j) r − 5 (m_i·r)(m_j·r) r / r²]`.
//!   Head to tail it is `−3 μ0 m² / (2π r⁴)` along r̂ (attractive).
//!
//! SI units: lengths [m], moments [A m²], energies [J], forces [N].

use glam::DVec3;

use crate::field::MU0;

/// Mie(n, m) parameters with the derived constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mie {
    /// Well depth ε [J].
    pub epsilon: f64,
    /// Repulsive exponent n.
    pub n: f64,
    /// Attractive exponent m.
    pub m: f64,
    /// Prefactor C = n/(n−m) (n/m)^{m/(n−m)}.
    pub prefactor: f64,
    /// r_min / σ = (n/m)^{1/(n−m)}.
    pub min_ratio: f64,
}

impl Mie {
    /// Mie(n, m) with well depth `epsilon` [J] (requires n > m > 0).
    ///
    /// ```
    /// use magsep_systems::brownian::pair::Mie;
    /// let mie = Mie::new(1.0, 30.0, 15.0);
    /// assert!((mie.prefactor - 4.0).abs() < 1e-14);
    /// assert!((2.0 * mie.min_ratio - 2.0946).abs() < 1e-4); // r_min = 2.0946 R
    /// assert!((mie.energy(2.0) - 1.0).abs() < 1e-12); // U(σ) = ε at σ = 2R, R = 1
    /// ```
    pub fn new(epsilon: f64, n: f64, m: f64) -> Self {
        let ratio = n / m;
        Self {
            epsilon,
            n,
            m,
            prefactor: n / (n - m) * ratio.powf(m / (n - m)),
            min_ratio: ratio.powf(1.0 / (n - m)),
        }
    }

    /// Shifted, truncated energy [J] at distance `r` for contact distance `sigma`.
    pub fn energy_at(&self, r: f64, sigma: f64) -> f64 {
        if r >= self.min_ratio * sigma {
            return 0.0;
        }
        let s = sigma / r;
        self.prefactor * self.epsilon * (s.powf(self.n) - s.powf(self.m)) + self.epsilon
    }

    /// Energy for equal spheres of unit radius (σ = 2): convenience for checks.
    pub fn energy(&self, r: f64) -> f64 {
        self.energy_at(r, 2.0)
    }

    /// Force on `i` [N] for `d = x_i − x_j` and contact distance `sigma` (repulsive, along d).
    #[inline]
    pub fn force(&self, d: DVec3, sigma: f64) -> DVec3 {
        let r2 = d.length_squared();
        let rc = self.min_ratio * sigma;
        if r2 >= rc * rc || r2 == 0.0 {
            return DVec3::ZERO;
        }
        let r = r2.sqrt();
        let s = sigma / r;
        // −dU/dr = C ε [n s^n − m s^m] / r
        let (sn, sm) = if self.n == 30.0 && self.m == 15.0 {
            let s3 = s * s * s;
            let s15 = s3 * s3 * s3 * s3 * s3;
            (s15 * s15, s15)
        } else {
            (s.powf(self.n), s.powf(self.m))
        };
        let mag = self.prefactor * self.epsilon * (self.n * sn - self.m * sm) / r;
        d * (mag / r)
    }

    /// −dU/dr [N] at distance `r` (positive: repulsive).
    pub fn radial_force(&self, r: f64, sigma: f64) -> f64 {
        self.force(DVec3::new(r, 0.0, 0.0), sigma).x
    }

    /// Curvature d²U/dr² [J/m²] at distance `r` (the stiffness of a contact).
    pub fn curvature(&self, r: f64, sigma: f64) -> f64 {
        if r >= self.min_ratio * sigma {
            return 0.0;
        }
        let s = sigma / r;
        self.prefactor
            * self.epsilon
            * (self.n * (self.n + 1.0) * s.powf(self.n) - self.m * (self.m + 1.0) * s.powf(self.m))
            / (r * r)
    }
}

/// Dipole-dipole energy [J] of moments `mi`, `mj` [A m²] at `d = x_i − x_j` [m] (eq. 6.21).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::brownian::pair::dipole_energy;
/// use magsep_systems::field::MU0;
/// // head to tail: U = −μ0 m² / (2π r³)
/// let (m, r) = (2.2e-15, 6.17e-6);
/// let u = dipole_energy(DVec3::X * r, DVec3::X * m, DVec3::X * m);
/// assert!((u + MU0 * m * m / (2.0 * std::f64::consts::PI * r.powi(3))).abs() < 1e-35);
/// ```
pub fn dipole_energy(d: DVec3, mi: DVec3, mj: DVec3) -> f64 {
    let r2 = d.length_squared();
    let r = r2.sqrt();
    -MU0 / (4.0 * std::f64::consts::PI)
        * (3.0 * d.dot(mi) * d.dot(mj) / (r2 * r2 * r) - mi.dot(mj) / (r2 * r))
}

/// Dipole-dipole force on `i` [N] for `d = x_i − x_j` (eq. 6.23).
#[inline]
pub fn dipole_force(d: DVec3, mi: DVec3, mj: DVec3) -> DVec3 {
    let r2 = d.length_squared();
    if r2 == 0.0 {
        return DVec3::ZERO;
    }
    let inv_r2 = 1.0 / r2;
    let inv_r5 = inv_r2 * inv_r2 * inv_r2.sqrt();
    let (a, b) = (mi.dot(d), mj.dot(d));
    let k = 3.0 * MU0 / (4.0 * std::f64::consts::PI) * inv_r5;
    (mj * a + mi * b + d * (mi.dot(mj) - 5.0 * a * b * inv_r2)) * k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn central_diff(f: impl Fn(DVec3) -> f64, x: DVec3, h: f64) -> DVec3 {
        let e = [DVec3::X, DVec3::Y, DVec3::Z];
        let g: Vec<f64> = e
            .iter()
            .map(|&u| (f(x + u * h) - f(x - u * h)) / (2.0 * h))
            .collect();
        DVec3::new(g[0], g[1], g[2])
    }

    #[test]
    fn mie_minimum_value_and_force_are_consistent() {
        let mie = Mie::new(100.0, 30.0, 15.0);
        // minimum of the unshifted potential at r = 2.0946 R (R = 1): force changes sign there
        let rmin = 2.0 * 2f64.powf(1.0 / 15.0);
        assert!((rmin - 2.0946).abs() < 5e-5);
        assert!(mie.radial_force(rmin * (1.0 - 1e-9), 2.0) > 0.0);
        assert!(mie.radial_force(rmin * (1.0 - 1e-9), 2.0) < 1e-4);
        assert_eq!(mie.radial_force(rmin * (1.0 + 1e-9), 2.0), 0.0);
        // U(2R) = ε, continuous to 0 at r_min
        assert!((mie.energy(2.0) - 100.0).abs() < 1e-10);
        assert!(mie.energy(rmin * (1.0 - 1e-9)).abs() < 1e-10);
        // force at contact: 3000 kT/R for ε = 100 kT (D-000-7)
        assert!((mie.radial_force(2.0, 2.0) - 3000.0).abs() < 1e-9);
        // force = −∇U
        for r in [2.0, 2.03, 2.08] {
            let x = DVec3::new(r * 0.6, r * 0.8, 0.0);
            let g = central_diff(|p| mie.energy_at(p.length(), 2.0), x, 1e-6);
            let f = mie.force(x, 2.0);
            assert!((f + g).length() < 1e-5 * f.length(), "{r}: {f} {g}");
        }
        // curvature against the force's derivative
        let r = 2.05;
        let c = -(mie.radial_force(r + 1e-6, 2.0) - mie.radial_force(r - 1e-6, 2.0)) / 2e-6;
        assert!((mie.curvature(r, 2.0) - c).abs() < 1e-6 * c.abs());
        // U = kT at r ≈ 2.081 R (D-000-7)
        let mut lo = 2.0;
        let mut hi = rmin;
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if mie.energy(mid) > 1.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        assert!((lo - 2.081).abs() < 1e-3, "{lo}");
    }

    #[test]
    fn general_exponents_match_lennard_jones() {
        // Mie(12, 6) is Lennard-Jones: C = 4, r_min = 2^{1/6} σ
        let lj = Mie::new(1.0, 12.0, 6.0);
        assert!((lj.prefactor - 4.0).abs() < 1e-14);
        assert!((lj.min_ratio - 2f64.powf(1.0 / 6.0)).abs() < 1e-15);
        let r: f64 = 1.05;
        let u = 4.0 * ((1.0 / r).powi(12) - (1.0 / r).powi(6)) + 1.0;
        assert!((lj.energy_at(r, 1.0) - u).abs() < 1e-13);
    }

    #[test]
    fn dipole_force_is_minus_gradient_and_antisymmetric() {
        let mi = DVec3::new(0.3, -0.2, 0.9) * 1e-16;
        let mj = DVec3::new(-0.5, 0.4, 0.7) * 1e-16;
        let d = DVec3::new(1.1e-7, -0.7e-7, 2.3e-7);
        let g = central_diff(|p| dipole_energy(p, mi, mj), d, 1e-12);
        let f = dipole_force(d, mi, mj);
        assert!((f + g).length() < 1e-6 * f.length(), "{f} {g}");
        // Newton's third law
        let fj = dipole_force(-d, mj, mi);
        assert!((f + fj).length() < 1e-15 * f.length());
    }

    #[test]
    fn head_to_tail_and_side_by_side() {
        let (m, r) = (1e-16, 3e-7);
        let f = dipole_force(DVec3::Z * r, DVec3::Z * m, DVec3::Z * m);
        let expect = -3.0 * MU0 * m * m / (2.0 * std::f64::consts::PI * r.powi(4));
        assert!((f.z - expect).abs() < 1e-14 * expect.abs() && f.x == 0.0);
        // side by side: repulsive, half the magnitude
        let f = dipole_force(DVec3::X * r, DVec3::Z * m, DVec3::Z * m);
        assert!((f.x + 0.5 * expect).abs() < 1e-14 * expect.abs());
        // energies: −2 and +1 in units of μ0 m²/(4π r³)
        let u0 = MU0 * m * m / (4.0 * std::f64::consts::PI * r.powi(3));
        assert!(
            (dipole_energy(DVec3::Z * r, DVec3::Z * m, DVec3::Z * m) + 2.0 * u0).abs() < 1e-12 * u0
        );
        assert!((dipole_energy(DVec3::X * r, DVec3::Z * m, DVec3::Z * m) - u0).abs() < 1e-12 * u0);
    }
}
