//! Scenes: TOML files in SI units, parsed, validated (every error with its key path) and
//! spawned (house plan, section 4).
//!
//! ```
//! use magsep::scene::parse_scene;
//! let text = r#"
//! [simulation]
//! pipeline = "packing"
//! [container]
//! kind = "periodic_box"
//! [[particles]]
//! count = 10
//! shape = { kind = "sphere", radius = -1.0 }
//! "#;
//! let errors = parse_scene(text, &Default::default()).unwrap_err();
//! assert_eq!(errors.0[0].path, "particles[0].shape.radius");
//! ```

mod brownian;
#[cfg(test)]
mod brownian_tests;
mod fibre_packing;
mod fibres;
mod fluid_spawn;
pub mod packing_geometry;
pub mod particle_fluid;
mod placement;
mod sections;
mod spawn;
#[cfg(test)]
mod tests;
mod validate;

use std::fmt;
use std::path::Path;

use bevy_ecs::prelude::*;

pub use brownian::{BrownianSection, PlacementSpec};
pub use fibre_packing::FibrePackingSpec;
pub use fibres::{ExternalFieldSection, FibreSpec};
pub use sections::{
    ContainerSpec, PackingSection, ParticleGroup, PipelineKind, RecordSection, ShapeSpec,
    SimulationSection,
};
pub use spawn::{RecordEvery, SceneText, SpawnError, spawn_scene, spawn_scene_with};

/// One problem in a scene: where (a key path such as `particles[2].shape.radius`) and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Key path, `(syntax)` for TOML syntax errors, `(file)` for I/O.
    pub path: String,
    /// What is wrong, with the offending value.
    pub message: String,
}

impl SceneError {
    /// A new error at `path`.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

/// All problems found in a scene (never empty when returned as an error).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneErrors(pub Vec<SceneError>);

impl fmt::Display for SceneErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneErrors {}

/// A scene entity kind contributed by a plugin: a top-level key of the scene file.
pub trait SceneKind: Send + Sync {
    /// The top-level key (e.g. `"magnets"`).
    fn key(&self) -> &str;
    /// Check `value` (found at `path`), pushing every problem.
    fn validate(&self, value: &toml::Value, path: &str, errors: &mut Vec<SceneError>);
    /// Spawn what `value` describes (after validation).
    ///
    /// # Errors
    /// [`SpawnError`] if spawning fails at run time.
    fn spawn(&self, value: &toml::Value, world: &mut World) -> Result<(), SpawnError>;
}

/// Registered plugin scene kinds.
#[derive(Default)]
pub struct SceneRegistry {
    kinds: Vec<Box<dyn SceneKind>>,
}

impl SceneRegistry {
    /// Register a kind (its key must not be a core key).
    pub fn register(&mut self, kind: Box<dyn SceneKind>) {
        self.kinds.push(kind);
    }

    /// The kind registered for `key`.
    pub fn get(&self, key: &str) -> Option<&dyn SceneKind> {
        self.kinds
            .iter()
            .find(|k| k.key() == key)
            .map(|k| k.as_ref())
    }

    fn keys(&self) -> Vec<String> {
        self.kinds.iter().map(|k| k.key().to_string()).collect()
    }
}

/// A parsed and validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The file's text, verbatim (recorded in the recording's metadata).
    pub text: String,
    /// `[simulation]` (absent in a field-only scene).
    pub simulation: Option<SimulationSection>,
    /// `[container]` (absent in a field-only scene).
    pub container: Option<ContainerSpec>,
    /// `[[fibres]]`, in file order.
    pub fibres: Vec<FibreSpec>,
    /// `[external_field]`.
    pub external_field: Option<ExternalFieldSection>,
    /// `[[particles]]`, in file order (particle ids follow this order).
    pub particles: Vec<ParticleGroup>,
    /// `[packing]` (all keys optional).
    pub packing: PackingSection,
    /// `[record]`.
    pub record: Option<RecordSection>,
    /// `[brownian]` (the brownian pipeline).
    pub brownian: Option<BrownianSection>,
    /// `[particle_fluid]`, `[liquid]`, `[magnet]`, `[collisions]` and the container of the
    /// particle_fluid pipeline.
    pub particle_fluid: Option<particle_fluid::ParticleFluidScene>,
    /// Plugin kinds: (key, value) in file order.
    pub extensions: Vec<(String, toml::Value)>,
}

/// The core top-level keys.
pub const CORE_KEYS: &[&str] = &[
    "simulation",
    "container",
    "particles",
    "packing",
    "record",
    "fibres",
    "fibre_packings",
    "external_field",
    "brownian",
    "particle_fluid",
    "liquid",
    "magnet",
    "collisions",
];

/// Parse and validate a scene; every problem is reported.
///
/// # Errors
/// [`SceneErrors`] with one entry per problem.
pub fn parse_scene(text: &str, registry: &SceneRegistry) -> Result<Scene, SceneErrors> {
    validate::parse_and_validate(text, registry).map_err(SceneErrors)
}

/// Read and parse a scene file.
///
/// # Errors
/// [`SceneErrors`]; an unreadable file is one error with path `(file)`.
pub fn load_scene(path: &Path, registry: &SceneRegistry) -> Result<Scene, SceneErrors> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        SceneErrors(vec![SceneError::new(
            "(file)",
            format!("cannot read {}: {e}", path.display()),
        )])
    })?;
    parse_scene(&text, registry)
}

impl Scene {
    /// The field sources of `[[fibres]]` (magnetisation resolved against the external field),
    /// the external flux density [T] and the field tolerance.
    pub fn field_sources(&self) -> (Vec<magsep_systems::field::CylinderSource>, glam::DVec3, f64) {
        let (b_ext, tol) = self
            .external_field
            .as_ref()
            .map(|e| (e.flux_density(), e.tolerance()))
            .unwrap_or((glam::DVec3::ZERO, magsep_systems::field::EXACT));
        let sources = self.fibres.iter().map(|f| f.source(b_ext)).collect();
        (sources, b_ext, tol)
    }

    /// The `[brownian]` section when the scene runs the brownian pipeline.
    pub fn brownian_section(&self) -> Option<&BrownianSection> {
        match &self.simulation {
            Some(SimulationSection {
                pipeline: PipelineKind::Brownian,
                ..
            }) => self.brownian.as_ref(),
            _ => None,
        }
    }

    /// Whether this is a field-only scene (fibres and an external field, nothing to run).
    pub fn is_field_only(&self) -> bool {
        self.simulation.is_none()
    }
}
