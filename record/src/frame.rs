//! Data exchanged with recordings: one frame of particle state, the run's metadata, and what
//! the scene draws besides the particles. Lengths in metres, time in seconds.

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Lossless state of all particles at one step (the `/state` channel). Arrays are in
/// `ParticleId` order and all have one entry per particle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParticleFrame {
    /// Schedule step (a compression step for packing).
    pub step: u64,
    /// Simulated time = step * dt \[s\] (0 for packing).
    pub time: f64,
    /// Edges of the periodic box \[m\].
    pub box_edges: DVec3,
    /// `ParticleId`s.
    pub ids: Vec<u64>,
    /// Centres \[m\].
    pub positions: Vec<DVec3>,
    /// Orientations (body z = symmetry axis).
    pub orientations: Vec<DQuat>,
    /// Radii R \[m\].
    pub radii: Vec<f64>,
    /// Half lengths of the axis segment \[m\] (0 for spheres).
    pub half_lengths: Vec<f64>,
    /// Per-particle xoshiro256++ state words (for bitwise resume).
    pub rng_states: Vec<[u64; 4]>,
    /// Pipeline status (counters, step sizes, RNG of the driver) as a JSON object.
    pub status_json: String,
}

/// A magnetised fibre as drawn in the Foxglove scene (entity `fibres`): a cylinder.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FibreShape {
    /// Centre \[m\].
    pub center: DVec3,
    /// Axis direction (unit).
    pub axis: DVec3,
    /// Radius \[m\].
    pub radius: f64,
    /// Half length \[m\].
    pub half_length: f64,
}

/// A translucent box drawn behind the particles in every scene update (entity `backdrop`),
/// e.g. the slices of a magnet field's colour map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BackdropCube {
    /// Centre \[m\].
    pub center: DVec3,
    /// Edge lengths \[m\].
    pub size: DVec3,
    /// Colour (RGBA, 0..1).
    pub colour: [f32; 4],
}

/// Metadata written once at the start of a recording (MCAP metadata record `magsep`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RecordingMetadata {
    /// The scene file's text, verbatim.
    pub scene_text: String,
    /// Seed of the run.
    pub seed: u64,
    /// magsep version that wrote the file.
    pub version: String,
    /// Pipeline name (`packing`, ...).
    pub pipeline: String,
    /// Resolved schedule: set name -> system names, in run order.
    pub schedule: BTreeMap<String, Vec<String>>,
    /// Time step \[s\] (0 for packing).
    pub dt: f64,
    /// The schedule's plugins and their parameters, in build order (empty when read from a
    /// file written before this field existed).
    #[serde(default)]
    pub plugins: Vec<PluginInfo>,
    /// Metadata that plugins add, key -> value (empty when read from an older file).
    #[serde(default)]
    pub extra: BTreeMap<String, String>,
}

/// A plugin of the run's schedule and its parameters (in [`RecordingMetadata::plugins`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PluginInfo {
    /// Plugin name, e.g. `brownian_forces`.
    pub name: String,
    /// Its parameters as JSON (SI units: lengths in metres, times in seconds, as in the scene
    /// file); `null` when it has none.
    #[serde(default)]
    pub params: serde_json::Value,
}

/// Hard-wall geometry drawn in the scene (entity `walls`), in the coordinates of the box
/// `[0, edges]` of each frame. Its serde form is that of `magsep_components::container::Walls`
/// (`"Cylinder"`, `{"Wedge": {"angle": rad}}`, `"Slab"`, `"Box"`), which
/// [`RecordingWriter::set_walls`](crate::RecordingWriter::set_walls) relies on to accept either.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WallShape {
    /// A cylinder wall of radius `edges.x / 2` about the axis through (edges.x/2, edges.y/2),
    /// along z.
    Cylinder,
    /// A right wedge prism: bottom plane y = 0, back plane x = edges.x, slope plane through the
    /// z axis.
    Wedge {
        /// Acute angle between the bottom and the slope \[rad\].
        angle: f64,
    },
    /// Two walls z = 0 and z = edges.z.
    Slab,
    /// Six walls (drawn as the box outline).
    Box,
}

impl WallShape {
    /// The shape of any value that serialises like a [`WallShape`]; `None` otherwise.
    pub fn from_serialize<W: Serialize>(walls: &W) -> Option<Self> {
        serde_json::to_value(walls)
            .ok()
            .and_then(|v| serde_json::from_value(v).ok())
    }
}
