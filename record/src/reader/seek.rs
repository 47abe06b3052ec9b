//! Random access on a [`RecordingReader`]: `/state` frame `i` without decoding the frames
//! before it ([`RecordingReader::frame`]), and the messages of one unit (a chunk, or a message
//! record outside chunks) at a time ([`RecordingReader::unit_messages`]), for callers that
//! cannot hold a borrowing iterator (the Python package) or that jump around a long file.
//!
//! Memory stays bounded whatever the file's size: one count per unit read so far, and the
//! `/state` messages of the last unit read.

use super::stream::{RawMessage, RecordingReader};
use crate::proto::ParticleStateWire;
use crate::reader::layout::Unit;
use crate::{ParticleFrame, RecordError, STATE_TOPIC};
use std::io::{Read, Seek};

/// What [`RecordingReader::frame`] has learnt of the file so far.
#[derive(Debug, Default)]
pub(crate) struct FrameIndex {
    /// `starts[k]`: the `/state` messages in the units before unit `k`, for the units counted
    /// so far (`starts.len() - 1` of them).
    starts: Vec<u64>,
    /// The last unit read for its frames, and its `/state` messages.
    cached: Option<(usize, Vec<RawMessage>)>,
}

/// Decodes the `/state` message `m`, frame number `number` of the file; `bad_encoding` is the
/// channel's message encoding when it is not `protobuf`.
pub(crate) fn decode_frame(
    m: &RawMessage,
    number: u64,
    bad_encoding: Option<&str>,
) -> Result<ParticleFrame, RecordError> {
    if let Some(enc) = bad_encoding {
        return Err(RecordError::Decode {
            detail: format!("{STATE_TOPIC} has message encoding {enc:?}, expected \"protobuf\""),
        });
    }
    ParticleStateWire::decode_payload(&m.data)
        .and_then(ParticleStateWire::into_frame)
        .map_err(|e| RecordError::Decode {
            detail: format!(
                "{STATE_TOPIC} frame #{number} (in the record at byte {}): {e}",
                m.offset
            ),
        })
}

impl<R: Read + Seek> RecordingReader<R> {
    /// The `/state` channel's message encoding when it is not `protobuf` (its frames cannot be
    /// decoded).
    pub(crate) fn state_encoding_error(&self) -> Option<String> {
        self.layout
            .channels
            .values()
            .find(|c| c.topic == STATE_TOPIC && c.message_encoding != "protobuf")
            .map(|c| c.message_encoding.clone())
    }

    /// Number of units holding messages: chunks, and message records outside chunks (see
    /// [`unit_messages`](Self::unit_messages)).
    pub fn unit_count(&self) -> usize {
        self.layout.units.len()
    }

    /// The messages on `topic` (all topics for `None`) in unit `unit` (`0..unit_count()`), in
    /// file order; `None` past the last unit. Reading unit after unit gives what
    /// [`messages`](Self::messages) yields, without borrowing the reader between calls; after
    /// the last unit, [`damage`](Self::damage) tells whether a damaged record ended the file.
    /// A chunk whose bytes are damaged gives no messages (`Ok` and empty), as the iterators
    /// skip it; [`damage`](Self::damage) names it ([`RecordError::SkippedChunks`]).
    pub fn unit_messages(
        &mut self,
        unit: usize,
        topic: Option<&str>,
    ) -> Option<Result<Vec<RawMessage>, RecordError>> {
        let u = self.layout.units.get(unit)?.clone();
        let wanted = self.layout.channel_ids(topic);
        if let (
            Some(wanted),
            Unit::Chunk {
                channels: Some(has),
                ..
            },
        ) = (&wanted, &u)
            && !wanted.iter().any(|id| has.contains(id))
        {
            return Some(Ok(Vec::new()));
        }
        let accept = move |id: u16| wanted.as_ref().is_none_or(|w| w.contains(&id));
        Some(match self.load(&u, &accept) {
            // a chunk whose bytes are damaged: skipped, as by the iterators (the index says
            // where the next unit starts)
            Err(RecordError::Corrupt { offset, detail }) if matches!(u, Unit::Chunk { .. }) => {
                self.layout.note_skipped(offset, detail);
                Ok(Vec::new())
            }
            other => other,
        })
    }

    /// The `/state` frame number `index` (0 is the first) decoded, reading only the units up
    /// to the one that holds it (each unit is read once to count its frames; the last one read
    /// is kept, so reading frames in order reads each unit once). `Ok(None)` past the last
    /// complete frame of an intact or truncated file; the damage error past the last readable
    /// frame of a damaged one. Chunks whose bytes are damaged are skipped (their frames are not
    /// numbered), as by [`frames`](Self::frames).
    ///
    /// # Errors
    /// A damaged or unreadable record before the frame, or an undecodable frame.
    pub fn frame(&mut self, index: u64) -> Result<Option<ParticleFrame>, RecordError> {
        let bad_encoding = self.state_encoding_error();
        let mut idx = std::mem::take(&mut self.frame_index);
        let found = self.find_unit(&mut idx, index);
        let result = found.and_then(|found| {
            let Some(unit) = found else {
                return self.damage().map_or(Ok(None), Err);
            };
            let messages = match idx.cached.take() {
                Some((k, m)) if k == unit => m,
                _ => self
                    .unit_messages(unit, Some(STATE_TOPIC))
                    .unwrap_or(Ok(Vec::new()))?,
            };
            let local = (index - idx.starts[unit]) as usize;
            let frame = messages
                .get(local)
                .map(|m| decode_frame(m, index, bad_encoding.as_deref()))
                .transpose();
            idx.cached = Some((unit, messages));
            frame
        });
        self.frame_index = idx;
        result
    }

    /// The unit holding `/state` frame `index`, counting the units not counted yet up to it
    /// (`None`: the file has fewer frames).
    fn find_unit(
        &mut self,
        idx: &mut FrameIndex,
        index: u64,
    ) -> Result<Option<usize>, RecordError> {
        if idx.starts.is_empty() {
            idx.starts.push(0);
        }
        loop {
            let counted = idx.starts.len() - 1;
            if idx.starts[counted] > index {
                // `starts` does not decrease: the last unit starting at or before `index`
                // (starts[0] = 0 <= index < starts[counted])
                return Ok(Some(idx.starts.partition_point(|&s| s <= index) - 1));
            }
            let Some(messages) = self.unit_messages(counted, Some(STATE_TOPIC)) else {
                return Ok(None);
            };
            // a chunk whose bytes are damaged gives no frames (skipped by `unit_messages`)
            let messages = messages?;
            let end = idx.starts[counted] + messages.len() as u64;
            idx.starts.push(end);
            idx.cached = Some((counted, messages));
        }
    }
}
