//! Random start configuration: random sequential insertion without overlap.
//!
//! Each particle, in id order, draws trial centres uniformly in the periodic cube and
//! orientations uniformly on the sphere (normalised Gaussian quaternion) from its own stream
//! until it overlaps no earlier particle (thesis: "care is taken to ensure no initial
//! particle-particle overlaps exist", L259).

use glam::{DQuat, DVec3};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::contact::pair_contact;
use super::state::{Body, PackingState};

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

/// Place `bodies` in a cube of edge `edge` (reduced units) without overlaps. `rngs[i]` is
/// particle i's stream; they are advanced.
pub fn random_insertion(
    bodies: &[Body],
    edge: f64,
    rngs: &mut [Xoshiro256PlusPlus],
) -> Result<PackingState, InsertionError> {
    let n = bodies.len();
    let mut state = PackingState {
        edge,
        positions: Vec::with_capacity(n),
        orientations: Vec::with_capacity(n),
        bodies: Vec::with_capacity(n),
    };
    let max_b = bodies
        .iter()
        .map(|b| b.bounding_radius())
        .fold(0.0, f64::max);
    let cutoff = 2.0 * max_b;
    let ncell = ((edge / cutoff).floor() as i64).max(1);
    let use_cells = ncell >= 3;
    let nc = ncell as usize;
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); if use_cells { nc * nc * nc } else { 1 }];
    let cell_of = |p: DVec3| -> [i64; 3] {
        let f = |c: f64| (((c / edge) * ncell as f64).floor() as i64).clamp(0, ncell - 1);
        [f(p.x), f(p.y), f(p.z)]
    };
    let k_img = (cutoff / edge).ceil() as i64;
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
                    packing_fraction: bodies.iter().map(|b| b.volume).sum::<f64>() / edge.powi(3),
                });
            }
            let p = DVec3::new(
                rng.random::<f64>(),
                rng.random::<f64>(),
                rng.random::<f64>(),
            ) * edge;
            let q = random_orientation(rng);
            let u = q * DVec3::Z;
            let overlaps = |j: usize, shift: DVec3| {
                let bj = &state.bodies[j];
                let r = state.positions[j] + shift - p;
                let reach = body.bounding_radius() + bj.bounding_radius();
                r.length_squared() < reach * reach
                    && pair_contact(
                        u,
                        body.half_length,
                        body.radius,
                        r,
                        state.axis(j),
                        bj.half_length,
                        bj.radius,
                    )
                    .overlap
                        > 0.0
            };
            let mut hit = false;
            if use_cells {
                let c = cell_of(p);
                'outer: for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let mut shift = DVec3::ZERO;
                            let mut idx = 0usize;
                            for (a, d) in [dx, dy, dz].into_iter().enumerate() {
                                let raw = c[a] + d;
                                let w = raw.rem_euclid(ncell);
                                shift[a] = ((raw - w) / ncell) as f64 * edge;
                                idx = idx * nc + w as usize;
                            }
                            for &j in &cells[idx] {
                                if overlaps(j as usize, shift) {
                                    hit = true;
                                    break 'outer;
                                }
                            }
                        }
                    }
                }
            } else {
                'brute: for j in 0..state.len() {
                    for a in -k_img..=k_img {
                        for b in -k_img..=k_img {
                            for cc in -k_img..=k_img {
                                if overlaps(j, DVec3::new(a as f64, b as f64, cc as f64) * edge) {
                                    hit = true;
                                    break 'brute;
                                }
                            }
                        }
                    }
                }
                // a rod longer than the box may overlap its own images
                if !hit && body.bounding_radius() * 2.0 > edge {
                    for a in -k_img..=k_img {
                        for b in -k_img..=k_img {
                            for cc in -k_img..=k_img {
                                if (a, b, cc) == (0, 0, 0) {
                                    continue;
                                }
                                let r = DVec3::new(a as f64, b as f64, cc as f64) * edge;
                                if pair_contact(
                                    u,
                                    body.half_length,
                                    body.radius,
                                    r,
                                    u,
                                    body.half_length,
                                    body.radius,
                                )
                                .overlap
                                    > 0.0
                                {
                                    hit = true;
                                }
                            }
                        }
                    }
                }
            }
            if !hit {
                if use_cells {
                    let c = cell_of(p);
                    cells[((c[0] as usize) * nc + c[1] as usize) * nc + c[2] as usize]
                        .push(i as u32);
                } else {
                    cells[0].push(i as u32);
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
