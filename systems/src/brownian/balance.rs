//! Part bounds that follow the measured times of the pair forces.
//!
//! [`super::parts::part_bounds`] splits the particles by a cost model (list entries, owned
//! pairs, particles). The model misses what each part really pays: the part after a bound
//! recomputes the pairs that straddle it (their owner is in the part before), a part's memory
//! traffic depends on where its particles are, and on a shared virtual machine one core can run
//! slower than the other for seconds at a time (on the 2-core machine of the benchmarks, the
//! same single-thread run of the LAMMPS-mirror scene took 2.3-2.6 s pinned to one core and
//! 2.4-3.1 s pinned to the other, alternated). With the bounds of the model, one part of the
//! mirror's pair pass took 9-11 % longer than the other at every step, and its thread's
//! partner waited.
//!
//! [`PartBalance`] keeps, per bound, a shift of its cost target (a fraction of the total
//! cost), learnt from each pair region's part times ([`next_shifts`]): at every bound, the
//! two neighbouring parts' time per unit of cost says how to move the bound so that both
//! would take the same time, and the shift moves a quarter of the way there. Regions where a
//! part was too short to time, where one thread did two parts (a busy pool), or where the two
//! times differ by more than a factor 3 (a thread preempted) teach nothing.
//!
//! Every kernel split into parts computes each particle's values in a fixed order, so the
//! results are bitwise the same for any bounds: the bounds move with the machine's timing, the
//! trajectory does not (tested with bounds shifted to either clamp in the model's tests, and
//! across thread counts in `tests/it/brownian_pipeline.rs`).

use std::sync::Mutex;

/// Fraction of the way to the balanced bound moved per observation.
const DAMPING: f64 = 0.25;
/// Largest shift of a bound, as a fraction of the total cost divided by the part count
/// (below 1/2, so that consecutive targets never cross).
const MAX_SHIFT: f64 = 0.4;
/// Shortest part time that is taken as a measurement \[s\].
const MIN_TIME_S: f64 = 20e-6;
/// Largest ratio of two neighbouring parts' times taken as a measurement.
const MAX_RATIO: f64 = 3.0;

/// The learnt shifts of the part bounds of one set of pair lists (see the module header). A
/// clone starts unshifted.
#[derive(Debug, Default)]
pub struct PartBalance(Mutex<State>);

#[derive(Debug, Default)]
struct State {
    parts: usize,
    n: usize,
    shifts: Vec<f64>,
}

impl Clone for PartBalance {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PartBalance {
    /// The shifts of the `parts - 1` inner bounds for `parts` parts of `n` particles (zeros
    /// until something was learnt for this split).
    pub fn shifts(&self, parts: usize, n: usize) -> Vec<f64> {
        let inner = parts.saturating_sub(1);
        match self.0.lock() {
            Ok(s) if s.parts == parts && s.n == n && s.shifts.len() == inner => s.shifts.clone(),
            _ => vec![0.0; inner],
        }
    }

    /// Set the shifts of `parts` parts of `n` particles (tests: bounds anywhere in their range).
    #[cfg(test)]
    pub(crate) fn set(&self, parts: usize, n: usize, shifts: Vec<f64>) {
        if let Ok(mut s) = self.0.lock() {
            *s = State { parts, n, shifts };
        }
    }

    /// Learn from one region over `parts = cost.len()` parts of `n` particles: `cost[p]`
    /// the model cost of part `p`, `time[p]` its time \[s\], `thread[p]` the pool thread
    /// that ran it.
    pub fn observe(&self, n: usize, cost: &[u64], time: &[f64], thread: &[usize]) {
        let parts = cost.len();
        let distinct = (1..thread.len()).all(|p| !thread[..p].contains(&thread[p]));
        if parts < 2 || time.len() != parts || thread.len() != parts || !distinct {
            return;
        }
        let Ok(mut s) = self.0.lock() else {
            return;
        };
        if s.parts != parts || s.n != n || s.shifts.len() != parts - 1 {
            *s = State {
                parts,
                n,
                shifts: vec![0.0; parts - 1],
            };
        }
        let cost: Vec<f64> = cost.iter().map(|&c| c as f64).collect();
        s.shifts = next_shifts(&s.shifts, &cost, time);
    }
}

/// The bound shifts after one observation: at each inner bound `b` (between parts `b - 1`
/// and `b`), the cost split of the two parts that equalises their times at their measured
/// time per cost, a quarter of the way from the current one, as a fraction of the total
/// cost, clamped to ±0.4 / parts. Bounds whose parts were not measured
/// properly keep their shift.
pub fn next_shifts(shifts: &[f64], cost: &[f64], time: &[f64]) -> Vec<f64> {
    let parts = cost.len();
    let total: f64 = cost.iter().sum();
    let limit = MAX_SHIFT / parts.max(1) as f64;
    let mut out = shifts.to_vec();
    if total <= 0.0 || time.len() != parts || shifts.len() + 1 != parts {
        return out;
    }
    for b in 1..parts {
        let (c0, c1, t0, t1) = (cost[b - 1], cost[b], time[b - 1], time[b]);
        let measured = c0 > 0.0
            && c1 > 0.0
            && t0.min(t1) >= MIN_TIME_S
            && t0.max(t1) <= MAX_RATIO * t0.min(t1);
        if !measured {
            continue;
        }
        // time per unit of cost of either side; the split with equal times gives the first
        // part the share r1 / (r0 + r1) of the two parts' cost
        let (r0, r1) = (t0 / c0, t1 / c1);
        let balanced = (c0 + c1) * r1 / (r0 + r1);
        let shift = out[b - 1] + DAMPING * (balanced - c0) / total;
        out[b - 1] = shift.clamp(-limit, limit);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two parts whose second costs 20 % more time per unit of cost: the learnt split
    /// equalises the times, within noise-free iteration, and stays put once equal.
    #[test]
    fn the_shift_equalises_the_parts_times() {
        let total = 1000.0;
        let rate = [1.0e-6, 1.2e-6];
        let mut shifts = vec![0.0];
        for _ in 0..60 {
            let c0 = total * (0.5 + shifts[0]);
            let cost = [c0, total - c0];
            let time = [cost[0] * rate[0], cost[1] * rate[1]];
            shifts = next_shifts(&shifts, &cost, &time);
        }
        // balanced: c0 * 1.0 = (1000 - c0) * 1.2, c0 = 545.45
        let c0 = total * (0.5 + shifts[0]);
        assert!((c0 - 545.4545).abs() < 0.5, "first part's cost {c0}");
        let again = next_shifts(
            &shifts,
            &[c0, total - c0],
            &[c0 * 1e-6, (total - c0) * 1.2e-6],
        );
        assert!((again[0] - shifts[0]).abs() < 1e-4);
    }

    /// Three parts, the middle one slow: both of its bounds move towards it.
    #[test]
    fn a_slow_middle_part_gets_less_work() {
        let rate = [1.0e-6, 2.0e-6, 1.0e-6];
        let mut shifts = vec![0.0, 0.0];
        let total = 3000.0;
        for _ in 0..200 {
            let b1 = total * (1.0 / 3.0 + shifts[0]);
            let b2 = total * (2.0 / 3.0 + shifts[1]);
            let cost = [b1, b2 - b1, total - b2];
            let time: Vec<f64> = cost.iter().zip(rate).map(|(c, r)| c * r).collect();
            shifts = next_shifts(&shifts, &cost, &time);
        }
        assert!(shifts[0] > 0.05 && shifts[1] < -0.05, "{shifts:?}");
        // the bounds stay ordered and inside the clamp
        let limit = MAX_SHIFT / 3.0;
        assert!(shifts.iter().all(|s| s.abs() <= limit + 1e-15));
    }

    /// Times too short to measure, too far apart (a preempted thread) or from one thread
    /// teach nothing; a changed split starts from zero.
    #[test]
    fn unreliable_times_teach_nothing() {
        let cost = [500.0, 500.0];
        assert_eq!(next_shifts(&[0.0], &cost, &[1e-6, 2e-6]), vec![0.0]);
        assert_eq!(next_shifts(&[0.01], &cost, &[1e-3, 5e-3]), vec![0.01]);
        let balance = PartBalance::default();
        balance.observe(100, &[500, 500], &[1e-3, 1.2e-3], &[0, 0]);
        assert_eq!(balance.shifts(2, 100), vec![0.0]);
        balance.observe(100, &[500, 500], &[1e-3, 1.2e-3], &[0, 1]);
        let learnt = balance.shifts(2, 100);
        assert!(learnt[0] > 0.0, "{learnt:?}");
        assert_eq!(balance.shifts(2, 101), vec![0.0]);
        assert_eq!(balance.shifts(3, 100), vec![0.0, 0.0]);
        assert_eq!(balance.clone().shifts(2, 100), vec![0.0]);
    }
}
