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
    let n = bodies.len();
    let mut state = container;
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
    Ok(state)
}
