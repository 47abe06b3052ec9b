//! Deterministic multithreaded kernels of the single-particle overlap removal
//! ([`super::removal`]): the overlap scan and the Gauss-Seidel sweep, both exactly the serial
//! algorithm's results for any number of rayon threads.
//!
//! **Scan** ([`OverlapTracker`]). Which particles carry an overlap above the tolerance. The
//! pair contacts of the Verlet list ([`NeighbourList::unique`]) are evaluated in parallel on
//! the removal's [`Team`], each task writing its own pairs' overlaps, Newton starts and cached
//! contacts (a pair owns its two list entries, so the evaluations are independent); only the
//! per-particle counts of pairs above the tolerance are updated serially, in pair order. Between two
//! scans of one overlap removal only the particles that moved change their contacts, so after
//! the first (full) scan only the pairs with a moved end are evaluated again; the others keep
//! their overlap. This is exact up to the contact solver's own accuracy (~5e-11 D at most):
//! the serial code it replaces re-solved every pair from its cached solution, which returns
//! the same overlap to that accuracy. The first scan, and every scan after a list rebuild
//! (the rebuild wraps the centres and renumbers the pairs), is full.
//!
//! **Contact cache.** The scan keeps each superquadric pair's contact for both directed
//! entries (the other direction by symmetry: the same overlap, the normal reversed, the contact
//! points exchanged) with the move counts of both ends, and hands its Newton start to the other
//! direction too. A move of i that meets a pair whose ends have not moved since the scan takes
//! that contact instead of solving again: in a sweep where both ends of a pair move, the first
//! of them finds the pair as scanned, so each such pair costs two solves per sweep instead of
//! three. The contact is the one of the present poses either way; a new warm-started solve
//! differs only at the solver's accuracy (~5e-11 D at most), so the packing is not the old
//! one bit for bit, but it is still the same for any thread count (the cache is written only
//! by the scan, between sweeps). Rod pairs (closed-form contacts) are not cached. Moves and
//! scans need only the contacts above the tolerance, so a superquadric pair whose
//! separating-axis bound along its last contact normal is below it is not solved at all
//! ([`PackingState::contact_warm_above`]; the cache records it as such): in the dense regime
//! about three quarters of the pair evaluations end there.
//!
//! **Certificates.** The overlap of two convex bodies changes by no more than how far their
//! surface points move. So a pair that a scan found below the tolerance by some room (its
//! bound or solved overlap, [`PackingState::contact_warm_above`]) stays below it until its
//! two ends have together moved their points by that room; the tracker keeps each particle's
//! travel (the sum of its moves' translations and turn bounds) and skips such pairs in scans
//! and moves without evaluating them ([`OverlapTracker::certified`]). The answer is the one an
//! evaluation would give (at most the tolerance); only the Newton start of a pair that would
//! have been solved below the tolerance is not refreshed.
//!
//! **Sweep** ([`sweep`]). The serial sweep moves the flagged particles one after the other in a
//! shuffled order, each with its contacts evaluated at that moment. The move of particle i
//! reads only the poses of i and of its listed neighbours and the cached Newton starts of i's
//! own list entries (which only i's moves write). So the moves of a batch of B particles
//! (B = 4 x threads) are computed in parallel from the state at the start of the batch
//! (speculatively), then committed serially in the sweep order: a proposal is used as it is
//! when no neighbour of i has moved since the batch started, and recomputed at its turn
//! otherwise (and the batch is cut short when the list needs a rebuild). Every committed move
//! is therefore bit for bit the move of the serial sweep, for any B and any thread count. Only
//! the rules without random numbers (revised, original) run in batches; the random-direction
//! variants of fig. 3.4 use the serial loop.
//!
//! **Sweep by cells** ([`cells`]). When the box holds four cells of the list's reach along a
//! periodic axis, the rules without random numbers sweep in a checkerboard order instead: the
//! cells of one colour share no listed pair, so they run at once, each serially, without
//! stale proposals and with one join per colour instead of one per batch. It is a different
//! serial order from the plain shuffled one (the packings differ, statistically the same), and
//! again the same on any thread count.

use glam::{DQuat, DVec3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use smallvec::SmallVec;

use super::moves::{Displacement, MoveContact, MoveRule, overlap_removal_move};
use super::neighbour::NeighbourList;
use super::removal::turn_bound;
use super::state::{Body, PackingState};
use crate::geometry::superquadric::WarmStart;
use crate::par::team::Team;

/// Moves proposed per batch and thread of the parallel sweep.
pub const BATCH_PER_THREAD: usize = 4;

/// The Newton starts a move changed: (list entry, start). Inline up to four (a move in a dense
/// packing changes ~2.4), so that proposals are not heap-allocated.
pub type WarmChanges = SmallVec<[(u32, Option<WarmStart>); 4]>;

/// The move of one particle computed from a fixed state: the Newton starts it changed and its
/// displacement.
#[derive(Debug, Clone, Default)]
pub struct Proposal {
    /// The Newton starts the move changed: (list entry, start).
    warm: WarmChanges,
    displacement: Option<Displacement>,
    /// How far the move takes a surface point: the translation's length plus the rotation's
    /// [`turn_bound`] (0 without a move).
    travel: f64,
    /// The orientation after the move (normalised; the present one without a move).
    orientation: DQuat,
}

impl Proposal {
    /// Set the displacement of a particle of `body` at orientation `q`, with what the serial
    /// write-back needs of it computed here (in the parallel part): the travel and the new
    /// orientation.
    fn set_displacement(&mut self, body: &Body, q: DQuat, d: Option<Displacement>) {
        self.displacement = d;
        self.travel = d.map_or(0.0, |d| d.dx.length() + turn_bound(body, d.rotation));
        self.orientation = d.map_or(q, |d| (d.rotation * q).normalize());
    }
}

/// Overlapping contacts (overlap > `tol`) of particle `i` with its neighbours and the walls
/// into `out`, reading the cached Newton starts and writing the ones that changed into `warm`
/// (list entry, new start), without changing the list. With a `tracker`, superquadric pairs whose
/// ends have not moved since its last scan take the scanned contact instead of a new solve
/// ([`OverlapTracker::cached`]).
pub fn contacts_of(
    state: &PackingState,
    list: &NeighbourList,
    tracker: Option<&OverlapTracker>,
    i: usize,
    tol: f64,
    out: &mut Vec<MoveContact>,
    warm: &mut WarmChanges,
) {
    contacts_with(state, list, tracker, i, tol, out, warm, |_| None);
}

/// Whether two Newton starts are the same bit for bit (so that storing one over the other
/// changes nothing, signed zeros included).
fn same_bits(a: &Option<WarmStart>, b: &Option<WarmStart>) -> bool {
    let bits = |v: DVec3| v.to_array().map(f64::to_bits);
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => bits(a.s_a) == bits(b.s_a) && bits(a.s_b) == bits(b.s_b),
        _ => false,
    }
}

/// [`contacts_of`] where `moved(j)` gives the pose (centre, orientation) and the travel of a
/// neighbour `j` that has moved since the state was written (a cell sweep's moves before their
/// write-back), None for the state's own pose. A moved neighbour's pair is not taken from the
/// tracker's cache; it is skipped when the tracker certifies it with that travel counted, as
/// the serial order would after the write-back, and otherwise solved anew.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn contacts_with(
    state: &PackingState,
    list: &NeighbourList,
    tracker: Option<&OverlapTracker>,
    i: usize,
    tol: f64,
    out: &mut Vec<MoveContact>,
    warm: &mut WarmChanges,
    moved: impl Fn(usize) -> Option<((DVec3, DQuat), f64)>,
) {
    out.clear();
    warm.clear();
    let first = list.entry_start(i);
    let pose_i = (state.positions[i], state.orientations[i]);
    for k in first..first + list.of(i).len() {
        let nb = list.entry(k);
        let j = nb.j as usize;
        let old = list.warm(k);
        let mut w = old;
        // a moved neighbour's pose and pending travel, else its pose in the state, whose
        // pair the tracker may have cached since neither end moved
        let ((xj, qj), pending) = match moved(j) {
            Some(m) => m,
            None => {
                if let Some(c) = tracker.and_then(|t| t.cached(list, k, i, j)) {
                    if let Some(c) = c.filter(|c| c.overlap > tol) {
                        out.push(c);
                    }
                    continue;
                }
                ((state.positions[j], state.orientations[j]), 0.0)
            }
        };
        if tracker.is_some_and(|t| t.certified_after(list, k, i, j, pending)) {
            continue;
        }
        let pose_j = (xj + nb.shift(state.edges), qj);
        let c = state
            .contact_warm_above_at(i, pose_i, j, pose_j, &mut w, tol)
            .contact;
        if !same_bits(&w, &old) {
            warm.push((k as u32, w));
        }
        if let Some(c) = c {
            out.push(MoveContact::from(&c));
        }
    }
    let mut walls = Vec::new();
    state.wall_contacts(i, -tol, &mut walls);
    out.extend(walls.iter().map(MoveContact::from));
}

/// The move of particle `i` under `rule` in the present state (see [`commit`]).
#[allow(clippy::too_many_arguments)]
pub fn propose(
    state: &PackingState,
    list: &NeighbourList,
    tracker: Option<&OverlapTracker>,
    i: usize,
    rule: MoveRule,
    tol: f64,
    scratch: &mut Vec<MoveContact>,
    rng: &mut impl Rng,
) -> Proposal {
    let mut p = Proposal::default();
    contacts_of(state, list, tracker, i, tol, scratch, &mut p.warm);
    let body = &state.bodies[i];
    let q = state.orientations[i];
    p.set_displacement(body, q, overlap_removal_move(rule, body, q, scratch, rng));
    p
}

/// Apply the proposal of particle `i`: store its Newton starts and move it. Returns whether it
/// moved.
pub fn commit(state: &mut PackingState, list: &mut NeighbourList, i: usize, p: &Proposal) -> bool {
    for &(k, w) in &p.warm {
        *list.warm_mut(k as usize) = w;
    }
    let Some(d) = p.displacement else {
        return false;
    };
    state.positions[i] += d.dx;
    state.orientations[i] = p.orientation;
    list.note_travel(i, p.travel);
    true
}

/// [`commit`] and count it: a move that happened is an attempt, a move of the sweep and a
/// version step of particle `i` in the tracker. Returns whether it moved.
pub(crate) fn commit_counted(
    state: &mut PackingState,
    list: &mut NeighbourList,
    tracker: &mut OverlapTracker,
    i: usize,
    p: &Proposal,
    attempts: &mut u64,
    count: &mut SweepCount,
) -> bool {
    let moved = commit(state, list, i, p);
    if moved {
        *attempts += 1;
        count.moves += 1;
        tracker.note_moved(i, p.travel);
    }
    moved
}

/// Whether `rule` draws random numbers (then sweeps are serial).
pub fn uses_rng(rule: MoveRule) -> bool {
    matches!(
        rule,
        MoveRule::RevisedRandomRotation { .. } | MoveRule::RevisedRandomBoth { .. }
    )
}

/// Counters of one sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SweepCount {
    /// Moves made (attempts).
    pub moves: u64,
    /// Proposals recomputed because a neighbour had moved within the batch.
    pub recomputed: u64,
}

/// Move the particles of `order` once each (those still overlapping), in that order, until
/// `attempts` reaches `budget`; rebuilds the list when needed. `batch` = 1 is the serial
/// sweep; larger batches propose moves in parallel with identical results (module header).
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    state: &mut PackingState,
    list: &mut NeighbourList,
    tracker: &mut OverlapTracker,
    order: &[usize],
    rule: MoveRule,
    tol: f64,
    budget: u64,
    attempts: &mut u64,
    batch: usize,
    rng: &mut impl Rng,
    team: &Team<'_>,
) -> SweepCount {
    let mut count = SweepCount::default();
    let mut scratch = Vec::new();
    if batch <= 1 || uses_rng(rule) {
        for &i in order {
            if *attempts >= budget {
                break;
            }
            if list.needs_rebuild() {
                list.build(state);
            }
            let p = propose(state, list, Some(tracker), i, rule, tol, &mut scratch, rng);
            commit_counted(state, list, tracker, i, &p, attempts, &mut count);
        }
        return count;
    }
    // the rules that run here draw no random numbers: this stream is never read
    let mut no_rng = unused_rng();
    let mut stamp = vec![0u32; state.len()];
    let mut round = 0u32;
    let mut pos = 0;
    'batches: while pos < order.len() && *attempts < budget {
        if list.needs_rebuild() {
            list.build(state);
        }
        let end = (pos + batch).min(order.len());
        let ids = &order[pos..end];
        let (s, l, t) = (&*state, &*list, &*tracker);
        let proposals: Vec<Proposal> = team.map(ids.len(), |m| {
            let mut scratch = Vec::new();
            propose(
                s,
                l,
                Some(t),
                ids[m],
                rule,
                tol,
                &mut scratch,
                &mut unused_rng(),
            )
        });
        round += 1;
        for (m, (&i, p)) in ids.iter().zip(&proposals).enumerate() {
            if *attempts >= budget {
                break 'batches;
            }
            if m > 0 && list.needs_rebuild() {
                // the rebuild wraps the centres: the remaining proposals are stale
                list.build(state);
                pos += m;
                continue 'batches;
            }
            let stale = list.of(i).iter().any(|nb| stamp[nb.j as usize] == round);
            let p = if stale {
                count.recomputed += 1;
                &propose(
                    state,
                    list,
                    Some(tracker),
                    i,
                    rule,
                    tol,
                    &mut scratch,
                    &mut no_rng,
                )
            } else {
                p
            };
            if commit_counted(state, list, tracker, i, p, attempts, &mut count) {
                stamp[i] = round;
            }
        }
        pos = end;
    }
    count
}

/// A random stream for the rules that draw no random numbers ([`uses_rng`] false): never read
/// by them.
fn unused_rng() -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(0)
}

/// The batch of [`sweep`] for the current rayon pool: 1 (serial) on one thread.
pub fn batch_for_threads() -> usize {
    let t = rayon::current_num_threads();
    if t <= 1 { 1 } else { BATCH_PER_THREAD * t }
}

pub mod cells;
mod tracker;

pub use tracker::{OverlapTracker, ScanCount};

#[cfg(test)]
mod tests;
