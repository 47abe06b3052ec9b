//! Positioned reads from a file (or any `Read + Seek`) of known length.

use std::io::{self, Read, Seek, SeekFrom};

/// Block size of streaming reads that hash or skip bytes.
const BLOCK: usize = 1 << 16;

pub(crate) struct Source<R> {
    inner: R,
    /// Total length (bytes).
    pub len: u64,
}

impl<R: Read + Seek> Source<R> {
    pub(crate) fn new(mut inner: R) -> io::Result<Self> {
        let len = inner.seek(SeekFrom::End(0))?;
        Ok(Self { inner, len })
    }

    /// Reads `n` bytes at `offset`. The caller has checked `offset + n <= len`, so `n` is
    /// bounded by the file size.
    pub(crate) fn read_at(&mut self, offset: u64, n: u64) -> io::Result<Vec<u8>> {
        let n = usize::try_from(n)
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "read too large"))?;
        self.inner.seek(SeekFrom::Start(offset))?;
        let mut buf = vec![0u8; n];
        self.inner.read_exact(&mut buf)?;
        Ok(buf)
    }

    /// Up to `n` bytes at `offset` (fewer at the end of the file).
    pub(crate) fn read_upto(&mut self, offset: u64, n: u64) -> io::Result<Vec<u8>> {
        let n = n.min(self.len.saturating_sub(offset));
        self.read_at(offset, n)
    }

    /// Feeds bytes `from..to` to `hasher` in blocks (bounded memory).
    pub(crate) fn hash_range(
        &mut self,
        from: u64,
        to: u64,
        hasher: &mut crc32fast::Hasher,
    ) -> io::Result<()> {
        self.inner.seek(SeekFrom::Start(from))?;
        let mut left = to.saturating_sub(from);
        let mut buf = vec![0u8; BLOCK];
        while left > 0 {
            let n = left.min(BLOCK as u64) as usize;
            self.inner.read_exact(&mut buf[..n])?;
            hasher.update(&buf[..n]);
            left -= n as u64;
        }
        Ok(())
    }
}
