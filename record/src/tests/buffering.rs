//! Frames sharing chunks ([`RecordingWriter::buffer_frames`]): fewer chunks, the same frames,
//! and nothing lost when the writer is finished or dropped.

use std::time::Duration;

use super::{TempFile, assert_frames_bitwise_eq, metadata, random_frames};
use crate::frame::FibreShape;
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

/// Buffered chunks of nearly equal frames compress far beyond the reader's ratio limit (one
/// particle, a 1 MiB chunk, ~100:1): they must read back (they are exempt by size), with the
/// default buffering policy the pipelines use.
#[test]
fn a_full_buffered_chunk_of_similar_frames_reads_back() {
    let mut frame = random_frames(14, 1, false).remove(0);
    let path = TempFile::new("buffered_similar.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    w.buffer_frames(Some(FrameBuffering::default()));
    // a magnet's colour map, as the particle-fluid pipeline draws it
    w.set_backdrop(
        (0..20)
            .map(|k| crate::BackdropCube {
                center: glam::DVec3::new(0.5, 0.5, 0.05 * k as f64),
                size: glam::DVec3::new(1.0, 1.0, 0.05),
                colour: [0.9, 0.3, 0.2, 0.1],
            })
            .collect(),
    );
    let mut frames = Vec::new();
    for k in 0..6000u64 {
        frame.step = k;
        frame.time = k as f64 * 1e-3;
        w.write_frame(&frame, None).unwrap();
        frames.push(frame.clone());
    }
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let rec = read_recording_bytes(&bytes).unwrap();
    assert!(rec.truncated.is_none());
    assert_frames_bitwise_eq(&rec.frames, &frames);
    // the premise: a chunk beyond the 64:1 ratio limit, exempt because it is small
    let summary = mcap::Summary::read(&bytes).unwrap().expect("summary");
    let ratio = summary
        .chunk_indexes
        .iter()
        .map(|c| c.uncompressed_size / c.compressed_size.max(1))
        .max()
        .unwrap();
    assert!(ratio > 64, "best chunk ratio {ratio}");
}

/// Every message of `bytes` in file order: (channel topic, sequence, log time, payload).
fn messages(bytes: &[u8]) -> Vec<(String, u32, u64, Vec<u8>)> {
    mcap::MessageStream::new(bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            (
                m.channel.topic.clone(),
                m.sequence,
                m.log_time,
                m.data.to_vec(),
            )
        })
        .collect()
}

#[test]
fn queued_frames_encode_to_the_messages_of_unqueued_ones() {
    // small frames are queued and encoded in batches; a decoration change between frames
    // (fibres here) must apply to the frames after it only, as when each frame is encoded
    // at once
    let frames = random_frames(14, 150, true);
    let fibre = FibreShape {
        center: glam::DVec3::ZERO,
        axis: glam::DVec3::Z,
        radius: 0.1,
        half_length: 1.0,
    };
    // odd frames with colours
    let colours = |k: usize, n: usize| (k % 2 == 1).then(|| vec![[0.1, 0.2, 0.3, 1.0]; n]);
    // 0: each frame encoded at once; 1: queued (copied); 2: queued (moved, `write_frame_owned`)
    let write = |mode: usize| {
        let path = TempFile::new(&format!("queued{mode}.mcap"));
        let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
        if mode > 0 {
            w.buffer_frames(Some(FrameBuffering {
                max_bytes: u64::MAX,
                max_wait: Duration::from_secs(3600),
            }));
        }
        for (k, f) in frames.iter().enumerate() {
            if k == 70 {
                w.set_fibres(vec![fibre]);
            }
            let c = colours(k, f.ids.len());
            if mode == 2 {
                w.write_frame_owned(f.clone(), c).unwrap();
            } else {
                w.write_frame(f, c.as_deref()).unwrap();
            }
        }
        assert_eq!(w.frames_written(), frames.len() as u64);
        w.finish().unwrap();
        std::fs::read(&path).unwrap()
    };
    let (unqueued, queued, owned) = (write(0), write(1), write(2));
    let (a, b) = (messages(&queued), messages(&unqueued));
    assert_eq!(a.len(), 2 * frames.len());
    assert!(a == b, "queued frames gave other messages");
    assert!(
        messages(&owned) == b,
        "frames queued by value gave other messages"
    );
    // the fibres are drawn from frame 70 on, not before
    let scene = |k: usize| &a[2 * k + 1].3;
    assert!(scene(71).len() > scene(69).len());
}
