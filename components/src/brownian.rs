//! Brownian dynamics data: moments, force contributions, capture flags and the pipeline's
//! configuration (thesis 000, ch. 6). SI units throughout.

use bevy_ecs::prelude::*;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Boltzmann constant k_B [J/K].
pub const BOLTZMANN: f64 = 1.380_649e-23;

/// How a particle's magnetic moment follows the local flux density B. The moment is always
/// parallel to B (superparamagnetic particles, [T000 §6.2.4]).
///
/// ```
/// use magsep_components::brownian::MomentModel;
/// let m = MomentModel::Langevin { moment: 1e-16, domain_moment: 2.3e-19 };
/// let kt = 1.380649e-23 * 298.0;
/// // x = 2.3e-19 * 1 T / kT = 55.9: L(x) = coth x - 1/x = 0.982
/// assert!((m.magnitude(1.0, kt) / 1e-16 - 0.98211).abs() < 1e-4);
/// ```
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MomentModel {
    /// Non-magnetic.
    #[default]
    None,
    /// Saturated: `|m| = moment` [A m²] (the thesis's table 6.1 moments at ~1 T).
    Saturated {
        /// Moment μ_s [A m²]. Range: > 0.
        moment: f64,
    },
    /// Langevin (thesis eq. 6.22): `|m| = moment · L(x)`, `x = domain_moment |B| / (k_B T)`,
    /// `L(x) = coth x − 1/x`.
    Langevin {
        /// Saturation moment of the particle μ_s [A m²]. Range: > 0.
        moment: f64,
        /// Moment of one single-domain core μ_d [A m²] (2.3e-19 for a 10 nm magnetite core).
        /// Range: > 0.
        domain_moment: f64,
    },
}

impl MomentModel {
    /// `|m|` [A m²] at flux density magnitude `b` \[T\] and thermal energy `kt` \[J\].
    pub fn magnitude(&self, b: f64, kt: f64) -> f64 {
        match *self {
            Self::None => 0.0,
            Self::Saturated { moment } => moment,
            Self::Langevin {
                moment,
                domain_moment,
            } => moment * langevin(domain_moment * b / kt),
        }
    }

    /// Whether the particle carries a moment.
    pub fn is_magnetic(&self) -> bool {
        !matches!(self, Self::None)
    }
}

/// Langevin function `coth x − 1/x` (series where the difference cancels).
pub fn langevin(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        x / 3.0 - x * x * x / 45.0
    } else if x.abs() > 40.0 {
        x.signum() - 1.0 / x
    } else {
        1.0 / x.tanh() - 1.0 / x
    }
}

crate::force_contribution!(
    /// Force of the applied field and the fibres on the particle's moment, `|m| ∇|B|` \[N\].
    FieldForce
);
crate::force_contribution!(
    /// Sum of dipole-dipole forces from the other particles within the cut-off \[N\].
    DipoleForce
);
crate::force_contribution!(
    /// Soft-core (Mie) contact force from the other particles \[N\].
    ContactForce
);

/// The particle's current magnetic moment m [A m²] (parallel to the local B).
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagneticMoment(pub DVec3);

/// Where the particle started \[m\] (for the mean square displacement and the Brownian criterion).
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InitialPosition(pub DVec3);

/// Capture on a fibre: once set the particle is fixed for the rest of the run.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Captured(pub Option<CaptureEvent>);

/// When and where a particle was captured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CaptureEvent {
    /// Step at whose end the particle touched the fibre.
    pub step: u64,
    /// Fibre index (`FibreId`).
    pub fibre: u64,
}

/// Default of [`BrownianConfig::ewald_tolerance`].
fn default_ewald_tolerance() -> f64 {
    1e-6
}

/// Mobility choice of the scene (`mobility = "auto"`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MobilityChoice {
    /// Pick by particle count and concentration (the summary says what was picked).
    #[default]
    Auto,
    /// No hydrodynamic interactions: `D_ii = k_B T / (6 π η a_i)`.
    FreeDraining,
    /// Rotne-Prager-Yamakawa with dense Cholesky displacements (exact, O(N³)).
    Cholesky,
    /// Rotne-Prager-Yamakawa with the TEA-HI displacements of Geyer and Winter (O(N²)).
    Tea,
    /// Rotne-Prager-Yamakawa with Krylov (Lanczos) square-root displacements.
    Krylov,
    /// Rotne-Prager-Yamakawa without a matrix: free-space spectral Ewald products (relative
    /// accuracy `ewald_tolerance`), Krylov square-root displacements; O(N log N) per product.
    SpectralEwald,
}

/// Time stepping of the Ermak-McCammon update.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum StepControl {
    /// One explicit Euler step of `dt` per step (the thesis's scheme).
    Fixed,
    /// Step doubling on a Brownian tree: each `dt` is bisected until the one-step and
    /// two-half-step results agree within `tolerance` and no particle moves more than
    /// `max_displacement` (both in units of its radius).
    Adaptive {
        /// Local error tolerance in units of the particle radius. Default 1e-2. Range (0, 1].
        #[serde(default = "default_step_tolerance")]
        tolerance: f64,
        /// Largest move of one accepted sub-step in units of the radius. Default 0.5.
        /// Range (0, 10].
        #[serde(default = "default_max_displacement")]
        max_displacement: f64,
        /// Deepest bisection (sub-steps of dt / 2^depth). Default 24. Range 1..=40.
        #[serde(default = "default_max_depth")]
        max_depth: u32,
    },
    /// As `Adaptive`, but only the particles that fail the test, with their interaction
    /// partners, are bisected; the others take the whole interval and enter the refined
    /// sub-steps at interpolated positions (multirate). Free draining with a soft or no core;
    /// with hydrodynamic interactions or hard cores it steps as `Adaptive`.
    Multirate {
        /// As in `Adaptive`. Default 1e-2. Range (0, 1].
        #[serde(default = "default_step_tolerance")]
        tolerance: f64,
        /// As in `Adaptive`. Default 0.5. Range (0, 10].
        #[serde(default = "default_max_displacement")]
        max_displacement: f64,
        /// As in `Adaptive`. Default 24. Range 1..=40.
        #[serde(default = "default_max_depth")]
        max_depth: u32,
    },
}

impl StepControl {
    /// `(tolerance, max_displacement, max_depth)` of the adaptive kinds (None: fixed).
    pub fn adaptive_parameters(&self) -> Option<(f64, f64, u32)> {
        match *self {
            Self::Fixed => None,
            Self::Adaptive {
                tolerance,
                max_displacement,
                max_depth,
            }
            | Self::Multirate {
                tolerance,
                max_displacement,
                max_depth,
            } => Some((tolerance, max_displacement, max_depth)),
        }
    }
}

fn default_step_tolerance() -> f64 {
    1e-2
}

fn default_max_displacement() -> f64 {
    0.5
}

fn default_max_depth() -> u32 {
    24
}

impl Default for StepControl {
    fn default() -> Self {
        Self::Adaptive {
            tolerance: default_step_tolerance(),
            max_displacement: default_max_displacement(),
            max_depth: default_max_depth(),
        }
    }
}

/// Particle-particle excluded volume.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactModel {
    /// None (ideal particles).
    None,
    /// Pseudo-hard spheres: Mie(n, m) shifted and truncated at its minimum (thesis eq. 6.19).
    Mie {
        /// Well depth ε in units of k_B T. Default 100. Range (0, 1e6].
        epsilon_kt: f64,
        /// Repulsive exponent n. Default 30.
        n: f64,
        /// Attractive exponent m < n. Default 15.
        m: f64,
    },
    /// Hard spheres: after every (sub-)step overlapping pairs are pushed apart to contact.
    HardCore,
}

impl Default for ContactModel {
    fn default() -> Self {
        Self::Mie {
            epsilon_kt: 100.0,
            n: 30.0,
            m: 15.0,
        }
    }
}

/// Configuration of the `brownian` pipeline (a resource).
#[derive(Resource, Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BrownianConfig {
    /// Temperature T \[K\]. Default 298.
    pub temperature: f64,
    /// Fluid viscosity η [Pa s]. Default 1e-3.
    pub viscosity: f64,
    /// Number of steps of `dt` to run (duration / dt, rounded).
    pub steps: u64,
    /// Mobility.
    pub mobility: MobilityChoice,
    /// Relative tolerance of the Krylov square root. Default 1e-6.
    pub krylov_tolerance: f64,
    /// Relative accuracy of the spectral Ewald mobility product. Default 1e-6.
    #[serde(default = "default_ewald_tolerance")]
    pub ewald_tolerance: f64,
    /// Time stepping.
    pub step_control: StepControl,
    /// Excluded volume.
    pub contact: ContactModel,
    /// Dipole-dipole cut-off in units of the mean radius of a pair; `None`: no dipole forces.
    /// Default 30.
    pub dipole_cutoff: Option<f64>,
    /// Whether captured particles keep exerting dipole and contact forces on free ones.
    /// Default true.
    pub captured_interact: bool,
    /// Sample the capture curve every this many steps. Default: steps / 200.
    pub observe_every: u64,
    /// Relative size ε of the field patches (the fibres' field from a Taylor expansion about
    /// lattice nodes spaced ≤ ε × the distance to the nearest fibre); `None` (default): the
    /// exact field at every evaluation.
    #[serde(default)]
    pub field_patch: Option<f64>,
    /// Mean velocity u of the liquid \[m/s\] (interstitial: the pore velocity that carries a
    /// particle), added to every free particle's drift, `dx = (u + μF) dt + noise`; captured
    /// particles do not move. Default zero (quiescent liquid).
    #[serde(default)]
    pub flow: [f64; 3],
    /// Whether the liquid flows around the fibres (potential flow past each fibre, see
    /// `magsep_systems::brownian::fibre_flow`) rather than through them with the mean velocity
    /// everywhere. Default false.
    #[serde(default)]
    pub flow_around_fibres: bool,
}

impl BrownianConfig {
    /// Thermal energy k_B T \[J\].
    pub fn kt(&self) -> f64 {
        BOLTZMANN * self.temperature
    }
}

/// Counters of the time stepper and the interactions (a resource).
#[derive(Resource, Debug, Default, Clone, PartialEq, Serialize, Deserialize)]
pub struct BrownianStats {
    /// Accepted sub-steps in all (intervals of the tree, two sub-steps each).
    pub substeps: u64,
    /// Sub-steps taken per particle, summed over particles (multirate stepping; the global
    /// scheme's is `substeps` × free particles).
    #[serde(default)]
    pub particle_substeps: u64,
    /// Rejected trial sub-steps (bisected).
    pub rejections: u64,
    /// Deepest bisection reached.
    pub max_depth_reached: u32,
    /// Sub-steps accepted at the depth limit without meeting the tolerance.
    pub depth_limit_hits: u64,
    /// Force evaluations.
    pub force_evaluations: u64,
    /// Hard-core overlap-removal sweeps.
    pub hard_core_sweeps: u64,
    /// Mobility method actually used (resolved from `auto`).
    pub mobility: String,
    /// Why that mobility was chosen.
    pub mobility_reason: String,
    /// Krylov iterations in all.
    pub krylov_iterations: u64,
    /// Neighbour-list rebuilds of the pair forces (Verlet lists with a skin). A cost counter,
    /// not state: not recorded in checkpoints (a resumed run counts its own rebuilds).
    #[serde(skip)]
    pub neighbour_list_builds: u64,
}

/// Capture curve of one run: `(step, captured count)` samples (a resource).
#[derive(Resource, Debug, Default, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaptureCurve {
    /// Samples `(step, captured particles)`, in step order.
    pub samples: Vec<(u64, u64)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn langevin_limits_and_values() {
        assert!((langevin(1.0) - 0.313_035_285_499_331).abs() < 1e-15);
        for x in [1e-6, 1e-4, 9.9e-4] {
            assert!((langevin(x) / x - 1.0 / 3.0).abs() < 1e-6, "{x}");
        }
        assert!((langevin(57.0) - (1.0 - 1.0 / 57.0)).abs() < 1e-15);
        // continuity across the branch points
        for x in [1e-3f64, 40.0] {
            let (a, b) = (langevin(x * (1.0 - 1e-12)), langevin(x * (1.0 + 1e-12)));
            assert!((a - b).abs() < 1e-12, "{x}");
        }
        assert_eq!(langevin(-2.0), -langevin(2.0));
    }

    #[test]
    fn langevin_moment_is_the_derivative_of_the_free_energy() {
        // |m|(B) = -dF/dB with F(B) = -kT (μs/μd) ln(sinh x / x), x = μd B / kT
        let kt = BOLTZMANN * 298.0;
        let (ms, md) = (0.87e-16, 2.3e-19);
        let law = MomentModel::Langevin {
            moment: ms,
            domain_moment: md,
        };
        let free = |b: f64| {
            let x = md * b / kt;
            -kt * ms / md * (x.sinh() / x).ln()
        };
        for b in [0.005, 0.05, 0.2] {
            let h = 1e-6 * b;
            let m = -(free(b + h) - free(b - h)) / (2.0 * h);
            assert!((law.magnitude(b, kt) / m - 1.0).abs() < 1e-6, "B = {b}");
        }
        // D-000-8 (docs/references.md): a 10 nm magnetite core at 1 T: x ≈ 56, L ≈ 0.98; at 0.4 T L ≈ 0.96
        assert!((law.magnitude(1.0, kt) / ms - 0.982).abs() < 0.002);
        assert!((law.magnitude(0.4, kt) / ms - 0.955).abs() < 0.005);
        assert_eq!(MomentModel::Saturated { moment: ms }.magnitude(0.1, kt), ms);
    }
}
