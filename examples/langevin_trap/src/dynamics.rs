//! Spawning, the exact Ornstein-Uhlenbeck step and the sampled statistics, as ECS systems.
//!
//! | plugin | set | system | touches |
//! |---|---|---|---|
//! | [`LangevinTrapPlugin`] | `Integrate` | [`ou_step`] | `Position`, `ParticleRng` |
//! | | `Observe` | [`sample_statistics`] | `TrapStats` |
//!
//! The overdamped Langevin equation γ dx = -k (x - x0) dt + sqrt(2 γ k_B T) dW is linear, so
//! its transition over Δt is known exactly (an Ornstein-Uhlenbeck process):
//!
//! x(t + Δt) = x0 + (x(t) - x0) e^{-k Δt/γ} + sqrt(k_B T / k (1 - e^{-2 k Δt/γ})) ξ,
//!
//! with ξ three independent standard normal numbers drawn from the particle's own stream
//! ([`ParticleRng`], seeded from (seed, [`ParticleId`])), so the trajectory of a particle
//! depends neither on the other particles nor on the thread count.

use magsep::bevy_ecs;
use magsep::bevy_ecs::prelude::*;
use magsep::components::prelude::*;
use magsep::glam::{DQuat, DVec3};
use magsep::plugins::app::{SimApp, SimPlugin};
use magsep::scene::{RecordEvery, Scene, SpawnError};
use magsep::systems::rng::particle_stream;
use magsep::systems::sets::SimSystems;
use rand_distr::{Distribution, StandardNormal};

use crate::scene::{TrapParams, TrapScene, friction};
use crate::summary::TrapStats;

/// The run parameters (a resource).
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct TrapConfig(pub TrapParams);

/// Per-particle coefficients of the exact step (a component): `decay` = e^{-k Δt/γ} and
/// `noise` = sqrt(k_B T / k (1 - decay²)) \[m\].
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct OuStep {
    /// Factor on the displacement from the centre over one step.
    pub decay: f64,
    /// Standard deviation of the random displacement per axis over one step \[m\].
    pub noise: f64,
}

impl OuStep {
    /// The coefficients for a sphere of friction `gamma` \[kg/s\] under `p`.
    pub fn new(p: &TrapParams, gamma: f64) -> Self {
        let decay = (-p.stiffness * p.dt / gamma).exp();
        // 1 - e^{-2x} without cancellation for small x
        let one_minus = -(-2.0 * p.stiffness * p.dt / gamma).exp_m1();
        Self {
            decay,
            noise: (p.variance() * one_minus).sqrt(),
        }
    }
}

/// Spawn the particles of `scene` (ids in file order, each with its own random stream) and
/// the resources the plugins need: [`TrapConfig`], [`TrapStats`], `StepClock`, `Container`.
///
/// # Errors
/// [`SpawnError::Other`] when the scene is not a `langevin_trap` scene.
pub fn spawn(scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
    let (Some(section), Some(params)) = (scene.section::<TrapScene>(), TrapParams::of_scene(scene))
    else {
        return Err(SpawnError::Other("not a langevin_trap scene".into()));
    };
    let viscosity = section.trap.viscosity;
    let mut id = 0u64;
    for (k, group) in scene.particles.iter().enumerate() {
        let shape = group.shape.shape();
        let start = section.starts.get(k).copied().unwrap_or(params.centre);
        let step = OuStep::new(&params, friction(viscosity, shape.radius()));
        let batch: Vec<_> = (0..group.count)
            .map(|i| {
                (
                    ParticleBundle {
                        id: ParticleId(id + i),
                        position: Position(start),
                        orientation: Orientation(DQuat::IDENTITY),
                        shape,
                        species: Species(k as u32),
                        rng: ParticleRng(particle_stream(seed, id + i)),
                        net_force: NetForce::default(),
                        net_torque: NetTorque::default(),
                    },
                    step,
                )
            })
            .collect();
        world.spawn_batch(batch);
        id += group.count;
    }
    world.insert_resource(TrapConfig(params));
    world.insert_resource(TrapStats::default());
    world.insert_resource(StepClock::new(params.dt));
    world.insert_resource(Container::Unbounded);
    Ok(())
}

/// Integrate: one exact Ornstein-Uhlenbeck step of every particle, in parallel (each particle
/// reads only its own state and stream).
pub fn ou_step(config: Res<TrapConfig>, mut q: Query<(&mut Position, &mut ParticleRng, &OuStep)>) {
    let centre = config.0.centre;
    q.par_iter_mut().for_each(|(mut pos, mut rng, c)| {
        let rng = &mut rng.0;
        let xi = DVec3::new(
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
        );
        pos.0 = centre + (pos.0 - centre) * c.decay + xi * c.noise;
    });
}

/// The particles' displacements from the centre `x - x0` \[m\], in `ParticleId` order (the
/// summation order of every statistic, here and in replay).
pub fn displacements(rows: &[(ParticleId, DVec3)], centre: DVec3) -> Vec<DVec3> {
    let mut rows = rows.to_vec();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|(_, x)| x - centre).collect()
}

/// Observe: after every sample step (see [`TrapParams::is_sample_step`]) add the particles'
/// displacements to [`TrapStats`].
pub fn sample_statistics(
    config: Res<TrapConfig>,
    clock: Res<StepClock>,
    mut stats: ResMut<TrapStats>,
    q: Query<(&ParticleId, &Position)>,
) {
    if !config.0.is_sample_step(clock.step) {
        return;
    }
    let rows: Vec<_> = q.iter().map(|(id, p)| (*id, p.0)).collect();
    stats.add_sample(&displacements(&rows, config.0.centre));
}

/// The step and the statistics. Needs [`TrapConfig`] (inserted by [`spawn`]); sets the
/// record interval (`RecordEvery`) to the sample interval, so that every sample is a
/// recorded frame and replay recomputes the statistics exactly.
#[derive(Debug, Clone, Copy, Default)]
pub struct LangevinTrapPlugin;

impl SimPlugin for LangevinTrapPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<TrapStats>();
        if let Some(c) = app.world.get_resource::<TrapConfig>().copied() {
            // the driver inserted `[record] every` (or 100) after spawning: use ours
            app.world.insert_resource(RecordEvery(c.0.sample_every));
        }
        app.schedule.add_systems((
            ou_step.in_set(SimSystems::Integrate),
            sample_statistics.in_set(SimSystems::Observe),
        ));
    }
}
