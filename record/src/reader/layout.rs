//! What the reader knows of a file before iterating its messages: schemas, channels, metadata
//! and where the messages are (chunks, or message records outside chunks).

use crate::meta::parse_metadata;
use crate::parse::{Cursor, clip};
use crate::{METADATA_NAME, RecordError, RecordingMetadata, STATE_TOPIC, SUMMARY_METADATA_NAME};
use std::collections::{BTreeMap, HashMap};

/// A schema record.
#[derive(Debug, Clone)]
pub(crate) struct SchemaRec {
    pub name: String,
    pub encoding: String,
    pub data: Vec<u8>,
}

/// A channel record with the number of messages found (or counted by the summary) on it.
#[derive(Debug, Clone)]
pub(crate) struct ChannelRec {
    pub topic: String,
    pub schema_id: u16,
    pub message_encoding: String,
    pub message_count: u64,
}

/// A place in the file holding messages.
#[derive(Debug, Clone)]
pub(crate) enum Unit {
    /// A chunk record starting at `offset` (opcode byte), `len` bytes long including opcode and
    /// length; `channels` lists the channel ids it holds messages of, when an index says so.
    Chunk {
        offset: u64,
        len: u64,
        channels: Option<Vec<u16>>,
    },
    /// A message record outside chunks.
    Message { offset: u64, len: u64 },
}

impl Unit {
    pub(crate) fn offset(&self) -> u64 {
        match self {
            Unit::Chunk { offset, .. } | Unit::Message { offset, .. } => *offset,
        }
    }
}

/// An MCAP metadata record: a name and a string map.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MetadataRecord {
    /// Record name, e.g. `magsep`, `magsep.summary`, or one a plugin added.
    pub name: String,
    /// Its key/value pairs.
    pub entries: BTreeMap<String, String>,
}

/// How the file ends.
#[derive(Debug, Default)]
pub(crate) enum End {
    /// Footer and closing magic present, every CRC checked passed.
    #[default]
    Complete,
    /// The file ends early; the message says where and how many frames are complete.
    Truncated(String),
    /// A damaged record stops the file here; the units before it are usable.
    Failed(RecordError),
}

/// Error of one record: damage (structure) or undecodable content.
pub(crate) enum RecErr {
    Corrupt(String),
    Decode(String),
}

impl From<String> for RecErr {
    fn from(s: String) -> Self {
        RecErr::Corrupt(s)
    }
}

impl RecErr {
    /// The error for the record at byte `offset`, described as `at`.
    pub(crate) fn at(self, offset: u64, at: &str) -> RecordError {
        match self {
            RecErr::Corrupt(e) => RecordError::Corrupt {
                offset,
                detail: format!("{at}: {e}"),
            },
            RecErr::Decode(e) => RecordError::Decode {
                detail: format!("{at}: {e}"),
            },
        }
    }
}

/// The header fields of a message record body; the payload is `body[20..]`.
pub(crate) struct MessageHead {
    pub channel_id: u16,
    pub sequence: u32,
    pub log_time: u64,
    pub publish_time: u64,
}

/// Bytes of a message record body before the payload.
pub(crate) const MESSAGE_HEAD_LEN: usize = 22;

pub(crate) fn message_head(body: &[u8]) -> Result<MessageHead, String> {
    let mut c = Cursor::new(body);
    Ok(MessageHead {
        channel_id: c.u16("channel id")?,
        sequence: c.u32("sequence")?,
        log_time: c.u64("log time")?,
        publish_time: c.u64("publish time")?,
    })
}

#[derive(Debug, Default)]
pub(crate) struct Layout {
    pub schemas: HashMap<u16, SchemaRec>,
    pub channels: BTreeMap<u16, ChannelRec>,
    pub units: Vec<Unit>,
    pub metadata_records: Vec<MetadataRecord>,
    pub metadata: Option<RecordingMetadata>,
    pub summary_json: Option<String>,
    /// Messages on `/state` found so far (complete frames, for truncation messages).
    pub state_messages: u64,
    pub end: End,
    /// Bytes after the closing magic: (offset of the first, count). Not part of the recording.
    pub trailing: Option<(u64, u64)>,
    /// Whether the layout comes from the summary section (else from a linear scan).
    pub indexed: bool,
    /// Chunks left out because their bytes are damaged (CRC, compression, record framing),
    /// in file order: the scan, and the iterators of an indexed file, go on past them.
    /// (byte offset, what is wrong) of each.
    pub skipped: Vec<(u64, String)>,
}

impl Layout {
    /// The ids of the channels on `topic` (`None`: all topics, no filter).
    pub(crate) fn channel_ids(&self, topic: Option<&str>) -> Option<Vec<u16>> {
        topic.map(|t| {
            self.channels
                .iter()
                .filter(|(_, c)| c.topic == t)
                .map(|(id, _)| *id)
                .collect()
        })
    }

    /// Records the damaged chunk at `offset` as skipped (once, however often it is met).
    pub(crate) fn note_skipped(&mut self, offset: u64, detail: String) {
        if !self.skipped.iter().any(|(at, _)| *at == offset) {
            self.skipped.push((offset, detail));
        }
    }

    pub(crate) fn schema(&mut self, body: &[u8]) -> Result<(), RecErr> {
        let mut c = Cursor::new(body);
        let id = c.u16("schema id")?;
        let name = c.string("schema name")?;
        let encoding = c.string("schema encoding")?;
        let data = c.bytes_u32("schema data")?.to_vec();
        if id == 0 {
            return Err(RecErr::Corrupt(format!(
                "schema {:?} has the reserved id 0",
                clip(&name)
            )));
        }
        self.schemas.insert(
            id,
            SchemaRec {
                name,
                encoding,
                data,
            },
        );
        Ok(())
    }

    pub(crate) fn channel(&mut self, body: &[u8]) -> Result<(), RecErr> {
        let mut c = Cursor::new(body);
        let id = c.u16("channel id")?;
        let schema_id = c.u16("schema id")?;
        let topic = c.string("topic")?;
        let message_encoding = c.string("message encoding")?;
        c.string_map("channel metadata")?;
        if schema_id != 0 && !self.schemas.contains_key(&schema_id) {
            return Err(RecErr::Corrupt(format!(
                "channel {:?} refers to schema id {schema_id}, which no earlier schema \
                 record defines",
                clip(&topic)
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
        Ok(())
    }

    /// Counts a message record of the linear scan.
    pub(crate) fn message(&mut self, body: &[u8]) -> Result<(), RecErr> {
        let head = message_head(body)?;
        let Some(channel) = self.channels.get_mut(&head.channel_id) else {
            return Err(RecErr::Corrupt(format!(
                "message on channel id {}, which no earlier channel record defines",
                head.channel_id
            )));
        };
        channel.message_count += 1;
        if channel.topic == STATE_TOPIC {
            self.state_messages += 1;
        }
        Ok(())
    }

    pub(crate) fn metadata_record(&mut self, body: &[u8]) -> Result<(), RecErr> {
        let mut c = Cursor::new(body);
        let name = c.string("metadata name")?;
        let entries = c.string_map("metadata map")?;
        if name == METADATA_NAME {
            self.metadata = Some(parse_metadata(&entries).map_err(RecErr::Decode)?);
        } else if name == SUMMARY_METADATA_NAME {
            let summary = entries.get("summary").ok_or_else(|| {
                RecErr::Decode(format!("metadata {:?} lacks key \"summary\"", clip(&name)))
            })?;
            self.summary_json = Some(summary.clone());
        }
        self.metadata_records.push(MetadataRecord { name, entries });
        Ok(())
    }
}
