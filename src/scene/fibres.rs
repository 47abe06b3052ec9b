//! `[[fibres]]` and `[external_field]`: magnetised fibres and the applied field (SI units).
//!
//! ```toml
//! [external_field]
//! flux_density = [1.0, 0.0, 0.0]      # B_ext [T]
//! field_tolerance = 1e-10             # relative accuracy of each fibre's field; default 1e-15
//!
//! [[fibres]]
//! kind = "cylinder"
//! radius = 300e-6                     # [m]
//! half_length = 6e-3                  # [m] (half of the fibre's length)
//! center = [0.0, 0.0, 0.0]            # [m]
//! axis = [0.0, 0.0, 1.0]              # direction (normalised)
//! saturation_magnetisation = 985e3    # [A/m]: direction by Stoner-Wohlfarth from B_ext
//! # or: magnetisation = [0.0, 0.0, 985e3]   # [A/m], fixed vector
//! ```

use glam::DVec3;
use magsep_systems::field::{CylinderSource, EXACT, demag::stoner_wohlfarth_magnetisation};
use serde::{Deserialize, Serialize};

use super::SceneError;
use super::checks::{LENGTH_RANGE, num, within};

/// `[external_field]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalFieldSection {
    /// Uniform applied flux density B_ext \[T\]. Default: zero.
    #[serde(default)]
    pub flux_density: [f64; 3],
    /// Relative accuracy asked of every fibre's field: far fibres use a multipole expansion
    /// whose error bound is within it. Default 1e-15 (exact). Range: [1e-15, 0.1].
    #[serde(default)]
    pub field_tolerance: Option<f64>,
}

/// One `[[fibres]]` entry, tagged by `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FibreSpec {
    /// `"cylinder"`: a uniformly magnetised finite circular cylinder.
    Cylinder {
        /// Radius R \[m\]. Range: > 0.
        radius: f64,
        /// Half length L \[m\]. Range: > 0.
        half_length: f64,
        /// Centre \[m\]. Default: origin.
        #[serde(default)]
        center: [f64; 3],
        /// Axis direction (any length > 0).
        axis: [f64; 3],
        /// Fixed magnetisation vector M [A/m].
        #[serde(default)]
        magnetisation: Option<[f64; 3]>,
        /// Saturation magnetisation M_s [A/m]; the direction follows from the external field
        /// by Stoner-Wohlfarth with the cylinder's demagnetising factors.
        #[serde(default)]
        saturation_magnetisation: Option<f64>,
    },
}

impl FibreSpec {
    /// The field source, with the magnetisation resolved against `b_ext` \[T\].
    pub fn source(&self, b_ext: DVec3) -> CylinderSource {
        let FibreSpec::Cylinder {
            radius,
            half_length,
            center,
            axis,
            magnetisation,
            saturation_magnetisation,
        } = self;
        let axis = DVec3::from_array(*axis);
        let m = match (magnetisation, saturation_magnetisation) {
            (Some(m), _) => DVec3::from_array(*m),
            (None, Some(ms)) => {
                stoner_wohlfarth_magnetisation(axis, *radius, *half_length, *ms, b_ext)
            }
            (None, None) => DVec3::ZERO,
        };
        CylinderSource::new(DVec3::from_array(*center), axis, *radius, *half_length, m)
    }
}

impl ExternalFieldSection {
    /// B_ext \[T\].
    pub fn flux_density(&self) -> DVec3 {
        DVec3::from_array(self.flux_density)
    }
    /// The tolerance (default [`EXACT`]).
    pub fn tolerance(&self) -> f64 {
        self.field_tolerance.unwrap_or(EXACT)
    }
}

/// Largest external flux density component accepted \[T\].
pub const MAX_FLUX_DENSITY: f64 = 100.0;
/// Largest fibre magnetisation accepted \[A/m\] (iron saturates at 1.7e6 A/m).
pub const MAX_MAGNETISATION: f64 = 1e7;

/// Semantic checks of the fibres and the external field.
pub fn validate_fibres(
    fibres: &[(usize, FibreSpec)],
    external: Option<&ExternalFieldSection>,
    errors: &mut Vec<SceneError>,
) {
    if let Some(e) = external {
        for (k, b) in e.flux_density.iter().enumerate() {
            let path = format!("external_field.flux_density[{k}]");
            within(
                errors,
                &path,
                *b,
                -MAX_FLUX_DENSITY,
                MAX_FLUX_DENSITY,
                "[T]",
            );
        }
        if let Some(t) = e.field_tolerance
            && !(t.is_finite() && (1e-15..=0.1).contains(&t))
        {
            errors.push(SceneError::new(
                "external_field.field_tolerance",
                format!("must be in [1e-15, 0.1], got {t}"),
            ));
        }
    }
    for (i, f) in fibres {
        let p = format!("fibres[{i}]");
        let FibreSpec::Cylinder {
            radius,
            half_length,
            center,
            axis,
            magnetisation,
            saturation_magnetisation,
        } = f;
        for (key, v) in [("radius", radius), ("half_length", half_length)] {
            within(
                errors,
                &format!("{p}.{key}"),
                *v,
                LENGTH_RANGE.0,
                LENGTH_RANGE.1,
                "[m]",
            );
        }
        for (k, c) in center.iter().enumerate() {
            let (path, hi) = (format!("{p}.center[{k}]"), LENGTH_RANGE.1);
            within(errors, &path, *c, -hi, hi, "[m]");
        }
        let a = DVec3::from_array(*axis);
        if !(a.is_finite() && a.length() > 0.0) {
            errors.push(SceneError::new(
                format!("{p}.axis"),
                format!("must be a finite non-zero vector, got {axis:?}"),
            ));
        }
        match (magnetisation, saturation_magnetisation) {
            (Some(_), Some(_)) => errors.push(SceneError::new(
                format!("{p}.magnetisation"),
                "give either magnetisation or saturation_magnetisation, not both",
            )),
            (None, None) => errors.push(SceneError::new(
                format!("{p}.magnetisation"),
                "missing: give magnetisation [A/m] (a vector) or saturation_magnetisation [A/m]",
            )),
            (Some(m), None) if !m.iter().all(|c| c.abs() <= MAX_MAGNETISATION) => {
                errors.push(SceneError::new(
                    format!("{p}.magnetisation"),
                    format!(
                        "must be three numbers in [-{}, {}] [A/m], got {m:?}",
                        num(MAX_MAGNETISATION),
                        num(MAX_MAGNETISATION)
                    ),
                ))
            }
            (None, Some(ms)) if !(ms.is_finite() && *ms > 0.0 && *ms <= MAX_MAGNETISATION) => {
                errors.push(SceneError::new(
                    format!("{p}.saturation_magnetisation"),
                    format!("must be in (0, {}] [A/m], got {ms}", num(MAX_MAGNETISATION)),
                ))
            }
            (None, Some(_)) if external.is_none_or(|e| e.flux_density == [0.0; 3]) => {
                errors.push(SceneError::new(
                    format!("{p}.saturation_magnetisation"),
                    "needs a non-zero [external_field] flux_density (it sets the direction)",
                ))
            }
            _ => {}
        }
    }
}
