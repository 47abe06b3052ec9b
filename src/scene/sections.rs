//! Typed scene sections (serde, `deny_unknown_fields`, tagged enums). SI units.

use glam::DVec3;
use magsep_components::shape::Shape;
use serde::{Deserialize, Serialize};

use super::Scene;

/// `[simulation]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Name of the pipeline that runs the scene (one registered in the
    /// [`Registry`](super::Registry): `packing`, `brownian`, `particle_fluid` or a plugin's).
    pub pipeline: String,
    /// Seed of every random stream. Default 0.
    #[serde(default)]
    pub seed: u64,
}

/// A particle shape in a scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// Sphere of `radius` [m].
    Sphere {
        /// Radius R [m]. Range: > 0.
        radius: f64,
    },
    /// Spherocylinder: a cylinder of `cylinder_length` [m] and `radius` [m] capped by two
    /// hemispheres; aspect ratio (L + D) / D.
    Spherocylinder {
        /// Radius R [m]. Range: > 0.
        radius: f64,
        /// Length L of the cylindrical part [m]. Range: >= 0.
        cylinder_length: f64,
    },
    /// Superquadric |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 (thesis 000, eq. 4.3).
    Superquadric {
        /// Semi-axes (a1, a2, a3) [m]. Range: each > 0.
        semi_axes: [f64; 3],
        /// Exponents (g1, g2, g3). Range: each in [2, 20] (strictly convex).
        exponents: [f64; 3],
    },
    /// Superball |x|^g + |y|^g + |z|^g <= a^g (g = 2: sphere; g -> infinity: cube of side 2a).
    Superball {
        /// Semi-axis a (half the side of the enclosing cube) [m]. Range: > 0.
        semi_axis: f64,
        /// Exponent g. Range: [2, 20].
        exponent: f64,
    },
    /// Ellipsoid (x/a1)^2 + (y/a2)^2 + (z/a3)^2 <= 1 (a spheroid when two semi-axes agree).
    Ellipsoid {
        /// Semi-axes (a1, a2, a3) [m]. Range: each > 0.
        semi_axes: [f64; 3],
    },
}

impl ShapeSpec {
    /// The component shape.
    pub fn shape(&self) -> Shape {
        match *self {
            ShapeSpec::Sphere { radius } => Shape::Sphere { radius },
            ShapeSpec::Spherocylinder {
                radius,
                cylinder_length,
            } => Shape::Spherocylinder {
                radius,
                half_length: 0.5 * cylinder_length,
            },
            ShapeSpec::Superquadric {
                semi_axes,
                exponents,
            } => Shape::Superquadric {
                semi_axes: DVec3::from_array(semi_axes),
                exponents: DVec3::from_array(exponents),
            },
            ShapeSpec::Superball {
                semi_axis,
                exponent,
            } => Shape::Superquadric {
                semi_axes: DVec3::splat(semi_axis),
                exponents: DVec3::splat(exponent),
            },
            ShapeSpec::Ellipsoid { semi_axes } => Shape::Superquadric {
                semi_axes: DVec3::from_array(semi_axes),
                exponents: DVec3::splat(2.0),
            },
        }
    }
}

/// `[[particles]]`: one species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleGroup {
    /// Number of particles. Range: >= 1 (particle_fluid: or give `volume_fraction`).
    #[serde(default)]
    pub count: u64,
    /// Shape.
    pub shape: ShapeSpec,
    /// Magnetic moment law (brownian pipeline). Default: non-magnetic.
    #[serde(default)]
    pub moment: Option<magsep_components::brownian::MomentModel>,
    /// Start region (brownian and particle_fluid pipelines; required there).
    #[serde(default)]
    pub placement: Option<super::placement::PlacementSpec>,
    /// Particle density ρ_p [kg/m³] (particle_fluid).
    #[serde(default)]
    pub density: Option<f64>,
    /// Evenly spaced density ratios ρ_p/ρ_f instead of one `density` (particle_fluid).
    #[serde(default)]
    pub density_ratios: Option<super::placement::DensityRatios>,
    /// Initial velocity [m/s] (particle_fluid). Default zero.
    #[serde(default)]
    pub velocity: Option<[f64; 3]>,
    /// Volume fraction Φ of the container instead of `count`: count = floor(Φ V / V_p)
    /// (particle_fluid).
    #[serde(default)]
    pub volume_fraction: Option<f64>,
    /// Keys of this group that are not fields above, for a plugin pipeline to read (it
    /// declares them in [`Pipeline::particle_keys`](super::Pipeline::particle_keys)).
    #[serde(skip)]
    pub extra: toml::Table,
}

/// The `[[particles]]` keys [`ParticleGroup`] types itself; any other key of a group is
/// moved to [`ParticleGroup::extra`] before typing.
pub const GROUP_KEYS: &[&str] = &[
    "count",
    "shape",
    "moment",
    "placement",
    "density",
    "density_ratios",
    "velocity",
    "volume_fraction",
];

/// `[record]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSection {
    /// Record a frame every this many steps (and the final one). Default 100. Range >= 1.
    #[serde(default = "default_every")]
    pub every: u64,
}

fn default_every() -> u64 {
    100
}

impl Scene {
    /// Total number of particles.
    pub fn total_particles(&self) -> u64 {
        self.particles.iter().map(|g| g.count).sum()
    }

    /// The group (`[[particles]]` index) of every particle, in id order.
    pub fn species_ids(&self) -> Vec<u32> {
        self.particles
            .iter()
            .enumerate()
            .flat_map(|(k, g)| std::iter::repeat_n(k as u32, g.count as usize))
            .collect()
    }

    /// One shape per particle, in id order.
    pub fn shapes(&self) -> Vec<Shape> {
        self.particles
            .iter()
            .flat_map(|g| std::iter::repeat_n(g.shape.shape(), g.count as usize))
            .collect()
    }

    /// The smallest particle diameter D [m] (1 if there are no particles).
    pub fn reference_diameter(&self) -> f64 {
        let d = self
            .particles
            .iter()
            .map(|g| 2.0 * g.shape.shape().radius())
            .fold(f64::INFINITY, f64::min);
        if d.is_finite() { d } else { 1.0 }
    }
}
