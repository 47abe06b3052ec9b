//! A fixed split of the particles among the rayon pool's threads, held across the phases of a
//! step: the pair forces, the fixed step's update and the write-back to the components each
//! run as one parallel region over the same parts, and a thread takes the part of its own
//! pool index first, so it handles the same particles in every phase and every step and their
//! positions, forces and random streams stay in its core's cache (with rayon's adaptive
//! splits, each phase cut the particles differently and the write-back read every particle on
//! one thread: at 2 threads the update alone took 2.4 times its 1-thread CPU time, its data
//! coming from the other core's cache).
//!
//! The parts are contiguous index ranges with about equal pair work
//! ([`part_bounds`]: list entries and owned pairs, plus a per-particle term), so they do not
//! depend on where the particles are, only on the lists. Every particle's values are its own
//! computation in a fixed order, so the results are bitwise the same for any split and any
//! thread count; a part that its thread has not taken yet is done by whichever thread is free,
//! so a busy pool (replicates run side by side) is never waited for.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::model::{ForceModel, PairLists, ParticleView, dipole_pair};
use super::verlet::NO_SLOT;

/// Fewest particles split among the threads (below, one part on the calling thread: a
/// parallel region costs more wake-up time than it saves).
pub const SPLIT_MIN: usize = 1024;

/// Cost of a particle's own work (update, write-back) in list entries, in [`part_bounds`].
const PARTICLE_COST: u64 = 8;

/// Number of parts for `n` particles: the pool's threads from [`SPLIT_MIN`] particles, else 1.
pub fn part_count(n: usize) -> usize {
    if n < SPLIT_MIN {
        1
    } else {
        rayon::current_num_threads().clamp(1, n)
    }
}

/// `parts + 1` bounds splitting `0..n` into contiguous parts of about equal cost, where
/// `prefix(i)` is the (nondecreasing) cost of the particles `0..i`, with the cost target of
/// inner bound `p` (1-based) moved by `shifts[p - 1]` times the total cost (see
/// [`super::balance`]; missing shifts are zero).
pub fn shifted_bounds(
    n: usize,
    parts: usize,
    shifts: &[f64],
    prefix: impl Fn(usize) -> u64,
) -> Vec<usize> {
    let parts = parts.max(1);
    let total = prefix(n) as u128;
    let mut bounds = Vec::with_capacity(parts + 1);
    bounds.push(0);
    for p in 1..parts {
        let share = p as f64 / parts as f64 + shifts.get(p - 1).copied().unwrap_or(0.0);
        let target = (total as f64 * share.clamp(0.0, 1.0)) as u128;
        // the first i whose prefix reaches the target
        let (mut lo, mut hi) = (*bounds.last().unwrap_or(&0), n);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if (prefix(mid) as u128) < target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        bounds.push(lo);
    }
    bounds.push(n);
    bounds
}

/// The parts of `n` particles for the pair lists `lists` ([`part_count`] of them): about
/// equal dipole pairs owned (the pair pass, weighted twice), list entries (the gathers) and
/// particles (the update). Every phase of a step asks for these same bounds.
///
/// The bounds are moved from the cost model's by the shifts that the lists'
/// [`PartBalance`](super::balance::PartBalance) learnt from the pair pass's part times.
pub fn part_bounds(lists: &PairLists, n: usize) -> Vec<usize> {
    let parts = part_count(n);
    let shifts = lists.balance.shifts(parts, n);
    shifted_bounds(n, parts, &shifts, |i| part_cost_before(lists, i))
}

/// The cost model of [`part_bounds`] of the particles `0..i`.
fn part_cost_before(lists: &PairLists, i: usize) -> u64 {
    let (d, c) = (&lists.dipole, &lists.contact);
    2 * d.owned_before(i) + d.entries_before(i) + c.entries_before(i) + PARTICLE_COST * i as u64
}

/// The displacement tests of the dipole and contact lists ([`super::verlet::VerletList::within_skin`])
/// in the parts of the step, one parallel region for both (None, None: one part, the lists
/// test on the calling thread).
pub fn lists_within_skin(x: &[DVec3], lists: &PairLists) -> (Option<bool>, Option<bool>) {
    lists_within_skin_and(x, lists, (&mut [], &mut []), |_, _, _| {})
}

/// [`lists_within_skin`], and in the same region `also(a, m, f)` for each part `a..b` with
/// `m` and `f` that part's slices of `values` (used for the moments of a uniform field, see
/// [`ForceModel::prepare_step`]; empty `values` give empty slices).
pub fn lists_within_skin_and(
    x: &[DVec3],
    lists: &PairLists,
    values: (&mut [DVec3], &mut [DVec3]),
    also: impl Fn(usize, &mut [DVec3], &mut [DVec3]) + Sync + Clone,
) -> (Option<bool>, Option<bool>) {
    let bounds = part_bounds(lists, x.len());
    if bounds.len() <= 2 {
        also(0, values.0, values.1);
        return (None, None);
    }
    let (dipole, contact) = (AtomicBool::new(true), AtomicBool::new(true));
    let (d, c, b) = (&dipole, &contact, bounds.as_slice());
    // empty `values` split into empty parts (`split_at_bounds` clamps)
    let items: Vec<_> = split_at_bounds(values.0, b)
        .into_iter()
        .zip(split_at_bounds(values.1, b))
        .collect();
    run_parts(items, move |p, (m, f)| {
        also(b[p], m, f);
        if !lists.dipole.within_skin(x, b[p], b[p + 1]) {
            d.store(false, Ordering::Relaxed);
        }
        if !lists.contact.within_skin(x, b[p], b[p + 1]) {
            c.store(false, Ordering::Relaxed);
        }
    });
    (Some(dipole.into_inner()), Some(contact.into_inner()))
}

/// `f(p, item)` for every part `p` and its item, one part per pool thread: thread `t` takes
/// part `t mod parts` first, then any part nobody has taken. One part runs on the calling
/// thread. Returns each part's result, in part order.
///
/// Each thread runs its own copy of `f`: a closure's captures live in the calling thread's
/// stack frame, in cache lines that thread keeps writing while it runs its own part, and the
/// other thread reading them there at every particle took its update 3.7 times its 1-thread
/// CPU time (capture by `move` so that the copy holds the values, not references to them).
pub fn run_parts<T: Send, R: Send>(
    items: Vec<T>,
    f: impl Fn(usize, T) -> R + Sync + Clone,
) -> Vec<R> {
    let parts = items.len();
    if parts <= 1 {
        return items.into_iter().map(|t| f(0, t)).collect();
    }
    let slots: Vec<Mutex<Option<T>>> = items.into_iter().map(|t| Mutex::new(Some(t))).collect();
    let done: Vec<Mutex<Option<R>>> = (0..parts).map(|_| Mutex::new(None)).collect();
    let take = |p: usize| slots[p].lock().ok().and_then(|mut g| g.take());
    let put = |p: usize, r: R| {
        if let Ok(mut g) = done[p].lock() {
            *g = Some(r);
        }
    };
    (0..parts).into_par_iter().with_max_len(1).for_each(|_| {
        let f = std::hint::black_box(f.clone());
        let own = rayon::current_thread_index().unwrap_or(0) % parts;
        if let Some(t) = take(own) {
            put(own, f(own, t));
        }
        for p in 0..parts {
            if let Some(t) = take(p) {
                put(p, f(p, t));
            }
        }
    });
    // every part ran exactly once (a panic in `f` propagates out of the region)
    done.into_iter()
        .filter_map(|m| m.into_inner().ok().flatten())
        .collect()
}

/// Split `v` at `bounds` (ascending, the last no more than `v.len()`) into mutable parts.
pub fn split_at_bounds<'a, T>(v: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(bounds.len().saturating_sub(1));
    let mut rest = v;
    let mut at = bounds.first().copied().unwrap_or(0);
    for &b in bounds.iter().skip(1) {
        let len = b.saturating_sub(at).min(rest.len());
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        out.push(head);
        rest = tail;
        at = b;
    }
    out
}

/// [`ForceModel::pair_forces`] in parts ([`part_bounds`]) with no barrier: each part computes
/// the dipole pairs its particles own into their slots, then gathers its particles' dipole
/// sums and contact sums. A pair owned by a particle of an earlier part is computed again
/// there, with the owner's expression (the same bits as its slot), instead of being read from
/// the other part's slots. The same values as the separate passes, bit for bit.
pub fn pair_forces_in_parts(
    model: &ForceModel,
    x: &[DVec3],
    moments: &[DVec3],
    view: &ParticleView,
    lists: &PairLists,
    (dipole, contact): (&mut [DVec3], &mut [DVec3]),
) {
    let n = x.len().min(dipole.len()).min(contact.len());
    let bounds = part_bounds(lists, n);
    let cut = model.dipole_cutoff;
    let list = &lists.dipole;
    let mut pf = match cut {
        Some(_) => lists.pair_scratch.take(list.pair_count()),
        None => Vec::new(),
    };
    let slot_bounds: Vec<usize> = bounds.iter().map(|&b| list.owned_range(0, b).end).collect();
    let items: Vec<_> = split_at_bounds(&mut pf, &slot_bounds)
        .into_iter()
        .zip(split_at_bounds(dipole, &bounds))
        .zip(split_at_bounds(contact, &bounds))
        .collect();
    let range = model.contact_range(view);
    // each part's time and thread, for the balance of the bounds
    let clocks = run_parts(items, |p, ((own, d), c)| {
        let started = Instant::now();
        let (a, b) = (bounds[p], bounds[p + 1]);
        let base = slot_bounds[p];
        if let Some(cut) = cut {
            // the pairs the part's particles own, in slot order
            let mut slots = own.iter_mut();
            for i in a..b {
                let (js, _) = list.owned(i);
                let (xi, ai, mi) = (x[i], view.radii[i], moments[i]);
                for (&j, o) in js.iter().zip(&mut slots) {
                    let j = j as usize;
                    *o = dipole_pair(cut, xi - x[j], (ai, view.radii[j]), mi, moments[j]);
                }
            }
        }
        let own: &[DVec3] = own;
        for i in a..b {
            d[i - a] = match cut {
                Some(cut) if view.mobile[i] && moments[i] != DVec3::ZERO => {
                    let mut sum = DVec3::ZERO;
                    for (j, s) in list.entries(i) {
                        // a slot of this part (NO_SLOT and earlier parts' slots wrap past it)
                        sum += match own.get((s as usize).wrapping_sub(base)) {
                            Some(&p) if j > i => p,
                            Some(&p) => -p,
                            None if s == NO_SLOT => dipole_pair(
                                cut,
                                x[i] - x[j],
                                (view.radii[i], view.radii[j]),
                                moments[i],
                                moments[j],
                            ),
                            // owned by a particle of an earlier part: its expression
                            None => -dipole_pair(
                                cut,
                                x[j] - x[i],
                                (view.radii[j], view.radii[i]),
                                moments[j],
                                moments[i],
                            ),
                        };
                    }
                    sum
                }
                _ => DVec3::ZERO,
            };
            c[i - a] = model.contact_force_on(x, view, lists, range, i);
        }
        let thread = rayon::current_thread_index().unwrap_or(usize::MAX);
        (started.elapsed().as_secs_f64(), thread)
    });
    if cut.is_some() {
        lists.pair_scratch.put(pf);
    }
    if bounds.len() > 2 {
        let (time, thread): (Vec<f64>, Vec<usize>) = clocks.into_iter().unzip();
        let cost: Vec<u64> = bounds
            .windows(2)
            .map(|w| part_cost_before(lists, w[1]) - part_cost_before(lists, w[0]))
            .collect();
        lists.balance.observe(n, &cost, &time, &thread);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_split_the_cost_evenly_and_cover_every_particle() {
        // the first 100 particles cost 10 each, the other 900 one each: 1900 in all
        let prefix = |i: usize| (10 * i.min(100) + i.saturating_sub(100)) as u64;
        assert_eq!(shifted_bounds(1000, 2, &[], prefix), vec![0, 95, 1000]);
        let b = shifted_bounds(1000, 4, &[], prefix);
        assert_eq!((b[0], b[4]), (0, 1000));
        assert!(b.windows(2).all(|w| w[0] <= w[1]));
        for p in 0..4 {
            let cost = prefix(b[p + 1]) - prefix(b[p]);
            assert!((470..=480).contains(&cost), "part {p}: {cost}");
        }
        assert_eq!(shifted_bounds(0, 3, &[], prefix), vec![0, 0, 0, 0]);
        assert_eq!(shifted_bounds(5, 1, &[], prefix), vec![0, 5]);
    }

    #[test]
    fn every_part_runs_once_on_any_pool() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut v: Vec<u32> = (0..1000).collect();
            let bounds = [0, 10, 10, 600, 1000];
            pool.install(|| {
                let parts = split_at_bounds(&mut v, &bounds);
                assert_eq!(
                    parts.iter().map(|p| p.len()).collect::<Vec<_>>(),
                    [10, 0, 590, 400]
                );
                run_parts(parts, |p, part| {
                    for x in part.iter_mut() {
                        *x = *x * 10 + p as u32;
                    }
                });
            });
            for (i, x) in v.iter().enumerate() {
                let p = bounds
                    .windows(2)
                    .position(|w| (w[0]..w[1]).contains(&i))
                    .unwrap();
                assert_eq!(*x, i as u32 * 10 + p as u32);
            }
        }
    }
}
