//! Candidate collision pairs for one step from a dense cell grid (Hoomans' "collision blocks",
//! [T002 §4.2.1.3]).
//!
//! Two spheres that touch at some time in a step, while every particle's speed stays below
//! `v_max`, started at most `r_i + r_j + 2 v_max h` apart. With `reach = 2 v_max h + margin`, the
//! cells have edge `≥ 2 r_max + reach`, so each particle's candidates lie in its own and the 26
//! neighbouring cells; a candidate is kept if its start offset (minimum image) is at most
//! `r_i + r_j + reach`. Periodic axes wrap the cell index (with fewer than three cells along an
//! axis each cell is visited once); the grid spans the bounding box along the other axes, and the
//! cell edge grows until the grid has at most `4 N + 27` cells, so a sparse or tiny system
//! degenerates gracefully into a few cells (exhaustive search for tiny `N`).
//!
//! The lists are symmetric (`j ∈ C(i) ⇔ i ∈ C(j)`), sorted by index, and independent of any
//! hash order: the result is a pure function of the input. From 2048 particles the lists are
//! built on fixed chunks of 1024 particles side by side and joined in particle order (the same
//! lists on any number of threads).

use glam::DVec3;
use rayon::prelude::*;

use super::domain::CollisionDomain;
use crate::buckets::bucket_sort;

/// Per-particle sorted candidate lists (compressed rows) and the grid scratch.
#[derive(Debug, Clone, Default)]
pub struct Candidates {
    offsets: Vec<usize>,
    partners: Vec<u32>,
    cell_of: Vec<usize>,
    cell_start: Vec<usize>,
    cell_items: Vec<u32>,
}

/// Grid layout along one axis.
#[derive(Debug, Clone, Copy)]
struct Axis {
    origin: f64,
    edge: f64,
    cells: usize,
    periodic: bool,
}

impl Axis {
    fn layout(domain: &CollisionDomain, k: usize, lo: f64, hi: f64, edge: f64) -> Self {
        match domain.periodic[k] {
            Some(p) => {
                let cells = (p.length / edge).floor().clamp(1.0, 1e6) as usize;
                Self {
                    origin: p.min,
                    edge: p.length / cells as f64,
                    cells,
                    periodic: true,
                }
            }
            None => {
                let span = if hi >= lo { hi - lo } else { 0.0 };
                let cells = ((span / edge).floor() + 1.0).clamp(1.0, 1e6) as usize;
                Self {
                    origin: if lo.is_finite() { lo } else { 0.0 },
                    edge,
                    cells,
                    periodic: false,
                }
            }
        }
    }

    fn index(&self, x: f64) -> usize {
        let q = ((x - self.origin) / self.edge).floor();
        let q = if q.is_finite() { q as i64 } else { 0 };
        if self.periodic {
            q.rem_euclid(self.cells as i64) as usize
        } else {
            q.clamp(0, self.cells as i64 - 1) as usize
        }
    }

    /// Distinct neighbouring cell indices of cell `c` (at most 3), in ascending offset order.
    fn neighbours(&self, c: usize) -> ([usize; 3], usize) {
        let mut out = [0; 3];
        let mut len = 0;
        let n = self.cells as i64;
        for o in -1..=1i64 {
            let q = c as i64 + o;
            let q = if self.periodic {
                q.rem_euclid(n)
            } else if (0..n).contains(&q) {
                q
            } else {
                continue;
            };
            let q = q as usize;
            if !out[..len].contains(&q) {
                out[len] = q;
                len += 1;
            }
        }
        (out, len)
    }
}

impl Candidates {
    /// Candidates of particle `i` (sorted indices, `i` excluded).
    pub fn of(&self, i: usize) -> &[u32] {
        &self.partners[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Positions of particle `i`'s candidates in the flat list of all candidates (`0..`[`Self::total`]).
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i]..self.offsets[i + 1]
    }

    /// Candidate at position `k` of the flat list.
    #[inline]
    pub fn at(&self, k: usize) -> u32 {
        self.partners[k]
    }

    /// Length of the flat list of all candidates.
    pub fn total(&self) -> usize {
        self.partners.len()
    }

    /// Rebuilds the lists for start positions `x` [m], radii [m] and `reach` [m] (see the module
    /// header).
    pub fn build(&mut self, x: &[DVec3], radii: &[f64], domain: &CollisionDomain, reach: f64) {
        let n = x.len();
        let r_max = radii
            .iter()
            .copied()
            .filter(|r| r.is_finite())
            .fold(0.0, f64::max);
        let mut edge = (2.0 * r_max + reach).max(f64::MIN_POSITIVE);
        if !edge.is_finite() {
            edge = f64::MAX;
        }
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in x.iter().filter(|p| p.is_finite()) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let limit = (4 * n + 27) as f64;
        let axes = loop {
            let axes: [Axis; 3] =
                std::array::from_fn(|k| Axis::layout(domain, k, lo[k], hi[k], edge));
            let total: f64 = axes.iter().map(|a| a.cells as f64).product();
            if total <= limit || edge >= f64::MAX / 2.0 {
                break axes;
            }
            edge *= 1.26;
        };
        let [nx, ny, _] = axes.map(|a| a.cells);
        let n_cells = axes.iter().map(|a| a.cells).product::<usize>();
        let cell_id = |c: [usize; 3]| c[0] + nx * (c[1] + ny * c[2]);

        // counting sort of particles into cells (index order within a cell)
        self.cell_of.clear();
        self.cell_of.extend(x.iter().map(|p| {
            let w = domain.wrap(*p);
            cell_id(std::array::from_fn(|k| axes[k].index(w[k])))
        }));
        bucket_sort(
            &self.cell_of,
            n_cells,
            &mut self.cell_start,
            &mut self.cell_items,
        );

        self.offsets.clear();
        self.offsets.push(0);
        self.partners.clear();
        let grid = Grid {
            axes,
            cell_of: &self.cell_of,
            cell_start: &self.cell_start,
            cell_items: &self.cell_items,
        };
        if n < 2 * CHUNK {
            for i in 0..n {
                grid.list(i, x, radii, domain, reach, &mut self.partners);
                self.offsets.push(self.partners.len());
            }
            return;
        }
        // fixed chunks side by side, joined in particle order: the same lists on any thread count
        let chunks: Vec<(Vec<u32>, Vec<usize>)> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let (mut partners, mut ends) = (Vec::new(), Vec::with_capacity(CHUNK));
                for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                    grid.list(i, x, radii, domain, reach, &mut partners);
                    ends.push(partners.len());
                }
                (partners, ends)
            })
            .collect();
        for (partners, ends) in chunks {
            let base = self.partners.len();
            self.offsets.extend(ends.iter().map(|e| base + e));
            self.partners.extend_from_slice(&partners);
        }
    }
}

/// Particles per chunk of the parallel list build; fewer than two chunks build serially.
const CHUNK: usize = 1024;

/// The filled cell grid of one build.
struct Grid<'a> {
    axes: [Axis; 3],
    cell_of: &'a [usize],
    cell_start: &'a [usize],
    cell_items: &'a [u32],
}

impl Grid<'_> {
    /// Appends particle `i`'s sorted candidates to `out`.
    fn list(
        &self,
        i: usize,
        x: &[DVec3],
        radii: &[f64],
        domain: &CollisionDomain,
        reach: f64,
        out: &mut Vec<u32>,
    ) {
        let axes = &self.axes;
        let (nx, ny) = (axes[0].cells, axes[1].cells);
        let cell_id = |c: [usize; 3]| c[0] + nx * (c[1] + ny * c[2]);
        let c = self.cell_of[i];
        let home = [c % nx, (c / nx) % ny, c / (nx * ny)];
        let [(bx, lx), (by, ly), (bz, lz)] = std::array::from_fn(|k| axes[k].neighbours(home[k]));
        let start = out.len();
        for &cz in &bz[..lz] {
            for &cy in &by[..ly] {
                for &cx in &bx[..lx] {
                    let cell = cell_id([cx, cy, cz]);
                    for &j in &self.cell_items[self.cell_start[cell]..self.cell_start[cell + 1]] {
                        let j = j as usize;
                        if j == i {
                            continue;
                        }
                        let d = domain.minimum_image(x[j] - x[i]).length();
                        if d <= radii[i] + radii[j] + reach {
                            out.push(j as u32);
                        }
                    }
                }
            }
        }
        out[start..].sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    use super::*;

    #[test]
    fn matches_brute_force_with_periodic_axes_and_small_boxes() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        for (len, n) in [(1.0, 400), (0.25, 50), (0.1, 20), (3.0, 300), (1.0, 2500)] {
            let domain = CollisionDomain::unbounded()
                .with_periodic(0, -0.5, len)
                .with_periodic(2, 0.0, len);
            let x: Vec<DVec3> = (0..n)
                .map(|_| {
                    DVec3::new(
                        rng.random_range(-2.0..2.0),
                        rng.random_range(0.0..1.0),
                        rng.random_range(-1.0..3.0),
                    )
                })
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.005..0.02)).collect();
            let reach = 0.03;
            let mut c = Candidates::default();
            c.build(&x, &radii, &domain, reach);
            for i in 0..n {
                let brute: Vec<u32> = (0..n)
                    .filter(|&j| {
                        j != i
                            && domain.minimum_image(x[j] - x[i]).length()
                                <= radii[i] + radii[j] + reach
                    })
                    .map(|j| j as u32)
                    .collect();
                assert_eq!(c.of(i), &brute[..], "particle {i}, box {len}");
            }
        }
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let mut c = Candidates::default();
        let domain = CollisionDomain::unbounded();
        c.build(&[], &[], &domain, 0.0);
        let x = [
            DVec3::ZERO,
            DVec3::NAN,
            DVec3::new(1e300, 0.0, 0.0),
            DVec3::X,
        ];
        c.build(&x, &[0.5, 0.5, 0.5, 0.5], &domain, f64::INFINITY);
        assert_eq!(c.of(0), &[2, 3]);
        c.build(&x, &[0.0; 4], &domain, 0.0);
        assert!(c.of(0).is_empty());
    }
}
