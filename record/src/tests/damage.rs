//! Tests of damaged recordings: killed writers, cut files, corrupt and fuzzed bytes.

use super::{TempFile, assert_frames_bitwise_eq, bits, metadata, random_frames, write_recording};
use crate::*;
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

#[test]
fn record_killed_writer_leaves_every_frame_readable() {
    let frames = random_frames(21, 6, true);
    let path = TempFile::new("killed.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    for f in &frames {
        w.write_frame(f, None).unwrap();
    }
    // Simulate a kill: no finish, no drop, no buffered data written after the last flush.
    std::mem::forget(w);
    let mut bytes = std::fs::read(&path).unwrap();
    let rec = read_recording_bytes(&bytes).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames);
    assert_eq!(rec.metadata, Some(metadata()));
    let msg = rec.truncated.unwrap();
    assert!(
        msg.contains("after a complete record") && msg.contains("6 complete frames"),
        "{msg}"
    );

    // Killed while a chunk was being written: its header still holds the placeholder length.
    let start = bytes.len();
    bytes.push(0x06);
    bytes.extend_from_slice(&u64::MAX.to_le_bytes());
    bytes.extend_from_slice(&[0; 30]);
    let rec = read_recording_bytes(&bytes).unwrap();
    assert_eq!(rec.frames.len(), 6);
    let msg = rec.truncated.unwrap();
    assert!(msg.contains(&format!("starts at byte {start}")) && msg.contains("placeholder"));
}

#[test]
fn record_truncated_files_yield_a_prefix_of_frames() {
    let frames = random_frames(99, 8, false);
    let (_, bytes) = write_recording("cut.mcap", &frames, true);
    let full = read_recording_bytes(&bytes).unwrap();
    let mut last_count = 0;
    let mut metadata_seen_at = None;
    for cut in (0..bytes.len()).step_by(3).chain([1, 8, 10, 17]) {
        let rec =
            read_recording_bytes(&bytes[..cut]).unwrap_or_else(|e| panic!("cut at {cut}: {e}"));
        let msg = rec.truncated.as_ref().expect("a cut file is truncated");
        assert!(msg.contains(&format!("file ends at byte {cut}")), "{msg}");
        let n = rec.frames.len();
        let read = if n == 1 {
            "1 complete frame read".to_string()
        } else {
            format!("{n} complete frames read")
        };
        assert!(msg.contains(&read), "{msg}");
        assert_frames_bitwise_eq(&rec.frames, &frames[..n]);
        if cut % 3 == 0 {
            assert!(
                n >= last_count,
                "cut at {cut}: fewer frames than a shorter cut"
            );
            last_count = n;
        }
        if let Some(m) = &rec.metadata {
            assert_eq!(m, &metadata());
            metadata_seen_at.get_or_insert(cut);
        }
        assert_eq!(rec.file_bytes, cut as u64);
    }
    assert_eq!(last_count, frames.len());
    assert!(metadata_seen_at.unwrap() < bytes.len() / 4);
    assert_eq!(full.truncated, None);
}

#[test]
fn record_rejects_non_mcap_and_corrupt_files() {
    let err = read_recording_bytes(b"{\"json\": true}\n").unwrap_err();
    assert!(matches!(err, RecordError::NotMcap { .. }), "{err}");
    assert!(err.to_string().contains("89 4d 43 41 50 30 0d 0a"), "{err}");

    let missing = read_recording(&TempFile::new("does-not-exist.mcap")).unwrap_err();
    assert!(matches!(missing, RecordError::Io { .. }));

    let frames = random_frames(4, 3, true);
    let (_, bytes) = write_recording("corrupt.mcap", &frames, true);
    // An impossible length in the header record.
    let mut bad = bytes.clone();
    bad[9 + 7] = 0x7f;
    match read_recording_bytes(&bad).unwrap_err() {
        RecordError::Corrupt { offset, detail } => {
            assert_eq!(offset, 8);
            assert!(detail.contains("declares a length"), "{detail}");
        }
        e => panic!("{e}"),
    }
    // A flipped byte inside the last chunk's compressed data: frames before it survive.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let last = summary.chunk_indexes.last().unwrap();
    let mut bad = bytes.clone();
    let at = (last.chunk_start_offset + last.chunk_length - 5) as usize;
    bad[at] ^= 0x40;
    let rec = read_recording_bytes(&bad).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames[..2]);
    // the chunk is skipped, so reading did not stop: damaged, not truncated
    assert_eq!(rec.truncated, None);
    let msg = rec.damaged.unwrap();
    assert!(
        msg.contains(&format!(
            "corrupt recording at byte {}",
            last.chunk_start_offset
        )) && msg.contains("skipped")
            && msg.contains("2 complete frames read"),
        "{msg}"
    );
    assert_eq!(rec.metadata, Some(metadata()));
}

/// A chunk whose bytes are damaged is skipped: the metadata and every frame of the other
/// chunks are read, by the linear scan and by an indexed reader, and the damage names the
/// first damaged chunk and how many were skipped.
#[test]
fn record_damaged_chunks_are_skipped_and_the_rest_read() {
    let frames = random_frames(17, 12, true);
    let (_, bytes) = write_recording("skipped.mcap", &frames, true);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunks: Vec<(u64, u64)> = summary
        .chunk_indexes
        .iter()
        .map(|c| (c.chunk_start_offset, c.chunk_length))
        .collect();
    assert!(chunks.len() >= 4, "{chunks:?}");
    let indexed = |b: Vec<u8>| {
        RecordingReader::from_reader(
            std::io::Cursor::new(b),
            std::path::Path::new("skipped.mcap"),
            ReadMode::Indexed,
            ReaderLimits::default(),
        )
        .unwrap()
    };
    // the frames of each chunk, from the intact file
    let mut intact = indexed(bytes.clone());
    let per_unit: Vec<usize> = (0..intact.unit_count())
        .map(|u| {
            intact
                .unit_messages(u, Some(STATE_TOPIC))
                .unwrap()
                .unwrap()
                .len()
        })
        .collect();
    assert_eq!(per_unit.iter().sum::<usize>(), frames.len());
    // damage the first chunk (it holds the schemas and channels) and a middle one
    let damaged = [0, chunks.len() / 2];
    let mut bad = bytes.clone();
    for &k in &damaged {
        let (start, len) = chunks[k];
        bad[(start + len / 2) as usize] ^= 0x5a;
    }
    let mut expected = Vec::new();
    let mut next = 0;
    for (u, n) in per_unit.iter().enumerate() {
        if !damaged.contains(&u) {
            expected.extend_from_slice(&frames[next..next + n]);
        }
        next += n;
    }
    assert!(expected.len() < frames.len());
    let missing = frames.len() - expected.len();
    // linear scan
    let rec = read_recording_bytes(&bad).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &expected);
    assert_eq!(rec.metadata, Some(metadata()));
    assert_eq!(rec.summary_json.as_deref(), Some(super::SUMMARY));
    assert_eq!(rec.truncated, None);
    let msg = rec.damaged.clone().unwrap();
    assert!(
        msg.contains(&format!("corrupt recording at byte {}", chunks[0].0))
            && msg.contains("2 damaged chunk(s) skipped")
            && msg.contains(&format!("{} complete frames read", expected.len())),
        "{msg} ({missing} frames missing)"
    );
    // indexed: the same frames, then the damage
    let mut reader = indexed(bad.clone());
    assert!(reader.is_indexed());
    assert_eq!(reader.metadata(), Some(&metadata()));
    let read: Vec<Result<ParticleFrame, RecordError>> = reader.frames().collect();
    let (last, ok) = read.split_last().unwrap();
    let ok: Vec<ParticleFrame> = ok.iter().map(|f| f.as_ref().unwrap().clone()).collect();
    assert_frames_bitwise_eq(&ok, &expected);
    match last {
        Err(RecordError::SkippedChunks { offset, count, .. }) => {
            assert_eq!((*offset, *count), (chunks[0].0, 2));
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        reader.damage(),
        Some(RecordError::SkippedChunks { count: 2, .. })
    ));
    // random access numbers the frames read, as the iterator does
    let bytes_damaged = bad.clone();
    let mut reader = indexed(bad);
    let by_index: Vec<ParticleFrame> = (0..expected.len() as u64)
        .map(|i| reader.frame(i).unwrap().unwrap())
        .collect();
    assert_frames_bitwise_eq(&by_index, &expected);
    assert!(matches!(
        reader.frame(expected.len() as u64),
        Err(RecordError::SkippedChunks { count: 2, .. })
    ));
    // unit by unit (the Python `messages`): the damaged chunks give nothing, the others
    // their messages, then the damage
    let mut reader = indexed(bytes_damaged);
    let mut by_unit = Vec::new();
    for u in 0..reader.unit_count() {
        let m = reader.unit_messages(u, Some(STATE_TOPIC)).unwrap().unwrap();
        assert_eq!(m.is_empty(), damaged.contains(&u), "unit {u}");
        by_unit.extend(
            m.iter()
                .map(|m| crate::reader::decode_frame(m, 0, None).unwrap()),
        );
    }
    assert!(reader.unit_messages(reader.unit_count(), None).is_none());
    assert_frames_bitwise_eq(&by_unit, &expected);
    assert!(matches!(
        reader.damage(),
        Some(RecordError::SkippedChunks { count: 2, .. })
    ));
}

#[test]
fn record_fuzzed_files_never_panic() {
    let frames = random_frames(1234, 5, true);
    let (_, bytes) = write_recording("fuzz.mcap", &frames, true);
    let original = read_recording_bytes(&bytes).unwrap();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(77);
    let (mut ok, mut flagged, mut failed) = (0, 0, 0);
    for i in 0..400 {
        let mut data = bytes.clone();
        let flips = 1 + (i % 3);
        for _ in 0..flips {
            let at = (rng.next_u64() % data.len() as u64) as usize;
            data[at] ^= (1 + rng.next_u64() % 255) as u8;
        }
        if i % 4 == 0 {
            data.truncate((rng.next_u64() % data.len() as u64) as usize);
        }
        match std::panic::catch_unwind(|| read_recording_bytes(&data)) {
            Err(_) => panic!("reader panicked on fuzz case {i}"),
            Ok(Err(e)) => {
                if std::env::var_os("MAGSEP_SHOW_FUZZ").is_some() {
                    eprintln!("{i}: error: {e}");
                }
                failed += 1;
            }
            Ok(Ok(rec)) if rec.truncated.is_some() || rec.damaged.is_some() => {
                // Chunk contents are under CRCs: frames read are original frames, in order.
                let mut rest = original.frames.iter();
                for f in &rec.frames {
                    assert!(
                        rest.any(|o| bits(o) == bits(f)),
                        "fuzz case {i}: altered frame"
                    );
                }
                if std::env::var_os("MAGSEP_SHOW_FUZZ").is_some() {
                    eprintln!("{i}: {:?} {:?}", rec.truncated, rec.damaged);
                }
                flagged += 1;
            }
            Ok(Ok(rec)) => {
                // Every byte is under some CRC, so an unflagged read must be the original.
                assert_eq!(rec.metadata, original.metadata, "fuzz case {i}");
                assert_eq!(rec.summary_json, original.summary_json, "fuzz case {i}");
                assert_frames_bitwise_eq(&rec.frames, &original.frames);
                ok += 1;
            }
        }
    }
    eprintln!("fuzz: {ok} intact, {flagged} flagged truncated, {failed} rejected");
    assert!(
        failed + flagged > 300,
        "ok {ok}, flagged {flagged}, failed {failed}"
    );
}

#[test]
fn record_bytes_after_the_closing_magic_are_damage() {
    let frames = random_frames(31, 4, true);
    let (_, bytes) = write_recording("trailing.mcap", &frames, true);
    let n = bytes.len() as u64;
    let intact = read_recording_bytes(&bytes).unwrap();
    assert_eq!((intact.trailing_bytes, intact.damaged), (0, None));
    let mut more = bytes.clone();
    more.extend_from_slice(&[0u8; 100]);
    let rec = read_recording_bytes(&more).unwrap();
    // everything before is read; the file is damaged, not truncated
    assert_frames_bitwise_eq(&rec.frames, &frames);
    assert_eq!(rec.truncated, None);
    assert_eq!(rec.trailing_bytes, 100);
    let msg = rec.damaged.unwrap();
    assert!(
        msg.contains(&format!(
            "100 trailing bytes after the footer (bytes {n}..{})",
            n + 100
        )),
        "{msg}"
    );
    // a whole second copy appended: the indexed reader falls back to the scan, which finds it
    let mut twice = bytes.clone();
    twice.extend_from_slice(&bytes);
    let path = TempFile::new("trailing-copy.mcap");
    std::fs::write(&path, &twice).unwrap();
    let reader = RecordingReader::open(path.as_ref()).unwrap();
    assert_eq!(reader.trailing_bytes(), Some((n, n)));
    let last = read_last_frame(path.as_ref()).unwrap();
    assert_eq!(last.frames, 4);
    assert!(
        last.damaged
            .unwrap()
            .contains(&format!("{n} trailing bytes"))
    );
}

#[cfg(unix)]
#[test]
fn record_inputs_must_be_regular_files_and_are_never_quoted() {
    for path in ["/dev/zero", "/tmp"] {
        let err = read_recording(std::path::Path::new(path)).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
        let err = RecordingReader::open(std::path::Path::new(path)).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }
    let path = TempFile::new("passwd");
    std::fs::write(&path, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let err = read_recording(path.as_ref()).unwrap_err().to_string();
    assert!(
        err.contains("not an MCAP file") && err.contains("text"),
        "{err}"
    );
    for leak in ["root", "72 6f 6f 74", "bash"] {
        assert!(!err.contains(leak), "{leak} in {err}");
    }
    // strings of a damaged file are quoted cut short
    assert_eq!(crate::parse::clip(&"x".repeat(1000)).len(), 64 + 3);
    assert_eq!(crate::parse::clip("short"), "short");
}

#[test]
fn record_writer_refuses_frames_the_reader_would_refuse() {
    let frames = random_frames(5, 3, true);
    let path = TempFile::new("big-frame.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    w.write_frame(&frames[0], None).unwrap();
    // a chunk limit of 200 bytes stands for the 1 GiB of MAX_CHUNK_BYTES
    w.max_chunk = 200;
    let big = ParticleFrame {
        ids: (0..10).collect(),
        positions: vec![glam::DVec3::ZERO; 10],
        orientations: vec![glam::DQuat::IDENTITY; 10],
        radii: vec![1.0; 10],
        half_lengths: vec![0.0; 10],
        rng_states: vec![[1, 2, 3, 4]; 10],
        ..frames[1].clone()
    };
    let err = w.write_frame(&big, None).unwrap_err().to_string();
    assert!(err.contains("more than the 200 bytes per chunk"), "{err}");
    w.finish().unwrap();
    // nothing of the refused frame was written: the file is intact
    let rec = read_recording(path.as_ref()).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames[..1]);
    assert_eq!((rec.truncated, rec.damaged), (None, None));
}
