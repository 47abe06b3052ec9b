//! The Orr-Sommerfeld eigenmode of plane Poiseuille flow (the least-stable mode at Re = 7500,
//! α = 1: Orszag 1971, c = 0.24989154 + 0.00223497 i), computed on Chebyshev points, and the
//! linear growth of its Tollmien-Schlichting wave in the full solver: the solver's validation
//! and its accuracy-against-cost chart (`magsep chart liquid-solver`). Dimensionless: channel
//! half-height 1, centreline velocity 1.

use super::cheb::{diff_matrix, matmul};
use super::grid::ChannelGrid;
use super::solver::{ChannelError, ChannelParams};
use super::stepper::ChannelSolver;
use faer::Mat;
use faer::linalg::solvers::Solve;
use num_complex::Complex64 as C;
use std::f64::consts::PI;

/// Orszag's eigenvalue for Re = 7500, α = 1.
pub const C_ORSZAG: C = C::new(0.24989154, 0.00223497);

/// The least-stable Orr-Sommerfeld eigenvalue near `shift` and its eigenfunction `v(ξ)` at the
/// `nz` ascending Chebyshev-Gauss-Lobatto points of `−1 ≤ ξ ≤ 1` (walls included, zero there),
/// for the base flow `U = 1 − ξ²`. Clamped fourth derivative with `v = (1 − ξ²) p(ξ)`
/// (Weideman & Reddy 2000), complex inverse iteration with faer's LU.
///
/// ```
/// use num_complex::Complex64 as C;
/// use magsep_systems::fluid::channel::orr_sommerfeld::{orr_sommerfeld, C_ORSZAG};
/// let (c, _) = orr_sommerfeld(1.0, 7500.0, 65, C::new(0.2499, 0.0022)).unwrap();
/// assert!((c - C_ORSZAG).norm() < 1e-6);
/// ```
///
/// # Errors
/// [`ChannelError::Grid`] for fewer than 5 points.
pub fn orr_sommerfeld(
    alpha: f64,
    re: f64,
    nz: usize,
    shift: C,
) -> Result<(C, Vec<C>), ChannelError> {
    let g = ChannelGrid::new([4, 4, nz], [1.0, 1.0, 2.0])?;
    let x: Vec<f64> = (0..nz).map(|k| g.z(k) - 1.0).collect();
    let d1 = diff_matrix(&g);
    let d2 = matmul(&d1, &d1, nz);
    let d3 = matmul(&d2, &d1, nz);
    let d4 = matmul(&d3, &d1, nz);
    let m = nz - 2;
    // clamped operators on the interior: v = (1 − x²) p, p(±1) = 0
    let at = |d: &[f64], i: usize, j: usize| d[(i + 1) * nz + j + 1];
    let d4c = Mat::<f64>::from_fn(m, m, |i, j| {
        let xi = x[i + 1];
        ((1.0 - xi * xi) * at(&d4, i, j) - 8.0 * xi * at(&d3, i, j) - 12.0 * at(&d2, i, j))
            / (1.0 - x[j + 1] * x[j + 1])
    });
    let d2c = Mat::<f64>::from_fn(m, m, |i, j| {
        let xi = x[i + 1];
        let id = if i == j { 1.0 } else { 0.0 };
        ((1.0 - xi * xi) * at(&d2, i, j) - 4.0 * xi * at(&d1, i, j) - 2.0 * id)
            / (1.0 - x[j + 1] * x[j + 1])
    });
    let a2 = alpha * alpha;
    let visc = C::new(1.0, 0.0) / C::new(0.0, alpha * re);
    let b = Mat::<C>::from_fn(m, m, |i, j| {
        C::new(d2c[(i, j)] - if i == j { a2 } else { 0.0 }, 0.0)
    });
    let a = Mat::<C>::from_fn(m, m, |i, j| {
        let id = if i == j { 1.0 } else { 0.0 };
        let u = 1.0 - x[i + 1] * x[i + 1];
        let lap2 = d4c[(i, j)] - 2.0 * a2 * d2c[(i, j)] + a2 * a2 * id;
        C::new(u * (d2c[(i, j)] - a2 * id) + 2.0 * id, 0.0) - visc * lap2
    });
    let shifted = Mat::<C>::from_fn(m, m, |i, j| a[(i, j)] - shift * b[(i, j)]);
    let lu = shifted.partial_piv_lu();
    let mut v = Mat::<C>::from_fn(m, 1, |i, _| C::new(1.0 + 0.1 * i as f64, 0.0));
    let mut c = shift;
    for _ in 0..60 {
        let mut y = &b * &v;
        lu.solve_in_place(&mut y);
        // y = λ v with λ = 1/(c − σ)
        let (mut num, mut den) = (C::new(0.0, 0.0), 0.0);
        for i in 0..m {
            num += y[(i, 0)] * v[(i, 0)].conj();
            den += v[(i, 0)].norm_sqr();
        }
        c = shift + den / num;
        let big = (0..m).map(|i| y[(i, 0)]).fold(C::new(0.0, 0.0), |b, z| {
            if z.norm() > b.norm() { z } else { b }
        });
        v = Mat::<C>::from_fn(m, 1, |i, _| y[(i, 0)] / big);
    }
    let mut out = vec![C::new(0.0, 0.0); nz];
    for i in 0..m {
        out[i + 1] = v[(i, 0)];
    }
    Ok((c, out))
}

/// A Tollmien-Schlichting wave's growth in the solver: the measured rate, the reference rate
/// and the wall time of the run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthRun {
    /// Measured growth rate `ln(E(t)/E(0))/(2t)` of the disturbance energy.
    pub rate: f64,
    /// `α c_i` of the Orr-Sommerfeld eigenvalue at nz = 129.
    pub reference: f64,
    /// `|rate − reference| / reference`.
    pub relative_error: f64,
    /// Wall time of the time stepping \[s\].
    pub wall_time_s: f64,
}

/// Grow a small Tollmien-Schlichting wave (Re = 7500, α = 1, amplitude 1e-5 on the
/// Poiseuille profile held by its pressure gradient) for `t_end` with step `dt` on `nz`
/// levels (8 × 4 periodic points) and measure its growth rate against `α c_i` of
/// [`orr_sommerfeld`] at nz = 129 (Orszag's 8-digit c_i is itself rounded by 2e-6 relative).
///
/// # Errors
/// [`ChannelError`] when the grid or the time step is invalid.
pub fn ts_growth(nz: usize, dt: f64, t_end: f64) -> Result<GrowthRun, ChannelError> {
    let (alpha, re) = (1.0, 7500.0);
    let nu = 1.0 / re;
    let g = ChannelGrid::new([8, 4, nz], [2.0 * PI / alpha, 1.0, 2.0])?;
    let mut p = ChannelParams::new(g, nu, dt);
    p.mean_pressure_gradient = [2.0 * nu, 0.0];
    let mut s = ChannelSolver::new(p)?;
    let (_, vh) = orr_sommerfeld(alpha, re, nz, C::new(0.2499, 0.0022))?;
    let (c_ref, _) = orr_sommerfeld(alpha, re, 129, C::new(0.2499, 0.0022))?;
    // w = Re(ε v̂ e^{iαx}), u = Re(i/α v̂' ε e^{iαx}) + U
    let d = diff_matrix(&g);
    let dv: Vec<C> = (0..nz)
        .map(|i| (0..nz).map(|j| vh[j] * d[i * nz + j]).sum())
        .collect();
    let eps = 1e-5;
    let n = g.len();
    let (mut u, mut w) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..nz {
        for i in 0..g.nx {
            let e = C::from_polar(eps, alpha * g.x(i));
            for j in 0..g.ny {
                let z = g.z(k);
                u[g.index(i, j, k)] = z * (2.0 - z) + (C::new(0.0, 1.0 / alpha) * dv[k] * e).re;
                w[g.index(i, j, k)] = (vh[k] * e).re;
            }
        }
    }
    s.set_velocity([&u, &vec![0.0; n], &w])?;
    let energy = |s: &ChannelSolver| {
        let wts = g.z_quadrature_weights();
        let np = g.nx * g.ny;
        let mut e = 0.0;
        for k in 0..nz {
            for c in 0..3 {
                let f = &s.velocity()[c][k * np..(k + 1) * np];
                let mean = f.iter().sum::<f64>() / np as f64;
                e += wts[k] * f.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
            }
        }
        e
    };
    let e0 = energy(&s);
    let steps = (t_end / dt).round() as usize;
    let start = std::time::Instant::now();
    for _ in 0..steps {
        s.step();
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    let rate = (energy(&s) / e0).ln() / (2.0 * s.time());
    let reference = alpha * c_ref.im;
    Ok(GrowthRun {
        rate,
        reference,
        relative_error: (rate - reference).abs() / reference,
        wall_time_s,
    })
}
