//! The bad recordings of `tests/data/bad_recordings/`, derived from its `base.mcap` (a real
//! recording of `tests/data/brownian_short.toml`) by cutting, flipping bits, rewriting length
//! fields, splicing crafted chunks (zstd bombs), appending bytes, and by re-writing its frames
//! under altered metadata (for `replay --resume`). Deterministic: the same base gives the same
//! bytes, which `bad_recordings_corpus_is_reproducible` checks.

use magsep::plugins::record::{RecordingMetadata, RecordingWriter, read_recording};

/// The top-level records of `bytes`: (opcode, start of the opcode byte, end).
fn records(bytes: &[u8]) -> Vec<(u8, usize, usize)> {
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap()) as usize;
        let end = pos + 9 + len;
        assert!(end <= bytes.len(), "base.mcap is not intact");
        out.push((bytes[pos], pos, end));
        pos = end;
    }
    out
}

const HEADER: u8 = 0x01;
const FOOTER: u8 = 0x02;
const CHUNK: u8 = 0x06;
const METADATA: u8 = 0x0C;
const DATA_END: u8 = 0x0F;

/// A zstd frame of RLE blocks (128 KiB of zeros each, 4 bytes per block) that decompresses
/// to `blocks` x 128 KiB.
fn rle_frame(blocks: usize) -> Vec<u8> {
    let mut out = vec![0x28, 0xB5, 0x2F, 0xFD]; // magic
    out.push(0x00); // frame header descriptor: no content size, no checksum, no dictionary
    out.push(7 << 3); // window descriptor: window log 10 + 7 = 17 (128 KiB)
    for k in 0..blocks {
        let last = u32::from(k + 1 == blocks);
        let header = last | (1 << 1) | ((128u32 << 10) << 3); // RLE block of 128 KiB
        out.extend_from_slice(&header.to_le_bytes()[..3]);
        out.push(0);
    }
    out
}

/// A chunk record holding `data` (zstd) and declaring `uncompressed` bytes, CRC 0.
fn chunk_record(data: &[u8], uncompressed: u64) -> Vec<u8> {
    let mut body = Vec::new();
    body.extend_from_slice(&0u64.to_le_bytes()); // message start time
    body.extend_from_slice(&0u64.to_le_bytes()); // message end time
    body.extend_from_slice(&uncompressed.to_le_bytes());
    body.extend_from_slice(&0u32.to_le_bytes()); // CRC 0: not checked
    body.extend_from_slice(&4u32.to_le_bytes());
    body.extend_from_slice(b"zstd");
    body.extend_from_slice(&(data.len() as u64).to_le_bytes());
    body.extend_from_slice(data);
    let mut rec = vec![CHUNK];
    rec.extend_from_slice(&(body.len() as u64).to_le_bytes());
    rec.extend_from_slice(&body);
    rec
}

/// `bytes` with the record `start..end` replaced by `with`.
fn splice(bytes: &[u8], start: usize, end: usize, with: &[u8]) -> Vec<u8> {
    let mut out = bytes[..start].to_vec();
    out.extend_from_slice(with);
    out.extend_from_slice(&bytes[end..]);
    out
}

fn flip(bytes: &[u8], at: usize, mask: u8) -> Vec<u8> {
    let mut out = bytes.to_vec();
    out[at] ^= mask;
    out
}

fn put_u64(bytes: &[u8], at: usize, value: u64) -> Vec<u8> {
    let mut out = bytes.to_vec();
    out[at..at + 8].copy_from_slice(&value.to_le_bytes());
    out
}

/// The frames of `base` re-written under the metadata `meta` changes (the /scene channel
/// is drawn without fibres; only the metadata and frames matter here).
fn rewritten(base: &[u8], edit: impl Fn(&mut RecordingMetadata)) -> Vec<u8> {
    let rec = magsep::plugins::record::read_recording_bytes(base).unwrap();
    let mut meta = rec.metadata.clone().unwrap();
    edit(&mut meta);
    let path = std::env::temp_dir().join(format!(
        "magsep-bad-recording-{}-{}.mcap",
        std::process::id(),
        meta.seed ^ meta.scene_text.len() as u64 ^ meta.dt.to_bits()
    ));
    let mut w = RecordingWriter::create(&path, &meta).unwrap();
    for f in &rec.frames {
        w.write_frame(f, None).unwrap();
    }
    if let Some(s) = &rec.summary_json {
        w.write_summary(s).unwrap();
    }
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(read_recording(&path).unwrap().frames, rec.frames);
    let _ = std::fs::remove_file(&path);
    bytes
}

/// Every bad recording: (file name, bytes).
pub fn corpus(base: &[u8]) -> Vec<(&'static str, Vec<u8>)> {
    let recs = records(base);
    let find = |op: u8| recs.iter().find(|r| r.0 == op).copied().unwrap();
    let chunks: Vec<_> = recs.iter().filter(|r| r.0 == CHUNK).copied().collect();
    // chunk 0 holds the schemas and channels, chunk 1 frame 0, chunk 2 frame 1, ...
    let (_, c2, c2_end) = chunks[2];
    let header = find(HEADER);
    let meta = find(METADATA);
    let data_end = find(DATA_END);
    let footer = find(FOOTER);
    let n = base.len();
    let gib_bomb = rle_frame(8192 - 1); // 1 GiB - 128 KiB, 32 KB of zstd data
    let mut doubled = base.to_vec();
    doubled.extend_from_slice(base);
    let mut trailing = base.to_vec();
    trailing.extend_from_slice(&[0u8; 100]);
    vec![
        ("empty.mcap", Vec::new()),
        ("cut_in_magic.mcap", base[..5].to_vec()),
        ("cut_after_header.mcap", base[..header.2].to_vec()),
        ("cut_mid_chunk.mcap", base[..(c2 + c2_end) / 2].to_vec()),
        (
            "cut_in_summary.mcap",
            base[..(data_end.2 + footer.1) / 2].to_vec(),
        ),
        ("cut_in_closing_magic.mcap", base[..n - 3].to_vec()),
        ("flip_magic.mcap", flip(base, 1, 0x04)),
        // the header's library string: only the data-section CRC notices
        ("flip_header.mcap", flip(base, header.2 - 2, 0x01)),
        ("flip_first_chunk.mcap", flip(base, chunks[0].2 - 5, 0x10)),
        ("flip_chunk_data.mcap", flip(base, c2_end - 40, 0x10)),
        // the summary CRC stored in the footer
        ("flip_footer.mcap", flip(base, footer.2 - 2, 0x80)),
        ("long_record_length.mcap", put_u64(base, c2 + 1, 1 << 62)),
        // declared uncompressed size of chunk 2
        (
            "long_uncompressed_size.mcap",
            put_u64(base, c2 + 9 + 16, 1 << 40),
        ),
        // the name length of the `magsep` metadata record (a u32 prefix)
        ("long_string_length.mcap", {
            let mut b = base.to_vec();
            b[meta.1 + 9..meta.1 + 13].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
            b
        }),
        (
            "zstd_bomb.mcap",
            splice(
                base,
                c2,
                c2_end,
                &chunk_record(&gib_bomb, 128 * 1024 * (8192 - 1)),
            ),
        ),
        (
            "zstd_bomb_understated.mcap",
            splice(base, c2, c2_end, &chunk_record(&gib_bomb, 1 << 20)),
        ),
        ("trailing_bytes.mcap", trailing),
        ("trailing_copy.mcap", doubled),
        (
            "text_file.mcap",
            b"root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/usr/sbin/nologin\n"
                .to_vec(),
        ),
        (
            "resume_many_particles.mcap",
            rewritten(base, |m| {
                m.scene_text = m.scene_text.replace("count = 4", "count = 10000000");
            }),
        ),
        (
            "resume_time_step.mcap",
            rewritten(base, |m| {
                m.scene_text = m
                    .scene_text
                    .replace("time_step = 5e-5", "time_step = 1e-4")
                    .replace("duration = 0.005", "duration = 0.01");
            }),
        ),
        ("resume_seed.mcap", rewritten(base, |m| m.seed += 1)),
        ("resume_intact.mcap", {
            // a run cut after its second frame: resuming it must work
            let cut = rewritten(base, |_| {});
            let cr: Vec<_> = records(&cut).into_iter().filter(|r| r.0 == CHUNK).collect();
            cut[..cr[2].2].to_vec()
        }),
    ]
}
