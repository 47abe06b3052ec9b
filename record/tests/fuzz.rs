//! Property tests of the recording reader on damaged files: random truncations, bit flips and
//! rewritten length fields of a real recording. The reader must never panic and never
//! allocate much more than the file: every allocation of a case is watched, and no single
//! one may exceed [`LARGEST_ALLOWED`] (the file is about 40 KB; the reader's ratio
//! bound allows at most `max(1 MiB, 64 x compressed chunk)` for one chunk).
//!
//! Cases: 256 per property (three properties, 768 damaged files), about two seconds in
//! release mode. The proptest seed is random per run; a failure prints the minimal case.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::Cursor;
use std::path::Path;
use std::sync::OnceLock;

use glam::{DQuat, DVec3};
use magsep_record::{
    ParticleFrame, ReadMode, ReaderLimits, RecordingMetadata, RecordingReader, RecordingWriter,
    read_recording_bytes,
};
use proptest::prelude::*;
use proptest::sample::Index;

/// Records the largest single allocation of each thread (the properties run in parallel).
struct Counting;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    // `try_with`: nothing to note while the thread's locals are being torn down
    let _ = LARGEST.try_with(|l| l.set(l.get().max(size)));
}

// SAFETY: every call is forwarded to the system allocator unchanged; only a counter is kept.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: the caller's contract is passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The largest single allocation any case may cause: 8 MiB (the file is ~40 KB).
const LARGEST_ALLOWED: usize = 8 << 20;

/// Cases per property.
const CASES: u32 = 256;

/// A real recording: 6 frames of 60 particles, summary and footer (~40 KB).
fn base() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| {
        let path = std::env::temp_dir().join(format!("magsep-fuzz-{}.mcap", std::process::id()));
        let meta = RecordingMetadata {
            scene_text: "[simulation]\npipeline = \"test\"\n".into(),
            seed: 7,
            version: "test".into(),
            pipeline: "test".into(),
            dt: 1e-3,
            ..Default::default()
        };
        let mut w = RecordingWriter::create(&path, &meta).unwrap();
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for step in 0..6u64 {
            let n = 60;
            let mut u = || (next() >> 11) as f64 / (1u64 << 53) as f64;
            let frame = ParticleFrame {
                step: step * 10,
                time: step as f64 * 1e-2,
                box_edges: DVec3::splat(1e-5),
                ids: (0..n as u64).collect(),
                positions: (0..n).map(|_| DVec3::new(u(), u(), u()) * 1e-5).collect(),
                orientations: vec![DQuat::IDENTITY; n],
                radii: vec![1e-7; n],
                half_lengths: vec![0.0; n],
                rng_states: (0..n).map(|_| [next(), next(), next(), next()]).collect(),
                status_json: format!("{{\"step\": {step}}}"),
            };
            w.write_frame(&frame, None).unwrap();
        }
        w.write_summary("{\"steps\": 50}").unwrap();
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        bytes
    })
}

/// Starts of the top-level records (opcode bytes) of `bytes`, following lengths from the
/// header on.
fn record_starts(bytes: &[u8]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut pos = 8usize;
    while pos + 9 <= bytes.len() {
        out.push(pos);
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap());
        match usize::try_from(len)
            .ok()
            .and_then(|l| pos.checked_add(9 + l))
        {
            Some(next) if next <= bytes.len() => pos = next,
            _ => break,
        }
    }
    out
}

/// Runs every reader entry point on `bytes` to the end; panics propagate to proptest.
fn read_all(bytes: &[u8]) {
    LARGEST.with(|l| l.set(0));
    let _ = read_recording_bytes(bytes);
    for mode in [ReadMode::Indexed, ReadMode::Linear] {
        let Ok(mut reader) = RecordingReader::from_reader(
            Cursor::new(bytes),
            Path::new("<fuzz>"),
            mode,
            ReaderLimits::default(),
        ) else {
            continue;
        };
        let _ = reader.channels();
        for m in reader.messages(None) {
            if m.is_err() {
                break;
            }
        }
        for f in reader.frames() {
            if f.is_err() {
                break;
            }
        }
        let _ = (reader.truncated(), reader.damage(), reader.trailing_bytes());
    }
    let largest = LARGEST.with(Cell::get);
    assert!(
        largest <= LARGEST_ALLOWED,
        "an allocation of {largest} bytes for a {}-byte file",
        bytes.len()
    );
}

/// Length values that break readers: zero, off by one, the file size, powers of two, the
/// largest u64, and any value.
fn length_value() -> impl Strategy<Value = u64> {
    prop_oneof![
        Just(0u64),
        Just(1),
        Just(u32::MAX as u64),
        Just(1 << 31),
        Just(1 << 40),
        Just(u64::MAX),
        Just(u64::MAX - 8),
        (0u64..200_000),
        // log-uniform up to 2^40, so sizes within the absolute limit (1 GiB) but far beyond
        // the file come up often
        (0u32..40, any::<u16>()).prop_map(|(e, j)| (1u64 << e).wrapping_add(u64::from(j))),
        any::<u64>(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    #[test]
    fn reader_survives_truncation(cut in any::<Index>(), extra in 0usize..3) {
        let bytes = base();
        let cut = cut.index(bytes.len() + 1);
        read_all(&bytes[..cut]);
        // and a cut file with a few bytes appended after the cut
        let mut more = bytes[..cut].to_vec();
        more.extend(std::iter::repeat_n(0xA5u8, extra * 7));
        read_all(&more);
    }

    #[test]
    fn reader_survives_bit_flips(flips in prop::collection::vec((any::<Index>(), 0u8..8), 1..8)) {
        let mut bytes = base().to_vec();
        let n = bytes.len();
        for (at, bit) in flips {
            bytes[at.index(n)] ^= 1 << bit;
        }
        read_all(&bytes);
    }

    #[test]
    fn reader_survives_rewritten_lengths(
        record in any::<Index>(),
        field in 0usize..4,
        anywhere in any::<Index>(),
        value in length_value(),
    ) {
        let mut bytes = base().to_vec();
        let starts = record_starts(&bytes);
        // a record's length, a chunk's uncompressed size or compressed size, or any 8 bytes
        let at = match field {
            0 => starts[record.index(starts.len())] + 1,
            1 | 2 => {
                let chunks: Vec<usize> =
                    starts.iter().copied().filter(|&s| bytes[s] == 0x06).collect();
                let c = chunks[record.index(chunks.len())] + 9;
                if field == 1 {
                    c + 16 // after start and end time: uncompressed size
                } else {
                    // after uncompressed size, CRC and the compression string
                    let slen = u32::from_le_bytes(bytes[c + 28..c + 32].try_into().unwrap());
                    c + 32 + slen as usize
                }
            }
            _ => anywhere.index(bytes.len() - 8),
        };
        bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
        read_all(&bytes);
    }
}

#[test]
fn base_recording_reads_back_whole() {
    let rec = read_recording_bytes(base()).unwrap();
    assert_eq!(rec.frames.len(), 6);
    assert!(rec.truncated.is_none() && rec.damaged.is_none());
    // every chunk is a candidate for the length rewrites
    let starts = record_starts(base());
    assert!(starts.iter().filter(|&&s| base()[s] == 0x06).count() >= 6);
    assert!(
        base().len() > 20_000 && base().len() < 100_000,
        "{}",
        base().len()
    );
}
