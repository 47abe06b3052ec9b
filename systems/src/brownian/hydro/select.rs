//! Method selection (`auto`) and the covariance-accuracy measure used for cost/accuracy
//! charts: ‖B Bᵀ − μ‖_F / ‖μ‖_F for the factor B that a [`Mobility`] actually applies.

use super::{HydroError, Mobility, MobilityMethod};

/// Relative covariance error ‖B Bᵀ − μ‖_F / ‖μ‖_F of the factor used by `mob`, against the
/// exact mobility `exact` (e.g. from [`rpy_matrix`](super::rpy::rpy_matrix)); 0 up to rounding for Cholesky. For a
/// cost/accuracy chart. O(N³) (dense product); for Krylov also 3N noise evaluations.
pub fn covariance_error(mob: &Mobility, exact: &faer::Mat<f64>) -> Result<f64, HydroError> {
    if mob.method() == MobilityMethod::FreeDraining {
        let mut num = 0.0;
        let mut den = 0.0;
        for c in 0..exact.ncols() {
            for r in 0..exact.nrows() {
                let e = exact[(r, c)];
                den += e * e;
                if r != c {
                    num += e * e;
                }
            }
        }
        return Ok((num / den).sqrt());
    }
    let b = mob.dense_factor()?;
    let bbt = &b * b.transpose();
    Ok((&bbt - exact).norm_l2() / exact.norm_l2())
}

/// `auto` choice of the mobility method by particle number `n` and the volume fraction
/// `volume_fraction` of the particles' bounding region. Rule: free draining is never chosen
/// automatically; N ≤ 300 → Cholesky (exact, 900×900 factorisation is cheap); otherwise
/// φ < 1e-3 → TEA (dilute: weak HI, TEA's few-% cross-correlation error is negligible and it
/// is O(N²)); else Krylov (accurate to its tolerance at O(m N²)). Returns the method and a
/// one-line reason.
///
/// ```
/// use magsep_systems::brownian::hydro::{auto_method, MobilityMethod};
/// assert_eq!(auto_method(100, 0.1).0, MobilityMethod::Cholesky);
/// assert_eq!(auto_method(1000, 1e-4).0, MobilityMethod::Tea);
/// assert_eq!(auto_method(1000, 0.05).0, MobilityMethod::Krylov);
/// ```
#[must_use]
pub fn auto_method(n: usize, volume_fraction: f64) -> (MobilityMethod, &'static str) {
    if n <= 300 {
        (
            MobilityMethod::Cholesky,
            "N <= 300: exact dense Cholesky of the RPY mobility is cheap",
        )
    } else if volume_fraction < 1e-3 {
        (
            MobilityMethod::Tea,
            "N > 300 and dilute (phi < 1e-3): TEA-HI, O(N^2), weak HI",
        )
    } else {
        (
            MobilityMethod::Krylov,
            "N > 300 and phi >= 1e-3: Krylov square root, O(m N^2)",
        )
    }
}
