//! Chebyshev-Gauss-Lobatto collocation in the wall-normal direction: differentiation
//! matrices, Clenshaw-Curtis quadrature weights and the matrix-diagonalisation Helmholtz solver.
//!
//! All matrices act on values at the ascending levels `z_k` of [`ChannelGrid`] and are scaled
//! to physical units (derivatives in 1/m, 1/m²). They are dense, row-major `nz × nz`.
//!
//! **Matrix diagonalisation** (Haldenwang, Labrosse, Abboudi & Deville 1984, J. Comput.
//! Phys. 55): the interior block `D2_II` of the second-derivative matrix (rows and columns of
//! the `nz − 2` interior levels) is diagonalised once, `D2_II = P Λ P⁻¹`, with real negative
//! eigenvalues. A Dirichlet problem `(a + b k² − b D2) f = r` at the interior levels, with the
//! wall values `f_0`, `f_N` given, becomes `f_I = P (a + b k² − b Λ)⁻¹ P⁻¹ (r_I + b D2_I0 f_0 +
//! b D2_IN f_N)`: two dense mat-vecs and a diagonal scaling, for every wavenumber and every
//! Runge-Kutta stage, with nothing stored per mode.

use super::grid::ChannelGrid;
use faer::Mat;
use faer::linalg::solvers::DenseSolveCore;
use num_complex::Complex64 as C;
use std::f64::consts::PI;

/// Dense row-major matrix-vector product on complex data with a real matrix, `y = A x`.
#[inline]
pub(crate) fn matvec_c(a: &[f64], n_cols: usize, x: &[C], y: &mut [C]) {
    for (row, yr) in a.chunks_exact(n_cols).zip(y.iter_mut()) {
        *yr = row_dot_c(row, &x[..n_cols]);
    }
}

/// One row of a real matrix applied to complex data. Four independent partial sums per
/// component (fixed order, so bit-reproducible) let the products pipeline.
#[inline]
pub(crate) fn row_dot_c(row: &[f64], x: &[C]) -> C {
    let n = row.len().min(x.len());
    let (row, x) = (&row[..n], &x[..n]);
    let mut re = [0.0f64; 4];
    let mut im = [0.0f64; 4];
    let (rc, rr) = row.split_at(n - n % 4);
    let (xc, xr) = x.split_at(n - n % 4);
    for (a, b) in rc.chunks_exact(4).zip(xc.chunks_exact(4)) {
        for l in 0..4 {
            re[l] += a[l] * b[l].re;
            im[l] += a[l] * b[l].im;
        }
    }
    for (a, b) in rr.iter().zip(xr) {
        re[0] += a * b.re;
        im[0] += a * b.im;
    }
    C::new(
        (re[0] + re[1]) + (re[2] + re[3]),
        (im[0] + im[1]) + (im[2] + im[3]),
    )
}

/// Reference coordinates `ξ_k = −cos(π k/N)` of the levels, in the symmetric sine form.
fn xi_levels(nz: usize) -> Vec<f64> {
    let n = (nz - 1) as f64;
    (0..nz)
        .map(|k| (PI * (2.0 * k as f64 - n) / (2.0 * n)).sin())
        .collect()
}

/// First-derivative collocation matrix on the levels of `grid` \[1/m\] (row-major `nz × nz`).
///
/// Off-diagonal entries from the barycentric formula, diagonal entries by the negative-sum
/// trick (exact derivative of constants).
pub fn diff_matrix(grid: &ChannelGrid) -> Vec<f64> {
    let nz = grid.nz;
    let x = xi_levels(nz);
    let c = |k: usize| if k == 0 || k == nz - 1 { 2.0 } else { 1.0 };
    let scale = 2.0 / grid.height;
    let mut d = vec![0.0; nz * nz];
    for i in 0..nz {
        let mut sum = 0.0;
        for j in 0..nz {
            if i != j {
                let sign = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
                let v = c(i) / c(j) * sign / (x[i] - x[j]);
                d[i * nz + j] = v * scale;
                sum += v;
            }
        }
        d[i * nz + i] = -sum * scale;
    }
    d
}

/// Product of two square row-major matrices.
pub(crate) fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for k in 0..n {
            let aik = a[i * n + k];
            for j in 0..n {
                c[i * n + j] += aik * b[k * n + j];
            }
        }
    }
    c
}

/// Clenshaw-Curtis quadrature weights \[m\] at the levels of `grid`: `Σ_k w_k f(z_k)` integrates
/// polynomials of degree ≤ `nz − 1` over `0 ≤ z ≤ height` exactly (up to rounding).
///
/// ```
/// use magsep_systems::fluid::channel::{cheb::clenshaw_curtis_weights, grid::ChannelGrid};
/// let g = ChannelGrid::new([4, 4, 9], [1.0, 1.0, 2.0]).unwrap();
/// let w = clenshaw_curtis_weights(&g);
/// let int: f64 = (0..9).map(|k| w[k] * g.z(k).powi(3)).sum();
/// assert!((int - 4.0).abs() < 1e-13);
/// ```
pub fn clenshaw_curtis_weights(grid: &ChannelGrid) -> Vec<f64> {
    grid.z_quadrature_weights()
}

/// Why the wall-normal operators could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChebError {
    /// The eigendecomposition failed or produced complex/non-negative eigenvalues.
    #[error("the interior second-derivative matrix could not be diagonalised: {0}")]
    Eigen(String),
}

/// The diagonalised interior block of the second-derivative matrix, for Dirichlet Helmholtz
/// solves `(a + b k² − b ∂²_z) f = r`.
#[derive(Debug, Clone)]
pub struct HelmholtzDiag {
    /// Interior size `nz − 2`.
    m: usize,
    /// Eigenvectors (row-major `m × m`).
    p: Vec<f64>,
    /// Their inverse (row-major `m × m`).
    pinv: Vec<f64>,
    /// Eigenvalues of `D2_II` \[1/m²\] (negative).
    lam: Vec<f64>,
    /// Column of D2 at the bottom wall, interior rows.
    col0: Vec<f64>,
    /// Column of D2 at the top wall, interior rows.
    col_n: Vec<f64>,
}

impl HelmholtzDiag {
    /// Diagonalises the interior block of `d2` (row-major `nz × nz`).
    pub fn new(d2: &[f64], nz: usize) -> Result<Self, ChebError> {
        let m = nz - 2;
        let a = Mat::<f64>::from_fn(m, m, |i, j| d2[(i + 1) * nz + j + 1]);
        let eig = a.eigen().map_err(|e| ChebError::Eigen(format!("{e:?}")))?;
        let s = eig.S().column_vector();
        let u = eig.U();
        let scale = d2.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let mut lam = Vec::with_capacity(m);
        for i in 0..m {
            let l = s[i];
            if l.re.is_nan() || l.re >= 0.0 || l.im.abs() > 1e-8 * scale {
                return Err(ChebError::Eigen(format!(
                    "eigenvalue {l} is not real negative"
                )));
            }
            lam.push(l.re);
        }
        let mut p = vec![0.0; m * m];
        for j in 0..m {
            // normalise each eigenvector to unit max-norm with a real phase
            let (mut big, mut phase) = (0.0, C::new(1.0, 0.0));
            for i in 0..m {
                let z = u[(i, j)];
                if z.norm() > big {
                    big = z.norm();
                    phase = z / z.norm();
                }
            }
            if big.is_nan() || big <= 0.0 {
                return Err(ChebError::Eigen("zero eigenvector".into()));
            }
            for i in 0..m {
                let z = u[(i, j)] / phase / big;
                if z.im.abs() > 1e-8 {
                    return Err(ChebError::Eigen("complex eigenvector".into()));
                }
                p[i * m + j] = z.re;
            }
        }
        let pm = Mat::<f64>::from_fn(m, m, |i, j| p[i * m + j]);
        let inv = pm.partial_piv_lu().inverse();
        let mut pinv = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                pinv[i * m + j] = inv[(i, j)];
            }
        }
        if pinv.iter().any(|v| !v.is_finite()) {
            return Err(ChebError::Eigen("singular eigenvector matrix".into()));
        }
        let col0 = (0..m).map(|i| d2[(i + 1) * nz]).collect();
        let col_n = (0..m).map(|i| d2[(i + 1) * nz + nz - 1]).collect();
        Ok(Self {
            m,
            p,
            pinv,
            lam,
            col0,
            col_n,
        })
    }

    /// Interior size `nz − 2`.
    pub fn interior(&self) -> usize {
        self.m
    }

    /// Eigenvalues of the interior second-derivative block \[1/m²\].
    pub fn eigenvalues(&self) -> &[f64] {
        &self.lam
    }

    /// Solves `(a + b k2 − b ∂²_z) f = r` at the interior levels with wall values `f0` (z = 0)
    /// and `f_n` (z = height). `r` and `out` are full columns of length `nz`: `r`'s wall
    /// entries are ignored, `out`'s are set to the wall values. `tmp` needs `2 (nz − 2)` slots.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        a: f64,
        b: f64,
        k2: f64,
        r: &[C],
        f0: C,
        f_n: C,
        out: &mut [C],
        tmp: &mut [C],
    ) {
        let m = self.m;
        let (t1, t2) = tmp.split_at_mut(m);
        for i in 0..m {
            t1[i] = r[i + 1] + (f0 * self.col0[i] + f_n * self.col_n[i]) * b;
        }
        matvec_c(&self.pinv, m, &t1[..m], &mut t2[..m]);
        for (t, l) in t2[..m].iter_mut().zip(&self.lam) {
            *t /= a + b * k2 - b * l;
        }
        matvec_c(&self.p, m, &t2[..m], &mut out[1..m + 1]);
        out[0] = f0;
        out[m + 1] = f_n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_quadrature_and_helmholtz_are_exact_for_polynomials() {
        let g = ChannelGrid::new([4, 4, 17], [1.0, 1.0, 0.3]).unwrap();
        let nz = g.nz;
        let z = g.z_levels();
        let d = diff_matrix(&g);
        let d2 = matmul(&d, &d, nz);
        let f: Vec<C> = z.iter().map(|z| C::new(z.powi(5), -z * z)).collect();
        let mut df = vec![C::new(0.0, 0.0); nz];
        matvec_c(&d2, nz, &f, &mut df);
        for k in 0..nz {
            let ex = C::new(20.0 * z[k].powi(3), -2.0);
            assert!((df[k] - ex).norm() < 1e-9, "{k} {} {}", df[k], ex);
        }
        let w = clenshaw_curtis_weights(&g);
        let int: f64 = (0..nz).map(|k| w[k] * z[k].powi(8)).sum();
        assert!((int - 0.3f64.powi(9) / 9.0).abs() < 1e-16);
        // Helmholtz: (2 + 3·4 − 3 ∂²) f with f = z^3 + 1
        let h = HelmholtzDiag::new(&d2, nz).unwrap();
        let (a, b, k2) = (2.0, 3.0, 4.0);
        let r: Vec<C> = z
            .iter()
            .map(|z| C::new((a + b * k2) * (z.powi(3) + 1.0) - b * 6.0 * z, 0.0))
            .collect();
        let mut out = vec![C::new(0.0, 0.0); nz];
        let mut tmp = vec![C::new(0.0, 0.0); 2 * nz];
        let top = C::new(0.3f64.powi(3) + 1.0, 0.0);
        h.solve(a, b, k2, &r, C::new(1.0, 0.0), top, &mut out, &mut tmp);
        for k in 0..nz {
            assert!((out[k].re - z[k].powi(3) - 1.0).abs() < 1e-12, "{k}");
        }
    }
}
