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

/// Fixed row chunks of the product (each with its own partial output, summed in chunk
/// order: the same result for every thread count).
const CHUNKS: usize = 8;

/// Rows per parallel task of the final sum.
const ROWS: usize = 64;

/// Upper block rows: row i holds the pairs (i, j), j > i, each stored once as (iso, dyad
/// factor f) with block = iso I + f d dᵀ, d = x_i − x_j recomputed from the stored positions
/// in every product (the same bits as when the block was made; 20 bytes per pair read per
/// product). The product uses each block for both rows, B x_j into row i and B x_i into
/// row j (the blocks are symmetric).
#[derive(Debug)]
pub(crate) struct Near {
    rows: Vec<Row>,
    /// first row of each chunk (and n at the end): about equal pair counts per chunk
    bounds: Vec<usize>,
    diag: Vec<f64>,
    positions: Vec<DVec3>,
    /// the chunks' partial outputs (CHUNKS × 3N), reused across products
    partial: std::sync::Mutex<Vec<f64>>,
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
    /// j > i, in parallel over rows, columns in the cell list's order, independent of the
    /// thread count) and serves both rows (the block is symmetric: same r, same
    /// s = a_i² + a_j²).
    pub fn new(params: &Params, positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let n = positions.len();
        let xi = params.xi;
        // cells of edge r_c/2 searched two to each side: 3.8 instead of 6.4 candidates per
        // pair within the cut-off
        let cells = (!params.is_direct())
            .then(|| CellList::build_with_reach(positions, params.cutoff, 2, |_| true));
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
        let total: usize = upper.iter().map(|r| r.0.len()).sum();
        let mut bounds = vec![0];
        let mut seen = 0;
        for (i, r) in upper.iter().enumerate() {
            // cut before row i once the running count reaches the next chunk's share
            if bounds.len() < CHUNKS && seen * CHUNKS >= total * bounds.len() && seen > 0 {
                bounds.push(i);
            }
            seen += r.0.len();
        }
        bounds.resize(CHUNKS, n);
        bounds.push(n);
        Self {
            rows: upper,
            bounds,
            diag,
            positions: positions.to_vec(),
            partial: std::sync::Mutex::new(Vec::new()),
        }
    }

    /// Number of pair blocks of the operator (each pair twice, once per row; stored once).
    pub fn pairs(&self) -> usize {
        2 * self.rows.iter().map(|r| r.0.len()).sum::<usize>()
    }

    /// out = near-field product of the flat force vector `x` (3N).
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        let n3 = out.len();
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        // the buffers of the previous product (a fresh set if another product holds them)
        let mut guard = self.partial.try_lock().ok();
        let mut fresh = Vec::new();
        let partial = match guard.as_deref_mut() {
            Some(p) => p,
            None => &mut fresh,
        };
        partial.clear();
        partial.resize(CHUNKS * n3, 0.0);
        partial
            .par_chunks_mut(n3.max(1))
            .enumerate()
            .for_each(|(c, part)| {
                #[cfg(target_arch = "x86_64")]
                if avx2 {
                    // SAFETY: `avx2` is true only when the processor has AVX2 and FMA
                    unsafe { self.chunk_avx2(c, part, x) };
                    return;
                }
                self.chunk(c, part, x);
            });
        let partial = &*partial;
        out.par_chunks_mut(3 * ROWS).enumerate().for_each(|(k, o)| {
            for (r, oi) in o.iter_mut().enumerate() {
                let e = 3 * k * ROWS + r;
                let mut acc = x[e] * self.diag[e / 3];
                for c in 0..CHUNKS {
                    acc += partial[c * n3 + e];
                }
                *oi = acc;
            }
        });
    }

    /// [`Near::chunk`] compiled for AVX2 (bitwise the same result).
    ///
    /// # Safety
    /// The processor must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn chunk_avx2(&self, c: usize, part: &mut [f64], x: &[f64]) {
        self.chunk(c, part, x);
    }

    /// The pairs of chunk `c`'s rows added into its partial output `part` (3N, zero on entry).
    #[inline(always)]
    fn chunk(&self, c: usize, part: &mut [f64], x: &[f64]) {
        for i in self.bounds[c]..self.bounds[c + 1] {
            let (cols, blocks) = &self.rows[i];
            let pi = self.positions[i];
            let fi = DVec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
            let mut acc = DVec3::ZERO;
            for (&j, &(iso, f)) in cols.iter().zip(blocks) {
                let j = j as usize;
                let d = pi - self.positions[j];
                let xj = DVec3::new(x[3 * j], x[3 * j + 1], x[3 * j + 2]);
                acc += xj * iso + d * (f * d.dot(xj));
                let v = fi * iso + d * (f * d.dot(fi));
                let o = &mut part[3 * j..3 * j + 3];
                o[0] += v.x;
                o[1] += v.y;
                o[2] += v.z;
            }
            let o = &mut part[3 * i..3 * i + 3];
            o[0] += acc.x;
            o[1] += acc.y;
            o[2] += acc.z;
        }
    }
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
    /// diagonal's self term: the half list (each pair stored once) serves both rows.
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
