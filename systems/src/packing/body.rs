//! Geometry and inertia of one particle in reduced units (lengths / D): the leaf module that
//! both the contact routines ([`super::contact`]) and the dense state ([`super::state`]) use.

use glam::{DQuat, DVec3};
use magsep_components::shape::Shape;

use crate::geometry::superquadric::{PreparedShape, Superquadric};
use crate::geometry::{bounding_radius, inertia_body_unit_density, volume};

/// Geometry class of a body: decides the contact routine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BodyKind {
    /// A sphere or spherocylinder (`radius`, `half_length`): segment distance.
    Rod,
    /// A superquadric in reduced units: common-normal Newton-Raphson.
    Superquadric(Superquadric),
}

/// Geometry and inertia of one particle, reduced units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Radius R / D (smallest semi-axis for a superquadric).
    pub radius: f64,
    /// Half length of the axis segment / D (0 for spheres and superquadrics).
    pub half_length: f64,
    /// Volume / D^3 (= mass at density 1).
    pub volume: f64,
    /// Principal moments of inertia (x, y, z) at density 1, / D^5.
    pub inertia: DVec3,
    /// I_xy / m of eq. 2.3 (the thesis's xi for the original scheme) / D^2.
    pub xi_default: f64,
    /// Radius of the bounding sphere about the centre / D.
    pub bounding: f64,
    /// Contact class.
    pub kind: BodyKind,
    /// The body as a superquadric with its contact constants computed once (a rod: its
    /// circumscribed spheroid), for contacts with superquadrics.
    pub contact_shape: PreparedShape,
    /// Whether [`Self::contact_shape`] only approximates the body (a rod of nonzero length).
    pub contact_approximate: bool,
}

impl Body {
    /// The body of `shape` scaled by `1/d` (d = reference diameter \[m\]).
    pub fn from_shape(shape: &Shape, d: f64) -> Self {
        let scaled = match *shape {
            Shape::Sphere { radius } => Shape::Sphere { radius: radius / d },
            Shape::Spherocylinder {
                radius,
                half_length,
            } => Shape::Spherocylinder {
                radius: radius / d,
                half_length: half_length / d,
            },
            Shape::Superquadric { .. } | Shape::Spheroid { .. } => {
                let (semi_axes, exponents) = shape.as_superquadric().unwrap_or_default();
                Shape::Superquadric {
                    semi_axes: semi_axes / d,
                    exponents,
                }
            }
        };
        let v = volume(&scaled);
        let inertia = inertia_body_unit_density(&scaled);
        let kind = match scaled {
            Shape::Superquadric {
                semi_axes,
                exponents,
            } => BodyKind::Superquadric(Superquadric {
                semi_axes,
                exponents,
            }),
            _ => BodyKind::Rod,
        };
        let radius = scaled.radius();
        let half_length = scaled.half_length();
        let (sq, approximate) = match kind {
            BodyKind::Superquadric(s) => (s, false),
            BodyKind::Rod => (
                Superquadric {
                    semi_axes: DVec3::new(radius, radius, radius + half_length),
                    exponents: DVec3::splat(2.0),
                },
                half_length > 0.0,
            ),
        };
        Self {
            radius,
            half_length,
            volume: v,
            inertia,
            xi_default: inertia.x / v,
            bounding: bounding_radius(&scaled),
            kind,
            contact_shape: PreparedShape::new(&sq),
            contact_approximate: approximate,
        }
    }

    /// Radius of the bounding sphere / D.
    #[inline]
    pub fn bounding_radius(&self) -> f64 {
        self.bounding
    }

    /// Whether rotations move the body's surface (false for spheres).
    pub fn rotates(&self) -> bool {
        match self.kind {
            BodyKind::Rod => self.half_length > 0.0,
            BodyKind::Superquadric(s) => {
                s.exponents != DVec3::splat(2.0)
                    || s.semi_axes.max_element() > s.semi_axes.min_element()
            }
        }
    }

    /// Farthest surface point in lab direction `dir` (unit), relative to the centre, for the
    /// orientation `q`.
    pub fn support(&self, q: DQuat, dir: DVec3) -> DVec3 {
        match self.kind {
            BodyKind::Rod => {
                let u = q * DVec3::Z;
                let end = if u.dot(dir) >= 0.0 { u } else { -u };
                self.half_length * end + self.radius * dir
            }
            BodyKind::Superquadric(s) => q * s.support(q.inverse() * dir),
        }
    }
}
