//! ECS glue of the MCM: thin systems around the dense kernels.
//!
//! | set | system | reads / writes |
//! |---|---|---|
//! | Prepare | [`begin_compression_step`] | `McmWorkspace`, `PackingStatus` |
//! | Constraints | [`remove_overlaps_mcm`] | `McmWorkspace` |
//! | Finalize | [`settle_compression_step`] -> [`write_back_particles`] | `McmWorkspace`, `PackingStatus`, `Position`, `Orientation`, `Container` |
//! | Observe | [`observe_packing`] | `Position`, `Orientation`, `Shape`, `ParticleId`, `Container` -> `PackingObservables` |

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use magsep_components::prelude::*;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::compress::{DriverParams, compress, next_volume_step, settle_step};
use super::external::PackingKernels;
use super::neighbour::NeighbourList;
use super::removal::RemovalOutcome;
use super::state::PackingState;
use super::walls::WallKind;
use crate::analysis::cubatic::cubatic_order;
use crate::analysis::wall_order::aligned_fraction;
use crate::analysis::{contact_numbers, nematic_order};
use crate::forces::ExternalForces;
use crate::rng::{DRIVER_STREAM, particle_stream};

/// Dense working copy of the packing, in reduced units; the source of truth within a step.
#[derive(Resource, Debug, Clone)]
pub struct McmWorkspace {
    /// Driver parameters (reduced units).
    pub params: DriverParams,
    /// Current configuration.
    pub state: PackingState,
    /// Last overlap-free configuration (saved in `Prepare`).
    pub saved: Option<PackingState>,
    /// Verlet list.
    pub list: NeighbourList,
    /// Driver random stream (sweep order).
    pub rng: Xoshiro256PlusPlus,
    /// Reference diameter D \[m\] of the reduced units.
    pub reference_diameter: f64,
    /// Particle entities in dense order (see [`spatial_order`]).
    pub entities: Vec<Entity>,
    /// `ParticleId`s in dense order.
    pub ids: Vec<u64>,
    /// SI shapes in dense order (what external force kernels see).
    pub shapes: Vec<Shape>,
    /// Volume step of the current step / D^3.
    pub current_volume_step: f64,
    /// Outcome of the current step's overlap removal.
    pub outcome: Option<RemovalOutcome>,
}

/// Skin of the MCM Verlet list / D.
pub const MCM_SKIN: f64 = 0.1;

/// Build the workspace from the spawned particles (exclusive; call once after spawning).
pub fn init_mcm_workspace(world: &mut World) {
    let config = *world.resource::<PackingConfig>();
    let seed = world
        .get_resource::<crate::RunSeed>()
        .map(|s| s.0)
        .unwrap_or(0);
    let container = *world.resource::<Container>();
    let mut q = world.query::<(Entity, &ParticleId, &Position, &Orientation, &Shape)>();
    let mut rows: Vec<_> = q
        .iter(world)
        .map(|(e, id, p, o, s)| (*id, e, p.0, o.0, *s))
        .collect();
    rows.sort_by_key(|r| r.0);
    let order = spatial_order(&rows.iter().map(|r| r.2).collect::<Vec<_>>());
    let rows: Vec<_> = order.into_iter().map(|k| rows[k]).collect();
    let d = reference_diameter(rows.iter().map(|r| &r.4));
    let positions: Vec<DVec3> = rows.iter().map(|r| r.2).collect();
    let orientations: Vec<DQuat> = rows.iter().map(|r| r.3).collect();
    let shapes: Vec<Shape> = rows.iter().map(|r| r.4).collect();
    let state = state_from_si(&container, &positions, &orientations, &shapes, d);
    let params = DriverParams::from_config(&config, d);
    let shapes = shapes.clone();
    let mut status = super::compress::initial_status(&params, &state);
    if let Some(old) = world.get_resource::<PackingStatus>() {
        // resuming: keep counters and step sizes
        status = *old;
    }
    world.insert_resource(status);
    world.insert_resource(McmWorkspace {
        params,
        state,
        saved: None,
        list: NeighbourList::new(MCM_SKIN),
        rng: world
            .get_resource::<DriverRng>()
            .map(|r| r.0.clone())
            .unwrap_or_else(|| particle_stream(seed, DRIVER_STREAM)),
        reference_diameter: d,
        entities: rows.iter().map(|r| r.1).collect(),
        ids: rows.iter().map(|r| r.0.0).collect(),
        shapes,
        current_volume_step: 0.0,
        outcome: None,
    });
    world.init_resource::<PackingObservables>();
}

/// The dense order of particles at `positions` (given in `ParticleId` order): along a Z-order
/// (Morton) curve through their bounding box, 10 bits per axis, ties in id order. Particles
/// close in space are then close in memory, which the packing's sweeps need on more than one
/// thread: a cell's particles share cache lines, and data of particles moved by one thread
/// rarely share a line with data another thread writes at the same time (with ids in random
/// places, a line of a per-particle array held particles from all over the box). Only the
/// dense order changes: every output goes through the entities, and the order is a function
/// of the positions alone, so a run is the same on any number of threads.
pub fn spatial_order(positions: &[DVec3]) -> Vec<usize> {
    let lo = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
    let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
    let scale = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE)).recip() * 1023.0;
    let spread = |v: u64| (0..10).fold(0u64, |m, b| m | ((v >> b) & 1) << (3 * b));
    let key = |p: DVec3| {
        let c = ((p - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(1023.0));
        // NaN coordinates clamp to 0 through the cast
        // y most significant, then x: the sweeps' cells in a cube cut x and y and are
        // numbered y first, so the first half of the particles is the first half of the cells
        (spread(c.y as u64) << 2) | (spread(c.x as u64) << 1) | spread(c.z as u64)
    };
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_by_key(|&k| key(positions[k]));
    order
}

/// The driver's random stream when restored from a recording.
#[derive(Resource, Debug, Clone)]
pub struct DriverRng(pub Xoshiro256PlusPlus);

/// The kernel's wall geometry (reduced units) of `container`, whose lengths are divided by
/// the reference diameter `d` \[m\].
pub fn wall_kind(container: &Container, d: f64) -> WallKind {
    match container {
        Container::PeriodicBox { .. } | Container::Unbounded => WallKind::Periodic,
        Container::Walled { walls, edges } => match walls {
            Walls::Cylinder => WallKind::Cylinder {
                radius: 0.5 * edges.x / d,
            },
            Walls::Wedge { angle } => WallKind::Wedge { alpha: *angle },
            Walls::Slab => WallKind::Slab,
            Walls::Box => WallKind::Box,
        },
    }
}

/// The container of a kernel state with reference diameter `d` \[m\] (SI).
pub fn container_of(state: &PackingState, d: f64) -> Container {
    let edges = state.edges * d;
    let walls = match state.walls {
        WallKind::Periodic => return Container::PeriodicBox { edges },
        WallKind::Cylinder { .. } => Walls::Cylinder,
        WallKind::Wedge { alpha } => Walls::Wedge { angle: alpha },
        WallKind::Slab => Walls::Slab,
        WallKind::Box => Walls::Box,
    };
    Container::Walled { walls, edges }
}

/// A kernel state from SI data in `container`.
pub fn state_from_si(
    container: &Container,
    positions: &[DVec3],
    orientations: &[DQuat],
    shapes: &[Shape],
    d: f64,
) -> PackingState {
    PackingState::from_si(
        container.edges(),
        wall_kind(container, d),
        positions,
        orientations,
        shapes,
        d,
    )
}

/// The reference diameter of a set of shapes: the smallest particle diameter 2R \[m\].
pub fn reference_diameter<'a>(shapes: impl Iterator<Item = &'a Shape>) -> f64 {
    let d = shapes
        .map(|s| 2.0 * s.radius())
        .fold(f64::INFINITY, f64::min);
    if d.is_finite() { d } else { 1.0 }
}

/// Prepare: save the overlap-free state and compress the box.
pub fn begin_compression_step(mut ws: ResMut<McmWorkspace>, status: Res<PackingStatus>) {
    if status.stopped.is_some() {
        return;
    }
    let ws = &mut *ws;
    ws.saved = Some(ws.state.clone());
    let dv = next_volume_step(&ws.params, &status, &ws.state);
    ws.current_volume_step = dv;
    compress(&mut ws.state, &mut ws.list, dv);
}

/// Constraints: remove overlaps within the attempt budget (FIRE: with the registered
/// external force kernels, see [`super::external`]).
pub fn remove_overlaps_mcm(
    mut ws: ResMut<McmWorkspace>,
    status: Res<PackingStatus>,
    kernels: Option<Res<ExternalForces>>,
    clock: Option<Res<StepClock>>,
) {
    if status.stopped.is_some() {
        return;
    }
    let ws = &mut *ws;
    let p = ws.params;
    let kernels = kernels.as_deref().filter(|k| !k.is_empty());
    let packing_kernels = kernels.map(|k| PackingKernels {
        kernels: k,
        d: ws.reference_diameter,
        shapes: &ws.shapes,
        ids: &ws.ids,
        time: clock.as_ref().map(|c| c.time()).unwrap_or(0.0),
    });
    let (state, list, rng) = (&mut ws.state, &mut ws.list, &mut ws.rng);
    // many short parallel loops in a row: run them from inside rayon's pool
    ws.outcome = Some(crate::par::in_rayon_pool(|| {
        super::compress::run_removal_with(&p, state, list, rng, packing_kernels.as_ref())
    }));
}

/// Finalize: accept the step, or revert and refine it; decide whether the run ends.
pub fn settle_compression_step(mut ws: ResMut<McmWorkspace>, mut status: ResMut<PackingStatus>) {
    let Some(out) = ws.outcome.take() else {
        return;
    };
    let ws = &mut *ws;
    let p = ws.params;
    let dv = ws.current_volume_step;
    let saved = ws.saved.take();
    let (state, list) = (&mut ws.state, &mut ws.list);
    settle_step(&p, &mut status, dv, out, || {
        if let Some(s) = saved {
            *state = s;
            list.invalidate();
        }
    });
    status.packing_fraction = ws.state.packing_fraction();
}

/// Finalize: copy the dense state back to the entities and the container (SI units).
pub fn write_back_particles(
    ws: Res<McmWorkspace>,
    mut container: ResMut<Container>,
    mut q: Query<(&mut Position, &mut Orientation)>,
) {
    let d = ws.reference_diameter;
    let mut wrapped = ws.state.clone();
    wrapped.wrap_all();
    let (_, positions) = wrapped.to_si(d);
    *container = container_of(&wrapped, d);
    for (k, e) in ws.entities.iter().enumerate() {
        if let Ok((mut p, mut o)) = q.get_mut(*e) {
            p.0 = positions[k];
            o.0 = ws.state.orientations[k];
        }
    }
}

/// Measured properties of the current packing (a resource).
#[derive(Resource, Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PackingObservables {
    /// Step at which they were computed.
    pub step: u64,
    /// Packing fraction.
    pub packing_fraction: f64,
    /// Mean contact number extrapolated to delta -> 0.
    pub mean_contact_number: f64,
    /// Mean contact number at delta = 1e-4 D.
    pub mean_contact_number_1e_4: f64,
    /// Nematic order S.
    pub nematic_order: f64,
    /// Largest remaining overlap \[m\].
    pub max_overlap: f64,
    /// Contact-number histogram (index = number of contacts).
    pub contact_histogram: Vec<u64>,
    /// Fraction of rods near a wall that lie along it (4 deg, within 1 D; thesis fig. 2.6);
    /// None without walls or rods.
    pub wall_aligned_fraction: Option<f64>,
    /// Cubatic order S_4 (eq. 4.17) of superquadrics; None without them.
    pub cubatic_order: Option<f64>,
    /// Largest penetration of a particle into a wall \[m\] (<= 0 without walls).
    pub max_wall_penetration: f64,
    /// Whether they were ever computed.
    pub computed: bool,
}

/// Whether [`observe_packing`] runs this step: at the end of the run, and every
/// `observe_every` steps.
pub fn should_observe(
    clock: Res<StepClock>,
    status: Option<Res<PackingStatus>>,
    config: Option<Res<PackingConfig>>,
) -> bool {
    let end = status.map(|s| s.stopped.is_some()).unwrap_or(true);
    let every = config.map(|c| c.observe_every).unwrap_or(0);
    end || (every > 0 && clock.step.is_multiple_of(every))
}

/// Observe: packing fraction, extrapolated contact number and nematic order, from the
/// entities (so it runs unchanged on replayed frames).
pub fn observe_packing(
    clock: Res<StepClock>,
    container: Res<Container>,
    q: Query<(&ParticleId, &Position, &Orientation, &Shape)>,
    mut obs: ResMut<PackingObservables>,
) {
    let mut rows: Vec<_> = q.iter().map(|(id, p, o, s)| (*id, p.0, o.0, *s)).collect();
    rows.sort_by_key(|r| r.0);
    let shapes: Vec<Shape> = rows.iter().map(|r| r.3).collect();
    let d = reference_diameter(shapes.iter());
    let positions: Vec<DVec3> = rows.iter().map(|r| r.1).collect();
    let orientations: Vec<DQuat> = rows.iter().map(|r| r.2).collect();
    let state = state_from_si(&container, &positions, &orientations, &shapes, d);
    let cn = contact_numbers(&state);
    let rod_axes: Vec<DVec3> = (0..state.len())
        .filter(|&i| state.bodies[i].half_length > 0.0)
        .map(|i| state.axis(i))
        .collect();
    let walled = state.walls != WallKind::Periodic;
    let max_wall_penetration = if walled {
        (0..state.len())
            .map(|i| state.wall_penetration(i))
            .fold(f64::NEG_INFINITY, f64::max)
            * d
    } else {
        0.0
    };
    let sq: Vec<DQuat> = (0..state.len())
        .filter(|&i| shapes[i].is_superquadric())
        .map(|i| state.orientations[i])
        .collect();
    *obs = PackingObservables {
        step: clock.step,
        packing_fraction: state.packing_fraction(),
        mean_contact_number: cn.extrapolated,
        mean_contact_number_1e_4: cn.at_1e_4,
        nematic_order: nematic_order(&rod_axes),
        max_overlap: cn.max_overlap * d,
        contact_histogram: cn.histogram,
        wall_aligned_fraction: (walled && !rod_axes.is_empty()).then(|| aligned_fraction(&state)),
        cubatic_order: (!sq.is_empty()).then(|| cubatic_order(&sq)),
        max_wall_penetration,
        computed: true,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense order is a permutation that puts the low half of the box along y before the
    /// high half and neighbouring particles next to each other; ties and NaN do not panic.
    #[test]
    fn spatial_order_is_a_permutation_along_a_z_curve() {
        use rand::{RngExt, SeedableRng};
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12345);
        let positions: Vec<DVec3> = (0..1000)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 10.0)
            .collect();
        let order = spatial_order(&positions);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..1000).collect::<Vec<_>>());
        let lo = positions.iter().fold(f64::INFINITY, |a, p| a.min(p.y));
        let hi = positions.iter().fold(f64::NEG_INFINITY, |a, p| a.max(p.y));
        let high = |k: usize| positions[k].y > lo + 0.501 * (hi - lo);
        let low = |k: usize| positions[k].y < lo + 0.499 * (hi - lo);
        let first_high = order.iter().position(|&k| high(k)).unwrap();
        let last_low = order.iter().rposition(|&k| low(k)).unwrap();
        assert!(last_low < first_high, "{last_low} {first_high}");
        // consecutive particles are close: the mean step along the curve is a few times the
        // mean spacing (~1 for 1000 points in a 10^3 box), not the box size
        let mean_step = order
            .windows(2)
            .map(|w| positions[w[0]].distance(positions[w[1]]))
            .sum::<f64>()
            / 999.0;
        assert!(mean_step < 2.5, "{mean_step}");
        // a random order's mean step is ~6.6 (the mean distance of two points in the box)
        let random_step = (0..999)
            .map(|k| positions[k].distance(positions[k + 1]))
            .sum::<f64>()
            / 999.0;
        assert!(random_step > 5.0, "{random_step}");
        // equal and non-finite positions: still a permutation, ties in index order
        let odd = [DVec3::ONE, DVec3::NAN, DVec3::ONE, DVec3::ZERO];
        let order = spatial_order(&odd);
        assert_eq!(order.len(), 4);
        assert!(order.iter().position(|&k| k == 0) < order.iter().position(|&k| k == 2));
        assert!(spatial_order(&[]).is_empty());
    }
}
