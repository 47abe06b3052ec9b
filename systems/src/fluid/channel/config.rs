//! Scene-level options of the simulated liquid (`[liquid] solver = { kind = "channel", ... }`).

use serde::{Deserialize, Serialize};

/// How the particles and the liquid exchange momentum (thesis 002, table 2.4 and §4.3.1.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CouplingLevel {
    /// The liquid acts on the particles only; it stays at rest, so it is not solved at all.
    OneWay,
    /// The particles' hydrodynamic forces are fed back (eq. 2.38-2.40), torques are not (the
    /// thesis's sphere cases).
    TwoWayForce,
    /// Forces and torques (pitching and rotational drag) are fed back (eqs. 4.20-4.23, the
    /// thesis's spheroid cases).
    #[default]
    TwoWay,
}

impl CouplingLevel {
    /// Whether the liquid needs to be solved.
    pub fn solves_liquid(self) -> bool {
        self != Self::OneWay
    }

    /// Whether torques are fed back.
    pub fn feeds_torque(self) -> bool {
        self == Self::TwoWay
    }
}

fn yes() -> bool {
    true
}

/// Which solver simulates the liquid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverKind {
    /// The pseudo-spectral channel solver ([`super::stepper::ChannelSolver`]): periodic in x
    /// and y, no-slip walls at z = 0 and z = height (needs `[container] kind = "channel"`).
    Channel,
}

/// The scene's liquid solver (`[liquid] solver`). A plain struct with a `kind` field rather
/// than a tagged enum, so that every error names its innermost key.
pub type LiquidSolver = ChannelSpec;

/// Options of the channel solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// The solver: `"channel"`.
    pub kind: SolverKind,
    /// Grid `[nx, ny, nz]`: Fourier points along x and y (even, ≥ 4) and Chebyshev-Gauss-Lobatto
    /// points along z (≥ 5, walls included). The thesis used 256 × 256 × 129.
    pub grid: [usize; 3],
    /// Coupling level. Default `two_way` (force and torque).
    #[serde(default)]
    pub coupling: CouplingLevel,
    /// Subtract the particle's own filtered Stokeslet from the sampled velocity
    /// ([`super::self_induced`]). Default false (the thesis applies no correction). A Stokes
    /// response: for particle Reynolds numbers of order one and beyond it over-corrects and
    /// can make the run diverge (docs/references.md D-002-19).
    #[serde(default)]
    pub self_induced_correction: bool,
    /// Dealias the nonlinear term (3/2 rule). Default true.
    #[serde(default = "yes")]
    pub dealias: bool,
    /// Feed the shape-induced lift of spheroids back too. Default true (momentum is then
    /// conserved; the thesis's eq. 4.20 leaves it out).
    #[serde(default = "yes")]
    pub feedback_lift: bool,
    /// Write a liquid slice and the solver state to the recording every this many steps.
    /// Default: the recording's interval.
    #[serde(default)]
    pub record_every: Option<u64>,
    /// Advance the liquid once every this many particle steps, with a time step that many
    /// times the particles' and the fed-back forces averaged over those steps (momentum is
    /// still conserved exactly). Default 1. The liquid's velocities are small and its viscous
    /// term is implicit, so a few particle steps per liquid step cost little accuracy where
    /// the convective CFL number stays well below 1 (the summary reports it); the particles
    /// see the liquid of the last liquid step in between.
    #[serde(default = "one")]
    pub step_every: u32,
}

fn one() -> u32 {
    1
}

impl ChannelSpec {
    /// The checks of the spec alone, as `(key, message)` pairs (keys relative to the spec).
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        let [nx, ny, nz] = self.grid;
        if nx < 4 || ny < 4 || nx % 2 == 1 || ny % 2 == 1 {
            out.push((
                "grid",
                format!("nx and ny must be even and at least 4 (got {nx}, {ny})"),
            ));
        }
        if nz < 5 {
            out.push(("grid", format!("nz must be at least 5 (got {nz})")));
        }
        if nx.saturating_mul(ny).saturating_mul(nz) > 1 << 27 {
            out.push((
                "grid",
                format!("{nx} x {ny} x {nz} points exceed the limit of 2^27 (memory)"),
            ));
        }
        if !(1..=1000).contains(&self.step_every) {
            out.push((
                "step_every",
                format!("must be in [1, 1000], got {}", self.step_every),
            ));
        }
        if self.record_every == Some(0) {
            out.push(("record_every", "must be at least 1".to_string()));
        }
        out
    }
}
