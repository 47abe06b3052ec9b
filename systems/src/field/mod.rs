//! Magnetic fields of magnetised fibres: the exact field, gradient and force of uniformly
//! magnetised finite cylinders (thesis 000, ch. 5), demagnetising factors and the
//! Stoner-Wohlfarth magnetisation direction (D-000-4 in docs/references.md).
//!
//! * [`batch`]: the closed form on four points at a time (vector lanes).
//! * [`cel`]: Bulirsch's generalised complete elliptic integral (fused for the cylinder).
//! * [`cylinder`]: the body-frame kernel (closed form, near-axis expansion).
//! * [`multipole`]: the exterior multipole expansion with its error bound.
//! * [`source`]: a cylinder with any pose, superposition, [`MU0`].
//! * [`force`]: the force on a superparamagnetic dipole.
//! * [`demag`]: demagnetising factors and Stoner-Wohlfarth.
//! * [`real`]: `f64` or [`Dual3`] numbers (exact gradients by forward-mode differentiation).
//!
//! SI units: lengths \[m\], magnetisation and H [A/m], B \[T\], gradients [T/m], forces \[N\].
//!
//! ```
//! use glam::DVec3;
//! use magsep_systems::field::{CylinderSource, EXACT, MU0};
//! // a long fibre magnetised along its axis: B ≈ μ0 M inside, near the middle
//! let m = 1e6;
//! let fibre = CylinderSource::new(DVec3::ZERO, DVec3::Z, 1e-4, 1.0, DVec3::Z * m);
//! let f = fibre.field(DVec3::new(3e-5, 0.0, 0.0), EXACT);
//! assert!((f.b.z - MU0 * m).abs() < 1e-6 * MU0 * m);
//! ```

pub mod batch;
pub mod cel;
pub mod cylinder;
pub mod demag;
pub mod force;
pub mod multipole;
pub mod real;
pub mod source;

pub use force::{MomentModel, dipole_force};
pub use real::{Dual3, Real};
pub use source::{
    CylinderSource, EXACT, FieldGradient, FieldValue, MU0, total_field, total_field_batch,
    total_field_gradient,
};
