//! Start regions and densities of `[[particles]]` groups, shared by the pipelines that place
//! particles (brownian, particle_fluid and plugin pipelines). SI units.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::FibreSpec;

/// Where a group's particles start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PlacementSpec {
    /// Uniform in an axis-aligned box \[m\].
    Box {
        /// Lower corner \[m\].
        min: [f64; 3],
        /// Upper corner \[m\].
        max: [f64; 3],
    },
    /// Above the `+axis` end face of a fibre (the thesis's TOP region).
    FibreTop {
        /// Fibre index in `[[fibres]]`.
        fibre: usize,
        /// Distance of the nearest centres from the face \[m\]. Range: > particle radius.
        gap: f64,
        /// Height of the slab \[m\]. Range: > 0.
        height: f64,
    },
    /// Around the lateral surface of a fibre (the thesis's SIDE region).
    FibreSide {
        /// Fibre index in `[[fibres]]`.
        fibre: usize,
        /// Distance of the nearest centres from the surface \[m\]. Range: > particle radius.
        gap: f64,
        /// Thickness of the annulus \[m\]. Range: > 0.
        thickness: f64,
    },
    /// Explicit centres \[m\] (one per particle).
    Points {
        /// Centres \[m\].
        positions: Vec<[f64; 3]>,
    },
    /// Density-separation injection (particle_fluid; thesis 002 §2.5.3): particles denser than
    /// the liquid start in the `heavy` height band, lighter ones in the `light` band, except a
    /// fraction `impurity` of each that starts in the other band; uniform over the container's
    /// x and y, without overlap.
    Injection {
        /// [z_min, z_max] of the heavy particles' band \[m\].
        heavy: [f64; 2],
        /// [z_min, z_max] of the light particles' band \[m\].
        light: [f64; 2],
        /// Imp: fraction of each kind in the wrong band (0: pre-separated, 0.5: random).
        impurity: f64,
    },
}

fn fibre_dims(fibres: &[FibreSpec], k: usize) -> Option<(f64, f64)> {
    fibres.get(k).map(|f| {
        let FibreSpec::Cylinder {
            radius,
            half_length,
            ..
        } = f;
        (*radius, *half_length)
    })
}

impl PlacementSpec {
    /// Volume of the start region \[m³\] the particles can occupy (the weight of a group in
    /// volume-weighted averages; `None` for explicit points): a box's volume less the parts
    /// of the fibres inside it (`scene::box_region` gives the method and its accuracy).
    pub fn volume(&self, fibres: &[FibreSpec]) -> Option<f64> {
        use std::f64::consts::PI;
        match self {
            Self::Box { min, max } => Some(super::box_region::box_volume_outside_fibres(
                DVec3::from_array(*min),
                DVec3::from_array(*max),
                fibres,
            )),
            Self::FibreTop { fibre, height, .. } => {
                fibre_dims(fibres, *fibre).map(|(r, _)| PI * r * r * height)
            }
            Self::FibreSide {
                fibre,
                gap,
                thickness,
            } => fibre_dims(fibres, *fibre).map(|(r, h)| {
                let (r0, r1) = (r + gap, r + gap + thickness);
                PI * (r1 * r1 - r0 * r0) * 2.0 * h
            }),
            Self::Points { .. } | Self::Injection { .. } => None,
        }
    }
}

/// Density of the particles of a group: one value or evenly spaced ratios ρ_p/ρ_f.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DensityRatios {
    /// Smallest ρ_p/ρ_f. Range > 0.
    pub min: f64,
    /// Largest ρ_p/ρ_f. Range >= min.
    pub max: f64,
    /// Number of groups (particle k of the group gets group k mod `groups`). Range >= 1.
    pub groups: u32,
}

impl DensityRatios {
    /// ρ_p/ρ_f of group `k`.
    pub fn ratio(&self, k: u32) -> f64 {
        if self.groups <= 1 {
            self.min
        } else {
            self.min + (self.max - self.min) * f64::from(k) / f64::from(self.groups - 1)
        }
    }
}

/// An error at `{path}.positions[j]` for the first pair of explicit centres (of spheres of
/// `radius` \[m\]) that would start overlapping (see [`first_overlap`]).
pub fn check_overlap(
    path: &str,
    positions: &[[f64; 3]],
    radius: f64,
    errors: &mut Vec<super::SceneError>,
) {
    if let Some((a, b)) = first_overlap(positions, radius) {
        errors.push(super::SceneError::new(
            format!("{path}.positions[{b}]"),
            format!("overlaps positions[{a}]: centres closer than a diameter"),
        ));
    }
}

/// The first pair (i < j, by j then i) of explicit centres closer than `2 radius` \[m\]: two
/// spheres that would start overlapping. A sweep along x after sorting, O(n log n) for
/// spread points.
pub fn first_overlap(positions: &[[f64; 3]], radius: f64) -> Option<(usize, usize)> {
    let reach = 2.0 * radius;
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_by(|&a, &b| positions[a][0].total_cmp(&positions[b][0]));
    let mut found: Option<(usize, usize)> = None;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            let d = DVec3::from_array(positions[b]) - DVec3::from_array(positions[a]);
            if d.x > reach {
                break;
            }
            if d.length() < reach {
                let pair = (a.min(b), a.max(b));
                if found.is_none_or(|f| (pair.1, pair.0) < (f.1, f.0)) {
                    found = Some(pair);
                }
            }
        }
    }
    found
}
