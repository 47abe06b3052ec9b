//! Bounds-checked parsing of MCAP record bodies (chunk headers, metadata), and CRC-32.
//!
//! The reader parses records itself rather than through `mcap::parse_record`, whose string
//! parsing reserves memory for a declared length before checking it against the data; here every
//! length is checked against the bytes actually present first.

use super::{METADATA_NAME, RecordingMetadata};
use std::collections::BTreeMap;

/// A cursor over one record body. Errors are human-readable descriptions.
pub(crate) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, pos: 0 }
    }

    /// Bytes not yet consumed.
    pub(crate) fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos..]
    }

    pub(crate) fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        let left = self.bytes.len() - self.pos;
        match usize::try_from(n) {
            Ok(n) if n <= left => {
                let out = &self.bytes[self.pos..self.pos + n];
                self.pos += n;
                Ok(out)
            }
            _ => Err(format!(
                "{what} needs {n} bytes at offset {} of the record body but only {left} remain",
                self.pos
            )),
        }
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(N as u64, what)?);
        Ok(out)
    }

    pub(crate) fn u16(&mut self, what: &str) -> Result<u16, String> {
        self.array(what).map(u16::from_le_bytes)
    }

    pub(crate) fn u32(&mut self, what: &str) -> Result<u32, String> {
        self.array(what).map(u32::from_le_bytes)
    }

    pub(crate) fn u64(&mut self, what: &str) -> Result<u64, String> {
        self.array(what).map(u64::from_le_bytes)
    }

    /// A `uint32` length-prefixed byte string.
    pub(crate) fn bytes_u32(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)?;
        self.take(u64::from(n), what)
    }

    /// A `uint32` length-prefixed UTF-8 string.
    pub(crate) fn string(&mut self, what: &str) -> Result<String, String> {
        let b = self.bytes_u32(what)?;
        String::from_utf8(b.to_vec()).map_err(|e| format!("{what} is not valid UTF-8: {e}"))
    }

    /// A `Map<string, string>`: `uint32` byte length, then key/value pairs.
    pub(crate) fn string_map(&mut self, what: &str) -> Result<BTreeMap<String, String>, String> {
        let body = self.bytes_u32(what)?;
        let mut inner = Cursor::new(body);
        let mut map = BTreeMap::new();
        while !inner.rest().is_empty() {
            let key = inner.string(&format!("{what} key"))?;
            let value = inner.string(&format!("{what} value for key {key:?}"))?;
            if map.insert(key.clone(), value).is_some() {
                return Err(format!("{what} has key {key:?} twice"));
            }
        }
        Ok(map)
    }
}

/// Largest chunk accepted (bytes, uncompressed).
const MAX_CHUNK_LEN: u64 = 1 << 36;
/// Bound on zstd's expansion ratio (an RLE block turns 4 bytes into at most 128 KiB).
const MAX_ZSTD_RATIO: u64 = 1 << 16;

/// Checks a chunk header for plausibility; returns the record length limit for decompression.
pub(crate) fn check_chunk_header(body: &[u8]) -> Result<usize, String> {
    let mut c = Cursor::new(body);
    c.u64("message start time")?;
    c.u64("message end time")?;
    let uncompressed = c.u64("uncompressed size")?;
    c.u32("uncompressed CRC")?;
    let compression = c.string("compression")?;
    let compressed = c.u64("compressed size")?;
    let data_len = c.rest().len() as u64;
    if compressed > data_len {
        return Err(format!(
            "compressed size {compressed} exceeds the {data_len} data bytes in the record"
        ));
    }
    match compression.as_str() {
        "zstd" => {
            if uncompressed > compressed.saturating_mul(MAX_ZSTD_RATIO)
                || uncompressed > MAX_CHUNK_LEN
            {
                return Err(format!(
                    "uncompressed size {uncompressed} is impossible for {compressed} bytes of \
                     zstd data (limit {MAX_CHUNK_LEN})"
                ));
            }
        }
        "" => {
            if uncompressed != compressed || compressed != data_len {
                return Err(format!(
                    "uncompressed chunk with uncompressed size {uncompressed}, compressed size \
                     {compressed} and {data_len} data bytes; expected all three equal"
                ));
            }
        }
        other => {
            return Err(format!(
                "compression {other:?} is not supported; expected \"zstd\" or \"\""
            ));
        }
    }
    let limit = uncompressed.max(compressed).max(4096);
    usize::try_from(limit).map_err(|_| format!("chunk of {limit} bytes is too large"))
}

/// Parses the `magsep` metadata map (see `RecordingWriter::create`).
pub(crate) fn parse_metadata(map: &BTreeMap<String, String>) -> Result<RecordingMetadata, String> {
    let get = |key: &str| {
        map.get(key)
            .ok_or_else(|| format!("metadata {METADATA_NAME:?} lacks key {key:?}"))
    };
    let bad = |key: &str, value: &str, e: &dyn std::fmt::Display| {
        format!("metadata {METADATA_NAME:?} key {key:?} has value {value:?}: {e}")
    };
    let seed = get("seed")?;
    let dt = get("dt")?;
    let schedule = get("schedule")?;
    Ok(RecordingMetadata {
        scene_text: get("scene_text")?.clone(),
        seed: seed.parse().map_err(|e| bad("seed", seed, &e))?,
        version: get("version")?.clone(),
        pipeline: get("pipeline")?.clone(),
        schedule: serde_json::from_str(schedule).map_err(|e| bad("schedule", schedule, &e))?,
        dt: dt.parse().map_err(|e| bad("dt", dt, &e))?,
    })
}

const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

/// CRC-32 (IEEE 802.3, as used by MCAP) of `data`.
pub(crate) fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c = CRC_TABLE[((c ^ u32::from(b)) & 0xff) as usize] ^ (c >> 8);
    }
    !c
}

/// Formats up to 8 bytes as hex, for error messages.
pub(crate) fn hex_prefix(data: &[u8]) -> String {
    data.iter()
        .take(8)
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_crc32_matches_reference_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn record_cursor_rejects_overlong_lengths() {
        let mut c = Cursor::new(&[0xff, 0xff, 0xff, 0xff, 1, 2]);
        assert!(c.string("name").is_err());
        let mut c = Cursor::new(&[2, 0, 0, 0, b'h', b'i', 9]);
        assert_eq!(c.string("name").unwrap(), "hi");
        assert_eq!(c.rest(), &[9]);
    }
}
