//! Verlet neighbour list over all periodic images, built with a cell list.
//!
//! The list holds, for every particle i, the pairs (j, image shift) whose axis segments are
//! closer than R_i + R_j + skin (the thesis's "modified Verlet list", [T000 §2.2.3], made exact with the
//! segment distance). It stays valid while no pair can have approached by more than the skin:
//! the bookkeeping adds each particle's end-point displacement bound |dx| + h |du| and, for an
//! affine compression by s, (1 - s) times the largest centre range of a listed pair.
//!
//! Periodic images are done right for any rod length: when the box holds at least three cells
//! of the pair cut-off the cell list uses the unique minimum image; otherwise (rods longer than
//! about a third of the box) every image shift n in [-K, K]^3 with K = ceil(cut-off / edge) is
//! searched, including contacts of a particle with its own images.

use glam::DVec3;

use super::state::{BodyKind, PackingState};
use crate::geometry::segment_closest;
use crate::geometry::superquadric::WarmStart;

/// One neighbour entry: particle `j` in periodic image `image` (its centre is
/// x_j + image * edge, with the edge of the moment: compressions rescale the shift).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Index of the neighbour.
    pub j: u32,
    /// Periodic image index.
    pub image: [i16; 3],
}

impl Neighbour {
    /// The image shift for a box of edges `edges`.
    #[inline]
    pub fn shift(&self, edges: DVec3) -> DVec3 {
        DVec3::new(
            self.image[0] as f64,
            self.image[1] as f64,
            self.image[2] as f64,
        ) * edges
    }
}

fn image_of(shift: DVec3, edges: DVec3) -> [i16; 3] {
    let r = (shift / edges).round();
    [r.x as i16, r.y as i16, r.z as i16]
}

/// One unordered pair of the list (i < j, or i == j for a self-image pair with a positive
/// image), stored flat at build time so that force loops walk a slice instead of filtering
/// the symmetric CSR on every evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairEntry {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Index of i's directed entry (for [`NeighbourList::warm_mut`]).
    pub k: u32,
    /// Image of j as floats: the shift is `image * edges` with the edges of the moment.
    pub image: DVec3,
}

impl PairEntry {
    /// The image shift for a box of edges `edges` (bit for bit [`Neighbour::shift`]).
    #[inline]
    pub fn shift(&self, edges: DVec3) -> DVec3 {
        self.image * edges
    }
}

/// A cell grid over the box `[0, edges]` with cells no smaller than a cut-off, periodic along
/// the flagged axes (where at least three cells fit) and clamped along walled axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellGrid {
    /// Box edges / D.
    pub edges: DVec3,
    /// Periodic axes.
    pub periodic: [bool; 3],
    /// Cells per axis.
    pub cells: [usize; 3],
}

impl CellGrid {
    /// The grid for `cutoff`, or None when a periodic axis holds fewer than three cut-offs
    /// (then every image must be searched).
    pub fn new(edges: DVec3, periodic: [bool; 3], cutoff: f64) -> Option<Self> {
        let mut cells = [1usize; 3];
        for a in 0..3 {
            let c = (edges[a] / cutoff).floor();
            if periodic[a] && c < 3.0 {
                return None;
            }
            cells[a] = (c.max(1.0) as usize).min(1 << 10);
        }
        Some(Self {
            edges,
            periodic,
            cells,
        })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cells[0] * self.cells[1] * self.cells[2]
    }

    /// Whether the grid has no cells (never).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell coordinates of `p` (clamped into the grid).
    #[inline]
    pub fn coords(&self, p: DVec3) -> [i64; 3] {
        std::array::from_fn(|a| {
            let n = self.cells[a] as i64;
            (((p[a] / self.edges[a]) * n as f64).floor() as i64).clamp(0, n - 1)
        })
    }

    #[inline]
    fn index(&self, c: [usize; 3]) -> usize {
        (c[0] * self.cells[1] + c[1]) * self.cells[2] + c[2]
    }

    /// Linked cell lists (head per cell, next per particle) of `positions`.
    pub fn bin(&self, positions: &[DVec3]) -> (Vec<u32>, Vec<u32>) {
        let mut head = vec![u32::MAX; self.len()];
        let mut next = vec![u32::MAX; positions.len()];
        for (i, p) in positions.iter().enumerate().rev() {
            let c = self.coords(*p).map(|x| x as usize);
            let k = self.index(c);
            next[i] = head[k];
            head[k] = i as u32;
        }
        (head, next)
    }

    /// Call `f(cell index, image shift)` for the cell of `p` and its neighbour cells (each
    /// once; periodic wrap with the shift that brings the cell next to `p`).
    pub fn for_each_neighbour_cell(&self, p: DVec3, mut f: impl FnMut(usize, DVec3)) {
        let c = self.coords(p);
        let range = |a: usize| -> std::ops::RangeInclusive<i64> {
            let n = self.cells[a] as i64;
            if self.periodic[a] {
                -1..=1
            } else {
                (-1i64).max(-c[a])..=1i64.min(n - 1 - c[a])
            }
        };
        for dx in range(0) {
            for dy in range(1) {
                for dz in range(2) {
                    let mut shift = DVec3::ZERO;
                    let mut cj = [0usize; 3];
                    for (a, d) in [dx, dy, dz].into_iter().enumerate() {
                        let n = self.cells[a] as i64;
                        let raw = c[a] + d;
                        let wrapped = raw.rem_euclid(n);
                        shift[a] = ((raw - wrapped) / n) as f64 * self.edges[a];
                        cj[a] = wrapped as usize;
                    }
                    f(self.index(cj), shift);
                }
            }
        }
    }
}

/// Symmetric Verlet list (each pair is stored for both particles) in CSR layout.
#[derive(Debug, Clone, Default)]
pub struct NeighbourList {
    /// Skin / D.
    pub skin: f64,
    start: Vec<u32>,
    entries: Vec<Neighbour>,
    /// Accumulated displacement bound per particle since the last build / D.
    moved: Vec<f64>,
    /// Largest accumulated displacement bound / D.
    max_moved: f64,
    /// Extra approach from affine compressions since the last build / D.
    compressed: f64,
    /// Largest centre distance a listed pair can have / D.
    centre_range: f64,
    /// Number of builds.
    pub builds: u64,
    valid: bool,
    /// Superquadric contact solutions per directed entry, the next call's Newton start
    /// (carried over rebuilds for pairs that stay listed).
    warm: Vec<Option<WarmStart>>,
    /// Each unordered pair once, in [`Self::unique_entries`] order.
    pairs: Vec<PairEntry>,
    /// For every directed entry, the index in [`Self::unique`] of its unordered pair.
    pair_of_entry: Vec<u32>,
    /// For every directed entry, the other direction of its pair.
    twin: Vec<u32>,
    /// Centres at the last build, scaled with every compression since / D (the reference of
    /// [`Self::note_displacements`]).
    reference: Vec<DVec3>,
}

impl NeighbourList {
    /// An empty list with `skin` (reduced units).
    pub fn new(skin: f64) -> Self {
        Self {
            skin,
            ..Default::default()
        }
    }

    /// Neighbours of particle `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[Neighbour] {
        &self.entries[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Number of stored (directed) entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the list is empty.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Record that particle `i` moved by `dx` and turned so that no surface point moved more
    /// than `turn` relative to the centre (a rod: h |du|; any body: bounding radius x angle).
    #[inline]
    pub fn note_move(&mut self, i: usize, dx: DVec3, turn: f64) {
        self.note_travel(i, dx.length() + turn);
    }

    /// [`Self::note_move`] with the bound `travel` = |dx| + turn / D already summed.
    #[inline]
    pub fn note_travel(&mut self, i: usize, travel: f64) {
        if let Some(m) = self.moved.get_mut(i) {
            *m += travel;
            if *m > self.max_moved {
                self.max_moved = *m;
            }
        }
    }

    /// Record the translations of all particles at once (instead of [`Self::note_move`] per
    /// move, for bodies that do not turn): the displacement bound of particle i is the
    /// distance of its centre `positions[i]` from its centre at the last build, scaled with
    /// the compressions since (the affine part is counted by [`Self::note_compression`]).
    /// One square root per call instead of one per particle, and the bound is the net
    /// displacement, not the path length. Invalidates the list when `positions` does not
    /// match the build.
    pub fn note_displacements(&mut self, positions: &[DVec3]) {
        if positions.len() != self.reference.len() {
            self.valid = false;
            return;
        }
        let mut max2: f64 = 0.0;
        for (x, x0) in positions.iter().zip(&self.reference) {
            max2 = max2.max((*x - *x0).length_squared());
        }
        let m = max2.sqrt();
        if m > self.max_moved {
            self.max_moved = m;
        }
    }

    /// Record an affine compression of all centres by factors `s` <= 1 per axis.
    pub fn note_compression(&mut self, s: DVec3) {
        self.compressed += (DVec3::ONE - s).abs().max_element() * self.centre_range;
        self.reference.iter_mut().for_each(|x| *x *= s);
    }

    /// Whether the list must be rebuilt before use.
    #[inline]
    pub fn needs_rebuild(&self) -> bool {
        !self.valid || self.exceeds_skin(self.max_moved)
    }

    /// The displacement bound particle `i` has accumulated since the last build / D.
    #[inline]
    pub fn moved_of(&self, i: usize) -> f64 {
        self.moved.get(i).copied().unwrap_or(0.0)
    }

    /// Whether a particle whose displacement bound is `m` / D makes the list need a rebuild
    /// (the per-particle form of [`Self::needs_rebuild`]).
    #[inline]
    pub fn exceeds_skin(&self, m: f64) -> bool {
        2.0 * m + self.compressed >= self.skin
    }

    /// Largest centre distance a listed pair had at the last build / D (the list's cut-off).
    pub fn centre_range(&self) -> f64 {
        self.centre_range
    }

    /// Force a rebuild at the next [`Self::ensure`].
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Rebuild if needed. Returns whether a rebuild happened.
    pub fn ensure(&mut self, state: &mut PackingState) -> bool {
        if self.needs_rebuild() {
            self.build(state);
            true
        } else {
            false
        }
    }

    /// Wrap all centres into the box and build the list from scratch. Between builds the
    /// centres are not wrapped (the stored image shifts refer to the positions at build time).
    pub fn build(&mut self, state: &mut PackingState) {
        for i in 0..state.len() {
            state.wrap(i);
        }
        let state = &*state;
        let n = state.len();
        let max_b = state
            .bodies
            .iter()
            .map(|b| b.bounding_radius())
            .fold(0.0, f64::max);
        let cutoff = 2.0 * max_b + self.skin;
        self.centre_range = cutoff;
        let axes: Vec<DVec3> = (0..n).map(|i| state.axis(i)).collect();
        let mut pairs: Vec<(u32, u32, DVec3)> = Vec::new();
        let test = |i: usize, j: usize, shift: DVec3, pairs: &mut Vec<(u32, u32, DVec3)>| {
            let (bi, bj) = (&state.bodies[i], &state.bodies[j]);
            let r = state.positions[j] + shift - state.positions[i];
            let reach = bi.bounding_radius() + bj.bounding_radius() + self.skin;
            if r.length_squared() >= reach * reach {
                return;
            }
            if let (BodyKind::Rod, BodyKind::Rod) = (bi.kind, bj.kind) {
                let c = segment_closest(axes[i], bi.half_length, r, axes[j], bj.half_length);
                let lim = bi.radius + bj.radius + self.skin;
                if c.k.length_squared() >= lim * lim {
                    return;
                }
            }
            pairs.push((i as u32, j as u32, shift));
        };
        let grid = CellGrid::new(state.edges, state.periodic(), cutoff);
        if let Some(grid) = grid {
            let (head, next) = grid.bin(&state.positions);
            for i in 0..n {
                grid.for_each_neighbour_cell(state.positions[i], |cell, shift| {
                    let mut j = head[cell];
                    while j != u32::MAX {
                        if (j as usize) > i {
                            test(i, j as usize, shift, &mut pairs);
                        }
                        j = next[j as usize];
                    }
                });
            }
        } else {
            let periodic = state.periodic();
            let k: [i64; 3] = std::array::from_fn(|a| {
                if periodic[a] {
                    (cutoff / state.edges[a]).ceil() as i64
                } else {
                    0
                }
            });
            for i in 0..n {
                for j in i..n {
                    for a in -k[0]..=k[0] {
                        for b in -k[1]..=k[1] {
                            for c in -k[2]..=k[2] {
                                if i == j && (a, b, c) <= (0, 0, 0) {
                                    continue; // self: only one of each +n / -n pair
                                }
                                let shift = DVec3::new(a as f64, b as f64, c as f64) * state.edges;
                                test(i, j, shift, &mut pairs);
                            }
                        }
                    }
                }
            }
        }
        // CSR, both directions, in a deterministic order (by i, then by discovery order).
        let mut count = vec![0u32; n + 1];
        for &(i, j, _) in &pairs {
            count[i as usize] += 1;
            count[j as usize] += 1;
        }
        let old_start = std::mem::take(&mut self.start);
        let old_entries = std::mem::take(&mut self.entries);
        let old_warm = std::mem::take(&mut self.warm);
        self.start = vec![0; n + 1];
        for (i, c) in count.iter().take(n).enumerate() {
            self.start[i + 1] = self.start[i] + c;
        }
        let mut fill = self.start.clone();
        self.entries = vec![
            Neighbour {
                j: 0,
                image: [0; 3]
            };
            self.start[n] as usize
        ];
        // the two directed entries of each pair point at each other
        let mut twin = vec![0u32; self.start[n] as usize];
        for &(i, j, shift) in &pairs {
            let image = image_of(shift, state.edges);
            let (ki, kj) = (fill[i as usize], fill[j as usize] + u32::from(i == j));
            self.entries[ki as usize] = Neighbour { j, image };
            self.entries[kj as usize] = Neighbour {
                j: i,
                image: image.map(|x| -x),
            };
            twin[ki as usize] = kj;
            twin[kj as usize] = ki;
            fill[i as usize] += 1;
            fill[j as usize] += 1;
        }
        self.warm = vec![None; self.entries.len()];
        if old_start.len() == n + 1 && old_warm.len() == old_entries.len() {
            for i in 0..n {
                let old = old_start[i] as usize..old_start[i + 1] as usize;
                for k in self.start[i] as usize..self.start[i + 1] as usize {
                    if let Some(o) = old.clone().find(|&o| old_entries[o] == self.entries[k]) {
                        self.warm[k] = old_warm[o];
                    }
                }
            }
        }
        self.pairs.clear();
        self.pair_of_entry.clear();
        self.pair_of_entry.resize(self.entries.len(), u32::MAX);
        for i in 0..n {
            for k in self.start[i] as usize..self.start[i + 1] as usize {
                let nb = self.entries[k];
                if nb.j as usize > i || (nb.j as usize == i && nb.image > [0, 0, 0]) {
                    let idx = self.pairs.len() as u32;
                    let other = twin.get(k).map_or(k, |t| *t as usize);
                    self.pair_of_entry[k] = idx;
                    self.pair_of_entry[other] = idx;
                    self.pairs.push(PairEntry {
                        i: i as u32,
                        j: nb.j,
                        k: k as u32,
                        image: nb.shift(DVec3::ONE),
                    });
                }
            }
        }
        self.twin = twin;
        self.moved = vec![0.0; n];
        self.reference.clear();
        self.reference.extend_from_slice(&state.positions);
        self.max_moved = 0.0;
        self.compressed = 0.0;
        self.valid = true;
        self.builds += 1;
    }

    /// Each unordered pair once with its directed entry index (for [`Self::warm_mut`]): by
    /// i, then in [`Self::of`] order.
    pub fn unique_entries(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.pairs
            .iter()
            .map(|p| (p.i as usize, p.j as usize, p.k as usize))
    }

    /// Each unordered pair once, in [`Self::unique_entries`] order.
    #[inline]
    pub fn unique(&self) -> &[PairEntry] {
        &self.pairs
    }

    /// Index of i's first entry (entries of i are `entry_start(i)..` in [`Self::of`] order).
    #[inline]
    pub fn entry_start(&self, i: usize) -> usize {
        self.start[i] as usize
    }

    /// The entry `k`.
    #[inline]
    pub fn entry(&self, k: usize) -> Neighbour {
        self.entries[k]
    }

    /// The index in [`Self::unique`] of the unordered pair of directed entry `k`.
    #[inline]
    pub fn pair_of_entry(&self, k: usize) -> usize {
        self.pair_of_entry[k] as usize
    }

    /// The directed entry of the other direction of entry `k`'s pair (j's entry for i).
    #[inline]
    pub fn twin(&self, k: usize) -> usize {
        self.twin[k] as usize
    }

    /// The cached contact solution of entry `k` (a copy).
    #[inline]
    pub fn warm(&self, k: usize) -> Option<WarmStart> {
        self.warm[k]
    }

    /// The unordered pairs and the twin of every entry (read) beside the cached contact
    /// solutions (written), borrowed at once.
    pub(crate) fn pairs_and_warm(&mut self) -> (&[PairEntry], &[u32], &mut [Option<WarmStart>]) {
        (&self.pairs, &self.twin, &mut self.warm)
    }

    /// The cached contact solution of entry `k`.
    #[inline]
    pub fn warm_mut(&mut self, k: usize) -> &mut Option<WarmStart> {
        &mut self.warm[k]
    }

    /// Each unordered pair once: (i, j, shift) with i < j, or i == j for self-image pairs;
    /// shifts for a box of edges `edges`.
    pub fn unique_pairs(&self, edges: DVec3) -> impl Iterator<Item = (usize, usize, DVec3)> + '_ {
        self.pairs
            .iter()
            .map(move |p| (p.i as usize, p.j as usize, p.shift(edges)))
    }
}

#[cfg(test)]
mod tests;
