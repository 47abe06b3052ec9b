//! The core plugin: clock, health and the fine-grained `Finalize` sets every pipeline uses.
//!
//! | set | system | touches |
//! |---|---|---|
//! | `FinalizeSystems::Clock` (last in `Finalize`) | `advance_clock` | `StepClock` |
//!
//! Resources: `StepClock` (inserted if absent), `Health`.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::clock::advance_clock;
use magsep_systems::sets::SimSystems;

use crate::app::{SimApp, SimPlugin};

/// Ordered steps inside `SimSystems::Finalize`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FinalizeSystems {
    /// Accept or revert constrained moves.
    Settle,
    /// Copy dense workspaces back to entities; periodic wrap.
    WriteBack,
    /// Capture, quarantine.
    Flags,
    /// Advance the step clock (always last).
    Clock,
}

/// Clock and health; configures the `Finalize` sub-sets.
#[derive(Debug, Clone, Copy, Default)]
pub struct CorePlugin;

impl SimPlugin for CorePlugin {
    fn build(&self, app: &mut SimApp) {
        if !app.world.contains_resource::<StepClock>() {
            app.world.insert_resource(StepClock::default());
        }
        app.world.init_resource::<Health>();
        use FinalizeSystems::*;
        app.schedule.configure_sets(
            (Settle, WriteBack, Flags, Clock)
                .chain()
                .in_set(SimSystems::Finalize),
        );
        app.schedule.add_systems(advance_clock.in_set(Clock));
    }
}
