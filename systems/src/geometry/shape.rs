//! Volume, principal moments of inertia and bounding radius of particle shapes.
//!
//! Spherocylinder of radius R and cylinder length L (thesis 000, eqs. 2.2-2.3):
//!
//! V = pi R^2 (4/3 R + L),
//! I_x = I_y = m (5 L^3 + 20 L^2 R + 45 L R^2 + 32 R^3) / (20 (3 L + 4 R)),
//! I_z = m (15 L R^2 + 16 R^3) / (10 (3 L + 4 R)),
//!
//! both reducing to (2/5) m R^2 for L = 0. Exact (no approximation).
//!
//! Superquadric |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 (thesis 000, eqs. 4.21, 4.29-4.31,
//! 4.38-4.39; kernels in [`super::superquadric`]):
//!
//! V = 8 a1 a2 a3 G(1+1/g1) G(1+1/g2) G(1+1/g3) / G(1 + 1/g1 + 1/g2 + 1/g3),
//! I_xx = (8/3) a1 a2 a3 (a2^2 T(1,3,1) + a3^2 T(1,1,3)) and cyclic, with
//! T(p,q,r) = G(1+p/g1) G(1+q/g2) G(1+r/g3) / G(1 + p/g1 + q/g2 + r/g3),
//!
//! the thesis's Gamma(eps/2) form rewritten with eps G(eps/2) = 2 G(1 + 1/g) (exact). The
//! bounding radius is the maximum of |x| on the surface (erratum E-000-7): closed form 4.38/4.39
//! for equal exponents (max a_i at g = 2, where 4.38 is singular), a numerical upper bound
//! tight to round-off for unequal exponents.

use glam::DVec3;
use magsep_components::shape::Shape;
use std::f64::consts::PI;

use super::superquadric::{
    superquadric_bounding_radius, superquadric_inertia, superquadric_volume,
};

/// Volume [m^3].
///
/// ```
/// use magsep_components::shape::Shape;
/// use magsep_systems::geometry::volume;
/// let v = volume(&Shape::Sphere { radius: 1.0 });
/// assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 1e-15);
/// ```
pub fn volume(shape: &Shape) -> f64 {
    if let Shape::Spheroid {
        equatorial_radius: a,
        polar_radius: c,
    } = *shape
    {
        return 4.0 / 3.0 * PI * a * a * c;
    }
    if let Shape::Superquadric {
        semi_axes,
        exponents,
    } = *shape
    {
        return superquadric_volume(semi_axes, exponents);
    }
    let r = shape.radius();
    let l = 2.0 * shape.half_length();
    PI * r * r * (4.0 / 3.0 * r + l)
}

/// Principal moments of inertia (I_x, I_y, I_z) in the body frame at unit density
/// (mass = volume) [m^5].
///
/// ```
/// use magsep_components::shape::Shape;
/// use magsep_systems::geometry::{inertia_body_unit_density, volume};
/// let s = Shape::Sphere { radius: 0.5 };
/// let i = inertia_body_unit_density(&s);
/// assert!((i.x - 0.4 * volume(&s) * 0.25).abs() < 1e-15);
/// ```
pub fn inertia_body_unit_density(shape: &Shape) -> DVec3 {
    if let Shape::Spheroid {
        equatorial_radius: a,
        polar_radius: c,
    } = *shape
    {
        // the solid ellipsoid: I_x = I_y = m (a² + c²)/5, I_z = 2 m a²/5
        let m = volume(shape);
        let ix = m * (a * a + c * c) / 5.0;
        return DVec3::new(ix, ix, 0.4 * m * a * a);
    }
    if let Shape::Superquadric {
        semi_axes,
        exponents,
    } = *shape
    {
        return superquadric_inertia(semi_axes, exponents);
    }
    let m = volume(shape);
    let r = shape.radius();
    let l = 2.0 * shape.half_length();
    let den = 3.0 * l + 4.0 * r;
    let ixy =
        m / 20.0 * (5.0 * l.powi(3) + 20.0 * l * l * r + 45.0 * l * r * r + 32.0 * r.powi(3)) / den;
    let iz = m / 10.0 * (15.0 * l * r * r + 16.0 * r.powi(3)) / den;
    DVec3::new(ixy, ixy, iz)
}

/// Radius of the smallest sphere about the centre that contains the shape \[m\] (for a
/// superquadric with unequal exponents an upper bound tight to round-off).
///
/// ```
/// use glam::DVec3;
/// use magsep_components::shape::Shape;
/// use magsep_systems::geometry::bounding_radius;
/// let cube_ish = Shape::Superquadric { semi_axes: DVec3::ONE, exponents: DVec3::splat(4.0) };
/// assert!((bounding_radius(&cube_ish) - 3f64.powf(0.25)).abs() < 1e-14);
/// let rod = Shape::Spherocylinder { radius: 0.5, half_length: 1.0 };
/// assert_eq!(bounding_radius(&rod), 1.5);
/// ```
pub fn bounding_radius(shape: &Shape) -> f64 {
    match *shape {
        Shape::Superquadric {
            semi_axes,
            exponents,
        } => superquadric_bounding_radius(semi_axes, exponents),
        Shape::Spheroid {
            equatorial_radius,
            polar_radius,
        } => equatorial_radius.max(polar_radius),
        _ => shape.radius() + shape.half_length(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent check: integrate the inertia of a spherocylinder by slicing along the axis
    /// (disc slices, each with its own transverse inertia and parallel-axis shift).
    fn inertia_by_quadrature(r: f64, l: f64) -> (f64, f64, f64) {
        let h = l / 2.0;
        let n = 200_000;
        let (z0, z1) = (-h - r, h + r);
        let dz = (z1 - z0) / n as f64;
        let (mut v, mut ix, mut iz) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let z = z0 + (k as f64 + 0.5) * dz;
            let a = if z.abs() <= h {
                r
            } else {
                (r * r - (z.abs() - h).powi(2)).max(0.0).sqrt()
            };
            let dm = PI * a * a * dz;
            v += dm;
            iz += 0.5 * dm * a * a;
            ix += dm * (0.25 * a * a + z * z);
        }
        (v, ix, iz)
    }

    #[test]
    fn spherocylinder_volume_and_inertia_match_slicing_quadrature() {
        for &(r, l) in &[(0.5, 0.0), (0.5, 1.0), (0.5, 4.0), (0.3, 17.0), (2.0, 0.25)] {
            let s = Shape::Spherocylinder {
                radius: r,
                half_length: l / 2.0,
            };
            let (v, ix, iz) = inertia_by_quadrature(r, l);
            let i = inertia_body_unit_density(&s);
            assert!((volume(&s) - v).abs() / v < 1e-8, "V {r} {l}");
            assert!((i.x - ix).abs() / ix < 1e-8, "Ix {r} {l}: {} vs {ix}", i.x);
            assert!((i.z - iz).abs() / iz < 1e-8, "Iz {r} {l}: {} vs {iz}", i.z);
        }
    }

    #[test]
    fn thesis_table_values() {
        // D-000-13: Lambda = 5 (L = 4, R = 1/2): V = 3.6652, I_x/m = 1.8893, I_z/m = 0.1214
        let s = Shape::Spherocylinder {
            radius: 0.5,
            half_length: 2.0,
        };
        let m = volume(&s);
        let i = inertia_body_unit_density(&s);
        assert!((m - 3.6652).abs() < 5e-5);
        assert!((i.x / m - 1.8893).abs() < 5e-5);
        assert!((i.z / m - 0.1214).abs() < 5e-5);
        // sphere limit (2/5) m R^2, to 1e-12 relative
        let s = Shape::Spherocylinder {
            radius: 0.7,
            half_length: 0.0,
        };
        let i = inertia_body_unit_density(&s);
        let want = 0.4 * volume(&s) * 0.49;
        assert!((i.x - want).abs() / want < 1e-12 && (i.z - want).abs() / want < 1e-12);
    }

    fn sq(a: DVec3, g: DVec3) -> Shape {
        Shape::Superquadric {
            semi_axes: a,
            exponents: g,
        }
    }

    /// Superball reference table D-000-14 (a = 1): g, V, I_xx, I/V, r_bound.
    const SUPERBALL_TABLE: [(f64, f64, f64, f64, f64); 7] = [
        (2.0, 4.18879, 1.67552, 0.4000, 1.00000),
        (2.5, 5.07159, 2.31301, 0.4561, 1.11612),
        (3.0, 5.69658, 2.82662, 0.4962, 1.20094),
        (3.5, 6.14801, 3.23283, 0.5258, 1.26544),
        (4.0, 6.48199, 3.55431, 0.5483, 1.31607),
        (4.5, 6.73485, 3.81073, 0.5658, 1.35686),
        (5.0, 6.93035, 4.01741, 0.5797, 1.39039),
    ];

    /// Eqs. 4.21 and 4.29 in the thesis's own Gamma(eps/2) form, evaluated independently
    /// (Python's `math.gamma`, i.e. the C library's tgamma) to 16 digits: g, V, I_xx (a = 1).
    const SUPERBALL_REFERENCE: [(f64, f64, f64); 7] = [
        (2.0, 4.188790204786389, 1.675516081914556),
        (2.5, 5.07159484066611, 2.313012740520932),
        (3.0, 5.696583541509836, 2.826622000456719),
        (3.5, 6.148010502237433, 3.23283411481446),
        (4.0, 6.481987351786383, 3.554306350526694),
        (4.5, 6.734850174019244, 3.810727012931538),
        (5.0, 6.930354992554312, 4.017406269760096),
    ];

    #[test]
    fn superball_volume_and_inertia_match_independent_gamma_to_1e12() {
        for &(g, v, ixx) in &SUPERBALL_REFERENCE {
            let s = sq(DVec3::ONE, DVec3::splat(g));
            assert!(
                (volume(&s) - v).abs() <= 1e-12 * v,
                "V g={g}: {}",
                volume(&s)
            );
            let i = inertia_body_unit_density(&s).x;
            assert!((i - ixx).abs() <= 1e-12 * ixx, "Ixx g={g}: {i}");
        }
        // general superquadric a = (1, 0.7, 1.5), g = (3, 5, 2.5), same independent evaluation
        let s = sq(DVec3::new(1.0, 0.7, 1.5), DVec3::new(3.0, 5.0, 2.5));
        let want_v = 6.276328166991277;
        let want_i = DVec3::new(4.402731288808238, 5.1825099806665715, 2.411327834180294);
        assert!((volume(&s) - want_v).abs() <= 1e-12 * want_v);
        let i = inertia_body_unit_density(&s);
        assert!(
            ((i - want_i) / want_i).abs().max_element() <= 1e-12,
            "{i} vs {want_i}"
        );
    }

    #[test]
    fn superball_table_and_exact_limits() {
        for &(g, v, ixx, ratio, r) in &SUPERBALL_TABLE {
            let s = sq(DVec3::ONE, DVec3::splat(g));
            let (vv, ii, rr) = (
                volume(&s),
                inertia_body_unit_density(&s),
                bounding_radius(&s),
            );
            // the table has 5 decimals (4 for I/V): compare at half a unit of the last digit
            assert!((vv - v).abs() <= 5e-6, "V g={g}: {vv} vs {v}");
            assert!((ii.x - ixx).abs() <= 5e-6, "Ixx g={g}: {} vs {ixx}", ii.x);
            assert!((ii.x / vv - ratio).abs() <= 5e-5, "I/V g={g}");
            assert!((rr - r).abs() <= 5e-6, "r g={g}: {rr} vs {r}");
            // superball: isotropic inertia; r from eq. 4.39 exactly
            assert!((ii.y - ii.x).abs() <= 1e-14 * ii.x && (ii.z - ii.x).abs() <= 1e-14 * ii.x);
            assert!((rr - 3f64.powf(0.5 * (1.0 - 2.0 / g))).abs() <= 1e-14);
        }
        // sphere: 4 pi/3 and 8 pi/15, to round-off
        let s = sq(DVec3::ONE, DVec3::splat(2.0));
        assert!((volume(&s) - 4.0 * PI / 3.0).abs() <= 4e-15);
        assert!((inertia_body_unit_density(&s).x - 8.0 * PI / 15.0).abs() <= 4e-15);
        // ellipsoid: V = 4/3 pi abc, I_x = V (b^2 + c^2)/5, r = max a_i
        let a = DVec3::new(0.5, 1.25, 2.0);
        let s = sq(a, DVec3::splat(2.0));
        let v = 4.0 / 3.0 * PI * a.x * a.y * a.z;
        let i = inertia_body_unit_density(&s);
        assert!((volume(&s) - v).abs() <= 1e-14 * v);
        assert!((i.x - v * (a.y * a.y + a.z * a.z) / 5.0).abs() <= 1e-14 * i.x);
        assert!((i.z - v * (a.x * a.x + a.y * a.y) / 5.0).abs() <= 1e-14 * i.z);
        assert_eq!(bounding_radius(&s), 2.0);
        // cube limit (g = infinity): 8 a^3, 16 a^5/3, r = sqrt(3) a; and g = 1e9 next to it
        let s = sq(DVec3::ONE, DVec3::splat(f64::INFINITY));
        assert!((volume(&s) - 8.0).abs() <= 1e-13);
        assert!((inertia_body_unit_density(&s).x - 16.0 / 3.0).abs() <= 1e-13);
        assert!((bounding_radius(&s) - 3f64.sqrt()).abs() <= 1e-15);
        let s = sq(DVec3::ONE, DVec3::splat(1e9));
        assert!((volume(&s) - 8.0).abs() <= 1e-7);
        // box a x b x c limit: I_x = V (b^2 + c^2)/3
        let s = sq(a, DVec3::splat(f64::INFINITY));
        let v = 8.0 * a.x * a.y * a.z;
        assert!((volume(&s) - v).abs() <= 1e-13 * v);
        let ix = inertia_body_unit_density(&s).x;
        assert!((ix - v * (a.y * a.y + a.z * a.z) / 3.0).abs() <= 1e-13 * ix);
    }

    /// Halton radical inverse in `base`.
    fn halton(mut i: u64, base: u64) -> f64 {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    }

    #[test]
    fn general_superquadric_matches_quasi_monte_carlo() {
        let a = DVec3::new(1.0, 0.7, 1.5);
        let g = DVec3::new(3.0, 5.0, 2.5);
        let s = sq(a, g);
        let n = 1u64 << 20;
        let (mut v, mut ix, mut iy, mut iz, mut rmax) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
        let cell = 8.0 * a.x * a.y * a.z / n as f64;
        for i in 1..=n {
            let p = DVec3::new(
                (2.0 * halton(i, 2) - 1.0) * a.x,
                (2.0 * halton(i, 3) - 1.0) * a.y,
                (2.0 * halton(i, 5) - 1.0) * a.z,
            );
            let f = (p / a).abs().powf_vec(g);
            if f.x + f.y + f.z <= 1.0 {
                v += cell;
                ix += cell * (p.y * p.y + p.z * p.z);
                iy += cell * (p.x * p.x + p.z * p.z);
                iz += cell * (p.x * p.x + p.y * p.y);
                rmax = rmax.max(p.length());
            }
        }
        let vv = volume(&s);
        let ii = inertia_body_unit_density(&s);
        let rel = |x: f64, y: f64| (x - y).abs() / y;
        eprintln!(
            "QMC vs closed form: V {:.2e}, Ixx {:.2e}, Iyy {:.2e}, Izz {:.2e}",
            rel(vv, v),
            rel(ii.x, ix),
            rel(ii.y, iy),
            rel(ii.z, iz)
        );
        assert!(rel(vv, v) < 2e-3 && rel(ii.x, ix) < 2e-3);
        assert!(rel(ii.y, iy) < 2e-3 && rel(ii.z, iz) < 2e-3);
        assert!(rmax <= bounding_radius(&s));
    }

    trait PowfVec {
        fn powf_vec(self, e: DVec3) -> DVec3;
    }
    impl PowfVec for DVec3 {
        fn powf_vec(self, e: DVec3) -> DVec3 {
            DVec3::new(self.x.powf(e.x), self.y.powf(e.y), self.z.powf(e.z))
        }
    }
}
