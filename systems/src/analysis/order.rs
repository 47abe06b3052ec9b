//! Orientational order. Nematic order S (thesis 000, eq. 2.11): the largest eigenvalue of
//! Q = (1/N) sum_i (3/2 u_i u_i^T - 1/2 I). 1 for perfect alignment, about 0.036 for 500
//! random axes (finite-size floor, D-000-16).

use glam::{DMat3, DVec3};

/// Eigenvalues of a symmetric 3x3 matrix, ascending (faer's self-adjoint eigensolver, to
/// round-off; the lower triangle is read). NaN if an entry is not finite. Not a hot path (one
/// call per packing), so no closed-form 3x3 kernel is kept.
///
/// ```
/// use glam::DMat3;
/// use magsep_systems::analysis::symmetric_eigenvalues;
/// let e = symmetric_eigenvalues(DMat3::from_diagonal(glam::DVec3::new(3.0, 1.0, 2.0)));
/// assert_eq!(e, [1.0, 2.0, 3.0]);
/// ```
pub fn symmetric_eigenvalues(m: DMat3) -> [f64; 3] {
    let a = m.to_cols_array_2d();
    if a.iter().flatten().any(|v| !v.is_finite()) {
        return [f64::NAN; 3];
    }
    let mat = faer::Mat::from_fn(3, 3, |r, c| a[c][r]);
    match mat.self_adjoint_eigenvalues(faer::Side::Lower) {
        Ok(ev) if ev.len() == 3 => {
            let mut e = [ev[0], ev[1], ev[2]];
            e.sort_by(f64::total_cmp);
            e
        }
        _ => [f64::NAN; 3],
    }
}

/// Nematic order parameter S of unit axes `axes` (0 for an empty set).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::analysis::nematic_order;
/// assert!((nematic_order(&[DVec3::Z, -DVec3::Z]) - 1.0).abs() < 1e-14);
/// ```
pub fn nematic_order(axes: &[DVec3]) -> f64 {
    if axes.is_empty() {
        return 0.0;
    }
    let mut q = DMat3::ZERO;
    for u in axes {
        q += DMat3::from_cols(u * u.x, u * u.y, u * u.z) * 1.5;
    }
    q = q * (1.0 / axes.len() as f64) - DMat3::IDENTITY * 0.5;
    symmetric_eigenvalues(q)[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::packing::insert::random_orientation;
    use crate::rng::particle_stream;

    #[test]
    fn eigenvalues_of_a_rotated_matrix() {
        let r = DMat3::from_quat(glam::DQuat::from_axis_angle(
            DVec3::new(1.0, -2.0, 0.3).normalize(),
            1.1,
        ));
        let m = r * DMat3::from_diagonal(DVec3::new(-0.5, 0.25, 2.0)) * r.transpose();
        let e = symmetric_eigenvalues(m);
        for (a, b) in e.iter().zip([-0.5, 0.25, 2.0]) {
            assert!((a - b).abs() < 1e-13, "{e:?}");
        }
    }

    #[test]
    fn eigenvalues_of_a_known_matrix() {
        // [[2, 1, 0], [1, 2, 1], [0, 1, 2]]: 2 - sqrt 2, 2, 2 + sqrt 2.
        let m = DMat3::from_cols_array(&[2.0, 1.0, 0.0, 1.0, 2.0, 1.0, 0.0, 1.0, 2.0]);
        let e = symmetric_eigenvalues(m);
        let r2 = 2f64.sqrt();
        for (a, b) in e.iter().zip([2.0 - r2, 2.0, 2.0 + r2]) {
            assert!((a - b).abs() < 1e-14, "{e:?}");
        }
        // Degenerate (isotropic) and non-finite input.
        let iso = symmetric_eigenvalues(DMat3::IDENTITY * 0.5);
        assert!(iso.iter().all(|v| (v - 0.5).abs() < 1e-15), "{iso:?}");
        assert!(
            symmetric_eigenvalues(DMat3::from_diagonal(DVec3::new(f64::NAN, 1.0, 2.0)))[0].is_nan()
        );
    }

    #[test]
    fn random_axes_sit_at_the_finite_size_floor() {
        // D-000-16: <S> ~ 0.036 for N = 500 isotropic axes; check the mean over 40 sets
        let mut rng = particle_stream(5, 0);
        let mut mean = 0.0;
        for _ in 0..40 {
            let axes: Vec<DVec3> = (0..500)
                .map(|_| random_orientation(&mut rng) * DVec3::Z)
                .collect();
            mean += nematic_order(&axes) / 40.0;
        }
        assert!((mean - 0.036).abs() < 0.008, "{mean}");
    }
}
