//! Parse -> typed common sections -> the pipeline's own sections -> semantic checks,
//! collecting every error with its key path. This module knows no pipeline by name: the
//! pipeline of the scene is looked up in the [`Registry`] and parses the keys it owns.

use std::sync::Arc;

use super::checks::*;
use super::fibre_packing::FibrePackingSpec;
use super::fibres::{ExternalFieldSection, FibreSpec, validate_fibres};
use super::pipeline::{ParseContext, Pipeline, Registry};
use super::sections::*;
use super::{COMMON_KEYS, Scene, SceneError, SceneExtension};

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

/// The checks of one shape (`p` is `particles[i]`): lengths in [`LENGTH_RANGE`], exponents
/// in range, and the particle's own size ratio at most [`MAX_SIZE_RATIO`].
fn shape_checks(p: &str, shape: &ShapeSpec, errors: &mut Vec<SceneError>) {
    let (lo, hi) = LENGTH_RANGE;
    let length = |errors: &mut Vec<SceneError>, key: &str, v: f64| {
        within(errors, &format!("{p}.shape.{key}"), v, lo, hi, "[m]")
    };
    let ratio = |errors: &mut Vec<SceneError>, key: &str, big: f64, small: f64| {
        check(
            errors,
            (big / small).is_nan() || big / small <= MAX_SIZE_RATIO,
            &format!("{p}.shape.{key}"),
            || {
                format!(
                    "makes the particle {} times longer than wide; at most {MAX_SIZE_RATIO}",
                    num(big / small)
                )
            },
        )
    };
    match *shape {
        ShapeSpec::Sphere { radius } => length(errors, "radius", radius),
        ShapeSpec::Superquadric {
            semi_axes,
            exponents,
        } => {
            for (k, a) in semi_axes.iter().enumerate() {
                length(errors, &format!("semi_axes[{k}]"), *a);
            }
            for (k, g) in exponents.iter().enumerate() {
                exponent_in_range(errors, &format!("{p}.shape.exponents[{k}]"), *g);
            }
            let (big, small) = min_max(&semi_axes);
            ratio(errors, "semi_axes", big, small);
        }
        ShapeSpec::Superball {
            semi_axis,
            exponent,
        } => {
            length(errors, "semi_axis", semi_axis);
            exponent_in_range(errors, &format!("{p}.shape.exponent"), exponent);
        }
        ShapeSpec::Ellipsoid { semi_axes } => {
            for (k, a) in semi_axes.iter().enumerate() {
                length(errors, &format!("semi_axes[{k}]"), *a);
            }
            let (big, small) = min_max(&semi_axes);
            ratio(errors, "semi_axes", big, small);
        }
        ShapeSpec::Spheroid {
            equatorial_radius,
            polar_radius,
            major_diameter,
            equivalent_diameter,
            aspect_ratio,
        } => {
            let given = [
                ("equatorial_radius", equatorial_radius),
                ("polar_radius", polar_radius),
                ("major_diameter", major_diameter),
                ("equivalent_diameter", equivalent_diameter),
            ];
            for (key, v) in given {
                if let Some(v) = v {
                    length(errors, key, v);
                }
            }
            if let Some(w) = aspect_ratio {
                within(
                    errors,
                    &format!("{p}.shape.aspect_ratio"),
                    w,
                    1.0 / MAX_SIZE_RATIO,
                    MAX_SIZE_RATIO,
                    "[-]",
                );
            }
            match super::sections::spheroid_semi_axes(
                equatorial_radius,
                polar_radius,
                major_diameter,
                equivalent_diameter,
                aspect_ratio,
            ) {
                Some((a, c)) => {
                    let (big, small) = (a.max(c), a.min(c));
                    ratio(errors, "polar_radius", big, small);
                }
                None => errors.push(SceneError::new(
                    format!("{p}.shape"),
                    "give exactly one of: equatorial_radius and polar_radius; major_diameter \
                     and aspect_ratio; equivalent_diameter and aspect_ratio",
                )),
            }
        }
        ShapeSpec::Spherocylinder {
            radius,
            cylinder_length,
        } => {
            length(errors, "radius", radius);
            within(
                errors,
                &format!("{p}.shape.cylinder_length"),
                cylinder_length,
                0.0,
                hi,
                "[m]",
            );
            ratio(
                errors,
                "cylinder_length",
                cylinder_length + 2.0 * radius,
                2.0 * radius,
            );
        }
    }
}

fn min_max(v: &[f64; 3]) -> (f64, f64) {
    (
        v.iter().copied().fold(f64::MIN, f64::max),
        v.iter().copied().fold(f64::MAX, f64::min),
    )
}

/// The largest particle of the scene at most [`MAX_SIZE_RATIO`] times the smallest (the
/// error names the smallest group).
fn size_ratio_check(particles: &[(usize, ParticleGroup)], errors: &mut Vec<SceneError>) {
    let sizes: Vec<(usize, f64)> = particles
        .iter()
        .map(|(i, g)| (*i, g.shape.shape().radius()))
        .filter(|(_, r)| r.is_finite() && *r > 0.0)
        .collect();
    let big = sizes.iter().map(|s| s.1).fold(0.0, f64::max);
    if let Some(&(i, small)) = sizes.iter().min_by(|a, b| a.1.total_cmp(&b.1))
        && big / small > MAX_SIZE_RATIO
    {
        errors.push(SceneError::new(
            format!("particles[{i}].shape"),
            format!(
                "is {} times smaller than the largest particle (bounding radius {} m); \
                 at most {MAX_SIZE_RATIO}",
                num(big / small),
                num(big)
            ),
        ));
    }
}

/// The key path of the `key = value` line holding byte `offset` of `text`: the last table
/// header above it (`[a.b]`, `[[a]]` counted) joined with the line's key. `None` where the
/// line is no key-value pair (a broken header, a multi-line value).
fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text[..offset.min(text.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let line = text[start..].lines().next().unwrap_or("");
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    let bare = |k: &str| {
        !k.is_empty()
            && k.split('.').all(|p| {
                !p.trim().is_empty()
                    && p.trim()
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            })
    };
    if !bare(key) {
        return None;
    }
    let mut table = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    for l in text[..start].lines() {
        let l = l.trim();
        if let Some(name) = l.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
            let name = name.trim().to_string();
            let n = counts.entry(name.clone()).or_insert(0);
            table = format!("{name}[{n}]");
            *n += 1;
        } else if let Some(name) = l.strip_prefix('[').and_then(|r| r.split(']').next()) {
            table = name.trim().to_string();
        }
    }
    let key: Vec<&str> = key.split('.').map(str::trim).collect();
    let key = key.join(".");
    Some(if table.is_empty() {
        key
    } else {
        format!("{table}.{key}")
    })
}

/// The whole pipeline of checks.
pub fn parse_and_validate(text: &str, registry: &Registry) -> Result<Scene, Vec<SceneError>> {
    let table: toml::Table = match text.parse() {
        Ok(t) => t,
        Err(e) => {
            let e: toml::de::Error = e;
            let at = e.span().map(|s| (s.start, line_col(text, s.start)));
            let msg = e.message().trim().to_string();
            // a bad value on a `key = value` line is reported at the key's path
            let error = match at {
                Some((offset, (l, c))) => match key_at(text, offset) {
                    Some(key) => SceneError::new(key, format!("{msg} (line {l}, column {c})")),
                    None => SceneError::new(format!("(syntax, line {l}, column {c})"), msg),
                },
                None => SceneError::new("(syntax)", msg),
            };
            return Err(vec![error]);
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
                    "unknown pipeline \"{}\"; registered: {} (a pipeline of a plugin crate \
                     runs with the program built with it, which registers it through \
                     magsep::cli::Extensions)",
                    s.pipeline,
                    names.join(", ")
                ),
            ));
        }
        p
    });
    // a [simulation] with another error still names its pipeline: the other sections are
    // checked as that pipeline's (no false "only for pipeline = ..." beside the real error)
    let pipeline = pipeline.or_else(|| {
        simulation.is_none().then_some(())?;
        let name = table.get("simulation")?.get("pipeline")?.as_str()?;
        registry.pipeline(name).cloned()
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
                    extensions.push(SceneExtension {
                        key: other.to_string(),
                        value: value.clone(),
                        kind: kind.clone(),
                    });
                }
                // the sections of a pipeline this program does not know: its error says so
                None if simulation.as_ref().is_some_and(|_| pipeline.is_none()) => {}
                None => {
                    let owned = owners(registry, current, |p| p.sections().contains(&other));
                    if owned.is_empty() {
                        let mut keys: Vec<String> =
                            COMMON_KEYS.iter().map(|s| s.to_string()).collect();
                        match &pipeline {
                            Some(p) => keys.extend(p.sections().iter().map(|s| s.to_string())),
                            None => keys.push("the sections of the [simulation] pipeline".into()),
                        }
                        keys.extend(registry.kind_keys());
                        // a table may be a plugin's section this program was not built with
                        let hint = if value.is_table() {
                            "; a plugin's section is read only by a program built with that \
                             plugin (its kind registered through magsep::cli::Extensions)"
                        } else {
                            ""
                        };
                        errors.push(SceneError::new(
                            other,
                            format!("unknown key; expected one of {}{hint}", keys.join(", ")),
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
    let entries = |key: &str| {
        table
            .get(key)
            .and_then(|v| v.as_array())
            .map_or(0, Vec::len)
    };
    let before = errors.len();
    let typed_all =
        fibres.len() == entries("fibres") && fibre_packings.len() == entries("fibre_packings");
    let mut packed_columns = Vec::new();
    let scene_seed = simulation.as_ref().map_or(0, |s| s.seed);
    for (i, spec) in &fibre_packings {
        let first = fibres.len();
        let (expanded, report) = super::fibre_packing::expand(*i, spec, scene_seed, &mut errors);
        for f in expanded {
            fibres.push((first, f));
        }
        packed_columns.extend(report);
    }
    let fibres_valid = typed_all && errors.len() == before;
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
        if !p.uses_fibres() {
            for key in ["fibres", "fibre_packings", "external_field"] {
                if table.contains_key(key) {
                    errors.push(SceneError::new(
                        key,
                        format!(
                            "the {} pipeline does not use magnetised fibres or an applied field: \
                             a run would ignore them; remove this key (`magsep field` computes \
                             the field of a scene with only fibres and the applied field)",
                            p.name()
                        ),
                    ));
                }
            }
        }
        let mut cx = ParseContext {
            fibres_valid,
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
        shape_checks(&p, &g.shape, &mut errors);
    }
    size_ratio_check(&particles, &mut errors);
    if let Some(toml::Value::Array(items)) = table.get("particles")
        && items.is_empty()
        && pipeline.as_ref().is_some_and(|p| p.needs_particles())
    {
        errors.push(SceneError::new(
            "particles",
            "is empty: give at least one [[particles]] entry",
        ));
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
        overrides: Vec::new(),
        text: text.to_string(),
        simulation,
        pipeline,
        section,
        fibres: fibres.into_iter().map(|(_, f)| f).collect(),
        packed_columns,
        external_field,
        particles: particles.into_iter().map(|(_, g)| g).collect(),
        record,
        extensions,
    })
}
