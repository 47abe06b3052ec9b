//! Bounds-checked parsing of MCAP record bodies.
//!
//! The reader parses records itself rather than through `mcap::parse_record`, whose string
//! parsing reserves memory for a declared length before checking it against the data; here every
//! length is checked against the bytes actually present first.

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

    pub(crate) fn u8(&mut self, what: &str) -> Result<u8, String> {
        self.array(what).map(u8::from_le_bytes)
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

    /// A `Map<uint16, uint64>`: `uint32` byte length, then key/value pairs.
    pub(crate) fn u16_u64_map(&mut self, what: &str) -> Result<BTreeMap<u16, u64>, String> {
        let body = self.bytes_u32(what)?;
        let mut inner = Cursor::new(body);
        let mut map = BTreeMap::new();
        while !inner.rest().is_empty() {
            let key = inner.u16(&format!("{what} key"))?;
            let value = inner.u64(&format!("{what} value for key {key}"))?;
            map.insert(key, value);
        }
        Ok(map)
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

/// Formats up to 8 bytes as hex, for error messages.
/// `s` cut to 64 characters (with `...`): strings read from a damaged file are quoted in
/// error messages, never at full length.
pub(crate) fn clip(s: &str) -> String {
    const MAX: usize = 64;
    match s.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

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
        // The CRC-32 (IEEE 802.3) that MCAP specifies.
        assert_eq!(crc32fast::hash(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32fast::hash(b""), 0);
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
