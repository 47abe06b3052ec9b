//! Spawning a particle-fluid scene: spheres with their densities, start positions (points,
//! a box, or the density-separation injection bands, without overlap) and velocities, the
//! walls as boundary entities, and the pipeline's resources.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::prelude::*;
use magsep_systems::collision::{CollisionDomain, Plane};
use magsep_systems::fluid::channel::grid::ChannelGrid;
use magsep_systems::fluid::channel::systems::ChannelLiquid;
use magsep_systems::fluid::collide::CollisionWorkspace;
use magsep_systems::fluid::config::ParticleFluidConfig;
use magsep_systems::fluid::spheroid::SpheroidHydro;
use magsep_systems::fluid::spheroid_systems::SpheroidFluid;
use magsep_systems::fluid::systems::FluidDomain;
use magsep_systems::geometry::bounding_radius;
use magsep_systems::rng::particle_stream;
use rand::RngExt;
use std::collections::HashMap;

use super::scene::{FluidContainerSpec, ParticleFluidScene};
use crate::scene::{OrientationSpec, PlacementSpec, Scene, SpawnError};

/// Rejection attempts per particle before a region is declared too full.
const MAX_ATTEMPTS: usize = 100_000;

/// The space a placed particle claims: its bounding sphere, or for a spheroid with a vertical
/// symmetry axis (broadside) its bounding vertical cylinder (radius a, half height c), which
/// lets flat flakes stack as densely as the thesis injects them.
#[derive(Debug, Clone, Copy)]
struct Claim {
    /// Bounding-sphere radius \[m\].
    radius: f64,
    /// (a, c) of a broadside spheroid \[m\].
    upright: Option<(f64, f64)>,
}

impl Claim {
    fn overlaps(&self, other: &Claim, d: DVec3) -> bool {
        match (self.upright, other.upright) {
            (Some((a1, c1)), Some((a2, c2))) => d.z.abs() < c1 + c2 && d.x.hypot(d.y) < a1 + a2,
            _ => d.length() < self.radius + other.radius,
        }
    }

    /// Horizontal and vertical half extents \[m\] (for the margins of a start region).
    fn extents(&self) -> (f64, f64) {
        self.upright.unwrap_or((self.radius, self.radius))
    }
}

/// Placed particles on a hash grid (cell = the largest diameter), for overlap checks.
struct Placed {
    cell: f64,
    grid: HashMap<[i64; 3], Vec<usize>>,
    spheres: Vec<(DVec3, Claim)>,
    domain: CollisionDomain,
}

impl Placed {
    fn key(&self, x: DVec3) -> [i64; 3] {
        let k = (x / self.cell).floor();
        [k.x as i64, k.y as i64, k.z as i64]
    }

    fn clear(&self, x: DVec3, claim: Claim) -> bool {
        // periodic images are found through the minimum image of each candidate; cells of
        // the periodic faces are checked by wrapping the query point's neighbours
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let probe = self
                        .domain
                        .wrap(x + DVec3::new(dx as f64, dy as f64, dz as f64) * self.cell);
                    if let Some(list) = self.grid.get(&self.key(probe)) {
                        for &j in list {
                            let (y, other) = self.spheres[j];
                            if claim.overlaps(&other, self.domain.minimum_image(x - y)) {
                                return false;
                            }
                        }
                    }
                }
            }
        }
        true
    }

    fn insert(&mut self, x: DVec3, claim: Claim) {
        let k = self.key(self.domain.wrap(x));
        self.grid.entry(k).or_default().push(self.spheres.len());
        self.spheres.push((x, claim));
    }
}

/// The orientation (body → lab, symmetry axis body z) of a particle that starts as `spec`;
/// `Random` draws a uniform rotation from `rng` (Shoemake's method).
pub fn initial_orientation(spec: OrientationSpec, rng: &mut impl RngExt) -> DQuat {
    match spec {
        OrientationSpec::Broadside => DQuat::IDENTITY,
        OrientationSpec::EdgeOn => DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
        OrientationSpec::Axis(v) => {
            DQuat::from_rotation_arc(DVec3::Z, DVec3::from_array(v).normalize())
        }
        OrientationSpec::Tilt(deg) => DQuat::from_rotation_x(deg.to_radians()),
        OrientationSpec::Random => {
            let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
            let tau = std::f64::consts::TAU;
            let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
            DQuat::from_xyzw(
                s1 * (tau * u2).sin(),
                s1 * (tau * u2).cos(),
                s2 * (tau * u3).sin(),
                s2 * (tau * u3).cos(),
            )
            .normalize()
        }
    }
}

/// The domain (periodic axes and walls) of the container.
pub fn fluid_domain(spec: &FluidContainerSpec) -> CollisionDomain {
    let e = spec.edges();
    let walls = |d: CollisionDomain, axis: usize| {
        let n = DVec3::AXES[axis];
        d.with_plane(Plane::new(DVec3::ZERO, n))
            .with_plane(Plane::new(n * e[axis], -n))
    };
    match spec {
        FluidContainerSpec::Unbounded {} => CollisionDomain::unbounded(),
        FluidContainerSpec::Channel { side, .. } => walls(
            CollisionDomain::unbounded()
                .with_periodic(0, 0.0, side[0])
                .with_periodic(1, 0.0, side[1]),
            2,
        ),
        FluidContainerSpec::Tank { .. } => {
            walls(walls(walls(CollisionDomain::unbounded(), 0), 1), 2)
        }
    }
}

/// The container resource of the recording and the wall entities.
fn container_resource(spec: &FluidContainerSpec) -> Container {
    match spec {
        FluidContainerSpec::Unbounded {} => Container::Unbounded,
        FluidContainerSpec::Channel { .. } => Container::Walled {
            walls: Walls::Slab,
            edges: spec.edges(),
        },
        FluidContainerSpec::Tank { .. } => Container::Walled {
            walls: Walls::Box,
            edges: spec.edges(),
        },
    }
}

/// Spawn the particles and resources of a particle-fluid scene.
///
/// # Errors
/// [`SpawnError::Other`] when a start region is too full for its particles.
pub fn spawn_particle_fluid(
    scene: &Scene,
    pf: &ParticleFluidScene,
    world: &mut World,
    seed: u64,
) -> Result<(), SpawnError> {
    let cfg: ParticleFluidConfig = pf.config();
    let domain = fluid_domain(&pf.container);
    let edges = pf.container.edges();
    let d_max = scene
        .particles
        .iter()
        .map(|g| 2.0 * bounding_radius(&g.shape.shape()))
        .fold(0.0, f64::max);
    let mut placed = Placed {
        cell: d_max.max(1e-300),
        grid: HashMap::new(),
        spheres: Vec::new(),
        domain: domain.clone(),
    };
    let rho_f = pf.liquid.density;
    let mut id = 0u64;
    for (g, group) in scene.particles.iter().enumerate() {
        let shape = group.shape.shape();
        let r = bounding_radius(&shape);
        // a fixed orientation is known before placement (a random one is drawn after it, from
        // the particle's stream); a broadside spheroid claims its bounding cylinder
        let spec = group.orientation.unwrap_or_default();
        let upright = match (shape, spec) {
            (
                Shape::Spheroid {
                    equatorial_radius,
                    polar_radius,
                },
                OrientationSpec::Broadside,
            ) => Some((equatorial_radius, polar_radius)),
            _ => None,
        };
        let claim = Claim { radius: r, upright };
        let (rh, rv) = claim.extents();
        let Some(placement) = &group.placement else {
            continue;
        };
        let n = group.count as usize;
        // densities: one value or ratio groups (particle k of the group: group k mod n)
        let density = |k: usize| match (&group.density, &group.density_ratios) {
            (Some(rho), _) => *rho,
            (None, Some(dr)) => rho_f * dr.ratio((k % dr.groups.max(1) as usize) as u32),
            _ => rho_f,
        };
        // injection: which particles start in the wrong band (the first round(Imp n_kind) of
        // each kind, by index; placement is random anyway)
        let (mut heavy_seen, mut light_seen) = (0usize, 0usize);
        let n_heavy = (0..n).filter(|&k| density(k) > rho_f).count();
        let n_light = n - n_heavy;
        for k in 0..n {
            let rho_p = density(k);
            let mut rng = particle_stream(seed, id);
            let (lo, hi, explicit) = match placement {
                PlacementSpec::Points { positions } => {
                    let x = DVec3::from_array(positions[k]);
                    (x, x, true)
                }
                PlacementSpec::Box { min, max } => {
                    (DVec3::from_array(*min), DVec3::from_array(*max), false)
                }
                PlacementSpec::Injection {
                    heavy,
                    light,
                    impurity,
                } => {
                    let heavy_kind = rho_p > rho_f;
                    let (seen, total) = if heavy_kind {
                        heavy_seen += 1;
                        (heavy_seen - 1, n_heavy)
                    } else {
                        light_seen += 1;
                        (light_seen - 1, n_light)
                    };
                    let wrong = (seen as f64) < (impurity * total as f64).round();
                    let band = if heavy_kind != wrong { heavy } else { light };
                    (
                        DVec3::new(rh, rh, band[0].max(rv)),
                        DVec3::new(edges.x - rh, edges.y - rh, band[1].min(edges.z - rv)),
                        false,
                    )
                }
                _ => {
                    return Err(SpawnError::Other(format!(
                        "particles[{g}].placement: not supported by particle_fluid"
                    )));
                }
            };
            let mut found = None;
            for _ in 0..MAX_ATTEMPTS {
                let u = DVec3::new(rng.random(), rng.random(), rng.random());
                let x = lo + (hi - lo) * u;
                if explicit || placed.clear(x, claim) {
                    found = Some(x);
                    break;
                }
            }
            let Some(x) = found else {
                return Err(SpawnError::Other(format!(
                    "particles[{g}]: no overlap-free place for particle {k} after {MAX_ATTEMPTS} \
                     attempts (start region too small for count = {n})"
                )));
            };
            placed.insert(x, claim);
            let v0 = DVec3::from_array(group.velocity.unwrap_or([0.0; 3]));
            let orientation = initial_orientation(spec, &mut rng);
            let body = match shape {
                Shape::Spheroid {
                    equatorial_radius,
                    polar_radius,
                } => InertialBody::spheroid(equatorial_radius, polar_radius, rho_p),
                _ => InertialBody::sphere(r, rho_p),
            };
            let entity = world
                .spawn((
                    ParticleBundle {
                        id: ParticleId(id),
                        position: Position(x),
                        orientation: Orientation(orientation),
                        shape,
                        species: Species(g as u32),
                        rng: ParticleRng(rng),
                        net_force: NetForce::default(),
                        net_torque: NetTorque::default(),
                    },
                    Velocity(v0),
                    AngularVelocity::default(),
                    body,
                    cfg.flow.sample(x, 0.0),
                    Levitation {
                        equilibrium_height: cfg.equilibrium_height(rho_p).unwrap_or(f64::NAN),
                        last_outside: 0.0,
                    },
                ))
                .id();
            if let Shape::Spheroid {
                equatorial_radius: a,
                polar_radius: c,
            } = shape
            {
                let opts = cfg.spheroids;
                let mut hydro = SpheroidHydro::new(
                    2.0 * a,
                    c / a,
                    cfg.liquid.density,
                    rho_p,
                    cfg.liquid.viscosity,
                );
                hydro.drag_density = opts.drag_density;
                hydro.correlation = opts.correlation.unwrap_or(hydro.correlation);
                hydro.rotation = opts.rotation_fit.unwrap_or(hydro.rotation);
                world.entity_mut(entity).insert(SpheroidFluid {
                    hydro,
                    equatorial_radius: a,
                    polar_radius: c,
                });
            }
            id += 1;
        }
    }
    let container = container_resource(&pf.container);
    if let Some(walls) = container.walls() {
        for face in walls.faces() {
            world.spawn(face);
        }
    }
    world.insert_resource(container);
    world.insert_resource(FluidDomain(domain));
    if cfg.terms.collisions {
        world.insert_resource(CollisionWorkspace::new(
            pf.collisions.model(&pf.liquid),
            pf.collisions.history.unwrap_or_default(),
        ));
    }
    if let Some(spec) = cfg.channel() {
        let grid = ChannelGrid::new(spec.grid, edges.to_array())
            .map_err(|e| SpawnError::Other(format!("liquid.solver.grid: {e}")))?;
        let nu = cfg.liquid.viscosity / cfg.liquid.density;
        let liquid = ChannelLiquid::new(spec, grid, nu, cfg.dt)
            .map_err(|e| SpawnError::Other(format!("liquid.solver: {e}")))?;
        world.insert_resource(liquid);
    }
    world.insert_resource(StepClock::new(cfg.dt));
    world.insert_resource(cfg);
    Ok(())
}
