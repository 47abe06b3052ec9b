//! ECS glue of hard-particle collisions (`Constraints`): gathers the particles in
//! `ParticleId` order into dense arrays, runs the event-driven [`CollisionEngine`] over the
//! step from the start-of-step positions with the new velocities, writes positions and
//! velocities back, and marks each collided particle's Basset history for a restart with
//! the jump v(t_c⁻) − v(t_c⁺) of its last collision (eq. 2.29; the thesis discards the
//! pre-collision history).

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;

use super::config::ParticleFluidConfig;
use super::systems::{FluidDomain, PendingHistoryReset, StepStart};
use crate::collision::{CollisionEngine, CollisionModel, InverseInertia, ParticleArrays};

/// What a collision does to the Basset history of the particles involved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CollisionHistory {
    /// The thesis (eq. 2.29, [T002 §2.2.4.1]): discard the pre-collision history and keep the collision's
    /// jump term `(v(t_c⁻) − v(t_c⁺))/√(t − t_c)`, at every collision, resting contacts
    /// included ("sustained contacts are sequences of collisions").
    #[default]
    Reset,
    /// Keep the whole history: the collision's velocity change enters the history integral
    /// like any other change of slip (the Basset-Boussinesq-Oseen equation through an
    /// impulsive force).
    Keep,
}

/// The collision model, the engine and the dense arrays (a resource).
#[derive(Resource, Debug, Clone, Default)]
pub struct CollisionWorkspace {
    /// Restitution, friction and rest speed.
    pub model: CollisionModel,
    /// What collisions do to the Basset history.
    pub history: CollisionHistory,
    /// The event-driven engine (keeps its buffers between steps).
    pub engine: CollisionEngine,
    /// Particle entities in `ParticleId` order (filled by [`init_collision_workspace`]).
    pub order: Vec<Entity>,
    positions: Vec<DVec3>,
    velocities: Vec<DVec3>,
    angular: Vec<DVec3>,
    radii: Vec<f64>,
    inv_mass: Vec<f64>,
    inv_inertia: Vec<f64>,
    densities: Vec<f64>,
}

impl CollisionWorkspace {
    /// A workspace for `model` and `history` (the engine with its default settings).
    pub fn new(model: CollisionModel, history: CollisionHistory) -> Self {
        Self {
            model,
            history,
            ..Default::default()
        }
    }
}

/// Fill the entity order of the workspace (after spawning).
pub fn init_collision_workspace(world: &mut World) {
    let mut rows: Vec<(ParticleId, Entity)> = world
        .query::<(&ParticleId, Entity)>()
        .iter(world)
        .map(|(id, e)| (*id, e))
        .collect();
    rows.sort_by_key(|r| r.0);
    if let Some(mut ws) = world.get_resource_mut::<CollisionWorkspace>() {
        ws.order = rows.into_iter().map(|r| r.1).collect();
    }
}

type CollideQuery<'w, 's> = Query<
    'w,
    's,
    (
        &'static StepStart,
        &'static Shape,
        &'static InertialBody,
        &'static mut Position,
        &'static mut Velocity,
        &'static mut AngularVelocity,
        &'static mut PendingHistoryReset,
    ),
>;

/// Resolve the step's collisions (`Constraints`).
pub fn resolve_collisions(
    cfg: Res<ParticleFluidConfig>,
    clock: Res<StepClock>,
    domain: Res<FluidDomain>,
    mut ws: ResMut<CollisionWorkspace>,
    mut stats: ResMut<ParticleFluidStats>,
    mut health: ResMut<Health>,
    mut q: CollideQuery,
) {
    let ws = &mut *ws;
    let n = ws.order.len();
    ws.positions.clear();
    ws.velocities.clear();
    ws.angular.clear();
    ws.radii.clear();
    ws.inv_mass.clear();
    ws.inv_inertia.clear();
    ws.densities.clear();
    for &e in &ws.order {
        let Ok((start, shape, body, _, v, w, _)) = q.get(e) else {
            continue;
        };
        ws.positions.push(start.0);
        ws.velocities.push(v.0);
        ws.angular.push(w.0);
        ws.radii.push(shape.radius());
        ws.inv_mass.push(1.0 / body.mass);
        ws.inv_inertia.push(1.0 / body.inertia.x);
        ws.densities.push(body.density);
    }
    if ws.positions.len() != n {
        health.report("collision step: a particle entity disappeared");
        return;
    }
    let arrays = ParticleArrays {
        positions: &mut ws.positions,
        velocities: &mut ws.velocities,
        angular_velocities: &mut ws.angular,
        radii: &ws.radii,
        inv_masses: &ws.inv_mass,
        inv_inertias: InverseInertia::Scalar(&ws.inv_inertia),
        densities: &ws.densities,
        spheroids: None,
    };
    let report = match ws.engine.step(arrays, &domain.0, &ws.model, cfg.dt) {
        Ok(r) => r,
        Err(e) => {
            health.report(format!("collision step failed: {e}"));
            return;
        }
    };
    let t_n = clock.time();
    // the end of this step, as the next step's history system computes it (step * dt)
    let t_end = (clock.step + 1) as f64 * clock.dt;
    for (k, &e) in ws.order.iter().enumerate() {
        let Ok((_, _, _, mut x, mut v, mut w, mut reset)) = q.get_mut(e) else {
            continue;
        };
        x.0 = ws.positions[k];
        v.0 = ws.velocities[k];
        w.0 = ws.angular[k];
        if ws.history == CollisionHistory::Keep {
            continue;
        }
        if let Some(c) = report.last_collision[k] {
            let t_c = (t_n + c.time).min(t_end);
            reset.0 = Some((t_c, c.velocity_before - c.velocity_after));
        }
    }
    let s = &report.stats;
    stats.particle_collisions += (s.events - s.wall_events) as u64;
    stats.wall_collisions += s.wall_events as u64;
    stats.sticking += s.stick as u64;
    stats.sliding += s.slide as u64;
    stats.resting += s.resting as u64;
    stats.capped_steps += u64::from(s.capped_particles > 0);
    stats.max_overlap = stats.max_overlap.max(s.max_overlap_after_projection);
}
