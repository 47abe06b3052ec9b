//! Scenes: TOML files in SI units, parsed, validated (every error with its key path) and
//! spawned (docs/architecture.md §4, scenes).
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

pub(crate) mod box_overlap;
pub(crate) mod box_region;
pub mod checks;
mod fibre_pack;
mod fibre_packing;
mod fibres;
pub mod memory;
pub mod overrides;
pub mod pipeline;
pub mod placement;
mod sections;
mod spawn;
#[cfg(test)]
mod tests;
mod validate;

use std::path::Path;
use std::sync::Arc;

use bevy_ecs::prelude::*;

pub use crate::error::{SceneError, SceneErrors, SpawnError};
pub use fibre_pack::{MAX_PACKED_FIBRES, PackSpec};
pub use fibre_packing::FibrePackingSpec;
pub use fibres::{ExternalFieldSection, FibreSpec};
pub use pipeline::{
    ExecutorChoice, NoProgress, ParseContext, Pipeline, Progress, Registry, RunInfo, RunOptions,
    SceneSection,
};
pub use placement::{DensityRatios, PlacementSpec};
pub use sections::{
    GROUP_KEYS, OrientationSpec, ParticleGroup, RecordSection, ShapeSpec, SimulationSection,
    spheroid_semi_axes,
};
pub use spawn::{RecordEvery, SceneText, spawn_scene};

/// A scene entity kind contributed by a plugin: a top-level key of the scene file.
pub trait SceneKind: Send + Sync {
    /// The top-level key (e.g. `"magnets"`).
    fn key(&self) -> &str;
    /// Check `value` (found at `path`), pushing every problem.
    fn validate(&self, value: &toml::Value, path: &str, errors: &mut Vec<SceneError>);
    /// Spawn what `value` describes (after validation): [`spawn_scene`] calls it after the
    /// pipeline has spawned and before any plugin is built, so a plugin's `build` can read
    /// the resources inserted here (every run, replay and resume of the scene goes this way).
    ///
    /// # Errors
    /// [`SpawnError`] if spawning fails at run time.
    fn spawn(&self, value: &toml::Value, world: &mut World) -> Result<(), SpawnError>;
}

/// A parsed and validated scene.
#[derive(Clone)]
pub struct Scene {
    /// The file's text, verbatim, with any overrides applied (recorded in the recording's
    /// metadata).
    pub text: String,
    /// The overrides (`PATH=VALUE`, see [`overrides`]) already applied to [`Scene::text`],
    /// recorded in the recording's metadata (`extra["overrides"]`, a JSON list); empty when the
    /// file was run as it is.
    pub overrides: Vec<String>,
    /// `[simulation]` (absent in a field-only scene).
    pub simulation: Option<SimulationSection>,
    /// The pipeline `[simulation]` names (absent in a field-only scene).
    pub pipeline: Option<Arc<dyn Pipeline>>,
    /// The pipeline's own validated sections (see [`Scene::section`]).
    pub section: Option<SceneSection>,
    /// `[[fibres]]`, in file order.
    pub fibres: Vec<FibreSpec>,
    /// What the `[[fibre_packings]]` entries with `pack` packed (one JSON object each: entry
    /// index, fibres, packing fraction reached, height \[m\], compression steps, jammed), added
    /// to the run's summary as `fibre_packings`.
    pub packed_columns: Vec<serde_json::Value>,
    /// `[external_field]`.
    pub external_field: Option<ExternalFieldSection>,
    /// `[[particles]]`, in file order (particle ids follow this order).
    pub particles: Vec<ParticleGroup>,
    /// `[record]`.
    pub record: Option<RecordSection>,
    /// Plugin kinds' sections, in file order: spawned by [`spawn_scene`] after the pipeline.
    pub extensions: Vec<SceneExtension>,
}

/// A plugin kind's section of a scene: its top-level key, its value and the
/// [`SceneKind`] (from the [`Registry`] the scene was parsed with) that validated it and spawns it.
#[derive(Clone)]
pub struct SceneExtension {
    /// The top-level key.
    pub key: String,
    /// The section's value.
    pub value: toml::Value,
    /// The kind registered for `key`.
    pub kind: Arc<dyn SceneKind>,
}

impl std::fmt::Debug for SceneExtension {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneExtension")
            .field("key", &self.key)
            .field("value", &self.value)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("pipeline", &self.pipeline_name())
            .field("particles", &self.particles)
            .field("fibres", &self.fibres)
            .finish_non_exhaustive()
    }
}

/// The top-level keys every scene may hold (a pipeline adds its own, see
/// [`Pipeline::sections`]).
pub const COMMON_KEYS: &[&str] = &[
    "simulation",
    "particles",
    "record",
    "fibres",
    "fibre_packings",
    "external_field",
];

/// Parse and validate a scene; every problem is reported.
///
/// # Errors
/// [`SceneErrors`] with one entry per problem.
pub fn parse_scene(text: &str, registry: &Registry) -> Result<Scene, SceneErrors> {
    validate::parse_and_validate(text, registry).map_err(SceneErrors)
}

/// Parse a scene with overrides `PATH=VALUE` applied first (the `--set` of the CLI, e.g.
/// `"brownian.duration=0.01"`, `"particles[0].count=150"`), recorded in
/// [`Scene::overrides`] and so in the recording's metadata.
///
/// ```
/// let text = std::fs::read_to_string("scenes/spheres_500.toml").unwrap();
/// let registry = magsep::scene::Registry::default();
/// let scene =
///     magsep::scene::parse_scene_with_overrides(&text, &["particles[0].count=50"], &registry)
///         .unwrap();
/// assert_eq!(scene.total_particles(), 50);
/// assert_eq!(scene.overrides, ["particles[0].count=50"]);
/// let bad = magsep::scene::parse_scene_with_overrides(&text, &["particles[0].count=-1"], &registry);
/// assert_eq!(bad.unwrap_err().0[0].path, "particles[0].count");
/// ```
///
/// # Errors
/// [`SceneErrors`]: malformed overrides, or the scene's problems after applying them.
pub fn parse_scene_with_overrides(
    text: &str,
    set: &[&str],
    registry: &Registry,
) -> Result<Scene, SceneErrors> {
    let mut parsed = Vec::new();
    let mut errors = Vec::new();
    for arg in set {
        match overrides::Override::parse(arg) {
            Ok(o) => parsed.push(o),
            Err(e) => errors.push(e),
        }
    }
    if !errors.is_empty() {
        return Err(SceneErrors(errors));
    }
    let text = overrides::apply_overrides(text, &parsed)?;
    let mut scene = parse_scene(&text, registry)?;
    scene.overrides = parsed.iter().map(ToString::to_string).collect();
    Ok(scene)
}

/// Read and parse a scene file.
///
/// # Errors
/// [`SceneErrors`]; an unreadable file is one error with path `(file)`.
pub fn load_scene(path: &Path, registry: &Registry) -> Result<Scene, SceneErrors> {
    // a regular file of at most 16 MiB (crate::input)
    let text = crate::input::read_scene_text(path)
        .map_err(|e| SceneErrors(vec![SceneError::new("(file)", e)]))?;
    parse_scene(&text, registry)
}

impl Scene {
    /// The field sources of `[[fibres]]` (magnetisation resolved against the external field),
    /// the external flux density \[T\] and the field tolerance.
    pub fn field_sources(&self) -> (Vec<magsep_systems::field::CylinderSource>, glam::DVec3, f64) {
        let (b_ext, tol) = self
            .external_field
            .as_ref()
            .map(|e| (e.flux_density(), e.tolerance()))
            .unwrap_or((glam::DVec3::ZERO, magsep_systems::field::EXACT));
        let sources = self.fibres.iter().map(|f| f.source(b_ext)).collect();
        (sources, b_ext, tol)
    }

    /// The pipeline's validated scene data as `T` (e.g. a pipeline's section struct).
    pub fn section<T: std::any::Any>(&self) -> Option<&T> {
        self.section.as_ref().and_then(|s| s.get::<T>())
    }

    /// Replace the pipeline's scene data (e.g. a study that shortens a run): `value` must be
    /// the type the pipeline's [`Pipeline::parse`] returns. The scene is not re-validated.
    pub fn set_section<T: std::any::Any + Send + Sync>(&mut self, value: T) {
        self.section = Some(SceneSection::new(value));
    }

    /// The name of the scene's pipeline (`None` in a field-only scene).
    pub fn pipeline_name(&self) -> Option<&'static str> {
        self.pipeline.as_ref().map(|p| p.name())
    }

    /// Whether this is a field-only scene (fibres and an external field, nothing to run).
    pub fn is_field_only(&self) -> bool {
        self.simulation.is_none()
    }
}
