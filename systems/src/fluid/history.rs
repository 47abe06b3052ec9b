//! Basset history integral: full-memory product integration and the window + exponential-tail
//! kernel of van Hinsberg, ten Thije Boonkkamp & Clercx (2011, J. Comput. Phys. 230:1465).
//!
//! ## Equations
//! With the slip `w(t) = u(x_p(t), t) − v(t)` (fluid velocity at the particle minus particle
//! velocity), the Basset force of the extended Maxey–Riley equation (thesis 002 eq. 2.26,
//! [T002 §2.2.4.1]) with the step-change terms of eqs. 2.27–2.29 is `F_H = c_H · I(t)`,
//!
//! ```text
//! I(t) = ∫_{t_s}^{t} (dw/dτ) (t − τ)^{−1/2} dτ  +  J_s (t − t_s)^{−1/2},
//! c_H  = (3/2) d_p² √(π ρ_f μ)                                   (basset_coefficient)
//! ```
//!
//! where `(t_s, J_s)` is the last step change of the slip: the start `t_s = t0` with
//! `J_s = w(t0)` (eq. 2.27), or a collision at `t_c` with `J = w(t_c⁺) − w(t_c⁻) =
//! v(t_c⁻) − v(t_c⁺)`, after which **all pre-collision history is discarded** (eq. 2.29, the
//! thesis's modelling choice "the pre-collision history can be set to zero", [T002 §2.2.4.1]).
//!
//! **Product integration.** On a uniform grid `t_k = t_origin + kΔt` the slope
//! `g_k = Δw_k/Δt`, `Δw_k = w_{k+1} − w_k`, is taken constant on `[t_k, t_{k+1}]` (`w`
//! piecewise linear) and the kernel is integrated exactly over each interval, so the
//! singular end point needs no special care. Evaluated at `t_m`, the interval whose far end is
//! `j` steps back (lag `j`, `j = 0` the newest) has the weight
//!
//! ```text
//! c_j = (2/√Δt)(√(j+1) − √j) = 2 / (√Δt (√(j+1) + √j)),     I(t_m) = Σ_j c_j Δw_{m−1−j} + jump
//! ```
//!
//! (the second form is used: it has no cancellation at large `j`).
//!
//! **Window + tail.** [`HistoryKernel::Window`] keeps the last `N_w` intervals (lags
//! `0..N_w`, i.e. `s = t − τ ∈ [0, t_win]`, `t_win = N_w Δt`) with the exact weights; for older
//! intervals (`s ≥ t_win`) the kernel is replaced by ten exponentials,
//!
//! ```text
//! s^{−1/2} ≈ Σ_{i=1}^{10} a_i √(e/t_i) exp(−s/(2 t_i)),   t_i = t̃_i t_win       (tail_kernel)
//! ```
//!
//! with [`TAIL_TIMES`] `t̃_i` and [`TAIL_AMPLITUDES`] `a_i` of van Hinsberg et al. Each
//! exponential has an exactly recursive state (per component)
//!
//! ```text
//! F_i(t_m) = Σ_{j ≥ N_w} (Δw_{m−1−j}/Δt) 2t_i (e^{−jΔt/(2t_i)} − e^{−(j+1)Δt/(2t_i)})
//! F_i ← e^{−Δt/(2t_i)} F_i + (Δw_leaving/Δt) 2t_i (e^{−N_wΔt/(2t_i)} − e^{−(N_w+1)Δt/(2t_i)})
//! tail(t_m) = Σ_i a_i √(e/t_i) F_i(t_m)
//! ```
//!
//! where `Δw_leaving` is the increment whose lag becomes `N_w` in that step. The recursion
//! equals the direct sum with the exponential kernel to round-off (tested). With
//! `tail: false` the old intervals are simply dropped (a truncated window, to show why the
//! tail matters).
//!
//! ## Errors and costs
//! * Product integration of a smooth `w` converges like `O(Δt^{3/2})` (the slope error times
//!   the singular kernel near `s = 0`); it is exact for piecewise-linear `w` (tested: measured
//!   order 1.5).
//! * The tail kernel's relative error (measured) is `6.1e-5` at `s = t_win`, `≤ 0.28 %` on
//!   `[t_win, 30 t_win]` (maximum at `7.9 t_win`; the 0.2 % of D-002-4 is slightly optimistic),
//!   `≤ 0.7 %` up to `100 t_win` and `≤ 3.3 %` up to `1000 t_win`, so the tail's error is that
//!   fraction of the (small) old-history contribution. Over `10⁴` steps with `N_w = 100` the
//!   window + tail stays within `3e-3 max|I|` of the full memory; the truncated window is off
//!   by `50–85 %`.
//! * [`HistoryKernel::Full`] costs `O(n)` per call and memory `O(n)` (the reference);
//!   [`HistoryKernel::Window`] costs `O(N_w + 10)` per call, independent of `n`. No call
//!   allocates once the window buffer is full.
//!
//! ## Assumptions
//! * Uniform step `Δt` ([`HistoryPlan`]); a variable step needs a new plan and a restarted
//!   state (the buffer's lags are in units of `Δt`).
//! * Classic Basset kernel (no finite-Re kernel, [T002 §2.2.4.1]).
//! * After a collision during the step `[t_n, t_{n+1}]` the slip is taken constant from `t_c`
//!   to `t_{n+1}` (the buffer restarts at the step boundary), while the jump term uses the true
//!   `t_c` ([`HistoryState::reset_at_collision`]).
//!
//! ## Use by an integrator
//! * **Implicit** newest weight (stable for small particles, D-002-2):
//!   `F_H(t_{n+1}) = c_H (past_integral(t_{n+1}) + c_0 (w_{n+1} − w_n))` with
//!   `c_0 =` [`HistoryPlan::newest_weight`]; the `c_H c_0` part moves to the effective mass.
//! * **Explicit** (the thesis's forward Euler): `F_H(t_n) = c_H current_integral(t_n)`.
//! * Then [`HistoryState::push`] the new slip sample `w_{n+1}`.
//!
//! ```
//! use glam::DVec3;
//! use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
//! // slip w(t) = 3 t (x component), started at rest: I(t) = 2 · 3 · √t exactly
//! let plan = HistoryPlan::new(0.01, HistoryKernel::Full).unwrap();
//! let mut state = HistoryState::new(DVec3::ZERO, 0.0);
//! for n in 1..=100 {
//!     state.push(&plan, DVec3::new(3.0 * 0.01 * n as f64, 0.0, 0.0));
//! }
//! let i = state.current_integral(&plan, 1.0);
//! assert!((i.x - 6.0).abs() < 1e-12);
//! ```

use std::collections::VecDeque;

use glam::DVec3;
use serde::{Deserialize, Serialize};

#[path = "history_plan.rs"]
mod plan;
pub use plan::*;

/// Per-particle history (3 components): the increments of the current window (or all of them,
/// for [`HistoryKernel::Full`]), the exponential-tail sums, the last step change `(t_s, J_s)`
/// and the last slip sample. Cheap to clone (`O(N_w)`), serialisable.
///
/// **Time grid.** Samples lie at `t_origin + k Δt`; after `n` pushes the last sample is at
/// [`HistoryState::time`] `= t_origin + n Δt`. The origin is `t0` of [`HistoryState::new`] or
/// `t_next_sample` of [`HistoryState::reset_at_collision`].
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
/// // a constant slip switched on at t0 = 1: I(t) = w0/√(t − t0)
/// let plan = HistoryPlan::new(0.1, HistoryKernel::Window { steps: 4, tail: true }).unwrap();
/// let mut s = HistoryState::new(DVec3::Y * 2.0, 1.0);
/// (0..40).for_each(|_| s.push(&plan, DVec3::Y * 2.0));
/// assert!((s.current_integral(&plan, s.time(&plan)).y - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryState {
    /// Slip increments `Δw_k` [m/s], oldest at the front.
    increments: VecDeque<DVec3>,
    /// Exponential-tail states `F_i` [m/s].
    tail: [DVec3; TAIL_TERMS],
    /// Time of the last step change `t_s` [s].
    jump_time: f64,
    /// The last step change `J_s` [m/s].
    jump: DVec3,
    /// The last slip sample `w_n` [m/s].
    last_slip: DVec3,
    /// Time of the buffer's first sample [s].
    origin: f64,
    /// Pushes since the origin.
    steps: u64,
}

impl HistoryState {
    /// History starting at `t0` [s] with slip `initial_slip` [m/s]: a step change
    /// `J = initial_slip` at `t_s = t0` (eq. 2.27; a zero slip gives no jump term).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::HistoryState;
    /// let s = HistoryState::new(DVec3::X, 2.0);
    /// assert_eq!(s.jump(), (2.0, DVec3::X));
    /// assert_eq!(s.last_slip(), DVec3::X);
    /// ```
    pub fn new(initial_slip: DVec3, t0: f64) -> Self {
        HistoryState {
            increments: VecDeque::new(),
            tail: [DVec3::ZERO; TAIL_TERMS],
            jump_time: t0,
            jump: initial_slip,
            last_slip: initial_slip,
            origin: t0,
            steps: 0,
        }
    }

    /// Time of the last slip sample, `t_origin + n Δt` [s].
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.25, HistoryKernel::Full).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 1.0);
    /// s.push(&plan, DVec3::ZERO);
    /// assert_eq!(s.time(&plan), 1.25);
    /// ```
    pub fn time(&self, plan: &HistoryPlan) -> f64 {
        self.origin + self.steps as f64 * plan.dt
    }

    /// The last slip sample `w_n` [m/s].
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::HistoryState;
    /// assert_eq!(HistoryState::new(DVec3::Y, 0.0).last_slip(), DVec3::Y);
    /// ```
    pub fn last_slip(&self) -> DVec3 {
        self.last_slip
    }

    /// The last step change `(t_s [s], J_s [m/s])`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::HistoryState;
    /// assert_eq!(HistoryState::new(DVec3::ZERO, 0.5).jump(), (0.5, DVec3::ZERO));
    /// ```
    pub fn jump(&self) -> (f64, DVec3) {
        (self.jump_time, self.jump)
    }

    /// Number of intervals held with exact weights (`≤ N_w` for a window).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.1, HistoryKernel::Window { steps: 3, tail: true }).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// for _ in 0..5 {
    ///     s.push(&plan, DVec3::X);
    /// }
    /// assert_eq!(s.stored_intervals(), 3);
    /// ```
    pub fn stored_intervals(&self) -> usize {
        self.increments.len()
    }

    /// Jump term `J_s/√(t − t_s)` [m s^{−3/2}] at time `t` [s]; defined as zero for
    /// `t ≤ t_s` (it is singular but integrable at `t = t_s`).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::HistoryState;
    /// let s = HistoryState::new(DVec3::X, 0.0);
    /// assert_eq!(s.jump_term(4.0), DVec3::new(0.5, 0.0, 0.0));
    /// assert_eq!(s.jump_term(0.0), DVec3::ZERO);
    /// ```
    pub fn jump_term(&self, t: f64) -> DVec3 {
        if t > self.jump_time {
            self.jump / (t - self.jump_time).sqrt()
        } else {
            DVec3::ZERO
        }
    }

    /// Exponential-tail part of [`HistoryState::current_integral`] at the last sample
    /// [m s^{−3/2}] (zero unless the kernel is a window with tail).
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.1, HistoryKernel::Window { steps: 2, tail: true }).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// s.push(&plan, DVec3::X);
    /// assert_eq!(s.tail_integral(&plan), DVec3::ZERO); // still inside the window
    /// s.push(&plan, DVec3::X);
    /// s.push(&plan, DVec3::X);
    /// assert!(s.tail_integral(&plan).x > 0.0);
    /// ```
    pub fn tail_integral(&self, plan: &HistoryPlan) -> DVec3 {
        match &plan.tail {
            Some(tp) => {
                (0..TAIL_TERMS).fold(DVec3::ZERO, |acc, i| acc + tp.amplitude[i] * self.tail[i])
            }
            None => DVec3::ZERO,
        }
    }

    /// `Σ c_{j+shift} Δw` over the stored increments (`j = 0` the newest), skipping the oldest
    /// `skip` of them.
    fn window_sum(&self, plan: &HistoryPlan, shift: usize, skip: usize) -> DVec3 {
        let used = self.increments.len().saturating_sub(skip);
        let mut sum = DVec3::ZERO;
        if plan.weights.is_empty() {
            // Full: c_j = 2/(√Δt(√(j+1) + √j)), one square root per term.
            let mut sq = (shift as f64).sqrt();
            for (j, dw) in self.increments.iter().rev().take(used).enumerate() {
                let sq1 = ((j + shift + 1) as f64).sqrt();
                sum += (2.0 * plan.inv_sqrt_dt / (sq1 + sq)) * *dw;
                sq = sq1;
            }
        } else {
            let weights = &plan.weights[shift..];
            for (dw, c) in self.increments.iter().rev().take(used).zip(weights) {
                sum += *c * *dw;
            }
        }
        sum
    }

    /// Whether the window buffer is full (the next push moves its oldest increment out).
    fn window_full(&self, plan: &HistoryPlan) -> bool {
        match plan.kernel {
            HistoryKernel::Full => false,
            HistoryKernel::Window { steps, .. } => self.increments.len() >= steps,
        }
    }

    /// `I(t_n)` [m s^{−3/2}] at the last sample `t_n` from the completed intervals (the newest
    /// gets `c_0`), plus the tail and the jump term at `t_n` (`t_n` [s] is normally
    /// [`HistoryState::time`]; only the jump term uses it, and it is zero at `t_n = t_s`).
    /// The explicit scheme's force is `F_H(t_n) = c_H · current_integral`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(1.0, HistoryKernel::Full).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// s.push(&plan, DVec3::X); // w = t on [0, 1]: I(1) = 2
    /// assert!((s.current_integral(&plan, 1.0).x - 2.0).abs() < 1e-15);
    /// ```
    pub fn current_integral(&self, plan: &HistoryPlan, t_n: f64) -> DVec3 {
        self.window_sum(plan, 0, 0) + self.tail_integral(plan) + self.jump_term(t_n)
    }

    /// `I(t_{n+1})` [m s^{−3/2}] minus the newest interval's term `c_0 Δw_n`: the completed
    /// intervals as seen from `t_{n+1} = t_n + Δt` (lags shifted by one, the newest completed
    /// interval gets `c_1`; for a full window its oldest interval enters the tail exactly as
    /// [`HistoryState::push`] will move it), plus the tail and the jump term at `t_next` [s].
    /// The implicit scheme's force is
    /// `F_H(t_{n+1}) = c_H (past_integral + c_0 (w_{n+1} − w_n))`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.1, HistoryKernel::Full).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// s.push(&plan, DVec3::Z);
    /// let dw = DVec3::Z * 0.5;
    /// let implicit = s.past_integral(&plan, 0.2) + plan.newest_weight() * dw;
    /// s.push(&plan, DVec3::Z + dw);
    /// assert!((implicit - s.current_integral(&plan, 0.2)).length() < 1e-13);
    /// ```
    pub fn past_integral(&self, plan: &HistoryPlan, t_next: f64) -> DVec3 {
        let full = self.window_full(plan);
        let mut sum = self.window_sum(plan, 1, usize::from(full)) + self.jump_term(t_next);
        if let Some(tp) = &plan.tail {
            let leaving = if full {
                self.increments.front().copied().unwrap_or(DVec3::ZERO)
            } else {
                DVec3::ZERO
            };
            for i in 0..TAIL_TERMS {
                sum += tp.amplitude[i] * (tp.decay[i] * self.tail[i] + tp.entry[i] * leaving);
            }
        }
        sum
    }

    /// Completes a step: appends `Δw = new_slip − last_slip` (`new_slip` [m/s] is the sample at
    /// `time + Δt`), moves the increment leaving a full window into the tail (or drops it
    /// without a tail) and advances the time by `Δt`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.1, HistoryKernel::Full).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// s.push(&plan, DVec3::X);
    /// assert_eq!(s.last_slip(), DVec3::X);
    /// assert_eq!(s.stored_intervals(), 1);
    /// ```
    pub fn push(&mut self, plan: &HistoryPlan, new_slip: DVec3) {
        let dw = new_slip - self.last_slip;
        if self.window_full(plan) {
            let leaving = self.increments.pop_front().unwrap_or(DVec3::ZERO);
            if let Some(tp) = &plan.tail {
                for i in 0..TAIL_TERMS {
                    self.tail[i] = tp.decay[i] * self.tail[i] + tp.entry[i] * leaving;
                }
            }
        } else {
            if let HistoryKernel::Window { steps, .. } = plan.kernel
                && self.increments.capacity() < steps
            {
                // one allocation for the whole window (none once it is full)
                self.increments.reserve_exact(steps - self.increments.len());
            }
            if let Some(tp) = &plan.tail {
                // the tail is empty until the window first fills; decaying keeps it exact
                for i in 0..TAIL_TERMS {
                    self.tail[i] *= tp.decay[i];
                }
            }
        }
        self.increments.push_back(dw);
        self.last_slip = new_slip;
        self.steps += 1;
    }

    /// A collision at `t_c` [s] during the current step: discards all history (buffer and
    /// tail, eq. 2.29), records the step change `jump = w(t_c⁺) − w(t_c⁻) = v(t_c⁻) − v(t_c⁺)`
    /// [m/s] at `t_c`, and restarts the buffer at the step boundary `t_next_sample ≥ t_c` [s]
    /// with the post-collision slip `slip_after` [m/s] as its first sample (the slip is taken
    /// constant on `[t_c, t_next_sample]`). The next evaluation, at `t_next_sample + Δt > t_c`,
    /// has a finite jump term `J/√(t − t_c)` that uses the true `t_c`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
    /// let plan = HistoryPlan::new(0.01, HistoryKernel::Full).unwrap();
    /// let mut s = HistoryState::new(DVec3::ZERO, 0.0);
    /// s.push(&plan, DVec3::X);
    /// s.reset_at_collision(&plan, 0.015, -2.0 * DVec3::X, -DVec3::X, 0.02);
    /// assert_eq!(s.stored_intervals(), 0);
    /// assert_eq!(s.time(&plan), 0.02);
    /// let i = s.past_integral(&plan, 0.03); // only the jump: −2/√0.015
    /// assert!((i.x + 2.0 / 0.015f64.sqrt()).abs() < 1e-12);
    /// ```
    pub fn reset_at_collision(
        &mut self,
        plan: &HistoryPlan,
        t_c: f64,
        jump: DVec3,
        slip_after: DVec3,
        t_next_sample: f64,
    ) {
        debug_assert!(
            t_next_sample >= t_c && t_next_sample - t_c <= plan.dt * (1.0 + 1e-9) + 1e-300,
            "collision time {t_c} must lie in the step ending at {t_next_sample}"
        );
        self.increments.clear();
        self.tail = [DVec3::ZERO; TAIL_TERMS];
        self.jump_time = t_c;
        self.jump = jump;
        self.last_slip = slip_after;
        self.origin = t_next_sample;
        self.steps = 0;
    }
}

#[cfg(test)]
#[path = "history_tests.rs"]
mod tests;
