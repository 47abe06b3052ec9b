//! Prescribed (one-way coupled) fluid flows: the undisturbed velocity u, its material
//! derivative Du/Dt and vorticity ω at a point, as the Maxey-Riley forces need them.
//!
//! The particle-fluid pipeline samples the flow once per particle per step in `Prepare`
//! (`FluidSample` components). A two-way coupled solver (a later issue) replaces the sampler
//! with interpolation from its grid and adds a feedback system; the force systems only read
//! `FluidSample`, so they do not change.

use glam::DVec3;
use magsep_components::fluid::FluidSample;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A prescribed undisturbed flow.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FlowModel {
    /// Fluid at rest (the thesis's single- and two-particle runs, and its moving frame).
    #[default]
    Quiescent,
    /// Uniform, steady velocity [m/s].
    Uniform {
        /// u [m/s].
        velocity: [f64; 3],
    },
    /// Simple shear `u = rate · y e_x`: vorticity `−rate e_z`, Du/Dt = 0.
    Shear {
        /// Shear rate γ̇ [1/s].
        rate: f64,
    },
    /// Uniform flow oscillating in time, `u = amplitude sin(2π f t)`: Du/Dt = ∂u/∂t.
    Oscillating {
        /// Velocity amplitude [m/s].
        amplitude: [f64; 3],
        /// Frequency f \[Hz\]. Range: > 0.
        frequency: f64,
    },
}

impl FlowModel {
    /// u, Du/Dt and ω at `x` \[m\] and time `t` \[s\].
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::flow::FlowModel;
    /// let s = FlowModel::Shear { rate: 2.0 }.sample(DVec3::new(0.0, 0.5, 0.0), 0.0);
    /// assert_eq!(s.velocity, DVec3::new(1.0, 0.0, 0.0));
    /// assert_eq!(s.vorticity, DVec3::new(0.0, 0.0, -2.0));
    /// ```
    pub fn sample(&self, x: DVec3, t: f64) -> FluidSample {
        match *self {
            Self::Quiescent => FluidSample::default(),
            Self::Uniform { velocity } => FluidSample {
                velocity: DVec3::from_array(velocity),
                ..Default::default()
            },
            Self::Shear { rate } => FluidSample {
                velocity: DVec3::new(rate * x.y, 0.0, 0.0),
                acceleration: DVec3::ZERO,
                vorticity: DVec3::new(0.0, 0.0, -rate),
            },
            Self::Oscillating {
                amplitude,
                frequency,
            } => {
                let a = DVec3::from_array(amplitude);
                let w = TAU * frequency;
                FluidSample {
                    velocity: a * (w * t).sin(),
                    acceleration: a * w * (w * t).cos(),
                    vorticity: DVec3::ZERO,
                }
            }
        }
    }

    /// Whether the flow is zero everywhere (the fluid terms then need no sampling).
    pub fn is_quiescent(&self) -> bool {
        matches!(self, Self::Quiescent)
    }
}
