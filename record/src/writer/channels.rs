//! Channels and metadata records that plugins add to a recording.

use super::RecordingWriter;
use crate::schema::ProtobufSchema;
use crate::{
    INTERRUPTED_METADATA_NAME, METADATA_NAME, RecordError, SCENE_TOPIC, STATE_TOPIC,
    SUMMARY_METADATA_NAME,
};
use mcap::records::MessageHeader;
use std::collections::BTreeMap;

/// A channel added with [`RecordingWriter::add_channel`], for
/// [`RecordingWriter::write_message`]. Valid only with the writer that returned it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ChannelHandle {
    /// MCAP channel id.
    pub(crate) id: u16,
    /// Index into the writer's channel table.
    pub(crate) index: usize,
}

/// Book-keeping of one added channel.
#[derive(Debug, Clone)]
pub(crate) struct AddedChannel {
    pub topic: String,
    pub id: u16,
    /// Messages written so far (the next MCAP sequence number, mod 2^32).
    pub written: u64,
}

impl RecordingWriter {
    /// Adds a channel on `topic` with its schema (`schema_name`, `schema_encoding`,
    /// `schema_data`, e.g. `protobuf` and an encoded `FileDescriptorSet`, or `""` and no data
    /// for a schemaless channel) and `message_encoding` (e.g. `protobuf`, `json`). May be called
    /// at any time before [`finish`](Self::finish); the schema and channel records are flushed
    /// to the file at once.
    ///
    /// Fails with [`RecordError::InvalidInput`] for an empty topic, the reserved topics
    /// [`STATE_TOPIC`] and [`SCENE_TOPIC`], or a topic already added.
    pub fn add_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_encoding: &str,
        schema_data: &[u8],
        message_encoding: &str,
    ) -> Result<ChannelHandle, RecordError> {
        if topic == STATE_TOPIC || topic == SCENE_TOPIC {
            return Err(RecordError::InvalidInput {
                detail: format!("topic {topic:?} is reserved for the recorder's own channel"),
            });
        }
        if topic.is_empty() || self.channels.iter().any(|c| c.topic == topic) {
            return Err(RecordError::InvalidInput {
                detail: format!("topic {topic:?} is empty or already has a channel"),
            });
        }
        if let Some(bg) = &mut self.background {
            let (topic, name) = (topic.to_string(), schema_name.to_string());
            let (encoding, data) = (schema_encoding.to_string(), schema_data.to_vec());
            let message = message_encoding.to_string();
            return bg.call(move |w| w.add_channel(&topic, &name, &encoding, &data, &message));
        }
        self.drain_queue()?;
        let schema_id = if schema_encoding.is_empty() && schema_data.is_empty() {
            0
        } else {
            let result = self
                .mcap()
                .add_schema(schema_name, schema_encoding, schema_data);
            result.map_err(|e| self.write_error(e))?
        };
        let result = self
            .mcap()
            .add_channel(schema_id, topic, message_encoding, &BTreeMap::new());
        let id = result.map_err(|e| self.write_error(e))?;
        self.flush()?;
        self.channels.push(AddedChannel {
            topic: topic.to_string(),
            id,
            written: 0,
        });
        Ok(ChannelHandle {
            id,
            index: self.channels.len() - 1,
        })
    }

    /// Adds a `protobuf` channel on `topic` whose schema is `schema` (see
    /// [`protobuf_schema`](crate::protobuf_schema)): readers decode it from the file alone.
    pub fn add_protobuf_channel(
        &mut self,
        topic: &str,
        schema: &ProtobufSchema,
    ) -> Result<ChannelHandle, RecordError> {
        self.add_channel(
            topic,
            &schema.name,
            &schema.encoding,
            &schema.data,
            "protobuf",
        )
    }

    /// Writes one message on `channel` with log and publish time `log_time_ns` \[ns\], then
    /// ends the chunk and flushes the file, so the message survives a killed process.
    pub fn write_message(
        &mut self,
        channel: ChannelHandle,
        log_time_ns: u64,
        data: &[u8],
    ) -> Result<(), RecordError> {
        self.write_messages(&[(channel, log_time_ns, data)])
    }

    /// Writes a batch of messages `(channel, log time [ns], payload)` in one chunk, then ends
    /// the chunk and flushes the file once.
    pub fn write_messages(
        &mut self,
        messages: &[(ChannelHandle, u64, &[u8])],
    ) -> Result<(), RecordError> {
        if let Some(bg) = &mut self.background {
            let owned: Vec<_> = messages.iter().map(|m| (m.0, m.1, m.2.to_vec())).collect();
            let weight = owned.iter().map(|m| m.2.len()).sum();
            return bg.send(
                Box::new(move |w| {
                    let borrowed: Vec<_> = owned.iter().map(|m| (m.0, m.1, &m.2[..])).collect();
                    w.write_messages(&borrowed)
                }),
                weight,
            );
        }
        for (channel, _, _) in messages {
            if self.channels.get(channel.index).map(|c| c.id) != Some(channel.id) {
                return Err(RecordError::InvalidInput {
                    detail: format!(
                        "channel handle {channel:?} was not returned by this writer's add_channel"
                    ),
                });
            }
        }
        self.drain_queue()?;
        for &(channel, log_time, data) in messages {
            let added = &mut self.channels[channel.index];
            // MCAP sequence numbers are u32; wrapping after 2^32 messages is harmless.
            let sequence = added.written as u32;
            added.written += 1;
            let header = MessageHeader {
                channel_id: channel.id,
                sequence,
                log_time,
                publish_time: log_time,
            };
            let result = self.mcap().write_to_known_channel(&header, data);
            result.map_err(|e| self.write_error(e))?;
        }
        self.flush()
    }

    /// Writes the MCAP metadata record `name` with `entries`, then flushes. For metadata that
    /// plugins add; readers list every record in file order (`metadata_records`).
    ///
    /// Fails with [`RecordError::InvalidInput`] for an empty name or the reserved names
    /// [`METADATA_NAME`], [`SUMMARY_METADATA_NAME`] and [`INTERRUPTED_METADATA_NAME`] (use
    /// [`write_summary`](Self::write_summary) and
    /// [`write_interrupted`](Self::write_interrupted) for the latter two).
    pub fn add_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), RecordError> {
        if name.is_empty()
            || name == METADATA_NAME
            || name == SUMMARY_METADATA_NAME
            || name == INTERRUPTED_METADATA_NAME
        {
            return Err(RecordError::InvalidInput {
                detail: format!("metadata name {name:?} is empty or reserved"),
            });
        }
        self.write_metadata(name, entries)
    }
}
