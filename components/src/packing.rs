//! Configuration and status of the mechanical contraction method (thesis 000, ch. 2-3).

use bevy_ecs::prelude::Resource;
use serde::{Deserialize, Serialize};

/// Which overlap-removal rule moves an overlapping particle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverlapRemovalScheme {
    /// Williams-Philipse, thesis eqs. 2.4-2.10 (spherocylinders and spheres).
    Original,
    /// Lagrange-optimal rule, thesis eqs. 3.2-3.13 (any convex shape, polydisperse).
    Revised,
    /// Collective FIRE minimisation of the overlap energy (not in the thesis; reaches random
    /// close packing within the attempt budget where the single-particle rules stall).
    Fire,
}

/// How the volume removed per compression step is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VolumeStepRule {
    /// The thesis's rule: a constant step, halved after a failed step (revert).
    Fixed,
    /// A step proportional to the free volume, grown while compressions need no overlap
    /// removal and shrunk when removal gets expensive; ends with the same finest step and the
    /// same failure criterion as `Fixed`.
    Adaptive,
}

/// Validated configuration of a packing run. Lengths SI.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PackingConfig {
    /// Overlap-removal rule. Default: `Fire`.
    pub scheme: OverlapRemovalScheme,
    /// Packing fraction of the random start configuration. Default 0.05. Range (0, 0.3].
    pub initial_packing_fraction: f64,
    /// Volume removed per compression step (the fixed rule's step, and the finest step of both
    /// rules after `step_halvings` halvings) [m^3]. Default 0.1 D^3, D = smallest particle
    /// diameter (thesis ch. 2).
    pub volume_step: f64,
    /// Volume step rule. Default: `Adaptive`.
    pub volume_step_rule: VolumeStepRule,
    /// Initial fraction of the free volume removed per step by the adaptive rule.
    /// Default 0.01. Range (0, 0.5].
    pub adaptive_initial_fraction: f64,
    /// Overlap-removal budget per compression step, in single-particle moves (one FIRE
    /// iteration counts as N). Default 200 N for `Original`/`Revised` (thesis), 20000 N for
    /// `Fire`.
    pub max_attempts: u64,
    /// How many times the volume step is halved after failures before the run stops. Default 4.
    pub step_halvings: u32,
    /// Overlaps below this are tolerated, in units of the smallest particle diameter. Default 1e-4.
    pub overlap_tolerance: f64,
    /// Revised scheme: step factor Delta t of eq. 3.9 (dimensionless, thesis units D = 1,
    /// density 1, c = 1). Default 0.1.
    pub revised_dt: f64,
    /// Original scheme: beta of eq. 2.10. Default 0.5.
    pub original_beta: f64,
    /// Original scheme: xi of eq. 2.6, in units of D^2 (mass 1). `None`: I_xy of eq. 2.3
    /// per particle (thesis choice).
    pub original_xi: Option<f64>,
    /// Hard limit on compression steps (safety). Default 10^7.
    pub max_compression_steps: u64,
    /// Observe (characterise) every this many compression steps; the final state always.
    /// Default 0 (final state only).
    pub observe_every: u64,
}

impl PackingConfig {
    /// The default attempt budget of `scheme` for `n` particles.
    pub fn default_max_attempts(scheme: OverlapRemovalScheme, n: usize) -> u64 {
        match scheme {
            OverlapRemovalScheme::Fire => 20_000 * n as u64,
            _ => 200 * n as u64,
        }
    }

    /// The defaults for `n` particles whose smallest diameter is `diameter` \[m\] (the thesis's
    /// values, with the FIRE scheme and the adaptive step rule).
    ///
    /// ```
    /// use magsep_components::packing::{OverlapRemovalScheme, PackingConfig};
    /// let c = PackingConfig::defaults_for(500, 1.0);
    /// assert_eq!(c.scheme, OverlapRemovalScheme::Fire);
    /// assert_eq!(c.max_attempts, 10_000_000);
    /// assert_eq!(PackingConfig::default_max_attempts(OverlapRemovalScheme::Revised, 500), 100_000);
    /// assert!((c.volume_step - 0.1).abs() < 1e-15);
    /// ```
    pub fn defaults_for(n: usize, diameter: f64) -> Self {
        Self {
            scheme: OverlapRemovalScheme::Fire,
            initial_packing_fraction: 0.05,
            volume_step: 0.1 * diameter.powi(3),
            volume_step_rule: VolumeStepRule::Adaptive,
            adaptive_initial_fraction: 0.01,
            max_attempts: Self::default_max_attempts(OverlapRemovalScheme::Fire, n),
            step_halvings: 4,
            overlap_tolerance: 1e-4,
            revised_dt: 0.1,
            original_beta: 0.5,
            original_xi: None,
            max_compression_steps: 10_000_000,
            observe_every: 0,
        }
    }
}

/// Why a packing run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// Overlaps could not be removed at the finest volume step: the MCM's jammed state.
    Jammed,
    /// `max_compression_steps` reached.
    StepLimit,
    /// Stopped before the first successful compression: the volume step is too large for the
    /// attempt budget (the reported packing is the start configuration).
    BudgetTooSmall,
}

/// Progress of a packing run (a resource, updated every compression step).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PackingStatus {
    /// Accepted compression steps.
    pub compression_steps: u64,
    /// Rejected (reverted) compression steps.
    pub failed_steps: u64,
    /// Halvings of the volume step so far.
    pub halvings: u32,
    /// Current volume step [m^3].
    pub volume_step: f64,
    /// Current adaptive fraction of the free volume.
    pub adaptive_fraction: f64,
    /// Whether the adaptive rule may still grow the step.
    pub may_grow: bool,
    /// Total single-particle moves.
    pub attempts: u64,
    /// Moves in the last compression step.
    pub last_attempts: u64,
    /// Current packing fraction of the last overlap-free state.
    pub packing_fraction: f64,
    /// Set when the run ended.
    pub stopped: Option<StopReason>,
    /// Pair contacts evaluated in overlap scans (all steps).
    #[serde(default)]
    pub contact_evaluations: u64,
    /// Of which the superquadric contact solver did not converge and its GJK/EPA estimate was
    /// used instead (counted, never dropped).
    #[serde(default)]
    pub contact_fallbacks: u64,
}
