//! The `/state` wire format: protobuf message `magsep.ParticleState`.
//!
//! Encoding goes through `#[derive(foxglove::Encode)]`, which also generates the
//! `FileDescriptorSet` embedded in the MCAP schema record. The derive names the message
//! `particlestate.ParticleState` (package = lower-cased type name) and has no option to change
//! it, so [`state_schema`] renames the package to `magsep` in the descriptor. Decoding uses a
//! hand-written [`prost::Message`] with the same field numbers and types; a test checks that it
//! matches the derived descriptor field by field.
//!
//! Arrays are `bytes` fields holding little-endian values, which is compact (the derive would
//! write `Vec<f64>` as a non-packed repeated field) and lossless.

use super::{ParticleFrame, RecordError, STATE_SCHEMA_NAME};
use bytes::Bytes;
use foxglove::prost_types::FileDescriptorSet;
use glam::{DQuat, DVec3};
use prost::Message as _;

/// Package the derive gives `ParticleState` (lower-cased type name).
const DERIVED_PACKAGE: &str = "particlestate";
/// Package written to the embedded descriptor.
const PACKAGE: &str = "magsep";
/// File name of the `ParticleState` descriptor in the embedded `FileDescriptorSet`.
const PROTO_FILE: &str = "magsep/particle_state.proto";

/// Encoder of one `/state` message. Field numbers follow declaration order (1..=10).
#[derive(foxglove::Encode)]
pub(crate) struct ParticleState {
    step: u64,
    time: f64,
    box_edges: Bytes,
    ids: Bytes,
    positions: Bytes,
    orientations: Bytes,
    radii: Bytes,
    half_lengths: Bytes,
    rng_states: Bytes,
    status_json: String,
}

/// Decoder of one `/state` message; must mirror [`ParticleState`].
#[derive(Clone, PartialEq, prost::Message)]
pub(crate) struct ParticleStateWire {
    #[prost(uint64, tag = "1")]
    pub step: u64,
    #[prost(double, tag = "2")]
    pub time: f64,
    #[prost(bytes = "bytes", tag = "3")]
    pub box_edges: Bytes,
    #[prost(bytes = "bytes", tag = "4")]
    pub ids: Bytes,
    #[prost(bytes = "bytes", tag = "5")]
    pub positions: Bytes,
    #[prost(bytes = "bytes", tag = "6")]
    pub orientations: Bytes,
    #[prost(bytes = "bytes", tag = "7")]
    pub radii: Bytes,
    #[prost(bytes = "bytes", tag = "8")]
    pub half_lengths: Bytes,
    #[prost(bytes = "bytes", tag = "9")]
    pub rng_states: Bytes,
    #[prost(string, tag = "10")]
    pub status_json: String,
}

/// Returns `(schema name, encoding, FileDescriptorSet bytes)` of the `/state` channel.
pub(crate) fn state_schema() -> Result<(String, String, Vec<u8>), RecordError> {
    let schema = <ParticleState as foxglove::Encode>::get_schema().ok_or_else(|| {
        RecordError::InvalidInput {
            detail: "foxglove derive produced no schema for ParticleState".into(),
        }
    })?;
    let mut fds =
        FileDescriptorSet::decode(schema.data.as_ref()).map_err(|e| RecordError::Decode {
            detail: format!("derived ParticleState descriptor: {e}"),
        })?;
    for file in &mut fds.file {
        if file.package.as_deref() == Some(DERIVED_PACKAGE) {
            file.package = Some(PACKAGE.into());
            file.name = Some(PROTO_FILE.into());
        }
    }
    Ok((
        STATE_SCHEMA_NAME.to_string(),
        schema.encoding,
        fds.encode_to_vec(),
    ))
}

/// Checks that all per-particle arrays of `frame` have the same length; returns it.
pub(crate) fn particle_count(frame: &ParticleFrame) -> Result<usize, RecordError> {
    let n = frame.ids.len();
    let lens = [
        ("positions", frame.positions.len()),
        ("orientations", frame.orientations.len()),
        ("radii", frame.radii.len()),
        ("half_lengths", frame.half_lengths.len()),
        ("rng_states", frame.rng_states.len()),
    ];
    for (name, len) in lens {
        if len != n {
            return Err(RecordError::InvalidInput {
                detail: format!(
                    "frame at step {}: {name} has {len} entries but ids has {n}",
                    frame.step
                ),
            });
        }
    }
    Ok(n)
}

fn f64s<'a>(values: impl IntoIterator<Item = &'a f64>, cap: usize) -> Bytes {
    let mut out = Vec::with_capacity(cap * 8);
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    Bytes::from(out)
}

fn u64s<'a>(values: impl IntoIterator<Item = &'a u64>, cap: usize) -> Bytes {
    let mut out = Vec::with_capacity(cap * 8);
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    Bytes::from(out)
}

impl ParticleState {
    /// Packs `frame` (whose arrays must have equal lengths, see [`particle_count`]).
    pub(crate) fn from_frame(frame: &ParticleFrame) -> Self {
        let n = frame.ids.len();
        let e = frame.box_edges;
        Self {
            step: frame.step,
            time: frame.time,
            box_edges: f64s(&[e.x, e.y, e.z], 3),
            ids: u64s(&frame.ids, n),
            positions: f64s(frame.positions.iter().flat_map(|p| p.as_ref()), 3 * n),
            orientations: f64s(frame.orientations.iter().flat_map(|q| q.as_ref()), 4 * n),
            radii: f64s(&frame.radii, n),
            half_lengths: f64s(&frame.half_lengths, n),
            rng_states: u64s(frame.rng_states.iter().flatten(), 4 * n),
            status_json: frame.status_json.clone(),
        }
    }
}

/// Splits `bytes` into little-endian 8-byte words, checking the length is `words * 8`.
fn words<'a>(
    bytes: &'a [u8],
    field: &str,
    words: usize,
    what: &str,
) -> Result<impl Iterator<Item = [u8; 8]> + 'a, String> {
    if Some(bytes.len()) != words.checked_mul(8) {
        return Err(format!(
            "field `{field}` has {} bytes, expected {} ({what})",
            bytes.len(),
            words.saturating_mul(8)
        ));
    }
    Ok(bytes.chunks_exact(8).map(|c| {
        let mut w = [0u8; 8];
        w.copy_from_slice(c);
        w
    }))
}

impl ParticleStateWire {
    /// Decodes one `/state` message payload.
    pub(crate) fn decode_payload(data: &[u8]) -> Result<Self, String> {
        Self::decode(data).map_err(|e| format!("protobuf decode failed: {e}"))
    }

    /// Unpacks into a frame, checking every array length against the particle count
    /// (`ids` bytes / 8).
    pub(crate) fn into_frame(self) -> Result<ParticleFrame, String> {
        if !self.ids.len().is_multiple_of(8) {
            return Err(format!(
                "field `ids` has {} bytes, not a multiple of 8",
                self.ids.len()
            ));
        }
        let n = self.ids.len() / 8;
        let per = |k: usize| format!("{k} little-endian 8-byte words per particle, {n} particles");
        let f = f64::from_le_bytes;
        let edges: Vec<f64> = words(&self.box_edges, "box_edges", 3, "3 f64")?
            .map(f)
            .collect();
        let ids = words(&self.ids, "ids", n, &per(1))?
            .map(u64::from_le_bytes)
            .collect();
        let pos: Vec<f64> = words(&self.positions, "positions", 3 * n, &per(3))?
            .map(f)
            .collect();
        let ori: Vec<f64> = words(&self.orientations, "orientations", 4 * n, &per(4))?
            .map(f)
            .collect();
        let radii = words(&self.radii, "radii", n, &per(1))?.map(f).collect();
        let half_lengths = words(&self.half_lengths, "half_lengths", n, &per(1))?
            .map(f)
            .collect();
        let rng: Vec<u64> = words(&self.rng_states, "rng_states", 4 * n, &per(4))?
            .map(u64::from_le_bytes)
            .collect();
        Ok(ParticleFrame {
            step: self.step,
            time: self.time,
            box_edges: DVec3::new(edges[0], edges[1], edges[2]),
            ids,
            positions: pos
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect(),
            orientations: ori
                .chunks_exact(4)
                .map(|c| DQuat::from_xyzw(c[0], c[1], c[2], c[3]))
                .collect(),
            radii,
            half_lengths,
            rng_states: rng
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            status_json: self.status_json,
        })
    }
}
