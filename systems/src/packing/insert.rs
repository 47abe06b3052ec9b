//! Random start configuration: random sequential insertion without overlap.
//!
//! Each particle, in id order, draws trial centres uniformly in the container (rejecting
//! those where it would cross a wall) and
//! orientations uniformly on the sphere (normalised Gaussian quaternion) from its own stream
//! until it overlaps no earlier particle (thesis: "care is taken to ensure no initial
//! particle-particle overlaps exist", [T000 §2.2.1]).

use glam::{DQuat, DVec3};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::neighbour::CellGrid;
use super::state::{Body, PackingState, body_contact};
use super::walls::{self, WallKind};

/// Why insertion failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "random insertion of particle {index} failed after {trials} trials at packing fraction {packing_fraction:.3}; lower initial_packing_fraction"
)]
pub struct InsertionError {
    /// Index of the particle that could not be placed.
    pub index: usize,
    /// Trials made for it.
    pub trials: u64,
    /// Packing fraction of the box.
    pub packing_fraction: f64,
}

/// A uniformly distributed random rotation.
pub fn random_orientation(rng: &mut Xoshiro256PlusPlus) -> DQuat {
    loop {
        let v: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(rng));
        let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
        let n = q.length();
        if n > 1e-6 {
            return q / n;
        }
    }
}

/// Place `bodies` without overlaps in the (empty) container of `container` (reduced units),
/// uniformly in its volume and clear of its walls. `rngs[i]` is particle i's stream; they are
/// advanced.
///
/// # Errors
/// [`InsertionError`] when a particle finds no free place in 10^6 trials.
pub fn random_insertion(
    bodies: &[Body],
    container: PackingState,
    rngs: &mut [Xoshiro256PlusPlus],
) -> Result<PackingState, InsertionError> {
    let mut state = container;
    fill(bodies, &mut state, rngs, &|| false)?;
    Ok(state)
}

/// Trials between two polls of the stop request in [`random_insertion_until`].
pub const STOP_POLL_TRIALS: u64 = 1024;

/// [`random_insertion`] that gives up, returning `Ok(None)`, once `stop()` says so (polled
/// before each particle and every [`STOP_POLL_TRIALS`] trials): a slow insertion (a start
/// packing fraction near the random sequential limit, costly superquadric contacts) then ends
/// at a signal instead of running on for up to 10^6 trials per particle. Polling does not
/// change the placements.
///
/// # Errors
/// [`InsertionError`] when a particle finds no free place in 10^6 trials.
pub fn random_insertion_until(
    bodies: &[Body],
    container: PackingState,
    rngs: &mut [Xoshiro256PlusPlus],
    stop: &dyn Fn() -> bool,
) -> Result<Option<PackingState>, InsertionError> {
    let mut state = container;
    Ok(fill(bodies, &mut state, rngs, stop)?.then_some(state))
}

/// The insertion into `state`; `Ok(false)` when `stop()` ended it early.
fn fill(
    bodies: &[Body],
    state: &mut PackingState,
    rngs: &mut [Xoshiro256PlusPlus],
    stop: &dyn Fn() -> bool,
) -> Result<bool, InsertionError> {
    let n = bodies.len();
    state.positions = Vec::with_capacity(n);
    state.orientations = Vec::with_capacity(n);
    state.bodies = Vec::with_capacity(n);
    let edges = state.edges;
    let periodic = state.periodic();
    let max_b = bodies
        .iter()
        .map(|b| b.bounding_radius())
        .fold(0.0, f64::max);
    let cutoff = 2.0 * max_b;
    let grid = CellGrid::new(edges, periodic, cutoff);
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); grid.map(|g| g.len()).unwrap_or(1)];
    let cell_index = |g: &CellGrid, p: DVec3| {
        let c = g.coords(p);
        ((c[0] as usize) * g.cells[1] + c[1] as usize) * g.cells[2] + c[2] as usize
    };
    let k_img: [i64; 3] = std::array::from_fn(|a| {
        if periodic[a] {
            (cutoff / edges[a]).ceil() as i64
        } else {
            0
        }
    });
    let images = || {
        (-k_img[0]..=k_img[0]).flat_map(move |a| {
            (-k_img[1]..=k_img[1]).flat_map(move |b| {
                (-k_img[2]..=k_img[2])
                    .map(move |c| DVec3::new(a as f64, b as f64, c as f64) * edges)
            })
        })
    };
    let max_trials = 1_000_000u64;
    for (i, body) in bodies.iter().enumerate() {
        let rng = &mut rngs[i];
        let mut trials = 0;
        loop {
            if trials % STOP_POLL_TRIALS == 0 && stop() {
                return Ok(false);
            }
            trials += 1;
            if trials > max_trials {
                return Err(InsertionError {
                    index: i,
                    trials,
                    packing_fraction: bodies.iter().map(|b| b.volume).sum::<f64>()
                        / state.container_volume(),
                });
            }
            let p = DVec3::new(
                rng.random::<f64>(),
                rng.random::<f64>(),
                rng.random::<f64>(),
            ) * edges;
            let q = random_orientation(rng);
            if state.walls != WallKind::Periodic {
                let support = |d: DVec3| body.support(q, d);
                if walls::penetration_depth(state.walls, edges, p, &support) > -1e-9 {
                    continue;
                }
            }
            let overlaps = |j: usize, shift: DVec3| {
                let bj = &state.bodies[j];
                let xj = state.positions[j] + shift;
                let reach = body.bounding_radius() + bj.bounding_radius();
                (xj - p).length_squared() < reach * reach
                    && body_contact(body, p, q, bj, xj, state.orientations[j]).overlap > 0.0
            };
            let mut hit = false;
            if let Some(g) = &grid {
                g.for_each_neighbour_cell(p, |cell, shift| {
                    if !hit {
                        hit = cells[cell].iter().any(|&j| overlaps(j as usize, shift));
                    }
                });
            } else {
                hit = (0..state.len()).any(|j| images().any(|shift| overlaps(j, shift)));
                // a particle longer than the box may overlap its own images
                if !hit && body.bounding_radius() * 2.0 > edges.min_element() {
                    hit = images().any(|shift| {
                        shift != DVec3::ZERO
                            && shift.length() < 2.0 * body.bounding_radius()
                            && body_contact(body, p, q, body, p + shift, q).overlap > 0.0
                    });
                }
            }
            if !hit {
                match &grid {
                    Some(g) => cells[cell_index(g, p)].push(i as u32),
                    None => cells[0].push(i as u32),
                }
                state.positions.push(p);
                state.orientations.push(q);
                state.bodies.push(*body);
                break;
            }
        }
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use magsep_components::shape::Shape;

    use super::*;
    use crate::rng::particle_stream;

    /// `n` unit spheres and their streams for a periodic cube at packing fraction `phi`.
    fn spheres(n: usize, phi: f64) -> (Vec<Body>, PackingState, Vec<Xoshiro256PlusPlus>) {
        let shape = Shape::Sphere { radius: 0.5 };
        let bodies: Vec<Body> = (0..n).map(|_| Body::from_shape(&shape, 1.0)).collect();
        let v: f64 = bodies.iter().map(|b| b.volume).sum();
        let rngs = (0..n as u64).map(|i| particle_stream(7, i)).collect();
        (bodies, PackingState::periodic_cube((v / phi).cbrt()), rngs)
    }

    #[test]
    fn an_unstopped_insertion_places_what_the_plain_one_places() {
        let (bodies, empty, mut r1) = spheres(200, 0.2);
        let mut r2 = r1.clone();
        let plain = random_insertion(&bodies, empty.clone(), &mut r1).unwrap();
        let polls = Cell::new(0u64);
        let until = random_insertion_until(&bodies, empty, &mut r2, &|| {
            polls.set(polls.get() + 1);
            false
        })
        .unwrap();
        assert_eq!(Some(plain), until);
        // polled at least once per particle
        assert!(polls.get() >= 200, "{} polls", polls.get());
    }

    #[test]
    fn a_stop_ends_an_insertion_that_cannot_finish_within_a_few_polls() {
        // at phi 0.6 random sequential insertion of spheres jams (near 0.38): some particle k
        // would spend its 10^6 trials and fail. Each particle polls before its first trial, so
        // the 301st poll falls among particle k's trials; the stop requested there ends it
        let (bodies, empty, mut rngs) = spheres(300, 0.6);
        let polls = Cell::new(0u64);
        let out = random_insertion_until(&bodies, empty.clone(), &mut rngs, &|| {
            polls.set(polls.get() + 1);
            polls.get() > 300
        });
        assert_eq!(out, Ok(None));
        assert_eq!(polls.get(), 301);
        // without the stop the same insertion fails after its trials
        let (bodies, empty, mut rngs) = spheres(300, 0.6);
        let err = random_insertion(&bodies, empty, &mut rngs).unwrap_err();
        assert!(err.trials > 1_000_000, "{err}");
    }
}
