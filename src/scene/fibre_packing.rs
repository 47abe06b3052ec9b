//! `[[fibre_packings]]`: fibres taken from the last frame of a packing recording, or packed on
//! the spot by mechanical contraction to a chosen packing fraction (the fibre filter column of
//! thesis 000's stated open goal: separation efficiency against packing density).
//!
//! ```toml
//! [[fibre_packings]]
//! recording = "recordings/column.mcap"   # a `magsep run --record` of a rod packing
//! offset = [0.0, 0.0, 0.0]               # [m] added to every fibre centre; default 0
//! saturation_magnetisation = 1.7e6       # [A/m] (or magnetisation = [..], as in [[fibres]])
//! ```
//!
//! or, instead of `recording`, a column packed when the scene is read:
//!
//! ```toml
//! [[fibre_packings]]
//! saturation_magnetisation = 1.7e6
//! pack = { count = 200, radius = 25e-6, cylinder_length = 950e-6, column_radius = 500e-6, packing_fraction = 0.15 }
//! ```
//!
//! `pack` puts `count` spherocylinders of radius R and cylinder length L [m] at random in a hard
//! tube of radius `column_radius` [m] (its axis along z, periodic along z) at
//! `initial_packing_fraction` (default 0.01) and compresses the tube's length by the mechanical
//! contraction method until the packing fraction reaches `packing_fraction` (or the packing
//! jams first: the reached value is reported). `seed` defaults to `simulation.seed` as written
//! in the scene, so replicates of a sweep (which set `simulation.seed`) get different packings;
//! the `--seed` flag of `magsep run` does not re-pack. The tube's box is x, y in
//! [0, 2 column_radius], z in [0, height). A packing is computed once per process for the same
//! values (a sweep's points share it). The summary of a run lists each packed column under
//! `fibre_packings` (packing fraction reached, height [m], compression steps, jammed).
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
use super::fibre_pack::PackSpec;
use super::fibres::FibreSpec;

/// One `[[fibre_packings]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FibrePackingSpec {
    /// Path of a packing recording (MCAP) whose last complete frame holds the rods (or `pack`).
    #[serde(default)]
    pub recording: Option<String>,
    /// A column packed when the scene is read (or `recording`).
    #[serde(default)]
    pub pack: Option<PackSpec>,
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

/// Centres \[m\] and unit axes of spherocylinders of radius `r` and half length `h` (of the
/// cylindrical part) as equal-volume fibres.
fn fibres_of(
    spec: &FibrePackingSpec,
    rods: impl Iterator<Item = (DVec3, DVec3, f64, f64)>,
) -> Vec<FibreSpec> {
    let offset = DVec3::from_array(spec.offset);
    rods.map(|(centre, axis, r, h)| FibreSpec::Cylinder {
        radius: r,
        half_length: h + 2.0 * r / 3.0,
        center: (centre + offset).to_array(),
        axis: axis.to_array(),
        magnetisation: spec.magnetisation,
        saturation_magnetisation: spec.saturation_magnetisation,
    })
    .collect()
}

/// The fibres of `spec` (entry `index`; `seed`: the scene's `simulation.seed`) and, for a
/// packed column, its report for the summary; or errors with key paths.
pub(super) fn expand(
    index: usize,
    spec: &FibrePackingSpec,
    seed: u64,
    errors: &mut Vec<SceneError>,
) -> (Vec<FibreSpec>, Option<serde_json::Value>) {
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
    }
    if !DVec3::from_array(spec.offset).is_finite() {
        errors.push(SceneError::new(
            format!("fibre_packings[{index}].offset"),
            format!("must be three finite numbers [m], got {:?}", spec.offset),
        ));
    }
    let recording = match (&spec.recording, &spec.pack) {
        (Some(r), None) => r,
        (None, Some(pack)) => {
            let prefix = format!("fibre_packings[{index}].pack");
            let before = errors.len();
            pack.validate(&prefix, errors);
            if errors.len() > before || !ok_m {
                return (Vec::new(), None);
            }
            return match super::fibre_pack::packed(pack, seed) {
                Ok(c) => {
                    let (r, h) = (pack.radius, 0.5 * pack.cylinder_length);
                    let rods = c.centres.iter().zip(&c.axes).map(|(x, a)| (*x, *a, r, h));
                    (
                        fibres_of(spec, rods),
                        Some(super::fibre_pack::report(index, &c)),
                    )
                }
                Err(e) => {
                    errors.push(SceneError::new(prefix, e));
                    (Vec::new(), None)
                }
            };
        }
        _ => {
            errors.push(SceneError::new(
                format!("fibre_packings[{index}]"),
                "give exactly one of recording (a packing recording's path) or pack (a column \
                 to pack)",
            ));
            return (Vec::new(), None);
        }
    };
    if !ok_m {
        return (Vec::new(), None);
    }
    let path = format!("fibre_packings[{index}].recording");
    // a regular file, size-capped, streamed; errors never quote its bytes (crate::input)
    let last = match crate::input::read_named_recording(std::path::Path::new(recording)) {
        Ok(r) => r,
        Err(e) => {
            errors.push(SceneError::new(path, e));
            return (Vec::new(), None);
        }
    };
    let Some(frame) = last.frame.as_ref() else {
        errors.push(SceneError::new(
            path,
            format!("{recording} holds no complete frame"),
        ));
        return (Vec::new(), None);
    };
    for i in 0..frame.ids.len() {
        let (r, h) = (frame.radii[i], frame.half_lengths[i]);
        if !(r > 0.0 && h > 0.0 && r.is_finite() && h.is_finite()) {
            errors.push(SceneError::new(
                path,
                format!(
                    "particle {} of {recording} is not a spherocylinder (radius {r}, half length {h})",
                    frame.ids[i]
                ),
            ));
            return (Vec::new(), None);
        }
    }
    let rods = (0..frame.ids.len()).map(|i| {
        (
            frame.positions[i],
            frame.orientations[i] * DVec3::Z,
            frame.radii[i],
            frame.half_lengths[i],
        )
    });
    (fibres_of(spec, rods), None)
}
