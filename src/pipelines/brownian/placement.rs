//! Spawning the particles of a brownian scene in their start regions.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use magsep_systems::field::CylinderSource;
use magsep_systems::rng::particle_stream;
use rand::RngExt;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::BrownianSection;
use crate::scene::{PlacementSpec, Scene, SpawnError};

/// Rejection attempts per particle before the region is declared too full.
const MAX_ATTEMPTS: usize = 10_000;

/// A uniform random point of `placement` for a particle of radius `a`.
fn sample(
    placement: &PlacementSpec,
    sources: &[CylinderSource],
    k: usize,
    rng: &mut Xoshiro256PlusPlus,
) -> DVec3 {
    use std::f64::consts::TAU;
    match placement {
        PlacementSpec::Box { min, max } => {
            let (lo, hi) = (DVec3::from_array(*min), DVec3::from_array(*max));
            lo + (hi - lo) * DVec3::new(rng.random(), rng.random(), rng.random())
        }
        PlacementSpec::FibreTop { fibre, gap, height } => {
            let f = &sources[*fibre];
            let axis = f.axis();
            let (u, v) = any_perpendicular(axis);
            let r = f.radius * rng.random::<f64>().sqrt();
            let t = TAU * rng.random::<f64>();
            let z = f.half_length + gap + height * rng.random::<f64>();
            f.center + axis * z + (u * t.cos() + v * t.sin()) * r
        }
        PlacementSpec::FibreSide {
            fibre,
            gap,
            thickness,
        } => {
            let f = &sources[*fibre];
            let axis = f.axis();
            let (u, v) = any_perpendicular(axis);
            let (r0, r1) = (f.radius + gap, f.radius + gap + thickness);
            let r = (r0 * r0 + (r1 * r1 - r0 * r0) * rng.random::<f64>()).sqrt();
            let t = TAU * rng.random::<f64>();
            let z = f.half_length * (2.0 * rng.random::<f64>() - 1.0);
            f.center + axis * z + (u * t.cos() + v * t.sin()) * r
        }
        PlacementSpec::Points { positions } => DVec3::from_array(positions[k]),
        // rejected by validation for brownian scenes
        PlacementSpec::Injection { .. } => DVec3::ZERO,
    }
}

/// Two unit vectors completing `axis` to a right-handed frame.
fn any_perpendicular(axis: DVec3) -> (DVec3, DVec3) {
    let u = axis.any_orthonormal_vector();
    (u, axis.cross(u))
}

/// Spawn the particles of a brownian scene and the pipeline's resources.
///
/// # Errors
/// [`SpawnError::Other`] when a region is too full to place a particle without overlap.
pub fn spawn_brownian(
    scene: &Scene,
    section: &BrownianSection,
    world: &mut World,
    seed: u64,
) -> Result<(), SpawnError> {
    let (sources, _, _) = scene.field_sources();
    let mut placed: Vec<(DVec3, f64)> = Vec::new();
    let mut id = 0u64;
    for (g, group) in scene.particles.iter().enumerate() {
        let a = group.shape.shape().radius();
        let Some(placement) = &group.placement else {
            continue;
        };
        for k in 0..group.count as usize {
            let mut rng = particle_stream(seed, id);
            let explicit = matches!(placement, PlacementSpec::Points { .. });
            let mut found = None;
            for _ in 0..MAX_ATTEMPTS {
                let p = sample(placement, &sources, k, &mut rng);
                let clear = placed.iter().all(|(q, b)| (p - *q).length() >= a + b)
                    && sources.iter().all(|s| s.distance(p) > a);
                if clear || explicit {
                    found = Some(p);
                    break;
                }
            }
            if explicit
                && let Some(p) = found
                && let Some(j) = sources.iter().position(|s| s.distance(p) <= a)
            {
                // it would count as captured from the start
                return Err(SpawnError::Other(format!(
                    "particles[{g}].placement.positions[{k}]: {:?} m is inside fibre {j} or \
                     closer to its surface than the particle radius {a:e} m",
                    p.to_array()
                )));
            }
            let Some(p) = found else {
                if let PlacementSpec::Box { min, max } = placement
                    && let Some(j) = crate::scene::box_region::box_inside_fibre(
                        DVec3::from_array(*min),
                        DVec3::from_array(*max),
                        &scene.fibres,
                        a,
                    )
                {
                    return Err(SpawnError::Other(format!(
                        "particles[{g}].placement: {}",
                        crate::scene::box_region::inside_fibre_message(j, &format!("{a:e}"))
                    )));
                }
                return Err(SpawnError::Other(format!(
                    "particles[{g}]: no overlap-free place for particle {k} after {MAX_ATTEMPTS} \
                     attempts (start region too small for count = {})",
                    group.count
                )));
            };
            placed.push((p, a));
            world.spawn((
                ParticleBundle {
                    id: ParticleId(id),
                    position: Position(p),
                    orientation: Orientation::default(),
                    shape: group.shape.shape(),
                    species: Species(g as u32),
                    rng: ParticleRng(rng),
                    net_force: NetForce::default(),
                    net_torque: NetTorque::default(),
                },
                group.moment.unwrap_or_default(),
                InitialPosition(p),
                Captured::default(),
                MagneticMoment::default(),
                (
                    FieldForce::default(),
                    DipoleForce::default(),
                    ContactForce::default(),
                ),
            ));
            id += 1;
        }
    }
    world.insert_resource(crate::brownian::StartRegions(
        scene
            .particles
            .iter()
            .map(|g| g.placement.as_ref().and_then(|p| p.volume(&scene.fibres)))
            .collect(),
    ));
    world.insert_resource(Container::Unbounded);
    world.insert_resource(section.config());
    world.insert_resource(StepClock::new(section.time_step));
    Ok(())
}
