//! Test sinks for code that writes recordings: check how a writer (or a plugin's channel)
//! behaves when the disk fills up, without filling a disk.

use std::io::{Cursor, Seek, SeekFrom, Write};
use std::sync::{Arc, Mutex};

use crate::writer::RecordingSink;

/// An in-memory sink that accepts `limit` bytes, then fails every write like a full disk
/// (`ENOSPC`, "No space left on device"). `data` holds what was written, shared so a test can
/// read it back after the writer is gone.
///
/// ```
/// use std::io::Write;
/// let mut disk = magsep_record::testing::FullDisk::new(4);
/// assert_eq!(disk.write(b"abcdef").unwrap(), 4);
/// assert_eq!(disk.write(b"g").unwrap_err().raw_os_error(), Some(28));
/// assert_eq!(disk.data.lock().unwrap().get_ref().as_slice(), b"abcd");
/// ```
#[derive(Debug, Clone)]
pub struct FullDisk {
    /// The bytes written so far (and the write position).
    pub data: Arc<Mutex<Cursor<Vec<u8>>>>,
    /// Bytes accepted before the disk is full.
    pub limit: u64,
}

impl FullDisk {
    /// An empty disk that holds `limit` bytes.
    pub fn new(limit: u64) -> Self {
        Self {
            data: Arc::new(Mutex::new(Cursor::new(Vec::new()))),
            limit,
        }
    }
}

impl Write for FullDisk {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let mut c = self
            .data
            .lock()
            .map_err(|_| std::io::Error::other("poisoned test sink"))?;
        let room = self.limit.saturating_sub(c.position()) as usize;
        if room == 0 && !buf.is_empty() {
            return Err(std::io::Error::from_raw_os_error(28));
        }
        c.write(&buf[..buf.len().min(room)])
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for FullDisk {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.data
            .lock()
            .map_err(|_| std::io::Error::other("poisoned test sink"))?
            .seek(pos)
    }
}

impl RecordingSink for FullDisk {}
