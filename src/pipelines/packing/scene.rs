//! The packing pipeline's scene: `[container]` and `[packing]`, their checks, and the random
//! start configuration. SI units.

use bevy_ecs::prelude::*;
use magsep_components::packing::{OverlapRemovalScheme, PackingConfig, VolumeStepRule};
use magsep_components::prelude::*;
use magsep_systems::packing::insert::random_insertion_until;
use magsep_systems::packing::state::Body;
use magsep_systems::packing::systems::state_from_si;
use magsep_systems::rng::particle_stream;
use serde::{Deserialize, Serialize};

use super::geometry::start_container;
use crate::scene::checks::{check, finite_positive, in_range, within};
use crate::scene::pipeline::StopRequest;
use crate::scene::{ParseContext, Scene, SceneError, SpawnError};
use crate::sim::StopFlag;

/// The validated sections of a packing scene.
#[derive(Debug, Clone, PartialEq)]
pub struct PackingScene {
    /// `[container]`.
    pub container: ContainerSpec,
    /// `[packing]` (all keys optional).
    pub packing: PackingSection,
}

/// `[container]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContainerSpec {
    /// A periodic cube; its edge follows from `packing.initial_packing_fraction`.
    PeriodicBox {},
    /// A hard cylinder wall (thesis 000, ch. 2), periodic along its axis (z) and compressed
    /// along it only; its start length follows from `packing.initial_packing_fraction`.
    Cylinder {
        /// Radius of the cylinder R_cyl = D_cyl / 2 \[m\], fixed. Range: > the largest
        /// particle radius.
        radius: f64,
    },
    /// A hard wedge prism (thesis 000, ch. 2): bottom y = 0, back x = `length`, slope
    /// y = x tan(`angle`); periodic in z (its width) and compressed along it only.
    Wedge {
        /// Acute angle alpha between bottom and slope \[rad\]. Range: (0, pi/2).
        angle: f64,
        /// Length l_w of the wedge along x \[m\], fixed. Range: > 0 and room for a particle.
        length: f64,
    },
    /// Two hard walls z = 0 and z = height, periodic in x and y with the fixed side `side`;
    /// compressed along z; the start height follows from `packing.initial_packing_fraction`.
    Slab {
        /// Periodic side along x and y \[m\]. Range: > 0.
        side: f64,
    },
    /// A closed box of six hard walls, compressed isotropically; its start edge follows from
    /// `packing.initial_packing_fraction`.
    ClosedBox {},
}

/// `[packing]`: every key optional (see `PackingConfig` for meanings and defaults).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackingSection {
    /// Overlap-removal rule. Default `fire`.
    pub scheme: Option<OverlapRemovalScheme>,
    /// Start packing fraction. Default 0.05. Range [0.001, 0.3].
    pub initial_packing_fraction: Option<f64>,
    /// Volume step [m^3]. Default 0.1 D^3.
    pub volume_step: Option<f64>,
    /// Step rule. Default `adaptive`.
    pub volume_step_rule: Option<VolumeStepRule>,
    /// Adaptive rule's initial free-volume fraction. Default 0.01. Range (0, 0.5].
    pub adaptive_initial_fraction: Option<f64>,
    /// Attempt budget per compression step. Default 20000 N (fire), 200 N (others). Range
    /// 1..=1e9.
    pub max_attempts: Option<u64>,
    /// Halvings before the stop. Default 4. Range 0..=30.
    pub step_halvings: Option<u32>,
    /// Overlap tolerance in units of D. Default 1e-4. Range (0, 0.01].
    pub overlap_tolerance: Option<f64>,
    /// Revised Delta t. Default 0.1. Range (0, 10].
    pub revised_dt: Option<f64>,
    /// Original beta. Default 0.5. Range (0, 1].
    pub original_beta: Option<f64>,
    /// Original xi [m^2]. Default: I_xy / m per particle.
    pub original_xi: Option<f64>,
    /// Step limit. Default 10^7. Range 1..=1e9.
    pub max_compression_steps: Option<u64>,
    /// Observe every n steps (0: final only). Default 0.
    pub observe_every: Option<u64>,
}

/// The packing configuration of `scene` with every default resolved (defaults only when the
/// scene is not a packing scene).
pub fn packing_config(scene: &Scene) -> PackingConfig {
    let n = scene.total_particles() as usize;
    let mut c = PackingConfig::defaults_for(n, scene.reference_diameter());
    let default = PackingSection::default();
    let p = scene
        .section::<PackingScene>()
        .map(|s| &s.packing)
        .unwrap_or(&default);
    if let Some(v) = p.scheme {
        c.scheme = v;
        c.max_attempts = PackingConfig::default_max_attempts(v, n);
    }
    macro_rules! take {
        ($($f:ident),*) => { $( if let Some(v) = p.$f { c.$f = v; } )* };
    }
    take!(
        initial_packing_fraction,
        volume_step,
        volume_step_rule,
        adaptive_initial_fraction,
        max_attempts,
        step_halvings,
        overlap_tolerance,
        revised_dt,
        original_beta,
        max_compression_steps,
        observe_every
    );
    if p.original_xi.is_some() {
        c.original_xi = p.original_xi;
    }
    c
}

/// Check the `[packing]` values.
fn validate_packing(pk: &PackingSection, errors: &mut Vec<SceneError>) {
    if let Some(v) = pk.initial_packing_fraction {
        within(errors, "packing.initial_packing_fraction", v, 1e-3, 0.3, "");
    }
    if let Some(v) = pk.volume_step {
        finite_positive(errors, "packing.volume_step", v);
    }
    if let Some(v) = pk.adaptive_initial_fraction {
        in_range(errors, "packing.adaptive_initial_fraction", v, 0.0, 0.5);
    }
    if let Some(v) = pk.max_attempts {
        check(
            errors,
            (1..=1_000_000_000).contains(&v),
            "packing.max_attempts",
            || format!("must be in 1..=1e9, got {v}"),
        );
    }
    if let Some(v) = pk.step_halvings {
        check(errors, v <= 30, "packing.step_halvings", || {
            format!("must be in 0..=30, got {v}")
        });
    }
    if let Some(v) = pk.overlap_tolerance {
        in_range(errors, "packing.overlap_tolerance", v, 0.0, 0.01);
    }
    if let Some(v) = pk.revised_dt {
        in_range(errors, "packing.revised_dt", v, 0.0, 10.0);
    }
    if let Some(v) = pk.original_beta {
        in_range(errors, "packing.original_beta", v, 0.0, 1.0);
    }
    if let Some(v) = pk.original_xi {
        finite_positive(errors, "packing.original_xi", v);
    }
    if let Some(v) = pk.max_compression_steps {
        check(
            errors,
            (1..=1_000_000_000).contains(&v),
            "packing.max_compression_steps",
            || format!("must be in 1..=1e9, got {v}"),
        );
    }
}

/// Type and check `[container]` and `[packing]` (and the packing checks of the particles).
pub fn parse(cx: &mut ParseContext<'_>) -> Option<PackingScene> {
    let container = cx.required::<ContainerSpec>("container", "packing");
    let packing = cx.section::<PackingSection>("packing").unwrap_or_default();
    validate_packing(&packing, cx.errors);
    let container = container?;
    if cx.errors.is_empty() {
        let groups: Vec<&crate::scene::ParticleGroup> =
            cx.particles.iter().map(|(_, g)| g).collect();
        super::geometry::validate(Some(&container), &groups, &packing, cx.errors);
    }
    Some(PackingScene { container, packing })
}

/// Random non-overlapping particles in the periodic cube at the initial packing fraction.
pub fn spawn_packing_particles(
    scene: &Scene,
    world: &mut World,
    seed: u64,
) -> Result<(), SpawnError> {
    let shapes = scene.shapes();
    let config = packing_config(scene);
    let d = scene.reference_diameter();
    let bodies: Vec<Body> = shapes.iter().map(|s| Body::from_shape(s, d)).collect();
    let volume: f64 = bodies.iter().map(|b| b.volume).sum();
    let spec = scene
        .section::<PackingScene>()
        .map(|s| s.container.clone())
        .unwrap_or(ContainerSpec::PeriodicBox {});
    let container = start_container(&spec, volume * d.powi(3), config.initial_packing_fraction);
    let mut rngs: Vec<_> = (0..shapes.len() as u64)
        .map(|i| particle_stream(seed, i))
        .collect();
    let empty = state_from_si(&container, &[], &[], &[], d);
    let stop = world.get_resource::<StopRequest>().map(|s| s.0.clone());
    let stopped = || stop.as_ref().is_some_and(StopFlag::is_stopped);
    let Some(state) = random_insertion_until(&bodies, empty, &mut rngs, &stopped)? else {
        let reason = stop.and_then(|s| s.reason()).unwrap_or_default();
        return Err(SpawnError::Interrupted(reason));
    };
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
