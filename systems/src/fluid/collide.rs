//! ECS glue of hard-particle collisions (`Constraints`): gathers the particles in
//! `ParticleId` order into dense arrays, runs the event-driven [`CollisionEngine`] over the
//! step from the start-of-step positions with the new velocities, writes positions and
//! velocities back, and marks each collided particle's Basset history for a restart with
//! the jump v(t_c⁻) − v(t_c⁺) of its last collision (eq. 2.29; the thesis discards the
//! pre-collision history).
//!
//! Spheroids (thesis 002, ch. 4): if any particle has [`Shape::Spheroid`], the engine gets every
//! particle's semi-axes (other shapes enter as spheres of [`Shape::radius`], as without
//! spheroids), the start-of-step orientations from `StepStartOrientation` (the integrator has
//! already rotated `Orientation` to the end of the step; the engine re-rotates from the start with
//! the post-collision angular velocities and `Orientation` is overwritten with its result), and
//! the body-frame inverse principal moments `(1/I_x, 1/I_y, 1/I_z)` of `InertialBody::inertia`,
//! with `1/I_z = 0` for spheroids: collisions do not change the spin about the symmetry axis
//! (`I_z → ∞`, as the thesis suppresses that spin). Without spheroids the sphere-only path
//! (isotropic inverse inertia `1/I_x`, no shapes) runs unchanged.
//!
//! The engine's [`EngineConfig::resting_floor`](crate::collision::engine::EngineConfig) is set
//! to `|g| Δt` when gravity acts (0 otherwise): approaches at resting contacts slower than what
//! gravity adds in one step are left to the resting solve instead of the event loop.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::prelude::*;

use super::config::ParticleFluidConfig;
use super::systems::{FluidDomain, PendingHistoryReset, StepStart, StepStartOrientation};
use crate::collision::spheroid::Spheroid;
use crate::collision::{
    CollisionEngine, CollisionModel, InverseInertia, ParticleArrays, SpheroidArrays,
};

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
    shapes: Vec<Spheroid>,
    orientations: Vec<DQuat>,
    inv_principal: Vec<DVec3>,
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
        &'static StepStartOrientation,
        &'static Shape,
        &'static InertialBody,
        &'static mut Position,
        &'static mut Orientation,
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
    ws.shapes.clear();
    ws.orientations.clear();
    ws.inv_principal.clear();
    let mut any_spheroid = false;
    for &e in &ws.order {
        let Ok((start, start_q, shape, body, _, _, v, w, _)) = q.get(e) else {
            continue;
        };
        let spheroid = match *shape {
            Shape::Spheroid {
                equatorial_radius,
                polar_radius,
            } => {
                any_spheroid = true;
                Spheroid::new(equatorial_radius, polar_radius)
            }
            _ => Spheroid::sphere(shape.radius()),
        };
        let inv = body.inertia.recip();
        let axial = if shape.is_spheroid() { 0.0 } else { inv.z };
        ws.shapes.push(spheroid);
        ws.orientations.push(start_q.0);
        ws.inv_principal.push(DVec3::new(inv.x, inv.y, axial));
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
    let (inv_inertias, spheroids) = if any_spheroid {
        (
            InverseInertia::Principal(&ws.inv_principal),
            Some(SpheroidArrays {
                shapes: &ws.shapes,
                orientations: &mut ws.orientations,
            }),
        )
    } else {
        (InverseInertia::Scalar(&ws.inv_inertia), None)
    };
    let arrays = ParticleArrays {
        positions: &mut ws.positions,
        velocities: &mut ws.velocities,
        angular_velocities: &mut ws.angular,
        radii: &ws.radii,
        inv_masses: &ws.inv_mass,
        inv_inertias,
        densities: &ws.densities,
        spheroids,
    };
    // approaches at resting contacts slower than what gravity adds in a step are left to the
    // resting solve (`EngineConfig::resting_floor`)
    let floor = if cfg.terms.gravity {
        cfg.gravity.abs() * cfg.dt
    } else {
        0.0
    };
    if ws.engine.config().resting_floor != floor {
        let mut c = *ws.engine.config();
        c.resting_floor = floor;
        ws.engine.set_config(c);
    }
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
        let Ok((_, _, _, _, mut x, mut o, mut v, mut w, mut reset)) = q.get_mut(e) else {
            continue;
        };
        x.0 = ws.positions[k];
        if any_spheroid {
            o.0 = ws.orientations[k];
        }
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
    stats.resting_contacts += s.resting_contacts as u64;
    stats.capped_steps += u64::from(s.capped_particles > 0);
    stats.max_overlap = stats.max_overlap.max(s.max_overlap_after_projection);
}

#[cfg(test)]
mod tests;
