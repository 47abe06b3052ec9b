//! The simulation schedule and its chained sets (docs/architecture.md §2, schedule).
//!
//! One schedule, [`SimSchedule`], runs once per step. Its top-level sets run in this order:
//! `Prepare -> Forces -> Accumulate -> Mobility -> Integrate -> Constraints -> Finalize ->
//! Observe -> Record`. `Forces` holds the unordered sub-sets of [`ForceSystems`]; each force
//! system writes its own contribution component, so they never conflict.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use magsep_systems::sets::{new_sim_schedule, SimSchedule, SimSystems};
//!
//! fn hello() {}
//! let mut world = World::new();
//! let mut schedule = new_sim_schedule();
//! schedule.add_systems(hello.in_set(SimSystems::Observe));
//! schedule.initialize(&mut world).unwrap();
//! schedule.run(&mut world);
//! ```

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::graph::Direction;
use bevy_ecs::schedule::{LogLevel, NodeId, ScheduleBuildSettings, ScheduleLabel};
use std::collections::BTreeMap;

/// Label of the per-step simulation schedule.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct SimSchedule;

/// Label of the schedule that re-runs only the `Observe` systems on recorded frames (replay).
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct ObserveSchedule;

/// Top-level sets of [`SimSchedule`], chained in declaration order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimSystems {
    /// Clear contributions, compress the container, neighbour lists, wall particles, fields.
    Prepare,
    /// Force contributions (sub-sets [`ForceSystems`]).
    Forces,
    /// Fixed-order sum of the registered contributions into `NetForce`/`NetTorque`.
    Accumulate,
    /// Forces to velocities.
    Mobility,
    /// Positions and orientations.
    Integrate,
    /// Overlap removal, collisions, hard-core corrections.
    Constraints,
    /// Periodic wrap, capture, quarantine, clock advance.
    Finalize,
    /// Measurements (packing fraction, order, ...).
    Observe,
    /// Recording.
    Record,
}

/// Unordered sub-sets of [`SimSystems::Forces`].
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ForceSystems {
    /// Applied magnetic fields.
    Field,
    /// Particle-particle dipole interactions.
    Dipole,
    /// Contact (soft-core) forces.
    Contact,
    /// Walls.
    Wall,
    /// Fluid coupling.
    Fluid,
    /// User contributions.
    Custom,
}

/// Chain the top-level sets and nest the force sub-sets in `schedule`.
pub fn configure_sim_sets(schedule: &mut Schedule) {
    use SimSystems::*;
    schedule.configure_sets(
        (
            Prepare,
            Forces,
            Accumulate,
            Mobility,
            Integrate,
            Constraints,
            Finalize,
            Observe,
            Record,
        )
            .chain(),
    );
    use ForceSystems::*;
    schedule.configure_sets((Field, Dipole, Contact, Wall, Fluid, Custom).in_set(Forces));
}

/// A new [`SimSchedule`] with the sets configured and ambiguity detection as an error: two
/// systems with conflicting access and no order make `initialize` fail.
pub fn new_sim_schedule() -> Schedule {
    let mut schedule = Schedule::new(SimSchedule);
    configure_sim_sets(&mut schedule);
    schedule.set_build_settings(strict_build_settings());
    schedule
}

/// Build settings of every shipped schedule: ambiguities are errors.
pub fn strict_build_settings() -> ScheduleBuildSettings {
    ScheduleBuildSettings {
        ambiguity_detection: LogLevel::Error,
        ..Default::default()
    }
}

/// The resolved schedule: for each set (by name) the systems in it, in execution order.
/// Systems outside any named set are listed under `"(none)"`. The schedule must be
/// initialized.
pub fn resolved_schedule(schedule: &Schedule) -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let Ok(systems) = schedule.systems() else {
        return out;
    };
    let graph = schedule.graph();
    for (key, system) in systems {
        let name = system.name().to_string();
        let mut sets: Vec<String> = graph
            .hierarchy()
            .graph()
            .neighbors_directed(NodeId::System(key), Direction::Incoming)
            .filter_map(|n| match n {
                NodeId::Set(k) => graph.system_sets.get(k).map(|s| format!("{s:?}")),
                NodeId::System(_) => None,
            })
            .filter(|s| !s.starts_with("SystemTypeSet") && !s.starts_with("AnonymousSet"))
            .collect();
        if sets.is_empty() {
            sets.push("(none)".into());
        }
        for s in sets {
            out.entry(s).or_default().push(name.clone());
        }
    }
    out
}
