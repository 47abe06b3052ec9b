//! Numerical health of a run (docs/architecture.md §6, errors).

use bevy_ecs::prelude::Resource;
use serde::{Deserialize, Serialize};

/// Numerical failures noticed in hot loops. The CLI stops with a clear message when
/// [`Health::is_failed`] unless the user opted to continue.
///
/// ```
/// use magsep_components::health::Health;
/// let mut h = Health::default();
/// assert!(!h.is_failed());
/// h.report("non-finite position of particle 3");
/// assert!(h.is_failed());
/// ```
#[derive(Resource, Debug, Default, Clone, Serialize, Deserialize)]
pub struct Health {
    /// Messages, oldest first (at most 100 kept).
    pub messages: Vec<String>,
    /// Total number of reported failures.
    pub failures: u64,
}

impl Health {
    /// Record one failure.
    pub fn report(&mut self, message: impl Into<String>) {
        self.failures += 1;
        if self.messages.len() < 100 {
            self.messages.push(message.into());
        }
    }

    /// Whether any failure was reported.
    pub fn is_failed(&self) -> bool {
        self.failures > 0
    }
}
