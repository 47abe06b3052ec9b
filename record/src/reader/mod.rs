//! Reading recordings back: the streaming [`RecordingReader`], and [`read_recording`], which
//! reads a whole file into a [`Recording`] on top of it.

mod chunk;
mod layout;
mod scan;
mod seek;
mod source;
mod stream;
mod summary;

pub use chunk::{MAX_CHUNK_BYTES, RATIO_FREE_BYTES, ReaderLimits};
pub use layout::MetadataRecord;
#[cfg(test)]
pub(crate) use seek::decode_frame;
pub use stream::{
    Frames, Messages, RawMessage, ReadMode, RecordingReader, SchemaInfo, open_regular,
};

use crate::{ParticleFrame, RecordError, RecordingMetadata};
use std::io::{Read, Seek};
use std::path::Path;

/// A channel of a recording, with the number of messages on it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    /// Channel id in the file.
    pub id: u16,
    /// Topic, e.g. `/state`.
    pub topic: String,
    /// Name of the channel's schema, e.g. `magsep.ParticleState` (empty if it has none).
    pub schema_name: String,
    /// Encoding of the channel's schema, e.g. `protobuf` (empty if it has none).
    pub schema_encoding: String,
    /// Message encoding, e.g. `protobuf`.
    pub message_encoding: String,
    /// Number of messages on the channel (complete messages read, for a file cut short).
    pub message_count: u64,
}

/// Everything read from a recording.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recording {
    /// The run's metadata (record `magsep`), if present.
    pub metadata: Option<RecordingMetadata>,
    /// All complete `/state` frames, in file order.
    pub frames: Vec<ParticleFrame>,
    /// The JSON text of the last `magsep.summary` record, if any.
    pub summary_json: Option<String>,
    /// The channels, in channel-id order.
    pub channels: Vec<ChannelInfo>,
    /// All metadata records in file order (`magsep`, `magsep.summary`, plugins' records).
    pub metadata_records: Vec<MetadataRecord>,
    /// `None` for a complete, intact file. Otherwise why reading stopped early: the file ends
    /// before its footer (process killed; the message gives the byte where the file ends and
    /// the start of the incomplete record), or a damaged record follows the frames read.
    pub truncated: Option<String>,
    /// `None` unless the file is damaged: a corrupt or undecodable record stopped the reading
    /// (also given in [`truncated`](Self::truncated)), chunks whose bytes are damaged were
    /// skipped ([`RecordError::SkippedChunks`]: the frames of the other chunks are read, and
    /// `truncated` stays `None`), or bytes follow the closing magic
    /// ([`trailing_bytes`](Self::trailing_bytes)). Frames before the damage are read.
    pub damaged: Option<String>,
    /// Bytes after the closing magic (0 for an intact or a truncated file).
    pub trailing_bytes: u64,
    /// Size of the file (bytes).
    pub file_bytes: u64,
}

/// Reads the recording at `path`: metadata, all complete frames, summary and channel list.
///
/// The file is scanned linearly ([`ReadMode::Linear`]), checking every CRC, and streamed: only
/// one chunk is in memory at a time besides the frames returned. A file cut short (no footer)
/// gives `Ok` with the frames read and [`Recording::truncated`] set. Data that is not MCAP
/// gives [`RecordError::NotMcap`]; a damaged record gives [`RecordError::Corrupt`] or
/// [`RecordError::Decode`] with its byte offset, unless frames were read before it, in which
/// case they are returned with the error in [`Recording::truncated`]. A chunk whose bytes are
/// damaged is skipped and the rest read ([`Recording::damaged`]). Never panics.
pub fn read_recording(path: &Path) -> Result<Recording, RecordError> {
    let reader = RecordingReader::open_with(path, ReadMode::Linear, ReaderLimits::default())?;
    collect(reader)
}

/// Like [`read_recording`], on the bytes of a recording already in memory.
pub fn read_recording_bytes(data: &[u8]) -> Result<Recording, RecordError> {
    let reader = RecordingReader::from_reader(
        std::io::Cursor::new(data),
        Path::new("<memory>"),
        ReadMode::Linear,
        ReaderLimits::default(),
    )?;
    collect(reader)
}

/// The last complete `/state` frame of a recording, from [`read_last_frame`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LastFrame {
    /// The last complete frame (`None`: the file holds none).
    pub frame: Option<ParticleFrame>,
    /// Number of complete frames read.
    pub frames: u64,
    /// As [`Recording::truncated`].
    pub truncated: Option<String>,
    /// As [`Recording::damaged`].
    pub damaged: Option<String>,
}

/// The last complete frame of the recording at `path`, streamed: at most one chunk and two
/// frames are in memory, whatever the file's size ([`ReadMode::Indexed`], default limits).
/// Errors as [`read_recording`].
pub fn read_last_frame(path: &Path) -> Result<LastFrame, RecordError> {
    let mut reader = RecordingReader::open(path)?;
    let mut last = LastFrame::default();
    let mut failure = None;
    for frame in reader.frames() {
        match frame {
            Ok(f) => {
                last.frame = Some(f);
                last.frames += 1;
            }
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    match failure {
        Some(e) if last.frames == 0 && stops_reading(&e) => return Err(e),
        Some(e) => (last.truncated, last.damaged) = crate::damage_messages(&e, last.frames),
        None => {
            last.truncated = reader.truncated().map(str::to_string);
            last.damaged = reader
                .trailing_bytes()
                .map(|(at, count)| trailing_message(at, count));
        }
    }
    Ok(last)
}

fn collect<R: Read + Seek>(mut reader: RecordingReader<R>) -> Result<Recording, RecordError> {
    let mut frames = Vec::new();
    let mut failure = None;
    for frame in reader.frames() {
        match frame {
            Ok(f) => frames.push(f),
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    let n = frames.len();
    let trailing = reader.trailing_bytes();
    let (truncated, damaged) = match failure {
        None => (
            reader.truncated().map(str::to_string),
            trailing.map(|(at, count)| trailing_message(at, count)),
        ),
        // nothing read at all: an error (skipped chunks with the metadata read are not)
        Some(e) if n == 0 && (stops_reading(&e) || reader.metadata().is_none()) => return Err(e),
        Some(e) => crate::damage_messages(&e, n as u64),
    };
    Ok(Recording {
        metadata: reader.metadata().cloned(),
        frames,
        summary_json: reader.summary_json().map(str::to_string),
        channels: reader.channels(),
        metadata_records: reader.metadata_records().to_vec(),
        truncated,
        damaged,
        trailing_bytes: trailing.map_or(0, |t| t.1),
        file_bytes: reader.file_bytes(),
    })
}

/// Whether damage `e` ended the reading (every error but [`RecordError::SkippedChunks`],
/// which the reader met after reading everything else).
fn stops_reading(e: &RecordError) -> bool {
    !matches!(e, RecordError::SkippedChunks { .. })
}

/// The damage message of `count` bytes after the closing magic, from byte `at`.
pub fn trailing_message(at: u64, count: u64) -> String {
    format!(
        "{count} trailing bytes after the footer (bytes {at}..{}): not part of the recording; \
         the records before them are intact",
        at + count
    )
}
