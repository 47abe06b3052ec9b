//! Thin ECS glue of the particle-fluid pipeline: each system reads components, calls the
//! kernels of [`crate::fluid`] and writes its own contribution (docs/architecture.md §2, schedule).
//!
//! Vertical is z (the thesis's y): gravity −g e_z, the magnet model's y = z − `mid_plane`.
//!
//! Per step: `Prepare` samples the flow; `Forces` write `GravityForce`, `BuoyancyForce`,
//! `MagneticBuoyancyForce` (set `Field`) and `DragForce`, `UndisturbedFlowForce`,
//! `HistoryForce`, `RotationalDragTorque` (set `Fluid`); `Accumulate` sums them; `Mobility`
//! advances velocities (linearly implicit or explicit Euler, [`super::motion`]);
//! `Integrate` moves positions and orientations; `Constraints` resolves collisions
//! ([`super::collide`]); `Finalize` wraps periodic axes and updates the levitation
//! bookkeeping. The Basset history is advanced at the start of the next step's history
//! system, from the slip sampled then (a collision in between resets it, eq. 2.29).

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::prelude::*;

use super::config::{Integrator, ParticleFluidConfig};
use super::drag::{rotational_drag, translational_drag};
use super::history::{HistoryPlan, HistoryState, basset_coefficient};
use super::motion::{effective_mass, rotate, velocity_step};
use super::rigid::angular_velocity_step;
use super::spheroid_systems::SpheroidFluid;
use crate::collision::CollisionDomain;

/// The Basset history plan shared by all particles (a resource).
#[derive(Resource, Debug, Clone)]
pub struct BassetPlan(pub HistoryPlan);

/// The domain's periodic axes and walls (a resource), for collisions and wrapping.
#[derive(Resource, Debug, Clone)]
pub struct FluidDomain(pub CollisionDomain);

/// A particle's Basset history (window, tail and last step change).
#[derive(Component, Debug, Clone)]
pub struct BassetHistory(pub HistoryState);

/// A collision during the last step that the history must restart from: (absolute time
/// t_c \[s\], jump v(t_c⁻) − v(t_c⁺) [m/s]).
#[derive(Component, Debug, Clone, Copy, Default)]
pub struct PendingHistoryReset(pub Option<(f64, DVec3)>);

/// Position at the start of the step \[m\] (the collision step re-advances from it).
#[derive(Component, Debug, Clone, Copy, Default)]
pub struct StepStart(pub DVec3);

/// Orientation at the start of the step (the collision step re-rotates non-spherical
/// particles from it).
#[derive(Component, Debug, Clone, Copy, Default)]
pub struct StepStartOrientation(pub DQuat);

/// Whether the flow needs sampling (run condition).
pub fn flow_is_not_quiescent(cfg: Res<ParticleFluidConfig>) -> bool {
    !cfg.flow.is_quiescent()
}

/// Sample the undisturbed flow at each particle (`Prepare`).
pub fn sample_fluid(
    cfg: Res<ParticleFluidConfig>,
    clock: Res<StepClock>,
    mut q: Query<(&Position, &mut FluidSample)>,
) {
    let t = clock.time();
    crate::par_for_each_mut!(q, |(x, mut s)| {
        *s = cfg.flow.sample(x.0, t);
    });
}

/// Weight and hydrostatic buoyancy (`Forces::Field`).
pub fn compute_body_forces(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<(&InertialBody, &mut GravityForce, &mut BuoyancyForce)>,
) {
    let g = cfg.gravity;
    let (on_g, on_b) = (cfg.terms.gravity, cfg.terms.buoyancy);
    let rho_f = cfg.liquid.density;
    crate::par_for_each_mut!(q, |(b, mut fg, mut fb)| {
        if on_g {
            fg.0 = DVec3::new(0.0, 0.0, -b.mass * g);
        }
        if on_b {
            fb.0 = DVec3::new(0.0, 0.0, rho_f * b.volume * g);
        }
    });
}

/// Magnetic buoyancy −μ₀ V χ H dH/dy e_z (`Forces::Field`).
pub fn compute_magnetic_buoyancy(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<(&Position, &InertialBody, &mut MagneticBuoyancyForce)>,
) {
    let chi = cfg.liquid.susceptibility;
    crate::par_for_each_mut!(q, |(x, b, mut f)| {
        let fz = cfg
            .magnet
            .magnetic_buoyancy(chi, b.volume, cfg.magnet_y(x.0.z));
        f.0 = DVec3::new(0.0, 0.0, fz);
    });
}

/// Steady drag at the start-of-step velocity, with its stiffness (`Forces::Fluid`).
pub fn compute_drag(
    cfg: Res<ParticleFluidConfig>,
    mut stats: ResMut<ParticleFluidStats>,
    mut q: Query<(&Velocity, &FluidSample, &InertialBody, &mut DragForce), Without<SpheroidFluid>>,
) {
    let (rho, mu, law) = (cfg.liquid.density, cfg.liquid.viscosity, cfg.drag_law);
    let mut re_max = stats.max_reynolds;
    for (v, s, b, mut d) in &mut q {
        let (f, k, re) = translational_drag(law, rho, mu, b.diameter, s.velocity - v.0);
        d.force = f;
        d.stiffness = k;
        re_max = re_max.max(re);
    }
    stats.max_reynolds = re_max;
}

/// Undisturbed-flow force and the fluid part of the added mass (`Forces::Fluid`).
pub fn compute_undisturbed_flow(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<(&FluidSample, &InertialBody, &mut UndisturbedFlowForce)>,
) {
    let rho = cfg.liquid.density;
    let factor = f64::from(u8::from(cfg.terms.undisturbed_flow))
        + 0.5 * f64::from(u8::from(cfg.terms.added_mass));
    crate::par_for_each_mut!(q, |(s, b, mut f)| {
        f.0 = factor * rho * b.volume * s.acceleration;
    });
}

/// Advance each history by the slip of the step just finished (or restart it after a
/// collision), then write the history force: the completed steps seen from t_{n+1}
/// (implicit) or from t_n (explicit) (`Forces::Fluid`).
#[allow(clippy::type_complexity)]
pub fn compute_history(
    cfg: Res<ParticleFluidConfig>,
    plan: Res<BassetPlan>,
    clock: Res<StepClock>,
    mut q: Query<(
        &Velocity,
        &FluidSample,
        &InertialBody,
        &mut BassetHistory,
        &mut PendingHistoryReset,
        &mut HistoryForce,
    )>,
) {
    let plan = &plan.0;
    let t_n = clock.time();
    let t_next = t_n + plan.dt();
    let implicit = cfg.integrator == Integrator::Implicit;
    let (rho, mu) = (cfg.liquid.density, cfg.liquid.viscosity);
    // a history window costs ~1 µs per particle: parallel from a few dozen particles on
    crate::par_for_each_mut!(q, 32, |(v, s, b, mut h, mut reset, mut f)| {
        let slip = s.velocity - v.0;
        if let Some((t_c, jump)) = reset.0.take() {
            h.0.reset_at_collision(plan, t_c, jump, slip, t_n);
        } else if h.0.time(plan) < t_n - 0.5 * plan.dt() {
            h.0.push(plan, slip);
        }
        let c_h = basset_coefficient(b.diameter, rho, mu);
        let integral = if implicit {
            h.0.past_integral(plan, t_next)
        } else {
            h.0.current_integral(plan, t_n)
        };
        f.0 = c_h * integral;
    });
}

/// Rotational drag of spheres with its stiffness (`Forces::Fluid`).
pub fn compute_rotational_drag(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<
        (
            &AngularVelocity,
            &FluidSample,
            &InertialBody,
            &mut RotationalDragTorque,
        ),
        Without<SpheroidFluid>,
    >,
) {
    let (rho, mu) = (cfg.liquid.density, cfg.liquid.viscosity);
    crate::par_for_each_mut!(q, |(w, s, b, mut t)| {
        let (torque, k, _) = rotational_drag(rho, mu, b.diameter, 0.5 * s.vorticity - w.0);
        t.torque = torque;
        t.stiffness = k;
    });
}

/// Advance velocities and angular velocities (`Mobility`): linearly implicit Euler with the
/// drag, added mass and newest history weight implicit, or forward Euler; spheroids rotate by
/// Euler's equations ([`super::rigid`]). With the implicit
/// scheme the history force is completed with its newest-step part.
#[allow(clippy::type_complexity)]
pub fn update_velocities(
    cfg: Res<ParticleFluidConfig>,
    plan: Option<Res<BassetPlan>>,
    mut health: ResMut<Health>,
    mut q: Query<(
        &ParticleId,
        &NetForce,
        &NetTorque,
        &InertialBody,
        Option<&DragForce>,
        Option<&RotationalDragTorque>,
        &mut Velocity,
        &mut AngularVelocity,
        Option<&mut HistoryForce>,
        (&Orientation, Has<SpheroidFluid>),
    )>,
) {
    let dt = cfg.dt;
    let implicit = cfg.integrator == Integrator::Implicit;
    let history_weight = plan.as_ref().map(|p| p.0.newest_weight()).unwrap_or(0.0);
    let (rho, mu) = (cfg.liquid.density, cfg.liquid.viscosity);
    let added = cfg.terms.added_mass;
    let spin = cfg.spheroids.spin;
    // non-finite velocities: counted, the first one named (one message, not one per particle)
    let mut failed: (usize, Option<u64>) = (0, None);
    for (id, f, t, b, drag, rot, mut v, mut w, hist, (o, spheroid)) in &mut q {
        let mass = effective_mass(b.mass, b.volume, rho, added);
        let mut stiffness = 0.0;
        let mut history_stiffness = 0.0;
        if implicit {
            stiffness += drag.map(|d| d.stiffness).unwrap_or(0.0);
            if hist.is_some() {
                history_stiffness = basset_coefficient(b.diameter, rho, mu) * history_weight;
                stiffness += history_stiffness;
            }
        }
        let v_new = velocity_step(v.0, f.0, mass, stiffness, dt);
        if let Some(mut h) = hist {
            h.0 -= history_stiffness * (v_new - v.0);
        }
        let k_rot = if implicit {
            rot.map(|r| r.stiffness).unwrap_or(0.0)
        } else {
            0.0
        };
        let w_new = if spheroid {
            angular_velocity_step(w.0, t.0, o.0, b.inertia, k_rot, dt, spin)
        } else {
            velocity_step(w.0, t.0, b.inertia.x, k_rot, dt)
        };
        if !(v_new.is_finite() && w_new.is_finite()) {
            failed.0 += 1;
            failed.1.get_or_insert(id.0);
            continue;
        }
        v.0 = v_new;
        w.0 = w_new;
    }
    if let (n, Some(first)) = failed {
        health.report(format!(
            "non-finite velocity of {n} particle(s), the first particle {first} (time step too \
             large for the explicit scheme, or an unstable coupling to the solved liquid?)"
        ));
    }
}

/// Move positions with the new velocities and rotate orientations (`Integrate`).
pub fn integrate_positions(
    cfg: Res<ParticleFluidConfig>,
    mut q: Query<(
        &Velocity,
        &AngularVelocity,
        &mut Position,
        &mut Orientation,
        &mut StepStart,
        &mut StepStartOrientation,
    )>,
) {
    let dt = cfg.dt;
    crate::par_for_each_mut!(q, |(v, w, mut x, mut o, mut s, mut so)| {
        s.0 = x.0;
        so.0 = o.0;
        x.0 += dt * v.0;
        o.0 = rotate(o.0, w.0, dt);
    });
}

/// Wrap positions into the periodic cell (`Finalize::WriteBack`).
pub fn wrap_periodic(domain: Res<FluidDomain>, mut q: Query<&mut Position>) {
    if domain.0.periodic.iter().all(Option::is_none) {
        return;
    }
    crate::par_for_each_mut!(q, |mut x| {
        x.0 = domain.0.wrap(x.0);
    });
}

/// Track the last time each particle was outside the levitation band (`Finalize::Flags`).
pub fn track_levitation(
    cfg: Res<ParticleFluidConfig>,
    clock: Res<StepClock>,
    mut q: Query<(&Position, &mut Levitation)>,
) {
    let t_end = clock.time() + cfg.dt;
    let tol = cfg.levitation_tolerance;
    crate::par_for_each_mut!(q, |(x, mut l)| {
        let gap = (x.0.z - l.equilibrium_height).abs();
        if gap.is_nan() || gap > tol {
            l.last_outside = t_end;
        }
    });
}
