//! Verlet neighbour lists with a skin for the Brownian pair sums.
//!
//! A list built at reference positions `x⁰` holds, for every particle `i`, the exerting
//! particles `j` with `|x⁰_i − x⁰_j| < range + skin`. While no particle has moved more than
//! `skin / 2` from its reference position, every pair closer than `range` is in the list (the
//! distance can shrink by at most `skin`), so the list serves any such configuration and the
//! pair sums need not rebin the particles: a rebuild happens when some particle crossed
//! `skin / 2`, when the set of exerting particles changed, or when a larger range is asked for.
//!
//! Each particle's neighbours are stored in ascending index order, and the build is split into
//! fixed chunks of particles, so a per-particle force sum is bitwise the same whatever the
//! thread count.
//!
//! **Pairs.** Every pair of exerting particles `i < j` in the list has a slot (numbered by `i`,
//! then `j`): [`VerletList::owned`] gives the pairs a particle owns, [`VerletList::entries`] the
//! slot of each list entry, so a pair force can be computed once per pair into its slot and
//! gathered by both particles (Newton's third law) in each particle's fixed list order:
//! half the pair arithmetic and still thread-count independent sums.
//!
//! **Adaptive skin.** The skin asked for is a floor: a list that served fewer than
//! [`SKIN_GROW_BELOW`] evaluations before the next rebuild doubles its skin (up to
//! [`SKIN_MAX_SCALE`] times the floor), one that served more than [`SKIN_SHRINK_ABOVE`] halves
//! it again. A Brownian step can move every particle by more than a skin sized by the pair
//! range alone (a 75 nm particle diffuses ~30 nm per 50 µs step, the Mie contact list's skin
//! is 45 nm), and a list rebuilt at every evaluation cost half of a dilute run. The skin
//! only changes how many pairs a list holds, never which pairs are within range, so the sums
//! are the same bit for bit.
//!
//! [`VerletList::rebuild_always`] turns the cache off (a fresh list at every evaluation): the
//! reference the tests compare the cached path with.

use glam::DVec3;
use rayon::prelude::*;

use super::cells::CellList;

/// Particles per build chunk (fixed: the list does not depend on the thread count).
const CHUNK: usize = 256;

/// Fewest particles for which the per-evaluation displacement check runs in parallel: below,
/// it takes a few tens of µs on one thread, less than waking the pool's other threads for it
/// (a parallel region per check and list, two per step, each paid in wake-ups).
const SERVES_PAR_MIN: usize = 1 << 16;

/// A list rebuilt after serving fewer evaluations than this doubles its skin.
pub const SKIN_GROW_BELOW: u64 = 4;
/// A list rebuilt after serving more evaluations than this halves its skin (not below the
/// floor).
pub const SKIN_SHRINK_ABOVE: u64 = 64;
/// The largest skin, in multiples of the skin asked for.
pub const SKIN_MAX_SCALE: f64 = 8.0;

/// Slot of an entry whose particle does not exert (no shared pair).
pub const NO_SLOT: u32 = u32::MAX;

/// A cached neighbour list (see the module header).
#[derive(Debug, Clone, Default)]
pub struct VerletList {
    /// Pair range served without the skin \[m\].
    range: f64,
    /// Skin \[m\].
    skin: f64,
    /// Positions at the build \[m\].
    reference: Vec<DVec3>,
    /// Exerting mask at the build.
    exerts: Vec<bool>,
    /// `starts[i]..starts[i + 1]` indexes `neighbours` for particle i.
    starts: Vec<u32>,
    /// Neighbour indices (ascending for each particle).
    neighbours: Vec<u32>,
    /// Pair slot of each entry (`NO_SLOT` where the particle itself does not exert).
    slots: Vec<u32>,
    /// Offset of the first entry `j > i` within particle i's entries.
    upper: Vec<u32>,
    /// First slot owned by particle i (`pair_base[n]` = number of pairs).
    pair_base: Vec<u32>,
    /// Rebuilds so far.
    builds: u64,
    /// Evaluations served since the last build.
    served: u64,
    /// Skin in multiples of the skin asked for (adaptive, see the module header; 0: not yet
    /// set, i.e. 1).
    skin_scale: f64,
    /// Rebuild at every [`VerletList::ensure`] (the uncached reference).
    pub rebuild_always: bool,
    /// The list built before this one, kept for a configuration it still serves (see
    /// [`VerletList::ensure`]); its own `spare` is always `None`.
    spare: Option<Box<VerletList>>,
    /// Build scratch kept for the next build (cell list and per-chunk neighbour runs): a
    /// build allocates nothing once they have grown, so it pays no page faults.
    cells: CellList,
    scratch: Vec<ChunkScratch>,
}

/// One build chunk's particles: their neighbours (each particle's run sorted), run lengths,
/// and the offset of the first neighbour `j > i` in each run.
#[derive(Debug, Clone, Default)]
struct ChunkScratch {
    js: Vec<u32>,
    counts: Vec<u32>,
    ups: Vec<u32>,
}

/// A buffer reused across evaluations through a shared reference: the dipole sum's per-pair
/// forces take a few MB at N = 10⁴ (about 14 pairs per particle). Allocated afresh at every
/// evaluation, the allocator handed it back to the system each time and every step paid
/// page faults and page clearing for it. A clone starts empty.
#[derive(Debug, Default)]
pub struct PairScratch(std::sync::Mutex<Vec<DVec3>>);

impl Clone for PairScratch {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PairScratch {
    /// The buffer, resized to `len` (its old values are kept; new entries are zero).
    pub fn take(&self, len: usize) -> Vec<DVec3> {
        let mut v = self
            .0
            .lock()
            .map(|mut g| std::mem::take(&mut *g))
            .unwrap_or_default();
        v.resize(len, DVec3::ZERO);
        v
    }

    /// Give the buffer back for the next evaluation.
    pub fn put(&self, v: Vec<DVec3>) {
        if let Ok(mut g) = self.0.lock() {
            *g = v;
        }
    }
}

impl VerletList {
    /// Number of builds so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Pairs stored (each pair twice, once per particle).
    pub fn stored_pairs(&self) -> usize {
        self.neighbours.len()
    }

    /// Whether the list serves configuration `x` with exerting mask `exerts` for pairs closer
    /// than `range` \[m\].
    pub fn serves(&self, x: &[DVec3], exerts: &[bool], range: f64) -> bool {
        self.serves_checked(x, exerts, range, None)
    }

    /// Whether the particles `a..b` of `x` are within half the skin of their positions at the
    /// build (the displacement part of [`VerletList::serves`], for one part of the particles;
    /// false when `x` is not the built configuration's length).
    pub fn within_skin(&self, x: &[DVec3], a: usize, b: usize) -> bool {
        if x.len() != self.reference.len() || b > x.len() || a > b {
            return false;
        }
        let limit = 0.25 * self.skin * self.skin;
        x[a..b]
            .iter()
            .zip(&self.reference[a..b])
            .all(|(p, q)| (*p - *q).length_squared() <= limit)
    }

    /// [`VerletList::serves`] with the displacement test already done (`within`: the
    /// [`VerletList::within_skin`] of every part), or done here (None).
    fn serves_checked(
        &self,
        x: &[DVec3],
        exerts: &[bool],
        range: f64,
        within: Option<bool>,
    ) -> bool {
        if self.rebuild_always
            || self.builds == 0
            || range > self.range
            || x.len() != self.reference.len()
            || exerts != self.exerts.as_slice()
        {
            return false;
        }
        if let Some(within) = within {
            return within;
        }
        let limit = 0.25 * self.skin * self.skin;
        // NaN displacements fail the test, so a broken configuration is rebinned (and its
        // non-finite particles dropped by the cell list)
        let within = |(p, q): (&DVec3, &DVec3)| (*p - *q).length_squared() <= limit;
        if x.len() < SERVES_PAR_MIN {
            x.iter().zip(&self.reference).all(within)
        } else {
            x.par_iter()
                .zip(self.reference.par_iter())
                .with_min_len(SERVES_PAR_MIN / 2)
                .all(within)
        }
    }

    /// Make the list serve `x` for pairs closer than `range` \[m\], rebuilding with `skin` \[m\]
    /// if needed. Returns whether it was rebuilt.
    ///
    /// The list built before the current one is kept as a spare: an adaptive stepper that
    /// tries a long step, rejects it and goes back to shorter ones alternates between
    /// configurations on both sides of a skin crossing, and the spare serves the way back
    /// without a rebuild. Either list holds every pair within `range`, in ascending order, so
    /// the pair sums are bitwise the same whichever serves.
    pub fn ensure(&mut self, x: &[DVec3], exerts: &[bool], range: f64, skin: f64) -> bool {
        self.ensure_checked(x, exerts, range, skin, None)
    }

    /// [`VerletList::ensure`] with the displacement test of the current list already done
    /// (`within`, see [`VerletList::within_skin`]; None: done here).
    pub fn ensure_checked(
        &mut self,
        x: &[DVec3],
        exerts: &[bool],
        range: f64,
        skin: f64,
        within: Option<bool>,
    ) -> bool {
        if self.serves_checked(x, exerts, range, within) {
            self.served += 1;
            return false;
        }
        let mut scale = self.skin_scale.max(1.0);
        if self.builds > 0 && !self.rebuild_always {
            if self.served < SKIN_GROW_BELOW {
                scale = (scale * 2.0).min(SKIN_MAX_SCALE);
            } else if self.served > SKIN_SHRINK_ABOVE {
                scale = (scale * 0.5).max(1.0);
            }
        }
        if !self.rebuild_always {
            let spare_serves = self
                .spare
                .as_ref()
                .is_some_and(|s| s.serves(x, exerts, range));
            // the current list becomes the spare; the old spare's buffers are reused (or
            // serve as they are)
            let mut other = self.spare.take().unwrap_or_default();
            std::mem::swap(self, &mut other);
            (self.builds, self.rebuild_always) = (other.builds, other.rebuild_always);
            self.skin_scale = scale;
            self.spare = Some(other);
            self.served = 0;
            if spare_serves {
                return false;
            }
        }
        self.served = 0;
        self.build(x, exerts, range, skin.max(0.0) * scale);
        true
    }

    fn build(&mut self, x: &[DVec3], exerts: &[bool], range: f64, skin: f64) {
        let reach_range = range + skin;
        let mut cells = std::mem::take(&mut self.cells);
        cells.rebuild_with_reach(x, reach_range, 2, |j| exerts[j]);
        let n = x.len();
        // each chunk's particles: their sorted neighbours, counts and first entry j > i
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.resize_with(n.div_ceil(CHUNK), ChunkScratch::default);
        scratch.par_iter_mut().enumerate().for_each(|(c, s)| {
            let (a, b) = (c * CHUNK, ((c + 1) * CHUNK).min(n));
            s.counts.clear();
            s.ups.clear();
            s.js.clear();
            for i in a..b {
                let before = s.js.len();
                if x[i].is_finite() {
                    cells.for_each_neighbour(x, i, reach_range, |j, _| s.js.push(j as u32));
                }
                let own = &mut s.js[before..];
                own.sort_unstable();
                s.ups
                    .push(own.partition_point(|&j| (j as usize) < i) as u32);
                s.counts.push(own.len() as u32);
            }
        });
        self.cells = cells;
        // offsets (serial sums over the particles)
        self.starts.clear();
        self.starts.push(0);
        self.upper.clear();
        self.pair_base.clear();
        self.pair_base.push(0);
        let (mut entries, mut pairs) = (0u32, 0u32);
        for (c, s) in scratch.iter().enumerate() {
            for (k, (&count, &up)) in s.counts.iter().zip(&s.ups).enumerate() {
                entries += count;
                self.starts.push(entries);
                self.upper.push(up);
                if exerts.get(c * CHUNK + k).copied().unwrap_or(false) {
                    pairs += count - up;
                }
                self.pair_base.push(pairs);
            }
        }
        // each chunk's entries and slots straight into their place (in parallel: the list is
        // the same for any split)
        let total = entries as usize;
        self.neighbours.resize(total, 0);
        self.slots.resize(total, 0);
        let mut parts: Vec<(usize, &mut [u32], &mut [u32])> = Vec::with_capacity(scratch.len());
        let (mut nb, mut sl) = (self.neighbours.as_mut_slice(), self.slots.as_mut_slice());
        for (c, s) in scratch.iter().enumerate() {
            let (head, tail) = std::mem::take(&mut nb).split_at_mut(s.js.len());
            let (shead, stail) = std::mem::take(&mut sl).split_at_mut(s.js.len());
            parts.push((c, head, shead));
            (nb, sl) = (tail, stail);
        }
        let (starts, upper, pair_base) = (&self.starts, &self.upper, &self.pair_base);
        let scratch_ref = &scratch;
        // neighbour list of particle j, read from its chunk's scratch
        let list_of = |j: usize| -> &[u32] {
            let s = &scratch_ref[j / CHUNK];
            let first = starts[j / CHUNK * CHUNK];
            &s.js[(starts[j] - first) as usize..(starts[j + 1] - first) as usize]
        };
        parts.into_par_iter().for_each(|(c, nb, sl)| {
            let s = &scratch_ref[c];
            nb.copy_from_slice(&s.js);
            let (a, b) = (c * CHUNK, ((c + 1) * CHUNK).min(n));
            let mut e = 0;
            for i in a..b {
                let exerting = exerts.get(i).copied().unwrap_or(false);
                let own = list_of(i);
                for (k, &j) in own.iter().enumerate() {
                    let j = j as usize;
                    sl[e] = if !exerting {
                        NO_SLOT
                    } else if j > i {
                        pair_base[i] + (k as u32 - upper[i])
                    } else {
                        // i is in j's list (both exert, the test is symmetric)
                        match list_of(j).binary_search(&(i as u32)) {
                            Ok(pos) => pair_base[j] + (pos as u32 - upper[j]),
                            Err(_) => NO_SLOT,
                        }
                    };
                    e += 1;
                }
            }
        });
        self.scratch = scratch;
        self.reference.clear();
        self.reference.extend_from_slice(x);
        self.exerts.clear();
        self.exerts.extend_from_slice(exerts);
        self.range = range;
        self.skin = skin;
        self.builds += 1;
    }

    /// List entries of the particles `0..i` (those of every particle for `i` past the end; 0
    /// before the first build).
    pub fn entries_before(&self, i: usize) -> u64 {
        let last = self.starts.len().saturating_sub(1);
        self.starts.get(i.min(last)).copied().unwrap_or(0) as u64
    }

    /// Pairs owned by the particles `0..i` (as [`VerletList::entries_before`]).
    pub fn owned_before(&self, i: usize) -> u64 {
        self.owned_range(0, i).end as u64
    }

    /// Number of pair slots.
    pub fn pair_count(&self) -> usize {
        self.pair_base.last().copied().unwrap_or(0) as usize
    }

    /// The pairs particle `i` owns: its neighbours `j > i` and the slot of the first (the
    /// others follow consecutively). Empty when `i` does not exert.
    #[inline]
    pub fn owned(&self, i: usize) -> (&[u32], usize) {
        let (Some(&a), Some(&b), Some(&up)) =
            (self.starts.get(i), self.pair_base.get(i), self.upper.get(i))
        else {
            return (&[], 0);
        };
        let count = self.pair_base[i + 1] - b;
        let from = (a + up) as usize;
        (&self.neighbours[from..from + count as usize], b as usize)
    }

    /// Slots owned by particles `a..b`.
    pub fn owned_range(&self, a: usize, b: usize) -> std::ops::Range<usize> {
        let at = |i: usize| {
            self.pair_base
                .get(i.min(self.pair_base.len().saturating_sub(1)))
                .copied()
                .unwrap_or(0) as usize
        };
        at(a)..at(b)
    }

    /// Particle `i`'s entries `(j, slot)` in list order (`slot` is [`NO_SLOT`] when `i`
    /// does not exert).
    #[inline]
    pub fn entries(&self, i: usize) -> impl Iterator<Item = (usize, u32)> + '_ {
        let (a, b) = match (self.starts.get(i), self.starts.get(i + 1)) {
            (Some(&a), Some(&b)) => (a as usize, b as usize),
            _ => (0, 0),
        };
        self.neighbours[a..b]
            .iter()
            .zip(&self.slots[a..b])
            .map(|(&j, &s)| (j as usize, s))
    }

    /// Call `f(j, d)` for every listed `j` with `|d| < cutoff`, `d = x_i − x_j`, in the list's
    /// fixed order (`cutoff` no larger than the range of the last [`VerletList::ensure`]).
    #[inline]
    pub fn for_each_neighbour(
        &self,
        x: &[DVec3],
        i: usize,
        cutoff: f64,
        mut f: impl FnMut(usize, DVec3),
    ) {
        let (Some(&a), Some(&b)) = (self.starts.get(i), self.starts.get(i + 1)) else {
            return;
        };
        let xi = x[i];
        let c2 = cutoff * cutoff;
        for &j in &self.neighbours[a as usize..b as usize] {
            let d = xi - x[j as usize];
            if d.length_squared() < c2 {
                f(j as usize, d);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn brute(x: &[DVec3], exerts: &[bool], i: usize, cutoff: f64) -> Vec<usize> {
        (0..x.len())
            .filter(|&j| j != i && exerts[j] && (x[i] - x[j]).length() < cutoff)
            .collect()
    }

    /// Every pair of exerting particles has one slot, reached from both entries, and the
    /// owner's `owned` run lists it at that slot.
    fn check_slots(list: &VerletList, exerts: &[bool]) {
        let mut seen = vec![0u8; list.pair_count()];
        for (i, &exerting) in exerts.iter().enumerate() {
            let (owned, base) = list.owned(i);
            for (j, s) in list.entries(i) {
                if !exerting {
                    assert_eq!(s, NO_SLOT);
                    continue;
                }
                seen[s as usize] += 1;
                if j > i {
                    assert_eq!(owned[s as usize - base] as usize, j);
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 2), "each slot from both sides");
    }

    #[test]
    fn a_cached_list_finds_every_pair_until_it_is_rebuilt() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let n = 700;
        let mut x: Vec<DVec3> = (0..n)
            .map(|_| {
                DVec3::new(
                    rng.random_range(0.0..8.0),
                    rng.random_range(0.0..8.0),
                    rng.random_range(0.0..8.0),
                )
            })
            .collect();
        let mut exerts: Vec<bool> = (0..n).map(|i| i % 9 != 4).collect();
        let (range, skin) = (1.3, 0.4);
        let mut list = VerletList::default();
        let mut rebuilds = 0;
        for step in 0..60 {
            if step == 30 {
                exerts[17] = false; // a capture changes the exerting set
            }
            rebuilds += list.ensure(&x, &exerts, range, skin) as usize;
            check_slots(&list, &exerts);
            for i in 0..n {
                let mut got = vec![];
                list.for_each_neighbour(&x, i, range, |j, d| {
                    assert_eq!(d, x[i] - x[j]);
                    got.push(j)
                });
                got.sort();
                assert_eq!(got, brute(&x, &exerts, i, range), "step {step}, i {i}");
            }
            for p in x.iter_mut() {
                *p += DVec3::new(
                    rng.random_range(-0.05..0.05),
                    rng.random_range(-0.05..0.05),
                    rng.random_range(-0.05..0.05),
                );
            }
        }
        // cached: far fewer builds than evaluations, but more than one (the skin was crossed)
        assert!(rebuilds > 2 && rebuilds < 30, "{rebuilds}");
        assert_eq!(list.builds(), rebuilds as u64);
        // a larger range forces a rebuild; the uncached reference rebuilds every time
        assert!(list.ensure(&x, &exerts, 1.5, skin));
        list.rebuild_always = true;
        assert!(list.ensure(&x, &exerts, 1.5, skin));
    }

    #[test]
    fn the_spare_list_serves_a_rejected_step_s_way_back() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let n = 300;
        let xa: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 6.0)
            .collect();
        // a trial step moves one particle by more than half the skin, then is rejected
        let mut xb = xa.clone();
        xb[7] += DVec3::new(0.3, 0.0, 0.0);
        let exerts = vec![true; n];
        let (range, skin) = (1.0, 0.4);
        let mut list = VerletList::default();
        for round in 0..6 {
            let x = if round % 2 == 0 { &xa } else { &xb };
            list.ensure(x, &exerts, range, skin);
            check_slots(&list, &exerts);
            for i in 0..n {
                let mut got = vec![];
                list.for_each_neighbour(x, i, range, |j, _| got.push(j));
                assert_eq!(got, brute(x, &exerts, i, range), "round {round}, i {i}");
            }
        }
        assert_eq!(list.builds(), 2, "one build per configuration");
        // a third configuration that neither serves is built anew
        let mut xc = xa.clone();
        xc[9] += DVec3::new(0.0, 2.0, 0.0);
        assert!(list.ensure(&xc, &exerts, range, skin));
        assert_eq!(list.builds(), 3);
    }

    #[test]
    fn the_skin_grows_when_particles_outrun_it_and_every_pair_is_still_found() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
        let n = 200;
        let mut x: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 5.0)
            .collect();
        let exerts = vec![true; n];
        // every evaluation moves particles by up to 0.17 per axis: past the floor's half skin
        let (range, skin) = (0.5, 0.1);
        let mut list = VerletList::default();
        let evaluations = 200;
        for step in 0..evaluations {
            list.ensure(&x, &exerts, range, skin);
            check_slots(&list, &exerts);
            for i in 0..n {
                let mut got = vec![];
                list.for_each_neighbour(&x, i, range, |j, _| got.push(j));
                assert_eq!(got, brute(&x, &exerts, i, range), "step {step}, i {i}");
            }
            for p in x.iter_mut() {
                *p += DVec3::new(
                    rng.random_range(-0.1..0.1),
                    rng.random_range(-0.1..0.1),
                    rng.random_range(-0.1..0.1),
                );
            }
        }
        // with the floor's skin every evaluation would rebuild
        assert!(list.builds() < evaluations / 2, "{}", list.builds());
        assert!(list.skin > skin, "{}", list.skin);
    }

    #[test]
    fn non_finite_positions_force_a_rebuild_and_are_skipped() {
        let mut x = vec![DVec3::ZERO, DVec3::X * 0.5, DVec3::X * 5.0];
        let exerts = vec![true; 3];
        let mut list = VerletList::default();
        assert!(list.ensure(&x, &exerts, 1.0, 0.2));
        x[1] = DVec3::NAN;
        assert!(list.ensure(&x, &exerts, 1.0, 0.2));
        let mut seen = vec![];
        list.for_each_neighbour(&x, 0, 1.0, |j, _| seen.push(j));
        list.for_each_neighbour(&x, 1, 1.0, |j, _| seen.push(j));
        assert!(seen.is_empty());
    }
}
