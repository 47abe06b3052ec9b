//! Opening a finished recording through its summary section: schemas, channels, statistics,
//! chunk and metadata indexes, without reading the data section.

use super::chunk::ReaderLimits;
use super::layout::{End, Layout, Unit};
use super::source::Source;
use crate::STATE_TOPIC;
use crate::parse::Cursor;
use mcap::records::op;
use std::collections::BTreeMap;
use std::io::{Read, Seek};

/// Bytes of a footer record: opcode, length, summary start, summary offset start, CRC.
const FOOTER_LEN: u64 = 9 + 20;

/// The layout from the summary section, or `None` when the file has no usable summary (no
/// footer, no summary, a bad summary CRC, no statistics, messages outside chunks, any
/// inconsistency): the caller then scans the file linearly, which reports what is wrong.
pub(crate) fn indexed<R: Read + Seek>(
    src: &mut Source<R>,
    limits: &ReaderLimits,
) -> Option<Layout> {
    let magic = mcap::MAGIC;
    let mlen = magic.len() as u64;
    let len = src.len;
    if len < 2 * mlen + FOOTER_LEN || src.read_at(len - mlen, mlen).ok()? != magic {
        return None;
    }
    let footer_start = len - mlen - FOOTER_LEN;
    let footer = src.read_at(footer_start, FOOTER_LEN).ok()?;
    let mut c = Cursor::new(&footer);
    let (opcode, rlen) = (c.u8("opcode").ok()?, c.u64("length").ok()?);
    let summary_start = c.u64("summary start").ok()?;
    c.u64("summary offset start").ok()?;
    let crc = c.u32("summary CRC").ok()?;
    if opcode != op::FOOTER || rlen != 20 || summary_start < mlen || summary_start > footer_start {
        return None;
    }
    let size = footer_start - summary_start;
    if size > limits.max_record_bytes {
        return None;
    }
    // The summary CRC covers the summary section and the footer up to its CRC field.
    let bytes = src.read_at(summary_start, size + 9 + 16).ok()?;
    if crc != 0 && crc32fast::hash(&bytes) != crc {
        return None;
    }
    let mut layout = Layout {
        indexed: true,
        end: End::Complete,
        ..Default::default()
    };
    let mut counts = None;
    let mut metadata_indexes = Vec::new();
    let mut c = Cursor::new(&bytes[..size as usize]);
    while !c.rest().is_empty() {
        let opcode = c.u8("opcode").ok()?;
        let len = c.u64("length").ok()?;
        let body = c.take(len, "record").ok()?;
        match opcode {
            op::SCHEMA => layout.schema(body).ok()?,
            op::CHANNEL => layout.channel(body).ok()?,
            op::STATISTICS => counts = Some(statistics(body).ok()?),
            op::CHUNK_INDEX => layout.units.push(chunk_index(body, summary_start).ok()?),
            op::METADATA_INDEX => {
                let mut m = Cursor::new(body);
                let offset = m.u64("offset").ok()?;
                let length = m.u64("length").ok()?;
                metadata_indexes.push((offset, length));
            }
            _ => {}
        }
    }
    let (message_count, counts) = counts?;
    let chunked = layout.units.len() as u64;
    if message_count > 0 && chunked == 0 {
        return None; // Messages outside chunks: only a linear scan finds them.
    }
    for (id, channel) in &mut layout.channels {
        channel.message_count = counts.get(id).copied().unwrap_or(0);
        if channel.topic == STATE_TOPIC {
            layout.state_messages += channel.message_count;
        }
    }
    layout.units.sort_by_key(Unit::offset);
    for (offset, length) in metadata_indexes {
        if offset.checked_add(length)? > summary_start
            || length > limits.max_record_bytes
            || length < 9
        {
            return None;
        }
        let record = src.read_at(offset, length).ok()?;
        if record[0] != op::METADATA {
            return None;
        }
        layout.metadata_record(&record[9..]).ok()?;
    }
    Some(layout)
}

/// `(message count, channel id -> message count)` of a statistics record.
fn statistics(body: &[u8]) -> Result<(u64, BTreeMap<u16, u64>), String> {
    let mut c = Cursor::new(body);
    let message_count = c.u64("message count")?;
    c.u16("schema count")?;
    c.u32("channel count")?;
    c.u32("attachment count")?;
    c.u32("metadata count")?;
    c.u32("chunk count")?;
    c.u64("message start time")?;
    c.u64("message end time")?;
    let counts = c.u16_u64_map("channel message counts")?;
    Ok((message_count, counts))
}

/// The chunk a chunk index points to, which must lie before the summary section.
fn chunk_index(body: &[u8], summary_start: u64) -> Result<Unit, String> {
    let mut c = Cursor::new(body);
    c.u64("message start time")?;
    c.u64("message end time")?;
    let offset = c.u64("chunk start offset")?;
    let len = c.u64("chunk length")?;
    let channels = c.u16_u64_map("message index offsets")?;
    if offset
        .checked_add(len)
        .is_none_or(|end| end > summary_start)
        || len < 9
    {
        return Err(format!(
            "chunk index points to bytes {offset}+{len}, beyond the data section"
        ));
    }
    Ok(Unit::Chunk {
        offset,
        len,
        // A writer without message indexes leaves this empty: the chunk's channels are unknown.
        channels: (!channels.is_empty()).then(|| channels.into_keys().collect()),
    })
}
