//! Random access ([`RecordingReader::frame`], [`RecordingReader::unit_messages`]) against the
//! sequential readers, on files with one frame per chunk, many frames per chunk, and cut short.

use std::time::Duration;

use super::{TempFile, bits, metadata, random_frames, write_recording};
use crate::*;

/// `order` of frame indices read through [`RecordingReader::frame`], each compared bit for
/// bit with the whole-file reader's frame.
fn check_order(path: &std::path::Path, order: &[u64]) {
    let whole = read_recording(path).unwrap();
    let mut reader = RecordingReader::open(path).unwrap();
    for &i in order {
        let got = reader.frame(i).unwrap();
        match whole.frames.get(i as usize) {
            Some(want) => assert_eq!(bits(&got.expect("a frame")), bits(want), "frame {i}"),
            None => assert!(got.is_none(), "frame {i} past the end"),
        }
    }
}

fn orders(n: u64) -> Vec<Vec<u64>> {
    let forward: Vec<u64> = (0..=n + 1).collect();
    let backward: Vec<u64> = (0..=n + 1).rev().collect();
    // a fixed shuffle: i * 7 mod (n + 2)
    let jumps: Vec<u64> = (0..n + 2).map(|i| (i * 7) % (n + 2)).collect();
    vec![forward, backward, jumps]
}

#[test]
fn seek_frames_one_per_chunk_equal_the_sequential_reader() {
    let frames = random_frames(21, 25, true);
    let (path, _) = write_recording("seek-single.mcap", &frames, true);
    for order in orders(25) {
        check_order(&path, &order);
    }
}

#[test]
fn seek_frames_sharing_chunks_equal_the_sequential_reader() {
    let frames = random_frames(22, 37, true);
    let path = TempFile::new("seek-shared.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    // about five frames per chunk
    let per_frame = {
        let (_, bytes) = write_recording("seek-size.mcap", &frames[..1], false);
        bytes.len() as u64
    };
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: 5 * per_frame,
        max_wait: Duration::from_secs(3600),
    }));
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    w.finish().unwrap();
    let reader = RecordingReader::open(&path).unwrap();
    let state_units = reader.unit_count();
    assert!(
        (3..30).contains(&state_units),
        "expected chunks of several frames, got {state_units} units"
    );
    for order in orders(37) {
        check_order(&path, &order);
    }
}

#[test]
fn seek_a_truncated_file_gives_the_complete_frames_then_none() {
    let frames = random_frames(23, 20, true);
    let (_, bytes) = write_recording("seek-cut.mcap", &frames, true);
    // cut inside the chunk of frame 12 (chunk 0 holds the metadata)
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[1 + 12];
    let cut = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    let path = TempFile::new("seek-cut-short.mcap");
    std::fs::write(&path, &bytes[..cut]).unwrap();
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(reader.truncated().is_some());
    let complete = reader.frames().count() as u64;
    assert_eq!(complete, 12);
    for order in orders(complete) {
        check_order(&path, &order);
    }
}

#[test]
fn seek_unit_messages_concatenate_to_the_message_iterator() {
    let frames = random_frames(24, 12, true);
    let (path, _) = write_recording("seek-units.mcap", &frames, true);
    let mut reader = RecordingReader::open(&path).unwrap();
    for topic in [None, Some(STATE_TOPIC), Some("/scene"), Some("/nothing")] {
        let want: Vec<RawMessage> = reader.messages(topic).map(Result::unwrap).collect();
        let mut got = Vec::new();
        let mut k = 0;
        while let Some(unit) = reader.unit_messages(k, topic) {
            got.extend(unit.unwrap());
            k += 1;
        }
        assert_eq!(k, reader.unit_count());
        assert_eq!(got, want, "topic {topic:?}");
    }
    assert!(reader.unit_messages(reader.unit_count(), None).is_none());
}
