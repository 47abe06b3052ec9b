//! Tests of the recording format: round trips, truncation, corruption, interoperability.

mod background;
mod buffering;
mod channels;
mod damage;
mod encoding;
mod seek;
mod stream;

use crate::proto::{ParticleStateWire, state_schema};
use crate::*;
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

/// A file under the system temp dir, removed on drop.
pub(crate) struct TempFile(PathBuf);

impl TempFile {
    pub(crate) fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join("magsep-record-tests");
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir.join(format!("{}-{name}", std::process::id())))
    }
}

/// Where a sample for the Python checks goes: the `.mcap` path in the environment variable
/// `var` (kept), else a [`TempFile`] named `name` (the guard, removed when dropped).
pub(crate) fn sample_target(var: &str, name: &str) -> (PathBuf, Option<TempFile>) {
    match std::env::var(var).ok().filter(|t| t.ends_with(".mcap")) {
        Some(t) => (PathBuf::from(t), None),
        None => {
            let temp = TempFile::new(name);
            (temp.to_path_buf(), Some(temp))
        }
    }
}

impl AsRef<std::path::Path> for TempFile {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl std::ops::Deref for TempFile {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
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
pub(crate) fn random_frames(seed: u64, count: usize, physical: bool) -> Vec<ParticleFrame> {
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

pub(crate) fn metadata() -> RecordingMetadata {
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
        plugins: vec![
            PluginInfo {
                name: "brownian_forces".into(),
                params: serde_json::json!({"temperature_k": 293.15, "fibre_radius_m": 1e-5}),
            },
            PluginInfo {
                name: "record".into(),
                params: serde_json::Value::Null,
            },
        ],
        extra: BTreeMap::from([("capture.rule".into(), "touch ✓".into())]),
    }
}

pub(crate) const SUMMARY: &str = r#"{"steps": 1000, "accepted": 0.5}"#;

/// Writes a finished recording of `frames` to a temp file and returns its bytes.
pub(crate) fn write_recording(
    name: &str,
    frames: &[ParticleFrame],
    summary: bool,
) -> (TempFile, Vec<u8>) {
    let path = TempFile::new(name);
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
pub(crate) fn bits(f: &ParticleFrame) -> Vec<u64> {
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

pub(crate) fn assert_frames_bitwise_eq(a: &[ParticleFrame], b: &[ParticleFrame]) {
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
        let path = TempFile::new("meta.mcap");
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
    let expect = |id: u16, topic: &str, schema: &str| ChannelInfo {
        id,
        topic: topic.into(),
        schema_name: schema.into(),
        schema_encoding: "protobuf".into(),
        message_encoding: "protobuf".into(),
        message_count: 9,
    };
    let ids: Vec<u16> = rec.channels.iter().map(|c| c.id).collect();
    assert_eq!(
        rec.channels,
        vec![
            expect(ids[0], STATE_TOPIC, STATE_SCHEMA_NAME),
            expect(ids[1], SCENE_TOPIC, "foxglove.SceneUpdate")
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
    let s = scene::scene_update(&frame, Some(&colours), &Default::default(), 4);
    let unbounded = ParticleFrame {
        box_edges: DVec3::ZERO,
        ..frame.clone()
    };
    assert_eq!(
        scene::scene_update(&unbounded, None, &Default::default(), 4)
            .entities
            .len(),
        1
    );
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
    let path = TempFile::new("invalid.mcap");
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

/// Writes a sample recording (spheres and capsules in a box, with colours) and checks that it
/// reads back: to the `.mcap` path in `MAGSEP_WRITE_SAMPLE` (for the Python check), else to a
/// temporary file.
#[test]
fn record_write_sample_for_python_check() {
    let (path, _temp) = sample_target("MAGSEP_WRITE_SAMPLE", "sample.mcap");
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
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.frames.len(), 20);
    assert!(rec.truncated.is_none());
}

#[test]
fn record_scene_draws_the_backdrop() {
    let frame = ParticleFrame {
        step: 1,
        time: 0.0,
        box_edges: DVec3::splat(1.0),
        ids: vec![0],
        positions: vec![DVec3::splat(0.5)],
        orientations: vec![DQuat::IDENTITY],
        radii: vec![0.1],
        half_lengths: vec![0.0],
        rng_states: vec![[0; 4]],
        status_json: "{}".into(),
    };
    let decor = scene::SceneDecor {
        backdrop: vec![crate::BackdropCube {
            center: DVec3::new(0.5, 0.5, 0.25),
            size: DVec3::new(1.0, 1.0, 0.5),
            colour: [0.9, 0.3, 0.2, 0.1],
        }],
        ..Default::default()
    };
    let s = scene::scene_update(&frame, None, &decor, 1);
    let b = s
        .entities
        .iter()
        .find(|e| e.id == scene::BACKDROP_ENTITY)
        .expect("backdrop entity");
    assert_eq!(b.cubes.len(), 1);
    assert_eq!(b.cubes[0].color.unwrap().a, f64::from(0.1f32));
}
