//! The pseudo-spectral channel-flow solver in the wall-normal velocity / wall-normal vorticity
//! formulation of Kim, Moin & Moser (1987, J. Fluid Mech. 177, 133–166).
//!
//! # Method
//!
//! The liquid is incompressible, `∂u/∂t = u × ω − ∇P + ν ∇²u + f + G`, with `ω = ∇ × u`, the
//! reduced pressure `P = p/ρ + |u|²/2`, the body force per unit mass `f` \[m/s²\] supplied by
//! the caller and an imposed mean pressure gradient `G` \[m/s²\] along x and y. In the
//! quasi-equilibrium ferrohydrodynamic model the magnetic body force `μ₀ M ∇H / ρ` of the
//! magnetised liquid is a gradient and is absorbed into `P`; the solver needs nothing extra
//! for it (a gradient force produces no velocity, see the tests).
//!
//! Fourier series in the periodic x and y, collocation at the Chebyshev-Gauss-Lobatto levels in
//! z (see [`super::grid`]). For every Fourier mode with `k² = kx² + ky² > 0` the state is the
//! z-velocity `w` and the z-vorticity `η = ∂v/∂x − ∂u/∂y`, which obey
//!
//! * `∂(∇²w)/∂t = h_w + ν ∇⁴w`, `h_w = −∂_z(∂_x H_x + ∂_y H_y) + (∂²_x + ∂²_y) H_z`,
//!   `w = ∂_z w = 0` at the walls;
//! * `∂η/∂t = h_η + ν ∇²η`, `h_η = ∂_x H_y − ∂_y H_x`, `η = 0` at the walls
//!   (the z-component of the curl of the momentum equation);
//!
//! with `H = u × ω + f`. The horizontal velocities follow from continuity and `η`:
//! `û = (i kx ∂_z ŵ + i ky η̂)/k²`, `v̂ = (i ky ∂_z ŵ − i kx η̂)/k²`. The mode `kx = ky = 0` holds
//! the mean flow `U(z)`, `V(z)` (`∂U/∂t = ⟨H_x⟩ + G_x + ν U''`, no slip), and its mean `w` is
//! zero. Nyquist modes are zero.
//!
//! `H` is evaluated in physical space from `u` and `ω` on a grid padded by the 3/2 rule in x
//! and y (`dealias = true`) or on the collocation grid itself (`dealias = false`).
//!
//! Time integration: the low-storage three-stage Runge-Kutta scheme of Spalart, Moser & Rogers
//! (1991, J. Comput. Phys. 96, 297–324) for `H` (coefficients `γ = 8/15, 5/12, 3/4`,
//! `ζ = 0, −17/60, −5/12`) and Crank-Nicolson for the viscous terms inside each stage
//! (`α = β = (γ + ζ)/2`, i.e. 4/15, 1/15, 1/6): second order overall. The body force is held
//! constant over the step.
//!
//! Each stage needs Dirichlet Helmholtz solves `(1 + βΔtν k² − βΔtν ∂²_z) q = r`, done by
//! matrix diagonalisation (Haldenwang et al. 1984; see [`super::cheb`]). The fourth-order
//! w-equation is split as `φ = ∇²w`: `φ` from its Helmholtz equation with unknown wall values,
//! then `w` from `∇²w = φ`, `w = 0`; the two clamping conditions `∂_z w = 0` are met by the
//! influence-matrix method: a particular solution (`φ = 0` at the walls) plus the two
//! homogeneous solutions with `φ = 1` at one wall, combined per mode and stage by a 2 × 2 solve.
//! The homogeneous solutions depend only on the mode and the stage; they and the inverses of
//! their 2 × 2 wall-slope matrices are precomputed when the solver is built (`3 · 2 · nz` reals
//! per mode: about 51 MB for a 128 × 128 × 129 grid, whose whole solver state stays a few
//! hundred MB). Nothing else is stored per mode.
//!
//! # Choices and deviations
//!
//! * The z-vorticity right-hand side is `h_η = ∂_x H_y − ∂_y H_x`, the z-component of
//!   `∇ × H` for `η = ∂v/∂x − ∂u/∂y` (the form `∂_y H_x − ∂_x H_y` would be the sign of
//!   Kim-Moin-Moser's y-normal vorticity transcribed without the change of axes). The forced
//!   steady-state test fails with the opposite sign.
//! * Crank-Nicolson splits each stage's implicit weight evenly, `α_s = β_s`, rather than
//!   Spalart-Moser-Rogers' unequal pairs; both sum to `γ_s + ζ_s`, both are second order.
//! * `φ = ∇²w` is recomputed from `w` (`D2 w − k² w`) at every stage, so the state is `w`, `η`,
//!   U and V only; the previous-stage right-hand sides are not part of the state because the
//!   first stage has `ζ = 0`. Restarts are therefore exact.
//! * A field given to [`ChannelSolver::set_velocity`](super::stepper::ChannelSolver::set_velocity)
//!   keeps its w and η per mode; w's wall values and slopes are removed by cubic Hermite
//!   polynomials (a projection that leaves admissible fields unchanged).
//!
//! Parallelism: rayon over z-planes (transforms) and over Fourier modes (wall-normal solves);
//! every value is computed by one task in a fixed order, so results are bit-for-bit identical
//! for any thread count.

use super::cheb::{self, HelmholtzDiag, row_dot_c};

use super::grid::ChannelGrid;
use num_complex::Complex64 as C;
use std::f64::consts::PI;

/// Runge-Kutta coefficients of Spalart, Moser & Rogers (1991).
pub(crate) const GAMMA: [f64; 3] = [8.0 / 15.0, 5.0 / 12.0, 3.0 / 4.0];
/// The previous-stage weights.
pub(crate) const ZETA: [f64; 3] = [0.0, -17.0 / 60.0, -5.0 / 12.0];

const ZERO: C = C::new(0.0, 0.0);

/// Parameters of a [`ChannelSolver`](super::stepper::ChannelSolver).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelParams {
    /// The collocation grid.
    pub grid: ChannelGrid,
    /// Kinematic viscosity ν \[m²/s\].
    pub viscosity: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// Evaluate the nonlinear term on a 3/2-padded grid (true, default) or on the collocation
    /// grid (aliased).
    pub dealias: bool,
    /// Imposed mean pressure gradient per unit mass, `−(1/ρ) ∂p/∂x`, `−(1/ρ) ∂p/∂y` \[m/s²\].
    pub mean_pressure_gradient: [f64; 2],
}

impl ChannelParams {
    /// Parameters with dealiasing on and no mean pressure gradient.
    pub fn new(grid: ChannelGrid, viscosity: f64, dt: f64) -> Self {
        Self {
            grid,
            viscosity,
            dt,
            dealias: true,
            mean_pressure_gradient: [0.0; 2],
        }
    }
}

/// Why a solver could not be built or restored.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChannelError {
    /// The viscosity is not finite and positive.
    #[error("the kinematic viscosity must be finite and > 0 (got {0})")]
    Viscosity(f64),
    /// The time step is not finite and positive.
    #[error("the time step must be finite and > 0 (got {0})")]
    TimeStep(f64),
    /// The mean pressure gradient is not finite.
    #[error("the mean pressure gradient must be finite (got {0:?})")]
    PressureGradient([f64; 2]),
    /// The grid is invalid (dimensions or lengths).
    #[error("invalid grid: {0}")]
    Grid(#[from] super::grid::GridError),
    /// The wall-normal operators could not be built.
    #[error(transparent)]
    Operators(#[from] cheb::ChebError),
    /// A field has the wrong length.
    #[error("field {component} has {got} values, the grid has {expected}")]
    FieldSize {
        /// Component index (0 = x, 1 = y, 2 = z).
        component: usize,
        /// Values given.
        got: usize,
        /// Grid points.
        expected: usize,
    },
    /// A field holds a non-finite value.
    #[error("field {0} holds a non-finite value")]
    NonFinite(usize),
    /// The state bytes do not start with the channel-state magic.
    #[error("not a channel solver state (bad magic)")]
    Magic,
    /// The state was written by an unsupported format version.
    #[error("unsupported channel state version {0}")]
    Version(u32),
    /// The state belongs to a different grid.
    #[error("state grid {state:?} does not match the parameters' grid {params:?}")]
    GridMismatch {
        /// `[nx, ny, nz]` of the state.
        state: [u64; 3],
        /// `[nx, ny, nz]` of the parameters.
        params: [u64; 3],
    },
    /// The state bytes are shorter or longer than their header says.
    #[error("channel state has {got} bytes, expected {expected}")]
    Length {
        /// Bytes given.
        got: usize,
        /// Bytes expected.
        expected: usize,
    },
    /// The state holds a non-finite or inconsistent value.
    #[error("corrupt channel state: {0}")]
    Corrupt(&'static str),
}

/// Fixed operators and wavenumbers.
#[derive(Debug)]
pub(crate) struct Ops {
    pub(crate) nz: usize,
    /// First-derivative matrix \[1/m\].
    pub(crate) d: Vec<f64>,
    /// Second-derivative matrix \[1/m²\].
    pub(crate) d2: Vec<f64>,
    pub(crate) helm: HelmholtzDiag,
    /// kx per spectral row \[1/m\].
    pub(crate) kx: Vec<f64>,
    /// ky per spectral column \[1/m\].
    pub(crate) ky: Vec<f64>,
    pub(crate) nyh: usize,
    pub(crate) nx: usize,
}

impl Ops {
    pub(crate) fn new(g: &ChannelGrid) -> Result<Self, ChannelError> {
        let d = cheb::diff_matrix(g);
        let d2 = cheb::matmul(&d, &d, g.nz);
        let helm = HelmholtzDiag::new(&d2, g.nz)?;
        let nyh = g.ny / 2 + 1;
        let kx = (0..g.nx)
            .map(|i| {
                let s = if i <= g.nx / 2 {
                    i as f64
                } else {
                    i as f64 - g.nx as f64
                };
                2.0 * PI / g.lx * s
            })
            .collect();
        let ky = (0..nyh).map(|j| 2.0 * PI / g.ly * j as f64).collect();
        Ok(Self {
            nz: g.nz,
            d,
            d2,
            helm,
            kx,
            ky,
            nyh,
            nx: g.nx,
        })
    }

    /// Wavenumbers of mode m, or None for a Nyquist mode.
    #[inline]
    pub(crate) fn k(&self, m: usize) -> Option<(f64, f64)> {
        let (ix, iy) = (m / self.nyh, m % self.nyh);
        if ix == self.nx / 2 || iy == self.nyh - 1 {
            None
        } else {
            Some((self.kx[ix], self.ky[iy]))
        }
    }

    /// `D x` at all levels.
    pub(crate) fn dz(&self, x: &[C], y: &mut [C]) {
        cheb::matvec_c(&self.d, self.nz, x, y);
    }

    /// `D2 x` at all levels.
    pub(crate) fn dzz(&self, x: &[C], y: &mut [C]) {
        cheb::matvec_c(&self.d2, self.nz, x, y);
    }

    /// `∂_z x` at the bottom and top wall.
    pub(crate) fn wall_dz(&self, x: &[C]) -> (C, C) {
        let n = self.nz;
        (
            row_dot_c(&self.d[..n], x),
            row_dot_c(&self.d[(n - 1) * n..], x),
        )
    }

    /// The two homogeneous solutions of the clamped w-problem of wavenumber² `k2` and implicit
    /// weight `b > 0`: `φ = 1` at the bottom (`h1`) or top (`h2`) wall, `(1 + b k2 − b ∂²) φ = 0`
    /// inside, `∇²w = φ` inside, `w = 0` at the walls. Returns the inverse of the matrix of
    /// their wall slopes, row-major `[[∂w1(0), ∂w2(0)], [∂w1(h), ∂w2(h)]]⁻¹`. `work` needs
    /// `4 nz` slots.
    pub(crate) fn homogeneous(
        &self,
        b: f64,
        k2: f64,
        h1: &mut [f64],
        h2: &mut [f64],
        work: &mut [C],
    ) -> [f64; 4] {
        let nz = self.nz;
        let (phi, rest) = work.split_at_mut(nz);
        let (out, tmp) = rest.split_at_mut(nz);
        let one = C::new(1.0, 0.0);
        let mut slopes = [(ZERO, ZERO); 2];
        for (wall, h) in [h1, h2].into_iter().enumerate() {
            let zero = vec![ZERO; nz];
            let (f0, f_n) = if wall == 0 { (one, ZERO) } else { (ZERO, one) };
            self.helm.solve(1.0, b, k2, &zero, f0, f_n, phi, tmp);
            phi.iter_mut().for_each(|p| *p = -*p);
            self.helm.solve(0.0, 1.0, k2, phi, ZERO, ZERO, out, tmp);
            out[0] = ZERO;
            out[nz - 1] = ZERO;
            for k in 0..nz {
                h[k] = out[k].re;
            }
            slopes[wall] = self.wall_dz(out);
        }
        let (a00, a10) = (slopes[0].0.re, slopes[0].1.re);
        let (a01, a11) = (slopes[1].0.re, slopes[1].1.re);
        let det = a00 * a11 - a01 * a10;
        [a11 / det, -a01 / det, -a10 / det, a00 / det]
    }

    /// The clamped w of wavenumber² `k2` whose Laplacian, away from the walls, solves the
    /// Helmholtz equation `(1 + b k2 − b ∂²) φ = r` (r at interior levels), `w = ∂w = 0` at
    /// the walls: the influence-matrix solution with the precomputed homogeneous solutions
    /// `h1`, `h2` and slope-matrix inverse `inv` of [`Ops::homogeneous`]. `work` needs `3 nz`
    /// slots.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn clamped_solve(
        &self,
        b: f64,
        k2: f64,
        r: &[C],
        w: &mut [C],
        work: &mut [C],
        h1: &[f64],
        h2: &[f64],
        inv: [f64; 4],
    ) {
        let nz = self.nz;
        let (phi, tmp) = work.split_at_mut(nz);
        self.helm.solve(1.0, b, k2, r, ZERO, ZERO, phi, tmp);
        phi.iter_mut().for_each(|p| *p = -*p);
        self.helm.solve(0.0, 1.0, k2, phi, ZERO, ZERO, w, tmp);
        let (p0, pn) = self.wall_dz(w);
        let c1 = -(p0 * inv[0] + pn * inv[1]);
        let c2 = -(p0 * inv[2] + pn * inv[3]);
        for k in 0..nz {
            w[k] += c1 * h1[k] + c2 * h2[k];
        }
        w[0] = ZERO;
        w[nz - 1] = ZERO;
    }
}
