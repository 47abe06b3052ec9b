//! The particle-fluid scene: `[particle_fluid]`, `[liquid]`, `[magnet]`, `[collisions]`, its
//! `[container]` kinds and the inertial keys of `[[particles]]` (thesis 002, ch. 1-2). SI
//! units; magsep's vertical is z (gravity along −z), the thesis's y.
//!
//! ```toml
//! [simulation]
//! pipeline = "particle_fluid"
//!
//! [particle_fluid]
//! time_step = 1e-3               # Δt [s]
//! duration = 10.0                # [s]
//! history = { kind = "window", window = 0.2 }   # or { kind = "full" }
//! terms = { history = true }     # every term on by default; switch any off
//!
//! [liquid]
//! density = 1403.0               # ρ_f [kg/m³]
//! viscosity = 5.54e-3            # μ [Pa s]
//! susceptibility = 7e-4          # χ (SI)
//!
//! [magnet]
//! kind = "bottom"                # bottom | top | two
//! surface_field = 422e3          # H₀ [A/m]
//! pole_size = 0.1181             # p [m]
//! half_height = 0.075            # L [m]: faces at y = ±L
//! # mid_plane = 0.075            # world z of y = 0; default: the container's mid-height
//!
//! [container]
//! kind = "tank"                  # closed box [0, edges] (or "channel", "unbounded")
//! edges = [0.15, 0.15, 0.15]
//!
//! [[particles]]
//! count = 1
//! shape = { kind = "sphere", radius = 2.5e-3 }
//! density = 1434.0               # ρ_p [kg/m³]
//! placement = { kind = "points", positions = [[0.075, 0.075, 0.0075]] }
//! ```

use glam::DVec3;
use magsep_systems::collision::{CollisionModel, Restitution};
use magsep_systems::fluid::channel::config::LiquidSolver;
use magsep_systems::fluid::collide::CollisionHistory;
use magsep_systems::fluid::config::{
    ForceTerms, HistoryChoice, Integrator, ParticleFluidConfig, STANDARD_GRAVITY, SpheroidOptions,
};
use magsep_systems::fluid::drag::DragLaw;
use magsep_systems::fluid::flow::FlowModel;
use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
use serde::{Deserialize, Serialize};

pub use super::validate::{DENSITY_RANGE, MAX_EXTENT, MAX_FIELD, MAX_RATE, MAX_SPEED, validate};

/// `[particle_fluid]`: every key but `time_step` and `duration` optional.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleFluidSection {
    /// Time step Δt \[s\]. Range (0, 1].
    pub time_step: f64,
    /// Simulated time \[s\]. Range: 1 to 1e9 steps.
    pub duration: f64,
    /// g [m/s²] along −z. Default 9.81. Range [0, 1000].
    #[serde(default)]
    pub gravity: Option<f64>,
    /// Terms of the equation of motion; each defaults to on.
    #[serde(default)]
    pub terms: ForceTerms,
    /// `schiller_naumann` (default) or `stokes`.
    #[serde(default)]
    pub drag_law: DragLaw,
    /// History kernel. Default a 0.2 s window with the exponential tail.
    #[serde(default)]
    pub history: HistoryChoice,
    /// `implicit` (default) or `explicit` (the thesis's forward Euler).
    #[serde(default)]
    pub integrator: Integrator,
    /// Levitation tolerance \[m\]. Default 0.5e-3 (thesis). Range > 0.
    #[serde(default)]
    pub levitation_tolerance: Option<f64>,
    /// Sample e_m every this many steps. Default steps / 200 (at least 1).
    #[serde(default)]
    pub observe_every: Option<u64>,
    /// How spheroids are modelled: `spin` (`suppressed` | `free`), `drag_density` (`fluid` |
    /// `particle`), `correlation` (`sanjeevi25` | `zastawny15` | `disc110` | `sphere`),
    /// `rotation_fit` (`zastawny_prolate52` | `zastawny_oblate15` | `sphere`). Default: the
    /// thesis's choices by aspect ratio, spin suppressed, ρ_f in the drag.
    #[serde(default)]
    pub spheroids: SpheroidOptions,
}

/// `[liquid]`: the carrier liquid and its undisturbed flow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiquidSection {
    /// ρ_f [kg/m³]. Range > 0.
    pub density: f64,
    /// μ [Pa s]. Range > 0.
    pub viscosity: f64,
    /// χ (SI volume susceptibility). Default 0. Range [-1, 10].
    #[serde(default)]
    pub susceptibility: f64,
    /// Undisturbed flow. Default quiescent.
    #[serde(default)]
    pub flow: FlowModel,
    /// Solve the liquid (two-way coupling): `{ kind = "channel", grid = [nx, ny, nz],
    /// coupling = "two_way" | "two_way_force" | "one_way", self_induced_correction = false,
    /// dealias = true, feedback_lift = true, record_every = N }`. Default: none (the liquid is
    /// the prescribed `flow`, one-way coupled).
    #[serde(default)]
    pub solver: Option<LiquidSolver>,
}

/// Which magnet arrangement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MagnetKind {
    /// Strong face at y = −L.
    Bottom,
    /// Strong face at y = +L.
    Top,
    /// Faces at y = ±L.
    Two,
}

/// `[magnet]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagnetSection {
    /// Arrangement.
    pub kind: MagnetKind,
    /// H₀ [A/m]. Range >= 0.
    pub surface_field: f64,
    /// Pole size p \[m\]. Range > 0.
    pub pole_size: f64,
    /// L \[m\]. Range > 0.
    pub half_height: f64,
    /// World z \[m\] of the model's y = 0. Default: the container's mid-height (0 unbounded).
    #[serde(default)]
    pub mid_plane: Option<f64>,
}

impl MagnetSection {
    /// The kernel model.
    pub fn model(&self) -> MagnetModel {
        let (surface_field, pole_size, half_height) =
            (self.surface_field, self.pole_size, self.half_height);
        match self.kind {
            MagnetKind::Bottom => MagnetModel::Bottom {
                surface_field,
                pole_size,
                half_height,
            },
            MagnetKind::Top => MagnetModel::Top {
                surface_field,
                pole_size,
                half_height,
            },
            MagnetKind::Two => MagnetModel::Two {
                surface_field,
                pole_size,
                half_height,
            },
        }
    }
}

/// `[collisions]`: every key optional (thesis ch. 2 defaults).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollisionsSection {
    /// Normal restitution. Default wet (Izard) with e_dry = 0.85, η_e = 1.5 µm.
    pub restitution: Option<Restitution>,
    /// Coulomb friction μ. Default 0.005.
    pub friction: Option<f64>,
    /// Tangential restitution e_t. Default 0.
    pub tangential_restitution: Option<f64>,
    /// Approaches slower than this are fully inelastic [m/s]. Default 0.01.
    pub rest_speed: Option<f64>,
    /// What a collision does to the Basset history: `reset` (thesis, default) or `keep`.
    pub history: Option<CollisionHistory>,
}

impl CollisionsSection {
    /// The model for `liquid`.
    pub fn model(&self, liquid: &LiquidSection) -> CollisionModel {
        let d = CollisionModel::default();
        CollisionModel {
            restitution: self.restitution.unwrap_or(d.restitution),
            tangential_restitution: self
                .tangential_restitution
                .unwrap_or(d.tangential_restitution),
            friction: self.friction.unwrap_or(d.friction),
            rest_speed: self.rest_speed.unwrap_or(d.rest_speed),
            fluid_density: liquid.density,
            kinematic_viscosity: liquid.viscosity / liquid.density,
        }
    }
}

/// The particle-fluid pipeline's `[container]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FluidContainerSpec {
    /// A channel between two walls z = 0 and z = `height`, periodic in x and y over `side`
    /// (the thesis's many-particle domain, with its y as our z).
    Channel {
        /// Periods along x and y \[m\]. Range > 4 particle diameters.
        side: [f64; 2],
        /// Wall distance \[m\]. Range > a particle diameter.
        height: f64,
    },
    /// A closed box [0, edges] (the experiment's tank).
    Tank {
        /// Edges along x, y, z \[m\]. Range > a particle diameter.
        edges: [f64; 3],
    },
    /// No walls, no periodicity.
    Unbounded {},
}

impl FluidContainerSpec {
    /// The box extent \[m\] (zero when unbounded).
    pub fn edges(&self) -> DVec3 {
        match self {
            Self::Channel { side, height } => DVec3::new(side[0], side[1], *height),
            Self::Tank { edges } => DVec3::from_array(*edges),
            Self::Unbounded {} => DVec3::ZERO,
        }
    }

    /// Fluid volume \[m³\] (infinite when unbounded).
    pub fn volume(&self) -> f64 {
        match self {
            Self::Unbounded {} => f64::INFINITY,
            _ => self.edges().element_product(),
        }
    }
}

/// Everything a particle-fluid scene adds, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleFluidScene {
    /// `[particle_fluid]`.
    pub section: ParticleFluidSection,
    /// `[liquid]`.
    pub liquid: LiquidSection,
    /// `[magnet]` (none: no magnetic buoyancy).
    pub magnet: Option<MagnetSection>,
    /// `[collisions]`.
    pub collisions: CollisionsSection,
    /// `[container]` (default unbounded).
    pub container: FluidContainerSpec,
}

impl ParticleFluidScene {
    /// Number of steps.
    pub fn steps(&self) -> u64 {
        (self.section.duration / self.section.time_step)
            .round()
            .max(1.0) as u64
    }

    /// The configuration with every default resolved.
    pub fn config(&self) -> ParticleFluidConfig {
        let s = &self.section;
        let steps = self.steps();
        let mid_default = 0.5 * self.container.edges().z;
        ParticleFluidConfig {
            dt: s.time_step,
            steps,
            gravity: s.gravity.unwrap_or(STANDARD_GRAVITY),
            mid_plane: self
                .magnet
                .as_ref()
                .and_then(|m| m.mid_plane)
                .unwrap_or(mid_default),
            liquid: Liquid {
                density: self.liquid.density,
                viscosity: self.liquid.viscosity,
                susceptibility: self.liquid.susceptibility,
            },
            magnet: self
                .magnet
                .as_ref()
                .map(|m| m.model())
                .unwrap_or(MagnetModel::None),
            flow: self.liquid.flow,
            terms: s.terms,
            drag_law: s.drag_law,
            history: s.history,
            integrator: s.integrator,
            levitation_tolerance: s.levitation_tolerance.unwrap_or(0.5e-3),
            observe_every: s.observe_every.unwrap_or((steps / 200).max(1)),
            spheroids: s.spheroids,
            solver: self.liquid.solver,
        }
    }
}

/// Number of particles of a group given by `volume_fraction`: floor(Φ V_fluid / V_p) for
/// particles of volume `particle_volume` \[m³\] (thesis table 2.4: 8835, 70685, 17671).
pub fn count_from_volume_fraction(fraction: f64, fluid_volume: f64, particle_volume: f64) -> u64 {
    (fraction * fluid_volume / particle_volume).floor() as u64
}
