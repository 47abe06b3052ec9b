//! Force contributions and their fixed-order accumulation.
//!
//! Each contribution type `T: ForceContribution` gets two generic systems: [`clear_contribution`]
//! (in `Prepare`) and [`add_contribution`] (in `Accumulate`). The `add` systems are chained in
//! registration order after [`clear_net_force`], so `NetForce` is summed in the same order on
//! every run and thread count. Register with [`ForceRegistry::register`].
//!
//! Forces that depend on the particle's state and must be re-evaluated wherever a pipeline
//! needs forces (sub-steps, minimiser iterations) are kernels: see [`kernel`] (re-exported
//! here).

use bevy_ecs::prelude::*;
use magsep_components::forces::{ForceContribution, NetForce, NetTorque};

use crate::sets::SimSystems;

pub mod kernel;
pub use kernel::{
    Consumption, ExternalForce, ExternalForces, ForceUse, ParticleState, compute_kernel_forces,
};

/// Zero `NetForce` and `NetTorque` (first system of `Accumulate`).
///
/// The passes here are plain loops on the system's thread: they move a few bytes per
/// particle, and splitting them among threads cost more than it saved (the 2-thread rate of
/// the LAMMPS-mirror Brownian bench rose from 2.33 M to 2.74 M particle-steps/s, mean of four
/// interleaved rounds, when they went back to one thread).
pub fn clear_net_force(mut q: Query<(&mut NetForce, &mut NetTorque)>) {
    for (mut f, mut t) in &mut q {
        f.0 = glam::DVec3::ZERO;
        t.0 = glam::DVec3::ZERO;
    }
}

/// Reset contribution `T` on every entity (runs in `Prepare`).
pub fn clear_contribution<T: ForceContribution>(mut q: Query<&mut T>) {
    for mut c in &mut q {
        c.clear();
    }
}

/// Add contribution `T` into `NetForce`/`NetTorque` (runs in `Accumulate`).
pub fn add_contribution<T: ForceContribution>(mut q: Query<(&T, &mut NetForce, &mut NetTorque)>) {
    for (c, mut f, mut t) in &mut q {
        f.0 += c.force();
        t.0 += c.torque();
    }
}

/// Order of registered contributions (a resource), and the last `add` system's set so the
/// next one is chained after it.
#[derive(Resource, Debug, Default, Clone)]
pub struct ForceRegistry {
    /// Type names of the registered contributions, in summation order.
    pub names: Vec<String>,
}

/// The set of every generic contribution pass ([`clear_contribution`], [`clear_net_force`],
/// [`add_contribution`]): a pipeline that keeps its forces in a dense workspace can skip them
/// all with one run condition (see [`ForceComponents`]).
#[derive(bevy_ecs::schedule::SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ContributionPasses;

/// Whether the force contribution components (and `NetForce`) must be kept up to date at every
/// step (a resource; absent means [`ForceComponents::EveryStep`]).
///
/// A pipeline whose integrator reads its forces from a dense workspace (the brownian one)
/// honours [`ForceComponents::WorkspaceOnly`] while its own contributions are the only ones
/// registered: it then skips writing them to the components and the contribution passes,
/// which only readers outside the pipeline would see. `magsep`'s scene driver asks for it when
/// the caller promises that nothing reads them (`RunOptions::forces_unread`: `magsep run`,
/// sweeps, benches) and the run has no plugin besides the pipeline's own (the recorder reads
/// positions, never forces); any other app keeps the default, and inserting `EveryStep` at any
/// time brings the components back from the next step on.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ForceComponents {
    /// Written every step.
    #[default]
    EveryStep,
    /// Kept only in the pipeline's workspace where the pipeline can (the components keep
    /// their last written values).
    WorkspaceOnly,
}

/// Marker set of the `n`-th accumulation system (to chain them).
#[derive(bevy_ecs::schedule::SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AccumulateSlot(pub usize);

impl ForceRegistry {
    /// Register contribution `T`: adds its clear and add systems to `schedule` and records the
    /// order. Registering the same type twice is a no-op.
    ///
    /// ```
    /// use bevy_ecs::prelude::*;
    /// use glam::DVec3;
    /// use magsep_components::forces::{ForceContribution, NetForce, NetTorque};
    /// use magsep_systems::forces::ForceRegistry;
    /// use magsep_systems::sets::new_sim_schedule;
    ///
    /// #[derive(Component, Default)]
    /// struct PushForce(DVec3);
    /// impl ForceContribution for PushForce {
    ///     fn force(&self) -> DVec3 { self.0 }
    ///     fn clear(&mut self) {}
    /// }
    /// let mut world = World::new();
    /// let mut schedule = new_sim_schedule();
    /// let mut reg = ForceRegistry::default();
    /// reg.register::<PushForce>(&mut schedule);
    /// let e = world.spawn((PushForce(DVec3::X), NetForce::default(), NetTorque::default())).id();
    /// schedule.run(&mut world);
    /// assert_eq!(world.get::<NetForce>(e).unwrap().0, DVec3::X);
    /// ```
    pub fn register<T: ForceContribution>(&mut self, schedule: &mut Schedule) {
        let name = std::any::type_name::<T>().to_string();
        if self.names.contains(&name) {
            return;
        }
        let n = self.names.len();
        if n == 0 {
            schedule.add_systems(
                clear_net_force
                    .in_set(SimSystems::Accumulate)
                    .in_set(ContributionPasses)
                    .before(AccumulateSlot(0)),
            );
        }
        schedule.configure_sets(AccumulateSlot(n).in_set(SimSystems::Accumulate));
        if n > 0 {
            schedule.configure_sets(AccumulateSlot(n).after(AccumulateSlot(n - 1)));
        }
        schedule.add_systems(
            (
                clear_contribution::<T>.in_set(SimSystems::Prepare),
                add_contribution::<T>.in_set(AccumulateSlot(n)),
            )
                .in_set(ContributionPasses),
        );
        self.names.push(name);
    }
}
