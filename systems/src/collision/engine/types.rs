//! Public input, output and settings types of the collision step.

use glam::{DMat3, DQuat, DVec3};

use crate::collision::impulse::FrictionRegime;
use crate::collision::spheroid::Spheroid;

/// Settings of the event loop.
///
/// ```
/// use magsep_systems::collision::engine::EngineConfig;
/// let c = EngineConfig::default();
/// assert_eq!((c.max_events_per_particle, c.projection_sweeps), (64, 50));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineConfig {
    /// Events a particle may take part in per step. Default: 64. Range: ≥ 1.
    pub max_events_per_particle: u32,
    /// After this many events of a particle in a step, its approaches slower than the rest speed
    /// are deferred to the projection and the next step's resting solve. Default: 16. Range: ≥ 0.
    pub defer_slow_after: u32,
    /// Maximum Gauss–Seidel overlap-projection sweeps after the event loop (0 disables the
    /// projection). Default: 50. Range: ≥ 0.
    pub projection_sweeps: u32,
    /// The projection stops once no overlap exceeds this fraction of the (mean) diameter [-].
    /// Default: 1e-5. Range: ≥ 0.
    pub projection_tolerance: f64,
    /// Approaches below `approach_tolerance · (r_i + r_j)/h` are ignored [-]. Default: 1e-5.
    /// Range: ≥ 0.
    pub approach_tolerance: f64,
    /// Whether [`CollisionReport::events`] is filled. Default: true.
    pub record_events: bool,
    /// Maximum projected Gauss–Seidel sweeps of the resting-contact solve (0 disables it).
    /// Default: 50. Range: ≥ 0.
    pub resting_sweeps: u32,
    /// The resting solve stops when no contact velocity changes by more than
    /// `resting_tolerance · (r_i + r_j)/h` in a sweep [-]. Default: 1e-5. Range: > 0.
    pub resting_tolerance: f64,
    /// Whether the resting-contact solve starts from the previous step's contact impulses.
    /// Default: true.
    pub warm_start: bool,
    /// Maximum sweeps of the resting solve of spheres with nonsmooth nonlinear conjugate
    /// gradients (projected Gauss–Seidel sweeps with momentum, on blocks of the contact graph
    /// solved side by side); 0 selects the plain projected Gauss–Seidel sweeps, at most
    /// `resting_sweeps`. Non-spherical particles always use the plain sweeps. Default: 35.
    /// Range: ≥ 0.
    pub nncg_sweeps: u32,
    /// Approach speed \[m/s\] up to which the event loop leaves an approach at a resting contact
    /// to the resting solve (and the projection): it ignores approaches there up to
    /// `max(resting_floor, 2 × residual)`, the residual being the largest approach the resting
    /// solve left. Set it to the speed the step's largest body acceleration adds in one step
    /// (`|g| h` under gravity: the `particle_fluid` pipeline does): an approach that slow is
    /// indistinguishable from resting within the step. Spheres only: pairs with a spheroid keep
    /// the residual rule alone. Default: 0 (the residual rule alone). Range: ≥ 0.
    #[serde(default)]
    pub resting_floor: f64,
    /// Maximum sweeps of the overlap projection of spheres with momentum (on two blocks side by
    /// side; used with the NNCG resting solve, `nncg_sweeps > 0`, from 512 spheres), at most
    /// `projection_sweeps`. Default: 30. Range: ≥ 0.
    #[serde(default = "default_nncg_projection_sweeps")]
    pub nncg_projection_sweeps: u32,
}

/// The default of [`EngineConfig::nncg_projection_sweeps`].
fn default_nncg_projection_sweeps() -> u32 {
    30
}

impl Default for EngineConfig {
    fn default() -> Self {
        Self {
            max_events_per_particle: 64,
            defer_slow_after: 16,
            projection_sweeps: 50,
            projection_tolerance: 1e-5,
            approach_tolerance: 1e-5,
            record_events: true,
            resting_sweeps: 50,
            resting_tolerance: 1e-5,
            warm_start: true,
            nncg_sweeps: 35,
            resting_floor: 0.0,
            nncg_projection_sweeps: default_nncg_projection_sweeps(),
        }
    }
}

/// Inverse inertia per particle, world frame.
#[derive(Debug, Clone, Copy)]
pub enum InverseInertia<'a> {
    /// Isotropic `I⁻¹ = s 𝕀` (spheres) [1/(kg m²)].
    Scalar(&'a [f64]),
    /// Full tensors [1/(kg m²)], held fixed during the step.
    Tensor(&'a [DMat3]),
    /// Body-frame inverse principal moments `(1/I_x, 1/I_y, 1/I_z)` [1/(kg m²)]; the world tensor
    /// `R diag(·) Rᵀ` is recomputed from the current orientation at every use (identity
    /// orientation without [`SpheroidArrays`]). A zero entry suppresses spin about that body
    /// axis (`I → ∞`), e.g. `(1/I_x, 1/I_x, 0)` for a spheroid whose axial spin is neglected.
    Principal(&'a [DVec3]),
}

impl InverseInertia<'_> {
    pub(crate) fn len(&self) -> usize {
        match self {
            Self::Scalar(s) => s.len(),
            Self::Tensor(t) => t.len(),
            Self::Principal(p) => p.len(),
        }
    }
}

/// Shapes and orientations of non-spherical particles.
#[derive(Debug)]
pub struct SpheroidArrays<'a> {
    /// Per particle semi-axes (symmetry axis body z). A particle with equal semi-axes is a sphere
    /// of that radius and keeps the analytic sphere path with other spheres.
    pub shapes: &'a [Spheroid],
    /// In: body→lab orientations at the start of the step; out: at its end (rotated
    /// ballistically between collisions with the post-collision angular velocities).
    pub orientations: &'a mut [DQuat],
}

/// The particle arrays of one step, all of length `N`, in a stable particle order.
#[derive(Debug)]
pub struct ParticleArrays<'a> {
    /// In: positions at the start of the step; out: at the end (unwrapped) \[m\].
    pub positions: &'a mut [DVec3],
    /// In: velocities after the force update; out: after the collisions [m/s].
    pub velocities: &'a mut [DVec3],
    /// In/out like `velocities` [rad/s].
    pub angular_velocities: &'a mut [DVec3],
    /// Radii \[m\]. Ignored when `spheroids` is given: the shapes are then authoritative (a
    /// round shape is a sphere of that radius, others use their bounding radius `max(a, c)` for
    /// the cell grid).
    pub radii: &'a [f64],
    /// Inverse masses [1/kg] (0: immovable particle).
    pub inv_masses: &'a [f64],
    /// Inverse inertias.
    pub inv_inertias: InverseInertia<'a>,
    /// Densities (for the wet restitution) [kg/m³].
    pub densities: &'a [f64],
    /// Shapes and orientations; `None`: all particles are spheres of `radii` (the analytic path).
    pub spheroids: Option<SpheroidArrays<'a>>,
}

/// The other body of a collision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Partner {
    /// Particle index.
    Particle(usize),
    /// Index into [`CollisionDomain::planes`](crate::collision::domain::CollisionDomain::planes).
    Wall(usize),
}

/// One processed collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionEvent {
    /// Particle index (the lower index of a pair).
    pub particle: usize,
    /// The other body.
    pub partner: Partner,
    /// Time within the step \[s\].
    pub time: f64,
    /// Normal approach speed [m/s].
    pub approach_speed: f64,
    /// Stick or slide.
    pub regime: FrictionRegime,
    /// Whether the rest-speed rule made it fully inelastic.
    pub resting: bool,
    /// Impulse on `particle` (the partner receives the opposite) [N s].
    pub impulse: DVec3,
}

/// A particle's last collision in the step (to reset its Basset history).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LastCollision {
    /// Time within the step \[s\].
    pub time: f64,
    /// Velocity just before [m/s].
    pub velocity_before: DVec3,
    /// Velocity just after [m/s].
    pub velocity_after: DVec3,
    /// Whether it was a resting contact (rest-speed rule or the resting solve at time 0).
    pub resting: bool,
}

/// Counters of one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CollisionStats {
    /// Binary collisions with an impulse (event loop).
    pub events: usize,
    /// Of which with a wall.
    pub wall_events: usize,
    /// Of which sticking.
    pub stick: usize,
    /// Of which sliding.
    pub slide: usize,
    /// Of which resting contacts (fully inelastic by the rest speed).
    pub resting: usize,
    /// Particles that reached the event cap.
    pub capped_particles: usize,
    /// Predicted events dropped because a participant was capped.
    pub skipped_events: usize,
    /// Resting contacts that received an impulse in the resting-contact solve (not in `events`).
    pub resting_contacts: usize,
    /// Sweeps the resting-contact solve took.
    pub resting_sweeps: usize,
    /// Largest velocity change in the last resting sweep [m/s] (the solve's residual).
    pub resting_residual: f64,
    /// Grid rebuilds after a speed-bound increase.
    pub rebuilds: usize,
    /// Projection sweeps done.
    pub projection_sweeps: usize,
    /// Largest overlap at the end of the event loop, relative to the (mean) diameter [-].
    pub max_overlap_before_projection: f64,
    /// Largest overlap after the projection, relative to the (mean) diameter [-].
    pub max_overlap_after_projection: f64,
}

/// Output of [`CollisionEngine::step`](super::CollisionEngine::step) besides the updated arrays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CollisionReport {
    /// Resting-contact impulses (time 0, `resting`), then the processed collisions in processing
    /// order (empty unless `record_events`).
    pub events: Vec<CollisionEvent>,
    /// Per particle, the last collision of the step.
    pub last_collision: Vec<Option<LastCollision>>,
    /// Counters.
    pub stats: CollisionStats,
}

/// Invalid input to [`CollisionEngine::step`](super::CollisionEngine::step).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CollisionError {
    /// An array's length differs from the number of positions.
    #[error("array `{name}` has length {found}, expected {expected}")]
    LengthMismatch {
        /// Array name.
        name: &'static str,
        /// Number of positions.
        expected: usize,
        /// Its length.
        found: usize,
    },
    /// The step is negative or not finite.
    #[error("invalid step h = {0} s")]
    InvalidStep(f64),
    /// A periodic axis has a non-positive or non-finite length.
    #[error("periodic axis {axis} has invalid length {length}")]
    InvalidDomain {
        /// Axis index.
        axis: usize,
        /// Its length.
        length: f64,
    },
}
