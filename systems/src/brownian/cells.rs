//! Cell lists for the short-ranged pair sums (dipole cut-off, Mie contact) in an unbounded
//! domain: particles are binned into cubic cells of edge `>= cutoff`, keyed by their integer
//! cell coordinates in a hash map, so the domain needs no box and empty space costs nothing.
//!
//! Each particle's neighbours are visited in a fixed order (the 27 cells in lexicographic
//! offset order, particles in a cell by index), so a per-particle force sum is bitwise the same
//! whatever the thread count.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::DVec3;
use rayon::prelude::*;

/// A fast hasher for integer cell keys (multiply-rotate; keys are not adversarial).
#[derive(Default, Clone, Copy)]
pub struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
}

type CellMap = HashMap<[i64; 3], (u32, u32), BuildHasherDefault<CellHasher>>;

/// Largest cell coordinate (2^60): far from `i64` overflow when offsets are added.
const KEY_LIMIT: f64 = (1u64 << 60) as f64;

/// Fewest particles per task of the parallel binning passes (each particle's key is its own
/// computation, so the split does not change the list).
const PAR_MIN: usize = 1024;

/// Largest dense grid, in cells per binned particle (sparser sets use the hash map).
const DENSE_CELLS_PER_PARTICLE: usize = 8;

/// Where each cell's particles lie in the sorted arrays.
#[derive(Debug, Clone)]
enum Index {
    /// Row-major grid over the bounding box (x fastest): `starts[c]..starts[c + 1]`.
    Dense { dims: [i64; 3], starts: Vec<u32> },
    /// Cell -> range.
    Sparse(CellMap),
}

/// Binned particle indices, with the positions copied in cell order (neighbour candidates are
/// contiguous in memory).
#[derive(Debug, Clone)]
pub struct CellList {
    edge: f64,
    /// Cells searched on each side (the cut-off spans `reach` cells).
    reach: i64,
    inv: f64,
    origin: DVec3,
    /// Particle indices sorted by cell, then index.
    order: Vec<u32>,
    /// Their positions, in the same order.
    sorted: Vec<DVec3>,
    index: Index,
    /// Build scratch, kept for the next build: the binned particles, their cell keys, and
    /// the counting sort's fill pointers.
    members: Vec<u32>,
    keys: Vec<usize>,
    fill: Vec<u32>,
}

impl Default for CellList {
    fn default() -> Self {
        Self {
            edge: 1.0,
            reach: 1,
            inv: 1.0,
            origin: DVec3::ZERO,
            order: Vec::new(),
            sorted: Vec::new(),
            index: Index::Sparse(CellMap::default()),
            members: Vec::new(),
            keys: Vec::new(),
            fill: Vec::new(),
        }
    }
}

impl CellList {
    fn key(&self, p: DVec3) -> [i64; 3] {
        // clamped, so that neighbour offsets never overflow even for absurd positions
        let q =
            ((p - self.origin) * self.inv).clamp(DVec3::splat(-KEY_LIMIT), DVec3::splat(KEY_LIMIT));
        [q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64]
    }

    /// Bin the particles `i` with `include(i)` into cells of edge `edge` \[m\] (> 0).
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
    pub fn build(positions: &[DVec3], edge: f64, include: impl Fn(usize) -> bool + Sync) -> Self {
        Self::build_with_reach(positions, edge, 1, include)
    }

    /// As [`CellList::build`] with cells of edge `cutoff / reach`, searched `reach` cells to
    /// each side: fewer candidates outside the cut-off sphere (27 (2r+1)³/(8r³)/(4π/3) times the
    /// sphere's volume: 6.4 at r = 1, 3.8 at r = 2). Sparse sets fall back to `reach` 1.
    pub fn build_with_reach(
        positions: &[DVec3],
        cutoff: f64,
        reach: i64,
        include: impl Fn(usize) -> bool + Sync,
    ) -> Self {
        let mut list = Self::default();
        list.rebuild_with_reach(positions, cutoff, reach, include);
        list
    }

    /// [`CellList::build_with_reach`] into this list, reusing its buffers (a list rebuilt at
    /// every neighbour-list build allocates nothing once its buffers have grown).
    pub fn rebuild_with_reach(
        &mut self,
        positions: &[DVec3],
        cutoff: f64,
        reach: i64,
        include: impl Fn(usize) -> bool + Sync,
    ) {
        let reach = reach.max(1);
        let edge = cutoff / reach as f64;
        let mut members = std::mem::take(&mut self.members);
        members.clear();
        members.extend(
            (0..positions.len())
                .filter(|&i| include(i) && positions[i].is_finite())
                .map(|i| i as u32),
        );
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &i in &members {
            lo = lo.min(positions[i as usize]);
            hi = hi.max(positions[i as usize]);
        }
        if members.is_empty() {
            lo = DVec3::ZERO;
            hi = DVec3::ZERO;
        }
        (self.edge, self.reach, self.inv, self.origin) = (edge, reach, 1.0 / edge, lo);
        let span = ((hi - lo) * self.inv)
            .floor()
            .clamp(DVec3::ZERO, DVec3::splat(KEY_LIMIT));
        let cells = (span + DVec3::ONE).element_product();
        // NaN or huge spans (absurd positions) take the sparse map, never a dense grid
        let dense = cells <= (DENSE_CELLS_PER_PARTICLE * members.len().max(512)) as f64;
        let dims = if dense {
            [span.x as i64 + 1, span.y as i64 + 1, span.z as i64 + 1]
        } else {
            [0; 3]
        };
        if !dense && reach > 1 {
            self.members = members;
            return self.rebuild_with_reach(positions, cutoff, 1, include);
        }
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        if dense {
            // counting sort into the grid (stable: particles by index within a cell)
            let n = (dims[0] * dims[1] * dims[2]) as usize;
            let flat = |k: [i64; 3]| ((k[2] * dims[1] + k[1]) * dims[0] + k[0]) as usize;
            let mut keys = std::mem::take(&mut self.keys);
            let mut fill = std::mem::take(&mut self.fill);
            let mut starts =
                match std::mem::replace(&mut self.index, Index::Sparse(CellMap::default())) {
                    Index::Dense { starts, .. } => starts,
                    Index::Sparse(_) => Vec::new(),
                };
            let this = &*self;
            let key = |i: u32| flat(this.key(positions[i as usize]));
            keys.clear();
            keys.resize(members.len(), 0);
            if members.len() < PAR_MIN {
                keys.iter_mut()
                    .zip(&members)
                    .for_each(|(k, &i)| *k = key(i));
            } else {
                keys.par_iter_mut()
                    .zip(members.par_iter())
                    .with_min_len(PAR_MIN)
                    .for_each(|(k, &i)| *k = key(i));
            }
            starts.clear();
            starts.resize(n + 1, 0);
            for &k in &keys {
                starts[k + 1] += 1;
            }
            for c in 0..n {
                starts[c + 1] += starts[c];
            }
            fill.clear();
            fill.extend_from_slice(&starts[..n]);
            order.resize(members.len(), 0);
            for (&i, &k) in members.iter().zip(&keys) {
                order[fill[k] as usize] = i;
                fill[k] += 1;
            }
            (self.keys, self.fill) = (keys, fill);
            self.index = Index::Dense { dims, starts };
        } else {
            let mut keyed: Vec<([i64; 3], u32)> = members
                .iter()
                .map(|&i| (self.key(positions[i as usize]), i))
                .collect();
            keyed.sort_unstable();
            let mut map = CellMap::with_capacity_and_hasher(keyed.len(), Default::default());
            let mut start = 0usize;
            for k in 1..=keyed.len() {
                if k == keyed.len() || keyed[k].0 != keyed[start].0 {
                    map.insert(keyed[start].0, (start as u32, k as u32));
                    start = k;
                }
            }
            order.extend(keyed.into_iter().map(|(_, i)| i));
            self.index = Index::Sparse(map);
        }
        let mut sorted = std::mem::take(&mut self.sorted);
        sorted.clear();
        sorted.resize(order.len(), DVec3::ZERO);
        let at = |(s, &i): (&mut DVec3, &u32)| *s = positions[i as usize];
        if order.len() < PAR_MIN {
            sorted.iter_mut().zip(&order).for_each(at);
        } else {
            sorted
                .par_iter_mut()
                .zip(order.par_iter())
                .with_min_len(PAR_MIN)
                .for_each(at);
        }
        (self.members, self.order, self.sorted) = (members, order, sorted);
    }

    /// Largest cut-off the list serves \[m\] (cell edge × reach).
    pub fn edge(&self) -> f64 {
        self.edge * self.reach as f64
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
        let c = self.key(xi);
        let c2 = cutoff * cutoff;
        let mut visit = |a: u32, b: u32| {
            let (a, b) = (a as usize, b as usize);
            for (&j, &xj) in self.order[a..b].iter().zip(&self.sorted[a..b]) {
                let d = xi - xj;
                if d.length_squared() < c2 && j as usize != i {
                    f(j as usize, d);
                }
            }
        };
        let r = self.reach;
        match &self.index {
            Index::Dense { dims, starts } => {
                let x0 = (c[0] - r).max(0);
                let x1 = (c[0] + r).min(dims[0] - 1);
                if x0 > x1 {
                    return;
                }
                for z in (c[2] - r).max(0)..=(c[2] + r).min(dims[2] - 1) {
                    for y in (c[1] - r).max(0)..=(c[1] + r).min(dims[1] - 1) {
                        let row = (z * dims[1] + y) * dims[0];
                        // the cells of a row are contiguous
                        visit(starts[(row + x0) as usize], starts[(row + x1) as usize + 1]);
                    }
                }
            }
            Index::Sparse(map) => {
                for dz in -1..=1 {
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            if let Some(&(a, b)) = map.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                                visit(a, b);
                            }
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
        // two far clusters make the grid sparse: the hash-map path
        let mut far = p.clone();
        for q in far.iter_mut().step_by(2) {
            *q += DVec3::splat(1e4);
        }
        // one list rebuilt over every case (its buffers reused, dense after sparse too)
        let mut reused = CellList::default();
        for (p, cutoff) in [(&p, 0.3), (&p, 1.0), (&p, 2.5), (&far, 1.0), (&p, 2.5)] {
            let reach = if cutoff > 2.0 { 2 } else { 1 };
            let cells = CellList::build_with_reach(p, cutoff * 1.3, reach, skip);
            reused.rebuild_with_reach(p, cutoff * 1.3, reach, skip);
            for i in 0..p.len() {
                let mut got = vec![];
                cells.for_each_neighbour(p, i, cutoff, |j, d| {
                    assert_eq!(d, p[i] - p[j]);
                    got.push(j)
                });
                let mut again = vec![];
                reused.for_each_neighbour(p, i, cutoff, |j, _| again.push(j));
                assert_eq!(again, got, "the same order, i = {i}");
                got.sort();
                let want: Vec<usize> = (0..p.len())
                    .filter(|&j| j != i && skip(j) && (p[i] - p[j]).length() < cutoff)
                    .collect();
                assert_eq!(got, want, "i = {i}, cutoff = {cutoff}");
            }
        }
    }
}
