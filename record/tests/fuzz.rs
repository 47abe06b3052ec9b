//! Property tests of the recording reader on damaged files: random truncations, bit flips and
//! rewritten length fields of a real recording. The reader must never panic and never
//! allocate much more than the file: every allocation of a case is watched, and no single
//! one may exceed [`LARGEST_ALLOWED`] (the file is about 40 KB; a chunk's output grows with
//! what its data really decompresses to, whatever size it declares).
//!
//! Cases: 256 per property (four properties, 1024 damaged files), about a second in release
//! mode. The proptest seed is random per run; a failure prints the minimal case.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::Cursor;
use std::path::Path;

use magsep_record::{ReadMode, ReaderLimits, RecordingReader, read_recording_bytes};
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

/// The largest single allocation any case may cause: 8 MiB (the file is 28 KB).
const LARGEST_ALLOWED: usize = 8 << 20;

/// Cases per property.
const CASES: u32 = 256;

/// A real recording: `magsep run tests/data/brownian_short.toml --record ...` (5 frames of 4
/// particles, summary and footer, 28 KB), the base of the bad-recordings corpus.
fn base() -> &'static [u8] {
    include_bytes!("../../tests/data/bad_recordings/base.mcap")
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

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    /// A chunk's declared uncompressed or compressed size set to 2^e (+ jitter), e in 0..34:
    /// sizes within the absolute limit but far beyond the chunk (the 1 KB chunks of the base
    /// would allocate up to 64 MiB under the old 65536:1 bound) come up in about one case in
    /// eight.
    #[test]
    fn reader_survives_rewritten_chunk_sizes(
        chunk in any::<Index>(),
        compressed in any::<bool>(),
        e in 0u32..34,
        jitter in any::<u16>(),
    ) {
        let mut bytes = base().to_vec();
        let chunks: Vec<usize> = record_starts(&bytes)
            .into_iter()
            .filter(|&s| bytes[s] == 0x06)
            .collect();
        let c = chunks[chunk.index(chunks.len())] + 9;
        let slen = u32::from_le_bytes(bytes[c + 28..c + 32].try_into().unwrap()) as usize;
        let at = if compressed { c + 32 + slen } else { c + 16 };
        let value = (1u64 << e).wrapping_add(u64::from(jitter));
        bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
        read_all(&bytes);
    }
}

#[test]
fn base_recording_reads_back_whole() {
    let rec = read_recording_bytes(base()).unwrap();
    assert_eq!(rec.frames.len(), 5);
    assert_eq!(rec.metadata.unwrap().pipeline, "brownian");
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
