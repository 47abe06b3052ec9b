//! `magsep bench fluid [--json] [--quick]`: the channel solver's cost per time step against the
//! grid size with one and two threads, the fitted cost exponent, and the cost of the coupling
//! per particle.
//!
//! Rows:
//! * `fluid_step`: seconds per step of `ChannelSolver::step` on an `n × n × (n+1)` grid (the
//!   thesis's 256 × 256 × 129 has this shape with a half-height grid), dealiased, in a
//!   liquid driven by a random divergence-free field so that the nonlinear term is non-trivial;
//!   median of the timed steps after one warm-up step, per thread count (a rayon pool of that
//!   size).
//! * `fluid_step_fit`: the exponent p of `t ∝ N^p` (N grid points) fitted over the sizes run,
//!   per thread count (1 would be linear; FFTs give ≈ 1.1, the Chebyshev mat-vecs O(nz²) per
//!   line raise it).
//! * `fluid_coupling`: seconds per particle of sampling (filter averages of u, ω and the
//!   convective derivative) plus spreading, for 10 000 spheres of one grid spacing on the
//!   64³ grid.
//!
//! Compare with a published solver run the same way: `scripts/peers/shenfun_kmm.sh` (see
//! `scripts/peers/README.md`).

use std::time::Instant;

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::{Value, json};

use magsep_systems::fluid::channel::coupling::FilterStencil;
use magsep_systems::fluid::channel::grid::ChannelGrid;
use magsep_systems::fluid::channel::solver::ChannelParams;
use magsep_systems::fluid::channel::stepper::ChannelSolver;

use crate::studies::bench::{BenchError, emit};
use crate::studies::fluid_charts::runtime;

/// A solver on an `n × n × (n+1)` grid of the thesis's channel proportions, with a random
/// smooth initial field.
fn solver(n: usize) -> Result<ChannelSolver, BenchError> {
    let l = 0.075;
    let grid = ChannelGrid::new(
        [n, n, n + 1],
        [
            4.0 * std::f64::consts::PI * l / 3.0,
            4.0 * std::f64::consts::PI * l / 3.0,
            2.0 * l,
        ],
    )
    .map_err(runtime)?;
    let mut s =
        ChannelSolver::new(ChannelParams::new(grid, 5.54e-3 / 1400.0, 0.9e-3)).map_err(runtime)?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let modes: Vec<(f64, f64, f64, f64)> = (0..8)
        .map(|_| {
            (
                rng.random_range(1..4) as f64,
                rng.random_range(1..4) as f64,
                rng.random_range(0.0..std::f64::consts::TAU),
                rng.random_range(-1e-3..1e-3),
            )
        })
        .collect();
    let mut u = vec![vec![0.0; grid.len()]; 3];
    for k in 0..grid.nz {
        let z = grid.z(k) / grid.height;
        let wall = (std::f64::consts::PI * z).sin();
        for i in 0..grid.nx {
            for j in 0..grid.ny {
                let (x, y) = (grid.x(i) / grid.lx, grid.y(j) / grid.ly);
                let n = grid.index(i, j, k);
                for (a, b, ph, amp) in &modes {
                    let arg = std::f64::consts::TAU * (a * x + b * y) + ph;
                    u[0][n] += amp * wall * arg.sin();
                    u[1][n] -= amp * wall * arg.cos();
                }
            }
        }
    }
    s.set_velocity([&u[0], &u[1], &u[2]]).map_err(runtime)?;
    Ok(s)
}

fn seconds_per_step(n: usize, steps: usize) -> Result<f64, BenchError> {
    let mut s = solver(n)?;
    s.step();
    let mut times: Vec<f64> = (0..steps)
        .map(|_| {
            let t = Instant::now();
            s.step();
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// Least-squares slope of ln t against ln N.
fn exponent(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0.ln(), a.1 + p.1.ln()));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |a, p| {
        let dx = p.0.ln() - mx;
        (a.0 + dx * (p.1.ln() - my), a.1 + dx * dx)
    });
    num / den
}

/// Coupling cost per particle \[s\] on the 64³ grid.
fn coupling_cost(particles: usize) -> Result<f64, BenchError> {
    let s = solver(64)?;
    let g = *s.grid();
    let zw = g.z_quadrature_weights();
    let zl = g.z_levels();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let xs: Vec<DVec3> = (0..particles)
        .map(|_| {
            DVec3::new(
                rng.random_range(0.0..g.lx),
                rng.random_range(0.0..g.ly),
                rng.random_range(0.0..g.height),
            )
        })
        .collect();
    let half = DVec3::splat(0.5 * g.dx());
    let mut f = [vec![0.0; g.len()], vec![0.0; g.len()], vec![0.0; g.len()]];
    let u = s.velocity();
    let w = s.vorticity();
    let start = Instant::now();
    let mut acc = DVec3::ZERO;
    for x in &xs {
        let Some(st) = FilterStencil::new(&g, &zw, &zl, *x, half) else {
            continue;
        };
        let v = st.average3(u);
        acc += v + st.average3(w);
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = half[k];
            if let (Some(p), Some(m)) = (
                FilterStencil::new(&g, &zw, &zl, *x + e, half),
                FilterStencil::new(&g, &zw, &zl, *x - e, half),
            ) {
                acc += v[k] * (p.average3(u) - m.average3(u));
            }
        }
        let [a, b, c] = &mut f;
        st.spread(DVec3::new(1e-6, 0.0, -1e-6), 1000.0, &mut [a, b, c]);
    }
    let t = start.elapsed().as_secs_f64();
    if !acc.is_finite() {
        return Err(runtime("non-finite coupling result"));
    }
    Ok(t / particles as f64)
}

/// Run the benchmark.
///
/// # Errors
/// [`BenchError`] when a solver cannot be built or stdout fails.
pub fn bench_fluid(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let sizes: &[usize] = if quick {
        &[16, 32]
    } else {
        &[32, 48, 64, 96, 128]
    };
    let steps = if quick { 3 } else { 5 };
    let mut rows: Vec<Value> = Vec::new();
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(runtime)?;
        let mut points = Vec::new();
        for &n in sizes {
            let t = pool.install(|| seconds_per_step(n, steps))?;
            let cells = (n * n * (n + 1)) as f64;
            points.push((cells, t));
            emit(
                &mut rows,
                as_json,
                json!({"name": "fluid_step", "grid": [n, n, n + 1], "threads": threads, "steps": steps, "seconds_per_step": t, "points_per_s": cells / t}),
            )?;
        }
        emit(
            &mut rows,
            as_json,
            json!({"name": "fluid_step_fit", "threads": threads, "exponent": exponent(&points), "sizes": sizes}),
        )?;
    }
    let n = if quick { 1000 } else { 10_000 };
    let per = coupling_cost(n)?;
    emit(
        &mut rows,
        as_json,
        json!({"name": "fluid_coupling", "grid": [64, 64, 65], "particles": n, "seconds_per_particle": per}),
    )
}
