//! Configuration of the particle-fluid pipeline (a resource), with every default resolved.
//! It sits beside the kernels because it is made of their types (liquid, magnet, flow, drag
//! law, history kernel, collision model).

use bevy_ecs::prelude::Resource;
use serde::{Deserialize, Serialize};

use super::channel::config::{ChannelSpec, LiquidSolver};
use super::drag::DragLaw;
use super::flow::FlowModel;
use super::magnet::{Liquid, MagnetModel};
use super::rigid::SpinModel;
use super::spheroid::{Correlation, DragDensity, RotationFit};

/// Standard gravity g [m/s²].
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Which terms of the equation of motion a run models (scene key `terms`; each defaults to
/// on). A term that cannot act in a scene (the undisturbed-flow force in a quiescent liquid,
/// the magnetic buoyancy without a magnet) is not run at all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForceTerms {
    /// Weight −ρ_p V g e_z.
    pub gravity: bool,
    /// Hydrostatic buoyancy ρ_f V g e_z.
    pub buoyancy: bool,
    /// Magnetic buoyancy −μ₀ V χ H dH/dy e_z.
    pub magnetic_buoyancy: bool,
    /// Steady drag.
    pub drag: bool,
    /// Added mass ½ ρ_f V (Du/Dt − dv/dt).
    pub added_mass: bool,
    /// Undisturbed-flow force ρ_f V Du/Dt.
    pub undisturbed_flow: bool,
    /// Basset history force.
    pub history: bool,
    /// Rotational drag and the rotation of the particles.
    pub rotation: bool,
    /// Hard-particle collisions (particle-particle and particle-wall).
    pub collisions: bool,
    /// Shape-induced lift of spheroids at incidence.
    pub lift: bool,
    /// Pitching torque of spheroids at incidence.
    pub pitching_torque: bool,
    /// Magnetic-buoyancy torque on spheroids.
    pub magnetic_torque: bool,
}

impl Default for ForceTerms {
    fn default() -> Self {
        Self {
            gravity: true,
            buoyancy: true,
            magnetic_buoyancy: true,
            drag: true,
            added_mass: true,
            undisturbed_flow: true,
            history: true,
            rotation: true,
            collisions: true,
            lift: true,
            pitching_torque: true,
            magnetic_torque: true,
        }
    }
}

/// The history kernel of a scene (`history = { kind = "window", window = 0.2 }`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum HistoryChoice {
    /// Full memory (O(n) per step; the reference).
    Full,
    /// Window of `window` seconds with exact weights plus the ten-exponential tail of van
    /// Hinsberg et al. (O(1) per step); `tail = false` truncates the memory at the window.
    Window {
        /// t_win \[s\]. Range: >= the time step. Default 0.2 s (the thesis's fig. 2.10 runs).
        window: f64,
        /// Keep the exponential tail. Default true.
        #[serde(default = "yes")]
        tail: bool,
    },
}

fn yes() -> bool {
    true
}

impl Default for HistoryChoice {
    fn default() -> Self {
        Self::Window {
            window: 0.2,
            tail: true,
        }
    }
}

/// How velocities are advanced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Linearly implicit Euler (default): drag (secant stiffness), added mass and the newest
    /// history weight implicit, other forces at the start of the step; positions with the
    /// new velocity. Stable at any step for the drag and history terms.
    #[default]
    Implicit,
    /// The thesis's forward Euler: every force at the start of the step, the history from
    /// completed steps only. Unstable for Δt > 2τ_eff or small particles (D-002-2).
    Explicit,
}

/// How spheroids are modelled (scene key `spheroids`; every key optional).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpheroidOptions {
    /// Rotation about the symmetry axis: `suppressed` (the thesis; default) or `free`.
    pub spin: SpinModel,
    /// Density in the drag and lift: `fluid` (default) or `particle` (as the thesis prints).
    pub drag_density: DragDensity,
    /// Drag/lift/pitching correlation for every spheroid. Default: by aspect ratio (the
    /// thesis's choice: Sanjeevi 2:5 for w >= 0.3, Zastawny 1:5 for w >= 0.15, else 1:10).
    pub correlation: Option<Correlation>,
    /// Rotational-resistance fit for every spheroid. Default: by aspect ratio (Zastawny 5:2
    /// prolate for w >= 0.3, Zastawny 1:5 oblate below).
    pub rotation_fit: Option<RotationFit>,
}

/// The particle-fluid pipeline's configuration.
#[derive(Resource, Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParticleFluidConfig {
    /// Time step Δt \[s\].
    pub dt: f64,
    /// Number of steps of the run.
    pub steps: u64,
    /// Gravitational acceleration g [m/s²], acting along −z (magsep's vertical; the thesis's
    /// y).
    pub gravity: f64,
    /// World height z \[m\] of the magnet model's y = 0 (the mid-plane between the faces at
    /// y = ±L): the thesis's y is z − `mid_plane`.
    pub mid_plane: f64,
    /// The liquid.
    pub liquid: Liquid,
    /// The magnet arrangement.
    pub magnet: MagnetModel,
    /// The undisturbed flow.
    pub flow: FlowModel,
    /// Terms of the equation of motion.
    pub terms: ForceTerms,
    /// Steady drag law.
    pub drag_law: DragLaw,
    /// History kernel.
    pub history: HistoryChoice,
    /// Velocity update.
    pub integrator: Integrator,
    /// Levitation tolerance \[m\] (|y − y_e| within it counts as levitated; thesis 0.5 mm).
    pub levitation_tolerance: f64,
    /// Sample the separation error every this many steps.
    pub observe_every: u64,
    /// How spheroids are modelled.
    #[serde(default)]
    pub spheroids: SpheroidOptions,
    /// The simulated liquid (two-way coupling), if any.
    #[serde(default)]
    pub solver: Option<LiquidSolver>,
}

impl ParticleFluidConfig {
    /// The magnet model's height y of world height `z` \[m\].
    pub fn magnet_y(&self, z: f64) -> f64 {
        z - self.mid_plane
    }

    /// Equilibrium height (world z) \[m\] of a particle of `density` [kg/m³], if it levitates.
    pub fn equilibrium_height(&self, density: f64) -> Option<f64> {
        self.magnet
            .equilibrium_height(&self.liquid, self.gravity, density)
            .map(|y| y + self.mid_plane)
    }

    /// Whether the magnetic buoyancy term runs (a magnet and a magnetisable liquid).
    pub fn magnetic_on(&self) -> bool {
        self.terms.magnetic_buoyancy
            && !matches!(self.magnet, MagnetModel::None)
            && self.liquid.susceptibility != 0.0
    }

    /// The channel solver's options when the liquid is solved (a solver whose coupling is
    /// not one-way).
    pub fn channel(&self) -> Option<ChannelSpec> {
        match self.solver {
            Some(c) if c.coupling.solves_liquid() => Some(c),
            _ => None,
        }
    }

    /// Whether a magnetic torque can act (a magnet and a magnetisable liquid).
    pub fn magnet_torque_can_act(&self) -> bool {
        !matches!(self.magnet, MagnetModel::None) && self.liquid.susceptibility != 0.0
    }

    /// Whether the undisturbed-flow force runs (a non-quiescent flow or a solved liquid).
    pub fn undisturbed_on(&self) -> bool {
        (self.terms.undisturbed_flow || self.terms.added_mass)
            && (!self.flow.is_quiescent() || self.channel().is_some())
    }

    /// The terms that run, by name, in a stable order (for the summary).
    pub fn active_terms(&self) -> Vec<&'static str> {
        let t = &self.terms;
        let mut out = Vec::new();
        for (on, name) in [
            (t.gravity, "gravity"),
            (t.buoyancy, "buoyancy"),
            (self.magnetic_on(), "magnetic_buoyancy"),
            (t.drag, "drag"),
            (t.added_mass, "added_mass"),
            (
                t.undisturbed_flow && !self.flow.is_quiescent(),
                "undisturbed_flow",
            ),
            (t.history, "history"),
            (t.rotation, "rotation"),
            (t.collisions, "collisions"),
            (t.lift, "lift"),
            (t.pitching_torque, "pitching_torque"),
            (
                t.magnetic_torque && self.magnet_torque_can_act(),
                "magnetic_torque",
            ),
        ] {
            if on {
                out.push(name);
            }
        }
        out
    }
}
