//! Thin ECS glue of the simulated liquid: the [`ChannelLiquid`] resource holds the solver, the
//! particles carry [`LiquidCoupling`]. Per step:
//!
//! 1. `Prepare`, [`sample_liquid`]: each particle samples the liquid with its filter (the
//!    filter average of u and ω; Du/Dt from the local time derivative plus the convective term
//!    from central differences of filter averages), minus its own disturbance when the
//!    self-induced correction is on, into `FluidSample`, which every force system reads.
//! 2. `Mobility`, [`remember_step_start_velocity`] before and [`compute_feedback`] after the
//!    velocity update: the hydrodynamic force the particle received over the step exactly as
//!    the integrator applied it (drag and history with their implicit parts, the undisturbed
//!    flow force, the added-mass reaction, optionally the lift) and the torque (pitching and
//!    rotational drag).
//! 3. `Integrate`, [`advance_liquid`]: the reactions are spread onto the grid (force: top-hat
//!    filter at the step-start position; torque: the eight-node couple) and the liquid
//!    advances one step with them.
//!
//! Gravity, hydrostatic and magnetic buoyancy are not fed back: they are balanced by the
//! reduced pressure (thesis eq. 2.38). The particle sequence of the spreading is the query's
//! (spawn) order on one thread, so the liquid is the same for every thread count.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;

use super::config::ChannelSpec;
use super::coupling::{FilterStencil, bounding_half_widths, spread_couple, torque_couple};
use super::grid::ChannelGrid;
use super::self_induced::self_mobility;
use super::stepper::ChannelSolver;
use crate::fluid::config::{Integrator, ParticleFluidConfig};
use crate::fluid::spheroid_systems::SpheroidFluid;
use crate::fluid::systems::StepStart;

/// The liquid (a resource): the solver and what the coupling keeps between steps.
#[derive(Resource)]
pub struct ChannelLiquid {
    /// The solver.
    pub solver: ChannelSolver,
    /// The scene's options.
    pub spec: ChannelSpec,
    /// z quadrature weights of the grid \[m\].
    pub z_weights: Vec<f64>,
    /// z levels of the grid \[m\].
    pub z_levels: Vec<f64>,
    /// The velocity field of the previous step (for ∂u/∂t) [m/s].
    pub previous: [Vec<f64>; 3],
    /// Total force the particles put into the liquid, averaged over the last liquid step \[N\].
    pub last_feedback: DVec3,
    /// Particle steps accumulated into the body force since the last liquid step (below
    /// `spec.step_every`).
    pub pending: u32,
    /// The force being accumulated for the next liquid step \[N\].
    accumulated: DVec3,
}

impl ChannelLiquid {
    /// The liquid at rest for `spec` on `grid`, with kinematic viscosity `nu` [m²/s], advanced
    /// every `spec.step_every` particle steps of `dt` \[s\].
    ///
    /// # Errors
    /// The solver's message when it rejects the parameters.
    pub fn new(spec: ChannelSpec, grid: ChannelGrid, nu: f64, dt: f64) -> Result<Self, String> {
        let params = super::solver::ChannelParams {
            grid,
            viscosity: nu,
            dt: dt * f64::from(spec.step_every.max(1)),
            dealias: spec.dealias,
            mean_pressure_gradient: [0.0; 2],
        };
        let solver = ChannelSolver::new(params).map_err(|e| e.to_string())?;
        Ok(Self::from_solver(spec, solver))
    }

    /// Wrap an existing solver (a restarted state).
    pub fn from_solver(spec: ChannelSpec, solver: ChannelSolver) -> Self {
        let grid = *solver.grid();
        let previous = solver.velocity().map(<[f64]>::to_vec);
        Self {
            z_weights: grid.z_quadrature_weights(),
            z_levels: grid.z_levels(),
            solver,
            spec,
            previous,
            last_feedback: DVec3::ZERO,
            pending: 0,
            accumulated: DVec3::ZERO,
        }
    }

    /// The grid.
    pub fn grid(&self) -> &ChannelGrid {
        self.solver.grid()
    }
}

/// What a particle exchanges with the liquid (a component).
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct LiquidCoupling {
    /// Filter half-widths \[m\] at the last sampling (the axis-aligned bounding box).
    pub half_widths: DVec3,
    /// Diagonal self-mobility of the filter [m/(N s)] (for the self-induced correction).
    pub mobility: DVec3,
    /// The z level the mobility was computed at (it depends on the local spacing).
    pub mobility_level: Option<usize>,
    /// Velocity at the start of the step [m/s].
    pub step_start_velocity: DVec3,
    /// Angular velocity at the start of the step [rad/s].
    pub step_start_spin: DVec3,
    /// The hydrodynamic force F_2w on the particle over the last step \[N\].
    pub force: DVec3,
    /// The hydrodynamic torque T_2w on the particle over the last step \[N m\].
    pub torque: DVec3,
}

/// Half-widths of a particle's filter box \[m\].
fn half_widths(body: &InertialBody, spheroid: Option<&SpheroidFluid>, o: &Orientation) -> DVec3 {
    match spheroid {
        Some(s) => bounding_half_widths(s.equatorial_radius, s.polar_radius, o.0),
        None => DVec3::splat(0.5 * body.diameter),
    }
}

/// The half-widths \[m\] of the box whose unbounded Stokes response the self-induced correction
/// subtracts: the filter box convolved with the grid's hat functions has the variance
/// `h²/3 + Δ²/6` per axis, which a box of half-width `sqrt(h² + Δ²/2)` matches (Δ the local
/// spacing; along z the gap to the next level).
fn effective_half(grid: &ChannelGrid, x: DVec3, half: DVec3) -> DVec3 {
    let k = grid.level_below(x.z).unwrap_or(0).min(grid.nz - 2);
    let dz = grid.z(k + 1) - grid.z(k);
    let d = DVec3::new(grid.dx(), grid.dy(), dz);
    (half * half + 0.5 * d * d).map(f64::sqrt)
}

/// Sample the liquid at each particle (`Prepare`).
#[allow(clippy::type_complexity)]
pub fn sample_liquid(
    cfg: Res<ParticleFluidConfig>,
    liquid: Res<ChannelLiquid>,
    mut q: Query<(
        &Position,
        &Orientation,
        &InertialBody,
        Option<&SpheroidFluid>,
        &mut LiquidCoupling,
        &mut FluidSample,
    )>,
) {
    let lq = &*liquid;
    let grid = lq.grid();
    let u = lq.solver.velocity();
    let w = lq.solver.vorticity();
    let prev = [
        &lq.previous[0][..],
        &lq.previous[1][..],
        &lq.previous[2][..],
    ];
    // the field changes once per liquid step
    let dt = lq.solver.params().dt;
    let mu = cfg.liquid.viscosity;
    let accel = cfg.terms.undisturbed_flow || cfg.terms.added_mass;
    let correct = lq.spec.self_induced_correction;
    q.par_iter_mut()
        .for_each(|(x, o, body, spheroid, mut c, mut sample)| {
            let half = half_widths(body, spheroid, o);
            let level = grid.level_below(x.0.z);
            if correct && (half != c.half_widths || level != c.mobility_level) {
                c.mobility = self_mobility(effective_half(grid, x.0, half), mu);
                c.mobility_level = level;
            }
            c.half_widths = half;
            let Some(st) = FilterStencil::new(grid, &lq.z_weights, &lq.z_levels, x.0, half) else {
                return;
            };
            let mut velocity = st.average3(u);
            let vorticity = st.average3(w);
            let mut acceleration = DVec3::ZERO;
            if accel {
                let dudt = (velocity - st.average3(prev)) / dt;
                // (u·∇)u from central differences of filter averages over ± half-widths
                let mut conv = DVec3::ZERO;
                for k in 0..3 {
                    let mut e = DVec3::ZERO;
                    e[k] = half[k];
                    let (Some(p), Some(m)) = (
                        FilterStencil::new(grid, &lq.z_weights, &lq.z_levels, x.0 + e, half),
                        FilterStencil::new(grid, &lq.z_weights, &lq.z_levels, x.0 - e, half),
                    ) else {
                        continue;
                    };
                    let grad = (p.average3(u) - m.average3(u)) / (2.0 * half[k]);
                    conv += velocity[k] * grad;
                }
                acceleration = dudt + conv;
            }
            if correct {
                // the liquid received −F_2w: its self-induced velocity is M·(−F_2w)
                velocity += c.mobility * c.force;
            }
            *sample = FluidSample {
                velocity,
                acceleration,
                vorticity,
            };
        });
}

/// Remember the step-start velocities (`Mobility`, before the velocity update).
pub fn remember_step_start_velocity(
    mut q: Query<(&Velocity, &AngularVelocity, &mut LiquidCoupling)>,
) {
    q.par_iter_mut().for_each(|(v, w, mut c)| {
        c.step_start_velocity = v.0;
        c.step_start_spin = w.0;
    });
}

/// The hydrodynamic force and torque each particle received over the step, as the
/// integrator applied them (`Mobility`, after the velocity update).
#[allow(clippy::type_complexity)]
pub fn compute_feedback(
    cfg: Res<ParticleFluidConfig>,
    liquid: Res<ChannelLiquid>,
    mut q: Query<(
        &Velocity,
        &AngularVelocity,
        &InertialBody,
        (Option<&DragForce>, Option<&LiftForce>),
        (Option<&UndisturbedFlowForce>, Option<&HistoryForce>),
        (Option<&RotationalDragTorque>, Option<&PitchingTorque>),
        &mut LiquidCoupling,
    )>,
) {
    let implicit = cfg.integrator == Integrator::Implicit;
    let dt = cfg.dt;
    let rho = cfg.liquid.density;
    let added = cfg.terms.added_mass;
    let lift_back = liquid.spec.feedback_lift;
    q.par_iter_mut().for_each(
        |(v, w, b, (drag, lift), (und, hist), (rot, pitch), mut c)| {
            let dv = v.0 - c.step_start_velocity;
            let mut f = DVec3::ZERO;
            if let Some(d) = drag {
                f += d.force
                    - if implicit {
                        d.stiffness * dv
                    } else {
                        DVec3::ZERO
                    };
            }
            if lift_back && let Some(l) = lift {
                f += l.0;
            }
            if let Some(u) = und {
                f += u.0;
            }
            if let Some(h) = hist {
                // the integrator already completed it with its newest-step part
                f += h.0;
            }
            if added {
                f -= 0.5 * rho * b.volume * dv / dt;
            }
            let mut t = DVec3::ZERO;
            if let Some(r) = rot {
                let dw = w.0 - c.step_start_spin;
                t += r.torque
                    - if implicit {
                        r.stiffness * dw
                    } else {
                        DVec3::ZERO
                    };
            }
            if let Some(p) = pitch {
                t += p.0;
            }
            c.force = f;
            c.torque = t;
        },
    );
}

/// Spread the reactions onto the grid and advance the liquid (`Integrate`): every particle
/// step adds its reactions, weighted `1/step_every`, to the body force; every `step_every`-th
/// step advances the liquid by one liquid step with their average.
pub fn advance_liquid(
    mut liquid: ResMut<ChannelLiquid>,
    cfg: Res<ParticleFluidConfig>,
    mut health: ResMut<Health>,
    q: Query<(&StepStart, &LiquidCoupling)>,
) {
    let lq = &mut *liquid;
    let grid = *lq.solver.grid();
    let rho = cfg.liquid.density;
    let torque = lq.spec.coupling.feeds_torque();
    let every = lq.spec.step_every.max(1);
    let weight = 1.0 / f64::from(every);
    let zw = &lq.z_weights;
    let zl = &lq.z_levels;
    {
        let [fx, fy, fz] = lq.solver.body_force_mut();
        if lq.pending == 0 {
            fx.fill(0.0);
            fy.fill(0.0);
            fz.fill(0.0);
            lq.accumulated = DVec3::ZERO;
        }
        let mut out = [fx, fy, fz];
        for (x0, c) in &q {
            let Some(st) = FilterStencil::new(&grid, zw, zl, x0.0, c.half_widths) else {
                continue;
            };
            st.spread(-c.force * weight, rho, &mut out);
            lq.accumulated -= c.force * weight;
            if torque
                && c.torque != DVec3::ZERO
                && let Some(corners) = torque_couple(&grid, x0.0, c.torque * weight)
            {
                spread_couple(&grid, zw, &corners, rho, &mut out);
            }
        }
    }
    lq.pending += 1;
    if lq.pending < every {
        return;
    }
    lq.pending = 0;
    lq.last_feedback = lq.accumulated;
    for (dst, src) in lq.previous.iter_mut().zip(lq.solver.velocity()) {
        dst.copy_from_slice(src);
    }
    lq.solver.step();
    let u = lq.solver.velocity();
    if u.iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        health.report(format!(
            "the liquid's velocity became non-finite at t = {} s (time step beyond the solver's \
             stability limit? CFL {:.3})",
            lq.solver.time(),
            lq.solver.cfl()
        ));
    }
}
