//! The integer step clock (docs/architecture.md §3, determinism): time is `step * dt`, never accumulated.

use bevy_ecs::prelude::Resource;
use serde::{Deserialize, Serialize};

/// Integer step counter of a simulation.
///
/// ```
/// use magsep_components::clock::StepClock;
/// let mut c = StepClock::new(1e-3);
/// c.advance();
/// c.advance();
/// assert_eq!(c.step, 2);
/// assert_eq!(c.time(), 2e-3);
/// ```
#[derive(Resource, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepClock {
    /// Number of completed schedule steps.
    pub step: u64,
    /// Time step dt [s]. Zero for pipelines without physical time (packing).
    pub dt: f64,
}

impl StepClock {
    /// A clock at step 0 with time step `dt` [s].
    pub fn new(dt: f64) -> Self {
        Self { step: 0, dt }
    }

    /// Time of the current step, `step * dt` [s].
    pub fn time(&self) -> f64 {
        self.step as f64 * self.dt
    }

    /// Move to the next step.
    pub fn advance(&mut self) {
        self.step += 1;
    }
}

impl Default for StepClock {
    fn default() -> Self {
        Self::new(0.0)
    }
}
