//! Containers with hard walls and superquadric particles in packing scenes: validation and
//! the container's start size.
//!
//! The fixed dimensions come from the scene (cylinder radius, wedge length and angle, slab
//! side); the compressed one (cylinder and wedge length along z, slab height, box edge) follows
//! from `packing.initial_packing_fraction` phi0: V_particles / (phi0 * cross-section).

use glam::DVec3;
use magsep_components::container::{Container, Walls};
use magsep_components::packing::OverlapRemovalScheme;
use magsep_components::shape::Shape;

use super::scene::{ContainerSpec, PackingSection};
use crate::scene::checks::{check, finite_positive, num, num4};
use crate::scene::{ParticleGroup, SceneError, ShapeSpec};

fn is_superquadric(s: &ShapeSpec) -> bool {
    matches!(
        s,
        ShapeSpec::Superquadric { .. }
            | ShapeSpec::Superball { .. }
            | ShapeSpec::Ellipsoid { .. }
            | ShapeSpec::Spheroid { .. }
    )
}

/// Cross-shape, scheme and container checks of a packing scene (after the per-field checks
/// passed).
/// Largest fixed container dimension (cylinder radius, wedge length, slab side), in
/// diameters of the smallest particle.
pub const MAX_CONTAINER_DIAMETERS: f64 = 1000.0;

pub(crate) fn validate(
    container: Option<&ContainerSpec>,
    groups: &[&ParticleGroup],
    packing: &PackingSection,
    errors: &mut Vec<SceneError>,
) {
    let any_sq = groups.iter().any(|g| is_superquadric(&g.shape));
    for (i, g) in groups.iter().enumerate() {
        if any_sq
            && let ShapeSpec::Spherocylinder {
                cylinder_length, ..
            } = g.shape
            && cylinder_length > 0.0
        {
            errors.push(SceneError::new(
                format!("particles[{i}].shape.kind"),
                "spherocylinders cannot be mixed with superquadrics in one packing (spheres can)",
            ));
        }
    }
    if any_sq && packing.scheme == Some(OverlapRemovalScheme::Original) {
        errors.push(SceneError::new(
            "packing.scheme",
            "the original (Williams-Philipse) scheme is defined for spheres and spherocylinders \
             only; use \"revised\" or \"fire\" with superquadrics",
        ));
    }
    let shapes: Vec<Shape> = groups.iter().map(|g| g.shape.shape()).collect();
    let largest_bound = shapes
        .iter()
        .map(magsep_systems::geometry::bounding_radius)
        .fold(0.0, f64::max);
    let largest_radius = shapes.iter().map(|s| s.radius()).fold(0.0, f64::max);
    // what must fit across the container: a rod's cap, a superquadric's bounding sphere
    let needed = if any_sq {
        largest_bound
    } else {
        largest_radius
    };
    // a fixed container dimension spans at most MAX_CONTAINER_DIAMETERS particles (the
    // neighbour grid's cells grow with its square)
    let smallest = shapes
        .iter()
        .map(|s| s.radius())
        .fold(f64::INFINITY, f64::min);
    let at_most = MAX_CONTAINER_DIAMETERS * 2.0 * smallest;
    let fixed = |errors: &mut Vec<SceneError>, key: &str, v: f64| {
        if smallest.is_finite() {
            check(errors, v <= at_most, &format!("container.{key}"), || {
                format!(
                    "must be at most {MAX_CONTAINER_DIAMETERS} diameters of the smallest particle \
                     ({} m), got {}",
                    num(at_most),
                    num(v)
                )
            });
        }
    };
    match container {
        Some(ContainerSpec::Cylinder { radius }) => {
            finite_positive(errors, "container.radius", *radius);
            fixed(errors, "radius", *radius);
            check(errors, *radius > needed, "container.radius", || {
                format!("must exceed the largest particle radius {needed:e} m, got {radius:e}")
            });
        }
        Some(ContainerSpec::Wedge { angle, length }) => {
            check(
                errors,
                angle.is_finite() && *angle > 0.0 && *angle < std::f64::consts::FRAC_PI_2,
                "container.angle",
                || format!("must be in (0, pi/2) rad, got {angle}"),
            );
            finite_positive(errors, "container.length", *length);
            fixed(errors, "length", *length);
            let t = angle.tan();
            let inscribed = length * t / (1.0 + t + 1.0 / angle.cos());
            check(errors, inscribed > needed, "container.length", || {
                format!(
                    "the wedge's inscribed circle (radius {inscribed:e} m) must exceed the \
                     largest particle radius {needed:e} m"
                )
            });
        }
        Some(ContainerSpec::Slab { side }) => {
            finite_positive(errors, "container.side", *side);
            fixed(errors, "side", *side);
            // a period must hold a particle and its image apart
            check(
                errors,
                *side > 2.0 * largest_bound,
                "container.side",
                || {
                    format!(
                        "must exceed the largest particle's bounding diameter {} m, got {}",
                        num(2.0 * largest_bound),
                        num(*side)
                    )
                },
            );
        }
        Some(ContainerSpec::PeriodicBox {}) | Some(ContainerSpec::ClosedBox {}) | None => {}
    }
    if errors.is_empty() {
        start_size(
            container,
            groups,
            &shapes,
            packing,
            needed,
            largest_bound,
            errors,
        );
    }
}

/// The start container must hold the largest particle: a box's edge its bounding diameter (in a
/// periodic box, a particle and its own image apart; the random insertion would otherwise try
/// its 10^6 places against hundreds of images each), the compressed length of a cylinder,
/// wedge or slab the particle's width across (`needed`, a radius).
fn start_size(
    container: Option<&ContainerSpec>,
    groups: &[&ParticleGroup],
    shapes: &[Shape],
    packing: &PackingSection,
    needed: f64,
    largest_bound: f64,
    errors: &mut Vec<SceneError>,
) {
    let phi0 = packing.initial_packing_fraction.unwrap_or(0.05);
    let volume: f64 = (groups.iter().zip(shapes))
        .map(|(g, s)| g.count as f64 * magsep_systems::geometry::volume(s))
        .sum();
    let spec = container.cloned().unwrap_or(ContainerSpec::PeriodicBox {});
    let boxed = matches!(
        spec,
        ContainerSpec::PeriodicBox {} | ContainerSpec::ClosedBox {}
    );
    let edges = start_container(&spec, volume, phi0).edges();
    // the compressed dimension: every edge of a box, z of the others
    let (length, width) = if boxed {
        (edges.min_element(), 2.0 * largest_bound)
    } else {
        (edges.z, 2.0 * needed)
    };
    if !(volume > 0.0 && length.is_finite()) || length > width {
        return;
    }
    // the packing fraction at which the start length equals the width
    let phi_max = if boxed {
        volume / width.powi(3)
    } else {
        phi0 * length / width
    };
    let (key, what) = match spec {
        ContainerSpec::PeriodicBox {} | ContainerSpec::ClosedBox {} => {
            ("packing.initial_packing_fraction", "box edge")
        }
        ContainerSpec::Cylinder { .. } => ("container.radius", "cylinder length"),
        ContainerSpec::Wedge { .. } => ("container.length", "wedge length"),
        ContainerSpec::Slab { .. } => ("container.side", "slab height"),
    };
    let lower = format!(
        "lower packing.initial_packing_fraction below {}",
        num4(phi_max)
    );
    let advice = match (phi_max >= 1e-3, boxed) {
        (true, true) => format!("{lower}, or use more particles"),
        (false, true) => "use more particles (at the lowest initial_packing_fraction, 1e-3, \
                          the box is still too small)"
            .to_string(),
        (true, false) => format!("{lower}, or give a smaller cross-section"),
        (false, false) => "give a smaller cross-section or more particles".to_string(),
    };
    errors.push(SceneError::new(
        key,
        format!(
            "at initial_packing_fraction {} the start {what} is {} m, not more than the \
             largest particle's {} {} m: it cannot hold it; {advice}",
            num(phi0),
            num4(length),
            if boxed { "bounding diameter" } else { "width" },
            num4(width),
        ),
    ));
}

/// The start container for `particle_volume` [m^3] at packing fraction `phi0`.
pub fn start_container(spec: &ContainerSpec, particle_volume: f64, phi0: f64) -> Container {
    let v = particle_volume / phi0;
    match *spec {
        ContainerSpec::PeriodicBox {} => Container::PeriodicBox {
            edges: DVec3::splat(v.cbrt()),
        },
        ContainerSpec::ClosedBox {} => Container::Walled {
            walls: Walls::Box,
            edges: DVec3::splat(v.cbrt()),
        },
        ContainerSpec::Cylinder { radius } => Container::Walled {
            walls: Walls::Cylinder,
            edges: DVec3::new(
                2.0 * radius,
                2.0 * radius,
                v / (std::f64::consts::PI * radius * radius),
            ),
        },
        ContainerSpec::Wedge { angle, length } => {
            let h = length * angle.tan();
            Container::Walled {
                walls: Walls::Wedge { angle },
                edges: DVec3::new(length, h, v / (0.5 * length * h)),
            }
        }
        ContainerSpec::Slab { side } => Container::Walled {
            walls: Walls::Slab,
            edges: DVec3::new(side, side, v / (side * side)),
        },
    }
}
