//! Chunk records: bounded decompression, CRC check, and the records inside.
//!
//! Decompression bounds (defaults of [`ReaderLimits`]): a chunk may declare at most 1 GiB
//! uncompressed, and at most 64 times its compressed size unless it is at most 1 MiB
//! uncompressed. Both are checked before anything is allocated; one buffer of the declared
//! size is then allocated fallibly and filled, and data decompressing to more or less than
//! declared is an error. Real chunks compress by 1.7-4.4 (see [`ReaderLimits`]).

use crate::parse::Cursor;
use mcap::records::op;
use std::io::Read;
use std::ops::Range;

/// Limits of the reader against damaged or crafted length fields and compression bombs.
///
/// The defaults bound the memory of one chunk to [`ReaderLimits::max_chunk_bytes`] (1 GiB)
/// and to [`ReaderLimits::max_compression_ratio`] (64) times its compressed size (chunks that
/// decompress to at most [`RATIO_FREE_BYTES`], 1 MiB, are exempt from the ratio). Real
/// recordings stay far inside both: the chunks of the shipped scenes' recordings compress by
/// 1.7-4.4 (the large ones, 0.1-17 MB, by 1.7-2.8), and a frame takes 240 (spheres) to 550
/// (spherocylinders) bytes per particle before compression, so a 1 GiB chunk is a frame of
/// 2-4 million particles; [`RecordingWriter`](crate::RecordingWriter) refuses to write a
/// frame the default reader would refuse. A 33 KB zstd bomb declaring 1 GiB is refused
/// before anything is allocated (`recordings/README.md` has the measurements).
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
    /// Largest ratio of a chunk's declared uncompressed size to its compressed size, for
    /// chunks larger than [`RATIO_FREE_BYTES`] uncompressed.
    pub max_compression_ratio: u64,
}

impl Default for ReaderLimits {
    /// 1 GiB records, 1 GiB decompressed chunks, compression ratio at most 64.
    fn default() -> Self {
        Self {
            max_record_bytes: 1 << 30,
            max_chunk_bytes: MAX_CHUNK_BYTES,
            max_compression_ratio: 64,
        }
    }
}

/// Default [`ReaderLimits::max_chunk_bytes`] (1 GiB); the writer refuses larger frames.
pub const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Chunks that decompress to at most this many bytes (16 MiB) are exempt from
/// [`ReaderLimits::max_compression_ratio`]: small chunks (schemas, a frame of few particles,
/// the up-to-1-MiB chunks of buffered frames, which compress ~100:1 when frames differ little)
/// may compress well without costing much memory.
pub const RATIO_FREE_BYTES: u64 = 16 << 20;

/// Decompresses the chunk record body `body` and checks its CRC; returns the records it holds.
/// Memory: at most what the data decompresses to (grown as it comes, up to twice that in
/// capacity), never past the declared uncompressed size, which is checked first against
/// `limits.max_chunk_bytes` and against `limits.max_compression_ratio` times the compressed
/// size.
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
            let allowed = compressed
                .saturating_mul(limits.max_compression_ratio)
                .max(RATIO_FREE_BYTES);
            if uncompressed > allowed {
                return Err(format!(
                    "uncompressed size {uncompressed} for {compressed} bytes of zstd data is a \
                     compression ratio above the reader's limit of {}:1 (a compression bomb or \
                     a damaged size)",
                    limits.max_compression_ratio
                ));
            }
            inflate(data, uncompressed)?
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
                "compression {:?} is not supported; expected \"zstd\" or \"\"",
                crate::parse::clip(other)
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

/// Decompresses the zstd `data` into exactly `size` bytes (checked by the caller): one buffer
/// of that size, allocated fallibly, and an error if the data gives fewer or more bytes.
fn inflate(data: &[u8], size: u64) -> Result<Vec<u8>, String> {
    let n = usize::try_from(size).map_err(|_| format!("uncompressed size {size} is too large"))?;
    let mut decoder =
        zstd::stream::read::Decoder::new(data).map_err(|e| format!("zstd decoder: {e}"))?;
    // The output grows with what the data really decompresses to (never past `n`), so a
    // damaged declared size costs no memory beyond the chunk's true content.
    let mut out = Vec::new();
    let mut scratch = vec![0u8; n.min(64 << 10)];
    while out.len() < n {
        let want = (n - out.len()).min(scratch.len());
        match decoder.read(&mut scratch[..want]) {
            Ok(0) => break,
            Ok(k) => {
                out.try_reserve(k).map_err(|_| {
                    format!("cannot allocate {size} bytes for the decompressed chunk")
                })?;
                out.extend_from_slice(&scratch[..k]);
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(format!("zstd decompression failed: {e}")),
        }
    }
    let filled = out.len();
    if filled < n {
        return Err(format!(
            "zstd data decompresses to {filled} bytes, but the chunk declares {size}"
        ));
    }
    // One more byte means the declared size is wrong (never decompressed further).
    let mut probe = [0u8; 1];
    match decoder.read(&mut probe) {
        Ok(0) => Ok(out),
        Ok(_) => Err(format!(
            "zstd data decompresses to more than the {size} bytes the chunk declares"
        )),
        Err(e) => Err(format!("zstd decompression failed: {e}")),
    }
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
