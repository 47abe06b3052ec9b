//! The plan of the Basset history quadrature: the van Hinsberg tail coefficients, the kernel
//! choice and everything that depends only on (Δt, kernel), shared by all particles. See the
//! parent module [`super`] for the equations.

use std::f64::consts::{E, PI};

use serde::{Deserialize, Serialize};

/// Number of exponentials in the van Hinsberg tail kernel.
pub const TAIL_TERMS: usize = 10;

/// Dimensionless tail times `t̃_i = t_i / t_win` of van Hinsberg et al. (2011).
pub const TAIL_TIMES: [f64; TAIL_TERMS] = [
    0.1, 0.3, 1.0, 3.0, 10.0, 40.0, 190.0, 1000.0, 6500.0, 50000.0,
];

/// Tail amplitudes `a_i` of van Hinsberg et al. (2011) (dimensionless).
#[rustfmt::skip]
pub const TAIL_AMPLITUDES: [f64; TAIL_TERMS] = [
    0.23477481312586, 0.28549576238194, 0.28479416718255, 0.26149775537574, 0.32056200511938,
    0.35354490689146, 0.39635904496921, 0.42253908596514, 0.48317384225265, 0.63661146557001,
];

/// Longest accepted window, in steps (`2^24`; the weights are precomputed).
pub const MAX_WINDOW_STEPS: usize = 1 << 24;

/// Basset coefficient `c_H = (3/2) d_p² √(π ρ_f μ)` [kg s^{−1/2}], so that the history force is
/// `F_H = c_H · I` \[N\] with `I` [m s^{−3/2}].
///
/// `diameter` `d_p` \[m\], `fluid_density` `ρ_f` [kg/m³], `viscosity` (dynamic) `μ` [Pa s].
///
/// ```
/// use magsep_systems::fluid::history::basset_coefficient;
/// let c = basset_coefficient(2e-3, 1000.0, 1e-3);
/// assert!((c - 1.5 * 4e-6 * std::f64::consts::PI.sqrt()).abs() < 1e-18);
/// ```
pub fn basset_coefficient(diameter: f64, fluid_density: f64, viscosity: f64) -> f64 {
    1.5 * diameter * diameter * (PI * fluid_density * viscosity).sqrt()
}

/// The ten-exponential approximation of `s^{−1/2}` [s^{−1/2}] for a window of duration
/// `window_duration = t_win` \[s\]: `Σ a_i √(e/t_i) exp(−s/(2t_i))`, `t_i = t̃_i t_win`. Meant for
/// `s ≥ t_win` (lag `s` \[s\]).
///
/// ```
/// use magsep_systems::fluid::history::tail_kernel;
/// let k = tail_kernel(2.0, 1.0);
/// assert!((k * 2f64.sqrt() - 1.0).abs() < 2e-3);
/// ```
pub fn tail_kernel(s: f64, window_duration: f64) -> f64 {
    TAIL_TIMES
        .iter()
        .zip(TAIL_AMPLITUDES)
        .map(|(&tt, a)| {
            let ti = tt * window_duration;
            a * (E / ti).sqrt() * (-s / (2.0 * ti)).exp()
        })
        .sum()
}

/// Which quadrature of the history integral (configuration; serde-friendly).
///
/// ```
/// use magsep_systems::fluid::history::HistoryKernel;
/// // 0.35 s window at 0.9 ms steps, with the exponential tail (the thesis's many-particle runs)
/// let k = HistoryKernel::window(0.35, 0.9e-3, true);
/// assert_eq!(k, HistoryKernel::Window { steps: 389, tail: true });
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum HistoryKernel {
    /// Full-memory product integration: `O(n)` per step; the reference.
    Full,
    /// Exact weights over the last `steps` intervals (`t_win = steps · Δt`), plus, if `tail`,
    /// the van Hinsberg exponential tail for older intervals (dropped otherwise).
    Window {
        /// Window length `N_w` in steps. Range: `1..=MAX_WINDOW_STEPS`.
        steps: usize,
        /// Whether intervals older than the window enter through the exponential tail.
        tail: bool,
    },
}

impl HistoryKernel {
    /// A window of duration `window_duration` \[s\] at step `dt` \[s\]: `N_w = max(1,
    /// round(window_duration/dt))` (a non-finite ratio gives `N_w = 0`, which
    /// [`HistoryPlan::new`] rejects).
    ///
    /// ```
    /// use magsep_systems::fluid::history::HistoryKernel;
    /// assert_eq!(HistoryKernel::window(0.2, 1e-3, false), HistoryKernel::Window { steps: 200, tail: false });
    /// ```
    pub fn window(window_duration: f64, dt: f64, tail: bool) -> Self {
        let ratio = window_duration / dt;
        let steps = if ratio.is_finite() {
            ratio.round().max(1.0) as usize
        } else {
            0
        };
        HistoryKernel::Window { steps, tail }
    }
}

/// Invalid history-plan parameters.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum HistoryError {
    /// The time step must be positive and finite.
    #[error("history time step must be positive and finite, got {0}")]
    InvalidTimeStep(f64),
    /// The window must hold at least one and at most `MAX_WINDOW_STEPS` intervals.
    #[error("history window must have 1..={max} steps, got {0}", max = MAX_WINDOW_STEPS)]
    InvalidWindow(usize),
}

/// Precomputed exponential-tail constants (all for one `(Δt, N_w)`).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TailPlan {
    /// `e^{−Δt/(2t_i)}`.
    pub(super) decay: [f64; TAIL_TERMS],
    /// `(2t_i/Δt)(e^{−N_wΔt/(2t_i)} − e^{−(N_w+1)Δt/(2t_i)})`: the leaving increment's factor.
    pub(super) entry: [f64; TAIL_TERMS],
    /// `a_i √(e/t_i)` [s^{−1/2}].
    pub(super) amplitude: [f64; TAIL_TERMS],
}

/// Everything that depends only on `(Δt, kernel)`, shared by all particles.
///
/// ```
/// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
/// let plan = HistoryPlan::new(0.01, HistoryKernel::Window { steps: 50, tail: true }).unwrap();
/// assert!((plan.newest_weight() - 20.0).abs() < 1e-12); // 2/√Δt
/// assert!((plan.window_duration().unwrap() - 0.5).abs() < 1e-15);
/// assert!(HistoryPlan::new(0.0, HistoryKernel::Full).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryPlan {
    pub(super) dt: f64,
    pub(super) kernel: HistoryKernel,
    /// `1/√Δt`.
    pub(super) inv_sqrt_dt: f64,
    /// `c_j` for `j = 0..=N_w` (Window); empty for Full (computed on the fly).
    pub(super) weights: Vec<f64>,
    /// Tail constants (Window with tail).
    pub(super) tail: Option<TailPlan>,
}

/// `c_j = 2/(√Δt (√(j+1) + √j))` without cancellation.
#[inline]
pub(super) fn lag_weight(inv_sqrt_dt: f64, j: usize) -> f64 {
    let jf = j as f64;
    2.0 * inv_sqrt_dt / ((jf + 1.0).sqrt() + jf.sqrt())
}

impl HistoryPlan {
    /// Plan for step `dt` \[s\] and `kernel`. Errors: `dt` not positive and finite, or a window
    /// with 0 or more than [`MAX_WINDOW_STEPS`] steps.
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryError, HistoryKernel, HistoryPlan};
    /// let bad = HistoryPlan::new(1e-3, HistoryKernel::Window { steps: 0, tail: true });
    /// assert_eq!(bad.unwrap_err(), HistoryError::InvalidWindow(0));
    /// ```
    pub fn new(dt: f64, kernel: HistoryKernel) -> Result<Self, HistoryError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(HistoryError::InvalidTimeStep(dt));
        }
        let inv_sqrt_dt = 1.0 / dt.sqrt();
        let (weights, tail) = match kernel {
            HistoryKernel::Full => (Vec::new(), None),
            HistoryKernel::Window { steps, tail } => {
                if steps == 0 || steps > MAX_WINDOW_STEPS {
                    return Err(HistoryError::InvalidWindow(steps));
                }
                let weights = (0..=steps).map(|j| lag_weight(inv_sqrt_dt, j)).collect();
                let t_win = steps as f64 * dt;
                let t_i = |i: usize| TAIL_TIMES[i] * t_win;
                // x_i = Δt/(2t_i); N_w x_i = 1/(2 t̃_i); entry = (2t_i/Δt) e^{−N_w x_i}(1 − e^{−x_i})
                let tail = tail.then(|| TailPlan {
                    decay: std::array::from_fn(|i| (-dt / (2.0 * t_i(i))).exp()),
                    entry: std::array::from_fn(|i| {
                        let x = dt / (2.0 * t_i(i));
                        (-0.5 / TAIL_TIMES[i]).exp() * (-(-x).exp_m1()) / x
                    }),
                    amplitude: std::array::from_fn(|i| TAIL_AMPLITUDES[i] * (E / t_i(i)).sqrt()),
                });
                (weights, tail)
            }
        };
        Ok(HistoryPlan {
            dt,
            kernel,
            inv_sqrt_dt,
            weights,
            tail,
        })
    }

    /// The step `Δt` \[s\].
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
    /// assert_eq!(HistoryPlan::new(0.5, HistoryKernel::Full).unwrap().dt(), 0.5);
    /// ```
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The kernel this plan was built for.
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
    /// assert_eq!(HistoryPlan::new(0.5, HistoryKernel::Full).unwrap().kernel(), HistoryKernel::Full);
    /// ```
    pub fn kernel(&self) -> HistoryKernel {
        self.kernel
    }

    /// Window duration `t_win = N_w Δt` \[s\] (`None` for [`HistoryKernel::Full`]).
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
    /// assert_eq!(HistoryPlan::new(0.5, HistoryKernel::Full).unwrap().window_duration(), None);
    /// ```
    pub fn window_duration(&self) -> Option<f64> {
        match self.kernel {
            HistoryKernel::Full => None,
            HistoryKernel::Window { steps, .. } => Some(steps as f64 * self.dt),
        }
    }

    /// Weight `c_0 = 2/√Δt` [s^{−1/2}] of the newest interval: the factor of the unknown
    /// increment `Δw_n = w_{n+1} − w_n` in an implicit step.
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
    /// let plan = HistoryPlan::new(0.04, HistoryKernel::Full).unwrap();
    /// assert!((plan.newest_weight() - 10.0).abs() < 1e-12);
    /// ```
    pub fn newest_weight(&self) -> f64 {
        2.0 * self.inv_sqrt_dt
    }

    /// Exact product-integration weight `c_j = (2/√Δt)(√(j+1) − √j)` [s^{−1/2}] of the interval
    /// at lag `j` (whatever the kernel; the window uses it for `j < N_w`).
    ///
    /// ```
    /// use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan};
    /// let plan = HistoryPlan::new(1.0, HistoryKernel::Full).unwrap();
    /// assert!((plan.weight(3) - 2.0 * (2.0 - 3f64.sqrt())).abs() < 1e-15);
    /// ```
    pub fn weight(&self, lag: usize) -> f64 {
        self.weights
            .get(lag)
            .copied()
            .unwrap_or_else(|| lag_weight(self.inv_sqrt_dt, lag))
    }
}
