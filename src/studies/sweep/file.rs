//! The sweep file (TOML): format, validation with key paths, and its points.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml_edit::Value;

use crate::scene::overrides::{KeyPath, Override, lookup, parse_document};
use crate::scene::{SceneError, SceneErrors};

/// Most points a sweep may have.
pub const MAX_POINTS: usize = 1_000_000;

/// `range = { start, stop, step }`, `linspace`/`logspace = { start, stop, num }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RangeSpec {
    start: toml::Value,
    stop: toml::Value,
    step: toml::Value,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpaceSpec {
    start: f64,
    stop: f64,
    num: u64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisSpec {
    path: String,
    name: Option<String>,
    unit: Option<String>,
    values: Option<Vec<toml::Value>>,
    range: Option<RangeSpec>,
    linspace: Option<SpaceSpec>,
    logspace: Option<SpaceSpec>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepSpec {
    scene: String,
    #[serde(default)]
    axes: Vec<AxisSpec>,
    #[serde(default)]
    zip: Vec<Vec<String>>,
    replicates: Option<u64>,
    seed: Option<u64>,
    seed_key: Option<String>,
    #[serde(default)]
    collect: Vec<String>,
    #[serde(default)]
    curves: Vec<CurveSpec>,
}

/// `[[curves]]`: a pair of summary arrays, averaged over replicates point by point.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveSpec {
    x: String,
    y: String,
    name: Option<String>,
    x_unit: Option<String>,
}

/// A curve collected from every point's summary: `y` against `x`, both arrays of numbers.
#[derive(Debug, Clone)]
pub struct Curve {
    /// File name stem and chart title (`name`, default the `y` path).
    pub name: String,
    /// Summary path of the x array (as written, path).
    pub x: (String, KeyPath),
    /// Summary path of the y array (as written, path).
    pub y: (String, KeyPath),
    /// Unit of x for the chart label.
    pub x_unit: Option<String>,
}

/// One axis: the override path and its values.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Column name (`name`, default the path).
    pub name: String,
    /// The scene key the axis sets.
    pub path: KeyPath,
    /// Unit for labels (`unit`, optional).
    pub unit: Option<String>,
    /// The values, in order.
    pub values: Vec<Value>,
    /// Whether the axis is logarithmic (`logspace`): charts use a log x axis.
    pub log: bool,
}

/// One point of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// 0-based index (the point's directory name).
    pub index: usize,
    /// Index into each axis' values.
    pub values: Vec<usize>,
    /// Replicate index (0-based).
    pub replicate: u64,
    /// The seed set at the seed key (`None`: the scene's own).
    pub seed: Option<u64>,
}

/// A validated sweep.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The sweep file's text.
    pub sweep_text: String,
    /// The base scene's path (relative to the sweep file, resolved) and text.
    pub scene_path: PathBuf,
    /// The base scene's text.
    pub scene_text: String,
    /// The axes, in file order.
    pub axes: Vec<Axis>,
    /// Axes crossed in this order; the axes of one group are zipped.
    pub groups: Vec<Vec<usize>>,
    /// Replicates per combination of axis values.
    pub replicates: u64,
    /// The seed key and the base seed, when seeds are set (`replicates` or `seed` given).
    pub seed: Option<(KeyPath, u64)>,
    /// The scene's own seed at the seed key (when seeds are not set).
    pub scene_seed: Option<u64>,
    /// Collected summary values: (as written, path).
    pub collect: Vec<(String, KeyPath)>,
    /// Collected curves (`[[curves]]`).
    pub curves: Vec<Curve>,
}

fn err(path: impl Into<String>, msg: impl Into<String>) -> SceneError {
    SceneError::new(path, msg)
}

/// `v` as a number.
fn number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// The values of `range = { start, stop, step }` at `at`: integers when all three are, the
/// stop included when it is on the grid (within 1e-9 steps).
fn range_values(r: &RangeSpec, at: &str, errors: &mut Vec<SceneError>) -> Vec<Value> {
    if let (Some(a), Some(b), Some(s)) = (
        r.start.as_integer(),
        r.stop.as_integer(),
        r.step.as_integer(),
    ) {
        if s == 0 || (b - a).signum() * s.signum() < 0 {
            errors.push(err(
                format!("{at}.step"),
                format!("must be non-zero and lead from start {a} to stop {b}, got {s}"),
            ));
            return Vec::new();
        }
        let n = (b - a) / s + 1;
        if n as usize > MAX_POINTS {
            errors.push(err(at, format!("gives {n} values, more than {MAX_POINTS}")));
            return Vec::new();
        }
        return (0..n).map(|k| Value::from(a + k * s)).collect();
    }
    let mut nums = Vec::new();
    for (key, v) in [("start", &r.start), ("stop", &r.stop), ("step", &r.step)] {
        match number(v).filter(|x| x.is_finite()) {
            Some(x) => nums.push(x),
            None => errors.push(err(
                format!("{at}.{key}"),
                format!("must be a finite number, got {v}"),
            )),
        }
    }
    let [a, b, s] = nums[..] else {
        return Vec::new();
    };
    if s == 0.0 || (b - a) * s < 0.0 {
        errors.push(err(
            format!("{at}.step"),
            format!("must be non-zero and lead from start {a} to stop {b}, got {s}"),
        ));
        return Vec::new();
    }
    let n = ((b - a) / s + 1e-9).floor() + 1.0;
    if n > MAX_POINTS as f64 {
        errors.push(err(at, format!("gives {n} values, more than {MAX_POINTS}")));
        return Vec::new();
    }
    (0..n as u64)
        .map(|k| Value::from(a + k as f64 * s))
        .collect()
}

/// The values of `linspace` (`log`: `logspace`, start and stop are values > 0, not
/// exponents) at `at`.
fn space_values(s: &SpaceSpec, log: bool, at: &str, errors: &mut Vec<SceneError>) -> Vec<Value> {
    let before = errors.len();
    for (key, v) in [("start", s.start), ("stop", s.stop)] {
        if !v.is_finite() || (log && v <= 0.0) {
            let rule = if log { "finite and > 0" } else { "finite" };
            errors.push(err(
                format!("{at}.{key}"),
                format!("must be {rule}, got {v}"),
            ));
        }
    }
    if s.num == 0 || s.num as usize > MAX_POINTS {
        errors.push(err(
            format!("{at}.num"),
            format!("must be in 1..={MAX_POINTS}, got {}", s.num),
        ));
    }
    if errors.len() > before {
        return Vec::new();
    }
    let (a, b) = if log {
        (s.start.ln(), s.stop.ln())
    } else {
        (s.start, s.stop)
    };
    (0..s.num)
        .map(|k| {
            let x = if s.num == 1 {
                a
            } else if k + 1 == s.num {
                b
            } else {
                a + (b - a) * k as f64 / (s.num - 1) as f64
            };
            // ends exact: the first and last values are start and stop as written
            Value::from(match (log, k) {
                (true, 0) => s.start,
                (true, k) if k + 1 == s.num => s.stop,
                (true, _) => x.exp(),
                (false, _) => x,
            })
        })
        .collect()
}

/// `v` (parsed by `toml`) as a `toml_edit` value.
fn edit_value(v: &toml::Value) -> Option<Value> {
    let mut t = toml::Table::new();
    t.insert("v".into(), v.clone());
    let doc = toml::to_string(&t)
        .ok()?
        .parse::<toml_edit::DocumentMut>()
        .ok()?;
    // a table value serialises as a `[v]` section: back to an inline table
    doc.get("v")?.clone().into_value().ok()
}

fn axis(spec: &AxisSpec, k: usize, errors: &mut Vec<SceneError>) -> Option<Axis> {
    let at = format!("axes[{k}]");
    let path = KeyPath::parse(&spec.path)
        .map_err(|e| errors.push(err(format!("{at}.path"), e)))
        .ok();
    let given = [
        spec.values.is_some(),
        spec.range.is_some(),
        spec.linspace.is_some(),
        spec.logspace.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        errors.push(err(
            &at,
            "needs exactly one of values, range, linspace or logspace",
        ));
        return None;
    }
    let values = if let Some(v) = &spec.values {
        if v.is_empty() {
            errors.push(err(format!("{at}.values"), "must not be empty"));
        }
        (v.iter().enumerate())
            .filter_map(|(j, x)| {
                let e = edit_value(x);
                if e.is_none() {
                    errors.push(err(
                        format!("{at}.values[{j}]"),
                        "not a value a scene can hold",
                    ));
                }
                e
            })
            .collect()
    } else if let Some(r) = &spec.range {
        range_values(r, &format!("{at}.range"), errors)
    } else if let Some(s) = &spec.linspace {
        space_values(s, false, &format!("{at}.linspace"), errors)
    } else if let Some(s) = &spec.logspace {
        space_values(s, true, &format!("{at}.logspace"), errors)
    } else {
        Vec::new()
    };
    Some(Axis {
        name: spec.name.clone().unwrap_or_else(|| spec.path.clone()),
        path: path?,
        unit: spec.unit.clone(),
        values,
        log: spec.logspace.is_some(),
    })
}

/// The crossing order: one group per axis, except that zipped axes share the group of the
/// first of them.
fn groups(spec: &SweepSpec, axes: &[Axis], errors: &mut Vec<SceneError>) -> Vec<Vec<usize>> {
    let mut group_of: Vec<Option<usize>> = vec![None; axes.len()];
    for (g, names) in spec.zip.iter().enumerate() {
        let mut first_len = None;
        for (j, name) in names.iter().enumerate() {
            let at = format!("zip[{g}][{j}]");
            let Some(a) = axes.iter().position(|a| &a.name == name) else {
                errors.push(err(at, format!("names no axis (`{name}`)")));
                continue;
            };
            if group_of[a].is_some() {
                errors.push(err(at, format!("axis `{name}` is zipped twice")));
                continue;
            }
            group_of[a] = Some(g);
            let len = axes[a].values.len();
            match first_len {
                None => first_len = Some(len),
                Some(l) if l != len => errors.push(err(
                    at,
                    format!("axis `{name}` has {len} values, the first axis of the zip {l}"),
                )),
                _ => {}
            }
        }
    }
    let mut out: Vec<Vec<usize>> = Vec::new();
    let mut placed: Vec<Option<usize>> = vec![None; spec.zip.len()];
    for (a, g) in group_of.iter().enumerate() {
        match g {
            Some(g) if placed[*g].is_some() => out[placed[*g].unwrap_or(0)].push(a),
            Some(g) => {
                placed[*g] = Some(out.len());
                out.push(vec![a]);
            }
            None => out.push(vec![a]),
        }
    }
    out
}

impl Sweep {
    /// Read and validate the sweep file at `path` and its base scene (the file only; see
    /// [`super::run::check_points`] for the points' scenes).
    ///
    /// # Errors
    /// Every problem at its key path (`scene` when the base scene cannot be read).
    pub fn load(path: &Path) -> Result<Self, SceneErrors> {
        let text =
            crate::input::read_scene_text(path).map_err(|e| SceneErrors(vec![err("(file)", e)]))?;
        let spec = parse_spec(&text)?;
        let dir = path.parent().unwrap_or(Path::new(""));
        let scene_path = dir.join(&spec.scene);
        let scene_text = crate::input::read_scene_text(&scene_path)
            .map_err(|e| SceneErrors(vec![err("scene", e)]))?;
        Self::build(spec, text, scene_path, scene_text)
    }

    /// The sweep of `sweep_text` with the base scene `scene_text` (e.g. from a sweep
    /// directory's manifest).
    ///
    /// # Errors
    /// As [`Sweep::load`].
    pub fn from_texts(
        sweep_text: &str,
        scene_path: PathBuf,
        scene_text: String,
    ) -> Result<Self, SceneErrors> {
        let spec = parse_spec(sweep_text)?;
        Self::build(spec, sweep_text.to_string(), scene_path, scene_text)
    }

    fn build(
        spec: SweepSpec,
        sweep_text: String,
        scene_path: PathBuf,
        scene_text: String,
    ) -> Result<Self, SceneErrors> {
        let mut errors = Vec::new();
        let axes: Vec<Axis> = (spec.axes.iter().enumerate())
            .filter_map(|(k, a)| axis(a, k, &mut errors))
            .collect();
        for (k, a) in axes.iter().enumerate() {
            if axes[..k].iter().any(|b| b.name == a.name) {
                errors.push(err(
                    format!("axes[{k}].name"),
                    format!("`{}` names two axes (give each a distinct name)", a.name),
                ));
            }
        }
        let groups = groups(&spec, &axes, &mut errors);
        let replicates = spec.replicates.unwrap_or(1);
        if replicates == 0 || replicates as usize > MAX_POINTS {
            errors.push(err(
                "replicates",
                format!("must be in 1..={MAX_POINTS}, got {replicates}"),
            ));
        }
        let seed_key = KeyPath::parse(spec.seed_key.as_deref().unwrap_or("simulation.seed"))
            .map_err(|e| errors.push(err("seed_key", e)))
            .ok();
        let collect = (spec.collect.iter().enumerate())
            .filter_map(|(k, c)| match KeyPath::parse(c) {
                Ok(p) => Some((c.clone(), p)),
                Err(e) => {
                    errors.push(err(format!("collect[{k}]"), e));
                    None
                }
            })
            .collect();
        let mut curves = Vec::new();
        for (k, c) in spec.curves.iter().enumerate() {
            let x = KeyPath::parse(&c.x).map_err(|e| errors.push(err(format!("curves[{k}].x"), e)));
            let y = KeyPath::parse(&c.y).map_err(|e| errors.push(err(format!("curves[{k}].y"), e)));
            let name = c.name.clone().unwrap_or_else(|| c.y.clone());
            if curves.iter().any(|d: &Curve| d.name == name) {
                errors.push(err(
                    format!("curves[{k}].name"),
                    format!("`{name}` names two curves (give each a distinct name)"),
                ));
            }
            if let (Ok(x), Ok(y)) = (x, y) {
                curves.push(Curve {
                    name,
                    x: (c.x.clone(), x),
                    y: (c.y.clone(), y),
                    x_unit: c.x_unit.clone(),
                });
            }
        }
        let doc = parse_document(&scene_text).map_err(|e| {
            SceneErrors(
                e.0.into_iter()
                    .map(|x| err("scene", format!("{}: {}", x.path, x.message)))
                    .collect(),
            )
        })?;
        let scene_seed = seed_key
            .as_ref()
            .and_then(|k| lookup(&doc, k))
            .and_then(|i| i.as_integer())
            .map(|s| s as u64);
        let combos = groups
            .iter()
            .map(|g| axes[g[0]].values.len().max(1))
            .try_fold(1usize, |n, l| n.checked_mul(l));
        if combos
            .and_then(|c| c.checked_mul(replicates as usize))
            .is_none_or(|n| n > MAX_POINTS)
        {
            errors.push(err(
                "axes",
                format!("the sweep has more than {MAX_POINTS} points"),
            ));
        }
        if !errors.is_empty() {
            return Err(SceneErrors(errors));
        }
        let seeded = spec.replicates.is_some() || spec.seed.is_some();
        let seed = seed_key
            .filter(|_| seeded)
            .map(|k| (k, spec.seed.or(scene_seed).unwrap_or(0)));
        Ok(Self {
            sweep_text,
            scene_path,
            scene_text,
            axes,
            groups,
            replicates,
            seed,
            scene_seed,
            collect,
            curves,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        let combos: usize = (self.groups.iter())
            .map(|g| self.axes[g[0]].values.len())
            .product();
        combos * self.replicates as usize
    }

    /// Whether the sweep has no points (an axis without values).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `index`: axis groups crossed in file order (the first slowest), replicates
    /// innermost; the seed of replicate r is the base seed + r (wrapping).
    pub fn point(&self, index: usize) -> Point {
        let reps = self.replicates as usize;
        let replicate = (index % reps) as u64;
        let mut combo = index / reps;
        let mut values = vec![0; self.axes.len()];
        for g in self.groups.iter().rev() {
            let len = self.axes[g[0]].values.len();
            for &a in g {
                values[a] = combo % len;
            }
            combo /= len;
        }
        Point {
            index,
            values,
            replicate,
            seed: self.seed.as_ref().map(|(_, b)| b.wrapping_add(replicate)),
        }
    }

    /// The overrides of `point`: one per axis, then the seed.
    pub fn overrides(&self, point: &Point) -> Vec<Override> {
        let mut out: Vec<Override> = (self.axes.iter().zip(&point.values))
            .map(|(a, &v)| Override::new(a.path.clone(), a.values[v].clone()))
            .collect();
        if let (Some((key, _)), Some(s)) = (&self.seed, point.seed) {
            out.push(Override::new(key.clone(), Value::from(s as i64)));
        }
        out
    }

    /// The seed of `point` as run: the sweep's or the scene's own.
    pub fn seed_of(&self, point: &Point) -> Option<u64> {
        point.seed.or(self.scene_seed)
    }
}

/// `text` parsed as a sweep file, with key paths on type errors.
fn parse_spec(text: &str) -> Result<SweepSpec, SceneErrors> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        SceneErrors(vec![err("(syntax)", e.to_string().trim().to_string())])
    })?;
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." { "(top)".into() } else { path };
        SceneErrors(vec![err(path, e.into_inner().to_string())])
    })
}

/// `v` as a CSV cell: strings bare, numbers in shortest round-trip form, else TOML text.
pub fn value_cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.value().clone(),
        Value::Float(f) => format!("{:?}", f.value()),
        Value::Integer(i) => i.value().to_string(),
        other => other.clone().decorated("", "").to_string(),
    }
}

/// `v` as a number (charts), if it is one.
pub fn value_number(v: &Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}
