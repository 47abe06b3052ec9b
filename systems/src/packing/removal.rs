//! Overlap removal: sequential (Gauss-Seidel) sweeps of single-particle moves.
//!
//! One sweep: find every particle with an overlap above the tolerance, shuffle them, and move
//! each in turn with its contacts recomputed at that moment (the thesis does not state the update
//! order, E-000-13; in-place sweeps in random order are the convention of D-000-19). One "attempt" is
//! one single-particle move (the thesis's try: ~200 N per compression step, [T000 §3.2]). The run
//! succeeds when no overlap above the tolerance remains, and fails when the attempt budget is
//! spent first. In a box that holds four cells of the neighbour list's reach along a periodic
//! axis, the shuffled particles are visited cell by cell in a checkerboard order instead
//! ([`super::sweep::cells`]: still random, in-place and serial in effect, and it runs on
//! several threads); the budget is then tested before each colour's run of cells.
//!
//! The scans and sweeps run on the current rayon pool with results independent of the thread
//! count ([`super::sweep`]); [`overlap_scan`] is the serial full scan they are tested against.

use glam::DQuat;
use rand::Rng;
use rand::seq::SliceRandom;

use super::moves::{MoveContact, MoveRule};
use super::neighbour::NeighbourList;
use super::state::{Body, BodyKind, PackingState};
use super::sweep::cells::{SweepCells, sweep_cells};
use super::sweep::{
    OverlapTracker, batch_for_threads, commit, contacts_of, propose, sweep, uses_rng,
};
use crate::par::team::Team;

/// Result of [`remove_overlaps`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RemovalOutcome {
    /// No overlap above the tolerance is left.
    pub success: bool,
    /// Single-particle moves made.
    pub attempts: u64,
    /// Sweeps made.
    pub sweeps: u64,
    /// Pair contacts evaluated in overlap scans.
    pub contacts: u64,
    /// Of which the contact solver fell back to its estimate (superquadrics).
    pub fallbacks: u64,
}

/// Overlapping contacts (overlap > `tol`) of particle `i` with its neighbours and the walls,
/// written into `out` (the pairs' cached Newton starts updated).
pub fn overlapping_contacts(
    state: &PackingState,
    list: &mut NeighbourList,
    i: usize,
    tol: f64,
    out: &mut Vec<MoveContact>,
) {
    let mut warm = super::sweep::WarmChanges::new();
    contacts_of(state, list, None, i, tol, out, &mut warm);
    for (k, w) in warm {
        *list.warm_mut(k as usize) = w;
    }
}

/// Result of [`overlap_scan`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OverlapScan {
    /// Sum over pairs and wall contacts of max(overlap, 0) / D.
    pub total: f64,
    /// Largest overlap / D.
    pub max: f64,
    /// Pair contacts evaluated.
    pub contacts: u64,
    /// Of which the contact solver fell back to its estimate (superquadrics).
    pub fallbacks: u64,
}

/// Total overlap (pairs and walls) and the flags of particles with an overlap above `tol`:
/// every pair evaluated serially (the reference of [`OverlapTracker::scan`]).
pub fn overlap_scan(
    state: &PackingState,
    list: &mut NeighbourList,
    tol: f64,
    flags: &mut Vec<bool>,
) -> OverlapScan {
    flags.clear();
    flags.resize(state.len(), false);
    let mut scan = OverlapScan::default();
    for idx in 0..list.unique().len() {
        let p = list.unique()[idx];
        let (i, j, k) = (p.i as usize, p.j as usize, p.k as usize);
        let shift = list.entry(k).shift(state.edges);
        let c = state.contact_warm(i, j, shift, list.warm_mut(k));
        scan.contacts += 1;
        scan.fallbacks += c.fallback as u64;
        if c.overlap > 0.0 {
            scan.total += c.overlap;
            scan.max = scan.max.max(c.overlap);
        }
        if c.overlap > tol {
            flags[i] = true;
            flags[j] = true;
        }
    }
    let mut walls = Vec::new();
    for (i, flag) in flags.iter_mut().enumerate() {
        walls.clear();
        state.wall_contacts(i, 0.0, &mut walls);
        for c in &walls {
            scan.total += c.overlap.max(0.0);
            scan.max = scan.max.max(c.overlap);
            if c.overlap > tol {
                *flag = true;
            }
        }
    }
    scan
}

/// How far a rotation `r` (a unit quaternion) can move a surface point of `body` relative to
/// its centre / D: the chord 2 R sin(theta/2) of the reach R, with sin(theta/2) the length of
/// the quaternion's vector part (no inverse cosine and sine on the move's path).
#[inline]
pub fn turn_bound(body: &Body, r: DQuat) -> f64 {
    if !body.rotates() {
        return 0.0;
    }
    let half_sin = r.xyz().length().min(1.0);
    let reach = match body.kind {
        BodyKind::Rod => body.half_length,
        BodyKind::Superquadric(_) => body.bounding_radius(),
    };
    reach * 2.0 * half_sin
}

/// Move particle `i` once with `rule` if it overlaps anything above `tol`. Returns whether it
/// moved.
pub fn move_particle(
    state: &mut PackingState,
    list: &mut NeighbourList,
    i: usize,
    rule: MoveRule,
    tol: f64,
    scratch: &mut Vec<MoveContact>,
    rng: &mut impl Rng,
) -> bool {
    let p = propose(state, list, None, i, rule, tol, scratch, rng);
    commit(state, list, i, &p)
}

/// Remove overlaps above `tol` with at most `budget` single-particle moves, on the threads of
/// the current rayon pool (the same result for any number: [`super::sweep`]).
pub fn remove_overlaps(
    state: &mut PackingState,
    list: &mut NeighbourList,
    rule: MoveRule,
    tol: f64,
    budget: u64,
    rng: &mut impl Rng,
) -> RemovalOutcome {
    remove_overlaps_batched(state, list, rule, tol, budget, batch_for_threads(), rng)
}

/// [`remove_overlaps`] with `batch` moves proposed at a time in the plain shuffled order (1:
/// the serial sweep); a sweep by cells ([`super::sweep::cells`]) has its own order and
/// ignores `batch`. The parallel phases run on a [`Team`] of the current rayon pool's size.
pub fn remove_overlaps_batched(
    state: &mut PackingState,
    list: &mut NeighbourList,
    rule: MoveRule,
    tol: f64,
    budget: u64,
    batch: usize,
    rng: &mut impl Rng,
) -> RemovalOutcome {
    Team::scope(|team| {
        let mut attempts = 0;
        let mut sweeps = 0;
        let mut flags = Vec::new();
        let mut order = Vec::new();
        let mut tracker = OverlapTracker::new();
        let (mut contacts, mut fallbacks) = (0, 0);
        loop {
            list.ensure(state);
            let scan = tracker.scan(state, list, tol, &mut flags, team);
            contacts += scan.contacts;
            fallbacks += scan.fallbacks;
            order.clear();
            order.extend(
                flags
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| **f)
                    .map(|(i, _)| i),
            );
            let outcome = |success, attempts| RemovalOutcome {
                success,
                attempts,
                sweeps,
                contacts,
                fallbacks,
            };
            if order.is_empty() {
                return outcome(true, attempts);
            }
            if attempts >= budget {
                return outcome(false, attempts);
            }
            order.shuffle(rng);
            let cells = if uses_rng(rule) {
                None
            } else {
                SweepCells::choose(state, list, rng)
            };
            let swept = match cells {
                Some(cells) => sweep_cells(
                    state,
                    list,
                    &mut tracker,
                    &order,
                    &cells,
                    rule,
                    tol,
                    budget,
                    &mut attempts,
                    team,
                ),
                None => sweep(
                    state,
                    list,
                    &mut tracker,
                    &order,
                    rule,
                    tol,
                    budget,
                    &mut attempts,
                    batch,
                    rng,
                    team,
                ),
            };
            sweeps += 1;
            if swept.moves == 0 {
                // every overlapping particle is stuck (no positive-rate contact): spend the budget
                return RemovalOutcome {
                    success: false,
                    attempts: budget.max(attempts),
                    sweeps,
                    contacts,
                    fallbacks,
                };
            }
        }
    })
}
