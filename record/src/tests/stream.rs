//! Tests of the streaming reader: indexed and linear reads, truncation, bounded memory, and
//! files written before plugin channels and self-describing schemas existed.

use super::{TempFile, assert_frames_bitwise_eq, bits, metadata, random_frames, write_recording};
use crate::*;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn record_streaming_matches_read_recording_on_1000_frames() {
    let frames = random_frames(1000, 1000, true);
    let (path, _) = write_recording("stream-1000.mcap", &frames, true);
    let whole = read_recording(&path).unwrap();
    for mode in [ReadMode::Indexed, ReadMode::Linear] {
        let mut reader = RecordingReader::open_with(&path, mode, ReaderLimits::default()).unwrap();
        assert_eq!(reader.is_indexed(), mode == ReadMode::Indexed);
        assert_eq!(reader.truncated(), None);
        assert!(reader.damage().is_none());
        assert_eq!(reader.metadata(), whole.metadata.as_ref());
        assert_eq!(reader.summary_json(), whole.summary_json.as_deref());
        assert_eq!(reader.channels(), whole.channels);
        let mut n = 0;
        for (got, want) in reader.frames().zip(&whole.frames) {
            assert_eq!(bits(&got.unwrap()), bits(want), "frame {n}");
            n += 1;
        }
        assert_eq!(n, 1000);
        let times: Vec<u64> = reader
            .messages(Some(STATE_TOPIC))
            .map(|m| m.unwrap().log_time_ns)
            .collect();
        let want: Vec<u64> = frames.iter().map(log_time_ns).collect();
        assert_eq!(times, want);
    }
    assert_frames_bitwise_eq(&whole.frames, &frames);
}

#[test]
fn record_streaming_a_truncated_file_reads_the_frames_before_the_cut() {
    let frames = random_frames(5, 40, true);
    let (_, bytes) = write_recording("stream-cut.mcap", &frames, true);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    // Cut inside the chunk of frame 30.
    let chunk = &summary.chunk_indexes[1 + 30];
    let cut = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    let path = TempFile::new("stream-cut-short.mcap");
    std::fs::write(&path, &bytes[..cut]).unwrap();
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(!reader.is_indexed());
    let msg = reader.truncated().unwrap().to_string();
    let start = chunk.chunk_start_offset;
    assert!(
        msg.contains(&format!(
            "file ends at byte {cut} inside a chunk record that starts at byte {start}"
        )) && msg.contains("30 complete frames read"),
        "{msg}"
    );
    let got: Vec<_> = reader.frames().collect::<Result<_, _>>().unwrap();
    assert_frames_bitwise_eq(&got, &frames[..30]);
    assert_eq!(reader.metadata(), Some(&metadata()));
    let state = reader
        .channels()
        .into_iter()
        .find(|c| c.topic == STATE_TOPIC)
        .unwrap();
    assert_eq!(state.message_count, 30);
}

/// A minimal MCAP file: magic, header, one chunk record with the given header fields and
/// data bytes, and no footer.
fn crafted_chunk(uncompressed: u64, compression: &str, data: &[u8], finish: bool) -> Vec<u8> {
    let mut out = mcap::MAGIC.to_vec();
    let mut record = |opcode: u8, body: &[u8]| {
        out.push(opcode);
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend_from_slice(body);
    };
    let mut header = Vec::new();
    for s in ["", "crafted"] {
        header.extend_from_slice(&(s.len() as u32).to_le_bytes());
        header.extend_from_slice(s.as_bytes());
    }
    record(0x01, &header);
    let mut chunk = Vec::new();
    chunk.extend_from_slice(&0u64.to_le_bytes());
    chunk.extend_from_slice(&0u64.to_le_bytes());
    chunk.extend_from_slice(&uncompressed.to_le_bytes());
    chunk.extend_from_slice(&0u32.to_le_bytes());
    chunk.extend_from_slice(&(compression.len() as u32).to_le_bytes());
    chunk.extend_from_slice(compression.as_bytes());
    chunk.extend_from_slice(&(data.len() as u64).to_le_bytes());
    chunk.extend_from_slice(data);
    record(0x06, &chunk);
    if finish {
        record(0x0f, &0u32.to_le_bytes());
        record(0x02, &[0; 20]);
        out.extend_from_slice(mcap::MAGIC);
    }
    out
}

fn corrupt_detail(result: Result<Recording, RecordError>) -> (u64, String) {
    match result {
        Err(
            RecordError::Corrupt { offset, detail }
            | RecordError::SkippedChunks { offset, detail, .. },
        ) => (offset, detail),
        other => panic!("expected a corrupt-record error, got {other:?}"),
    }
}

#[test]
fn record_crafted_huge_lengths_are_errors_not_allocations() {
    // A chunk declaring 2^40 uncompressed bytes for 13 bytes of zstd data.
    let zstd13 = zstd::bulk::compress(b"hello", 3).unwrap();
    let bytes = crafted_chunk(1 << 40, "zstd", &zstd13, true);
    let (offset, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert_eq!(offset, 8 + 9 + 15);
    assert!(detail.contains("exceeds the reader's limit"), "{detail}");
    // Within the size limit but beyond the compression ratio limit: refused before anything
    // is allocated or decompressed.
    let bytes = crafted_chunk(1 << 29, "zstd", &zstd13, true);
    let (_, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert!(detail.contains("compression ratio above"), "{detail}");
    // Declared smaller than the data decompresses to: decompression stops, no overrun.
    let big = zstd::bulk::compress(&vec![7u8; RATIO_FREE_BYTES as usize], 3).unwrap();
    let bytes = crafted_chunk(100, "zstd", &big, true);
    let (_, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert!(
        detail.contains("decompresses to more than the 100 bytes"),
        "{detail}"
    );
    // 16 MiB of one byte value is a ratio of thousands: allowed up to RATIO_FREE_BYTES (the
    // chunk then fails on its content), refused one byte above it.
    let bytes = crafted_chunk(RATIO_FREE_BYTES, "zstd", &big, true);
    let (_, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert!(
        detail.contains("record #0 in the chunk declares"),
        "{detail}"
    );
    let bytes = crafted_chunk(RATIO_FREE_BYTES + 1, "zstd", &big, true);
    let (_, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert!(
        detail.contains("compression ratio above the reader's limit of 64:1"),
        "{detail}"
    );
    // Declared larger than it decompresses to.
    let bytes = crafted_chunk(1000, "zstd", &zstd13, true);
    let (_, detail) = corrupt_detail(read_recording_bytes(&bytes));
    assert!(detail.contains("decompresses to 5 bytes"), "{detail}");

    // A record length of 2^60 in a finished file, and in a file cut short.
    let frames = random_frames(8, 3, true);
    let (_, good) = write_recording("huge-len.mcap", &frames, false);
    let summary = mcap::Summary::read(&good).unwrap().unwrap();
    let at = summary.chunk_indexes[2].chunk_start_offset as usize;
    let mut bad = good.clone();
    bad[at + 1..at + 9].copy_from_slice(&(1u64 << 60).to_le_bytes());
    let rec = read_recording_bytes(&bad).unwrap();
    assert_eq!(rec.frames.len(), 1);
    let msg = rec.truncated.unwrap();
    assert!(
        msg.contains(&format!("corrupt recording at byte {at}"))
            && msg.contains("1152921504606846976"),
        "{msg}"
    );
    let rec = read_recording_bytes(&bad[..at + 100]).unwrap();
    assert_eq!(rec.frames.len(), 1);
    assert!(rec.truncated.unwrap().contains("corrupt recording"));

    // Small limits reject what the defaults accept, with the limit in the message.
    let path = TempFile::new("limits.mcap");
    std::fs::write(&path, &good).unwrap();
    let limits = ReaderLimits {
        max_chunk_bytes: 64,
        ..ReaderLimits::default()
    };
    let mut reader = RecordingReader::open_with(&path, ReadMode::Linear, limits).unwrap();
    let err = reader.frames().next().unwrap().unwrap_err();
    assert!(err.to_string().contains("limit of 64 bytes"), "{err}");
    let mut reader = RecordingReader::open_with(&path, ReadMode::Indexed, limits).unwrap();
    let err = reader.frames().next().unwrap().unwrap_err();
    assert!(err.to_string().contains("limit of 64 bytes"), "{err}");
}

#[test]
fn record_reader_opens_errors_with_where_and_what() {
    let path = TempFile::new("not-mcap.mcap");
    std::fs::write(&path, b"PK\x03\x04 a zip file").unwrap();
    let err = RecordingReader::open(&path).unwrap_err();
    assert!(matches!(err, RecordError::NotMcap { .. }), "{err}");
    let err = RecordingReader::open(Path::new("/nonexistent/run.mcap")).unwrap_err();
    assert!(matches!(err, RecordError::Io { .. }), "{err}");
    // A damaged summary falls back to the linear scan, which reports the damage.
    let frames = random_frames(2, 4, false);
    let (_, mut bytes) = write_recording("bad-summary.mcap", &frames, true);
    let n = bytes.len();
    bytes[n - 8 - 1] ^= 0x55; // the summary CRC stored in the footer
    std::fs::write(&path, &bytes).unwrap();
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(!reader.is_indexed());
    assert_eq!(reader.frames().filter(Result::is_ok).count(), 4);
    let damage = reader.damage().map(|e| e.to_string()).unwrap_or_default();
    assert!(damage.contains("summary CRC mismatch"), "{damage}");
}

/// A recording written by magsep 0.1.0 before the codec moved to its own crate: the `/state`
/// descriptor generated by `#[derive(foxglove::Encode)]` (no comments) and `magsep` metadata
/// without `plugins` and `extra`. Written by `record_write_sample_for_python_check`.
#[test]
fn record_reads_files_of_the_previous_version() {
    let path = fixture("v0_sample.mcap");
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.truncated, None);
    assert_eq!(rec.frames.len(), 20);
    let meta = rec.metadata.unwrap();
    assert!(meta.plugins.is_empty() && meta.extra.is_empty());
    assert_eq!(meta.pipeline, "brownian");
    assert!(!rec.metadata_records[0].entries.contains_key("plugins"));
    for (step, f) in rec.frames.iter().enumerate() {
        assert_eq!((f.step, f.ids.len()), (step as u64, 16));
        assert_eq!(f.time.to_bits(), (step as f64 * 1e-4).to_bits());
        assert_eq!(f.rng_states[3], [3, step as u64, 1, 2]);
        assert_eq!(f.status_json, format!(r#"{{"step": {step}}}"#));
    }
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(reader.is_indexed());
    let streamed: Vec<_> = reader.frames().collect::<Result<_, _>>().unwrap();
    assert_frames_bitwise_eq(&streamed, &rec.frames);
    // Re-recording the frames with this version reads back identically.
    let (_, bytes) = write_recording("v0-rewrite.mcap", &rec.frames, false);
    assert_frames_bitwise_eq(&read_recording_bytes(&bytes).unwrap().frames, &rec.frames);
}

/// Every `/state` field is written, zero values included, so `-0.0` and empty frames survive.
#[test]
fn record_zero_and_negative_zero_fields_round_trip() {
    let frame = ParticleFrame {
        time: -0.0,
        box_edges: glam::DVec3::new(-0.0, 0.0, -0.0),
        status_json: String::new(),
        ..Default::default()
    };
    let mut with_particle = frame.clone();
    with_particle.ids = vec![0];
    with_particle.positions = vec![glam::DVec3::splat(-0.0)];
    with_particle.orientations = vec![glam::DQuat::from_xyzw(-0.0, 0.0, -0.0, 1.0)];
    with_particle.radii = vec![-0.0];
    with_particle.half_lengths = vec![0.0];
    with_particle.rng_states = vec![[0; 4]];
    let frames = [frame, with_particle];
    let (_, bytes) = write_recording("zeros.mcap", &frames, false);
    let rec = read_recording_bytes(&bytes).unwrap();
    assert_frames_bitwise_eq(&rec.frames, &frames);
    assert_eq!(rec.frames[0].time.to_bits(), (-0.0f64).to_bits());
}
