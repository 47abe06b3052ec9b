//! Frames sharing chunks ([`RecordingWriter::buffer_frames`]): fewer chunks, the same frames,
//! and nothing lost when the writer is finished or dropped.

use std::time::Duration;

use super::{TempFile, assert_frames_bitwise_eq, metadata, random_frames};
use crate::{FrameBuffering, RecordingWriter, read_recording, read_recording_bytes};

fn chunk_count(bytes: &[u8]) -> usize {
    let summary = mcap::Summary::read(bytes).unwrap().expect("summary");
    summary.stats.as_ref().unwrap().chunk_count as usize
}

#[test]
fn buffered_frames_share_chunks_and_read_back_bitwise() {
    let frames = random_frames(11, 40, true);
    let path = TempFile::new("buffered.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: u64::MAX,
        max_wait: Duration::from_secs(3600),
    }));
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // the metadata chunk, the first frame (written at once), the other 39 together
    assert_eq!(chunk_count(&bytes), 3);
    let rec = read_recording_bytes(&bytes).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames);
}

#[test]
fn buffered_frames_flush_by_size_and_on_drop() {
    let frames = random_frames(12, 30, true);
    let path = TempFile::new("buffered_drop.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: 1,
        max_wait: Duration::from_secs(3600),
    }));
    for f in &frames[..10] {
        w.write_frame(f, None).unwrap();
    }
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: u64::MAX,
        max_wait: Duration::from_secs(3600),
    }));
    for f in &frames[10..] {
        w.write_frame(f, None).unwrap();
    }
    // every frame past the byte limit ends its chunk; the rest wait until the drop
    drop(w);
    let rec = read_recording(&path).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(chunk_count(&bytes), 1 + 10 + 1);
}

#[test]
fn a_zero_wait_writes_every_frame_at_once() {
    let frames = random_frames(13, 8, true);
    let path = TempFile::new("buffered_zero.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: u64::MAX,
        max_wait: Duration::ZERO,
    }));
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(chunk_count(&bytes), 1 + frames.len());
}

/// A sink in memory that counts the syncs asked of it.
struct CountingSink {
    inner: std::io::Cursor<Vec<u8>>,
    syncs: std::sync::Arc<std::sync::atomic::AtomicUsize>,
}

impl std::io::Write for CountingSink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.inner.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl std::io::Seek for CountingSink {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(pos)
    }
}

impl crate::RecordingSink for CountingSink {
    fn sync(&mut self) -> std::io::Result<()> {
        self.syncs
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Ok(())
    }
}

#[test]
fn finish_syncs_only_when_asked() {
    use std::sync::atomic::Ordering;
    for synced in [false, true] {
        let syncs = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let sink = CountingSink {
            inner: std::io::Cursor::new(Vec::new()),
            syncs: syncs.clone(),
        };
        let name = std::path::Path::new("counting.mcap");
        let mut w = RecordingWriter::from_sink(name, Box::new(sink), &metadata()).unwrap();
        for f in &random_frames(13, 3, true) {
            w.write_frame(f, None).unwrap();
        }
        if synced {
            w.finish_synced().unwrap();
        } else {
            w.finish().unwrap();
        }
        assert_eq!(syncs.load(Ordering::Relaxed), usize::from(synced));
    }
}
