//! Force on a superparamagnetic point dipole: moment along the local field,
//! `F = ∇(m · B) = |m|(|B|) ∇|B|` (spec 1.10; thesis eq. 6.20 with `m ∥ B`).
//!
//! `∇|B| = (∇B)ᵀ B̂`. For an induced moment whose magnitude depends on `|B|` only (Langevin), the
//! force from the free energy is again `|m| ∇|B|`. Where `B = 0` the direction is undefined and
//! the force is zero.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::source::FieldGradient;

/// Boltzmann constant [J/K].
pub const K_B: f64 = magsep_components::brownian::BOLTZMANN;

/// How a particle's moment magnitude depends on the field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MomentLaw {
    /// Saturated: `|m| = moment` [A m²] (the thesis's ch. 6 particles at ~1 T).
    Saturated {
        /// Moment [A m²].
        moment: f64,
    },
    /// Langevin: `|m| = moment · (coth x - 1/x)`, `x = moment |B| / (k_B T)` (thesis eq. 6.22).
    Langevin {
        /// Saturation moment [A m²].
        moment: f64,
        /// Temperature [K].
        temperature: f64,
    },
}

impl MomentLaw {
    /// `|m|` [A m²] at flux density magnitude `b` [T].
    pub fn magnitude(&self, b: f64) -> f64 {
        match *self {
            Self::Saturated { moment } => moment,
            Self::Langevin {
                moment,
                temperature,
            } => moment * langevin(moment * b / (K_B * temperature)),
        }
    }
}

pub use magsep_components::brownian::langevin;

/// Force [N] on a dipole with moment law `law` in a field with gradient `g`.
///
/// ```
/// use glam::{DMat3, DVec3};
/// use magsep_systems::field::{FieldGradient, MomentLaw, dipole_force};
/// // B = (1 T + 2 T/m · x) x̂: F = m ∂|B|/∂x = 1e-15 A m² · 2 T/m
/// let g = FieldGradient {
///     b: DVec3::X,
///     grad_b: DMat3::from_cols(DVec3::new(2.0, 0.0, 0.0), DVec3::ZERO, DVec3::ZERO),
/// };
/// let f = dipole_force(&g, &MomentLaw::Saturated { moment: 1e-15 });
/// assert!((f.x - 2e-15).abs() < 1e-30);
/// ```
pub fn dipole_force(g: &FieldGradient, law: &MomentLaw) -> DVec3 {
    grad_abs_b(g)
        .map(|(bm, grad)| grad * law.magnitude(bm))
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
