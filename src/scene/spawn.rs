//! Spawn a validated scene into a world.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::RunSeed;

use super::{Scene, SpawnError};

/// The scene file's text, verbatim (a resource).
#[derive(Resource, Debug, Clone)]
pub struct SceneText(pub String);

/// Record a frame every this many steps (a resource).
#[derive(Resource, Debug, Clone, Copy)]
pub struct RecordEvery(pub u64);

/// Spawn `scene` with `seed`: the pipeline's particles and resources, then what every
/// pipeline expects (`RunSeed`, `Health`, `SceneText`, `RecordEvery`, the fibres as entities,
/// `ExternalField`) and then the plugin kinds' sections ([`Scene::extensions`], each by the
/// [`SceneKind`](super::SceneKind) that validated it).
///
/// # Errors
/// [`SpawnError`] from the pipeline (e.g. random insertion failed) or a plugin kind; a
/// field-only scene has nothing to spawn.
pub fn spawn_scene(scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
    let Some(pipeline) = &scene.pipeline else {
        return Err(SpawnError::Other(
            "a field-only scene has nothing to spawn".into(),
        ));
    };
    world.insert_resource(RunSeed(seed));
    world.insert_resource(Health::default());
    world.insert_resource(SceneText(scene.text.clone()));
    world.insert_resource(RecordEvery(
        scene.record.as_ref().map(|r| r.every).unwrap_or(100),
    ));
    // the pipeline spawns after the common resources, so it may override them
    pipeline.spawn(scene, world, seed)?;
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
    for ext in &scene.extensions {
        ext.kind.spawn(&ext.value, world)?;
    }
    Ok(())
}
