//! A minimal app: a `World`, the per-step [`SimSchedule`](magsep_systems::sets::SimSchedule), the replay [`ObserveSchedule`], and
//! the plugins that filled them. magsep does not use `bevy_app`: this trait and struct are all
//! a simulation needs (no event loop, no runner), and they keep the dependency tree small.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleBuildError;
use magsep_components::forces::{ForceContribution, KernelForce};
use magsep_components::particle::ParticleId;
use magsep_systems::forces::{
    ExternalForce, ExternalForces, ForceRegistry, ForceUse, compute_kernel_forces,
};
use magsep_systems::sets::{
    ForceSystems, ObserveSchedule, new_sim_schedule, resolved_schedule, strict_build_settings,
};
use std::any::Any;
use std::collections::BTreeMap;
use std::sync::Arc;

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
    /// The plugin's parameters, recorded with the run (default: none, `null`).
    fn params(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    /// Restore the plugin's own state when a run resumes from a recorded frame (`magsep
    /// replay --resume`, `magsep::replay::resume`), called in build order after every plugin's
    /// `finish`. `status` is the frame's status object: the keys that the world's
    /// [`FrameStatusProviders`](crate::recorder::FrameStatusProviders) wrote at that frame, so
    /// a plugin with state (a counter, an accumulated observable) registers a provider of its
    /// key in `build` and reads it back here. Default: nothing, the plugin's resources start
    /// afresh from its `build`.
    ///
    /// # Errors
    /// A message when the frame does not hold what the plugin needs (the resume fails with
    /// it, naming the plugin).
    fn restore(&self, _world: &mut World, _status: &serde_json::Value) -> Result<(), String> {
        Ok(())
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
    built: Vec<Arc<dyn SimPlugin>>,
    plugin_names: Vec<String>,
    plugin_params: Vec<serde_json::Value>,
    /// The schedule runs one system after the other on a thread of rayon's pool
    /// ([`Self::set_single_threaded`]).
    in_pool: bool,
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
            built: Vec::new(),
            plugin_names: Vec::new(),
            plugin_params: Vec::new(),
            in_pool: false,
        }
    }

    /// Build `plugin` into this app.
    pub fn add_plugin<P: SimPlugin + Clone>(&mut self, plugin: &P) -> &mut Self {
        self.add_boxed_plugin(Arc::new(plugin.clone()))
    }

    /// Build a boxed plugin (used by [`crate::PipelineGroup`]).
    pub fn add_boxed_plugin(&mut self, plugin: Arc<dyn SimPlugin>) -> &mut Self {
        let name = plugin.name();
        self.add_named_plugin(name, plugin)
    }

    /// Build a boxed plugin under `name` (its entry name in [`Self::plugin_infos`]; a group
    /// names several instances of one type apart).
    pub fn add_named_plugin(&mut self, name: String, plugin: Arc<dyn SimPlugin>) -> &mut Self {
        plugin.build(self);
        self.plugin_names.push(name);
        self.plugin_params.push(plugin.params());
        self.built.push(plugin.clone());
        self.plugins.push(Box::new(move |w| plugin.finish(w)));
        self
    }

    /// Give every plugin, in build order, the status of the frame a resumed run starts from
    /// ([`SimPlugin::restore`]); call after [`Self::finish`].
    ///
    /// # Errors
    /// The first plugin's refusal, prefixed with its name.
    pub fn restore(&mut self, status: &serde_json::Value) -> Result<(), String> {
        for (plugin, name) in self.built.iter().zip(&self.plugin_names) {
            plugin
                .restore(&mut self.world, status)
                .map_err(|e| format!("plugin {name} cannot resume from the frame: {e}"))?;
        }
        Ok(())
    }

    /// Register force contribution `T` (summed into `NetForce` in registration order) and
    /// attach `T::default()` to every particle (entity with a `ParticleId`): to those that
    /// exist now and, through an observer, to those spawned later. A particle that already
    /// has a `T` keeps it. Registering a type twice is a no-op.
    ///
    /// Whether the pipeline consumes the contribution is checked by [`Self::finish`]: a
    /// contribution is a value computed once per step, and a pipeline that needs forces
    /// elsewhere (adaptive sub-steps, a minimiser) refuses it; register an
    /// [`ExternalForce`] kernel with [`Self::add_external_force`] instead.
    pub fn register_force<T: ForceContribution>(&mut self) -> &mut Self {
        let name = std::any::type_name::<T>();
        if self.forces.names.iter().any(|n| n == name) {
            return self;
        }
        self.forces.register::<T>(&mut self.schedule);
        let ids: Vec<Entity> = self
            .world
            .query_filtered::<Entity, With<ParticleId>>()
            .iter(&self.world)
            .collect();
        for e in ids {
            self.world.entity_mut(e).insert_if_new(T::default());
        }
        self.world
            .add_observer(|add: On<Add<ParticleId>>, mut commands: Commands| {
                commands.entity(add.entity).insert_if_new(T::default());
            });
        self
    }

    /// Register an external force kernel under `name` (kernels are summed in registration
    /// order). Every pipeline evaluates the kernels where it needs forces (see
    /// [`ExternalForce`]); the sum at the step start is also the built-in contribution
    /// `KernelForce`, part of `NetForce`. [`Self::finish`] fails if the pipeline cannot use
    /// kernels.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_plugins::app::SimApp;
    /// use magsep_systems::forces::{ExternalForce, ExternalForces, ParticleState};
    /// use std::sync::Arc;
    ///
    /// /// Uniform force along -z [N].
    /// struct Weight(f64);
    /// impl ExternalForce for Weight {
    ///     fn force_torque(&self, _p: &ParticleState) -> (DVec3, DVec3) {
    ///         (DVec3::new(0.0, 0.0, -self.0), DVec3::ZERO)
    ///     }
    /// }
    /// let mut app = SimApp::new();
    /// app.add_external_force("weight", Arc::new(Weight(1e-12)));
    /// assert_eq!(app.world.resource::<ExternalForces>().names(), ["weight"]);
    /// // no plugin consumes forces in this empty app: refused, not ignored
    /// assert!(app.finish().unwrap_err().0.contains("weight"));
    /// ```
    pub fn add_external_force(
        &mut self,
        name: impl Into<String>,
        kernel: Arc<dyn ExternalForce>,
    ) -> &mut Self {
        let first = self
            .world
            .get_resource::<ExternalForces>()
            .is_none_or(|k| k.is_empty());
        self.world
            .get_resource_or_init::<ExternalForces>()
            .push(name, kernel);
        if first {
            self.register_force::<KernelForce>();
            self.schedule
                .add_systems(compute_kernel_forces.in_set(ForceSystems::Custom));
        }
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

    /// (name, parameters) of the plugins built, in order (for the run's record).
    pub fn plugin_infos(&self) -> Vec<(String, serde_json::Value)> {
        self.plugin_names
            .iter()
            .cloned()
            .zip(self.plugin_params.iter().cloned())
            .collect()
    }

    /// Run every plugin's `finish` hook, check that the pipeline consumes every registered
    /// force (the integrator plugin declares a [`ForceUse`]), then build both schedules.
    /// Errors on forces that would be ignored, ambiguities (two systems with conflicting
    /// access and no order) and cycles.
    ///
    /// # Errors
    /// Refused forces (what, why, what to do instead), or the schedule build error of
    /// bevy_ecs, as text naming the systems involved.
    pub fn finish(&mut self) -> Result<(), ScheduleError> {
        for f in std::mem::take(&mut self.plugins) {
            f(&mut self.world);
        }
        self.check_force_use()?;
        self.world.insert_resource(self.forces.clone());
        if let Err(e) = self.schedule.initialize(&mut self.world) {
            return Err(ScheduleError(describe(&e, &self.schedule, &self.world)));
        }
        if let Err(e) = self.observe.initialize(&mut self.world) {
            return Err(ScheduleError(describe(&e, &self.observe, &self.world)));
        }
        Ok(())
    }

    /// The force check of [`Self::finish`]: nothing registered, or everything consumed.
    fn check_force_use(&self) -> Result<(), ScheduleError> {
        let kernels: Vec<&str> = self
            .world
            .get_resource::<ExternalForces>()
            .map(|k| k.names())
            .unwrap_or_default();
        if self.forces.names.is_empty() && kernels.is_empty() {
            return Ok(());
        }
        let default = ForceUse::default();
        let used = self.world.get_resource::<ForceUse>().unwrap_or(&default);
        used.check(&self.forces.names, &kernels)
            .map_err(ScheduleError)
    }

    /// Run the per-step schedule's systems one after the other (bevy's single-threaded
    /// executor); `in_pool`: each step on a thread of rayon's pool ([`Self::step`]). The
    /// systems' own parallel loops then run as nested jobs of that pool instead of being handed
    /// to it from outside, which costs two cross-thread wake-ups per loop (the system's thread
    /// blocks until the pool is done); entering the pool costs the same once per step, so it
    /// pays only for scenes whose steps run parallel loops (the `magsep` driver asks for it from
    /// 256 particles, where per-particle loops go parallel). Same results, bitwise, either way.
    /// Setting another executor on [`Self::schedule`] afterwards is the caller's business.
    pub fn set_single_threaded(&mut self, in_pool: bool) -> &mut Self {
        self.schedule
            .set_executor(bevy_ecs::schedule::SingleThreadedExecutor::new());
        self.in_pool = in_pool;
        self
    }

    /// Run one step of the simulation schedule (inside rayon's pool when
    /// [`Self::set_single_threaded`] asked for it).
    pub fn step(&mut self) {
        if self.in_pool {
            let (schedule, world) = (&mut self.schedule, &mut self.world);
            magsep_systems::par::in_rayon_pool(|| schedule.run(world));
        } else {
            self.schedule.run(&mut self.world);
        }
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
