//! The recorder's frame gathering: the query kept between frames gives the frames of a query
//! built for each frame (`gather_frame_uncached`), also after particles of new archetypes
//! appear and others are despawned.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::container::{Container, Walls};
use magsep_components::prelude::*;
use magsep_plugins::recorder::{gather_frame, gather_frame_uncached};
use magsep_systems::rng::particle_stream;

/// A marker that puts the particles carrying it in an archetype of their own.
#[derive(Component)]
struct Tagged;

fn particle(id: u64) -> (ParticleId, Position, Orientation, Shape) {
    let f = id as f64;
    (
        ParticleId(id),
        Position(DVec3::new(f, 2.0 * f, -f)),
        Orientation(DQuat::from_rotation_z(0.1 * f)),
        if id.is_multiple_of(2) {
            Shape::Sphere {
                radius: 1e-3 * (1.0 + f),
            }
        } else {
            Shape::Spherocylinder {
                radius: 1e-3,
                half_length: 1e-4 * f,
            }
        },
    )
}

#[test]
fn kept_query_gathers_the_frames_of_a_fresh_one() {
    let mut world = World::new();
    world.insert_resource(StepClock::new(1e-3));
    world.insert_resource(Container::Walled {
        walls: Walls::Box,
        edges: DVec3::splat(0.1),
    });
    // ids out of spawn order, in two archetypes (with and without a random stream)
    for id in [5u64, 1, 3] {
        world.spawn(particle(id));
    }
    for id in [4u64, 0] {
        world.spawn((particle(id), ParticleRng(particle_stream(7, id))));
    }
    let first = gather_frame(&mut world);
    assert_eq!(first, gather_frame_uncached(&mut world));
    assert_eq!(first.ids, vec![0, 1, 3, 4, 5]);
    assert_ne!(first.rng_states[0], [0; 4]);
    assert_eq!(first.rng_states[1], [0; 4]);

    // a new archetype after the query was kept, a despawn, a move and a new step
    let e = world.spawn((particle(2), Tagged)).id();
    world.spawn((particle(9), Tagged, ParticleRng(particle_stream(7, 9))));
    let gone = world
        .query::<(Entity, &ParticleId)>()
        .iter(&world)
        .find(|(_, id)| id.0 == 3)
        .map(|(e, _)| e);
    world.despawn(gone.unwrap());
    world.get_mut::<Position>(e).unwrap().0 = DVec3::new(0.5, 0.5, 0.5);
    world.resource_mut::<StepClock>().advance();
    let second = gather_frame(&mut world);
    assert_eq!(second, gather_frame_uncached(&mut world));
    assert_eq!(second.ids, vec![0, 1, 2, 4, 5, 9]);
    assert_eq!(second.positions[2], DVec3::new(0.5, 0.5, 0.5));
    assert_eq!(second.step, 1);
    assert!(second.status_json.contains("\"container\""));
}
