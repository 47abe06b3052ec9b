//! Real-space (short-ranged) part of the spectral Ewald RPY product: a sparse symmetric
//! block matrix holding, for every pair closer than the cut-off r_c, the Ewald real-space
//! remainder (1/8πη)[S_R(r) + (a_i²+a_j²)/6 · L_R(r)] ([`super::kernels`]); for overlapping
//! pairs (r ≤ a_i + a_j) instead the exact Zuk et al. overlap block minus the wave-space
//! part that the grid adds, μ_ij^Zuk − (1/8πη)[W_S(r) + (a_i²+a_j²)/6 · W_L(r)]; and on the
//! diagonal the self mobility minus the grid's self-interaction,
//! I/(6πηa_i) − (1/8πη)[4ξ/√π − (a_i²/3)·16ξ³/(3√π)] I.
//! With ξ = 0 (direct sum) the blocks are the plain RPY blocks of every pair.

use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

use super::kernels::{far_rpy, real_rpy, smoothed_laplacian, wave_stokeslet};
use super::params::Params;
use crate::brownian::cells::CellList;
use crate::brownian::hydro::rpy::{rpy_coefficients, self_mobility};

/// Rows per parallel task.
const ROWS: usize = 64;

/// CSR block matrix: row i's blocks are `blocks[start[i]..start[i + 1]]` with columns `cols`;
/// blocks stored as (iso, dyad factor f) with block = iso I + f d dᵀ, d = x_i − x_j recomputed
/// from the stored positions in every product (the same bits as when the block was made;
/// 20 instead of 44 bytes per block read per product).
#[derive(Debug)]
pub(crate) struct Near {
    start: Vec<usize>,
    cols: Vec<u32>,
    blocks: Vec<(f64, f64)>,
    diag: Vec<f64>,
    positions: Vec<DVec3>,
}

/// One row of the pair list: columns and blocks.
type Row = (Vec<u32>, Vec<(f64, f64)>);

/// (iso, dyad) in SI of the pair block of particles at separation r with radii a_i, a_j.
fn pair(r: f64, a_i: f64, a_j: f64, viscosity: f64, xi: f64) -> (f64, f64) {
    let pre = 1.0 / (8.0 * PI * viscosity);
    let s = a_i * a_i + a_j * a_j;
    if r > a_i + a_j {
        if xi == 0.0 {
            let (a, b) = far_rpy(r, s);
            return (pre * a, pre * b);
        }
        let (a, b) = real_rpy(r, xi, s);
        (pre * a, pre * b)
    } else {
        let (za, zb) = rpy_coefficients(r * r, a_i, a_j, viscosity);
        if xi == 0.0 {
            return (za, zb);
        }
        let (wa, wb) = wave_stokeslet(r, xi, xi);
        let (la, lb) = smoothed_laplacian(r, xi);
        (
            za - pre * (wa + s / 6.0 * la),
            zb - pre * (wb + s / 6.0 * lb),
        )
    }
}

impl Near {
    /// Builds the blocks for `params` (cut-off, ξ). Each pair's block is computed once (for
    /// j > i, in parallel over rows) and mirrored into row j (the block is symmetric: same r,
    /// same s = a_i² + a_j²); row i holds first its columns k < i in increasing k, then its
    /// columns j > i in the cell list's order, independent of the thread count.
    pub fn new(params: &Params, positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let n = positions.len();
        let xi = params.xi;
        let cells =
            (!params.is_direct()).then(|| CellList::build(positions, params.cutoff, |_| true));
        let upper: Vec<Row> = (0..n)
            .into_par_iter()
            .with_min_len(ROWS)
            .map(|i| {
                let mut cols = Vec::new();
                let mut blocks = Vec::new();
                let mut add = |j: usize, d: DVec3| {
                    if j <= i {
                        return;
                    }
                    let r = d.length();
                    let (iso, dyad) = pair(r, radii[i], radii[j], viscosity, xi);
                    let f = if r > 0.0 { dyad / (r * r) } else { 0.0 };
                    cols.push(j as u32);
                    blocks.push((iso, f));
                };
                match &cells {
                    Some(c) => c.for_each_neighbour(positions, i, params.cutoff, &mut add),
                    None => {
                        for j in i + 1..n {
                            add(j, positions[i] - positions[j]);
                        }
                    }
                }
                (cols, blocks)
            })
            .collect();
        let pre = 1.0 / (8.0 * PI * viscosity);
        let sqrt_pi = PI.sqrt();
        let diag = radii
            .iter()
            .map(|&a| {
                let wave = 4.0 * xi / sqrt_pi - a * a / 3.0 * 16.0 * xi.powi(3) / (3.0 * sqrt_pi);
                self_mobility(a, viscosity) - pre * wave
            })
            .collect();
        let (start, cols, blocks) = mirror(&upper);
        Self {
            start,
            cols,
            blocks,
            diag,
            positions: positions.to_vec(),
        }
    }

    /// Number of stored pair blocks (each pair twice).
    pub fn pairs(&self) -> usize {
        self.cols.len()
    }

    /// out = near-field product of the flat force vector `x` (3N).
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        out.par_chunks_mut(3 * ROWS).enumerate().for_each(|(k, o)| {
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: `avx2` is true only when the processor has AVX2 and FMA
                unsafe { self.rows_avx2(k, o, x) };
                return;
            }
            self.rows(k, o, x);
        });
    }

    /// [`Near::rows`] compiled for AVX2 (bitwise the same result).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn rows_avx2(&self, k: usize, o: &mut [f64], x: &[f64]) {
        self.rows(k, o, x);
    }

    /// Rows `k ROWS ..` of the product into `o`.
    #[inline(always)]
    fn rows(&self, k: usize, o: &mut [f64], x: &[f64]) {
        for (r, oi) in o.chunks_exact_mut(3).enumerate() {
            let i = k * ROWS + r;
            let mut acc = DVec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]) * self.diag[i];
            let xi = self.positions[i];
            for b in self.start[i]..self.start[i + 1] {
                let j = self.cols[b] as usize;
                let (iso, f) = self.blocks[b];
                let d = xi - self.positions[j];
                let xj = DVec3::new(x[3 * j], x[3 * j + 1], x[3 * j + 2]);
                acc += xj * iso + d * (f * d.dot(xj));
            }
            oi.copy_from_slice(&[acc.x, acc.y, acc.z]);
        }
    }
}

/// The full CSR (start, columns, blocks) from the upper rows (columns j > i): row i gets the
/// mirrored blocks of every earlier row k that lists i (increasing k), then its own.
fn mirror(upper: &[Row]) -> (Vec<usize>, Vec<u32>, Vec<(f64, f64)>) {
    let n = upper.len();
    let mut lower = vec![0usize; n];
    for (cols, _) in upper {
        for &j in cols {
            lower[j as usize] += 1;
        }
    }
    let mut start = Vec::with_capacity(n + 1);
    start.push(0);
    for (i, (cols, _)) in upper.iter().enumerate() {
        start.push(start[i] + lower[i] + cols.len());
    }
    let total = start[n];
    let mut out_cols = vec![0u32; total];
    let mut out_blocks = vec![(0.0, 0.0); total];
    // cursor of the next mirrored entry per row
    let mut cursor: Vec<usize> = start[..n].to_vec();
    for (k, (cols, blocks)) in upper.iter().enumerate() {
        let own = start[k] + lower[k];
        out_cols[own..own + cols.len()].copy_from_slice(cols);
        out_blocks[own..own + cols.len()].copy_from_slice(blocks);
        for (&j, &b) in cols.iter().zip(blocks) {
            let c = &mut cursor[j as usize];
            out_cols[*c] = k as u32;
            out_blocks[*c] = b;
            *c += 1;
        }
    }
    (start, out_cols, out_blocks)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brownian::hydro::tests::{A, ETA, random_config};
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn unit(c: usize) -> DVec3 {
        let mut e = DVec3::ZERO;
        e[c] = 1.0;
        e
    }

    /// Every 3×3 block of the operator (read column by column through `apply`) equals the
    /// pair block computed directly for that pair (zero beyond the cut-off), with the
    /// diagonal's self term: the mirrored half list stores each pair in both rows.
    #[test]
    fn mirrored_blocks_equal_the_pair_blocks_in_both_rows() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let n = 120;
        let (pos, radii) = random_config(&mut rng, n, 10.0 * A, true);
        for cutoff in [Some(3.0 * A), None] {
            let params = Params::with_cutoff(1e-6, cutoff, &pos, &radii);
            let near = Near::new(&params, &pos, &radii, ETA);
            let (mut x, mut out) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
            let mut stored = 0;
            let mut worst = 0.0_f64;
            for col in 0..3 * n {
                x.fill(0.0);
                x[col] = 1.0;
                near.apply(&x, &mut out);
                let j = col / 3;
                for i in 0..n {
                    let d = pos[i] - pos[j];
                    let expect = if i == j {
                        unit(col % 3) * near.diag[i]
                    } else if d.length() < params.cutoff {
                        let r = d.length();
                        let (iso, dyad) = pair(r, radii[i], radii[j], ETA, params.xi);
                        let e = unit(col % 3);
                        e * iso + d * (dyad / (r * r) * d.dot(e))
                    } else {
                        DVec3::ZERO
                    };
                    if i != j && expect != DVec3::ZERO {
                        stored += 1;
                    }
                    let got = DVec3::new(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
                    let scale = 1.0 / (6.0 * PI * ETA * A);
                    worst = worst.max((got - expect).abs().max_element() / scale);
                }
            }
            assert!(worst < 1e-13, "{cutoff:?}: {worst}");
            assert_eq!(stored / 3, near.pairs(), "{cutoff:?}");
            assert!(near.pairs() > n, "{cutoff:?}: {}", near.pairs());
        }
    }
}
