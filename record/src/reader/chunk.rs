//! Chunk records: bounded decompression, CRC check, and the records inside.

use crate::parse::Cursor;
use mcap::records::op;
use std::io::Read;
use std::ops::Range;

/// Limits of the reader against damaged or crafted length fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReaderLimits {
    /// Largest record read into memory (bytes): a chunk, a message outside chunks, a metadata
    /// record, the summary section. A longer one is reported as corrupt. Lengths are also
    /// checked against the bytes left in the file before anything is read.
    pub max_record_bytes: u64,
    /// Largest decompressed chunk (bytes). The declared uncompressed size is checked against
    /// this before decompressing, and decompression stops as soon as the output would exceed
    /// the declared size.
    pub max_chunk_bytes: u64,
}

impl Default for ReaderLimits {
    /// 1 GiB records, 1 GiB decompressed chunks.
    fn default() -> Self {
        Self {
            max_record_bytes: 1 << 30,
            max_chunk_bytes: 1 << 30,
        }
    }
}

/// Bound on zstd's expansion ratio (an RLE block turns 4 bytes into at most 128 KiB).
const MAX_ZSTD_RATIO: u64 = 1 << 16;

/// Decompresses the chunk record body `body` and checks its CRC; returns the records it holds.
/// Memory: at most the declared uncompressed size (itself at most `limits.max_chunk_bytes`).
pub(crate) fn decompress(body: &[u8], limits: &ReaderLimits) -> Result<Vec<u8>, String> {
    let mut c = Cursor::new(body);
    c.u64("message start time")?;
    c.u64("message end time")?;
    let uncompressed = c.u64("uncompressed size")?;
    let crc = c.u32("uncompressed CRC")?;
    let compression = c.string("compression")?;
    let compressed = c.u64("compressed size")?;
    let data_len = c.rest().len() as u64;
    if compressed != data_len {
        return Err(format!(
            "compressed size {compressed} differs from the {data_len} data bytes in the record"
        ));
    }
    if uncompressed > limits.max_chunk_bytes {
        return Err(format!(
            "uncompressed size {uncompressed} exceeds the reader's limit of {} bytes",
            limits.max_chunk_bytes
        ));
    }
    let data = c.rest();
    let out = match compression.as_str() {
        "zstd" => {
            if uncompressed > compressed.saturating_mul(MAX_ZSTD_RATIO) {
                return Err(format!(
                    "uncompressed size {uncompressed} is impossible for {compressed} bytes of \
                     zstd data"
                ));
            }
            let decoder =
                zstd::stream::read::Decoder::new(data).map_err(|e| format!("zstd decoder: {e}"))?;
            // Never more than declared + 1 bytes: one more means the declared size is wrong.
            let mut out = Vec::with_capacity(uncompressed.min(1 << 24) as usize);
            decoder
                .take(uncompressed + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("zstd decompression failed: {e}"))?;
            if out.len() as u64 != uncompressed {
                return Err(format!(
                    "zstd data decompresses to {}{} bytes, but the chunk declares {uncompressed}",
                    out.len(),
                    if out.len() as u64 > uncompressed {
                        " or more"
                    } else {
                        ""
                    }
                ));
            }
            out
        }
        "" => {
            if uncompressed != compressed {
                return Err(format!(
                    "uncompressed chunk with uncompressed size {uncompressed} and compressed \
                     size {compressed}; expected both equal"
                ));
            }
            data.to_vec()
        }
        other => {
            return Err(format!(
                "compression {other:?} is not supported; expected \"zstd\" or \"\""
            ));
        }
    };
    if crc != 0 {
        let computed = crc32fast::hash(&out);
        if computed != crc {
            return Err(format!(
                "chunk CRC mismatch: the chunk stores 0x{crc:08x}, its {uncompressed} \
                 decompressed bytes give 0x{computed:08x}"
            ));
        }
    }
    Ok(out)
}

/// Splits the content of a chunk into records `(opcode, body range)`; only schema, channel,
/// message and metadata records may appear in a chunk.
pub(crate) fn split_records(data: &[u8]) -> Result<Vec<(u8, Range<usize>)>, String> {
    let mut out = Vec::new();
    let mut pos = 0usize;
    while pos < data.len() {
        let k = out.len();
        let left = data.len() - pos;
        if left < 9 {
            return Err(format!(
                "record #{k} in the chunk starts {left} bytes before its end (no room for an \
                 opcode and length)"
            ));
        }
        let opcode = data[pos];
        let mut len = [0u8; 8];
        len.copy_from_slice(&data[pos + 1..pos + 9]);
        let len = u64::from_le_bytes(len);
        if len > (left - 9) as u64 {
            return Err(format!(
                "record #{k} in the chunk declares {len} bytes but only {} follow",
                left - 9
            ));
        }
        if !matches!(
            opcode,
            op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA
        ) && opcode < 0x80
        {
            return Err(format!(
                "record #{k} in the chunk has opcode 0x{opcode:02x}, which does not belong in a \
                 chunk"
            ));
        }
        let body = pos + 9..pos + 9 + len as usize;
        pos = body.end;
        out.push((opcode, body));
    }
    Ok(out)
}
