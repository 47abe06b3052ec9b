//! Typed scene sections (serde, `deny_unknown_fields`, tagged enums). SI units.

use glam::DVec3;
use magsep_components::packing::{OverlapRemovalScheme, PackingConfig, VolumeStepRule};
use magsep_components::shape::Shape;
use serde::{Deserialize, Serialize};

use super::Scene;

/// Which pipeline runs the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PipelineKind {
    /// Mechanical contraction (random dense packings).
    Packing,
    /// Brownian dynamics of magnetic nanoparticles around magnetised fibres.
    Brownian,
    /// Inertial particles in a magnetised liquid (density separation), one-way coupled.
    ParticleFluid,
}

/// `[simulation]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Pipeline.
    pub pipeline: PipelineKind,
    /// Seed of every random stream. Default 0.
    #[serde(default)]
    pub seed: u64,
}

/// `[container]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContainerSpec {
    /// A periodic cube; its edge follows from `packing.initial_packing_fraction`.
    PeriodicBox {},
    /// A hard cylinder wall (thesis 000, ch. 2), periodic along its axis (z) and compressed
    /// along it only; its start length follows from `packing.initial_packing_fraction`.
    Cylinder {
        /// Radius of the cylinder R_cyl = D_cyl / 2 [m], fixed. Range: > the largest
        /// particle radius.
        radius: f64,
    },
    /// A hard wedge prism (thesis 000, ch. 2): bottom y = 0, back x = `length`, slope
    /// y = x tan(`angle`); periodic in z (its width) and compressed along it only.
    Wedge {
        /// Acute angle alpha between bottom and slope [rad]. Range: (0, pi/2).
        angle: f64,
        /// Length l_w of the wedge along x [m], fixed. Range: > 0 and room for a particle.
        length: f64,
    },
    /// Two hard walls z = 0 and z = height, periodic in x and y with the fixed side `side`;
    /// compressed along z; the start height follows from `packing.initial_packing_fraction`.
    Slab {
        /// Periodic side along x and y [m]. Range: > 0.
        side: f64,
    },
    /// A closed box of six hard walls, compressed isotropically; its start edge follows from
    /// `packing.initial_packing_fraction`.
    ClosedBox {},
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
    pub placement: Option<super::brownian::PlacementSpec>,
    /// Particle density ρ_p [kg/m³] (particle_fluid).
    #[serde(default)]
    pub density: Option<f64>,
    /// Evenly spaced density ratios ρ_p/ρ_f instead of one `density` (particle_fluid).
    #[serde(default)]
    pub density_ratios: Option<super::particle_fluid::DensityRatios>,
    /// Initial velocity [m/s] (particle_fluid). Default zero.
    #[serde(default)]
    pub velocity: Option<[f64; 3]>,
    /// Volume fraction Φ of the container instead of `count`: count = floor(Φ V / V_p)
    /// (particle_fluid).
    #[serde(default)]
    pub volume_fraction: Option<f64>,
}

/// `[packing]`: every key optional (see `PackingConfig` for meanings and defaults).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackingSection {
    /// Overlap-removal rule. Default `fire`.
    pub scheme: Option<OverlapRemovalScheme>,
    /// Start packing fraction. Default 0.05. Range (0, 0.3].
    pub initial_packing_fraction: Option<f64>,
    /// Volume step [m^3]. Default 0.1 D^3.
    pub volume_step: Option<f64>,
    /// Step rule. Default `adaptive`.
    pub volume_step_rule: Option<VolumeStepRule>,
    /// Adaptive rule's initial free-volume fraction. Default 0.01. Range (0, 0.5].
    pub adaptive_initial_fraction: Option<f64>,
    /// Attempt budget per compression step. Default 20000 N (fire), 200 N (others).
    pub max_attempts: Option<u64>,
    /// Halvings before the stop. Default 4. Range 0..=30.
    pub step_halvings: Option<u32>,
    /// Overlap tolerance in units of D. Default 1e-4. Range (0, 0.01].
    pub overlap_tolerance: Option<f64>,
    /// Revised Delta t. Default 0.1. Range (0, 10].
    pub revised_dt: Option<f64>,
    /// Original beta. Default 0.5. Range (0, 1].
    pub original_beta: Option<f64>,
    /// Original xi [m^2]. Default: I_xy / m per particle.
    pub original_xi: Option<f64>,
    /// Step limit. Default 10^7.
    pub max_compression_steps: Option<u64>,
    /// Observe every n steps (0: final only). Default 0.
    pub observe_every: Option<u64>,
}

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

    /// The packing configuration with every default resolved.
    pub fn packing_config(&self) -> PackingConfig {
        let n = self.total_particles() as usize;
        let mut c = PackingConfig::defaults_for(n, self.reference_diameter());
        let p = &self.packing;
        if let Some(v) = p.scheme {
            c.scheme = v;
            c.max_attempts = PackingConfig::default_max_attempts(v, n);
        }
        macro_rules! take {
            ($($f:ident),*) => { $( if let Some(v) = p.$f { c.$f = v; } )* };
        }
        take!(
            initial_packing_fraction,
            volume_step,
            volume_step_rule,
            adaptive_initial_fraction,
            max_attempts,
            step_halvings,
            overlap_tolerance,
            revised_dt,
            original_beta,
            max_compression_steps,
            observe_every
        );
        if p.original_xi.is_some() {
            c.original_xi = p.original_xi;
        }
        c
    }
}
