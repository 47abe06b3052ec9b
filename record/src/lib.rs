//! # magsep-record
//!
//! The MCAP codec of magsep recordings: writing simulation runs to MCAP files, and reading them
//! back. No ECS types: the simulation side (`magsep-plugins`) re-exports this crate as
//! `magsep_plugins::record`.
//!
//! A recording is an [MCAP](https://mcap.dev) file with zstd-compressed chunks and two channels:
//!
//! * [`STATE_TOPIC`] (`/state`): lossless particle state, one protobuf message
//!   `magsep.ParticleState` per frame (arrays as little-endian byte strings), decoded back into a
//!   [`ParticleFrame`] bit for bit by [`read_recording`];
//! * [`SCENE_TOPIC`] (`/scene`): a `foxglove.SceneUpdate` per frame (true-size spheres, capsules
//!   and the periodic box in frame `world`), so that the file opens in Foxglove as is.
//!
//! Plugins add channels of their own ([`RecordingWriter::add_channel`],
//! [`RecordingWriter::add_protobuf_channel`] with a self-describing schema from
//! [`protobuf_schema`]) and metadata records ([`RecordingWriter::add_metadata`]).
//!
//! The run's [`RecordingMetadata`] (scene, seed, schedule, the plugins and their parameters,
//! extra key/values) is stored as the MCAP metadata record [`METADATA_NAME`] (`magsep`) right
//! after the file header, and an optional JSON summary as the metadata record
//! [`SUMMARY_METADATA_NAME`] (`magsep.summary`). The writer ends a chunk and flushes the file after
//! every message batch and, by default, every frame (with
//! [`RecordingWriter::buffer_frames`], as `magsep run` sets it, fast frames share a chunk for
//! at most a bounded time and size), so a process killed mid-run leaves every flushed frame and
//! message readable; the readers report such a file through [`Recording::truncated`] and
//! [`RecordingReader::truncated`]. `recordings/README.md` documents the format for other
//! readers.
//!
//! [`RecordingReader`] streams any channel of a file chunk by chunk (through the summary's
//! indexes when present) with bounded memory; [`read_recording`] reads a whole file into a
//! [`Recording`] on top of it.
//!
//! Lengths are in metres and times in seconds throughout; MCAP log times are in nanoseconds
//! (see [`log_time_ns`]).
//!
//! # Example
//!
//! ```no_run
//! use magsep_record::{
//!     ParticleFrame, RecordingMetadata, RecordingWriter, read_recording,
//! };
//! use glam::{DQuat, DVec3};
//! use std::path::Path;
//!
//! # fn main() -> Result<(), magsep_record::RecordError> {
//! let path = Path::new("out/run.mcap");
//! let meta = RecordingMetadata {
//!     scene_text: "# scene file text".into(),
//!     seed: 42,
//!     version: "0.1.0".into(),
//!     pipeline: "packing".into(),
//!     ..Default::default()
//! };
//! let mut writer = RecordingWriter::create(path, &meta)?;
//! let frame = ParticleFrame {
//!     step: 0,
//!     time: 0.0,
//!     box_edges: DVec3::splat(1e-5),
//!     ids: vec![0],
//!     positions: vec![DVec3::splat(5e-6)],
//!     orientations: vec![DQuat::IDENTITY],
//!     radii: vec![1e-6],
//!     half_lengths: vec![0.0],
//!     rng_states: vec![[1, 2, 3, 4]],
//!     status_json: "{}".into(),
//! };
//! writer.write_frame(&frame, None)?;
//! writer.write_summary(r#"{"steps": 1}"#)?;
//! writer.finish()?;
//!
//! let recording = read_recording(path)?;
//! assert_eq!(recording.frames, vec![frame]);
//! assert_eq!(recording.metadata, Some(meta));
//! assert!(recording.truncated.is_none());
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

pub mod frame;
pub mod grid;
mod meta;
mod parse;
mod proto;
pub mod reader;
mod scene;
pub mod schema;
pub mod testing;
pub mod writer;

#[cfg(test)]
mod tests;

use std::path::PathBuf;

pub use frame::{
    BackdropCube, FibreShape, ParticleFrame, PluginInfo, RecordingMetadata, WallShape,
};
pub use reader::{
    ChannelInfo, Frames, LastFrame, MAX_CHUNK_BYTES, Messages, MetadataRecord, RATIO_FREE_BYTES,
    RawMessage, ReadMode, ReaderLimits, Recording, RecordingReader, SchemaInfo, open_regular,
    read_last_frame, read_recording, read_recording_bytes, trailing_message,
};
pub use schema::{ProtoField, ProtoLabel, ProtoType, ProtobufSchema, protobuf_schema};
pub use writer::{ChannelHandle, FrameBuffering, RecordingSink, RecordingWriter, log_time_ns};

/// Topic of the lossless particle state channel (schema `magsep.ParticleState`).
pub const STATE_TOPIC: &str = "/state";
/// Topic of the Foxglove visualisation channel (schema `foxglove.SceneUpdate`).
pub const SCENE_TOPIC: &str = "/scene";
/// Protobuf full name (and MCAP schema name) of the `/state` messages.
pub const STATE_SCHEMA_NAME: &str = "magsep.ParticleState";
/// Name of the MCAP metadata record holding the [`RecordingMetadata`].
pub const METADATA_NAME: &str = "magsep";
/// Name of the MCAP metadata record holding the run summary (key `summary`, JSON text).
pub const SUMMARY_METADATA_NAME: &str = "magsep.summary";
/// Name of the MCAP metadata record written when a run was stopped before its end (key
/// `reason`, e.g. `SIGINT`); see [`RecordingWriter::write_interrupted`].
pub const INTERRUPTED_METADATA_NAME: &str = "magsep.interrupted";
/// Foxglove frame id of all scene entities.
pub const SCENE_FRAME_ID: &str = "world";

/// Errors of recording and reading back.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// An operating-system I/O error on `path`.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP writer failed (I/O, compression or bookkeeping) on `path`.
    #[error("MCAP write error on {path}: {source}")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: mcap::McapError,
    },
    /// The data does not start with the MCAP magic bytes.
    #[error("not an MCAP file: {detail}")]
    NotMcap {
        /// What was found instead.
        detail: String,
    },
    /// A record of the file is damaged: bad CRC, impossible length, malformed fields.
    #[error("corrupt recording at byte {offset}: {detail}")]
    Corrupt {
        /// Byte offset (from the start of the file) of the damaged record.
        offset: u64,
        /// What was found and what was expected.
        detail: String,
    },
    /// A record is intact but its content cannot be decoded (protobuf, metadata values).
    #[error("cannot decode recording: {detail}")]
    Decode {
        /// What failed, with the byte offset of the record concerned.
        detail: String,
    },
    /// Chunks whose bytes are damaged (a CRC mismatch, data that does not decompress or does
    /// not split into records) were skipped, and the records before and after them read: the
    /// messages in those chunks are missing. Given once, after every message read.
    #[error(
        "corrupt recording at byte {offset}: {detail}; that chunk was skipped and the rest of \
         the file read ({count} damaged chunk(s) skipped in all)"
    )]
    SkippedChunks {
        /// Byte offset of the first damaged chunk.
        offset: u64,
        /// What is wrong with it.
        detail: String,
        /// Damaged chunks skipped in all.
        count: usize,
    },
    /// The caller passed inconsistent data to the writer (e.g. arrays of different lengths).
    #[error("invalid input: {detail}")]
    InvalidInput {
        /// What was wrong.
        detail: String,
    },
}

/// The `(truncated, damaged)` messages of a reader that met damage `e` after `frames`
/// complete frames: where reading stopped (in both), or for [`RecordError::SkippedChunks`],
/// which stops nothing, what was read around the damaged chunks (`damaged` only).
pub fn damage_messages(e: &RecordError, frames: u64) -> (Option<String>, Option<String>) {
    let read = complete_frames_read(frames);
    match e {
        RecordError::SkippedChunks { .. } => (None, Some(format!("{e}: {read}"))),
        _ => {
            let msg = format!("{e}; reading stopped there: {read}");
            (Some(msg.clone()), Some(msg))
        }
    }
}

/// "N complete frames read" ("1 complete frame read"): how a damaged file's messages say what
/// was recovered.
pub fn complete_frames_read(n: u64) -> String {
    if n == 1 {
        "1 complete frame read".into()
    } else {
        format!("{n} complete frames read")
    }
}
