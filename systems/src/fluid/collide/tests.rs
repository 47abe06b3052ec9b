//! The ECS glue with spheroids: shapes, start-of-step orientations and the write-back.

use bevy_ecs::system::RunSystemOnce;
use glam::{DQuat, DVec3};

use super::*;
use crate::collision::CollisionDomain;
use crate::fluid::config::{ForceTerms, HistoryChoice, Integrator};
use crate::fluid::drag::DragLaw;
use crate::fluid::flow::FlowModel;
use crate::fluid::single::SphereInLiquid;

fn world(shape: Shape, body: InertialBody, dt: f64) -> World {
    let rig = SphereInLiquid::table_2_1(2e-3);
    let mut w = World::new();
    w.insert_resource(ParticleFluidConfig {
        dt,
        steps: 1,
        gravity: rig.gravity,
        mid_plane: 0.075,
        liquid: rig.liquid,
        magnet: rig.magnet,
        flow: FlowModel::Quiescent,
        terms: ForceTerms::default(),
        drag_law: DragLaw::SchillerNaumann,
        history: HistoryChoice::default(),
        integrator: Integrator::Implicit,
        levitation_tolerance: 5e-4,
        observe_every: 1,
        spheroids: Default::default(),
        solver: None,
    });
    w.insert_resource(StepClock::new(dt));
    w.insert_resource(FluidDomain(CollisionDomain::unbounded()));
    w.insert_resource(CollisionWorkspace::new(
        CollisionModel::dry(1.0, 0.0, 0.0),
        CollisionHistory::Keep,
    ));
    w.insert_resource(ParticleFluidStats::default());
    w.insert_resource(Health::default());
    // two bodies face to face along z, 2 mm apart, closing at 2 m/s; the integrator has already
    // moved and rotated them to the end of the step (a bogus end orientation)
    for (k, (z, v)) in [(-1e-3, 1.0), (1e-3, -1.0)].into_iter().enumerate() {
        let start = DVec3::new(0.0, 0.0, z);
        w.spawn((
            ParticleId(k as u64),
            StepStart(start),
            StepStartOrientation(DQuat::IDENTITY),
            shape,
            body,
            Position(start + DVec3::Z * (v * dt)),
            Orientation(DQuat::from_rotation_x(1.0)),
            Velocity(DVec3::Z * v),
            AngularVelocity(DVec3::ZERO),
            PendingHistoryReset::default(),
        ));
    }
    init_collision_workspace(&mut w);
    w
}

fn state(w: &mut World) -> Vec<(DVec3, DVec3, DQuat)> {
    let mut rows: Vec<(ParticleId, DVec3, DVec3, DQuat)> = w
        .query::<(&ParticleId, &Position, &Velocity, &Orientation)>()
        .iter(w)
        .map(|(id, x, v, o)| (*id, x.0, v.0, o.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| (r.1, r.2, r.3)).collect()
}

#[test]
fn discs_collide_from_their_start_orientation_and_spheres_keep_the_fast_path() {
    let dt = 2e-3;
    // 1:10 discs lying flat: the faces meet after 0.9 mm of closing, at 0.45 ms
    let (a, c) = (1e-3, 1e-4);
    let mut w = world(
        Shape::Spheroid {
            equatorial_radius: a,
            polar_radius: c,
        },
        InertialBody::spheroid(a, c, 1000.0),
        dt,
    );
    w.run_system_once(resolve_collisions).unwrap();
    let s = state(&mut w);
    assert!((s[0].1 + DVec3::Z).length() < 1e-9 && (s[1].1 - DVec3::Z).length() < 1e-9);
    // the orientation is re-rotated from the start (identity, no spin), not the bogus end one
    assert!(s[0].2.angle_between(DQuat::IDENTITY) < 1e-12);
    // after the impact at 0.9 ms both move back: z = −1 mm + 0.9 mm − 1.1 mm
    assert!((s[0].0.z + 1.2e-3).abs() < 1e-6, "{}", s[0].0.z);
    let stats = w.resource::<ParticleFluidStats>();
    assert_eq!(stats.particle_collisions, 1);
    assert!(!w.resource::<Health>().is_failed());
    // spheres: the orientation written by the integrator is left alone
    let mut w = world(
        Shape::Sphere { radius: 5e-4 },
        InertialBody::sphere(5e-4, 1000.0),
        dt,
    );
    w.run_system_once(resolve_collisions).unwrap();
    let s = state(&mut w);
    assert!(s[0].2.angle_between(DQuat::from_rotation_x(1.0)) < 1e-12);
    assert!((s[0].1 + DVec3::Z).length() < 1e-12);
}
