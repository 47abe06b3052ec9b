//! Krylov (Lanczos) approximation of y = μ^{1/2} w (Ando, Chow, Saad & Skolnick,
//! *J. Chem. Phys.* **137**, 064106 (2012), "Krylov subspace methods for computing
//! hydrodynamic interactions in Brownian dynamics simulations").
//!
//! # Algorithm
//! With v₁ = w/‖w‖, m Lanczos steps give μ V_m = V_m T_m + β_m v_{m+1} e_mᵀ, T_m symmetric
//! tridiagonal (α on the diagonal, β off it), and
//!   y_m = ‖w‖ V_m T_m^{1/2} e₁.
//! T_m^{1/2} e₁ = Z Λ^{1/2} Zᵀ e₁ from the eigen-decomposition T_m = Z Λ Zᵀ (implicit QL with
//! Wilkinson-type shifts, `tridiagonal_eigen`; negative round-off eigenvalues are clamped to
//! 0). Iteration stops when the relative change ‖y_m − y_{m−1}‖/‖y_m‖ < tol (Ando et al.'s
//! criterion; because V is orthonormal this equals ‖c_m − (c_{m−1}, 0)‖/‖c_m‖ for the small
//! coefficient vectors c_m = ‖w‖ T_m^{1/2} e₁), on an invariant subspace (β_m ≈ 0, exact) or
//! when m reaches the dimension. The Lanczos vectors are fully re-orthogonalised (two passes of
//! modified Gram–Schmidt) so the basis stays orthonormal in floating point.
//!
//! # Properties
//! Cost O(m·N'²) with the dense matvec, memory O(m·N'). y is *not* linear in w (the Krylov
//! space depends on w); its covariance approximates μ to ≈ tol. Every step is sequential or
//! thread-count-independent, so results are bitwise reproducible.

use super::HydroError;

/// Result of one Krylov square-root evaluation.
#[derive(Debug, Clone)]
pub(crate) struct KrylovResult {
    pub y: Vec<f64>,
    pub iterations: usize,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// y ≈ A^{1/2} w for SPD A given by `matvec(x, out)` (out = A x).
pub(crate) fn lanczos_sqrt<F>(
    matvec: F,
    w: &[f64],
    tol: f64,
    max_iterations: usize,
) -> Result<KrylovResult, HydroError>
where
    F: Fn(&[f64], &mut [f64]),
{
    let n = w.len();
    let norm_w = dot(w, w).sqrt();
    if n == 0 || norm_w == 0.0 {
        return Ok(KrylovResult {
            y: vec![0.0; n],
            iterations: 0,
        });
    }
    let max_it = max_iterations.max(1).min(n);
    let mut basis: Vec<Vec<f64>> = vec![w.iter().map(|x| x / norm_w).collect()];
    let mut alpha: Vec<f64> = Vec::new();
    let mut beta: Vec<f64> = Vec::new();
    let mut u = vec![0.0; n];
    let mut c_prev: Vec<f64> = Vec::new();
    let mut last_change = f64::INFINITY;
    let mut coeffs: Option<Vec<f64>> = None;
    for k in 0..max_it {
        matvec(&basis[k], &mut u);
        let a_k = dot(&basis[k], &u);
        alpha.push(a_k);
        for (ui, vi) in u.iter_mut().zip(&basis[k]) {
            *ui -= a_k * vi;
        }
        if k > 0 {
            let b_prev = beta[k - 1];
            for (ui, vi) in u.iter_mut().zip(&basis[k - 1]) {
                *ui -= b_prev * vi;
            }
        }
        for _pass in 0..2 {
            for v in &basis {
                let h = dot(v, &u);
                for (ui, vi) in u.iter_mut().zip(v) {
                    *ui -= h * vi;
                }
            }
        }
        let b_k = dot(&u, &u).sqrt();
        let c = sqrt_t_e1(&alpha, &beta)?;
        let c: Vec<f64> = c.into_iter().map(|x| x * norm_w).collect();
        let norm_c = dot(&c, &c).sqrt();
        if k > 0 {
            let mut diff2 = 0.0;
            for (i, ci) in c.iter().enumerate() {
                let p = c_prev.get(i).copied().unwrap_or(0.0);
                diff2 += (ci - p) * (ci - p);
            }
            last_change = diff2.sqrt() / norm_c;
        }
        // Invariant subspace (β_k tiny relative to the matrix scale seen so far): exact.
        let scale = alpha.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
        let exhausted = b_k <= 1e-14 * scale || k + 1 == n;
        if last_change < tol || exhausted {
            coeffs = Some(c);
            break;
        }
        c_prev = c;
        beta.push(b_k);
        basis.push(u.iter().map(|x| x / b_k).collect());
    }
    let Some(c) = coeffs else {
        return Err(HydroError::KrylovNotConverged {
            iterations: max_it,
            residual: last_change,
        });
    };
    let mut y = vec![0.0; n];
    for (v, ci) in basis.iter().zip(&c) {
        for (yi, vi) in y.iter_mut().zip(v) {
            *yi += ci * vi;
        }
    }
    Ok(KrylovResult {
        y,
        iterations: c.len(),
    })
}

/// T^{1/2} e₁ for the symmetric tridiagonal T with diagonal `alpha` (len m) and
/// off-diagonal `beta` (len ≥ m − 1; only the first m − 1 are used).
pub(crate) fn sqrt_t_e1(alpha: &[f64], beta: &[f64]) -> Result<Vec<f64>, HydroError> {
    let m = alpha.len();
    let mut d = alpha.to_vec();
    let mut e = vec![0.0; m];
    e[..m - 1].copy_from_slice(&beta[..m - 1]);
    let z = tridiagonal_eigen(&mut d, &mut e)?;
    let mut c = vec![0.0; m];
    for (k, &lam) in d.iter().enumerate() {
        let f = lam.max(0.0).sqrt() * z[k]; // z[0 * m + k] = Z_{0k}
        for (i, ci) in c.iter_mut().enumerate() {
            *ci += z[i * m + k] * f;
        }
    }
    Ok(c)
}

/// Eigen-decomposition of a symmetric tridiagonal matrix by the implicit QL method.
///
/// On entry `d` holds the diagonal and `e[i]` the element (i, i+1), `e[m−1]` ignored. On exit
/// `d` holds the eigenvalues (unordered) and the returned row-major m×m matrix Z has the
/// eigenvectors as columns (T = Z diag(d) Zᵀ).
pub(crate) fn tridiagonal_eigen(d: &mut [f64], e: &mut [f64]) -> Result<Vec<f64>, HydroError> {
    let m = d.len();
    let mut z = vec![0.0; m * m];
    for i in 0..m {
        z[i * m + i] = 1.0;
    }
    if m == 0 {
        return Ok(z);
    }
    e[m - 1] = 0.0;
    for l in 0..m {
        let mut iter = 0;
        loop {
            // find a negligible off-diagonal element e[mm], splitting the matrix
            let mut mm = l;
            while mm + 1 < m {
                let dd = d[mm].abs() + d[mm + 1].abs();
                if e[mm].abs() <= f64::EPSILON * dd {
                    break;
                }
                mm += 1;
            }
            if mm == l {
                break;
            }
            iter += 1;
            if iter > 60 {
                return Err(HydroError::EigenNotConverged { size: m });
            }
            let mut g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let mut r = g.hypot(1.0);
            g = d[mm] - d[l] + e[l] / (g + r.copysign(g));
            let (mut s, mut c, mut p) = (1.0_f64, 1.0_f64, 0.0_f64);
            let mut underflow = false;
            let mut i = mm;
            while i > l {
                i -= 1;
                let f = s * e[i];
                let b = c * e[i];
                r = f.hypot(g);
                e[i + 1] = r;
                if r == 0.0 {
                    d[i + 1] -= p;
                    e[mm] = 0.0;
                    underflow = true;
                    break;
                }
                s = f / r;
                c = g / r;
                g = d[i + 1] - p;
                r = (d[i] - g) * s + 2.0 * c * b;
                p = s * r;
                d[i + 1] = g + p;
                g = c * r - b;
                for k in 0..m {
                    let zi1 = z[k * m + i + 1];
                    let zi = z[k * m + i];
                    z[k * m + i + 1] = s * zi + c * zi1;
                    z[k * m + i] = c * zi - s * zi1;
                }
            }
            if underflow {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[mm] = 0.0;
        }
    }
    Ok(z)
}
