//! Encoding shortcuts of the writer checked against their reference: the cached scene
//! entities against prost's encoding of the whole scene update, and the summary written from a
//! `serde_json::Value` against the summary written from its text.

use glam::DVec3;

use super::{TempFile, metadata, random_frames};
use crate::{RecordingWriter, scene};

/// The writer's encoder (static entities encoded once, timestamps spliced in) gives the bytes
/// prost gives for the whole scene update, frame after frame with the cache reused, with
/// walls, fibres, a backdrop and rods.
#[test]
fn cached_scene_encoding_equals_the_full_encoding_bit_for_bit() {
    let decor = scene::SceneDecor {
        backdrop: (0..7)
            .map(|k| crate::BackdropCube {
                center: DVec3::new(0.5, 0.5, 0.1 * k as f64),
                size: DVec3::new(1.0, 1.0, 0.1),
                colour: [0.9, 0.3, 0.2, 0.1],
            })
            .collect(),
        fibres: vec![crate::FibreShape {
            center: DVec3::new(0.2, 0.3, 0.4),
            axis: DVec3::new(0.0, 1.0, 1.0),
            radius: 0.05,
            half_length: 0.3,
        }],
        walls: Some(crate::WallShape::Wedge { angle: 0.4 }),
        ..Default::default()
    };
    let mut frames = random_frames(21, 9, true);
    // frames that keep the previous frame's box (the cached outline and walls are reused),
    // then edges that differ from it only in the sign of zero, and zero edges (no outline)
    for k in [2, 3, 5] {
        frames[k].box_edges = frames[k - 1].box_edges;
    }
    frames[6].box_edges = DVec3::new(-0.0, 1.0, 2.0);
    frames[7].box_edges = DVec3::new(0.0, 1.0, 2.0);
    frames[8].box_edges = DVec3::ZERO;
    let mut cache = scene::SceneCache::default();
    let mut fast = Vec::new();
    let mut decor = decor;
    for round in 0..2 {
        for (k, frame) in frames.iter().enumerate() {
            let log_time = 1_000_000_007 * k as u64 + 3;
            let mut full = Vec::new();
            foxglove::Encode::encode(
                &scene::scene_update(frame, None, &decor, log_time),
                &mut full,
            )
            .unwrap();
            scene::encode_scene_update(frame, None, &decor, log_time, &mut cache, &mut fast);
            assert_eq!(fast, full, "round {round}, frame {k}");
            if k == 4 {
                // walls change between frames of the same box
                decor.walls = [None, Some(crate::WallShape::Slab)][round];
            }
        }
    }
}

#[test]
fn summary_from_a_value_writes_the_bytes_of_its_text() {
    let frames = random_frames(5, 3, true);
    let summary = serde_json::json!({"steps": 1000, "accepted": 0.5, "x": [1e-300, -0.0, 3]});
    let write = |name: &str, as_value: bool| {
        let path = TempFile::new(name);
        let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
        for f in &frames {
            w.write_frame(f, None).unwrap();
        }
        if as_value {
            w.write_summary_value(&summary).unwrap();
        } else {
            w.write_summary(&summary.to_string()).unwrap();
        }
        w.finish().unwrap();
        std::fs::read(&path).unwrap()
    };
    let (text, value) = (
        write("summary_text.mcap", false),
        write("summary_value.mcap", true),
    );
    assert_eq!(text, value);
    let read = crate::read_recording_bytes(&value)
        .unwrap()
        .summary_json
        .unwrap();
    let back: serde_json::Value = serde_json::from_str(&read).unwrap();
    assert_eq!(back, summary);
}
