//! `[[fibre_packings]]`: fibres taken from the last frame of a packing recording (the fibre
//! filter column of thesis 000's stated open goal: separation efficiency against packing
//! density).
//!
//! ```toml
//! [[fibre_packings]]
//! recording = "recordings/column.mcap"   # a `magsep run --record` of a rod packing
//! offset = [0.0, 0.0, 0.0]               # [m] added to every fibre centre; default 0
//! saturation_magnetisation = 1.7e6       # [A/m] (or magnetisation = [..], as in [[fibres]])
//! ```
//!
//! Every spherocylinder of radius R and cylinder length L becomes a `[[fibres]]` cylinder of
//! radius R on the same axis with the same volume: half length L/2 + 2R/3 (the field kernels
//! know finite circular cylinders only; the caps' volume is kept, their shape is not). The
//! fibres are appended after the explicit `[[fibres]]`, in particle-id order, so placements
//! that name a fibre index count them after those. The path is relative to the working
//! directory. A periodic column is taken as it is recorded (centres wrapped into the box),
//! not replicated.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::SceneError;
use super::fibres::FibreSpec;

/// One `[[fibre_packings]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FibrePackingSpec {
    /// Path of a packing recording (MCAP) whose last complete frame holds the rods.
    pub recording: String,
    /// Translation added to every centre \[m\]. Default: zero.
    #[serde(default)]
    pub offset: [f64; 3],
    /// Fixed magnetisation vector of every fibre [A/m].
    #[serde(default)]
    pub magnetisation: Option<[f64; 3]>,
    /// Saturation magnetisation M_s [A/m]; each fibre's direction by Stoner-Wohlfarth.
    #[serde(default)]
    pub saturation_magnetisation: Option<f64>,
}

/// The fibres of `spec` (entry `index`), or errors with key paths.
pub(super) fn expand(
    index: usize,
    spec: &FibrePackingSpec,
    errors: &mut Vec<SceneError>,
) -> Vec<FibreSpec> {
    let path = format!("fibre_packings[{index}].recording");
    let ok_m = match (spec.magnetisation, spec.saturation_magnetisation) {
        (Some(m), None) => m.iter().all(|x| x.is_finite()),
        (None, Some(ms)) => ms.is_finite() && ms > 0.0,
        _ => false,
    };
    if !ok_m {
        errors.push(SceneError::new(
            format!("fibre_packings[{index}].magnetisation"),
            "give exactly one of magnetisation [A/m] (three finite numbers) or \
             saturation_magnetisation [A/m] (> 0)",
        ));
        return Vec::new();
    }
    // a regular file, size-capped, streamed; errors never quote its bytes (crate::input)
    let last = match crate::input::read_named_recording(std::path::Path::new(&spec.recording)) {
        Ok(r) => r,
        Err(e) => {
            errors.push(SceneError::new(path, e));
            return Vec::new();
        }
    };
    let Some(frame) = last.frame.as_ref() else {
        errors.push(SceneError::new(
            path,
            format!("{} holds no complete frame", spec.recording),
        ));
        return Vec::new();
    };
    let offset = DVec3::from_array(spec.offset);
    if !offset.is_finite() {
        errors.push(SceneError::new(
            format!("fibre_packings[{index}].offset"),
            format!("must be three finite numbers [m], got {:?}", spec.offset),
        ));
    }
    let mut out = Vec::with_capacity(frame.ids.len());
    for i in 0..frame.ids.len() {
        let (r, h) = (frame.radii[i], frame.half_lengths[i]);
        if !(r > 0.0 && h > 0.0 && r.is_finite() && h.is_finite()) {
            errors.push(SceneError::new(
                path,
                format!(
                    "particle {} of {} is not a spherocylinder (radius {r}, half length {h})",
                    frame.ids[i], spec.recording
                ),
            ));
            return Vec::new();
        }
        let centre = frame.positions[i] + offset;
        let axis = frame.orientations[i] * DVec3::Z;
        out.push(FibreSpec::Cylinder {
            radius: r,
            half_length: h + 2.0 * r / 3.0,
            center: centre.to_array(),
            axis: axis.to_array(),
            magnetisation: spec.magnetisation,
            saturation_magnetisation: spec.saturation_magnetisation,
        });
    }
    out
}
