//! Tests of the recording format: round trips, truncation, corruption, interoperability.

use super::proto::{ParticleStateWire, state_schema};
use super::*;
use foxglove::Decode;
use foxglove::messages::SceneUpdate;
use foxglove::prost_types::FileDescriptorSet;
use foxglove::prost_types::field_descriptor_proto::Type;
use glam::{DQuat, DVec3};
use prost::Message as _;
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A fresh path under the system temp dir.
fn temp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("magsep-record-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A random non-NaN f64 over the whole bit range (incl. infinities, subnormals, -0.0).
fn any_f64(rng: &mut Xoshiro256PlusPlus) -> f64 {
    loop {
        let x = f64::from_bits(rng.next_u64());
        if !x.is_nan() {
            return x;
        }
    }
}

/// Frames with random bits in every field; `physical` gives times `step * dt`, else 0.
fn random_frames(seed: u64, count: usize, physical: bool) -> Vec<ParticleFrame> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..count)
        .map(|k| {
            let n = (rng.next_u64() % 6) as usize;
            let mut v = || any_f64(&mut rng);
            let positions = (0..n).map(|_| DVec3::new(v(), v(), v())).collect();
            let orientations = (0..n)
                .map(|_| DQuat::from_xyzw(v(), v(), v(), v()))
                .collect();
            let radii = (0..n).map(|_| v()).collect();
            let box_edges = DVec3::new(v(), v(), v());
            let half_lengths = (0..n).map(|i| if i % 2 == 0 { 0.0 } else { v() }).collect();
            ParticleFrame {
                step: 10 * k as u64 + 3,
                time: if physical {
                    (10 * k + 3) as f64 * 1e-6
                } else {
                    0.0
                },
                box_edges,
                ids: (0..n).map(|_| rng.next_u64()).collect(),
                positions,
                orientations,
                radii,
                half_lengths,
                rng_states: (0..n)
                    .map(|_| {
                        [
                            rng.next_u64(),
                            rng.next_u64(),
                            rng.next_u64(),
                            rng.next_u64(),
                        ]
                    })
                    .collect(),
                status_json: format!(r#"{{"k": {k}, "note": "ünïcode ✓"}}"#),
            }
        })
        .collect()
}

fn metadata() -> RecordingMetadata {
    let mut schedule = BTreeMap::new();
    schedule.insert("Forces".to_string(), vec!["gravity".into(), "wca".into()]);
    schedule.insert("Integrate".to_string(), vec!["euler_maruyama".into()]);
    RecordingMetadata {
        scene_text: "[box]\nedges = [1e-5, 1e-5, 2e-5]\n# ünïcode ✓ \"quotes\"\n".into(),
        seed: u64::MAX - 7,
        version: "0.1.0-test".into(),
        pipeline: "brownian".into(),
        schedule,
        dt: 0.1 + 0.2,
    }
}

const SUMMARY: &str = r#"{"steps": 1000, "accepted": 0.5}"#;

/// Writes a finished recording of `frames` to a temp file and returns its bytes.
fn write_recording(name: &str, frames: &[ParticleFrame], summary: bool) -> (PathBuf, Vec<u8>) {
    let path = temp_path(name);
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    for f in frames {
        w.write_frame(f, None).unwrap();
    }
    if summary {
        w.write_summary(SUMMARY).unwrap();
    }
    assert_eq!(w.frames_written(), frames.len() as u64);
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    (path, bytes)
}

/// Equality of frames comparing every float bit for bit.
fn bits(f: &ParticleFrame) -> Vec<u64> {
    let mut out = vec![f.step, f.time.to_bits()];
    out.extend(f.box_edges.to_array().map(f64::to_bits));
    out.extend(&f.ids);
    out.extend(
        f.positions
            .iter()
            .flat_map(|p| p.to_array().map(f64::to_bits)),
    );
    out.extend(
        f.orientations
            .iter()
            .flat_map(|q| q.to_array().map(f64::to_bits)),
    );
    out.extend(f.radii.iter().map(|x| x.to_bits()));
    out.extend(f.half_lengths.iter().map(|x| x.to_bits()));
    out.extend(f.rng_states.iter().flatten());
    out.extend(f.status_json.bytes().map(u64::from));
    out
}

fn assert_frames_bitwise_eq(a: &[ParticleFrame], b: &[ParticleFrame]) {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(
            x.ids.len(),
            y.ids.len(),
            "frame {i}: particle counts differ"
        );
        assert_eq!(bits(x), bits(y), "frame {i} differs");
    }
}

#[test]
fn record_round_trip_is_bitwise_exact() {
    for physical in [false, true] {
        let frames = random_frames(7 + physical as u64, 25, physical);
        let (path, _) = write_recording(&format!("roundtrip-{physical}.mcap"), &frames, true);
        let rec = read_recording(&path).unwrap();
        assert_eq!(rec.truncated, None);
        assert_frames_bitwise_eq(&rec.frames, &frames);
        assert_eq!(rec.metadata, Some(metadata()));
        assert_eq!(rec.summary_json.as_deref(), Some(SUMMARY));
        assert_eq!(rec.file_bytes, std::fs::metadata(&path).unwrap().len());
    }
}

#[test]
fn record_metadata_round_trip_and_edge_values() {
    for dt in [0.0, 1e-300, 5e-324, 1.0 / 3.0, f64::MAX, f64::INFINITY] {
        let meta = RecordingMetadata {
            dt,
            schedule: BTreeMap::new(),
            ..metadata()
        };
        let path = temp_path("meta.mcap");
        RecordingWriter::create(&path, &meta)
            .unwrap()
            .finish()
            .unwrap();
        let rec = read_recording(&path).unwrap();
        assert_eq!(rec.metadata, Some(meta));
        assert!(rec.frames.is_empty());
        assert_eq!(rec.summary_json, None);
        assert_eq!(rec.truncated, None);
    }
}

#[test]
fn record_channels_are_listed_with_counts() {
    let frames = random_frames(11, 9, true);
    let (path, _) = write_recording("channels.mcap", &frames, false);
    let rec = read_recording(&path).unwrap();
    let expect = |topic: &str, schema: &str| ChannelInfo {
        topic: topic.into(),
        schema_name: schema.into(),
        message_encoding: "protobuf".into(),
        message_count: 9,
    };
    assert_eq!(
        rec.channels,
        vec![
            expect(STATE_TOPIC, STATE_SCHEMA_NAME),
            expect(SCENE_TOPIC, "foxglove.SceneUpdate")
        ]
    );
}

#[test]
fn record_state_descriptor_matches_decoder() {
    let (name, encoding, data) = state_schema().unwrap();
    assert_eq!(
        (name.as_str(), encoding.as_str()),
        (STATE_SCHEMA_NAME, "protobuf")
    );
    let fds = FileDescriptorSet::decode(data.as_slice()).unwrap();
    assert_eq!(fds.file.len(), 1);
    let file = &fds.file[0];
    assert_eq!(file.package.as_deref(), Some("magsep"));
    assert_eq!(file.message_type.len(), 1);
    let msg = &file.message_type[0];
    assert_eq!(msg.name.as_deref(), Some("ParticleState"));
    let fields: Vec<(String, i32, i32)> = msg
        .field
        .iter()
        .map(|f| (f.name().to_string(), f.number(), f.r#type() as i32))
        .collect();
    let b = Type::Bytes as i32;
    let expected = [
        ("step", Type::Uint64 as i32),
        ("time", Type::Double as i32),
        ("box_edges", b),
        ("ids", b),
        ("positions", b),
        ("orientations", b),
        ("radii", b),
        ("half_lengths", b),
        ("rng_states", b),
        ("status_json", Type::String as i32),
    ];
    let expected: Vec<(String, i32, i32)> = expected
        .iter()
        .enumerate()
        .map(|(i, (n, t))| (n.to_string(), i as i32 + 1, *t))
        .collect();
    assert_eq!(fields, expected);
    // Decoding an empty payload gives an empty frame.
    let frame = ParticleStateWire::decode_payload(&[]).unwrap().into_frame();
    assert!(frame.is_err(), "box_edges must hold 24 bytes");
}

#[test]
fn record_mcap_crate_reads_summary_and_validates_crcs() {
    let frames = random_frames(5, 12, true);
    let (_, bytes) = write_recording("mcapcrate.mcap", &frames, true);
    let summary = mcap::Summary::read(&bytes).unwrap().expect("summary");
    let stats = summary.stats.as_ref().unwrap();
    assert_eq!(stats.message_count, 24);
    assert_eq!(stats.channel_count, 2);
    assert_eq!(stats.metadata_count, 2);
    assert_eq!(stats.chunk_count as usize, 1 + frames.len());
    let names: Vec<_> = summary
        .metadata_indexes
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(names, [METADATA_NAME, SUMMARY_METADATA_NAME]);
    let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(meta.metadata["seed"], metadata().seed.to_string());
    assert_eq!(meta.metadata["scene_text"], metadata().scene_text);

    // All CRCs (chunks, data section, summary section) through the mcap crate's reader.
    let options = mcap::sans_io::LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_check_finishes_after_end_magic(true);
    let mut reader = mcap::sans_io::LinearReader::new_with_options(options);
    let mut input = bytes.as_slice();
    let mut records = 0;
    while let Some(event) = reader.next_event() {
        match event.expect("mcap crate validation") {
            mcap::sans_io::LinearReadEvent::ReadRequest(need) => {
                let n = need.min(input.len());
                reader.insert(n).copy_from_slice(&input[..n]);
                reader.notify_read(n);
                input = &input[n..];
            }
            mcap::sans_io::LinearReadEvent::Record { .. } => records += 1,
        }
    }
    assert!(records > 24);

    // Messages, and the scene content, through the mcap crate's message stream.
    let stream = mcap::MessageStream::new_with_options(
        &bytes,
        mcap::read::Options::ValidateChunkCrcs.into(),
    )
    .unwrap();
    let mut scenes = Vec::new();
    for msg in stream {
        let msg = msg.unwrap();
        if msg.channel.topic == SCENE_TOPIC {
            scenes.push((
                msg.log_time,
                <SceneUpdate as Decode>::decode(&msg.data[..]).unwrap(),
            ));
        }
    }
    assert_eq!(scenes.len(), frames.len());
    for ((log_time, scene), frame) in scenes.iter().zip(&frames) {
        assert_eq!(*log_time, log_time_ns(frame));
        check_scene(scene, frame, *log_time);
    }
}

fn check_scene(scene: &SceneUpdate, frame: &ParticleFrame, log_time: u64) {
    assert_eq!(scene.entities.len(), 2);
    let stamp = scene::timestamp(log_time);
    for e in &scene.entities {
        assert_eq!(e.frame_id, SCENE_FRAME_ID);
        assert_eq!(e.timestamp, Some(stamp));
        assert!(e.lifetime.is_some());
    }
    let (p, b) = (&scene.entities[0], &scene.entities[1]);
    assert_eq!((p.id.as_str(), b.id.as_str()), ("particles", "box"));
    let capsules = frame.half_lengths.iter().filter(|h| **h != 0.0).count();
    let n = frame.ids.len();
    assert_eq!(p.cylinders.len(), capsules);
    assert_eq!(p.spheres.len(), n - capsules + 2 * capsules);
    assert_eq!(b.lines.len(), 1);
    assert_eq!(b.lines[0].points.len(), 24);
}

#[test]
fn record_scene_geometry_of_spheres_capsules_and_box() {
    let q = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2); // body z -> world -y
    let frame = ParticleFrame {
        step: 4,
        time: 0.0,
        box_edges: DVec3::new(1.0, 2.0, 3.0),
        ids: vec![0, 1],
        positions: vec![DVec3::new(0.5, 0.5, 0.5), DVec3::new(0.5, 1.0, 1.5)],
        orientations: vec![DQuat::IDENTITY, q],
        radii: vec![0.1, 0.2],
        half_lengths: vec![0.0, 0.3],
        rng_states: vec![[0; 4]; 2],
        status_json: "{}".into(),
    };
    let colours = [[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.5]];
    let s = scene::scene_update(&frame, Some(&colours), 4);
    let p = &s.entities[0];
    let size = |v: &Option<foxglove::messages::Vector3>| {
        let v = v.unwrap();
        [v.x, v.y, v.z]
    };
    assert_eq!(size(&p.spheres[0].size), [0.2; 3]);
    assert_eq!(size(&p.cylinders[0].size), [0.4, 0.4, 0.6]);
    assert_eq!(p.cylinders[0].top_scale, 1.0);
    assert_eq!(p.cylinders[0].color.unwrap().a, 0.5);
    let ends: Vec<DVec3> = p.spheres[1..]
        .iter()
        .map(|s| {
            let v = s.pose.unwrap().position.unwrap();
            DVec3::new(v.x, v.y, v.z)
        })
        .collect();
    assert!((ends[0] - DVec3::new(0.5, 0.7, 1.5)).length() < 1e-12);
    assert!((ends[1] - DVec3::new(0.5, 1.3, 1.5)).length() < 1e-12);
    // 12 distinct edges of length 1, 2 or 3 along the axes.
    let pts = scene::box_edge_points(frame.box_edges);
    let mut lens: Vec<f64> = pts
        .chunks(2)
        .map(|e| DVec3::new(e[1].x - e[0].x, e[1].y - e[0].y, e[1].z - e[0].z).length())
        .collect();
    lens.sort_by(f64::total_cmp);
    assert_eq!(
        lens,
        [1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0]
    );
}

#[test]
fn record_log_times_follow_convention_and_are_monotone() {
    let mut frames = random_frames(3, 4, false);
    frames[0].step = 0;
    frames[1].time = 2.5e-9; // -> 3 ns (rounded)
    frames[2].time = 1e-9; // -> 1 ns, clamped to 3 ns
    frames[3].step = 100; // packing step -> 100 ns
    let (_, bytes) = write_recording("logtime.mcap", &frames, false);
    let times: Vec<u64> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == STATE_TOPIC)
        .map(|m| m.log_time)
        .collect();
    assert_eq!(times, [0, 3, 3, 100]);
}

#[test]
fn record_writer_rejects_inconsistent_frames() {
    let path = temp_path("invalid.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    let mut frame = random_frames(1, 1, false).remove(0);
    frame.ids.push(1);
    assert!(matches!(
        w.write_frame(&frame, None),
        Err(RecordError::InvalidInput { .. })
    ));
    frame.ids.pop();
    let colours = vec![[0.0; 4]; frame.ids.len() + 1];
    assert!(matches!(
        w.write_frame(&frame, Some(&colours)),
        Err(RecordError::InvalidInput { .. })
    ));
    assert!(matches!(
        w.write_summary("{not json"),
        Err(RecordError::InvalidInput { .. })
    ));
    w.write_frame(&frame, None).unwrap();
    drop(w); // Finishes the file best-effort.
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.truncated, None);
    assert_frames_bitwise_eq(&rec.frames, &[frame]);
}

#[test]
fn record_killed_writer_leaves_every_frame_readable() {
    let frames = random_frames(21, 6, true);
    let path = temp_path("killed.mcap");
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
        assert!(msg.contains(&format!("{n} complete frames read")), "{msg}");
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

    let missing = read_recording(&temp_path("does-not-exist.mcap")).unwrap_err();
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
    let msg = rec.truncated.unwrap();
    assert!(
        msg.contains(&format!(
            "corrupt recording at byte {}",
            last.chunk_start_offset
        )),
        "{msg}"
    );
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
            Ok(Ok(rec)) if rec.truncated.is_some() => {
                // Chunk contents are under CRCs: frames read are original frames, in order.
                let mut rest = original.frames.iter();
                for f in &rec.frames {
                    assert!(
                        rest.any(|o| bits(o) == bits(f)),
                        "fuzz case {i}: altered frame"
                    );
                }
                if std::env::var_os("MAGSEP_SHOW_FUZZ").is_some() {
                    eprintln!("{i}: {}", rec.truncated.unwrap());
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

/// Writes a sample recording (spheres and capsules in a box, with colours) for the Python check
/// when `MAGSEP_WRITE_SAMPLE` is set: to its value if that is a path ending in `.mcap`, else to
/// `target/record_sample.mcap`.
#[test]
fn record_write_sample_for_python_check() {
    let Ok(target) = std::env::var("MAGSEP_WRITE_SAMPLE") else {
        return;
    };
    let path = if target.ends_with(".mcap") {
        PathBuf::from(target)
    } else {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/record_sample.mcap")
    };
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    let edges = DVec3::new(4e-6, 4e-6, 8e-6);
    for step in 0..20u64 {
        let n = 16;
        let frame = ParticleFrame {
            step,
            time: step as f64 * 1e-4,
            box_edges: edges,
            ids: (0..n as u64).collect(),
            positions: (0..n)
                .map(|i| {
                    let f = i as f64;
                    DVec3::new(
                        (f % 4.0 + 0.5) * 1e-6,
                        ((f / 4.0).floor() + 0.5) * 1e-6,
                        (1.0 + 0.2 * step as f64 + 0.1 * f) * 1e-6,
                    )
                })
                .collect(),
            orientations: (0..n)
                .map(|i| DQuat::from_rotation_y(0.1 * (i + step as usize) as f64))
                .collect(),
            radii: vec![3e-7; n],
            half_lengths: (0..n)
                .map(|i| if i % 3 == 0 { 2e-7 } else { 0.0 })
                .collect(),
            rng_states: (0..n as u64).map(|i| [i, step, 1, 2]).collect(),
            status_json: format!(r#"{{"step": {step}}}"#),
        };
        let colours: Vec<[f32; 4]> = (0..n)
            .map(|i| [i as f32 / n as f32, 0.4, 0.8, 1.0])
            .collect();
        w.write_frame(&frame, Some(&colours)).unwrap();
    }
    w.write_summary(SUMMARY).unwrap();
    w.finish().unwrap();
    eprintln!("wrote {}", path.display());
}
