//! `[brownian]` and the Brownian keys of `[[particles]]` (`moment`, `placement`): Brownian
//! dynamics around magnetised fibres (thesis 000, ch. 6). SI units.
//!
//! ```toml
//! [simulation]
//! pipeline = "brownian"
//! seed = 1
//!
//! [brownian]
//! time_step = 5e-5          # dt [s] (outer step; the adaptive stepper bisects it as needed)
//! duration = 50.0           # [s]
//! runs = 30                 # independent replicates, run in parallel
//! temperature = 298.0       # [K]
//! viscosity = 1.0e-3        # [Pa s]
//! mobility = "auto"         # free_draining | cholesky | tea | krylov | spectral_ewald | auto
//! ewald_tolerance = 1e-6    # relative accuracy of the spectral_ewald product, [1e-12, 0.1]
//! step_control = { kind = "adaptive", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }
//! contact = { kind = "mie", epsilon_kt = 100.0, n = 30.0, m = 15.0 }   # or hard_core, none
//! dipole_cutoff = 30.0      # in mean radii of the pair; 0 switches dipole forces off
//! captured_interact = true  # captured particles keep exerting dipole/contact forces
//! flow = { kind = "uniform", velocity = [0.0, 0.0, -1e-3] }  # mean liquid velocity [m/s]
//!
//! [[particles]]
//! count = 100
//! shape = { kind = "sphere", radius = 75e-9 }
//! moment = { kind = "saturated", moment = 0.87e-16 }      # [A m²]
//! placement = { kind = "fibre_top", fibre = 0, gap = 1e-6, height = 300e-6 }
//! ```
//!
//! Start regions (the thesis's TOP and SIDE, fig. 6.2, whose sizes it does not give):
//! * `fibre_top`: centres uniform in the disc-shaped slab above the `+axis` end face of fibre
//!   `fibre`, with the fibre's radius, from `gap` to `gap + height` above the face.
//! * `fibre_side`: centres uniform in the annulus around the lateral surface, from `gap` to
//!   `gap + thickness` off the surface, over the fibre's length.
//! * `box`: uniform in an axis-aligned box `min`..`max`. `points`: explicit centres.
//!
//! Particles do not overlap each other at the start (rejection sampling per particle).

use magsep_components::brownian::{
    BrownianConfig, ContactModel, MobilityChoice, MomentModel, StepControl,
};
use serde::{Deserialize, Serialize};

use super::flow::{BrownianFlow, validate_flow};
use crate::scene::checks::{LENGTH_RANGE, VISCOSITY_RANGE, num, num4, within};
use crate::scene::{FibreSpec, PlacementSpec, SceneError};

/// Temperatures accepted \[K\] (a temperature near 0 switches the noise off, for
/// deterministic checks).
pub const TEMPERATURE_RANGE: (f64, f64) = (1e-20, 1e4);
/// The largest magnetisation a particle's moment may imply \[A/m\]: m / V at most this
/// (iron saturates at 1.7e6 A/m; no material exceeds 2e6 A/m).
pub const MAX_MAGNETISATION: f64 = 2e6;
/// Start regions: their extents (gap, height, thickness) at most this \[m\], and box
/// corners and points within this distance of the origin (the fibres' range too).
pub const MAX_REGION: f64 = LENGTH_RANGE.1;

/// `[brownian]`: every key but `time_step` and `duration` optional.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrownianSection {
    /// Outer time step dt \[s\]. Range (0, 1].
    pub time_step: f64,
    /// Simulated time \[s\]. Range [dt, 1e6].
    pub duration: f64,
    /// Independent replicates. Default 1. Range 1..=10000.
    #[serde(default)]
    pub runs: Option<u64>,
    /// Temperature \[K\]. Default 298.
    #[serde(default)]
    pub temperature: Option<f64>,
    /// Viscosity [Pa s]. Default 1e-3 (water).
    #[serde(default)]
    pub viscosity: Option<f64>,
    /// Mobility. Default `auto`.
    #[serde(default)]
    pub mobility: Option<MobilityChoice>,
    /// Krylov tolerance. Default 1e-6. Range (0, 0.1].
    #[serde(default)]
    pub krylov_tolerance: Option<f64>,
    /// Relative accuracy of the `spectral_ewald` mobility product. Default 1e-6.
    /// Range [1e-12, 0.1].
    #[serde(default)]
    pub ewald_tolerance: Option<f64>,
    /// Time stepping. Default adaptive (tolerance 1e-2, max_displacement 0.5, max_depth 24).
    #[serde(default)]
    pub step_control: Option<StepControl>,
    /// Excluded volume. Default Mie(30, 15) with ε = 100 k_B T.
    #[serde(default)]
    pub contact: Option<ContactModel>,
    /// Dipole cut-off in mean radii of a pair; 0 switches dipole forces off. Default 30.
    #[serde(default)]
    pub dipole_cutoff: Option<f64>,
    /// Whether captured particles keep exerting pair forces. Default true.
    #[serde(default)]
    pub captured_interact: Option<bool>,
    /// Capture-curve sampling interval in steps. Default: steps / 200 (at least 1).
    #[serde(default)]
    pub observe_every: Option<u64>,
    /// Relative field-patch size ε in [1e-6, 0.5]; default: the exact field everywhere.
    #[serde(default)]
    pub field_patch: Option<f64>,
    /// Mean flow of the liquid (`[brownian.flow]`, see [`super::flow`]). Default: none.
    #[serde(default)]
    pub flow: Option<BrownianFlow>,
}

impl BrownianSection {
    /// Number of outer steps.
    pub fn steps(&self) -> u64 {
        (self.duration / self.time_step).round().max(1.0) as u64
    }

    /// The configuration with every default resolved.
    pub fn config(&self) -> BrownianConfig {
        let steps = self.steps();
        BrownianConfig {
            temperature: self.temperature.unwrap_or(298.0),
            viscosity: self.viscosity.unwrap_or(1e-3),
            steps,
            mobility: self.mobility.unwrap_or_default(),
            krylov_tolerance: self.krylov_tolerance.unwrap_or(1e-6),
            ewald_tolerance: self.ewald_tolerance.unwrap_or(1e-6),
            step_control: self.step_control.unwrap_or_default(),
            contact: self.contact.unwrap_or_default(),
            dipole_cutoff: match self.dipole_cutoff {
                Some(0.0) => None,
                Some(c) => Some(c),
                None => Some(30.0),
            },
            captured_interact: self.captured_interact.unwrap_or(true),
            observe_every: self.observe_every.unwrap_or((steps / 200).max(1)),
            field_patch: self.field_patch,
            flow: self.flow.map_or([0.0; 3], |f| {
                f.velocity(self.viscosity.unwrap_or(1e-3)).to_array()
            }),
            flow_around_fibres: self.flow.is_some_and(|f| f.around_fibres()),
        }
    }

    /// Replicates.
    pub fn runs(&self) -> u64 {
        self.runs.unwrap_or(1)
    }
}

fn positive(errors: &mut Vec<SceneError>, path: &str, v: f64, unit: &str) {
    if !(v.is_finite() && v > 0.0) {
        errors.push(SceneError::new(
            path,
            format!("must be a finite number > 0{unit}, got {}", num(v)),
        ));
    }
}

/// Check `[brownian]`.
pub fn validate_section(b: &BrownianSection, errors: &mut Vec<SceneError>) {
    positive(errors, "brownian.time_step", b.time_step, " [s]");
    if b.time_step > 1.0 {
        errors.push(SceneError::new(
            "brownian.time_step",
            format!("must be <= 1 s, got {}", num(b.time_step)),
        ));
    }
    positive(errors, "brownian.duration", b.duration, " [s]");
    if b.time_step > 0.0 && b.duration.is_finite() {
        let steps = b.duration / b.time_step;
        if !(0.5..=1e11).contains(&steps) {
            errors.push(SceneError::new(
                "brownian.duration",
                format!("must give 1 to 1e11 steps of time_step, got {steps:.3e}"),
            ));
        }
    }
    if let Some(r) = b.runs
        && !(1..=10_000).contains(&r)
    {
        errors.push(SceneError::new(
            "brownian.runs",
            format!("must be in 1..=10000, got {r}"),
        ));
    }
    if let Some(t) = b.temperature {
        let (lo, hi) = TEMPERATURE_RANGE;
        within(errors, "brownian.temperature", t, lo, hi, "[K]");
    }
    if let Some(v) = b.viscosity {
        let (lo, hi) = VISCOSITY_RANGE;
        within(errors, "brownian.viscosity", v, lo, hi, "[Pa s]");
    }
    if let Some(e) = b.field_patch
        && !(1e-6..=0.5).contains(&e)
    {
        errors.push(SceneError::new(
            "brownian.field_patch",
            format!("must be in [1e-6, 0.5], got {e}"),
        ));
    }
    if let Some(flow) = &b.flow {
        validate_flow(flow, b.viscosity.unwrap_or(1e-3), errors);
    }
    if let Some(t) = b.krylov_tolerance
        && !(t.is_finite() && t > 0.0 && t <= 0.1)
    {
        errors.push(SceneError::new(
            "brownian.krylov_tolerance",
            format!("must be in (0, 0.1], got {t}"),
        ));
    }
    if let Some(t) = b.ewald_tolerance
        && !(t.is_finite() && (1e-12..=0.1).contains(&t))
    {
        errors.push(SceneError::new(
            "brownian.ewald_tolerance",
            format!("must be in [1e-12, 0.1], got {t}"),
        ));
    }
    if let Some((tolerance, max_displacement, max_depth)) =
        b.step_control.and_then(|c| c.adaptive_parameters())
    {
        let p = "brownian.step_control";
        if !(tolerance.is_finite() && tolerance > 0.0 && tolerance <= 1.0) {
            errors.push(SceneError::new(
                format!("{p}.tolerance"),
                format!("must be in (0, 1], got {tolerance}"),
            ));
        }
        if !(max_displacement.is_finite() && max_displacement > 0.0 && max_displacement <= 10.0) {
            errors.push(SceneError::new(
                format!("{p}.max_displacement"),
                format!("must be in (0, 10], got {max_displacement}"),
            ));
        }
        if !(1..=40).contains(&max_depth) {
            errors.push(SceneError::new(
                format!("{p}.max_depth"),
                format!("must be in 1..=40, got {max_depth}"),
            ));
        }
    }
    if let Some(ContactModel::Mie { epsilon_kt, n, m }) = b.contact {
        let p = "brownian.contact";
        if !(epsilon_kt.is_finite() && epsilon_kt > 0.0 && epsilon_kt <= 1e6) {
            errors.push(SceneError::new(
                format!("{p}.epsilon_kt"),
                format!("must be in (0, 1e6], got {epsilon_kt}"),
            ));
        }
        if !(m.is_finite() && n.is_finite() && m > 0.0 && n > m && n <= 200.0) {
            errors.push(SceneError::new(
                format!("{p}.n"),
                format!("exponents must satisfy 0 < m < n <= 200, got n = {n}, m = {m}"),
            ));
        }
    }
    if let Some(c) = b.dipole_cutoff
        && !(c.is_finite() && (c == 0.0 || (2.0..=1000.0).contains(&c)))
    {
        errors.push(SceneError::new(
            "brownian.dipole_cutoff",
            format!("must be 0 (off) or in [2, 1000] mean radii, got {c}"),
        ));
    }
    if b.observe_every == Some(0) {
        errors.push(SceneError::new(
            "brownian.observe_every",
            "must be >= 1, got 0",
        ));
    }
}

/// Check a group's `moment` and `placement` (`p` is `particles[i]`, `radius` its radius).
pub fn validate_group(
    p: &str,
    count: u64,
    radius: f64,
    moment: Option<&MomentModel>,
    placement: Option<&PlacementSpec>,
    fibres: Option<&[FibreSpec]>,
    errors: &mut Vec<SceneError>,
) {
    // a moment above MAX_MAGNETISATION times the particle's volume is not a material's
    let volume = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let largest = MAX_MAGNETISATION * volume;
    // without a valid radius (reported at the shape) there is no upper bound to state
    let radius_ok = radius.is_finite() && radius > 0.0;
    let moment_in_range = |errors: &mut Vec<SceneError>, key: &str, m: f64| {
        if !(m.is_finite() && m > 0.0 && (!radius_ok || m <= largest)) {
            let bound = if radius_ok {
                format!(
                    "in (0, {}] [A m²] (a sphere of radius {} m magnetised at {} A/m)",
                    num4(largest),
                    num(radius),
                    num(MAX_MAGNETISATION)
                )
            } else {
                "positive and finite [A m²] (its upper bound follows from the radius)".into()
            };
            errors.push(SceneError::new(
                format!("{p}.moment.{key}"),
                format!("must be {bound}, got {}", num(m)),
            ));
        }
    };
    match moment {
        Some(MomentModel::Saturated { moment }) => moment_in_range(errors, "moment", *moment),
        Some(MomentModel::Langevin {
            moment,
            domain_moment,
        }) => {
            moment_in_range(errors, "moment", *moment);
            moment_in_range(errors, "domain_moment", *domain_moment);
        }
        // optional: a group without `moment` is non-magnetic (as `kind = "none"`)
        Some(MomentModel::None) | None => {}
    }
    let Some(placement) = placement else {
        errors.push(SceneError::new(
            format!("{p}.placement"),
            "missing required key (the brownian pipeline needs a start region)",
        ));
        return;
    };
    let q = format!("{p}.placement");
    // `fibres` is None when a fibre entry is invalid: its errors say enough
    let check_fibre = |k: usize, errors: &mut Vec<SceneError>| {
        if let Some(fibres) = fibres
            && k >= fibres.len()
        {
            errors.push(SceneError::new(
                format!("{q}.fibre"),
                format!("no fibre {k}: the scene has {} [[fibres]]", fibres.len()),
            ));
        }
    };
    let extent = |errors: &mut Vec<SceneError>, key: &str, v: f64| {
        within(
            errors,
            &format!("{q}.{key}"),
            v,
            LENGTH_RANGE.0,
            MAX_REGION,
            "[m]",
        )
    };
    match placement {
        PlacementSpec::Box { min, max } => {
            for (key, corner) in [("min", min), ("max", max)] {
                for (k, &v) in corner.iter().enumerate() {
                    within(
                        errors,
                        &format!("{q}.{key}[{k}]"),
                        v,
                        -MAX_REGION,
                        MAX_REGION,
                        "[m]",
                    );
                }
            }
            if !(0..3).all(|k| max[k] > min[k]) {
                errors.push(SceneError::new(
                    format!("{q}.max"),
                    format!("must exceed min on every axis, got min {min:?}, max {max:?}"),
                ));
            } else if let Some(fibres) = fibres
                && let Some(k) = crate::scene::box_region::box_inside_fibre(
                    glam::DVec3::from_array(*min),
                    glam::DVec3::from_array(*max),
                    fibres,
                    radius,
                )
            {
                errors.push(SceneError::new(
                    q.clone(),
                    crate::scene::box_region::inside_fibre_message(k, &num(radius)),
                ));
            }
        }
        PlacementSpec::FibreTop { fibre, gap, height } => {
            check_fibre(*fibre, errors);
            extent(errors, "height", *height);
            extent(errors, "gap", *gap);
            if !(gap.is_finite() && *gap > radius) {
                errors.push(SceneError::new(
                    format!("{q}.gap"),
                    format!(
                        "must exceed the particle radius {} m, got {}",
                        num(radius),
                        num(*gap)
                    ),
                ));
            }
        }
        PlacementSpec::FibreSide {
            fibre,
            gap,
            thickness,
        } => {
            check_fibre(*fibre, errors);
            extent(errors, "thickness", *thickness);
            extent(errors, "gap", *gap);
            if !(gap.is_finite() && *gap > radius) {
                errors.push(SceneError::new(
                    format!("{q}.gap"),
                    format!(
                        "must exceed the particle radius {} m, got {}",
                        num(radius),
                        num(*gap)
                    ),
                ));
            }
        }
        PlacementSpec::Injection { .. } => errors.push(SceneError::new(
            format!("{q}.kind"),
            "injection is for the particle_fluid pipeline",
        )),
        PlacementSpec::Points { positions } => {
            if positions.len() as u64 != count {
                errors.push(SceneError::new(
                    format!("{q}.positions"),
                    format!("must hold count = {count} points, got {}", positions.len()),
                ));
            }
            if let Some(k) = positions
                .iter()
                .position(|p| !p.iter().all(|v| v.is_finite() && v.abs() <= MAX_REGION))
            {
                errors.push(SceneError::new(
                    format!("{q}.positions[{k}]"),
                    format!("must be three finite numbers in [-{MAX_REGION}, {MAX_REGION}] [m]"),
                ));
            }
            crate::scene::placement::check_overlap(&q, positions, radius, errors);
        }
    }
}
