//! Cell lists for the short-ranged pair sums (dipole cut-off, Mie contact) in an unbounded
//! domain: particles are binned into cubic cells of edge `>= cutoff`, keyed by their integer
//! cell coordinates in a hash map, so the domain needs no box and empty space costs nothing.
//!
//! Each particle's neighbours are visited in a fixed order (the 27 cells in lexicographic
//! offset order, particles in a cell by index), so a per-particle force sum is bitwise the same
//! whatever the thread count.

use std::collections::HashMap;

use glam::DVec3;

/// Binned particle indices.
#[derive(Debug, Clone, Default)]
pub struct CellList {
    edge: f64,
    /// Particle indices sorted by cell, then index.
    order: Vec<u32>,
    /// Cell -> range in `order`.
    cells: HashMap<[i64; 3], (u32, u32)>,
}

fn key(p: DVec3, inv: f64) -> [i64; 3] {
    [
        (p.x * inv).floor() as i64,
        (p.y * inv).floor() as i64,
        (p.z * inv).floor() as i64,
    ]
}

impl CellList {
    /// Bin the particles `i` with `include(i)` into cells of edge `edge` [m] (> 0).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::brownian::cells::CellList;
    /// let p = [DVec3::ZERO, DVec3::X * 0.5, DVec3::X * 3.0];
    /// let cells = CellList::build(&p, 1.0, |_| true);
    /// let mut near = vec![];
    /// cells.for_each_neighbour(&p, 0, 1.0, |j, _| near.push(j));
    /// assert_eq!(near, vec![1]);
    /// ```
    pub fn build(positions: &[DVec3], edge: f64, include: impl Fn(usize) -> bool) -> Self {
        let inv = 1.0 / edge;
        let mut keyed: Vec<([i64; 3], u32)> = (0..positions.len())
            .filter(|&i| include(i) && positions[i].is_finite())
            .map(|i| (key(positions[i], inv), i as u32))
            .collect();
        keyed.sort_unstable();
        let mut cells = HashMap::with_capacity(keyed.len());
        let mut start = 0usize;
        for k in 1..=keyed.len() {
            if k == keyed.len() || keyed[k].0 != keyed[start].0 {
                cells.insert(keyed[start].0, (start as u32, k as u32));
                start = k;
            }
        }
        Self {
            edge,
            order: keyed.into_iter().map(|(_, i)| i).collect(),
            cells,
        }
    }

    /// Cell edge [m].
    pub fn edge(&self) -> f64 {
        self.edge
    }

    /// Call `f(j, d)` for every binned `j != i` with `|d| < cutoff`, `d = x_i − x_j`
    /// (`cutoff <= edge`), in a fixed order.
    #[inline]
    pub fn for_each_neighbour(
        &self,
        positions: &[DVec3],
        i: usize,
        cutoff: f64,
        mut f: impl FnMut(usize, DVec3),
    ) {
        let xi = positions[i];
        let c = key(xi, 1.0 / self.edge);
        let c2 = cutoff * cutoff;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(&(a, b)) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &j in &self.order[a as usize..b as usize] {
                        let j = j as usize;
                        if j == i {
                            continue;
                        }
                        let d = xi - positions[j];
                        if d.length_squared() < c2 {
                            f(j, d);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn finds_exactly_the_brute_force_pairs() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let p: Vec<DVec3> = (0..400)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-1.0..1.0),
                )
            })
            .collect();
        let skip = |i: usize| i % 7 != 3;
        for cutoff in [0.3, 1.0, 2.5] {
            let cells = CellList::build(&p, cutoff * 1.3, skip);
            for i in 0..p.len() {
                let mut got = vec![];
                cells.for_each_neighbour(&p, i, cutoff, |j, d| {
                    assert_eq!(d, p[i] - p[j]);
                    got.push(j)
                });
                got.sort();
                let want: Vec<usize> = (0..p.len())
                    .filter(|&j| j != i && skip(j) && (p[i] - p[j]).length() < cutoff)
                    .collect();
                assert_eq!(got, want, "i = {i}, cutoff = {cutoff}");
            }
        }
    }
}
