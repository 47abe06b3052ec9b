//! Sweeps of the brownian capture studies: the thesis scenes compiled in, derived variants
//! (field angle, fibre half length, particle radius with its table 6.1 moment, reduced run
//! parameters), running them, and reading curves and fractions back from the summaries.

use serde_json::{Value, json};

use crate::scene::parse_scene;
use crate::sim::RunOptions;
use crate::studies::bench::BenchError;

/// `scenes/brownian_angle.toml` (L/D = 20, R = 75 nm, α = 45°, TOP and SIDE).
pub const ANGLE_SCENE: &str = include_str!("../../scenes/brownian_angle.toml");
/// `scenes/brownian_aspect.toml` (L/D = 5/3, R = 125 nm, α = 45°, TOP and SIDE).
pub const ASPECT_SCENE: &str = include_str!("../../scenes/brownian_aspect.toml");
/// `scenes/brownian_concentrated.toml` (N = 500, R = 75 nm, α = 0, box above the rim).
pub const CONCENTRATED_SCENE: &str = include_str!("../../scenes/brownian_concentrated.toml");

/// Thesis table 6.1: hydrodynamic radius R_h \[m\] and particle moment μ_s [A m²].
pub const TABLE_6_1: [(f64, f64); 6] = [
    (25e-9, 0.016e-16),
    (50e-9, 0.344e-16),
    (75e-9, 0.870e-16),
    (100e-9, 0.662e-16),
    (125e-9, 5.151e-16),
    (212e-9, 19.35e-16),
];

/// The table 6.1 moment [A m²] of radius `radius` \[m\] (`None` if it is not in the table).
pub fn table_moment(radius: f64) -> Option<f64> {
    TABLE_6_1
        .iter()
        .find(|(r, _)| (r - radius).abs() < 1e-12)
        .map(|(_, m)| *m)
}

/// What a sweep changes relative to its scene file (everything `None` keeps the file's value).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Variant {
    /// Angle between the fibre axis (z) and the 1 T field \[degrees\]; the field becomes
    /// `[sin α, 0, cos α]`.
    pub alpha_deg: Option<f64>,
    /// Particle radius \[m\] (every group), with its table 6.1 moment.
    pub radius: Option<f64>,
    /// Fibre half length \[m\] (fibre 0).
    pub half_length: Option<f64>,
}

/// Reduced run parameters (everything `None` keeps the file's value).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Reduction {
    /// Outer time step \[s\].
    pub time_step: Option<f64>,
    /// Simulated time \[s\].
    pub duration: Option<f64>,
    /// Replicates.
    pub runs: Option<u64>,
    /// Particles per group.
    pub count: Option<u64>,
    /// Mobility (`"free_draining"`, `"auto"`, ...).
    pub mobility: Option<String>,
    /// Adaptive step control: (tolerance, max_displacement), both in particle radii.
    pub adaptive: Option<(f64, f64)>,
    /// Capture-curve sampling interval in steps.
    pub observe_every: Option<u64>,
}

impl Reduction {
    /// A free-draining reduction with the chart's adaptive step control (tolerance 1e-2 and a
    /// 5-radius move limit, in radii).
    pub fn free_draining(
        time_step: f64,
        duration: f64,
        runs: u64,
        count: u64,
        observe_every: u64,
    ) -> Self {
        Self {
            time_step: Some(time_step),
            duration: Some(duration),
            runs: Some(runs),
            count: Some(count),
            mobility: Some("free_draining".into()),
            adaptive: Some((1e-2, 5.0)),
            observe_every: Some(observe_every),
        }
    }

    /// The reduction as JSON (for the printed summary and the sweep files).
    pub fn to_json(&self) -> Value {
        json!({
            "time_step_s": self.time_step,
            "duration_s": self.duration,
            "runs": self.runs,
            "particles_per_group": self.count,
            "mobility": self.mobility,
            "adaptive_tolerance_radii": self.adaptive.map(|a| a.0),
            "adaptive_max_displacement_radii": self.adaptive.map(|a| a.1),
        })
    }

    /// One line for a chart subtitle.
    pub fn describe(&self) -> String {
        let mut s = Vec::new();
        if let Some(n) = self.count {
            s.push(format!("N = {n}/region"));
        }
        if let Some(d) = self.duration {
            s.push(format!("t = {d} s"));
        }
        if let Some(dt) = self.time_step {
            s.push(format!("dt = {dt:e} s"));
        }
        if let Some((tol, disp)) = self.adaptive {
            s.push(format!("adaptive (tol {tol} R, max move {disp} R)"));
        }
        if let Some(r) = self.runs {
            s.push(format!("{r} runs"));
        }
        if let Some(m) = &self.mobility {
            s.push(m.replace('_', "-"));
        }
        s.join(", ")
    }
}

fn table_mut<'a>(v: &'a mut toml::Value, key: &str) -> Result<&'a mut toml::Table, BenchError> {
    v.get_mut(key)
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(|| BenchError::Runtime(format!("scene has no [{key}] table")))
}

/// The scene text `base` with `variant` and `reduction` applied (comments are dropped).
///
/// # Errors
/// [`BenchError::Runtime`] if `base` is not TOML or lacks the tables a sweep rewrites.
pub fn derive_scene(
    base: &str,
    variant: &Variant,
    reduction: &Reduction,
) -> Result<String, BenchError> {
    let mut doc: toml::Value =
        toml::from_str(base).map_err(|e| BenchError::Runtime(format!("scene: {e}")))?;
    if let Some(a) = variant.alpha_deg {
        let (s, c) = a.to_radians().sin_cos();
        let clean = |x: f64| if x.abs() < 1e-12 { 0.0 } else { x };
        let f = table_mut(&mut doc, "external_field")?;
        f.insert(
            "flux_density".into(),
            toml::Value::Array(vec![clean(s).into(), 0.0.into(), clean(c).into()]),
        );
    }
    if let Some(h) = variant.half_length {
        let fibres = doc
            .get_mut("fibres")
            .and_then(toml::Value::as_array_mut)
            .and_then(|a| a.first_mut())
            .and_then(toml::Value::as_table_mut)
            .ok_or_else(|| BenchError::Runtime("scene has no [[fibres]]".into()))?;
        fibres.insert("half_length".into(), h.into());
    }
    let groups = doc
        .get_mut("particles")
        .and_then(toml::Value::as_array_mut)
        .ok_or_else(|| BenchError::Runtime("scene has no [[particles]]".into()))?;
    for g in groups.iter_mut() {
        let g = g
            .as_table_mut()
            .ok_or_else(|| BenchError::Runtime("[[particles]] entry is not a table".into()))?;
        if let Some(r) = variant.radius {
            let m = table_moment(r)
                .ok_or_else(|| BenchError::Runtime(format!("radius {r} m is not in table 6.1")))?;
            let mut shape = toml::Table::new();
            shape.insert("kind".into(), "sphere".into());
            shape.insert("radius".into(), r.into());
            g.insert("shape".into(), toml::Value::Table(shape));
            let mut moment = toml::Table::new();
            moment.insert("kind".into(), "saturated".into());
            moment.insert("moment".into(), m.into());
            g.insert("moment".into(), toml::Value::Table(moment));
        }
        if let Some(n) = reduction.count {
            g.insert("count".into(), (n as i64).into());
        }
    }
    let b = table_mut(&mut doc, "brownian")?;
    if let Some(dt) = reduction.time_step {
        b.insert("time_step".into(), dt.into());
    }
    if let Some(d) = reduction.duration {
        b.insert("duration".into(), d.into());
    }
    if let Some(r) = reduction.runs {
        b.insert("runs".into(), (r as i64).into());
    }
    if let Some(m) = &reduction.mobility {
        b.insert("mobility".into(), m.as_str().into());
    }
    if let Some(e) = reduction.observe_every {
        b.insert("observe_every".into(), (e as i64).into());
    }
    if let Some((tol, disp)) = reduction.adaptive {
        let mut sc = toml::Table::new();
        sc.insert("kind".into(), "adaptive".into());
        sc.insert("tolerance".into(), tol.into());
        sc.insert("max_displacement".into(), disp.into());
        sc.insert("max_depth".into(), 24.into());
        b.insert("step_control".into(), toml::Value::Table(sc));
    }
    toml::to_string(&doc).map_err(|e| BenchError::Runtime(format!("scene: {e}")))
}

/// Parse and run a scene text for its `[brownian] runs` replicates; the ensemble summary.
///
/// # Errors
/// [`BenchError::Runtime`] on an invalid scene or a failed run.
pub fn run_scene_text(text: &str, seed: Option<u64>) -> Result<Value, BenchError> {
    let scene =
        parse_scene(text, &Default::default()).map_err(|e| BenchError::Runtime(e.to_string()))?;
    let runs = scene
        .section::<crate::pipelines::brownian::BrownianSection>()
        .map(|b| b.runs())
        .unwrap_or(1);
    let options = RunOptions {
        seed,
        forces_unread: true,
        ..RunOptions::default()
    };
    crate::pipelines::brownian::run_ensemble(&scene, runs, &options, &|_| {})
        .map_err(|e| BenchError::Runtime(e.to_string()))
}

/// A capture curve of a summary (`group` or all particles): (t, fraction, lo, hi).
pub fn curve_of(summary: &Value, group: Option<usize>) -> Vec<(f64, f64, f64, f64)> {
    let c = match group {
        Some(g) => &summary["groups"][g]["capture_curve"],
        None => &summary["capture_curve"],
    };
    let col = |k: &str| -> Vec<f64> {
        c[k].as_array()
            .map(|a| a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect())
            .unwrap_or_default()
    };
    let (t, f, lo, hi) = (
        col("time_s"),
        col("captured_fraction"),
        col("lo"),
        col("hi"),
    );
    (0..t.len().min(f.len()))
        .map(|i| {
            (
                t[i],
                f[i],
                lo.get(i).copied().unwrap_or(f[i]),
                hi.get(i).copied().unwrap_or(f[i]),
            )
        })
        .collect()
}

/// First time \[s\] at which a capture curve reaches `level` (`None` if never).
pub fn time_to(curve: &[(f64, f64, f64, f64)], level: f64) -> Option<f64> {
    curve.iter().find(|p| p.1 >= level - 1e-12).map(|p| p.0)
}

/// (mean, lo, hi) of a group's final captured fraction, or of the volume-weighted overall
/// fraction when `group` is `None` (its interval is the volume-weighted mean of the group
/// intervals, i.e. conservative: as if the groups' errors were fully correlated). Interval
/// ends are clipped to [0, 1] (a t interval from 2-3 runs can exceed them).
pub fn final_fraction(summary: &Value, group: Option<usize>, key: &str) -> (f64, f64, f64) {
    let get = |e: &Value| {
        (
            e["mean"].as_f64().unwrap_or(f64::NAN),
            e["lo"].as_f64().unwrap_or(f64::NAN),
            e["hi"].as_f64().unwrap_or(f64::NAN),
        )
    };
    if let Some(g) = group {
        let (m, lo, hi) = get(&summary["groups"][g][key]);
        return (m, lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0));
    }
    let groups = summary["groups"].as_array().cloned().unwrap_or_default();
    let mut acc = (0.0, 0.0, 0.0, 0.0);
    for g in &groups {
        let w = g["region_volume_m3"].as_f64().unwrap_or(0.0);
        let (m, lo, hi) = get(&g[key]);
        acc = (acc.0 + w, acc.1 + w * m, acc.2 + w * lo, acc.3 + w * hi);
    }
    let (m, lo, hi) = if acc.0 > 0.0 {
        (acc.1 / acc.0, acc.2 / acc.0, acc.3 / acc.0)
    } else {
        get(&summary[key])
    };
    (m, lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0))
}
