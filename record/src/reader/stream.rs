//! [`RecordingReader`]: a streaming reader of any channel, one chunk in memory at a time.

use super::chunk::{ReaderLimits, decompress, split_records};
use super::layout::{End, Layout, MESSAGE_HEAD_LEN, MetadataRecord, Unit, message_head};
use super::seek::{FrameIndex, decode_frame};
use super::source::Source;
use super::{ChannelInfo, scan, summary};
use crate::{ParticleFrame, RecordError, RecordingMetadata, STATE_TOPIC};
use mcap::records::op;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::{Path, PathBuf};

/// How [`RecordingReader`] finds the messages of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReadMode {
    /// Use the summary section (chunk and metadata indexes, statistics) when the file has a
    /// valid one: opening reads only the summary and the metadata records, and iterating a
    /// topic skips the chunks that hold none of its messages. Files without a usable summary
    /// (cut short, written without indexes) are scanned linearly. Chunk CRCs are checked as
    /// chunks are read; the data-section CRC is not.
    #[default]
    Indexed,
    /// Always scan the whole file linearly when opening, checking every CRC (chunks, data
    /// section, summary section) and the structure of every record.
    Linear,
}

/// A schema of a channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SchemaInfo {
    /// Schema name, e.g. `magsep.ParticleState`.
    pub name: String,
    /// Schema encoding, e.g. `protobuf` (the data is then a `FileDescriptorSet`).
    pub encoding: String,
    /// The schema data.
    pub data: Vec<u8>,
}

/// One message as stored: its channel, times and payload bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawMessage {
    /// Topic of its channel.
    pub topic: String,
    /// Name of the channel's schema (empty if it has none).
    pub schema_name: String,
    /// Channel id in the file.
    pub channel_id: u16,
    /// MCAP sequence number.
    pub sequence: u32,
    /// Log time \[ns\].
    pub log_time_ns: u64,
    /// Publish time \[ns\].
    pub publish_time_ns: u64,
    /// The payload, in the channel's message encoding.
    pub data: Vec<u8>,
    /// Byte offset of the record holding it (its chunk, or the message record itself).
    pub offset: u64,
}

/// A streaming reader of a recording (or any MCAP file with zstd or uncompressed chunks).
///
/// [`open`](Self::open) reads the summary section when the file has a valid one, else scans
/// the file once (see [`ReadMode`]); the file is never read into memory as a whole. Messages
/// are then read chunk by chunk: at most one chunk (compressed and decompressed) and its
/// messages are in memory at a time. Every length field is checked against the size of the
/// file and against [`ReaderLimits`] before anything is allocated.
///
/// A file cut short is read up to its last complete chunk ([`truncated`](Self::truncated)
/// says where it ends); a damaged record ends the iteration with its error (also in
/// [`damage`](Self::damage)), after every message before it.
///
/// ```no_run
/// use magsep_record::RecordingReader;
/// # fn main() -> Result<(), magsep_record::RecordError> {
/// let mut reader = RecordingReader::open(std::path::Path::new("run.mcap"))?;
/// for channel in reader.channels() {
///     println!("{} ({}): {} messages", channel.topic, channel.schema_name, channel.message_count);
/// }
/// for frame in reader.frames() {
///     let frame = frame?;
///     println!("step {} at t = {} s: {} particles", frame.step, frame.time, frame.ids.len());
/// }
/// for message in reader.messages(Some("/energy")) {
///     let message = message?;
///     println!("{} ns: {} bytes of {}", message.log_time_ns, message.data.len(), message.schema_name);
/// }
/// if let Some(why) = reader.truncated() {
///     eprintln!("warning: {why}");
/// }
/// # Ok(())
/// # }
/// ```
pub struct RecordingReader<R = BufReader<File>> {
    src: Source<R>,
    path: PathBuf,
    limits: ReaderLimits,
    pub(super) layout: Layout,
    pub(super) frame_index: FrameIndex,
}

impl RecordingReader<BufReader<File>> {
    /// Opens the recording at `path` ([`ReadMode::Indexed`], default limits).
    ///
    /// Fails with [`RecordError::Io`] if the file cannot be read and [`RecordError::NotMcap`]
    /// if it does not start with the MCAP magic; damage and truncation are reported by
    /// [`damage`](Self::damage), [`truncated`](Self::truncated) and the iterators.
    pub fn open(path: &Path) -> Result<Self, RecordError> {
        Self::open_with(path, ReadMode::Indexed, ReaderLimits::default())
    }

    /// Like [`open`](Self::open) with a read mode and limits.
    pub fn open_with(
        path: &Path,
        mode: ReadMode,
        limits: ReaderLimits,
    ) -> Result<Self, RecordError> {
        let file = open_regular(path).map_err(|source| RecordError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_reader(BufReader::new(file), path, mode, limits)
    }
}

/// Opens `path` for reading if it is a regular file (after following symbolic links):
/// directories, devices (`/dev/zero`), FIFOs and sockets are refused before they are opened
/// (opening a FIFO would block), and the opened file is checked again.
pub fn open_regular(path: &Path) -> std::io::Result<File> {
    let not_regular = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a directory, device, FIFO or socket)",
        )
    };
    if !std::fs::metadata(path)?.is_file() {
        return Err(not_regular());
    }
    let file = File::open(path)?;
    if !file.metadata()?.is_file() {
        return Err(not_regular());
    }
    Ok(file)
}

impl<R: Read + Seek> RecordingReader<R> {
    /// A reader over any `Read + Seek` source; `name` is used in error messages.
    pub fn from_reader(
        reader: R,
        name: &Path,
        mode: ReadMode,
        limits: ReaderLimits,
    ) -> Result<Self, RecordError> {
        let path = name.to_path_buf();
        let mut src = Source::new(reader).map_err(|source| RecordError::Io {
            path: path.clone(),
            source,
        })?;
        let indexed = match mode {
            ReadMode::Indexed => summary::indexed(&mut src, &limits),
            ReadMode::Linear => None,
        };
        let mut layout = match indexed {
            Some(layout) => layout,
            None => scan::scan(&mut src, &path, &limits),
        };
        // Nothing readable and not an MCAP file, or unreadable: an error, not a reader.
        if layout.units.is_empty()
            && matches!(
                layout.end,
                End::Failed(RecordError::NotMcap { .. } | RecordError::Io { .. })
            )
            && let End::Failed(e) = std::mem::take(&mut layout.end)
        {
            return Err(e);
        }
        Ok(Self {
            src,
            path,
            limits,
            layout,
            frame_index: FrameIndex::default(),
        })
    }

    /// The channels in channel-id order, with their message counts (from the summary
    /// statistics, or counted by the scan: complete messages only).
    pub fn channels(&self) -> Vec<ChannelInfo> {
        self.layout
            .channels
            .iter()
            .map(|(id, c)| {
                let schema = self.layout.schemas.get(&c.schema_id);
                ChannelInfo {
                    id: *id,
                    topic: c.topic.clone(),
                    schema_name: schema.map(|s| s.name.clone()).unwrap_or_default(),
                    schema_encoding: schema.map(|s| s.encoding.clone()).unwrap_or_default(),
                    message_encoding: c.message_encoding.clone(),
                    message_count: c.message_count,
                }
            })
            .collect()
    }

    /// The schema of the channel on `topic` (`None` if no such channel, or it has none).
    pub fn schema(&self, topic: &str) -> Option<SchemaInfo> {
        let channel = self.layout.channels.values().find(|c| c.topic == topic)?;
        let s = self.layout.schemas.get(&channel.schema_id)?;
        Some(SchemaInfo {
            name: s.name.clone(),
            encoding: s.encoding.clone(),
            data: s.data.clone(),
        })
    }

    /// The run's metadata (record `magsep`), if present.
    pub fn metadata(&self) -> Option<&RecordingMetadata> {
        self.layout.metadata.as_ref()
    }

    /// All metadata records in file order (`magsep`, `magsep.summary`, plugins' records).
    pub fn metadata_records(&self) -> &[MetadataRecord] {
        &self.layout.metadata_records
    }

    /// The JSON text of the last `magsep.summary` record, if any.
    pub fn summary_json(&self) -> Option<&str> {
        self.layout.summary_json.as_deref()
    }

    /// `None` unless the file ends early (no footer: a killed process, a copy in progress); then
    /// where it ends, where the incomplete record starts and how many frames are complete.
    pub fn truncated(&self) -> Option<&str> {
        match &self.layout.end {
            End::Truncated(msg) => Some(msg),
            _ => None,
        }
    }

    /// The damaged record that ends the readable part of the file, if any (with its offset);
    /// else, when damaged chunks were skipped ([`RecordError::SkippedChunks`]), the first of
    /// them and their number. Chunks are skipped by the scan of [`ReadMode::Linear`] (and of
    /// a file without a usable summary) when opening, and by [`Self::messages`] and
    /// [`Self::frames`] as they meet them in an indexed file, so that this grows as they run.
    pub fn damage(&self) -> Option<RecordError> {
        match (&self.layout.end, self.layout.skipped.first()) {
            // the chunks skipped before the record that stopped the reading are named too
            (End::Failed(RecordError::Corrupt { offset, detail }), Some((at, first))) => {
                Some(RecordError::Corrupt {
                    offset: *offset,
                    detail: format!(
                        "{detail} (before it, {} damaged chunk(s) were skipped, the first at \
                         byte {at}: {first})",
                        self.layout.skipped.len()
                    ),
                })
            }
            (End::Failed(e), _) => Some(duplicate(e)),
            _ => self
                .layout
                .skipped
                .first()
                .map(|(offset, detail)| RecordError::SkippedChunks {
                    offset: *offset,
                    detail: detail.clone(),
                    count: self.layout.skipped.len(),
                }),
        }
    }

    /// Bytes after the closing magic of a complete file: `(offset, count)`. A recording
    /// ends with its closing magic; anything after it was appended by something else, and
    /// the file counts as damaged (the records before are read as usual).
    pub fn trailing_bytes(&self) -> Option<(u64, u64)> {
        self.layout.trailing
    }

    /// Whether the file was opened through its summary section (else by a linear scan).
    pub fn is_indexed(&self) -> bool {
        self.layout.indexed
    }

    /// Size of the file (bytes).
    pub fn file_bytes(&self) -> u64 {
        self.src.len
    }

    /// Iterates the messages on `topic` (all topics for `None`) in file order, one chunk in
    /// memory at a time. Yields an error and stops at a damaged or unreadable record; a chunk
    /// whose bytes are damaged is skipped instead, and [`RecordError::SkippedChunks`] is
    /// yielded after the last message.
    pub fn messages(&mut self, topic: Option<&str>) -> Messages<'_, R> {
        let channels = self.layout.channel_ids(topic);
        Messages {
            reader: self,
            channels,
            next_unit: 0,
            pending: Vec::new().into_iter(),
            done: false,
        }
    }

    /// Iterates the `/state` frames, decoded lazily. Yields an error and stops at a damaged
    /// record or an undecodable frame; damaged chunks are skipped as in [`Self::messages`].
    pub fn frames(&mut self) -> Frames<'_, R> {
        let encoding = self.state_encoding_error();
        Frames {
            messages: self.messages(Some(STATE_TOPIC)),
            bad_encoding: encoding,
            count: 0,
            done: false,
        }
    }

    fn io(&self, source: std::io::Error) -> RecordError {
        RecordError::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Reads the messages of `unit` accepted by `accept`.
    pub(super) fn load(
        &mut self,
        unit: &Unit,
        accept: &dyn Fn(u16) -> bool,
    ) -> Result<Vec<RawMessage>, RecordError> {
        let (offset, len) = match unit {
            Unit::Chunk { offset, len, .. } | Unit::Message { offset, len } => (*offset, *len),
        };
        let corrupt = |detail: String| RecordError::Corrupt { offset, detail };
        if offset.checked_add(len).is_none_or(|end| end > self.src.len) || len < 9 {
            return Err(corrupt(format!(
                "record of {len} bytes runs past the end of the file ({} bytes)",
                self.src.len
            )));
        }
        if len - 9 > self.limits.max_record_bytes {
            return Err(corrupt(format!(
                "record of {len} bytes exceeds the reader's limit of {} bytes per record",
                self.limits.max_record_bytes
            )));
        }
        let record = self.src.read_at(offset, len).map_err(|e| self.io(e))?;
        let declared = u64::from_le_bytes(record[1..9].try_into().unwrap_or([0xff; 8]));
        let expected = if matches!(unit, Unit::Chunk { .. }) {
            op::CHUNK
        } else {
            op::MESSAGE
        };
        if record[0] != expected || declared != len - 9 {
            return Err(corrupt(format!(
                "expected a record of opcode 0x{expected:02x} and {} bytes, found opcode \
                 0x{:02x} declaring {declared} bytes",
                len - 9,
                record[0]
            )));
        }
        let mut out = Vec::new();
        if expected == op::MESSAGE {
            self.message(&record[9..], offset, accept, &mut out)
                .map_err(&corrupt)?;
            return Ok(out);
        }
        let data =
            decompress(&record[9..], &self.limits).map_err(|e| corrupt(format!("chunk: {e}")))?;
        let records = split_records(&data).map_err(|e| corrupt(format!("chunk: {e}")))?;
        for (k, (opcode, range)) in records.into_iter().enumerate() {
            if opcode == op::MESSAGE {
                self.message(&data[range], offset, accept, &mut out)
                    .map_err(|e| corrupt(format!("message record #{k} in the chunk: {e}")))?;
            }
        }
        Ok(out)
    }

    fn message(
        &self,
        body: &[u8],
        offset: u64,
        accept: &dyn Fn(u16) -> bool,
        out: &mut Vec<RawMessage>,
    ) -> Result<(), String> {
        let head = message_head(body)?;
        if !accept(head.channel_id) {
            return Ok(());
        }
        let channel = self.layout.channels.get(&head.channel_id).ok_or_else(|| {
            format!(
                "message on channel id {}, which no channel record defines",
                head.channel_id
            )
        })?;
        out.push(RawMessage {
            topic: channel.topic.clone(),
            schema_name: self
                .layout
                .schemas
                .get(&channel.schema_id)
                .map(|s| s.name.clone())
                .unwrap_or_default(),
            channel_id: head.channel_id,
            sequence: head.sequence,
            log_time_ns: head.log_time,
            publish_time_ns: head.publish_time,
            data: body[MESSAGE_HEAD_LEN..].to_vec(),
            offset,
        });
        Ok(())
    }
}

impl<R> std::fmt::Debug for RecordingReader<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordingReader")
            .field("path", &self.path)
            .field("file_bytes", &self.src.len)
            .field("indexed", &self.layout.indexed)
            .finish()
    }
}

/// A copy of an error of the scan, to yield from an iterator.
pub(super) fn duplicate(e: &RecordError) -> RecordError {
    match e {
        RecordError::Io { path, source } => RecordError::Io {
            path: path.clone(),
            source: std::io::Error::new(source.kind(), source.to_string()),
        },
        RecordError::NotMcap { detail } => RecordError::NotMcap {
            detail: detail.clone(),
        },
        RecordError::Corrupt { offset, detail } => RecordError::Corrupt {
            offset: *offset,
            detail: detail.clone(),
        },
        RecordError::Decode { detail } => RecordError::Decode {
            detail: detail.clone(),
        },
        other => RecordError::InvalidInput {
            detail: other.to_string(),
        },
    }
}

/// Iterator of [`RawMessage`]s, from [`RecordingReader::messages`].
pub struct Messages<'a, R> {
    reader: &'a mut RecordingReader<R>,
    /// Channel ids of the topic; `None`: all.
    channels: Option<Vec<u16>>,
    next_unit: usize,
    pending: std::vec::IntoIter<RawMessage>,
    done: bool,
}

impl<R: Read + Seek> Iterator for Messages<'_, R> {
    type Item = Result<RawMessage, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(m) = self.pending.next() {
                return Some(Ok(m));
            }
            if self.done {
                return None;
            }
            let Some(unit) = self.reader.layout.units.get(self.next_unit).cloned() else {
                self.done = true;
                return self.reader.damage().map(Err);
            };
            self.next_unit += 1;
            if let (
                Some(wanted),
                Unit::Chunk {
                    channels: Some(has),
                    ..
                },
            ) = (&self.channels, &unit)
                && !wanted.iter().any(|id| has.contains(id))
            {
                continue;
            }
            let wanted = self.channels.clone();
            let accept = move |id: u16| wanted.as_ref().is_none_or(|w| w.contains(&id));
            match self.reader.load(&unit, &accept) {
                Ok(messages) => self.pending = messages.into_iter(),
                // a chunk of an indexed file whose bytes are damaged: the index says where
                // the next one starts
                Err(RecordError::Corrupt { offset, detail })
                    if matches!(unit, Unit::Chunk { .. }) =>
                {
                    self.reader.layout.note_skipped(offset, detail);
                }
                Err(e) => {
                    self.done = true;
                    return Some(Err(e));
                }
            }
        }
    }
}

/// Iterator of decoded `/state` frames, from [`RecordingReader::frames`].
pub struct Frames<'a, R> {
    messages: Messages<'a, R>,
    /// The `/state` channel's message encoding when it is not `protobuf`.
    bad_encoding: Option<String>,
    count: u64,
    done: bool,
}

impl<R: Read + Seek> Iterator for Frames<'_, R> {
    type Item = Result<ParticleFrame, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let item = self
            .messages
            .next()?
            .and_then(|m| decode_frame(&m, self.count, self.bad_encoding.as_deref()));
        match &item {
            Ok(_) => self.count += 1,
            Err(_) => self.done = true,
        }
        Some(item)
    }
}
