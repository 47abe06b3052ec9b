//! Volume, principal moments of inertia and bounding radius of particle shapes.
//!
//! Spherocylinder of radius R and cylinder length L (thesis 000, eqs. 2.2-2.3):
//!
//! V = pi R^2 (4/3 R + L),
//! I_x = I_y = m (5 L^3 + 20 L^2 R + 45 L R^2 + 32 R^3) / (20 (3 L + 4 R)),
//! I_z = m (15 L R^2 + 16 R^3) / (10 (3 L + 4 R)),
//!
//! both reducing to (2/5) m R^2 for L = 0. Exact (no approximation).

use glam::DVec3;
use magsep_components::shape::Shape;
use std::f64::consts::PI;

/// Volume [m^3].
///
/// ```
/// use magsep_components::shape::Shape;
/// use magsep_systems::geometry::volume;
/// let v = volume(&Shape::Sphere { radius: 1.0 });
/// assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 1e-15);
/// ```
pub fn volume(shape: &Shape) -> f64 {
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
    let m = volume(shape);
    let r = shape.radius();
    let l = 2.0 * shape.half_length();
    let den = 3.0 * l + 4.0 * r;
    let ixy =
        m / 20.0 * (5.0 * l.powi(3) + 20.0 * l * l * r + 45.0 * l * r * r + 32.0 * r.powi(3)) / den;
    let iz = m / 10.0 * (15.0 * l * r * r + 16.0 * r.powi(3)) / den;
    DVec3::new(ixy, ixy, iz)
}

/// Radius of the smallest sphere about the centre that contains the shape [m].
pub fn bounding_radius(shape: &Shape) -> f64 {
    shape.radius() + shape.half_length()
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
        // spec packing.md 2.1: Lambda = 5 (L = 4, R = 1/2): V = 3.6652, I_x/m = 1.8893, I_z/m = 0.1214
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
}
