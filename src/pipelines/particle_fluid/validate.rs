//! The checks of a particle-fluid scene: every value in its documented range (SI units),
//! explicit start points inside the container and apart, `count` resolved from
//! `volume_fraction`.

use glam::DVec3;
use magsep_systems::collision::restitution::CollisionModelError;
use magsep_systems::fluid::config::HistoryChoice;
use magsep_systems::fluid::flow::FlowModel;

use super::scene::{FluidContainerSpec, ParticleFluidScene, count_from_volume_fraction};
use crate::scene::checks::{LENGTH_RANGE, VISCOSITY_RANGE, check, finite_positive, within};
use magsep_components::shape::Shape;

use crate::scene::checks::num;
use crate::scene::{OrientationSpec, ParticleGroup, PlacementSpec, SceneError};

/// Densities accepted, of liquids and particles \[kg/m³\] (osmium is 22.6e3).
pub const DENSITY_RANGE: (f64, f64) = (1.0, 3e4);
/// Smallest spheroid aspect ratio w = c/a: the flattest shape with drag data (the thesis's
/// 1:10 database).
pub const MIN_ASPECT_RATIO: f64 = 0.1;
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

/// The simulated liquid: its options, a channel container, and no prescribed flow beside it.
fn solver_checks(pf: &ParticleFluidScene, errors: &mut Vec<SceneError>) {
    let Some(spec) = &pf.liquid.solver else {
        return;
    };
    for (key, message) in spec.problems() {
        errors.push(SceneError::new(format!("liquid.solver.{key}"), message));
    }
    check(
        errors,
        matches!(pf.container, FluidContainerSpec::Channel { .. }),
        "liquid.solver.kind",
        || "a \"channel\" solver needs [container] kind = \"channel\"".into(),
    );
    check(errors, pf.liquid.flow.is_quiescent(), "liquid.flow", || {
        "a prescribed flow cannot be combined with a solved liquid (remove one)".into()
    });
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
        || format!("must be in (0, 1] s, got {}", num(s.time_step)),
    );
    let steps = s.duration / s.time_step;
    check(
        errors,
        s.duration.is_finite() && (0.5..=1e9).contains(&steps),
        "particle_fluid.duration",
        || {
            format!(
                "must give 1 to 1e9 steps of time_step ({} s), got {} s ({} steps)",
                num(s.time_step),
                num(s.duration),
                num(steps)
            )
        },
    );
    if let Some(g) = s.gravity {
        check(
            errors,
            g.is_finite() && (0.0..=1000.0).contains(&g),
            "particle_fluid.gravity",
            || format!("must be in [0, 1000] m/s², got {}", num(g)),
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
            || {
                format!(
                    "must be >= time_step ({} s) and at most 1.6e7 steps, got {} s",
                    num(s.time_step),
                    num(window)
                )
            },
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
    solver_checks(pf, errors);
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
    for e in pf.collisions.model(&pf.liquid).violations() {
        let CollisionModelError::OutOfRange { name, value, range } = e;
        // the liquid's density and viscosity enter the model too: `[liquid]`'s own checks
        // report them at their keys
        if !matches!(name, "fluid_density" | "kinematic_viscosity") {
            errors.push(SceneError::new(
                format!("collisions.{name}"),
                format!("must be in {range}, got {}", num(value)),
            ));
        }
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
        .map(|(_, g)| 2.0 * magsep_systems::geometry::bounding_radius(&g.shape.shape()))
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
    // the bounding radius: placement and overlap checks treat a spheroid as its sphere
    let radius = match g.shape.shape() {
        Shape::Sphere { radius } => radius,
        Shape::Spheroid {
            equatorial_radius: a,
            polar_radius: c,
        } => {
            let w = c / a;
            // at the key that gave w when the scene gives it directly, else at the shape
            let given = matches!(
                g.shape,
                crate::scene::ShapeSpec::Spheroid {
                    aspect_ratio: Some(_),
                    ..
                }
            );
            let at = if given {
                format!("{p}.shape.aspect_ratio")
            } else {
                format!("{p}.shape")
            };
            check(
                errors,
                w.is_nan() || (MIN_ASPECT_RATIO..=1.0 + 1e-12).contains(&w),
                &at,
                || {
                    format!(
                        "the particle_fluid pipeline simulates oblate spheroids with aspect \
                         ratio w = polar/equatorial radius in [{MIN_ASPECT_RATIO}, 1] (the \
                         range of its drag data), got w = {}",
                        num(w)
                    )
                },
            );
            a.max(c)
        }
        _ => {
            errors.push(SceneError::new(
                format!("{p}.shape.kind"),
                "the particle_fluid pipeline simulates spheres and spheroids",
            ));
            return;
        }
    };
    if !radius.is_finite() {
        // the shape's own error is reported; nothing else can be checked against it
        return;
    }
    if let Some(o) = g.orientation {
        // a sphere looks and moves the same in every orientation: its start orientation has
        // no effect on the run, so a given one is a mistake (a spheroid meant, or a stray key)
        if matches!(g.shape.shape(), Shape::Sphere { .. }) {
            errors.push(SceneError::new(
                format!("{p}.orientation"),
                "a sphere has no orientation to set (it only sets a spheroid's symmetry \
                 axis): remove it, or give a spheroid shape",
            ));
        } else {
            check_orientation(o, &p, errors);
        }
    }
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
                let vp = magsep_systems::geometry::volume(&g.shape.shape());
                g.count = count_from_volume_fraction(phi, pf.container.volume(), vp);
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
            } else if bounded {
                // the centres are drawn in the box: as for points, a particle clear of the walls
                let tol = 1e-12 * edges.max_element();
                for (key, corner, ok) in [
                    ("min", min, (0..3).all(|a| min[a] >= radius - tol)),
                    (
                        "max",
                        max,
                        (0..3).all(|a| max[a] <= edges[a] - radius + tol),
                    ),
                ] {
                    check(errors, ok, &format!("{q}.{key}"), || {
                        let r = crate::scene::checks::num(radius);
                        format!(
                            "the start box must lie inside the container, a particle radius clear \
                             of the walls (every coordinate in [{r}, edge - {r}] m, edges {:?} m), \
                             got {corner:?}",
                            edges.to_array()
                        )
                    });
                }
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
            crate::scene::placement::check_overlap(&q, positions, radius, errors);
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

/// A spheroid's `orientation` is a non-zero finite axis or a tilt in [-180, 180] degrees.
fn check_orientation(o: OrientationSpec, p: &str, errors: &mut Vec<SceneError>) {
    let ok = match o {
        OrientationSpec::Axis(v) => {
            v.iter().all(|c| c.is_finite() && c.abs() <= 1e6)
                && v.iter().map(|c| c * c).sum::<f64>() > 1e-24
        }
        OrientationSpec::Tilt(deg) => deg.is_finite() && deg.abs() <= 180.0,
        _ => true,
    };
    check(errors, ok, &format!("{p}.orientation"), || {
        "must be \"broadside\", \"edge_on\", \"random\", { axis = [x, y, z] } (non-zero, \
         finite) or { tilt = degrees } in [-180, 180]"
            .into()
    });
}
