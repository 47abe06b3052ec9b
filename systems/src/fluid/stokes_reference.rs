//! Exact unsteady-Stokes (Basset–Boussinesq–Oseen) reference: a sphere released in quiescent
//! fluid under a constant force, with Stokes drag, added mass and the Basset history force,
//! solved exactly in the Laplace domain and inverted numerically. It validates the history
//! kernels of [`super::history`] and the time integrators built on them.
//!
//! ## Equations
//! A sphere of radius `a` and density `ρ_p` moves along a constant force `F` in fluid
//! (`ρ_f`, `μ`, `ν = μ/ρ_f`) at rest, starting at `t = 0` with velocity `v0` at `x = 0`:
//!
//! ```text
//! M dv/dt = F − k v − c_H [ ∫_0^t v'(τ) (t − τ)^{−1/2} dτ + v0/√t ],
//! M = (ρ_p + ρ_f/2) V,   k = 6πμa,   c_H = 6a²√(πρ_f μ)   (= (3/2) d² √(πρ_f μ)),
//! ```
//!
//! the last term being the jump term of the initial slip (thesis 002 eq. 2.27). With
//! `L{∫_0^t v'(τ)(t−τ)^{−1/2}dτ + v0/√t} = √π √s V(s)` the Laplace transforms are
//!
//! ```text
//! V(s) = (F/s + M v0) / (M s + c_H √π √s + k),      X(s) = V(s)/s.
//! ```
//!
//! As a quadratic in `√s` the denominator has both roots in `Re √s < 0`, so `V` is analytic
//! off the negative real axis (branch cut) apart from the pole at `s = 0`.
//!
//! **Inversion**: the fixed Talbot method (Abate & Valkó 2004, "Multi-precision Laplace
//! transform inversion", Int. J. Numer. Meth. Eng. 60:979), contour
//! `s(θ) = rθ(cot θ + i)`, `r = 2N/(5t)`, `θ_j = jπ/N`,
//!
//! ```text
//! f(t) ≈ (r/N) [ ½ F(r) e^{rt} + Σ_{j=1}^{N−1} Re( e^{t s(θ_j)} F(s(θ_j)) (1 + iσ(θ_j)) ) ],
//! σ(θ) = θ + (θ cot θ − 1) cot θ,
//! ```
//!
//! with `N =` [`TALBOT_NODES`]. In `f64` the round-off grows like `ε e^{0.4N}` while the
//! truncation error falls like `10^{−0.6N}`; the chosen `N = 20` balances them. Measured
//! (tests): `4e-13` relative against the exact no-history exponential (`3e-11` with `N = 16`,
//! `4e-12` with 24, `6e-11` with 32), `1e-12` between `N = 20` and 24 with history, and
//! `1e-11` against an independent, Richardson-extrapolated time-stepping solution.
//!
//! ## Asymptotes (derived from the expansions of `V(s)`; all checked by the tests)
//! With `b = c_H√π/M`, `c = k/M`, `β = c_H√π/k = a/√ν`, `τ = M/k`, `v_∞ = F/k`:
//! * small `t` (large `s`): `v = (F/M)[t − b t^{3/2}/Γ(5/2) + (b² − c) t²/2 + …] +
//!   v0[1 − b √t/Γ(3/2) + (b² − c) t + …]`, i.e. `v ≈ (F/M)(t − (4/3)(c_H/M) t^{3/2})` from rest;
//! * large `t` (small `s`): `v_∞ − v(t) → v_∞ β/√(πt) = v_∞ a/√(πνt)` (the classic `t^{−1/2}`
//!   Basset tail) `− [v_∞(β³ − 2βτ) + τ v0 β]/(2√π) t^{−3/2} + O(t^{−5/2})`;
//!   `x(t) → v_∞ t − 2v_∞β√(t/π) + v_∞(β² − τ) + τ v0 + O(t^{−1/2})`.
//!
//! ## Assumptions
//! Creeping flow (Re → 0), uniform force, no walls, 1-D motion along the force; `history:
//! false` drops the Basset term (an exponential approach with time constant `τ`).
//!
//! ```
//! use magsep_systems::fluid::stokes_reference::StokesRelease;
//! // 1 mm glass bead in water
//! let bead = StokesRelease::gravitational(0.5e-3, 2500.0, 1000.0, 1e-3, 9.81);
//! let v_inf = bead.terminal_velocity();
//! // the history force slows the approach: still ~7 % short of v_∞ after 100 relaxation times
//! let t = 100.0 * bead.relaxation_time();
//! assert!(bead.velocity(t) < 0.99 * v_inf);
//! assert!(bead.without_history().velocity(t) > 0.999_999 * v_inf);
//! ```

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

/// Number of fixed-Talbot nodes `N` (round-off `~ε e^{0.4N}` vs truncation `~10^{−0.6N}` in
/// `f64`).
pub const TALBOT_NODES: usize = 20;

/// Complex numbers of the Laplace inversion (`num-complex`; divisions and reciprocals use
/// its scaled `fdiv`/`finv`, which do not overflow for large components).
type Complex = num_complex::Complex64;

/// Principal square root (branch cut on the negative real axis) without cancellation.
/// Kept by hand: `num_complex`'s `sqrt` goes through polar form, which near the cut loses
/// the small component entirely (`sqrt(-4 + 1e-30 i)` gets re = 1.2e-16 instead of 2.5e-31).
fn principal_sqrt(z: Complex) -> Complex {
    let m = z.norm();
    if m == 0.0 {
        return Complex::new(0.0, 0.0);
    }
    if z.re >= 0.0 {
        let r = (0.5 * (m + z.re)).sqrt();
        Complex::new(r, z.im / (2.0 * r))
    } else {
        let i = (0.5 * (m - z.re)).sqrt().copysign(z.im);
        Complex::new(z.im / (2.0 * i), i)
    }
}

/// Fixed-Talbot inverse Laplace transform of `f` at `t > 0` with `nodes` nodes.
fn talbot(f: impl Fn(Complex) -> Complex, t: f64, nodes: usize) -> f64 {
    let n = nodes as f64;
    let r = 2.0 * n / (5.0 * t);
    let mut sum = 0.5 * f(Complex::new(r, 0.0)).re * (r * t).exp();
    for j in 1..nodes {
        let theta = j as f64 * PI / n;
        let cot = 1.0 / theta.tan();
        let s = Complex::new(r * theta * cot, r * theta);
        let sigma = theta + (theta * cot - 1.0) * cot;
        let term = (s * t).exp() * f(s) * Complex::new(1.0, sigma);
        sum += term.re;
    }
    r / n * sum
}

/// A sphere released in quiescent fluid under a constant force (SI units), with the exact
/// unsteady-Stokes velocity and position (see the module docs).
///
/// ```
/// use magsep_systems::fluid::stokes_reference::StokesRelease;
/// let s = StokesRelease::new(1e-3, 2000.0, 1000.0, 1e-3, 1e-6).with_initial_velocity(0.01);
/// assert_eq!(s.velocity(0.0), 0.01);
/// assert!((s.viscous_time() - 1.0).abs() < 1e-12); // a²/ν
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StokesRelease {
    /// Sphere radius `a` [m]. Range: `> 0`.
    pub radius: f64,
    /// Particle density `ρ_p` [kg/m³].
    pub particle_density: f64,
    /// Fluid density `ρ_f` [kg/m³].
    pub fluid_density: f64,
    /// Dynamic viscosity `μ` [Pa s]. Range: `> 0`.
    pub viscosity: f64,
    /// Constant force `F` along the axis of motion [N], e.g. `(ρ_p − ρ_f) V g`.
    pub force: f64,
    /// Velocity `v0` at release `t = 0` [m/s] (a slip step: enters with the jump term).
    /// Default: 0.
    pub initial_velocity: f64,
    /// Whether the Basset history force acts (`c_H = 0` otherwise). Default: `true`.
    pub history: bool,
}

impl StokesRelease {
    /// Released from rest, with history: radius `a` [m], densities `ρ_p`, `ρ_f` [kg/m³],
    /// viscosity `μ` [Pa s], force `F` [N].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 6.0 * std::f64::consts::PI);
    /// assert!((s.terminal_velocity() - 1.0).abs() < 1e-15);
    /// ```
    pub fn new(
        radius: f64,
        particle_density: f64,
        fluid_density: f64,
        viscosity: f64,
        force: f64,
    ) -> Self {
        StokesRelease {
            radius,
            particle_density,
            fluid_density,
            viscosity,
            force,
            initial_velocity: 0.0,
            history: true,
        }
    }

    /// Released from rest under gravity and buoyancy, `F = (ρ_p − ρ_f) V g`, with `g` [m/s²]
    /// the signed acceleration along the axis of motion (positive: heavy spheres move to `+x`).
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::gravitational(1e-3, 1500.0, 1000.0, 1e-3, 9.81);
    /// assert!((s.force - 500.0 * s.volume() * 9.81).abs() < 1e-18);
    /// ```
    pub fn gravitational(
        radius: f64,
        particle_density: f64,
        fluid_density: f64,
        viscosity: f64,
        g: f64,
    ) -> Self {
        let volume = 4.0 / 3.0 * PI * radius.powi(3);
        let force = (particle_density - fluid_density) * volume * g;
        Self::new(radius, particle_density, fluid_density, viscosity, force)
    }

    /// The same release with initial velocity `v0` [m/s].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 0.0).with_initial_velocity(2.0);
    /// assert!(s.velocity(1.0) < 2.0); // decays towards v_∞ = 0
    /// ```
    pub fn with_initial_velocity(mut self, v0: f64) -> Self {
        self.initial_velocity = v0;
        self
    }

    /// The same release without the Basset history force (`c_H = 0`).
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 1.0).without_history();
    /// assert_eq!(s.history_coefficient(), 0.0);
    /// ```
    pub fn without_history(mut self) -> Self {
        self.history = false;
        self
    }

    /// Sphere volume `V = (4/3)πa³` [m³].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 1.0);
    /// assert!((s.volume() - 4.0 / 3.0 * std::f64::consts::PI).abs() < 1e-15);
    /// ```
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }

    /// Effective mass with added mass, `M = (ρ_p + ρ_f/2) V` [kg].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 1.0);
    /// assert!((s.effective_mass() - 2.5 * s.volume()).abs() < 1e-14);
    /// ```
    pub fn effective_mass(&self) -> f64 {
        (self.particle_density + 0.5 * self.fluid_density) * self.volume()
    }

    /// Stokes drag coefficient `k = 6πμa` [kg/s].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(2.0, 2.0, 1.0, 0.5, 1.0);
    /// assert!((s.drag_coefficient() - 6.0 * std::f64::consts::PI).abs() < 1e-14);
    /// ```
    pub fn drag_coefficient(&self) -> f64 {
        6.0 * PI * self.viscosity * self.radius
    }

    /// Basset coefficient `c_H = 6a²√(πρ_f μ)` [kg s^{−1/2}] (0 without history).
    ///
    /// ```
    /// use magsep_systems::fluid::history::basset_coefficient;
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1e-3, 2.0e3, 1.0e3, 1e-3, 1.0);
    /// assert!((s.history_coefficient() - basset_coefficient(2e-3, 1e3, 1e-3)).abs() < 1e-18);
    /// ```
    pub fn history_coefficient(&self) -> f64 {
        if self.history {
            6.0 * self.radius * self.radius * (PI * self.fluid_density * self.viscosity).sqrt()
        } else {
            0.0
        }
    }

    /// Terminal (Stokes) velocity `v_∞ = F/(6πμa)` [m/s].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 12.0 * std::f64::consts::PI);
    /// assert!((s.terminal_velocity() - 2.0).abs() < 1e-15);
    /// ```
    pub fn terminal_velocity(&self) -> f64 {
        self.force / self.drag_coefficient()
    }

    /// Viscous time `a²/ν` [s].
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(2.0, 2.0, 1.0, 1.0, 1.0);
    /// assert_eq!(s.viscous_time(), 4.0);
    /// ```
    pub fn viscous_time(&self) -> f64 {
        self.radius * self.radius * self.fluid_density / self.viscosity
    }

    /// Relaxation time `τ = M/(6πμa)` [s] (the exponential time constant without history).
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 1.0);
    /// assert!((s.relaxation_time() - 2.5 * (4.0 / 3.0) / 6.0).abs() < 1e-15);
    /// ```
    pub fn relaxation_time(&self) -> f64 {
        self.effective_mass() / self.drag_coefficient()
    }

    /// `V(s)` [m] (velocity transform, m/s · s).
    fn velocity_transform(&self, s: Complex) -> Complex {
        let m = self.effective_mass();
        let num = s.finv() * self.force + Complex::new(m * self.initial_velocity, 0.0);
        let den = s * m
            + principal_sqrt(s) * (self.history_coefficient() * PI.sqrt())
            + Complex::new(self.drag_coefficient(), 0.0);
        num.fdiv(den)
    }

    /// Velocity `v(t)` [m/s] at time `t` [s] after release (`v0` for `t ≤ 0`, `v_∞` for
    /// `t = ∞`; NaN for NaN).
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 1.0).without_history();
    /// let (v, tau) = (s.terminal_velocity(), s.relaxation_time());
    /// assert!((s.velocity(tau) - v * (1.0 - (-1f64).exp())).abs() < 1e-10 * v);
    /// ```
    pub fn velocity(&self, t: f64) -> f64 {
        if t.is_nan() {
            f64::NAN
        } else if t <= 0.0 {
            self.initial_velocity
        } else if t.is_infinite() {
            self.terminal_velocity()
        } else {
            talbot(|s| self.velocity_transform(s), t, TALBOT_NODES)
        }
    }

    /// Position `x(t)` [m] at time `t` [s] after release from `x = 0` (0 for `t ≤ 0`;
    /// `v_∞ · ∞` for `t = ∞`; NaN for NaN).
    ///
    /// ```
    /// use magsep_systems::fluid::stokes_reference::StokesRelease;
    /// let s = StokesRelease::new(1.0, 2.0, 1.0, 1.0, 0.0).with_initial_velocity(1.0).without_history();
    /// // no force: the sphere coasts a distance v0 τ
    /// assert!((s.position(1e3) - s.relaxation_time()).abs() < 1e-9);
    /// ```
    pub fn position(&self, t: f64) -> f64 {
        if t.is_nan() {
            f64::NAN
        } else if t <= 0.0 {
            0.0
        } else if t.is_infinite() {
            self.terminal_velocity() * t
        } else {
            talbot(|s| self.velocity_transform(s).fdiv(s), t, TALBOT_NODES)
        }
    }
}

#[cfg(test)]
#[path = "stokes_reference_tests.rs"]
mod tests;
