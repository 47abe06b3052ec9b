//! Dense packing state in reduced units.
//!
//! The MCM's revised step size depends on the unit system (spec packing.md 5.2: a move is at
//! most delta_min * dt * sqrt(2c/m)), so the kernels work in the thesis's units: lengths in
//! units of a reference diameter D (the smallest particle diameter of the scene), density 1
//! (mass = reduced volume), c = 1. [`PackingState::from_si`] and [`PackingState::to_si`]
//! convert.

use glam::{DQuat, DVec3};
use magsep_components::shape::Shape;

use crate::geometry::{inertia_body_unit_density, volume};
use crate::packing::contact::{PairContact, pair_contact};

/// Geometry and inertia of one particle, reduced units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Radius R / D.
    pub radius: f64,
    /// Half length of the axis segment / D (0 for spheres).
    pub half_length: f64,
    /// Volume / D^3 (= mass at density 1).
    pub volume: f64,
    /// Principal moments of inertia (x, y, z) at density 1, / D^5.
    pub inertia: DVec3,
    /// I_xy / m of eq. 2.3 (the thesis's xi for the original scheme) / D^2.
    pub xi_default: f64,
}

impl Body {
    /// The body of `shape` scaled by `1/d` (d = reference diameter [m]).
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
        };
        let v = volume(&scaled);
        let inertia = inertia_body_unit_density(&scaled);
        Self {
            radius: scaled.radius(),
            half_length: scaled.half_length(),
            volume: v,
            inertia,
            xi_default: inertia.x / v,
        }
    }

    /// Radius of the bounding sphere / D.
    pub fn bounding_radius(&self) -> f64 {
        self.radius + self.half_length
    }
}

/// Positions, orientations and bodies of all particles in a periodic cube, reduced units.
#[derive(Debug, Clone, PartialEq)]
pub struct PackingState {
    /// Edge of the periodic cube / D; positions lie in [0, edge).
    pub edge: f64,
    /// Centres / D.
    pub positions: Vec<DVec3>,
    /// Orientations (body z = rod axis).
    pub orientations: Vec<DQuat>,
    /// Per-particle bodies.
    pub bodies: Vec<Body>,
}

impl PackingState {
    /// Build from SI data; `d` is the reference diameter [m].
    pub fn from_si(
        edge: f64,
        positions: &[DVec3],
        orientations: &[DQuat],
        shapes: &[Shape],
        d: f64,
    ) -> Self {
        Self {
            edge: edge / d,
            positions: positions.iter().map(|p| *p / d).collect(),
            orientations: orientations.to_vec(),
            bodies: shapes.iter().map(|s| Body::from_shape(s, d)).collect(),
        }
    }

    /// Edge [m] and positions [m] for reference diameter `d`.
    pub fn to_si(&self, d: f64) -> (f64, Vec<DVec3>) {
        (
            self.edge * d,
            self.positions.iter().map(|p| *p * d).collect(),
        )
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Total particle volume / D^3.
    pub fn particle_volume(&self) -> f64 {
        self.bodies.iter().map(|b| b.volume).sum()
    }

    /// Packing fraction.
    pub fn packing_fraction(&self) -> f64 {
        self.particle_volume() / self.edge.powi(3)
    }

    /// Axis (body z in the lab frame) of particle `i`.
    #[inline]
    pub fn axis(&self, i: usize) -> DVec3 {
        self.orientations[i] * DVec3::Z
    }

    /// Contact of particles `i` and `j`, with `j` seen through the periodic image `shift`.
    #[inline]
    pub fn contact(&self, i: usize, j: usize, shift: DVec3) -> PairContact {
        let (bi, bj) = (&self.bodies[i], &self.bodies[j]);
        pair_contact(
            self.axis(i),
            bi.half_length,
            bi.radius,
            self.positions[j] + shift - self.positions[i],
            self.axis(j),
            bj.half_length,
            bj.radius,
        )
    }

    /// Wrap particle `i` into [0, edge).
    #[inline]
    pub fn wrap(&mut self, i: usize) {
        let l = self.edge;
        let p = &mut self.positions[i];
        for c in [&mut p.x, &mut p.y, &mut p.z] {
            *c -= l * (*c / l).floor();
            if *c >= l {
                *c = 0.0;
            }
        }
    }

    /// Scale the box and all centres by `s` (affine compression; orientations unchanged).
    /// Centres are not wrapped (images scale with them), see `NeighbourList::build`.
    pub fn scale(&mut self, s: f64) {
        self.edge *= s;
        for p in &mut self.positions {
            *p *= s;
        }
    }

    /// Wrap every centre into [0, edge).
    pub fn wrap_all(&mut self) {
        for i in 0..self.len() {
            self.wrap(i);
        }
    }
}
