//! Spawn a validated scene into a world.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::RunSeed;
use magsep_systems::packing::insert::{InsertionError, random_insertion};
use magsep_systems::packing::state::Body;
use magsep_systems::packing::systems::state_from_si;

use super::packing_geometry::start_container;
use super::sections::ContainerSpec;
use magsep_systems::rng::particle_stream;

use super::{Scene, SceneRegistry};

/// Why spawning failed (after validation only run-time failures remain).
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    /// Random insertion could not place a particle.
    #[error(transparent)]
    Insertion(#[from] InsertionError),
    /// A plugin kind failed.
    #[error("{0}")]
    Other(String),
}

/// The scene file's text, verbatim (a resource).
#[derive(Resource, Debug, Clone)]
pub struct SceneText(pub String);

/// Record a frame every this many steps (a resource).
#[derive(Resource, Debug, Clone, Copy)]
pub struct RecordEvery(pub u64);

/// Spawn `scene` with `seed`: random non-overlapping particles in the periodic cube at the
/// initial packing fraction, and the resources every pipeline expects (`Container`,
/// `PackingConfig`, `StepClock`, `RunSeed`, `Health`, `SceneText`, `RecordEvery`).
///
/// # Errors
/// [`SpawnError::Insertion`] when random insertion fails (initial packing fraction too high
/// for the shapes).
pub fn spawn_scene(scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
    spawn_scene_with(scene, world, seed, &SceneRegistry::default())
}

/// [`spawn_scene`] with plugin scene kinds.
///
/// # Errors
/// As [`spawn_scene`], and the kinds' own errors.
pub fn spawn_scene_with(
    scene: &Scene,
    world: &mut World,
    seed: u64,
    registry: &SceneRegistry,
) -> Result<(), SpawnError> {
    if let Some(section) = scene.brownian_section() {
        super::placement::spawn_brownian(scene, section, world, seed)?;
    } else if let Some(pf) = &scene.particle_fluid {
        super::fluid_spawn::spawn_particle_fluid(scene, pf, world, seed)?;
    } else {
        spawn_packing_particles(scene, world, seed)?;
    }
    world.insert_resource(RunSeed(seed));
    world.insert_resource(Health::default());
    world.insert_resource(SceneText(scene.text.clone()));
    world.insert_resource(RecordEvery(
        scene.record.as_ref().map(|r| r.every).unwrap_or(100),
    ));
    // fibres as entities, and the applied field
    let (sources, b_ext, tolerance) = scene.field_sources();
    for (i, s) in sources.iter().enumerate() {
        world.spawn((
            FibreId(i as u64),
            Fibre {
                center: s.center,
                axis: s.axis(),
                radius: s.radius,
                half_length: s.half_length,
                magnetisation: s.magnetisation,
            },
        ));
    }
    world.insert_resource(ExternalField {
        flux_density: b_ext,
        tolerance,
    });
    for (key, value) in &scene.extensions {
        if let Some(kind) = registry.get(key) {
            kind.spawn(value, world)?;
        }
    }
    Ok(())
}

/// Random non-overlapping particles in the periodic cube at the initial packing fraction.
fn spawn_packing_particles(scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
    let shapes = scene.shapes();
    let config = scene.packing_config();
    let d = scene.reference_diameter();
    let bodies: Vec<Body> = shapes.iter().map(|s| Body::from_shape(s, d)).collect();
    let volume: f64 = bodies.iter().map(|b| b.volume).sum();
    let spec = scene
        .container
        .clone()
        .unwrap_or(ContainerSpec::PeriodicBox {});
    let container = start_container(&spec, volume * d.powi(3), config.initial_packing_fraction);
    let mut rngs: Vec<_> = (0..shapes.len() as u64)
        .map(|i| particle_stream(seed, i))
        .collect();
    let empty = state_from_si(&container, &[], &[], &[], d);
    let state = random_insertion(&bodies, empty, &mut rngs)?;
    let species = scene.species_ids();
    for (i, rng) in rngs.into_iter().enumerate() {
        world.spawn(ParticleBundle {
            id: ParticleId(i as u64),
            position: Position(state.positions[i] * d),
            orientation: Orientation(state.orientations[i]),
            shape: shapes[i],
            species: Species(species[i]),
            rng: ParticleRng(rng),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        });
    }
    if let Some(walls) = container.walls() {
        for face in walls.faces() {
            world.spawn(face);
        }
    }
    world.insert_resource(container);
    world.insert_resource(config);
    world.insert_resource(StepClock::new(0.0));
    Ok(())
}
