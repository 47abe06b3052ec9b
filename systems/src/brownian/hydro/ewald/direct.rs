//! Streamed direct RPY product: v = μF summed over all pairs, with no matrix stored.
//!
//! Used by the spectral Ewald operator when its cost model picks the direct sum (small or
//! compact systems, e.g. N = 1000 at φ = 0.01). Each product evaluates every far pair block
//! (Zuk et al. 2014, r > a_i + a_j)
//! μ_ij = (1/8πηr)[(1 + q/3) I + (1 − q) r̂r̂], q = (a_i² + a_j²)/r²,
//! on the fly from structure-of-arrays positions, in eight independent lanes per row that the
//! compiler vectorises (SSE2; AVX2 when the processor has it: the same operations, no fused
//! multiply-add, so bitwise the same result). Overlapping pairs (r ≤ a_i + a_j, found once
//! per configuration with a cell list) are masked out of the lanes and added from a short list
//! of exact Zuk overlap blocks ([`rpy_coefficients`]); the self block is I/(6πηa_i).
//!
//! Preparation is O(N) plus the overlap search; each product is O(N²) flops with O(N) memory
//! (the stored alternative, [`super::near::Near`] with ξ = 0, keeps 20 bytes per pair and
//! spends most of its time building them). Rows are independent and each is summed in a
//! fixed order (lane l takes j ≡ l mod 8, lanes combined pairwise in a fixed tree, then the
//! overlap blocks), so the result is bitwise the same for every thread count.
//!
//! Units: positions and radii \[m\], viscosity [Pa s], forces \[N\], velocities [m/s].

use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

use crate::brownian::cells::CellList;
use crate::brownian::hydro::rpy::{rpy_coefficients, self_mobility};

/// Rows per parallel task.
const ROWS: usize = 16;

/// Lanes per row (independent partial sums).
const LANES: usize = 8;

/// The prepared streamed direct product of one configuration.
#[derive(Debug)]
pub(crate) struct Direct {
    /// particles (the arrays below are padded to a multiple of [`LANES`])
    n: usize,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    radius: Vec<f64>,
    radius_sq: Vec<f64>,
    self_mob: Vec<f64>,
    /// 1/(8πη)
    pre: f64,
    /// overlap blocks of row i: `overlap[start[i]..start[i + 1]]` as (j, iso, dyad/r², d)
    start: Vec<usize>,
    overlap: Vec<(u32, f64, f64, DVec3)>,
}

/// Squared distance, written once so that the lanes and the overlap search agree bitwise.
#[inline(always)]
fn dist2(dx: f64, dy: f64, dz: f64) -> f64 {
    dx * dx + dy * dy + dz * dz
}

/// True for a far pair (handled by the lanes), false for an overlapping one (listed).
#[inline(always)]
fn is_far(r2: f64, sum: f64) -> bool {
    r2 > sum * sum
}

/// Source particle data for one product (structure of arrays).
struct Src<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
    radius: &'a [f64],
    radius_sq: &'a [f64],
    fx: &'a [f64],
    fy: &'a [f64],
    fz: &'a [f64],
}

/// Lane values of one source field for sources `j0..j0 + LANES`.
#[inline(always)]
fn lanes(v: &[f64], j0: usize) -> [f64; LANES] {
    let mut out = [0.0; LANES];
    out.copy_from_slice(&v[j0..j0 + LANES]);
    out
}

/// Far-field contributions (times 8πη) of `LANES` sources at once, added to `acc`; the
/// overlapping ones (and the target itself) give exactly zero.
#[inline(always)]
fn add_lanes(s: &Src<'_>, j0: usize, p: [f64; 3], a: f64, a2: f64, acc: &mut [[f64; LANES]; 3]) {
    let (x, y, z) = (lanes(s.x, j0), lanes(s.y, j0), lanes(s.z, j0));
    let (rad, rad2) = (lanes(s.radius, j0), lanes(s.radius_sq, j0));
    let (fx, fy, fz) = (lanes(s.fx, j0), lanes(s.fy, j0), lanes(s.fz, j0));
    for l in 0..LANES {
        let dx = p[0] - x[l];
        let dy = p[1] - y[l];
        let dz = p[2] - z[l];
        let r2 = dist2(dx, dy, dz);
        let far = is_far(r2, a + rad[l]);
        let inv2 = 1.0 / if far { r2 } else { 1.0 };
        let inv = inv2.sqrt();
        let q = (a2 + rad2[l]) * inv2;
        let iso = inv * (1.0 + q * (1.0 / 3.0));
        let c = inv * inv2 * (1.0 - q);
        let t = c * (dx * fx[l] + dy * fy[l] + dz * fz[l]);
        let iso = if far { iso } else { 0.0 };
        let t = if far { t } else { 0.0 };
        acc[0][l] += iso * fx[l] + t * dx;
        acc[1][l] += iso * fy[l] + t * dy;
        acc[2][l] += iso * fz[l] + t * dz;
    }
}

/// Far-field velocity at target (`p`, radius `a`, `a2` = a²) from all sources, times 8πη,
/// overlapping pairs (and the target itself) contributing zero. The sources must be padded
/// to a multiple of [`LANES`] (padding: zero force, far away).
#[inline(always)]
fn row_sum(s: &Src<'_>, p: [f64; 3], a: f64, a2: f64) -> [f64; 3] {
    let mut acc = [[0.0_f64; LANES]; 3];
    for j0 in (0..s.x.len()).step_by(LANES) {
        add_lanes(s, j0, p, a, a2, &mut acc);
    }
    acc.map(|v| ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7])))
}

/// [`row_sum`] compiled for AVX2 (same operations, wider vectors).
///
/// # Safety
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn row_sum_avx2(s: &Src<'_>, p: [f64; 3], a: f64, a2: f64) -> [f64; 3] {
    row_sum(s, p, a, a2)
}

/// [`row_sum`] with the widest vectors the processor supports.
fn row_sum_best(s: &Src<'_>, p: [f64; 3], a: f64, a2: f64, avx2: bool) -> [f64; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        if avx2 {
            // SAFETY: callers pass `avx2` true only when the processor supports AVX2.
            return unsafe { row_sum_avx2(s, p, a, a2) };
        }
    }
    let _ = avx2;
    row_sum(s, p, a, a2)
}

impl Direct {
    /// Prepares the product (structure-of-arrays copy, self mobilities, overlap blocks).
    /// Inputs must be validated (finite positions, positive radii and viscosity).
    pub fn new(positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let n = positions.len();
        let a_max = radii.iter().fold(0.0_f64, |m, a| m.max(*a));
        let mut start = Vec::with_capacity(n + 1);
        start.push(0);
        let mut overlap = Vec::new();
        if n > 1 {
            let reach = 2.0 * a_max * (1.0 + 1e-9);
            let cells = CellList::build(positions, reach, |_| true);
            let rows: Vec<Vec<(u32, f64, f64, DVec3)>> = (0..n)
                .into_par_iter()
                .with_min_len(64)
                .map(|i| {
                    let mut row = Vec::new();
                    cells.for_each_neighbour(positions, i, reach, |j, _| {
                        let d = DVec3::new(
                            positions[i].x - positions[j].x,
                            positions[i].y - positions[j].y,
                            positions[i].z - positions[j].z,
                        );
                        let r2 = dist2(d.x, d.y, d.z);
                        if !is_far(r2, radii[i] + radii[j]) {
                            let (iso, dyad) = rpy_coefficients(r2, radii[i], radii[j], viscosity);
                            let f = if r2 > 0.0 { dyad / r2 } else { 0.0 };
                            row.push((j as u32, iso, f, d));
                        }
                    });
                    row.sort_by_key(|e| e.0);
                    row
                })
                .collect();
            for row in rows {
                overlap.extend(row);
                start.push(overlap.len());
            }
        } else {
            start.resize(n + 1, 0);
        }
        // padding sources (zero force, radius 0) at least 4 max(a) beyond every particle
        let (lo, hi) = positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let pad = hi + DVec3::splat((hi - lo).max_element().max(0.0) + 4.0 * a_max);
        let padded = n.div_ceil(LANES) * LANES;
        let field = |f: &dyn Fn(usize) -> f64, pad: f64| -> Vec<f64> {
            (0..padded)
                .map(|i| if i < n { f(i) } else { pad })
                .collect()
        };
        Self {
            x: field(&|i| positions[i].x, pad.x),
            y: field(&|i| positions[i].y, pad.y),
            z: field(&|i| positions[i].z, pad.z),
            radius: field(&|i| radii[i], 0.0),
            radius_sq: field(&|i| radii[i] * radii[i], 0.0),
            n,
            self_mob: radii.iter().map(|&a| self_mobility(a, viscosity)).collect(),
            pre: 1.0 / (8.0 * PI * viscosity),
            start,
            overlap,
        }
    }

    /// Number of stored (overlap) pair blocks, each pair twice.
    pub fn pairs(&self) -> usize {
        self.overlap.len()
    }

    /// out = μ x for flat 3N vectors.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        self.apply_with(x, out, avx2);
    }

    /// [`Direct::apply`] with AVX2 on or off (`avx2` true only if the processor has it).
    pub fn apply_with(&self, x: &[f64], out: &mut [f64], avx2: bool) {
        debug_assert_eq!(x.len(), 3 * self.n);
        debug_assert_eq!(out.len(), 3 * self.n);
        let len = self.x.len();
        let (mut fx, mut fy, mut fz) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        for (i, c) in x.chunks_exact(3).enumerate() {
            (fx[i], fy[i], fz[i]) = (c[0], c[1], c[2]);
        }
        let src = Src {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            radius: &self.radius,
            radius_sq: &self.radius_sq,
            fx: &fx,
            fy: &fy,
            fz: &fz,
        };
        out.par_chunks_mut(3 * ROWS).enumerate().for_each(|(k, o)| {
            for (r, oi) in o.chunks_exact_mut(3).enumerate() {
                let i = k * ROWS + r;
                let p = [self.x[i], self.y[i], self.z[i]];
                let far = row_sum_best(&src, p, self.radius[i], self.radius_sq[i], avx2);
                let xi = DVec3::new(fx[i], fy[i], fz[i]);
                let mut acc = DVec3::from_array(far) * self.pre + xi * self.self_mob[i];
                for &(j, iso, f, d) in &self.overlap[self.start[i]..self.start[i + 1]] {
                    let j = j as usize;
                    let xj = DVec3::new(fx[j], fy[j], fz[j]);
                    acc += xj * iso + d * (f * d.dot(xj));
                }
                oi.copy_from_slice(&[acc.x, acc.y, acc.z]);
            }
        });
    }
}
