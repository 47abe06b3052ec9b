//! The background writer ([`RecordingWriter::create_background`]): the same file as a plain
//! writer given the same calls; errors of its thread returned by a later call, never a panic.

use crate::testing::FullDisk;
use std::io::Cursor;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::{TempFile, assert_frames_bitwise_eq, metadata, random_frames};
use crate::frame::FibreShape;
use crate::{
    FrameBuffering, RecordingMetadata, RecordingWriter, read_recording, read_recording_bytes,
};
use glam::DVec3;

/// The same calls on `w`: frames (some with colours), decoration, a channel and its messages,
/// metadata, the summary and the interrupted record; then finish.
fn write_all(mut w: RecordingWriter) {
    let frames = random_frames(31, 150, true);
    w.buffer_frames(Some(FrameBuffering {
        max_bytes: 1 << 14,
        max_wait: Duration::from_secs(3600),
    }));
    let fibre = FibreShape {
        center: DVec3::ZERO,
        axis: DVec3::Z,
        radius: 1e-5,
        half_length: 1e-3,
    };
    w.set_fibres(vec![fibre]);
    let channel = w.add_channel("/energy", "", "", &[], "json").unwrap();
    for (i, f) in frames.iter().enumerate() {
        let colours = vec![[0.5, 0.25, 1.0, 1.0]; f.ids.len()];
        if i % 3 == 0 {
            w.write_frame(f, Some(&colours)).unwrap();
        } else {
            w.write_frame_owned(f.clone(), None).unwrap();
        }
        if i % 40 == 7 {
            w.write_message(channel, i as u64, format!("{{\"e\": {i}}}").as_bytes())
                .unwrap();
        }
        if i == 90 {
            w.set_semi_axes(vec![DVec3::ONE; f.ids.len()]);
            w.add_metadata("plugin", [("k".to_string(), "v".to_string())].into())
                .unwrap();
        }
    }
    assert_eq!(w.frames_written(), frames.len() as u64);
    w.write_interrupted("SIGINT").unwrap();
    w.write_summary(r#"{"steps": 3}"#).unwrap();
    w.finish().unwrap();
}

#[test]
fn a_background_writer_writes_the_same_bytes_as_a_plain_one() {
    let plain = TempFile::new("bg_plain.mcap");
    let background = TempFile::new("bg_thread.mcap");
    write_all(RecordingWriter::create(&plain, &metadata()).unwrap());
    write_all(RecordingWriter::create_background(&background, &metadata()).unwrap());
    let a = std::fs::read(&plain).unwrap();
    let b = std::fs::read(&background).unwrap();
    assert!(a.len() > 10_000);
    assert!(a == b, "files differ ({} and {} bytes)", a.len(), b.len());
    let rec = read_recording_bytes(&b).unwrap();
    assert_eq!(rec.frames.len(), 150);
}

#[test]
fn a_dropped_background_writer_leaves_every_frame_readable() {
    let frames = random_frames(32, 40, true);
    let path = TempFile::new("bg_drop.mcap");
    let mut w = RecordingWriter::create_background(&path, &metadata()).unwrap();
    w.buffer_frames(Some(FrameBuffering::default()));
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    drop(w);
    let rec = read_recording(&path).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames);
}

#[test]
fn a_background_writer_returns_a_bad_call_at_once_and_goes_on() {
    let path = TempFile::new("bg_bad_call.mcap");
    let mut w = RecordingWriter::create_background(&path, &metadata()).unwrap();
    let err = w.add_channel("/state", "", "", &[], "json").unwrap_err();
    assert!(err.to_string().contains("reserved"), "{err}");
    let frames = random_frames(33, 3, true);
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    w.finish().unwrap();
    assert_frames_bitwise_eq(&read_recording(&path).unwrap().frames, &frames);
}

#[test]
fn a_background_writer_cannot_create_a_file_in_a_missing_directory() {
    let err = RecordingWriter::create_background(
        Path::new("/nonexistent-dir/x.mcap"),
        &RecordingMetadata::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("/nonexistent-dir/x.mcap"), "{err}");
}

#[test]
fn a_full_disk_is_reported_by_a_later_call_and_what_was_written_stays_readable() {
    let data = Arc::new(Mutex::new(Cursor::new(Vec::new())));
    let sink = FullDisk {
        data: data.clone(),
        limit: 30_000,
    };
    let name = Path::new("/full/disk.mcap");
    let mut w = RecordingWriter::background_from_sink(name, Box::new(sink), &metadata()).unwrap();
    let frames = random_frames(34, 400, true);
    let mut failed = None;
    for f in &frames {
        if let Err(e) = w.write_frame(f, None) {
            failed = Some(e.to_string());
            break;
        }
    }
    let message = match failed {
        Some(m) => m,
        None => w.finish().unwrap_err().to_string(),
    };
    assert!(message.contains("/full/disk.mcap"), "{message}");
    assert!(message.contains("No space left on device"), "{message}");
    let bytes = data.lock().unwrap().get_ref().clone();
    assert!(bytes.len() as u64 <= 30_000);
    let rec = read_recording_bytes(&bytes).unwrap();
    assert!(!rec.frames.is_empty());
    assert!(rec.frames.len() < frames.len());
}

#[test]
fn every_call_after_the_reported_error_fails_without_a_panic() {
    let data = Arc::new(Mutex::new(Cursor::new(Vec::new())));
    let sink = FullDisk {
        data: data.clone(),
        limit: 100,
    };
    let name = Path::new("/full/tiny.mcap");
    // the header does not fit: the writer thread fails before any call
    let mut w = RecordingWriter::background_from_sink(name, Box::new(sink), &metadata()).unwrap();
    let frames = random_frames(35, 2, true);
    let first = loop {
        if let Err(e) = w.write_frame(&frames[0], None) {
            break e.to_string();
        }
    };
    assert!(first.contains("No space left on device"), "{first}");
    let later = w.write_frame(&frames[1], None).unwrap_err().to_string();
    assert!(
        later.contains("stopped at an earlier write error"),
        "{later}"
    );
    let finish = w.finish().unwrap_err().to_string();
    assert!(finish.contains("/full/tiny.mcap"), "{finish}");
}
