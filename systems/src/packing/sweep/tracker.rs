//! The overlap tracker of [`super`]: which particles carry an overlap above the tolerance,
//! evaluated incrementally between the sweeps of one overlap removal, and the contact cache
//! the moves read (see the parent module's header: **Scan** and **Contact cache**).

use super::super::moves::MoveContact;
use super::super::neighbour::NeighbourList;
use super::super::state::PackingState;
use crate::geometry::superquadric::WarmStart;
use crate::par::team::{Scatter, Team};

/// Pairs per team task of the pair scan (a sphere pair costs ~20 ns, a superball pair ~1 us).
const SCAN_CHUNK: usize = 64;

/// The overlaps of the list's pairs between scans of one overlap removal (see the module
/// header).
#[derive(Debug, Clone, Default)]
pub struct OverlapTracker {
    /// Overlap / D per pair of [`NeighbourList::unique`].
    overlap: Vec<f64>,
    /// Per particle: a wall overlap above the tolerance.
    wall: Vec<bool>,
    /// `NeighbourList::builds` at the last scan (None: no scan yet).
    built: Option<u64>,
    /// Particles moved since the last scan, and their marks.
    moved: Vec<u32>,
    moved_mark: Vec<bool>,
    /// Per particle: listed pairs whose overlap is above the tolerance.
    above: Vec<u32>,
    /// The tolerance of the last scan.
    tol: f64,
    /// Scratch: pair marks, one bit per pair of [`NeighbourList::unique`] (all zero between
    /// scans), and selected pairs.
    pair_mark: Vec<u64>,
    selected: Vec<u32>,
    /// Moves of each particle since the last full scan (the contact cache's clock).
    version: Vec<u32>,
    /// Per particle: how far its surface points have moved since the last full scan, at
    /// most (the sum of its moves' translations and turn bounds) / D.
    travel: Vec<f64>,
    /// Per pair of [`NeighbourList::unique`]: the pair's overlap stays at most the tolerance
    /// while the travels of its two ends sum to less than this (see [`Self::certified`]).
    clear: Vec<f64>,
    /// Per directed list entry: the superquadric pair contact of the last scan, with the
    /// versions of both ends it was computed at (see [`Self::cached`]).
    cache: Vec<Option<CachedContact>>,
}

/// A scanned pair contact and the move versions of its two ends at the time.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CachedContact {
    version_i: u32,
    version_j: u32,
    /// None: the overlap is certainly at most the tolerance (not solved).
    contact: Option<MoveContact>,
}

impl CachedContact {
    fn new(version_i: u32, version_j: u32, contact: Option<MoveContact>) -> Self {
        Self {
            version_i,
            version_j,
            contact,
        }
    }
}

/// What one task of the scan found: its counts and the pairs that crossed the tolerance
/// (i, j, now above).
#[derive(Default)]
struct ScanChunk {
    count: ScanCount,
    flips: Vec<(u32, u32, bool)>,
}

/// Contacts evaluated by one scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ScanCount {
    /// Pair contacts evaluated.
    pub contacts: u64,
    /// Of which the contact solver fell back to its estimate.
    pub fallbacks: u64,
}

impl OverlapTracker {
    /// A tracker whose next scan is full.
    pub fn new() -> Self {
        Self::default()
    }

    /// Record that particle `i` moved, its surface points by at most `travel` / D.
    pub fn note_moved(&mut self, i: usize, travel: f64) {
        if self.moved_mark.len() <= i {
            self.moved_mark.resize(i + 1, false);
        }
        if self.version.len() <= i {
            self.version.resize(i + 1, 0);
        }
        if self.travel.len() <= i {
            self.travel.resize(i + 1, 0.0);
        }
        self.version[i] = self.version[i].wrapping_add(1);
        self.travel[i] += travel;
        if !self.moved_mark[i] {
            self.moved_mark[i] = true;
            self.moved.push(i as u32);
        }
    }

    /// Force a full scan next time.
    pub fn invalidate(&mut self) {
        self.built = None;
    }

    /// The contact of list entry `k` (particle `i` with its neighbour `j`) as the last scan
    /// computed it (inner None: at most the tolerance, not solved), if it is still the
    /// contact of the present poses: a superquadric pair
    /// whose ends have not moved since, in the list the scan saw. Within one overlap removal
    /// only [`super::sweep`]'s commits move particles, and every moving commit is noted
    /// ([`Self::note_moved`]).
    #[inline]
    pub fn cached(
        &self,
        list: &NeighbourList,
        k: usize,
        i: usize,
        j: usize,
    ) -> Option<Option<MoveContact>> {
        if self.built != Some(list.builds) {
            return None;
        }
        let c = self.cache.get(k).copied().flatten()?;
        let v = |p: usize| self.version.get(p).copied().unwrap_or(0);
        (c.version_i == v(i) && c.version_j == v(j)).then_some(c.contact)
    }

    /// Whether the overlap of the pair of list entry `k` (particle `i` with its neighbour `j`,
    /// both at their poses in the state) is certainly at most the tolerance of the last scan
    /// without evaluating it: a scan found room r below the tolerance
    /// ([`crate::packing::state::Above::room`]) when the travels of the two ends summed to T,
    /// and they have moved since by less than r together. The overlap of two convex bodies
    /// changes by no more than how far their surface points move (each separating-axis bound
    /// h_a(u) + h_b(-u) - d.u along a fixed direction u does, and the overlap is their
    /// minimum), so it is still below the tolerance less the round-off margin.
    #[inline]
    pub fn certified(&self, list: &NeighbourList, k: usize, i: usize, j: usize) -> bool {
        self.certified_after(list, k, i, j, 0.0)
    }

    /// [`Self::certified`] as it will be once `j` has made a pending move of travel
    /// `pending` (a cell sweep's move before its write-back; the sum is rounded as
    /// [`Self::note_moved`] will round it, so the answer is the one after the write-back).
    #[inline]
    pub fn certified_after(
        &self,
        list: &NeighbourList,
        k: usize,
        i: usize,
        j: usize,
        pending: f64,
    ) -> bool {
        if self.built != Some(list.builds) {
            return false;
        }
        let clear = self.clear.get(list.pair_of_entry(k)).copied();
        let t = |p: usize| self.travel.get(p).copied().unwrap_or(f64::INFINITY);
        clear.is_some_and(|c| t(i) + (t(j) + pending) < c)
    }

    /// Set `flags[i]` for every particle with a pair or wall overlap above `tol`, evaluating
    /// the pairs with a moved end (all pairs on the first scan or after a rebuild). The list
    /// must be valid (`NeighbourList::ensure`).
    pub fn scan(
        &mut self,
        state: &PackingState,
        list: &mut NeighbourList,
        tol: f64,
        flags: &mut Vec<bool>,
        team: &Team<'_>,
    ) -> ScanCount {
        let n = state.len();
        let npairs = list.unique().len();
        let full = self.built != Some(list.builds)
            || self.overlap.len() != npairs
            || self.wall.len() != n
            || self.tol.to_bits() != tol.to_bits();
        self.selected.clear();
        if full {
            self.tol = tol;
            self.overlap.clear();
            self.overlap.resize(npairs, f64::NEG_INFINITY);
            self.above.clear();
            self.above.resize(n, 0);
            self.pair_mark.clear();
            self.pair_mark.resize(npairs.div_ceil(64), 0);
            self.wall.clear();
            self.wall.resize(n, false);
            self.version.clear();
            self.version.resize(n, 0);
            self.travel.clear();
            self.travel.resize(n, 0.0);
            self.clear.clear();
            self.clear.resize(npairs, f64::NEG_INFINITY);
            self.cache.clear();
            self.cache.resize(list.len(), None);
            self.selected.extend(0..npairs as u32);
        } else {
            // the pairs of the moved particles, each once and in pair order (a pass over the
            // marks' words is cheaper than sorting them, and than a pass over one flag per
            // pair, which was most of the scan's serial time; marks cleared again)
            for &i in &self.moved {
                let first = list.entry_start(i as usize);
                for k in first..first + list.of(i as usize).len() {
                    let p = list.pair_of_entry(k);
                    self.pair_mark[p / 64] |= 1 << (p % 64);
                }
            }
            for (w, word) in self.pair_mark.iter_mut().enumerate() {
                let mut bits = std::mem::take(word);
                while bits != 0 {
                    self.selected.push((w * 64) as u32 + bits.trailing_zeros());
                    bits &= bits - 1;
                }
            }
        }
        let count = self.evaluate_pairs(state, list, tol, team);
        // walls: every particle on a full scan, the moved ones otherwise
        let mut walls = Vec::new();
        let mut wall_of = |i: usize, wall: &mut Vec<bool>| {
            walls.clear();
            state.wall_contacts(i, 0.0, &mut walls);
            wall[i] = walls.iter().any(|c| c.overlap > tol);
        };
        if full {
            (0..n).for_each(|i| wall_of(i, &mut self.wall));
        } else {
            self.moved
                .iter()
                .for_each(|&i| wall_of(i as usize, &mut self.wall));
        }
        flags.clear();
        flags.extend(self.wall.iter().zip(&self.above).map(|(w, a)| *w || *a > 0));
        for &i in &self.moved {
            self.moved_mark[i as usize] = false;
        }
        self.moved.clear();
        self.built = Some(list.builds);
        count
    }
}

impl OverlapTracker {
    /// Evaluate the pairs `selected` (indices into [`NeighbourList::unique`]) on the team
    /// and store their overlaps, their Newton starts in the list (in both directions for
    /// superquadric pairs) and their superquadric contacts in the cache (both directions, at
    /// the present move versions). Each task writes only its own pairs' entries; the
    /// per-particle counts of pairs above the tolerance are then updated in `selected` order.
    fn evaluate_pairs(
        &mut self,
        state: &PackingState,
        list: &mut NeighbourList,
        tol: f64,
        team: &Team<'_>,
    ) -> ScanCount {
        let (pairs, twins, warm) = list.pairs_and_warm();
        let selected = &self.selected;
        let (version, travel) = (&self.version, &self.travel);
        let warm = Scatter::new(warm);
        let overlap = Scatter::new(&mut self.overlap);
        let cache = Scatter::new(&mut self.cache);
        let clear = Scatter::new(&mut self.clear);
        // sided: the pairs are in the order of their particles, which is spatial (see
        // `crate::packing::systems::spatial_order`), so each processor keeps its half
        let chunks = team.map_sided(selected.len().div_ceil(SCAN_CHUNK), |c| {
            let end = ((c + 1) * SCAN_CHUNK).min(selected.len());
            let mut out = ScanChunk::default();
            for &p in &selected[c * SCAN_CHUNK..end] {
                let p = p as usize;
                let e = pairs[p];
                let (i, j, k) = (e.i as usize, e.j as usize, e.k as usize);
                let twin = twins[k] as usize;
                // SAFETY: `selected` holds each pair once, and the indices touched here are
                // the pair's own: its overlap and certificate p and its two directed entries
                // k and twin
                unsafe {
                    let (vi, vj) = (version[i], version[j]);
                    let moved = travel[i] + travel[j];
                    if moved < clear.read(p) {
                        // still certainly at most the tolerance (see `certified`): the
                        // overlap was at most the tolerance and stays so, and the cache
                        // records the answer at the present versions as an evaluation would
                        cache.write(k, Some(CachedContact::new(vi, vj, None)));
                        cache.write(twin, Some(CachedContact::new(vj, vi, None)));
                        continue;
                    }
                    let mut w = warm.read(k);
                    let above = state.contact_warm_above(i, j, e.shift(state.edges), &mut w, tol);
                    out.count.contacts += 1;
                    clear.write(p, moved + above.room);
                    let c = above.contact;
                    let new = c.as_ref().map_or(f64::NEG_INFINITY, |c| c.overlap);
                    let (was, is) = (overlap.read(p) > tol, new > tol);
                    if was != is {
                        out.flips.push((i as u32, j as u32, is));
                    }
                    overlap.write(p, new);
                    let sq = state.is_superquadric_pair(i, j);
                    let Some(c) = c else {
                        // at most the tolerance, not solved: the Newton starts stay as they are
                        if sq {
                            cache.write(k, Some(CachedContact::new(vi, vj, None)));
                            cache.write(twin, Some(CachedContact::new(vj, vi, None)));
                        }
                        continue;
                    };
                    warm.write(k, w);
                    out.count.fallbacks += c.fallback as u64;
                    if sq {
                        // the other direction: the same contact seen from j (a valid starting
                        // point and contact for j's next move; superquadric contacts are
                        // warm-started Newton solutions, not bit-reproducible anyway)
                        warm.write(
                            twin,
                            w.map(|w| WarmStart {
                                s_a: w.s_b,
                                s_b: w.s_a,
                            }),
                        );
                        let mirrored = MoveContact {
                            overlap: c.overlap,
                            normal: -c.normal,
                            k: -c.k,
                            s: c.t,
                            rc: c.rc_j,
                        };
                        let own = MoveContact::from(&c);
                        cache.write(k, Some(CachedContact::new(vi, vj, Some(own))));
                        cache.write(twin, Some(CachedContact::new(vj, vi, Some(mirrored))));
                    }
                }
            }
            out
        });
        let mut count = ScanCount::default();
        for chunk in chunks {
            count.contacts += chunk.count.contacts;
            count.fallbacks += chunk.count.fallbacks;
            for (i, j, is) in chunk.flips {
                for e in [i as usize, j as usize] {
                    self.above[e] = if is {
                        self.above[e] + 1
                    } else {
                        self.above[e].saturating_sub(1)
                    };
                }
            }
        }
        count
    }
}
