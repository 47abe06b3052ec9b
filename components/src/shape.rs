//! Particle shapes (data). Geometry kernels (volume, inertia, distances) live in
//! `magsep_systems::geometry`.

use bevy_ecs::prelude::Component;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Shape of a particle, in its body frame (symmetry axis along body z).
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Radius R \[m\].
        radius: f64,
    },
    /// A cylinder of length `2 * half_length` capped by two hemispheres: all points within
    /// `radius` of the axis segment. Aspect ratio (L + D) / D = 1 + half_length / radius.
    Spherocylinder {
        /// Radius R of the cylinder and the caps \[m\].
        radius: f64,
        /// Half the length of the cylindrical part, L/2 \[m\].
        half_length: f64,
    },
    /// A superquadric |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 (thesis 000, eq. 4.3). Exponents
    /// g = 2 give an ellipsoid (a spheroid when two semi-axes agree); equal semi-axes and
    /// exponents give a superball (a sphere at g = 2, a cube as g -> infinity).
    Superquadric {
        /// Semi-axes (a1, a2, a3) along body x, y, z \[m\].
        semi_axes: DVec3,
        /// Shape exponents (g1, g2, g3), each >= 2 (strictly convex), dimensionless.
        exponents: DVec3,
    },
    /// A spheroid (ellipsoid of revolution) about body z: x²/a² + y²/a² + z²/c² <= 1. Oblate
    /// (a flake or disc) for c < a, prolate for c > a. Its aspect ratio in the sense of thesis
    /// 002 is w = d_minor/d_major = c/a for an oblate spheroid.
    Spheroid {
        /// Equatorial semi-axis a (along body x and y) \[m\].
        equatorial_radius: f64,
        /// Polar semi-axis c (along the symmetry axis, body z) \[m\].
        polar_radius: f64,
    },
}

impl Shape {
    /// Radius R \[m\] (of the sphere, or of the rod's cylinder and caps); the smallest semi-axis
    /// of a superquadric.
    pub fn radius(&self) -> f64 {
        match *self {
            Shape::Sphere { radius } | Shape::Spherocylinder { radius, .. } => radius,
            Shape::Superquadric { semi_axes, .. } => semi_axes.min_element(),
            Shape::Spheroid {
                equatorial_radius,
                polar_radius,
            } => equatorial_radius.min(polar_radius),
        }
    }

    /// Half length of the axis segment \[m\]; zero for a sphere and a superquadric.
    pub fn half_length(&self) -> f64 {
        match *self {
            Shape::Sphere { .. } | Shape::Superquadric { .. } | Shape::Spheroid { .. } => 0.0,
            Shape::Spherocylinder { half_length, .. } => half_length,
        }
    }

    /// Whether this is a superquadric (a spheroid is one, with exponents 2).
    pub fn is_superquadric(&self) -> bool {
        matches!(self, Shape::Superquadric { .. } | Shape::Spheroid { .. })
    }

    /// Whether this is a spheroid.
    pub fn is_spheroid(&self) -> bool {
        matches!(self, Shape::Spheroid { .. })
    }

    /// The semi-axes and exponents of the shape as a superquadric, if it is one (a spheroid is
    /// the superquadric (a, a, c) with exponents 2).
    pub fn as_superquadric(&self) -> Option<(DVec3, DVec3)> {
        match *self {
            Shape::Superquadric {
                semi_axes,
                exponents,
            } => Some((semi_axes, exponents)),
            Shape::Spheroid {
                equatorial_radius: a,
                polar_radius: c,
            } => Some((DVec3::new(a, a, c), DVec3::splat(2.0))),
            _ => None,
        }
    }

    /// Aspect ratio (L + D) / D (thesis 000, eq. 2.1); 1 for a sphere; largest over smallest
    /// semi-axis for a superquadric or a spheroid (1/w for an oblate spheroid).
    pub fn aspect_ratio(&self) -> f64 {
        match *self {
            Shape::Superquadric { semi_axes, .. } => {
                semi_axes.max_element() / semi_axes.min_element()
            }
            Shape::Spheroid {
                equatorial_radius: a,
                polar_radius: c,
            } => a.max(c) / a.min(c),
            _ => 1.0 + self.half_length() / self.radius(),
        }
    }
}
