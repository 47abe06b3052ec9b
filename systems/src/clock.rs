//! Clock systems.

use bevy_ecs::prelude::ResMut;
use magsep_components::clock::StepClock;

/// Finalize: advance the integer step clock (last system of `Finalize`).
pub fn advance_clock(mut clock: ResMut<StepClock>) {
    clock.advance();
}
