//! Parse -> typed common sections -> the pipeline's own sections -> semantic checks,
//! collecting every error with its key path. This module knows no pipeline by name: the
//! pipeline of the scene is looked up in the [`Registry`] and parses the keys it owns.

use std::sync::Arc;

use super::checks::*;
use super::fibre_packing::FibrePackingSpec;
use super::fibres::{ExternalFieldSection, FibreSpec, validate_fibres};
use super::pipeline::{ParseContext, Pipeline, Registry};
use super::sections::*;
use super::{COMMON_KEYS, Scene, SceneError};

/// The particle group at `path` typed: keys [`ParticleGroup`] does not type go to its
/// `extra` table.
fn typed_group(
    value: &toml::Value,
    path: &str,
    errors: &mut Vec<SceneError>,
) -> Option<ParticleGroup> {
    let toml::Value::Table(t) = value else {
        errors.push(SceneError::new(
            path,
            format!(
                "must be a table ([[particles]]), got a {}",
                value.type_str()
            ),
        ));
        return None;
    };
    let (known, extra): (toml::Table, toml::Table) = t
        .clone()
        .into_iter()
        .partition(|(k, _)| GROUP_KEYS.contains(&k.as_str()));
    let mut g = typed::<ParticleGroup>(&toml::Value::Table(known), path, errors)?;
    g.extra = extra;
    Some(g)
}

/// Pipelines other than `current` that own `key` (a top-level key or a particle key).
fn owners<'a>(
    registry: &'a Registry,
    current: Option<&str>,
    owns: impl Fn(&dyn Pipeline) -> bool + 'a,
) -> Vec<&'static str> {
    registry
        .pipelines()
        .filter(|p| Some(p.name()) != current && owns(p.as_ref()))
        .map(|p| p.name())
        .collect()
}

fn only_for(owners: &[&str]) -> String {
    let names: Vec<String> = owners
        .iter()
        .map(|n| format!("pipeline = \"{n}\""))
        .collect();
    format!("only for {}", names.join(" or "))
}

/// The whole pipeline of checks.
pub fn parse_and_validate(text: &str, registry: &Registry) -> Result<Scene, Vec<SceneError>> {
    let table: toml::Table = match text.parse() {
        Ok(t) => t,
        Err(e) => {
            let e: toml::de::Error = e;
            let at = e.span().map(|s| line_col(text, s.start));
            let msg = e.message().trim().to_string();
            let path = at
                .map(|(l, c)| format!("(syntax, line {l}, column {c})"))
                .unwrap_or_else(|| "(syntax)".into());
            return Err(vec![SceneError::new(path, msg)]);
        }
    };
    let mut errors = Vec::new();
    let simulation = table
        .get("simulation")
        .and_then(|v| typed::<SimulationSection>(v, "simulation", &mut errors));
    let pipeline: Option<Arc<dyn Pipeline>> = simulation.as_ref().and_then(|s| {
        let p = registry.pipeline(&s.pipeline).cloned();
        if p.is_none() {
            let names: Vec<String> = registry
                .names()
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect();
            errors.push(SceneError::new(
                "simulation.pipeline",
                format!(
                    "unknown pipeline \"{}\"; registered: {}",
                    s.pipeline,
                    names.join(", ")
                ),
            ));
        }
        p
    });
    let current = pipeline.as_ref().map(|p| p.name());
    let mut particles = Vec::new();
    let mut record = None;
    let mut extensions = Vec::new();
    let mut fibres = Vec::new();
    let mut fibre_packings = Vec::new();
    let mut external_field = None;
    for (key, value) in &table {
        match key.as_str() {
            "simulation" => {}
            "record" => record = typed::<RecordSection>(value, "record", &mut errors),
            "external_field" => {
                external_field = typed::<ExternalFieldSection>(value, "external_field", &mut errors)
            }
            "fibres" => fibres = typed_array::<FibreSpec>(value, "fibres", &mut errors),
            "fibre_packings" => {
                fibre_packings =
                    typed_array::<FibrePackingSpec>(value, "fibre_packings", &mut errors)
            }
            "particles" => match value {
                toml::Value::Array(items) => {
                    for (i, item) in items.iter().enumerate() {
                        if let Some(g) = typed_group(item, &format!("particles[{i}]"), &mut errors)
                        {
                            particles.push((i, g));
                        }
                    }
                }
                other => errors.push(SceneError::new(
                    "particles",
                    format!(
                        "must be an array of tables ([[particles]]), got a {}",
                        other.type_str()
                    ),
                )),
            },
            other
                if pipeline
                    .as_ref()
                    .is_some_and(|p| p.sections().contains(&other)) => {}
            other => match registry.kind(other) {
                Some(kind) => {
                    kind.validate(value, other, &mut errors);
                    extensions.push((other.to_string(), value.clone()));
                }
                None => {
                    let owned = owners(registry, current, |p| p.sections().contains(&other));
                    if owned.is_empty() {
                        let mut keys: Vec<String> =
                            COMMON_KEYS.iter().map(|s| s.to_string()).collect();
                        match &pipeline {
                            Some(p) => keys.extend(p.sections().iter().map(|s| s.to_string())),
                            None => keys.push("(the keys of the [simulation] pipeline)".into()),
                        }
                        keys.extend(registry.kind_keys());
                        errors.push(SceneError::new(
                            other,
                            format!("unknown key; expected one of {}", keys.join(", ")),
                        ));
                    } else {
                        errors.push(SceneError::new(other, only_for(&owned)));
                    }
                }
            },
        }
    }
    // a scene with nothing but fibres and an external field is a field-only scene
    let field_only = !table.contains_key("simulation")
        && !table.contains_key("particles")
        && !table.contains_key("container")
        && (table.contains_key("fibres")
            || table.contains_key("fibre_packings")
            || table.contains_key("external_field"));
    if !field_only && !table.contains_key("simulation") {
        errors.push(SceneError::new(
            "simulation",
            "missing required table [simulation]",
        ));
    }
    // fibres from packing recordings, appended after the explicit ones (reported under
    // fibre_packings[i] when invalid)
    for (i, spec) in &fibre_packings {
        let first = fibres.len();
        for f in super::fibre_packing::expand(*i, spec, &mut errors) {
            fibres.push((first, f));
        }
    }
    let fibre_specs: Vec<FibreSpec> = fibres.iter().map(|(_, f)| f.clone()).collect();
    // particle keys of other pipelines, and keys nobody reads
    let accepted: &[&str] = pipeline.as_ref().map(|p| p.particle_keys()).unwrap_or(&[]);
    if let Some(toml::Value::Array(items)) = table.get("particles") {
        for (i, item) in items.iter().enumerate() {
            let Some(t) = item.as_table() else { continue };
            for key in t.keys() {
                let k = key.as_str();
                if k == "count" || k == "shape" || accepted.contains(&k) {
                    continue;
                }
                let owned = owners(registry, current, |p| p.particle_keys().contains(&k));
                let message = if owned.is_empty() {
                    let mut keys = vec!["count", "shape"];
                    keys.extend(accepted);
                    format!("unknown key; expected one of {}", keys.join(", "))
                } else {
                    only_for(&owned)
                };
                errors.push(SceneError::new(format!("particles[{i}].{k}"), message));
            }
        }
    }
    let mut section = None;
    if let Some(p) = &pipeline {
        if p.needs_particles() && !table.contains_key("particles") {
            errors.push(SceneError::new(
                "particles",
                format!(
                    "the {} pipeline needs at least one [[particles]] entry",
                    p.name()
                ),
            ));
        }
        let mut cx = ParseContext {
            table: &table,
            particles: &mut particles,
            fibres: &fibre_specs,
            errors: &mut errors,
        };
        section = p.parse(&mut cx);
    }
    // semantic checks of the common keys
    let mut total: u64 = 0;
    for (i, g) in &particles {
        let p = format!("particles[{i}]");
        check(
            &mut errors,
            g.count >= 1 || g.volume_fraction.is_some(),
            &format!("{p}.count"),
            || format!("must be >= 1, got {}", g.count),
        );
        total = total.saturating_add(g.count);
        match g.shape {
            ShapeSpec::Sphere { radius } => {
                finite_positive(&mut errors, &format!("{p}.shape.radius"), radius)
            }
            ShapeSpec::Superquadric {
                semi_axes,
                exponents,
            } => {
                for (k, a) in semi_axes.iter().enumerate() {
                    finite_positive(&mut errors, &format!("{p}.shape.semi_axes[{k}]"), *a);
                }
                for (k, g) in exponents.iter().enumerate() {
                    exponent_in_range(&mut errors, &format!("{p}.shape.exponents[{k}]"), *g);
                }
            }
            ShapeSpec::Superball {
                semi_axis,
                exponent,
            } => {
                finite_positive(&mut errors, &format!("{p}.shape.semi_axis"), semi_axis);
                exponent_in_range(&mut errors, &format!("{p}.shape.exponent"), exponent);
            }
            ShapeSpec::Ellipsoid { semi_axes } => {
                for (k, a) in semi_axes.iter().enumerate() {
                    finite_positive(&mut errors, &format!("{p}.shape.semi_axes[{k}]"), *a);
                }
            }
            ShapeSpec::Spherocylinder {
                radius,
                cylinder_length,
            } => {
                finite_positive(&mut errors, &format!("{p}.shape.radius"), radius);
                check(
                    &mut errors,
                    cylinder_length.is_finite() && cylinder_length >= 0.0,
                    &format!("{p}.shape.cylinder_length"),
                    || format!("must be a finite number >= 0, got {cylinder_length}"),
                );
            }
        }
    }
    check(&mut errors, total <= 10_000_000, "particles", || {
        format!("at most 10^7 particles in all, got {total}")
    });
    if let Some(r) = &record {
        check(&mut errors, r.every >= 1, "record.every", || {
            format!("must be >= 1, got {}", r.every)
        });
    }
    validate_fibres(&fibres, external_field.as_ref(), &mut errors);
    if !errors.is_empty() || (!field_only && (pipeline.is_none() || section.is_none())) {
        if errors.is_empty() {
            errors.push(SceneError::new(
                "simulation.pipeline",
                "the pipeline returned no scene data and no error",
            ));
        }
        return Err(errors);
    }
    Ok(Scene {
        text: text.to_string(),
        simulation,
        pipeline,
        section,
        fibres: fibres.into_iter().map(|(_, f)| f).collect(),
        external_field,
        particles: particles.into_iter().map(|(_, g)| g).collect(),
        record,
        extensions,
    })
}
