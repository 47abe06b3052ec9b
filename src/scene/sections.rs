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
    /// Sphere of `radius` \[m\].
    Sphere {
        /// Radius R \[m\]. Range: > 0.
        radius: f64,
    },
    /// Spherocylinder: a cylinder of `cylinder_length` \[m\] and `radius` \[m\] capped by two
    /// hemispheres; aspect ratio (L + D) / D.
    Spherocylinder {
        /// Radius R \[m\]. Range: > 0.
        radius: f64,
        /// Length L of the cylindrical part \[m\]. Range: >= 0.
        cylinder_length: f64,
    },
    /// Superquadric |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 <= 1 (thesis 000, eq. 4.3).
    Superquadric {
        /// Semi-axes (a1, a2, a3) \[m\]. Range: each > 0.
        semi_axes: [f64; 3],
        /// Exponents (g1, g2, g3). Range: each in [2, 20] (strictly convex).
        exponents: [f64; 3],
    },
    /// Superball |x|^g + |y|^g + |z|^g <= a^g (g = 2: sphere; g -> infinity: cube of side 2a).
    Superball {
        /// Semi-axis a (half the side of the enclosing cube) \[m\]. Range: > 0.
        semi_axis: f64,
        /// Exponent g. Range: [2, 20].
        exponent: f64,
    },
    /// Ellipsoid (x/a1)^2 + (y/a2)^2 + (z/a3)^2 <= 1 (a spheroid when two semi-axes agree).
    Ellipsoid {
        /// Semi-axes (a1, a2, a3) \[m\]. Range: each > 0.
        semi_axes: [f64; 3],
    },
    /// Spheroid about body z (a flake: oblate, aspect ratio w = d_minor/d_major < 1). Give
    /// exactly one of: `equatorial_radius` and `polar_radius`; `major_diameter` and
    /// `aspect_ratio`; `equivalent_diameter` and `aspect_ratio` (d_e = d_major w^{1/3}, the
    /// volume-equivalent sphere's diameter).
    Spheroid {
        /// Equatorial semi-axis a \[m\].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        equatorial_radius: Option<f64>,
        /// Polar semi-axis c (along the symmetry axis) \[m\].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        polar_radius: Option<f64>,
        /// d_major = 2a \[m\].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        major_diameter: Option<f64>,
        /// Volume-equivalent diameter d_e = 2 (a² c)^{1/3} \[m\].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        equivalent_diameter: Option<f64>,
        /// w = c/a (d_minor/d_major for an oblate spheroid) [-].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        aspect_ratio: Option<f64>,
    },
}

/// The semi-axes (a, c) \[m\] of a spheroid given by any one of the scene's three forms
/// (`None` unless exactly one form is complete and nothing else is given).
///
/// ```
/// use magsep::scene::spheroid_semi_axes;
/// // the thesis's 1:10 flake of d_e = 4 mm has d_major = 8.62 mm
/// let (a, c) = spheroid_semi_axes(None, None, None, Some(4e-3), Some(0.1)).unwrap();
/// assert!((2.0 * a - 8.618e-3).abs() < 1e-6 && (c / a - 0.1).abs() < 1e-15);
/// assert!(spheroid_semi_axes(Some(1.0), None, None, None, Some(0.5)).is_none());
/// ```
pub fn spheroid_semi_axes(
    equatorial_radius: Option<f64>,
    polar_radius: Option<f64>,
    major_diameter: Option<f64>,
    equivalent_diameter: Option<f64>,
    aspect_ratio: Option<f64>,
) -> Option<(f64, f64)> {
    match (
        equatorial_radius,
        polar_radius,
        major_diameter,
        equivalent_diameter,
        aspect_ratio,
    ) {
        (Some(a), Some(c), None, None, None) => Some((a, c)),
        (None, None, Some(d), None, Some(w)) => Some((0.5 * d, 0.5 * d * w)),
        (None, None, None, Some(de), Some(w)) => {
            let a = 0.5 * de / w.cbrt();
            Some((a, w * a))
        }
        _ => None,
    }
}

/// The initial orientation of a group's particles (`orientation = "broadside"`, `"random"`,
/// `"edge_on"`, `{ axis = [x, y, z] }` or `{ tilt = 30.0 }`). Only non-spherical particles
/// care.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum OrientationSpec {
    /// Symmetry axis vertical (z): a flake lies flat, its broad side facing a vertical motion
    /// (the thesis's injection, §4.3.2). Default.
    #[default]
    Broadside,
    /// Symmetry axis along x: a flake stands on its edge.
    EdgeOn,
    /// Uniformly random orientations (from each particle's random stream).
    Random,
    /// Symmetry axis along this lab vector (normalised).
    Axis([f64; 3]),
    /// Symmetry axis tilted from vertical by this angle \[degrees\] about the x axis.
    Tilt(f64),
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
            ShapeSpec::Spheroid {
                equatorial_radius,
                polar_radius,
                major_diameter,
                equivalent_diameter,
                aspect_ratio,
            } => {
                let (a, c) = spheroid_semi_axes(
                    equatorial_radius,
                    polar_radius,
                    major_diameter,
                    equivalent_diameter,
                    aspect_ratio,
                )
                .unwrap_or((f64::NAN, f64::NAN));
                Shape::Spheroid {
                    equatorial_radius: a,
                    polar_radius: c,
                }
            }
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
    /// Initial orientation of spheroids (particle_fluid; refused on a sphere, which it would
    /// not affect). Default broadside.
    #[serde(default)]
    pub orientation: Option<OrientationSpec>,
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
    "orientation",
    "volume_fraction",
];

/// `[record]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSection {
    /// Record a frame every this many steps (and the final one). Default 100. Range >= 1.
    #[serde(default = "default_every")]
    pub every: u64,
    /// End a chunk and flush the file at every frame. Default false: frames share a chunk for
    /// up to 1 s of wall time or 1 MiB, so a process killed without warning loses at most the
    /// frames of the last second (SIGINT, SIGTERM and errors still flush everything).
    #[serde(default)]
    pub flush_every_frame: bool,
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

    /// The smallest particle diameter D \[m\] (1 if there are no particles).
    pub fn reference_diameter(&self) -> f64 {
        let d = self
            .particles
            .iter()
            .map(|g| 2.0 * g.shape.shape().radius())
            .fold(f64::INFINITY, f64::min);
        if d.is_finite() { d } else { 1.0 }
    }
}
