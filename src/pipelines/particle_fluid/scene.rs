//! The particle-fluid scene: `[particle_fluid]`, `[liquid]`, `[magnet]`, `[collisions]`, its
//! `[container]` kinds and the inertial keys of `[[particles]]` (thesis 002, ch. 1-2). SI
//! units; magsep's vertical is z (gravity along −z), the thesis's y.
//!
//! ```toml
//! [simulation]
//! pipeline = "particle_fluid"
//!
//! [particle_fluid]
//! time_step = 1e-3               # Δt [s]
//! duration = 10.0                # [s]
//! history = { kind = "window", window = 0.2 }   # or { kind = "full" }
//! terms = { history = true }     # every term on by default; switch any off
//!
//! [liquid]
//! density = 1403.0               # ρ_f [kg/m³]
//! viscosity = 5.54e-3            # μ [Pa s]
//! susceptibility = 7e-4          # χ (SI)
//!
//! [magnet]
//! kind = "bottom"                # bottom | top | two
//! surface_field = 422e3          # H₀ [A/m]
//! pole_size = 0.1181             # p [m]
//! half_height = 0.075            # L [m]: faces at y = ±L
//! # mid_plane = 0.075            # world z of y = 0; default: the container's mid-height
//!
//! [container]
//! kind = "tank"                  # closed box [0, edges] (or "channel", "unbounded")
//! edges = [0.15, 0.15, 0.15]
//!
//! [[particles]]
//! count = 1
//! shape = { kind = "sphere", radius = 2.5e-3 }
//! density = 1434.0               # ρ_p [kg/m³]
//! placement = { kind = "points", positions = [[0.075, 0.075, 0.0075]] }
//! ```

use glam::DVec3;
use magsep_systems::collision::{CollisionModel, Restitution};
use magsep_systems::fluid::collide::CollisionHistory;
use magsep_systems::fluid::config::{
    ForceTerms, HistoryChoice, Integrator, ParticleFluidConfig, STANDARD_GRAVITY,
};
use magsep_systems::fluid::drag::DragLaw;
use magsep_systems::fluid::flow::FlowModel;
use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
use serde::{Deserialize, Serialize};

use crate::scene::checks::{LENGTH_RANGE, check, finite_positive, within};
use crate::scene::{ParticleGroup, PlacementSpec, SceneError, ShapeSpec};

/// `[particle_fluid]`: every key but `time_step` and `duration` optional.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleFluidSection {
    /// Time step Δt \[s\]. Range (0, 1].
    pub time_step: f64,
    /// Simulated time \[s\]. Range: 1 to 1e9 steps.
    pub duration: f64,
    /// g [m/s²] along −z. Default 9.81. Range [0, 1000].
    #[serde(default)]
    pub gravity: Option<f64>,
    /// Terms of the equation of motion; each defaults to on.
    #[serde(default)]
    pub terms: ForceTerms,
    /// `schiller_naumann` (default) or `stokes`.
    #[serde(default)]
    pub drag_law: DragLaw,
    /// History kernel. Default a 0.2 s window with the exponential tail.
    #[serde(default)]
    pub history: HistoryChoice,
    /// `implicit` (default) or `explicit` (the thesis's forward Euler).
    #[serde(default)]
    pub integrator: Integrator,
    /// Levitation tolerance \[m\]. Default 0.5e-3 (thesis). Range > 0.
    #[serde(default)]
    pub levitation_tolerance: Option<f64>,
    /// Sample e_m every this many steps. Default steps / 200 (at least 1).
    #[serde(default)]
    pub observe_every: Option<u64>,
}

/// `[liquid]`: the carrier liquid and its undisturbed flow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiquidSection {
    /// ρ_f [kg/m³]. Range > 0.
    pub density: f64,
    /// μ [Pa s]. Range > 0.
    pub viscosity: f64,
    /// χ (SI volume susceptibility). Default 0. Range [-1, 10].
    #[serde(default)]
    pub susceptibility: f64,
    /// Undisturbed flow. Default quiescent.
    #[serde(default)]
    pub flow: FlowModel,
}

/// Which magnet arrangement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MagnetKind {
    /// Strong face at y = −L.
    Bottom,
    /// Strong face at y = +L.
    Top,
    /// Faces at y = ±L.
    Two,
}

/// `[magnet]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagnetSection {
    /// Arrangement.
    pub kind: MagnetKind,
    /// H₀ [A/m]. Range >= 0.
    pub surface_field: f64,
    /// Pole size p \[m\]. Range > 0.
    pub pole_size: f64,
    /// L \[m\]. Range > 0.
    pub half_height: f64,
    /// World z \[m\] of the model's y = 0. Default: the container's mid-height (0 unbounded).
    #[serde(default)]
    pub mid_plane: Option<f64>,
}

impl MagnetSection {
    /// The kernel model.
    pub fn model(&self) -> MagnetModel {
        let (surface_field, pole_size, half_height) =
            (self.surface_field, self.pole_size, self.half_height);
        match self.kind {
            MagnetKind::Bottom => MagnetModel::Bottom {
                surface_field,
                pole_size,
                half_height,
            },
            MagnetKind::Top => MagnetModel::Top {
                surface_field,
                pole_size,
                half_height,
            },
            MagnetKind::Two => MagnetModel::Two {
                surface_field,
                pole_size,
                half_height,
            },
        }
    }
}

/// `[collisions]`: every key optional (thesis ch. 2 defaults).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollisionsSection {
    /// Normal restitution. Default wet (Izard) with e_dry = 0.85, η_e = 1.5 µm.
    pub restitution: Option<Restitution>,
    /// Coulomb friction μ. Default 0.005.
    pub friction: Option<f64>,
    /// Tangential restitution e_t. Default 0.
    pub tangential_restitution: Option<f64>,
    /// Approaches slower than this are fully inelastic [m/s]. Default 0.01.
    pub rest_speed: Option<f64>,
    /// What a collision does to the Basset history: `reset` (thesis, default) or `keep`.
    pub history: Option<CollisionHistory>,
}

impl CollisionsSection {
    /// The model for `liquid`.
    pub fn model(&self, liquid: &LiquidSection) -> CollisionModel {
        let d = CollisionModel::default();
        CollisionModel {
            restitution: self.restitution.unwrap_or(d.restitution),
            tangential_restitution: self
                .tangential_restitution
                .unwrap_or(d.tangential_restitution),
            friction: self.friction.unwrap_or(d.friction),
            rest_speed: self.rest_speed.unwrap_or(d.rest_speed),
            fluid_density: liquid.density,
            kinematic_viscosity: liquid.viscosity / liquid.density,
        }
    }
}

/// The particle-fluid pipeline's `[container]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FluidContainerSpec {
    /// A channel between two walls z = 0 and z = `height`, periodic in x and y over `side`
    /// (the thesis's many-particle domain, with its y as our z).
    Channel {
        /// Periods along x and y \[m\]. Range > 4 particle diameters.
        side: [f64; 2],
        /// Wall distance \[m\]. Range > a particle diameter.
        height: f64,
    },
    /// A closed box [0, edges] (the experiment's tank).
    Tank {
        /// Edges along x, y, z \[m\]. Range > a particle diameter.
        edges: [f64; 3],
    },
    /// No walls, no periodicity.
    Unbounded {},
}

impl FluidContainerSpec {
    /// The box extent \[m\] (zero when unbounded).
    pub fn edges(&self) -> DVec3 {
        match self {
            Self::Channel { side, height } => DVec3::new(side[0], side[1], *height),
            Self::Tank { edges } => DVec3::from_array(*edges),
            Self::Unbounded {} => DVec3::ZERO,
        }
    }

    /// Fluid volume \[m³\] (infinite when unbounded).
    pub fn volume(&self) -> f64 {
        match self {
            Self::Unbounded {} => f64::INFINITY,
            _ => self.edges().element_product(),
        }
    }
}

/// Everything a particle-fluid scene adds, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleFluidScene {
    /// `[particle_fluid]`.
    pub section: ParticleFluidSection,
    /// `[liquid]`.
    pub liquid: LiquidSection,
    /// `[magnet]` (none: no magnetic buoyancy).
    pub magnet: Option<MagnetSection>,
    /// `[collisions]`.
    pub collisions: CollisionsSection,
    /// `[container]` (default unbounded).
    pub container: FluidContainerSpec,
}

impl ParticleFluidScene {
    /// Number of steps.
    pub fn steps(&self) -> u64 {
        (self.section.duration / self.section.time_step)
            .round()
            .max(1.0) as u64
    }

    /// The configuration with every default resolved.
    pub fn config(&self) -> ParticleFluidConfig {
        let s = &self.section;
        let steps = self.steps();
        let mid_default = 0.5 * self.container.edges().z;
        ParticleFluidConfig {
            dt: s.time_step,
            steps,
            gravity: s.gravity.unwrap_or(STANDARD_GRAVITY),
            mid_plane: self
                .magnet
                .as_ref()
                .and_then(|m| m.mid_plane)
                .unwrap_or(mid_default),
            liquid: Liquid {
                density: self.liquid.density,
                viscosity: self.liquid.viscosity,
                susceptibility: self.liquid.susceptibility,
            },
            magnet: self
                .magnet
                .as_ref()
                .map(|m| m.model())
                .unwrap_or(MagnetModel::None),
            flow: self.liquid.flow,
            terms: s.terms,
            drag_law: s.drag_law,
            history: s.history,
            integrator: s.integrator,
            levitation_tolerance: s.levitation_tolerance.unwrap_or(0.5e-3),
            observe_every: s.observe_every.unwrap_or((steps / 200).max(1)),
        }
    }
}

/// Number of particles of a group given by `volume_fraction`: floor(Φ V_fluid / V_p)
/// (thesis table 2.4: 8835, 70685, 17671).
pub fn count_from_volume_fraction(fraction: f64, fluid_volume: f64, radius: f64) -> u64 {
    let vp = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    (fraction * fluid_volume / vp).floor() as u64
}

/// Densities accepted, of liquids and particles \[kg/m³\] (osmium is 22.6e3).
pub const DENSITY_RANGE: (f64, f64) = (1.0, 3e4);
/// Viscosities accepted \[Pa s\].
pub const VISCOSITY_RANGE: (f64, f64) = (1e-6, 1e4);
/// Largest container edge, magnet size or position \[m\].
pub const MAX_EXTENT: f64 = 100.0;
/// Largest magnet surface field \[A/m\] (the strongest permanent magnets give about 1e6).
pub const MAX_FIELD: f64 = 1e8;
/// Largest flow or particle speed \[m/s\] (the model is Stokes-Oseen drag in a liquid).
pub const MAX_SPEED: f64 = 100.0;
/// Largest shear rate or flow frequency \[1/s\].
pub const MAX_RATE: f64 = 1e6;

/// The flow's values: finite, speeds at most [`MAX_SPEED`], rates at most [`MAX_RATE`].
fn flow_checks(flow: &FlowModel, errors: &mut Vec<SceneError>) {
    let speed = |errors: &mut Vec<SceneError>, key: &str, v: &[f64; 3]| {
        for (k, c) in v.iter().enumerate() {
            let path = format!("liquid.flow.{key}[{k}]");
            within(errors, &path, *c, -MAX_SPEED, MAX_SPEED, "[m/s]");
        }
    };
    match flow {
        FlowModel::Quiescent => {}
        FlowModel::Uniform { velocity } => speed(errors, "velocity", velocity),
        FlowModel::Shear { rate } => within(
            errors,
            "liquid.flow.rate",
            *rate,
            -MAX_RATE,
            MAX_RATE,
            "[1/s]",
        ),
        FlowModel::Oscillating {
            amplitude,
            frequency,
        } => {
            speed(errors, "amplitude", amplitude);
            within(
                errors,
                "liquid.flow.frequency",
                *frequency,
                1e-9,
                MAX_RATE,
                "[Hz]",
            );
        }
    }
}

/// Check the particle-fluid sections; resolve `count` from `volume_fraction`.
pub fn validate(
    pf: &ParticleFluidScene,
    groups: &mut [(usize, ParticleGroup)],
    errors: &mut Vec<SceneError>,
) {
    let s = &pf.section;
    check(
        errors,
        s.time_step.is_finite() && s.time_step > 0.0 && s.time_step <= 1.0,
        "particle_fluid.time_step",
        || format!("must be in (0, 1] s, got {}", s.time_step),
    );
    let steps = s.duration / s.time_step;
    check(
        errors,
        s.duration.is_finite() && (0.5..=1e9).contains(&steps),
        "particle_fluid.duration",
        || format!("must give 1 to 1e9 steps of time_step, got {}", s.duration),
    );
    if let Some(g) = s.gravity {
        check(
            errors,
            g.is_finite() && (0.0..=1000.0).contains(&g),
            "particle_fluid.gravity",
            || format!("must be in [0, 1000] m/s², got {g}"),
        );
    }
    if let Some(t) = s.levitation_tolerance {
        finite_positive(errors, "particle_fluid.levitation_tolerance", t);
    }
    check(
        errors,
        s.observe_every != Some(0),
        "particle_fluid.observe_every",
        || "must be >= 1, got 0".into(),
    );
    if let HistoryChoice::Window { window, .. } = s.history {
        check(
            errors,
            window.is_finite() && window >= s.time_step && window / s.time_step <= 1.6e7,
            "particle_fluid.history.window",
            || format!("must be >= time_step and at most 1.6e7 steps [s], got {window}"),
        );
    }
    let (lo, hi) = DENSITY_RANGE;
    within(
        errors,
        "liquid.density",
        pf.liquid.density,
        lo,
        hi,
        "[kg/m³]",
    );
    let (lo, hi) = VISCOSITY_RANGE;
    within(
        errors,
        "liquid.viscosity",
        pf.liquid.viscosity,
        lo,
        hi,
        "[Pa s]",
    );
    flow_checks(&pf.liquid.flow, errors);
    let chi = pf.liquid.susceptibility;
    check(
        errors,
        chi.is_finite() && (-1.0..=10.0).contains(&chi),
        "liquid.susceptibility",
        || format!("must be in [-1, 10], got {chi}"),
    );
    if let Some(m) = &pf.magnet {
        within(
            errors,
            "magnet.surface_field",
            m.surface_field,
            0.0,
            MAX_FIELD,
            "[A/m]",
        );
        within(
            errors,
            "magnet.pole_size",
            m.pole_size,
            LENGTH_RANGE.0,
            MAX_EXTENT,
            "[m]",
        );
        within(
            errors,
            "magnet.half_height",
            m.half_height,
            LENGTH_RANGE.0,
            MAX_EXTENT,
            "[m]",
        );
        if let Some(z) = m.mid_plane {
            within(
                errors,
                "magnet.mid_plane",
                z,
                -MAX_EXTENT,
                MAX_EXTENT,
                "[m]",
            );
        }
    }
    if let Err(e) = pf.collisions.model(&pf.liquid).validate() {
        errors.push(SceneError::new("collisions", e.to_string()));
    }
    let edges = pf.container.edges();
    let bounded = !matches!(pf.container, FluidContainerSpec::Unbounded {});
    if bounded {
        let keys = match pf.container {
            FluidContainerSpec::Channel { .. } => ["side[0]", "side[1]", "height"],
            _ => ["edges[0]", "edges[1]", "edges[2]"],
        };
        for (k, key) in keys.iter().enumerate() {
            let path = format!("container.{key}");
            within(errors, &path, edges[k], LENGTH_RANGE.0, MAX_EXTENT, "[m]");
        }
    }
    let d_max = groups
        .iter()
        .map(|(_, g)| 2.0 * g.shape.shape().radius())
        .fold(0.0, f64::max);
    if bounded && edges.min_element() > 0.0 {
        check(errors, edges.min_element() > d_max, "container", || {
            format!("every extent must exceed the largest particle diameter {d_max} m")
        });
        if let FluidContainerSpec::Channel { side, .. } = pf.container {
            check(
                errors,
                side[0].min(side[1]) > 4.0 * d_max,
                "container.side",
                || {
                    format!(
                        "periods must exceed 4 particle diameters ({} m)",
                        4.0 * d_max
                    )
                },
            );
        }
    }
    for (i, g) in groups.iter_mut() {
        validate_group(*i, g, pf, bounded, edges, errors);
    }
}

fn validate_group(
    i: usize,
    g: &mut ParticleGroup,
    pf: &ParticleFluidScene,
    bounded: bool,
    edges: DVec3,
    errors: &mut Vec<SceneError>,
) {
    let p = format!("particles[{i}]");
    let ShapeSpec::Sphere { radius } = g.shape else {
        errors.push(SceneError::new(
            format!("{p}.shape.kind"),
            "the particle_fluid pipeline simulates spheres (spheroids come later)",
        ));
        return;
    };
    match (g.density, &g.density_ratios) {
        (Some(rho), None) => {
            let (lo, hi) = DENSITY_RANGE;
            within(errors, &format!("{p}.density"), rho, lo, hi, "[kg/m³]")
        }
        (None, Some(r)) => {
            let q = format!("{p}.density_ratios");
            within(errors, &format!("{q}.min"), r.min, 1e-3, 1e3, "");
            within(errors, &format!("{q}.max"), r.max, 1e-3, 1e3, "");
            check(
                errors,
                r.max.is_finite() && r.max >= r.min,
                &format!("{q}.max"),
                || format!("must be >= min ({}), got {}", r.min, r.max),
            );
            check(errors, r.groups >= 1, &format!("{q}.groups"), || {
                "must be >= 1, got 0".into()
            });
        }
        _ => errors.push(SceneError::new(
            format!("{p}.density"),
            "give exactly one of density [kg/m³] or density_ratios",
        )),
    }
    if let Some(v) = g.velocity {
        check(
            errors,
            v.iter().all(|c| c.is_finite() && c.abs() <= MAX_SPEED),
            &format!("{p}.velocity"),
            || format!("must be three numbers in [-{MAX_SPEED}, {MAX_SPEED}] [m/s], got {v:?}"),
        );
    }
    match g.volume_fraction {
        Some(phi) => {
            check(
                errors,
                phi.is_finite() && phi > 0.0 && phi <= 0.5,
                &format!("{p}.volume_fraction"),
                || format!("must be in (0, 0.5], got {phi}"),
            );
            check(errors, bounded, &format!("{p}.volume_fraction"), || {
                "needs a bounded [container] (channel or tank)".into()
            });
            check(errors, g.count == 0, &format!("{p}.count"), || {
                "give count or volume_fraction, not both".into()
            });
            if bounded && phi > 0.0 && radius > 0.0 {
                g.count = count_from_volume_fraction(phi, pf.container.volume(), radius);
                check(
                    errors,
                    g.count >= 1,
                    &format!("{p}.volume_fraction"),
                    || "gives no particle".into(),
                );
            }
        }
        None => check(errors, g.count >= 1, &format!("{p}.count"), || {
            format!("must be >= 1 (or give volume_fraction), got {}", g.count)
        }),
    }
    let q = format!("{p}.placement");
    match &g.placement {
        None => errors.push(SceneError::new(q, "missing required key (a start region)")),
        Some(PlacementSpec::Box { min, max }) => {
            if !(0..3).all(|k| min[k].is_finite() && max[k].is_finite() && max[k] > min[k]) {
                errors.push(SceneError::new(
                    format!("{q}.max"),
                    format!("must exceed min on every axis, got min {min:?}, max {max:?}"),
                ));
            }
        }
        Some(PlacementSpec::Points { positions }) => {
            if positions.len() as u64 != g.count {
                errors.push(SceneError::new(
                    format!("{q}.positions"),
                    format!(
                        "must hold count = {} points, got {}",
                        g.count,
                        positions.len()
                    ),
                ));
            }
            for (k, x) in positions.iter().enumerate() {
                let inside = (0..3).all(|a| {
                    x[a].is_finite() && (!bounded || (x[a] >= radius && x[a] <= edges[a] - radius))
                });
                check(errors, inside, &format!("{q}.positions[{k}]"), || {
                    format!("must be finite and inside the container, got {x:?}")
                });
            }
            if let Some((a, b)) = crate::scene::placement::first_overlap(positions, radius) {
                errors.push(SceneError::new(
                    format!("{q}.positions[{b}]"),
                    format!("overlaps positions[{a}]: centres closer than a diameter"),
                ));
            }
        }
        Some(PlacementSpec::Injection {
            heavy,
            light,
            impurity,
        }) => {
            check(errors, bounded, &q, || "needs a bounded [container]".into());
            for (name, z) in [("heavy", heavy), ("light", light)] {
                let ok = z[0].is_finite() && z[1].is_finite() && z[1] > z[0];
                let inside = !bounded || (z[0] >= 0.0 && z[1] <= edges.z);
                check(errors, ok && inside, &format!("{q}.{name}"), || {
                    format!(
                        "must be [z_min, z_max] inside the container with z_max > z_min, got {z:?}"
                    )
                });
            }
            check(
                errors,
                impurity.is_finite() && (0.0..=1.0).contains(impurity),
                &format!("{q}.impurity"),
                || format!("must be in [0, 1], got {impurity}"),
            );
        }
        Some(_) => errors.push(SceneError::new(
            format!("{q}.kind"),
            "the particle_fluid pipeline places particles by box, points or injection",
        )),
    }
}
