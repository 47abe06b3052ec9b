//! The `[trap]` scene section and the `start` particle key: typing, validation (every error
//! at its innermost key path) and the run parameters derived from them. SI units throughout.
//!
//! ```toml
//! [simulation]
//! pipeline = "langevin_trap"
//! seed = 1
//!
//! [trap]
//! stiffness = 1e-6        # k [N/m]
//! centre = [0.0, 0.0, 0.0] # x0 [m] (default the origin)
//! temperature = 293.0     # T [K]
//! viscosity = 1.0e-3      # η [Pa s]
//! time_step = 1e-3        # Δt [s]
//! duration = 2.0          # [s]
//! record_every = 20       # [steps] (optional)
//! equilibration = 0.05    # [s] (optional, default 5 γ/k)
//!
//! [[particles]]
//! count = 500
//! shape = { kind = "sphere", radius = 0.5e-6 }
//! start = [1e-7, 0.0, 0.0] # [m] (optional, default the centre)
//! ```

use magsep::components::brownian::BOLTZMANN;
use magsep::glam::DVec3;
use magsep::scene::checks::{check, finite_positive, typed};
use magsep::scene::{ParseContext, Scene, SceneError, ShapeSpec};
use magsep::toml;
use serde::{Deserialize, Serialize};

/// The pipeline's name in `[simulation] pipeline = "..."`.
pub const PIPELINE: &str = "langevin_trap";

/// The top-level table this pipeline owns.
pub const SECTION: &str = "trap";

/// The `[[particles]]` key this pipeline reads beyond `count` and `shape`.
pub const START_KEY: &str = "start";

/// Largest number of steps of one run (beyond it `duration / time_step` is surely a typo).
pub const MAX_STEPS: f64 = 1e12;

/// `[trap]`, as written in the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrapSection {
    /// Trap stiffness k \[N/m\]. Range: finite, > 0.
    pub stiffness: f64,
    /// Trap centre x0 \[m\]. Default: the origin.
    #[serde(default)]
    pub centre: [f64; 3],
    /// Temperature T \[K\]. Range: finite, > 0.
    pub temperature: f64,
    /// Dynamic viscosity η of the fluid \[Pa s\]. Range: finite, > 0.
    pub viscosity: f64,
    /// Time step Δt \[s\]. Range: finite, > 0. The update is exact for any Δt.
    pub time_step: f64,
    /// Simulated time \[s\]; the run has `round(duration / time_step)` steps (>= 1).
    pub duration: f64,
    /// Steps between samples of the statistics and recorded frames. Default: `[record]
    /// every` if given, else one correlation time `γ/k` of the slowest particle in steps.
    #[serde(default)]
    pub record_every: Option<u64>,
    /// Time discarded before sampling \[s\] (particles relax from `start`). Default: five
    /// correlation times `5 γ/k` of the slowest particle. Range: finite, >= 0, < duration.
    #[serde(default)]
    pub equilibration: Option<f64>,
}

/// What [`parse`] returns (kept in the [`Scene`]): the section and one start point per
/// `[[particles]]` entry, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct TrapScene {
    /// `[trap]`.
    pub trap: TrapSection,
    /// `start` \[m\] of each particle group (the centre where absent).
    pub starts: Vec<DVec3>,
}

/// Friction coefficient γ = 6 π η a of a sphere of radius `radius` \[m\] in a fluid of
/// viscosity `viscosity` \[Pa s\], in \[kg/s\] (Stokes drag).
pub fn friction(viscosity: f64, radius: f64) -> f64 {
    6.0 * std::f64::consts::PI * viscosity * radius
}

/// Run parameters derived from the scene (a resource of the world, see
/// [`crate::dynamics`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrapParams {
    /// k \[N/m\].
    pub stiffness: f64,
    /// x0 \[m\].
    pub centre: DVec3,
    /// k_B T \[J\].
    pub kt: f64,
    /// Δt \[s\].
    pub dt: f64,
    /// Steps of the run.
    pub steps: u64,
    /// Steps between samples (and recorded frames).
    pub sample_every: u64,
    /// First step that is sampled (steps before it are equilibration).
    pub first_sample: u64,
}

impl TrapParams {
    /// The parameters of `trap` for particles of largest radius `max_radius` \[m\], with the
    /// scene's `[record] every` if given.
    pub fn new(trap: &TrapSection, max_radius: f64, record_every: Option<u64>) -> Self {
        let tau = friction(trap.viscosity, max_radius) / trap.stiffness;
        let dt = trap.time_step;
        let steps = (trap.duration / dt).round().max(1.0) as u64;
        let sample_every = trap
            .record_every
            .or(record_every)
            .unwrap_or_else(|| ((tau / dt).round() as u64).max(1));
        let eq = trap.equilibration.unwrap_or(5.0 * tau);
        // the first multiple of `sample_every` at or after the equilibration time (never 0)
        // (`as` saturates; past the last step nothing is sampled anyway)
        let eq_steps = ((eq / dt).ceil() as u64).clamp(1, steps.saturating_add(1));
        let first_sample = eq_steps.div_ceil(sample_every).saturating_mul(sample_every);
        Self {
            stiffness: trap.stiffness,
            centre: DVec3::from_array(trap.centre),
            kt: BOLTZMANN * trap.temperature,
            dt,
            steps,
            sample_every,
            first_sample,
        }
    }

    /// The parameters of a validated scene of this pipeline (`None` for another pipeline's).
    pub fn of_scene(scene: &Scene) -> Option<Self> {
        let s = scene.section::<TrapScene>()?;
        let max_radius = scene
            .particles
            .iter()
            .map(|g| g.shape.shape().radius())
            .fold(0.0, f64::max);
        Some(Self::new(
            &s.trap,
            max_radius,
            scene.record.as_ref().map(|r| r.every),
        ))
    }

    /// The equilibrium variance per axis k_B T / k \[m²\].
    pub fn variance(&self) -> f64 {
        self.kt / self.stiffness
    }

    /// Whether the statistics are sampled after step `step`.
    pub fn is_sample_step(&self, step: u64) -> bool {
        step >= self.first_sample && step.is_multiple_of(self.sample_every)
    }
}

/// A point \[m\] at `path`: an array of three finite numbers (integers allowed). Every
/// problem is pushed at its innermost path (`path[i]` for a bad component).
fn point(errors: &mut Vec<SceneError>, value: &toml::Value, path: &str) -> Option<[f64; 3]> {
    let Some(items) = value.as_array() else {
        errors.push(SceneError::new(
            path,
            format!(
                "must be an array of 3 numbers [m], got a {}",
                value.type_str()
            ),
        ));
        return None;
    };
    if items.len() != 3 {
        errors.push(SceneError::new(
            path,
            format!(
                "must be an array of 3 numbers [m], got {} items",
                items.len()
            ),
        ));
        return None;
    }
    let before = errors.len();
    let mut p = [0.0; 3];
    for (i, item) in items.iter().enumerate() {
        let x = match item {
            toml::Value::Float(x) => *x,
            toml::Value::Integer(n) => *n as f64,
            other => {
                errors.push(SceneError::new(
                    format!("{path}[{i}]"),
                    format!("must be a number, got a {}", other.type_str()),
                ));
                continue;
            }
        };
        check(errors, x.is_finite(), &format!("{path}[{i}]"), || {
            format!("must be a finite number, got {x}")
        });
        p[i] = x;
    }
    (errors.len() == before).then_some(p)
}

/// `[trap]` typed; `centre` is checked by [`point`] (for key paths like `trap.centre[1]`).
fn trap_section(cx: &mut ParseContext<'_>) -> Option<TrapSection> {
    let mut table = cx.required::<toml::Table>(SECTION, PIPELINE)?;
    let centre = match table.remove("centre") {
        None => Some([0.0; 3]),
        Some(v) => point(cx.errors, &v, &format!("{SECTION}.centre")),
    };
    let section = typed::<TrapSection>(&toml::Value::Table(table), SECTION, cx.errors);
    let (mut section, centre) = (section?, centre?);
    section.centre = centre;
    Some(section)
}

/// Type and check `[trap]` and each group's `start`, pushing every problem at its key path.
pub fn parse(cx: &mut ParseContext<'_>) -> Option<TrapScene> {
    let trap = trap_section(cx);
    let mut ok = trap.is_some();
    if let Some(t) = &trap {
        let before = cx.errors.len();
        for (key, v) in [
            ("stiffness", t.stiffness),
            ("temperature", t.temperature),
            ("viscosity", t.viscosity),
            ("time_step", t.time_step),
            ("duration", t.duration),
        ] {
            finite_positive(cx.errors, &format!("{SECTION}.{key}"), v);
        }
        if cx.errors.len() == before {
            let steps = t.duration / t.time_step;
            check(
                cx.errors,
                (0.5..=MAX_STEPS).contains(&steps),
                &format!("{SECTION}.duration"),
                || {
                    format!(
                        "must give between 1 and {MAX_STEPS:e} steps of time_step = {} s, got {steps:e}",
                        t.time_step
                    )
                },
            );
        }
        if let Some(n) = t.record_every {
            check(
                cx.errors,
                n >= 1,
                &format!("{SECTION}.record_every"),
                || format!("must be >= 1, got {n}"),
            );
            let common = cx
                .table
                .get("record")
                .and_then(|r| r.get("every"))
                .and_then(|e| e.as_integer());
            if let Some(every) = common.filter(|&e| e != n as i64) {
                cx.error(
                    format!("{SECTION}.record_every"),
                    format!("conflicts with record.every = {every}: give one of them"),
                );
            }
        }
        if let Some(eq) = t.equilibration {
            check(
                cx.errors,
                eq.is_finite() && eq >= 0.0 && eq < t.duration,
                &format!("{SECTION}.equilibration"),
                || {
                    format!(
                        "must be a finite number >= 0 and < duration = {} s, got {eq}",
                        t.duration
                    )
                },
            );
        }
        ok &= cx.errors.len() == before;
    }
    let centre = trap.as_ref().map(|t| t.centre).unwrap_or_default();
    let mut starts = Vec::with_capacity(cx.particles.len());
    let groups: Vec<(usize, ShapeSpec, Option<toml::Value>)> = cx
        .particles
        .iter()
        .map(|(i, g)| (*i, g.shape, g.extra.get(START_KEY).cloned()))
        .collect();
    for (i, shape, start) in groups {
        let path = format!("particles[{i}]");
        if !matches!(shape, ShapeSpec::Sphere { .. }) {
            cx.error(
                format!("{path}.shape.kind"),
                "the langevin_trap pipeline simulates spheres only",
            );
            ok = false;
        }
        let start = match start {
            None => Some(centre),
            Some(v) => point(cx.errors, &v, &format!("{path}.{START_KEY}")),
        };
        match start {
            Some(p) => starts.push(DVec3::from_array(p)),
            None => ok = false,
        }
    }
    if let Some(t) = trap.as_ref().filter(|t| ok && t.equilibration.is_none()) {
        // the default equilibration must leave time to sample
        let max_radius = cx
            .particles
            .iter()
            .map(|(_, g)| g.shape.shape().radius())
            .fold(0.0, f64::max);
        let eq = 5.0 * friction(t.viscosity, max_radius) / t.stiffness;
        if eq.is_finite() && eq >= t.duration {
            cx.error(
                format!("{SECTION}.duration"),
                format!(
                    "must exceed the default equilibration 5 γ/k = {eq:e} s of the largest \
                     sphere (set trap.equilibration to sample earlier), got {}",
                    t.duration
                ),
            );
            ok = false;
        }
    }
    match trap {
        Some(trap) if ok => Some(TrapScene { trap, starts }),
        _ => None,
    }
}
