//! Force on a superparamagnetic point dipole: moment along the local field,
//! `F = ∇(m · B) = |m|(|B|) ∇|B|` (D-000-5; thesis eq. 6.20 with `m ∥ B`).
//!
//! `∇|B| = (∇B)ᵀ B̂`. For an induced moment whose magnitude depends on `|B|` only (Langevin), the
//! force from the free energy is again `|m| ∇|B|`. Where `B = 0` the direction is undefined and
//! the force is zero.

use glam::DVec3;

use super::source::FieldGradient;

pub use magsep_components::brownian::{BOLTZMANN as K_B, MomentModel, langevin};

/// Force [N] on a dipole with moment law `law` (thermal energy `kt` [J], used by the Langevin
/// law) in a field with gradient `g`.
///
/// ```
/// use glam::{DMat3, DVec3};
/// use magsep_systems::field::{FieldGradient, MomentModel, dipole_force};
/// // B = (1 T + 2 T/m · x) x̂: F = m ∂|B|/∂x = 1e-15 A m² · 2 T/m
/// let g = FieldGradient {
///     b: DVec3::X,
///     grad_b: DMat3::from_cols(DVec3::new(2.0, 0.0, 0.0), DVec3::ZERO, DVec3::ZERO),
/// };
/// let f = dipole_force(&g, &MomentModel::Saturated { moment: 1e-15 }, 4.1e-21);
/// assert!((f.x - 2e-15).abs() < 1e-30);
/// ```
pub fn dipole_force(g: &FieldGradient, law: &MomentModel, kt: f64) -> DVec3 {
    grad_abs_b(g)
        .map(|(bm, grad)| grad * law.magnitude(bm, kt))
        .unwrap_or(DVec3::ZERO)
}

/// `(|B|, ∇|B|)` with `∂|B|/∂x_j = B̂ · ∂B/∂x_j`; `None` where B vanishes or is not finite.
pub fn grad_abs_b(g: &FieldGradient) -> Option<(f64, DVec3)> {
    let bmag = g.b.length();
    if bmag == 0.0 || !bmag.is_finite() {
        return None;
    }
    let bhat = g.b / bmag;
    Some((
        bmag,
        DVec3::new(
            bhat.dot(g.grad_b.x_axis),
            bhat.dot(g.grad_b.y_axis),
            bhat.dot(g.grad_b.z_axis),
        ),
    ))
}
