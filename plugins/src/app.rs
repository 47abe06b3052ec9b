//! A minimal app: a `World`, the per-step [`SimSchedule`], the replay [`ObserveSchedule`], and
//! the plugins that filled them. magsep does not use `bevy_app`: this trait and struct are all
//! a simulation needs (no event loop, no runner), and they keep the dependency tree small.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleBuildError;
use magsep_systems::forces::ForceRegistry;
use magsep_systems::sets::{
    ObserveSchedule, new_sim_schedule, resolved_schedule, strict_build_settings,
};
use std::any::Any;
use std::collections::BTreeMap;

/// A unit of wiring: adds resources and systems to a [`SimApp`].
///
/// ```
/// use bevy_ecs::prelude::*;
/// use magsep_plugins::app::{SimApp, SimPlugin};
/// use magsep_systems::sets::SimSystems;
///
/// #[derive(Resource, Default)]
/// struct Steps(u64);
/// fn count(mut s: ResMut<Steps>) { s.0 += 1; }
///
/// #[derive(Clone)]
/// struct CountPlugin;
/// impl SimPlugin for CountPlugin {
///     fn build(&self, app: &mut SimApp) {
///         app.world.init_resource::<Steps>();
///         app.schedule.add_systems(count.in_set(SimSystems::Observe));
///     }
/// }
/// let mut app = SimApp::new();
/// app.add_plugin(&CountPlugin);
/// app.finish().unwrap();
/// app.step();
/// assert_eq!(app.world.resource::<Steps>().0, 1);
/// ```
pub trait SimPlugin: Any + Send + Sync {
    /// Add resources and systems.
    fn build(&self, app: &mut SimApp);
    /// Called once after the scene was spawned (e.g. to gather dense workspaces).
    fn finish(&self, _world: &mut World) {}
    /// Name shown in the resolved schedule (default: the type name).
    fn name(&self) -> String {
        std::any::type_name::<Self>()
            .rsplit("::")
            .next()
            .unwrap_or("plugin")
            .to_string()
    }
}

/// A schedule that cannot be built (ambiguity, cycle), with the systems named.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ScheduleError(pub String);

fn describe(e: &ScheduleBuildError, schedule: &Schedule, world: &World) -> String {
    let text = e.to_string(schedule.graph(), world);
    if matches!(e, ScheduleBuildError::Elevated(_)) || text.to_lowercase().contains("ambigu") {
        format!("schedule ambiguity (systems with conflicting access and no order): {text}")
    } else {
        text
    }
}

/// A plugin's `finish` hook, kept until [`SimApp::finish`].
type FinishHook = Box<dyn Fn(&mut World) + Send + Sync>;

/// World + schedules of one simulation.
pub struct SimApp {
    /// The ECS world (entities and resources).
    pub world: World,
    /// Per-step schedule ([`magsep_systems::sets::SimSchedule`]), ambiguity detection on.
    pub schedule: Schedule,
    /// Replay schedule: only measurement systems.
    pub observe: Schedule,
    /// Registered force contributions, in summation order.
    pub forces: ForceRegistry,
    plugins: Vec<FinishHook>,
    plugin_names: Vec<String>,
}

impl Default for SimApp {
    fn default() -> Self {
        Self::new()
    }
}

impl SimApp {
    /// An empty app with the configured sets. Also makes sure bevy's compute task pool exists,
    /// which systems iterating queries in parallel need under any executor (its threads only
    /// split per-entity work, so results do not depend on their number).
    pub fn new() -> Self {
        bevy_tasks::ComputeTaskPool::get_or_init(bevy_tasks::TaskPool::default);
        let mut observe = Schedule::new(ObserveSchedule);
        observe.set_build_settings(strict_build_settings());
        Self {
            world: World::new(),
            schedule: new_sim_schedule(),
            observe,
            forces: ForceRegistry::default(),
            plugins: Vec::new(),
            plugin_names: Vec::new(),
        }
    }

    /// Build `plugin` into this app.
    pub fn add_plugin<P: SimPlugin + Clone>(&mut self, plugin: &P) -> &mut Self {
        plugin.build(self);
        let p = plugin.clone();
        self.plugin_names.push(plugin.name());
        self.plugins.push(Box::new(move |w| p.finish(w)));
        self
    }

    /// Build a boxed plugin (used by [`crate::PipelineGroup`]).
    pub fn add_boxed_plugin(&mut self, plugin: std::sync::Arc<dyn SimPlugin>) -> &mut Self {
        plugin.build(self);
        self.plugin_names.push(plugin.name());
        self.plugins.push(Box::new(move |w| plugin.finish(w)));
        self
    }

    /// Register force contribution `T` (summed in registration order).
    pub fn register_force<T: magsep_components::forces::ForceContribution>(&mut self) -> &mut Self {
        self.forces.register::<T>(&mut self.schedule);
        self
    }

    /// Insert a clone of `component` on every particle entity (those with a `ParticleId`), e.g.
    /// a plugin's own force contribution.
    pub fn insert_on_particles<C: Component + Clone>(&mut self, component: C) -> &mut Self {
        let ids: Vec<Entity> = self
            .world
            .query_filtered::<Entity, With<magsep_components::particle::ParticleId>>()
            .iter(&self.world)
            .collect();
        for e in ids {
            self.world.entity_mut(e).insert(component.clone());
        }
        self
    }

    /// Names of the plugins built, in order.
    pub fn plugin_names(&self) -> &[String] {
        &self.plugin_names
    }

    /// Run every plugin's `finish` hook, then build both schedules. Errors on ambiguities
    /// (two systems with conflicting access and no order) and cycles.
    ///
    /// # Errors
    /// The schedule build error of bevy_ecs, as text naming the systems involved.
    pub fn finish(&mut self) -> Result<(), ScheduleError> {
        for f in std::mem::take(&mut self.plugins) {
            f(&mut self.world);
        }
        self.world.insert_resource(self.forces.clone());
        if let Err(e) = self.schedule.initialize(&mut self.world) {
            return Err(ScheduleError(describe(&e, &self.schedule, &self.world)));
        }
        if let Err(e) = self.observe.initialize(&mut self.world) {
            return Err(ScheduleError(describe(&e, &self.observe, &self.world)));
        }
        Ok(())
    }

    /// Run one step of the simulation schedule.
    pub fn step(&mut self) {
        self.schedule.run(&mut self.world);
    }

    /// Run the observe schedule once (replay).
    pub fn observe_now(&mut self) {
        self.observe.run(&mut self.world);
    }

    /// The resolved schedule: set -> systems in execution order (after [`Self::finish`]).
    pub fn resolved_schedule(&self) -> BTreeMap<String, Vec<String>> {
        resolved_schedule(&self.schedule)
    }
}
