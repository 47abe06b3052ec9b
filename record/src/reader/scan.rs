//! [`read_recording`]: reads a recording back, tolerating files cut short.
//!
//! The file is read linearly from the start, so a file without summary or footer (a killed
//! process) still yields every frame in a complete chunk. Chunks are taken whole: their records
//! are used only once the chunk has decompressed and passed its CRC. The data-section and
//! summary CRCs are checked when the file has them.

use super::parse::{Cursor, check_chunk_header, crc32, hex_prefix, parse_metadata};
use super::proto::ParticleStateWire;
use super::{
    METADATA_NAME, ParticleFrame, RecordError, RecordingMetadata, STATE_TOPIC,
    SUMMARY_METADATA_NAME,
};
use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// A channel of a recording, with the number of messages read on it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    /// Topic, e.g. `/state`.
    pub topic: String,
    /// Name of the channel's schema, e.g. `magsep.ParticleState` (empty if it has none).
    pub schema_name: String,
    /// Message encoding, e.g. `protobuf`.
    pub message_encoding: String,
    /// Number of messages read on the channel.
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
    /// `None` for a complete, intact file. Otherwise why reading stopped early: the file ends
    /// before its footer (process killed; the message gives the byte where the file ends and
    /// the start of the incomplete record), or a damaged record follows the frames read.
    pub truncated: Option<String>,
    /// Size of the file (bytes).
    pub file_bytes: u64,
}

/// Reads the recording at `path`: metadata, all complete frames, summary and channel list.
///
/// A file cut short (no footer) gives `Ok` with the frames read and
/// [`Recording::truncated`] set. Data that is not MCAP gives [`RecordError::NotMcap`]; a damaged
/// record gives [`RecordError::Corrupt`] or [`RecordError::Decode`] with its byte offset, unless
/// frames were read before it, in which case they are returned with the error in
/// [`Recording::truncated`]. Never panics. The whole file is read into memory.
pub fn read_recording(path: &Path) -> Result<Recording, RecordError> {
    let data = std::fs::read(path).map_err(|source| RecordError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_recording_bytes(&data)
}

/// Like [`read_recording`], on the bytes of a recording already in memory.
pub fn read_recording_bytes(data: &[u8]) -> Result<Recording, RecordError> {
    let mut walk = Walk::default();
    let stop = walk.run(data);
    let n = walk.frames.len();
    let truncated = match stop {
        Ok(()) => None,
        Err(Stop::Truncated(msg)) => Some(msg),
        Err(Stop::Failed(e)) if n == 0 => return Err(e),
        Err(Stop::Failed(e)) => Some(format!(
            "{e}; reading stopped there: {n} complete frames read"
        )),
    };
    let channels = walk
        .channels
        .into_values()
        .map(|c| ChannelInfo {
            schema_name: walk.schemas.get(&c.schema_id).cloned().unwrap_or_default(),
            topic: c.topic,
            message_encoding: c.message_encoding,
            message_count: c.message_count,
        })
        .collect();
    Ok(Recording {
        metadata: walk.metadata,
        frames: walk.frames,
        summary_json: walk.summary_json,
        channels,
        truncated,
        file_bytes: data.len() as u64,
    })
}

/// Records longer than this are taken as damaged rather than cut short (bytes).
const MAX_RECORD_LEN: u64 = 1 << 40;

/// Why reading stopped before the footer.
enum Stop {
    /// The file ends early; the message says where.
    Truncated(String),
    /// A damaged or undecodable record.
    Failed(RecordError),
}

fn corrupt(offset: usize, detail: impl Into<String>) -> Stop {
    Stop::Failed(RecordError::Corrupt {
        offset: offset as u64,
        detail: detail.into(),
    })
}

fn decode_err(detail: String) -> Stop {
    Stop::Failed(RecordError::Decode { detail })
}

fn kind(opcode: u8) -> String {
    let name = match opcode {
        op::HEADER => "header",
        op::FOOTER => "footer",
        op::SCHEMA => "schema",
        op::CHANNEL => "channel",
        op::MESSAGE => "message",
        op::CHUNK => "chunk",
        op::MESSAGE_INDEX => "message index",
        op::CHUNK_INDEX => "chunk index",
        op::ATTACHMENT => "attachment",
        op::ATTACHMENT_INDEX => "attachment index",
        op::STATISTICS => "statistics",
        op::METADATA => "metadata",
        op::METADATA_INDEX => "metadata index",
        op::SUMMARY_OFFSET => "summary offset",
        op::DATA_END => "data end",
        _ => return format!("private (opcode 0x{opcode:02x})"),
    };
    name.to_string()
}

struct ChannelRec {
    topic: String,
    schema_id: u16,
    message_encoding: String,
    message_count: u64,
}

#[derive(Default)]
struct Walk {
    frames: Vec<ParticleFrame>,
    metadata: Option<RecordingMetadata>,
    summary_json: Option<String>,
    /// Schema id -> name.
    schemas: HashMap<u16, String>,
    channels: BTreeMap<u16, ChannelRec>,
}

impl Walk {
    fn truncated(&self, len: usize, what: String) -> Stop {
        Stop::Truncated(format!(
            "file ends at byte {len} {what}: {} complete frames read",
            self.frames.len()
        ))
    }

    fn run(&mut self, data: &[u8]) -> Result<(), Stop> {
        let len = data.len();
        let magic = mcap::MAGIC;
        if len < magic.len() && magic.starts_with(data) {
            return Err(self.truncated(len, "inside the 8-byte MCAP magic (no footer)".into()));
        }
        if !data.starts_with(magic) {
            return Err(Stop::Failed(RecordError::NotMcap {
                detail: format!(
                    "the file starts with bytes [{}], expected the MCAP magic [{}]",
                    hex_prefix(data),
                    hex_prefix(magic)
                ),
            }));
        }
        // A file ending in the magic was finished: a record running past its end is damage.
        let finished = len >= 2 * magic.len() + 9 && data.ends_with(magic);
        let mut pos = magic.len();
        let mut in_summary = false;
        loop {
            let start = pos;
            if len - pos < 9 {
                let what = if pos == len && in_summary {
                    "after a complete record of the summary section (no footer)".into()
                } else if pos == len {
                    "after a complete record, before the summary section (no footer)".into()
                } else {
                    format!(
                        "inside the opcode and length of a record that starts at byte {pos} \
                         (no footer)"
                    )
                };
                return Err(self.truncated(len, what));
            }
            let opcode = data[pos];
            let mut rlen = [0u8; 8];
            rlen.copy_from_slice(&data[pos + 1..pos + 9]);
            let rlen = u64::from_le_bytes(rlen);
            if opcode == 0 || (op::DATA_END < opcode && opcode < 0x80) {
                return Err(corrupt(
                    start,
                    format!(
                        "opcode 0x{opcode:02x} is not an MCAP record type \
                         (expected 0x01..=0x0f, or >= 0x80 for a private record)"
                    ),
                ));
            }
            if (start == magic.len()) != (opcode == op::HEADER) {
                return Err(corrupt(
                    start,
                    format!(
                        "found a {} record; expected exactly one header record, \
                         right after the magic",
                        kind(opcode)
                    ),
                ));
            }
            let avail = (len - pos - 9) as u64;
            if rlen > avail {
                let k = kind(opcode);
                if opcode == op::CHUNK && rlen == u64::MAX {
                    return Err(self.truncated(
                        len,
                        format!(
                            "inside a chunk record that starts at byte {start} and was never \
                             completed (its length is still the writer's placeholder: the \
                             writing process stopped in the middle of a frame; no footer)"
                        ),
                    ));
                }
                if finished || rlen > MAX_RECORD_LEN {
                    return Err(corrupt(
                        start,
                        format!(
                            "{k} record declares a length of {rlen} bytes but only {avail} \
                             bytes follow; expected the record to end within the file"
                        ),
                    ));
                }
                return Err(self.truncated(
                    len,
                    format!(
                        "inside a {k} record that starts at byte {start} and \
                         declares {rlen} bytes (no footer)"
                    ),
                ));
            }
            pos += 9 + rlen as usize;
            let body = &data[start + 9..pos];
            match opcode {
                op::FOOTER => return self.footer(data, start, body),
                op::CHUNK if in_summary => {
                    return Err(corrupt(start, "chunk record in the summary section"));
                }
                op::CHUNK => self.chunk(start, &data[start..pos], body)?,
                _ if in_summary => {} // Summary records repeat what the data section holds.
                op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA => {
                    let at = format!("the {} record at byte {start}", kind(opcode));
                    self.record(opcode, body)
                        .map_err(|e| e.into_stop(start, &at))?;
                }
                op::DATA_END => {
                    let saved = Cursor::new(body)
                        .u32("data section CRC")
                        .map_err(|e| corrupt(start, format!("data end record: {e}")))?;
                    let computed = crc32(&data[..start]);
                    if saved != 0 && saved != computed {
                        return Err(corrupt(
                            start,
                            format!(
                                "data section CRC mismatch: the data end record stores \
                                 0x{saved:08x}, bytes 0..{start} give 0x{computed:08x}"
                            ),
                        ));
                    }
                    in_summary = true;
                }
                _ => {} // Header, indexes, statistics, attachments, private records.
            }
        }
    }

    /// Checks the footer at `start` (body `body`), the summary CRC and the closing magic.
    fn footer(&mut self, data: &[u8], start: usize, body: &[u8]) -> Result<(), Stop> {
        let mut c = Cursor::new(body);
        let parsed = (|| {
            let summary_start = c.u64("summary start")?;
            c.u64("summary offset start")?;
            let crc = c.u32("summary CRC")?;
            Ok::<_, String>((summary_start, crc))
        })();
        let (summary_start, saved) =
            parsed.map_err(|e| corrupt(start, format!("footer record: {e}")))?;
        let crc_end = start + 9 + 16;
        if saved != 0 {
            let from = if summary_start == 0 {
                start as u64
            } else {
                summary_start
            };
            if from > start as u64 {
                return Err(corrupt(
                    start,
                    format!("footer says the summary starts at byte {from}, after the footer"),
                ));
            }
            let computed = crc32(&data[from as usize..crc_end]);
            if computed != saved {
                return Err(corrupt(
                    start,
                    format!(
                        "summary CRC mismatch: the footer stores 0x{saved:08x}, \
                         bytes {from}..{crc_end} give 0x{computed:08x}"
                    ),
                ));
            }
        }
        let end = start + 9 + body.len();
        let tail = &data[end..];
        let magic = mcap::MAGIC;
        if tail.len() < magic.len() && magic.starts_with(tail) {
            return Err(self.truncated(
                data.len(),
                format!(
                    "inside the closing magic after the footer at byte {start} \
                     (all records present)"
                ),
            ));
        }
        if !tail.starts_with(magic) {
            return Err(corrupt(
                end,
                format!(
                    "found bytes [{}] after the footer, expected the closing MCAP magic [{}]",
                    hex_prefix(tail),
                    hex_prefix(magic)
                ),
            ));
        }
        Ok(())
    }

    /// Decompresses the chunk record `record` (body `body`) at byte `start` and uses its records
    /// once the whole chunk has decompressed and passed its CRC.
    fn chunk(&mut self, start: usize, record: &[u8], body: &[u8]) -> Result<(), Stop> {
        let limit = check_chunk_header(body).map_err(|e| corrupt(start, format!("chunk: {e}")))?;
        let options = LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_emit_chunks(false)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(limit);
        let mut reader = LinearReader::new_with_options(options);
        let mut input = record;
        let mut records = Vec::new();
        while let Some(event) = reader.next_event() {
            match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let n = need.min(input.len());
                    reader.insert(n).copy_from_slice(&input[..n]);
                    reader.notify_read(n);
                    input = &input[n..];
                }
                Ok(LinearReadEvent::Record { opcode, data }) => {
                    records.push((opcode, data.to_vec()))
                }
                Err(e) => return Err(corrupt(start, format!("chunk: {e}"))),
            }
        }
        for (k, (opcode, body)) in records.iter().enumerate() {
            let at = format!(
                "the {} record #{k} in the chunk at byte {start}",
                kind(*opcode)
            );
            self.record(*opcode, body)
                .map_err(|e| e.into_stop(start, &at))?;
        }
        Ok(())
    }

    /// Handles a schema, channel, message or metadata record (others are ignored).
    fn record(&mut self, opcode: u8, body: &[u8]) -> Result<(), RecErr> {
        let mut c = Cursor::new(body);
        match opcode {
            op::SCHEMA => {
                let id = c.u16("schema id")?;
                let name = c.string("schema name")?;
                c.string("schema encoding")?;
                c.bytes_u32("schema data")?;
                self.schemas.insert(id, name);
            }
            op::CHANNEL => {
                let id = c.u16("channel id")?;
                let schema_id = c.u16("schema id")?;
                let topic = c.string("topic")?;
                let message_encoding = c.string("message encoding")?;
                c.string_map("channel metadata")?;
                if schema_id != 0 && !self.schemas.contains_key(&schema_id) {
                    return Err(RecErr::Corrupt(format!(
                        "channel {topic:?} refers to schema id {schema_id}, \
                         which no earlier schema record defines"
                    )));
                }
                // A repeated definition keeps counting.
                let message_count = self.channels.get(&id).map_or(0, |c| c.message_count);
                self.channels.insert(
                    id,
                    ChannelRec {
                        topic,
                        schema_id,
                        message_encoding,
                        message_count,
                    },
                );
            }
            op::MESSAGE => {
                let channel_id = c.u16("channel id")?;
                c.u32("sequence")?;
                c.u64("log time")?;
                c.u64("publish time")?;
                let Some(channel) = self.channels.get_mut(&channel_id) else {
                    return Err(RecErr::Corrupt(format!(
                        "message on channel id {channel_id}, which no earlier channel record \
                         defines"
                    )));
                };
                channel.message_count += 1;
                if channel.topic == STATE_TOPIC {
                    if channel.message_encoding != "protobuf" {
                        return Err(RecErr::Decode(format!(
                            "{STATE_TOPIC} has message encoding {:?}, expected \"protobuf\"",
                            channel.message_encoding
                        )));
                    }
                    let frame = ParticleStateWire::decode_payload(c.rest())
                        .and_then(ParticleStateWire::into_frame)
                        .map_err(|e| {
                            RecErr::Decode(format!(
                                "{STATE_TOPIC} frame #{}: {e}",
                                self.frames.len()
                            ))
                        })?;
                    self.frames.push(frame);
                }
            }
            op::METADATA => {
                let name = c.string("metadata name")?;
                let map = c.string_map("metadata map")?;
                if name == METADATA_NAME {
                    self.metadata = Some(parse_metadata(&map).map_err(RecErr::Decode)?);
                } else if name == SUMMARY_METADATA_NAME {
                    let summary = map.get("summary").ok_or_else(|| {
                        RecErr::Decode(format!("metadata {name:?} lacks key \"summary\""))
                    })?;
                    self.summary_json = Some(summary.clone());
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// Error of one record: damage (structure) or undecodable content.
enum RecErr {
    Corrupt(String),
    Decode(String),
}

impl From<String> for RecErr {
    fn from(s: String) -> Self {
        RecErr::Corrupt(s)
    }
}

impl RecErr {
    fn into_stop(self, offset: usize, at: &str) -> Stop {
        match self {
            RecErr::Corrupt(e) => corrupt(offset, format!("{at}: {e}")),
            RecErr::Decode(e) => decode_err(format!("{at}: {e}")),
        }
    }
}
