//! TEA-HI: truncated expansion approximation of the square root of the diffusion tensor
//! (Geyer & Winter, *J. Chem. Phys.* **130**, 114905 (2009), "An O(N²) approximation for
//! hydrodynamic interactions in Brownian dynamics simulations"; arXiv:0801.3212).
//!
//! # Equations (in the 3N×3N matrix, N' = 3N, Greek indices run over all N' coordinates)
//!
//! * ε = ⟨D_αβ / √(D_αα D_ββ)⟩, the mean over all N'(N'−1) off-diagonal elements (zeros
//!   included, signed values);
//! * a = (N'−1)ε² − (N'−2)ε, β' = (1 − √(1−a))/a, evaluated as β' = 1/(1 + √(1−a)) (same
//!   value, no 0/0: β' → 1/2 as a → 0, so ε = 0 gives free draining without NaN);
//! * C_α = (1 + Σ_{β≠α} β'² D_αβ²/(D_αα D_ββ))^{−1/2};
//! * B_αα = C_α √D_αα, B_αβ = C_α β' D_αβ/√D_ββ (α ≠ β), and R = √(2Δt) B g.
//!
//! (B Bᵀ)_αα = C_α² D_αα (1 + Σ_{β≠α} β'² D_αβ²/(D_αα D_ββ)) = D_αα exactly. For a matrix
//! whose normalised off-diagonals all equal ε, B Bᵀ = D exactly: with D̃ = I + εE,
//! E = 11ᵀ − I, E² = (N'−2)E + (N'−1)I, the requirement that C²(I + β'εE)² has off-diagonal
//! ε gives a β'² − 2β' + 1 = 0, whose root that stays finite as a → 0 is the β' above; TEA
//! applies this uniform-coupling solution with the mean ε to the real matrix. No real β'
//! exists for a > 1: [`HydroError::TeaBreakdown`] is returned.
//!
//! # Verification against the paper and differences
//!
//! The full paper text was not reachable through the reference search (only the abstract
//! and figure captions of arXiv:0801.3212 / JCP 130, 114905). The formulas above are the
//! reconstruction D-000-9 (docs/references.md), re-derived
//! here from the uniform-coupling ansatz (see above) and checked numerically (diagonal
//! variance exact; uniform-coupling matrix reproduced exactly). A public GPU code manual
//! (SOP-GPU) prints β' = (1 − √(1−[(N−1)ε² − (N−2)ε]))/√((N−1)ε² − (N−2)ε), C_α with
//! exponent +1/2 and D_αβ unsquared, and ε = ⟨D_αβ/D_αα⟩; the first three violate the exact
//! diagonal normalisation and are treated as typos. For ε we normalise by √(D_αα D_ββ)
//! instead of D_αα: identical for equal radii (the paper's case), symmetric and scale-free
//! for polydisperse suspensions — an extension, not from the paper.
//!
//! # Cost
//! Three O(N'²) passes over the dense mobility (ε, C_α, and one matvec per noise draw).

use super::HydroError;
use super::rpy::DenseSym;
use rayon::prelude::*;

/// Global TEA parameters of one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TeaStats {
    /// mean normalised off-diagonal coupling ε
    pub epsilon: f64,
    /// a = (N'−1)ε² − (N'−2)ε
    pub a: f64,
    /// β' = (1 − √(1−a))/a
    pub beta: f64,
}

/// Prepared TEA factor (B is never stored; it is applied through the mobility matrix).
#[derive(Debug, Clone)]
pub(crate) struct Tea {
    pub stats: TeaStats,
    /// C_α
    c: Vec<f64>,
    /// √D_αα
    sqrt_diag: Vec<f64>,
    /// 1/√D_αα
    inv_sqrt_diag: Vec<f64>,
}

impl Tea {
    pub fn new(m: &DenseSym) -> Result<Self, HydroError> {
        let n = m.n;
        let sqrt_diag: Vec<f64> = (0..n).map(|k| m.get(k, k).sqrt()).collect();
        let inv_sqrt_diag: Vec<f64> = sqrt_diag.iter().map(|s| 1.0 / s).collect();
        // Per-column partial sums (parallel), reduced sequentially: thread-count independent.
        let col_sums: Vec<(f64, f64)> = (0..n)
            .into_par_iter()
            .map(|b| {
                let col = m.col(b);
                let mut s1 = 0.0;
                let mut s2 = 0.0;
                for (a, &v) in col.iter().enumerate() {
                    if a != b {
                        let x = v * inv_sqrt_diag[a];
                        s1 += x;
                        s2 += x * x;
                    }
                }
                (
                    s1 * inv_sqrt_diag[b],
                    s2 * inv_sqrt_diag[b] * inv_sqrt_diag[b],
                )
            })
            .collect();
        let nf = n as f64;
        let pairs = nf * (nf - 1.0);
        let epsilon = if pairs > 0.0 {
            col_sums.iter().map(|p| p.0).sum::<f64>() / pairs
        } else {
            0.0
        };
        let a = (nf - 1.0) * epsilon * epsilon - (nf - 2.0) * epsilon;
        if !a.is_finite() || a > 1.0 {
            return Err(HydroError::TeaBreakdown { a });
        }
        let beta = 1.0 / (1.0 + (1.0 - a).sqrt());
        // symmetric matrix: column sums of squares are the row sums Σ_{β≠α} D_αβ²/(D_αα D_ββ)
        let c = col_sums
            .iter()
            .map(|p| 1.0 / (1.0 + beta * beta * p.1).sqrt())
            .collect();
        Ok(Self {
            stats: TeaStats { epsilon, a, beta },
            c,
            sqrt_diag,
            inv_sqrt_diag,
        })
    }

    /// y = B w (linear in w), O(N'²).
    pub fn apply(&self, m: &DenseSym, w: &[f64], y: &mut [f64]) {
        let what: Vec<f64> = w
            .iter()
            .zip(&self.inv_sqrt_diag)
            .map(|(w, s)| w * s)
            .collect();
        m.matvec(&what, y);
        let beta = self.stats.beta;
        for (k, yk) in y.iter_mut().enumerate() {
            // off-diagonal part Σ_{β≠α} D_αβ ŵ_β = (D ŵ)_α − D_αα ŵ_α
            let off = *yk - m.get(k, k) * what[k];
            *yk = self.c[k] * (self.sqrt_diag[k] * w[k] + beta * off);
        }
    }

    /// The explicit N'×N' factor B (for accuracy charts and tests).
    pub fn dense_b(&self, m: &DenseSym) -> faer::Mat<f64> {
        let beta = self.stats.beta;
        faer::Mat::from_fn(m.n, m.n, |a, b| {
            if a == b {
                self.c[a] * self.sqrt_diag[a]
            } else {
                self.c[a] * beta * m.get(a, b) * self.inv_sqrt_diag[b]
            }
        })
    }
}
