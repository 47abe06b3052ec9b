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
    /// Builds the blocks for `params` (cut-off, ξ).
    pub fn new(params: &Params, positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let n = positions.len();
        let xi = params.xi;
        let cells =
            (!params.is_direct()).then(|| CellList::build(positions, params.cutoff, |_| true));
        let rows: Vec<Row> = (0..n)
            .into_par_iter()
            .with_min_len(ROWS)
            .map(|i| {
                let mut cols = Vec::new();
                let mut blocks = Vec::new();
                let mut add = |j: usize, d: DVec3| {
                    let r = d.length();
                    let (iso, dyad) = pair(r, radii[i], radii[j], viscosity, xi);
                    let f = if r > 0.0 { dyad / (r * r) } else { 0.0 };
                    cols.push(j as u32);
                    blocks.push((iso, f));
                };
                match &cells {
                    Some(c) => c.for_each_neighbour(positions, i, params.cutoff, &mut add),
                    None => {
                        for j in (0..n).filter(|&j| j != i) {
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
        let mut start = Vec::with_capacity(n + 1);
        start.push(0);
        let mut cols = Vec::new();
        let mut blocks = Vec::new();
        for (c, b) in rows {
            cols.extend(c);
            blocks.extend(b);
            start.push(cols.len());
        }
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
        out.par_chunks_mut(3 * ROWS).enumerate().for_each(|(k, o)| {
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
        });
    }
}
