//! Overlap removal: sequential (Gauss-Seidel) sweeps of single-particle moves.
//!
//! One sweep: find every particle with an overlap above the tolerance, shuffle them, and move
//! each in turn with its contacts recomputed at that moment (the thesis does not state the update
//! order, E13; in-place sweeps in random order are the spec's recommendation). One "attempt" is
//! one single-particle move (the thesis's try: ~200 N per compression step, L610). The run
//! succeeds when no overlap above the tolerance remains, and fails when the attempt budget is
//! spent first.

use glam::DVec3;
use rand::Rng;
use rand::seq::SliceRandom;

use super::contact::pair_contact;
use super::moves::{MoveContact, MoveRule, overlap_removal_move};
use super::neighbour::NeighbourList;
use super::state::PackingState;

/// Result of [`remove_overlaps`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RemovalOutcome {
    /// No overlap above the tolerance is left.
    pub success: bool,
    /// Single-particle moves made.
    pub attempts: u64,
    /// Sweeps made.
    pub sweeps: u64,
}

/// Overlapping contacts (overlap > `tol`) of particle `i`, written into `out`.
pub fn overlapping_contacts(
    state: &PackingState,
    list: &NeighbourList,
    i: usize,
    tol: f64,
    out: &mut Vec<MoveContact>,
) {
    out.clear();
    let bi = &state.bodies[i];
    let ui = state.axis(i);
    let xi = state.positions[i];
    for nb in list.of(i) {
        let j = nb.j as usize;
        let bj = &state.bodies[j];
        let r = state.positions[j] + nb.shift(state.edge) - xi;
        let c = pair_contact(
            ui,
            bi.half_length,
            bi.radius,
            r,
            state.axis(j),
            bj.half_length,
            bj.radius,
        );
        if c.overlap > tol {
            out.push(MoveContact {
                overlap: c.overlap,
                normal: c.normal,
                k: c.k,
                s: c.s,
            });
        }
    }
}

/// Total overlap (sum over unique pairs of max(overlap, 0)) and the flags of particles with an
/// overlap above `tol`.
pub fn overlap_scan(
    state: &PackingState,
    list: &NeighbourList,
    tol: f64,
    flags: &mut Vec<bool>,
) -> f64 {
    flags.clear();
    flags.resize(state.len(), false);
    let mut total = 0.0;
    for (i, j, shift) in list.unique_pairs(state.edge) {
        let c = state.contact(i, j, shift);
        if c.overlap > 0.0 {
            total += c.overlap;
        }
        if c.overlap > tol {
            flags[i] = true;
            flags[j] = true;
        }
    }
    total
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
    overlapping_contacts(state, list, i, tol, scratch);
    let body = state.bodies[i];
    let Some(d) = overlap_removal_move(rule, &body, state.orientations[i], scratch, rng) else {
        return false;
    };
    let old_axis = state.axis(i);
    state.positions[i] += d.dx;
    state.orientations[i] = (d.rotation * state.orientations[i]).normalize();
    let du: DVec3 = state.axis(i) - old_axis;
    list.note_move(i, d.dx, du, body.half_length);
    true
}

/// Remove overlaps above `tol` with at most `budget` single-particle moves.
pub fn remove_overlaps(
    state: &mut PackingState,
    list: &mut NeighbourList,
    rule: MoveRule,
    tol: f64,
    budget: u64,
    rng: &mut impl Rng,
) -> RemovalOutcome {
    let mut attempts = 0;
    let mut sweeps = 0;
    let mut flags = Vec::new();
    let mut order = Vec::new();
    let mut scratch = Vec::new();
    loop {
        list.ensure(state);
        overlap_scan(state, list, tol, &mut flags);
        order.clear();
        order.extend(
            flags
                .iter()
                .enumerate()
                .filter(|(_, f)| **f)
                .map(|(i, _)| i),
        );
        if order.is_empty() {
            return RemovalOutcome {
                success: true,
                attempts,
                sweeps,
            };
        }
        if attempts >= budget {
            return RemovalOutcome {
                success: false,
                attempts,
                sweeps,
            };
        }
        order.shuffle(rng);
        let mut moved_any = false;
        for &i in &order {
            if attempts >= budget {
                break;
            }
            if list.needs_rebuild() {
                list.build(state);
            }
            if move_particle(state, list, i, rule, tol, &mut scratch, rng) {
                attempts += 1;
                moved_any = true;
            }
        }
        sweeps += 1;
        if !moved_any {
            // every overlapping particle is stuck (no positive-rate contact): spend the budget
            return RemovalOutcome {
                success: false,
                attempts: budget.max(attempts),
                sweeps,
            };
        }
    }
}
