//! Rotne–Prager–Yamakawa (RPY) translational mobility for spheres of different radii,
//! including the overlap regularisation, and the dense 3N×3N mobility matrix.
//!
//! # Equations
//!
//! Pair block μ_ij [m/(N s)] for r = x_i − x_j, r = |r|, r̂ = r/r, radii a_i, a_j,
//! viscosity η (Zuk, Wajnryb, Mizerski & Szymczak, *J. Fluid Mech.* **741**, R5 (2014),
//! "Rotne–Prager–Yamakawa approximation for different-sized particles in application to
//! macromolecular bead models"):
//!
//! * r > a_i + a_j (no overlap):
//!   μ_ij = 1/(8πηr) · [ (1 + (a_i²+a_j²)/(3r²)) I + (1 − (a_i²+a_j²)/r²) r̂r̂ ]
//! * |a_i − a_j| < r ≤ a_i + a_j (partial overlap):
//!   μ_ij = 1/(6πη a_i a_j) · [ (16r³(a_i+a_j) − ((a_i−a_j)² + 3r²)²)/(32r³) I
//!   + 3((a_i−a_j)² − r²)²/(32r³) r̂r̂ ]
//! * r ≤ |a_i − a_j| (one sphere inside the other):
//!   μ_ij = I/(6πη max(a_i, a_j))
//! * self block μ_ii = I/(6πη a_i).
//!
//! With d = a_i − a_j, s = a_i + a_j the overlap branch is evaluated in the expanded form
//! I-coefficient s/2 − 9r/32 − 3d²/(16r) − d⁴/(32r³) and r̂r̂-coefficient
//! 3r/32 − 3d²/(16r) + 3d⁴/(32r³) (algebraically identical), which for d = 0 is exactly the
//! thesis eq. 6.10 overlap branch (1 − 9r/32a) I + (3r/32a) r̂r̂ times 1/(6πηa), and has no
//! 0/0 when r → 0 (r = 0 with d = 0 falls into the third branch, whose value is the limit).
//! For a_i = a_j = a the far branch is eq. 6.10: (3a/4r + a³/2r³) I + (3a/4r − 3a³/2r³) r̂r̂
//! times 1/(6πηa). All three branches are continuous at r = a_i + a_j and r = |a_i − a_j|
//! (checked in the tests to 1e-12 relative) and the resulting 3N×3N matrix is symmetric
//! positive definite for every configuration (it is a Gram-type integral over sphere
//! surfaces); the divergence ∇·μ vanishes, so Ermak–McCammon needs no drift correction.
//!
//! # Assumptions
//! Unbounded fluid (no walls or fibres), pairwise (two-body) hydrodynamics, translation only
//! (rotations ignored, as in thesis §6.2), no lubrication.

use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// RPY mobility block μ_ij [m/(N s)] between two *distinct* particles, `r = x_i − x_j` \[m\],
/// radii `a_i`, `a_j` \[m\], `viscosity` η [Pa s] (Zuk et al. 2014, see module docs).
///
/// The self block (i == j) is I/(6πηa_i) and is the caller's job; for two distinct
/// particles at the same centre this returns I/(6πη max(a_i, a_j)).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::brownian::hydro::rpy_block;
/// let (a, eta) = (1.0e-7, 1.0e-3);
/// let r = 3.0 * a;
/// let m = rpy_block(DVec3::new(r, 0.0, 0.0), a, a, eta);
/// let mu0 = 1.0 / (6.0 * std::f64::consts::PI * eta * a);
/// // parallel component: 3a/2r − a³/r³ (thesis eq. 6.10)
/// let expect = mu0 * (1.5 * a / r - a.powi(3) / r.powi(3));
/// assert!((m.x_axis.x - expect).abs() < 1e-12 * mu0);
/// ```
#[must_use]
pub fn rpy_block(r: DVec3, a_i: f64, a_j: f64, viscosity: f64) -> DMat3 {
    let (iso, dyad) = rpy_coefficients(r.length_squared(), a_i, a_j, viscosity);
    let rr = r.length_squared();
    if dyad == 0.0 || rr == 0.0 {
        return DMat3::from_diagonal(DVec3::splat(iso));
    }
    // dyad · r̂r̂ = (dyad / r²) r rᵀ, built symmetric (r_k r_l == r_l r_k bitwise).
    let f = dyad / rr;
    let (x, y, z) = (r.x, r.y, r.z);
    let xy = f * x * y;
    let xz = f * x * z;
    let yz = f * y * z;
    DMat3::from_cols(
        DVec3::new(iso + f * x * x, xy, xz),
        DVec3::new(xy, iso + f * y * y, yz),
        DVec3::new(xz, yz, iso + f * z * z),
    )
}

/// Scalar coefficients (iso, dyad) with μ_ij = iso·I + dyad·r̂r̂, for squared distance `r2`.
#[must_use]
pub(crate) fn rpy_coefficients(r2: f64, a_i: f64, a_j: f64, viscosity: f64) -> (f64, f64) {
    let r = r2.sqrt();
    let s = a_i + a_j;
    let d = a_i - a_j;
    if r > s {
        let q = (a_i * a_i + a_j * a_j) / r2;
        let pre = 1.0 / (8.0 * PI * viscosity * r);
        (pre * (1.0 + q / 3.0), pre * (1.0 - q))
    } else if r <= d.abs() {
        (1.0 / (6.0 * PI * viscosity * a_i.max(a_j)), 0.0)
    } else {
        // r > |d| ≥ 0 here, so r > 0.
        // (a_i a_j) first: keeps μ_ij and μ_ji bitwise equal (products are not associative)
        let pre = 1.0 / (6.0 * PI * viscosity * (a_i * a_j));
        let d2 = d * d;
        let d4 = d2 * d2;
        let r3 = r2 * r;
        let iso = 0.5 * s - 9.0 * r / 32.0 - 3.0 * d2 / (16.0 * r) - d4 / (32.0 * r3);
        let dyad = 3.0 * r / 32.0 - 3.0 * d2 / (16.0 * r) + 3.0 * d4 / (32.0 * r3);
        (pre * iso, pre * dyad)
    }
}

/// Self mobility 1/(6πηa) [m/(N s)].
#[must_use]
pub(crate) fn self_mobility(a: f64, viscosity: f64) -> f64 {
    1.0 / (6.0 * PI * viscosity * a)
}

/// Dense symmetric 3N×3N matrix stored column-major in a plain `Vec<f64>` (element (r, c) at
/// `c * n + r`). Used for the RPY mobility; all products are row-chunk parallel with a fixed
/// summation order, so results are bitwise independent of the rayon thread count.
#[derive(Debug, Clone)]
pub(crate) struct DenseSym {
    pub n: usize,
    pub data: Vec<f64>,
}

/// Rows per parallel task in the matrix-vector products (fixed: determinism does not depend
/// on it, because every output element is summed over columns in increasing order).
const ROW_CHUNK: usize = 96;

impl DenseSym {
    /// Builds the RPY mobility (self blocks on the diagonal), column blocks in parallel.
    pub fn rpy(positions: &[DVec3], radii: &[f64], viscosity: f64) -> Self {
        let np = positions.len();
        let n = 3 * np;
        let mut data = vec![0.0; n * n];
        if n > 0 {
            data.par_chunks_mut(3 * n)
                .enumerate()
                .for_each(|(j, cols)| {
                    for i in 0..np {
                        let blk = if i == j {
                            DMat3::from_diagonal(DVec3::splat(self_mobility(radii[i], viscosity)))
                        } else {
                            rpy_block(positions[i] - positions[j], radii[i], radii[j], viscosity)
                        };
                        for l in 0..3 {
                            let c = blk.col(l);
                            let col = &mut cols[l * n + 3 * i..l * n + 3 * i + 3];
                            col.copy_from_slice(&[c.x, c.y, c.z]);
                        }
                    }
                });
        }
        Self { n, data }
    }

    #[inline]
    pub fn get(&self, r: usize, c: usize) -> f64 {
        self.data[c * self.n + r]
    }

    /// Column `c` as a slice.
    #[inline]
    pub fn col(&self, c: usize) -> &[f64] {
        &self.data[c * self.n..(c + 1) * self.n]
    }

    /// y = A x (A symmetric or not: plain product with the stored matrix).
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let n = self.n;
        matvec_cols(n, |c| &self.data[c * n..(c + 1) * n], x, y, false);
    }

    /// Copy into a faer matrix.
    pub fn to_faer(&self) -> faer::Mat<f64> {
        faer::Mat::from_fn(self.n, self.n, |r, c| self.get(r, c))
    }
}

/// y = A x for an n×n matrix given by its columns (`col(c)` has length n); with `lower_only`
/// the strictly upper part is treated as zero (for the Cholesky factor). Parallel over fixed
/// row chunks; each y_r is accumulated over columns c = 0, 1, … in order, so the result is
/// bitwise independent of the rayon thread count.
pub(crate) fn matvec_cols<'a, F>(n: usize, col_of: F, x: &[f64], y: &mut [f64], lower_only: bool)
where
    F: Fn(usize) -> &'a [f64] + Sync,
{
    debug_assert_eq!(x.len(), n);
    debug_assert_eq!(y.len(), n);
    y.par_chunks_mut(ROW_CHUNK).enumerate().for_each(|(k, ys)| {
        let r0 = k * ROW_CHUNK;
        let r1 = r0 + ys.len();
        ys.fill(0.0);
        // Columns fully below-left of the diagonal (all columns for a full product) in groups
        // of four: y += (a0 x0 + a1 x1) + (a2 x2 + a3 x3). Fixed order → deterministic.
        let c_full = if lower_only { r0 + 1 } else { n };
        let mut c = 0;
        while c + 4 <= c_full {
            let (a0, a1) = (&col_of(c)[r0..r1], &col_of(c + 1)[r0..r1]);
            let (a2, a3) = (&col_of(c + 2)[r0..r1], &col_of(c + 3)[r0..r1]);
            let (x0, x1, x2, x3) = (x[c], x[c + 1], x[c + 2], x[c + 3]);
            for k in 0..ys.len() {
                ys[k] += (a0[k] * x0 + a1[k] * x1) + (a2[k] * x2 + a3[k] * x3);
            }
            c += 4;
        }
        let c_end = if lower_only { r1 } else { n };
        for (c, &xc) in x.iter().enumerate().take(c_end).skip(c) {
            let col = &col_of(c)[r0..r1];
            // for the triangular factor, rows r < c lie above the diagonal: skip them
            let skip = if lower_only { c.saturating_sub(r0) } else { 0 };
            for (yv, av) in ys[skip..].iter_mut().zip(&col[skip..]) {
                *yv += av * xc;
            }
        }
    });
}

/// Dense 3N×3N RPY mobility [m/(N s)] (Zuk et al. 2014 blocks, self blocks I/(6πηa_i)),
/// row/column index 3i + k for particle i and Cartesian component k.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::brownian::hydro::rpy_matrix;
/// let m = rpy_matrix(&[DVec3::ZERO, DVec3::new(3.0, 0.0, 0.0)], &[1.0, 1.0], 1.0);
/// assert_eq!((m.nrows(), m.ncols()), (6, 6));
/// assert_eq!(m[(0, 3)], m[(3, 0)]);
/// ```
#[must_use]
pub fn rpy_matrix(positions: &[DVec3], radii: &[f64], viscosity: f64) -> faer::Mat<f64> {
    assert_eq!(
        positions.len(),
        radii.len(),
        "positions and radii must have equal length"
    );
    DenseSym::rpy(positions, radii, viscosity).to_faer()
}
