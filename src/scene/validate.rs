//! Parse -> typed sections -> semantic checks, collecting every error with its key path.

use serde::de::DeserializeOwned;

use super::brownian::{BrownianSection, validate_group, validate_section};
use super::fibre_packing::FibrePackingSpec;
use super::fibres::{ExternalFieldSection, FibreSpec, validate_fibres};
use super::particle_fluid::{
    CollisionsSection, FluidContainerSpec, LiquidSection, MagnetSection, ParticleFluidScene,
    ParticleFluidSection,
};
use super::sections::*;
use super::{CORE_KEYS, Scene, SceneError, SceneRegistry};

/// Line and column (1-based) of byte `offset` in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

/// Deserialize `value` as `T`; a failure becomes an error at `path` + the inner path.
fn typed<T: DeserializeOwned>(
    value: &toml::Value,
    path: &str,
    errors: &mut Vec<SceneError>,
) -> Option<T> {
    match serde_path_to_error::deserialize::<_, T>(value.clone()) {
        Ok(v) => Some(v),
        Err(e) => {
            let inner = e.path().to_string();
            let full = match (path.is_empty(), inner.as_str()) {
                (_, ".") => path.to_string(),
                (true, i) => i.to_string(),
                (false, i) => format!("{path}.{i}"),
            };
            let raw = e.into_inner().to_string();
            // toml appends context lines ("in `shape`"); the key path already says where
            let mut message = raw.lines().next().unwrap_or("").trim().to_string();
            // name the key of an unknown field in the path, as users look for it there
            let mut full = full;
            if let Some(rest) = message.strip_prefix("unknown field `")
                && let Some(end) = rest.find('`')
            {
                let key = &rest[..end];
                if !(full == key || full.ends_with(&format!(".{key}"))) {
                    full = if full.is_empty() {
                        key.to_string()
                    } else {
                        format!("{full}.{key}")
                    };
                }
                message = format!(
                    "unknown key; {}",
                    rest[end + 1..].trim_start_matches(',').trim()
                );
            } else if let Some(rest) = message.strip_prefix("missing field `")
                && let Some(end) = rest.find('`')
            {
                let key = &rest[..end];
                if !(full == key || full.ends_with(&format!(".{key}"))) {
                    full = if full.is_empty() {
                        key.to_string()
                    } else {
                        format!("{full}.{key}")
                    };
                }
                message = "missing required key".into();
            }
            errors.push(SceneError::new(full, message));
            None
        }
    }
}

/// An array of tables (`[[key]]`): each entry typed with its index in the path; entries with
/// errors are left out (their errors are pushed).
fn typed_array<T: DeserializeOwned>(
    value: &toml::Value,
    key: &str,
    errors: &mut Vec<SceneError>,
) -> Vec<(usize, T)> {
    match value {
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .filter_map(|(i, item)| {
                typed::<T>(item, &format!("{key}[{i}]"), errors).map(|t| (i, t))
            })
            .collect(),
        other => {
            errors.push(SceneError::new(
                key,
                format!(
                    "must be an array of tables ([[{key}]]), got a {}",
                    other.type_str()
                ),
            ));
            Vec::new()
        }
    }
}

pub(super) fn check(
    errors: &mut Vec<SceneError>,
    ok: bool,
    path: &str,
    message: impl FnOnce() -> String,
) {
    if !ok {
        errors.push(SceneError::new(path, message()));
    }
}

/// An error `only for pipeline = "<pipeline>"` at `<path>.<key>` for every present key.
fn reject_keys(errors: &mut Vec<SceneError>, path: &str, keys: &[(&str, bool)], pipeline: &str) {
    for (key, present) in keys {
        if *present {
            errors.push(SceneError::new(
                format!("{path}.{key}"),
                format!("only for pipeline = \"{pipeline}\""),
            ));
        }
    }
}

pub(super) fn finite_positive(errors: &mut Vec<SceneError>, path: &str, v: f64) {
    check(errors, v.is_finite() && v > 0.0, path, || {
        format!("must be a finite number > 0, got {v}")
    });
}

fn in_range(errors: &mut Vec<SceneError>, path: &str, v: f64, lo_open: f64, hi: f64) {
    check(
        errors,
        v.is_finite() && v > lo_open && v <= hi,
        path,
        || format!("must be in ({lo_open}, {hi}], got {v}"),
    );
}

/// The whole pipeline of checks.
pub fn parse_and_validate(text: &str, registry: &SceneRegistry) -> Result<Scene, Vec<SceneError>> {
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
    let mut simulation = None;
    let mut container = None;
    let mut particles = Vec::new();
    let mut packing = PackingSection::default();
    let mut record = None;
    let mut extensions = Vec::new();
    let mut fibres = Vec::new();
    let mut fibre_packings = Vec::new();
    let mut external_field = None;
    let mut brownian = None;
    let mut pf_section = None;
    let mut liquid = None;
    let mut magnet = None;
    let mut collisions = None;
    let is_pf = table
        .get("simulation")
        .and_then(|s| s.get("pipeline"))
        .and_then(|p| p.as_str())
        == Some("particle_fluid");
    let mut fluid_container = None;
    for (key, value) in &table {
        match key.as_str() {
            "simulation" => {
                simulation = typed::<SimulationSection>(value, "simulation", &mut errors)
            }
            "container" if is_pf => {
                fluid_container = typed::<FluidContainerSpec>(value, "container", &mut errors)
            }
            "container" => container = typed::<ContainerSpec>(value, "container", &mut errors),
            "particle_fluid" => {
                pf_section = typed::<ParticleFluidSection>(value, "particle_fluid", &mut errors)
            }
            "liquid" => liquid = typed::<LiquidSection>(value, "liquid", &mut errors),
            "magnet" => magnet = typed::<MagnetSection>(value, "magnet", &mut errors),
            "collisions" => {
                collisions = typed::<CollisionsSection>(value, "collisions", &mut errors)
            }
            "packing" => {
                packing = typed::<PackingSection>(value, "packing", &mut errors).unwrap_or_default()
            }
            "record" => record = typed::<RecordSection>(value, "record", &mut errors),
            "brownian" => brownian = typed::<BrownianSection>(value, "brownian", &mut errors),
            "external_field" => {
                external_field = typed::<ExternalFieldSection>(value, "external_field", &mut errors)
            }
            "fibres" => fibres = typed_array::<FibreSpec>(value, "fibres", &mut errors),
            "fibre_packings" => {
                fibre_packings =
                    typed_array::<FibrePackingSpec>(value, "fibre_packings", &mut errors)
            }
            "particles" => {
                particles = typed_array::<ParticleGroup>(value, "particles", &mut errors)
            }
            other => match registry.get(other) {
                Some(kind) => {
                    kind.validate(value, other, &mut errors);
                    extensions.push((other.to_string(), value.clone()));
                }
                None => {
                    let mut keys: Vec<String> = CORE_KEYS.iter().map(|s| s.to_string()).collect();
                    keys.extend(registry.keys());
                    errors.push(SceneError::new(
                        other,
                        format!("unknown key; expected one of {}", keys.join(", ")),
                    ));
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
    let is_brownian = matches!(
        simulation,
        Some(SimulationSection {
            pipeline: PipelineKind::Brownian,
            ..
        })
    );
    if !field_only && !is_brownian && !is_pf && !table.contains_key("container") {
        errors.push(SceneError::new(
            "container",
            "missing required table [container]",
        ));
    }
    if is_brownian {
        if table.contains_key("container") {
            errors.push(SceneError::new(
                "container",
                "the brownian pipeline runs in unbounded fluid around the fibres: remove [container]",
            ));
        }
        match &brownian {
            Some(b) => validate_section(b, &mut errors),
            None if !table.contains_key("brownian") => errors.push(SceneError::new(
                "brownian",
                "missing required table [brownian] (time_step, duration)",
            )),
            None => {}
        }
        if !table.contains_key("particles") {
            errors.push(SceneError::new(
                "particles",
                "the brownian pipeline needs at least one [[particles]] entry",
            ));
        }
    } else if brownian.is_some() {
        errors.push(SceneError::new(
            "brownian",
            "only for pipeline = \"brownian\"",
        ));
    }
    let mut particle_fluid = None;
    if is_pf {
        for (key, present) in [
            (
                "particle_fluid",
                pf_section.is_some() || table.contains_key("particle_fluid"),
            ),
            ("liquid", liquid.is_some() || table.contains_key("liquid")),
            ("particles", table.contains_key("particles")),
        ] {
            if !present {
                errors.push(SceneError::new(
                    key,
                    format!("missing required table [{key}] for pipeline = \"particle_fluid\""),
                ));
            }
        }
        if let (Some(section), Some(liquid)) = (pf_section.take(), liquid.take()) {
            let pf = ParticleFluidScene {
                section,
                liquid,
                magnet: magnet.take(),
                collisions: collisions.take().unwrap_or_default(),
                container: fluid_container
                    .take()
                    .unwrap_or(FluidContainerSpec::Unbounded {}),
            };
            super::particle_fluid::validate(&pf, &mut particles, &mut errors);
            particle_fluid = Some(pf);
        }
    } else {
        for (key, present) in [
            ("particle_fluid", pf_section.is_some()),
            ("liquid", liquid.is_some()),
            ("magnet", magnet.is_some()),
            ("collisions", collisions.is_some()),
        ] {
            if present {
                errors.push(SceneError::new(
                    key,
                    "only for pipeline = \"particle_fluid\"",
                ));
            }
        }
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
    // semantic checks
    let mut total: u64 = 0;
    for (i, g) in &particles {
        let p = format!("particles[{i}]");
        if !is_pf {
            check(&mut errors, g.count >= 1, &format!("{p}.count"), || {
                format!("must be >= 1, got {}", g.count)
            });
        }
        if is_pf && g.moment.is_some() {
            errors.push(SceneError::new(
                format!("{p}.moment"),
                "only for pipeline = \"brownian\"",
            ));
        }
        let fluid_keys = [
            ("density", g.density.is_some()),
            ("density_ratios", g.density_ratios.is_some()),
            ("velocity", g.velocity.is_some()),
            ("volume_fraction", g.volume_fraction.is_some()),
        ];
        if is_brownian {
            reject_keys(&mut errors, &p, &fluid_keys, "particle_fluid");
        }
        total = total.saturating_add(g.count);
        if is_brownian {
            match g.shape {
                ShapeSpec::Sphere { radius } => validate_group(
                    &p,
                    g.count,
                    radius,
                    g.moment.as_ref(),
                    g.placement.as_ref(),
                    &fibre_specs,
                    &mut errors,
                ),
                _ => errors.push(SceneError::new(
                    format!("{p}.shape.kind"),
                    "the brownian pipeline simulates spheres only",
                )),
            }
        } else if !is_pf {
            let brownian_keys = [
                ("moment", g.moment.is_some()),
                ("placement", g.placement.is_some()),
            ];
            reject_keys(&mut errors, &p, &brownian_keys, "brownian");
            reject_keys(&mut errors, &p, &fluid_keys, "particle_fluid");
        }
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
                    super::packing_geometry::exponent_in_range(
                        &mut errors,
                        &format!("{p}.shape.exponents[{k}]"),
                        *g,
                    );
                }
            }
            ShapeSpec::Superball {
                semi_axis,
                exponent,
            } => {
                finite_positive(&mut errors, &format!("{p}.shape.semi_axis"), semi_axis);
                super::packing_geometry::exponent_in_range(
                    &mut errors,
                    &format!("{p}.shape.exponent"),
                    exponent,
                );
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
    if matches!(
        simulation,
        Some(SimulationSection {
            pipeline: PipelineKind::Packing,
            ..
        })
    ) && !table.contains_key("particles")
    {
        errors.push(SceneError::new(
            "particles",
            "the packing pipeline needs at least one [[particles]] entry",
        ));
    }
    check(&mut errors, total <= 10_000_000, "particles", || {
        format!("at most 10^7 particles in all, got {total}")
    });
    let pk = &packing;
    if let Some(v) = pk.initial_packing_fraction {
        in_range(&mut errors, "packing.initial_packing_fraction", v, 0.0, 0.3);
    }
    if let Some(v) = pk.volume_step {
        finite_positive(&mut errors, "packing.volume_step", v);
    }
    if let Some(v) = pk.adaptive_initial_fraction {
        in_range(
            &mut errors,
            "packing.adaptive_initial_fraction",
            v,
            0.0,
            0.5,
        );
    }
    if let Some(v) = pk.max_attempts {
        check(&mut errors, v >= 1, "packing.max_attempts", || {
            format!("must be >= 1, got {v}")
        });
    }
    if let Some(v) = pk.step_halvings {
        check(&mut errors, v <= 30, "packing.step_halvings", || {
            format!("must be in 0..=30, got {v}")
        });
    }
    if let Some(v) = pk.overlap_tolerance {
        in_range(&mut errors, "packing.overlap_tolerance", v, 0.0, 0.01);
    }
    if let Some(v) = pk.revised_dt {
        in_range(&mut errors, "packing.revised_dt", v, 0.0, 10.0);
    }
    if let Some(v) = pk.original_beta {
        in_range(&mut errors, "packing.original_beta", v, 0.0, 1.0);
    }
    if let Some(v) = pk.original_xi {
        finite_positive(&mut errors, "packing.original_xi", v);
    }
    if let Some(v) = pk.max_compression_steps {
        check(&mut errors, v >= 1, "packing.max_compression_steps", || {
            format!("must be >= 1, got {v}")
        });
    }
    if errors.is_empty() && !is_brownian && !is_pf && !field_only {
        let groups: Vec<&ParticleGroup> = particles.iter().map(|(_, g)| g).collect();
        super::packing_geometry::validate(container.as_ref(), &groups, &packing, &mut errors);
    }
    if let Some(r) = &record {
        check(&mut errors, r.every >= 1, "record.every", || {
            format!("must be >= 1, got {}", r.every)
        });
    }
    validate_fibres(&fibres, external_field.as_ref(), &mut errors);
    match (simulation, container, errors.is_empty()) {
        (simulation, container, true)
            if field_only
                || (simulation.is_some() && (container.is_some() || is_brownian || is_pf)) =>
        {
            Ok(Scene {
                text: text.to_string(),
                simulation,
                container,
                fibres: fibres.into_iter().map(|(_, f)| f).collect(),
                external_field,
                particles: particles.into_iter().map(|(_, g)| g).collect(),
                packing,
                record,
                brownian,
                particle_fluid,
                extensions,
            })
        }
        _ => Err(errors),
    }
}
