//! Thin ECS glue of the `brownian` pipeline: gather particles into the dense
//! [`BrownianWorkspace`], write the three force contributions, prepare the mobility, run the
//! stepper, write back, sample the capture curve.
//!
//! | set | system | reads | writes |
//! |---|---|---|---|
//! | `Prepare` | [`prepare_brownian_step`] | | `BrownianWorkspace` (moments, lists, the three forces) |
//! | `Forces::Field` | [`compute_field_forces`] | `BrownianWorkspace` | `FieldForce`, `MagneticMoment` |
//! | `Forces::Dipole` | [`compute_dipole_forces`] | `BrownianWorkspace` | `DipoleForce` |
//! | `Forces::Contact` | [`compute_contact_forces`] | `BrownianWorkspace` | `ContactForce` |
//! | `Mobility` | [`prepare_mobility`] | `BrownianConfig` | `BrownianWorkspace`, `BrownianStats` |
//! | `Integrate` | [`integrate_brownian`] | forces, `StepClock` | `BrownianWorkspace`, `BrownianStats`, `Health` |
//! | `Finalize::WriteBack` | [`write_back_brownian`] | `BrownianWorkspace` | `Position`, `Captured`, `ParticleRng` |
//! | `Observe` | [`observe_capture`] | `BrownianWorkspace` | `CaptureCurve` |
//!
//! **Where the forces live.** The workspace holds every force of the step start; the three
//! `Forces` systems only copy them to the components, and the integrator reads `NetForce`.
//! With [`ForceComponents::WorkspaceOnly`] and no contribution registered besides the three
//! (no user `ForceContribution`, no kernel), nothing outside the pipeline needs them: the copies,
//! the generic contribution passes and the read of `NetForce` are skipped
//! ([`force_components_written`]), and the integrator sums the workspace's forces in the
//! order of the accumulation, so the trajectory is bitwise the same either way (tested in
//! `tests/it/brownian_pipeline.rs`). Positions, capture flags and random streams are
//! written back at every step.
//!
//! **Threads.** The numerical kernels run on the rayon pool, the fixed step's phases over one
//! split of the particles ([`super::parts`]); the write-back too when the particles fill one
//! table, the other component passes on the system's thread ([`super::passes`]). Every kernel
//! writes each particle's own value, so the
//! trajectory is bitwise the same for any thread count (tested in
//! `tests/it/brownian_pipeline.rs`).

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::dynamics::{HydroState, PipelineDynamics};
use super::fibre_flow::{FibreFlow, FlowFibre};
use super::hydro::{Mobility, MobilityMethod, MobilityOptions, auto_method};
use super::model::{ForceModel, PairLists, ParticleView};
use super::pair::Mie;
use super::stepper::advance;
use super::stepper::multirate::advance_multirate;
use crate::field::CylinderSource;
use crate::forces::{ExternalForces, ForceComponents, ForceRegistry};

use super::parts::part_bounds;
use super::passes::{
    PositionRows, StreamRows, in_workspace_order, write_back_in_parts, write_dense,
};
use magsep_components::forces::KernelForce;

/// Dense state of the run in `ParticleId` order (a resource; authoritative during a run, copied
/// to the components every step).
#[derive(Resource)]
pub struct BrownianWorkspace {
    /// Entities in `ParticleId` order.
    pub entities: Vec<Entity>,
    /// Centres \[m\].
    pub positions: Vec<DVec3>,
    /// Radii \[m\].
    pub radii: Vec<f64>,
    /// `ParticleId`s.
    pub ids: Vec<u64>,
    /// Shapes \[m\] (what external force kernels see).
    pub shapes: Vec<Shape>,
    /// Moment laws.
    pub laws: Vec<MomentModel>,
    /// Capture state.
    pub captured: Vec<Option<CaptureEvent>>,
    /// Random streams.
    pub rngs: Vec<Xoshiro256PlusPlus>,
    /// Fibres, field and interactions.
    pub model: ForceModel,
    /// Moments at the step start [A m²].
    pub moments: Vec<DVec3>,
    /// Field forces at the step start \[N\].
    pub field: Vec<DVec3>,
    /// Dipole-dipole forces at the step start \[N\].
    pub dipole: Vec<DVec3>,
    /// Contact forces at the step start \[N\].
    pub contact: Vec<DVec3>,
    /// Neighbour lists of the pair forces (cached across steps).
    pub lists: PairLists,
    /// Mobility of this step (None: free draining).
    pub hydro: Option<HydroState>,
    /// Resolved mobility method.
    pub method: MobilityMethod,
    /// The liquid's flow around the fibres (`BrownianConfig::flow_around_fibres` with a flow).
    pub flow_field: Option<FibreFlow>,
}

impl BrownianWorkspace {
    /// Free particles.
    pub fn mobile(&self) -> Vec<bool> {
        self.captured.iter().map(Option::is_none).collect()
    }

    /// Particles exerting pair forces.
    pub fn exerts(&self, config: &BrownianConfig) -> Vec<bool> {
        self.captured
            .iter()
            .map(|c| c.is_none() || config.captured_interact)
            .collect()
    }

    /// Number of captured particles.
    pub fn captured_count(&self) -> u64 {
        self.captured.iter().filter(|c| c.is_some()).count() as u64
    }
}

/// The force model of a configuration and fibre list.
pub fn force_model(config: &BrownianConfig, fibres: &[Fibre], field: &ExternalField) -> ForceModel {
    let kt = config.kt();
    ForceModel {
        sources: fibres
            .iter()
            .map(|f| {
                CylinderSource::new(f.center, f.axis, f.radius, f.half_length, f.magnetisation)
            })
            .collect(),
        b_ext: field.flux_density,
        tolerance: field.tolerance,
        kt,
        mie: match config.contact {
            ContactModel::Mie { epsilon_kt, n, m } => Some(Mie::new(epsilon_kt * kt, n, m)),
            _ => None,
        },
        dipole_cutoff: config.dipole_cutoff,
        field_patch: config.field_patch,
    }
}

/// Volume fraction of the particles in their bounding box (for the `auto` mobility rule).
fn bounding_volume_fraction(x: &[DVec3], radii: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (p, a) in x.iter().zip(radii) {
        lo = lo.min(*p - DVec3::splat(*a));
        hi = hi.max(*p + DVec3::splat(*a));
    }
    let v: f64 = radii
        .iter()
        .map(|a| 4.0 / 3.0 * std::f64::consts::PI * a.powi(3))
        .sum();
    (v / (hi - lo).element_product()).min(1.0)
}

/// Gather the spawned particles into a [`BrownianWorkspace`] (plugin `finish` hook).
/// Requires `BrownianConfig` and `ExternalField`.
pub fn init_brownian_workspace(world: &mut World) {
    let config = world.resource::<BrownianConfig>().clone();
    let field = *world.resource::<ExternalField>();
    let mut fibres: Vec<(FibreId, Fibre)> = world
        .query::<(&FibreId, &Fibre)>()
        .iter(world)
        .map(|(i, f)| (*i, *f))
        .collect();
    fibres.sort_by_key(|f| f.0);
    let fibres: Vec<Fibre> = fibres.into_iter().map(|f| f.1).collect();
    type Row<'a> = (
        Entity,
        &'a ParticleId,
        &'a Position,
        &'a Shape,
        Option<&'a MomentModel>,
        Option<&'a Captured>,
        &'a ParticleRng,
    );
    let mut rows: Vec<_> = world
        .query::<Row>()
        .iter(world)
        .map(|(e, id, p, s, m, c, r)| {
            (
                *id,
                e,
                p.0,
                s.radius(),
                m.copied().unwrap_or_default(),
                c.and_then(|c| c.0),
                r.0.clone(),
                *s,
            )
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    let positions: Vec<DVec3> = rows.iter().map(|r| r.2).collect();
    let radii: Vec<f64> = rows.iter().map(|r| r.3).collect();
    let n_free = rows.iter().filter(|r| r.5.is_none()).count();
    let (method, reason) = match config.mobility {
        MobilityChoice::Auto => auto_method(n_free, bounding_volume_fraction(&positions, &radii)),
        MobilityChoice::FreeDraining => (MobilityMethod::FreeDraining, "chosen in the scene"),
        MobilityChoice::Cholesky => (MobilityMethod::Cholesky, "chosen in the scene"),
        MobilityChoice::Tea => (MobilityMethod::Tea, "chosen in the scene"),
        MobilityChoice::Krylov => (MobilityMethod::Krylov, "chosen in the scene"),
        MobilityChoice::SpectralEwald => (MobilityMethod::SpectralEwald, "chosen in the scene"),
    };
    let mut stats = world
        .get_resource::<BrownianStats>()
        .cloned()
        .unwrap_or_default();
    stats.mobility = serde_json::to_value(method)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    stats.mobility_reason = reason.to_string();
    world.insert_resource(stats);
    let entities: Vec<Entity> = rows.iter().map(|r| r.1).collect();
    world.insert_resource(BrownianWorkspace {
        entities,
        ids: rows.iter().map(|r| r.0.0).collect(),
        shapes: rows.iter().map(|r| r.7).collect(),
        moments: vec![DVec3::ZERO; rows.len()],
        field: vec![DVec3::ZERO; rows.len()],
        dipole: vec![DVec3::ZERO; rows.len()],
        contact: vec![DVec3::ZERO; rows.len()],
        laws: rows.iter().map(|r| r.4).collect(),
        captured: rows.iter().map(|r| r.5).collect(),
        rngs: rows.iter().map(|r| r.6.clone()).collect(),
        positions,
        radii,
        model: force_model(&config, &fibres, &field),
        lists: PairLists::default(),
        hydro: None,
        method,
        flow_field: (config.flow_around_fibres && config.flow != [0.0; 3]).then(|| {
            FibreFlow::new(
                fibres
                    .iter()
                    .map(|f| FlowFibre {
                        center: f.center,
                        axis: f.axis,
                        radius: f.radius,
                        half_length: f.half_length,
                    })
                    .collect(),
            )
        }),
    });
    let step = world
        .get_resource::<StepClock>()
        .map(|c| c.step)
        .unwrap_or(0);
    let captured = world.resource::<BrownianWorkspace>().captured_count();
    let mut curve = world.get_resource_or_init::<CaptureCurve>();
    if curve.samples.is_empty() {
        curve.samples.push((step, captured));
    }
}

/// Whether the force components and `NetForce` are kept up to date this step (a run
/// condition of the component passes, see the module header): unless
/// [`ForceComponents::WorkspaceOnly`] was asked for and the registry holds only the
/// pipeline's own three contributions.
pub fn force_components_written(
    wanted: Option<Res<ForceComponents>>,
    registry: Option<Res<ForceRegistry>>,
) -> bool {
    let own = [
        std::any::type_name::<FieldForce>(),
        std::any::type_name::<DipoleForce>(),
        std::any::type_name::<ContactForce>(),
    ];
    wanted.is_none_or(|w| *w == ForceComponents::EveryStep)
        || registry.is_some_and(|r| r.names.iter().any(|n| !own.contains(&n.as_str())))
}

/// Moments, field forces (one field evaluation per particle), the neighbour lists and the
/// pair forces at the step start.
pub fn prepare_brownian_step(
    mut ws: ResMut<BrownianWorkspace>,
    config: Res<BrownianConfig>,
    mut stats: ResMut<BrownianStats>,
) {
    let ws = &mut *ws;
    let mobile = ws.mobile();
    let exerts = ws.exerts(&config);
    let view = ParticleView {
        radii: &ws.radii,
        moments: &ws.laws,
        mobile: &mobile,
        exerts: &exerts,
    };
    let n = ws.positions.len();
    let (mut m, mut f) = (
        std::mem::take(&mut ws.moments),
        std::mem::take(&mut ws.field),
    );
    m.resize(n, DVec3::ZERO);
    f.resize(n, DVec3::ZERO);
    stats.neighbour_list_builds +=
        ws.model
            .prepare_step(&ws.positions, &view, &mut ws.lists, &mut m, &mut f);
    (ws.moments, ws.field) = (m, f);
    let (mut d, mut c) = (
        std::mem::take(&mut ws.dipole),
        std::mem::take(&mut ws.contact),
    );
    d.resize(n, DVec3::ZERO);
    c.resize(n, DVec3::ZERO);
    ws.model.pair_forces(
        &ws.positions,
        &ws.moments,
        &view,
        &ws.lists,
        (&mut d, &mut c),
    );
    (ws.dipole, ws.contact) = (d, c);
}

/// Field forces and moments (computed in `Prepare` with the moments the dipole forces need).
pub fn compute_field_forces(
    ws: Res<BrownianWorkspace>,
    mut forces: Query<(Entity, &mut FieldForce)>,
    mut moments: Query<(Entity, &mut MagneticMoment)>,
) {
    write_dense(&ws.entities, &ws.field, &mut forces, |c, v| c.0 = v);
    write_dense(&ws.entities, &ws.moments, &mut moments, |c, v| c.0 = v);
}

/// Dipole-dipole forces (computed in `Prepare`).
pub fn compute_dipole_forces(
    ws: Res<BrownianWorkspace>,
    mut forces: Query<(Entity, &mut DipoleForce)>,
) {
    write_dense(&ws.entities, &ws.dipole, &mut forces, |c, v| c.0 = v);
}

/// Mie contact forces (computed in `Prepare`).
pub fn compute_contact_forces(
    ws: Res<BrownianWorkspace>,
    mut forces: Query<(Entity, &mut ContactForce)>,
) {
    write_dense(&ws.entities, &ws.contact, &mut forces, |c, v| c.0 = v);
}

/// Build this step's mobility over the free particles (nothing for free draining).
pub fn prepare_mobility(
    mut ws: ResMut<BrownianWorkspace>,
    config: Res<BrownianConfig>,
    mut stats: ResMut<BrownianStats>,
    mut health: ResMut<Health>,
) {
    let ws = &mut *ws;
    ws.hydro = None;
    if ws.method == MobilityMethod::FreeDraining {
        return;
    }
    let rows: Vec<usize> = (0..ws.positions.len())
        .filter(|&i| ws.captured[i].is_none())
        .collect();
    if rows.is_empty() {
        return;
    }
    let x: Vec<DVec3> = rows.iter().map(|&i| ws.positions[i]).collect();
    let a: Vec<f64> = rows.iter().map(|&i| ws.radii[i]).collect();
    let options = MobilityOptions {
        krylov_tolerance: config.krylov_tolerance,
        ewald_tolerance: config.ewald_tolerance,
        ..MobilityOptions::default()
    };
    match Mobility::new_with(ws.method, &x, &a, config.viscosity, options) {
        Ok(mobility) => {
            stats.krylov_iterations += mobility.krylov_iterations() as u64;
            ws.hydro = Some(HydroState { mobility, rows });
        }
        Err(e) => health.report(format!("mobility ({:?}): {e}", ws.method)),
    }
}

type ForceRow<'a> = (
    &'a NetForce,
    Option<&'a FieldForce>,
    Option<&'a DipoleForce>,
    Option<&'a ContactForce>,
    Option<&'a KernelForce>,
);

/// The kernels, and whether and which force components are written.
type ForceSources<'w> = (
    Option<Res<'w, ExternalForces>>,
    Option<Res<'w, ForceComponents>>,
    Option<Res<'w, ForceRegistry>>,
);

/// `NetForce` of the workspace's particles into `net`, and into `extra` the part the model and
/// the kernels do not account for (a user's contributions).
fn read_net_force(
    entities: &[Entity],
    forces: &Query<(Entity, ForceRow)>,
    net: &mut [DVec3],
    extra: &mut [DVec3],
) {
    let parts = |(f, a, b, c, kf): ForceRow| {
        let model = a.map(|v| v.0).unwrap_or_default()
            + b.map(|v| v.0).unwrap_or_default()
            + c.map(|v| v.0).unwrap_or_default()
            + kf.map(|v| v.force).unwrap_or_default();
        (f.0, f.0 - model)
    };
    let mut split = |k: usize, row: ForceRow| (net[k], extra[k]) = parts(row);
    // a linear pass while the query follows the workspace order, lookups for the rest
    let k = in_workspace_order(entities, forces.iter(), &mut split);
    for (k, e) in entities.iter().enumerate().skip(k) {
        if let Ok((_, row)) = forces.get(*e) {
            split(k, row);
        }
    }
}

/// One step of the stepper from the accumulated forces. The step-start drift comes from
/// `NetForce` (from the workspace's forces, summed in the accumulation's order, when the
/// components are not written: [`force_components_written`]); every sub-step re-evaluates the model forces and the external force kernels
/// (the `KernelForce` part of `NetForce`) at its own positions and time, and holds the rest of
/// `NetForce` (other registered contributions, accepted with fixed steps only) fixed.
pub fn integrate_brownian(
    mut ws: ResMut<BrownianWorkspace>,
    config: Res<BrownianConfig>,
    clock: Res<StepClock>,
    mut stats: ResMut<BrownianStats>,
    mut health: ResMut<Health>,
    forces: Query<(Entity, ForceRow)>,
    (kernels, wanted, registry): ForceSources,
) {
    let ws = &mut *ws;
    let n = ws.positions.len();
    let from_components = force_components_written(wanted, registry);
    let fused = config.step_control == StepControl::Fixed
        && ws.hydro.is_none()
        && config.contact != ContactModel::HardCore;
    // `NetForce` beyond the model's forces (the fused step reads `NetForce` whole)
    let mut extra = vec![DVec3::ZERO; if fused { 0 } else { n }];
    let mut net = Vec::new();
    if from_components {
        extra.resize(n, DVec3::ZERO);
        net = vec![DVec3::ZERO; n];
        read_net_force(&ws.entities, &forces, &mut net, &mut extra);
    }
    let (field, dipole, contact) = (&ws.field, &ws.dipole, &ws.contact);
    // `NetForce` as the accumulation sums it: zero, then the contributions in order
    let net_of = |k: usize| DVec3::ZERO + field[k] + dipole[k] + contact[k];
    let mut dynamics = PipelineDynamics {
        model: &ws.model,
        radii: &ws.radii,
        laws: &ws.laws,
        mobile: ws.captured.iter().map(Option::is_none).collect(),
        captured_interact: config.captured_interact,
        extra: &extra,
        kernels: kernels.as_deref().filter(|k| !k.is_empty()),
        ids: &ws.ids,
        shapes: &ws.shapes,
        time: (clock.time(), clock.dt),
        fraction: 0.0,
        kernel_out: Vec::new(),
        viscosity: config.viscosity,
        kt: config.kt(),
        flow: DVec3::from_array(config.flow),
        flow_field: ws.flow_field.as_ref(),
        hydro: ws.hydro.as_ref(),
        lists: &mut ws.lists,
        start_moments: &ws.moments,
        list_builds: 0,
        hard_core: config.contact == ContactModel::HardCore,
        step: clock.step,
        captures: Vec::new(),
        parts: Default::default(),
        sweeps: 0,
        failure: None,
    };
    let mut x = std::mem::take(&mut ws.positions);
    // the first non-finite position (the fused step finds it in its parts)
    let mut scanned = None;
    if fused {
        scanned = Some(if from_components {
            dynamics.fixed_free_step(&mut x, |k| net[k], clock.dt, &mut ws.rngs, &mut stats)
        } else {
            dynamics.fixed_free_step(&mut x, net_of, clock.dt, &mut ws.rngs, &mut stats)
        });
    } else {
        if !from_components {
            net = (0..n).map(net_of).collect();
        }
        let mut v0 = vec![DVec3::ZERO; n];
        dynamics.velocities(&x, &net, &mut v0);
        match config.step_control {
            // multirate needs per-particle noise and drift: free draining, no hard cores
            StepControl::Multirate {
                tolerance,
                max_displacement,
                max_depth,
            } if dynamics.hydro.is_none() && !dynamics.hard_core => advance_multirate(
                &mut dynamics,
                &mut x,
                Some(v0),
                clock.dt,
                (tolerance, max_displacement, max_depth),
                &mut ws.rngs,
                &mut stats,
            ),
            _ => advance(
                &mut dynamics,
                &mut x,
                Some(v0),
                clock.dt,
                &config.step_control,
                &mut ws.rngs,
                &mut stats,
            ),
        }
    }
    let captures = std::mem::take(&mut dynamics.captures);
    stats.hard_core_sweeps += dynamics.sweeps;
    stats.neighbour_list_builds += dynamics.list_builds;
    if let Some(f) = dynamics.failure.take() {
        health.report(format!("step {}: {f}", clock.step));
    }
    for (i, ev) in captures {
        ws.captured[i] = Some(ev);
    }
    let bad = scanned.unwrap_or_else(|| x.iter().position(|p| !p.is_finite()));
    if let Some(i) = bad {
        health.report(format!(
            "step {}: non-finite position of particle {i} (time step unstable?)",
            clock.step
        ));
    }
    ws.positions = x;
}

/// Copy positions, capture flags and random streams to the components: in the parts of the
/// step ([`write_back_in_parts`]) when the particles fill one table in workspace order, else
/// one pass per component (each is a plain copy, so the split changes nothing but the time).
pub fn write_back_brownian(
    ws: Res<BrownianWorkspace>,
    mut q: PositionRows,
    mut streams: StreamRows,
) {
    let ws = &*ws;
    let bounds = part_bounds(&ws.lists, ws.entities.len());
    if bounds.len() > 2 && write_back_in_parts(ws, &bounds, &mut q, &mut streams) {
        return;
    }
    let positions = |q: &mut PositionRows| {
        let write = |k: usize, mut p: Mut<Position>, c: Option<Mut<Captured>>| {
            p.0 = ws.positions[k];
            if let Some(mut c) = c {
                c.0 = ws.captured[k];
            }
        };
        // a linear pass while the query follows the workspace order, lookups for the rest
        let k = in_workspace_order(
            &ws.entities,
            q.iter_mut().map(|(e, p, c)| (e, (p, c))),
            |k, (p, c)| write(k, p, c),
        );
        for (k, e) in ws.entities.iter().enumerate().skip(k) {
            if let Ok((_, p, c)) = q.get_mut(*e) {
                write(k, p, c);
            }
        }
    };
    let rngs = |q: &mut StreamRows| {
        let write = |k: usize, mut r: Mut<ParticleRng>| r.0.clone_from(&ws.rngs[k]);
        let k = in_workspace_order(&ws.entities, q.iter_mut(), write);
        for (k, e) in ws.entities.iter().enumerate().skip(k) {
            if let Ok((_, r)) = q.get_mut(*e) {
                write(k, r);
            }
        }
    };
    positions(&mut q);
    rngs(&mut streams);
}

/// Whether this step samples the capture curve: every `observe_every` completed steps and the
/// last (`Observe` runs after the clock advanced).
pub fn should_sample(config: Res<BrownianConfig>, clock: Res<StepClock>) -> bool {
    clock.step.is_multiple_of(config.observe_every.max(1)) || clock.step >= config.steps
}

/// Append `(completed steps, captured)` to the capture curve.
pub fn observe_capture(
    ws: Res<BrownianWorkspace>,
    clock: Res<StepClock>,
    mut curve: ResMut<CaptureCurve>,
) {
    let s = clock.step;
    if curve.samples.last().is_some_and(|l| l.0 >= s) {
        return;
    }
    curve.samples.push((s, ws.captured_count()));
}
