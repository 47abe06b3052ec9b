//! Tests of plugin channels, plugin metadata and self-describing schemas.

use super::{TempFile, assert_frames_bitwise_eq, metadata, random_frames, sample_target};
use crate::schema::field_comments;
use crate::*;
use prost::Message as _;
use prost_types::FileDescriptorSet;
use std::collections::BTreeMap;

/// A plugin message: `magsep.test.Energy` (hand-encoded below with prost's encoders).
fn energy_schema() -> ProtobufSchema {
    protobuf_schema(
        "magsep.test",
        "Energy",
        "Energies of the system at one step.",
        &[
            ProtoField::new("step", 1, ProtoType::Uint64, "schedule step"),
            ProtoField::new("kinetic_j", 2, ProtoType::Double, "kinetic energy [J]"),
            ProtoField::new("label", 3, ProtoType::String, "free text"),
            ProtoField::new("per_particle_j", 4, ProtoType::Double, "energies [J]")
                .with_label(ProtoLabel::Repeated),
        ],
    )
    .unwrap()
}

fn energy_message(step: u64, kinetic: f64) -> Vec<u8> {
    use prost::encoding::{double, string, uint64};
    let mut buf = Vec::new();
    uint64::encode(1, &step, &mut buf);
    double::encode(2, &kinetic, &mut buf);
    string::encode(3, &format!("step {step}"), &mut buf);
    double::encode_packed(4, &[kinetic, 2.0 * kinetic], &mut buf);
    buf
}

/// Decoder of [`energy_message`].
#[derive(Clone, PartialEq, prost::Message)]
struct Energy {
    #[prost(uint64, tag = "1")]
    step: u64,
    #[prost(double, tag = "2")]
    kinetic_j: f64,
    #[prost(string, tag = "3")]
    label: String,
    #[prost(double, repeated, tag = "4")]
    per_particle_j: Vec<f64>,
}

/// Writes frames interleaved with messages on `/energy` and a schemaless JSON channel, a
/// plugin metadata record; returns the frames.
fn write_with_channels(path: &std::path::Path, finish: bool) -> Vec<ParticleFrame> {
    let frames = random_frames(31, 5, true);
    let mut w = RecordingWriter::create(path, &metadata()).unwrap();
    let energy = w.add_protobuf_channel("/energy", &energy_schema()).unwrap();
    for (k, f) in frames.iter().enumerate() {
        w.write_frame(f, None).unwrap();
        w.write_message(
            energy,
            1000 + k as u64,
            &energy_message(k as u64, 0.5 * k as f64),
        )
        .unwrap();
        if k == 2 {
            // A channel added mid-run, a batch of two messages.
            let notes = w.add_channel("/notes", "", "", &[], "json").unwrap();
            w.write_messages(&[(notes, 7, br#"{"a": 1}"#), (notes, 8, br#"{"a": 2}"#)])
                .unwrap();
        }
    }
    let entries = BTreeMap::from([("fibre_count".to_string(), "3".to_string())]);
    w.add_metadata("plugin.fibres", entries).unwrap();
    if finish {
        w.finish().unwrap();
    } else {
        std::mem::forget(w);
    }
    frames
}

#[test]
fn record_custom_channel_round_trips() {
    let path = TempFile::new("custom-channel.mcap");
    let frames = write_with_channels(&path, true);
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(reader.is_indexed());
    let channels = reader.channels();
    let topics: Vec<(&str, &str, u64)> = channels
        .iter()
        .map(|c| (c.topic.as_str(), c.schema_name.as_str(), c.message_count))
        .collect();
    assert_eq!(
        topics,
        [
            (STATE_TOPIC, STATE_SCHEMA_NAME, 5),
            (SCENE_TOPIC, "foxglove.SceneUpdate", 5),
            ("/energy", "magsep.test.Energy", 5),
            ("/notes", "", 2),
        ]
    );
    let schema = reader.schema("/energy").unwrap();
    assert_eq!(schema.data, energy_schema().data);
    let fds = FileDescriptorSet::decode(schema.data.as_slice()).unwrap();
    assert_eq!(
        field_comments(&fds)[1],
        ("kinetic_j".into(), "kinetic energy [J]".into())
    );

    let energies: Vec<_> = reader
        .messages(Some("/energy"))
        .map(|m| m.unwrap())
        .collect();
    assert_eq!(energies.len(), 5);
    for (k, m) in energies.iter().enumerate() {
        assert_eq!((m.log_time_ns, m.sequence), (1000 + k as u64, k as u32));
        assert_eq!(m.schema_name, "magsep.test.Energy");
        let e = Energy::decode(m.data.as_slice()).unwrap();
        assert_eq!((e.step, e.kinetic_j), (k as u64, 0.5 * k as f64));
        assert_eq!(e.per_particle_j, [e.kinetic_j, 2.0 * e.kinetic_j]);
    }
    let notes: Vec<_> = reader
        .messages(Some("/notes"))
        .map(|m| m.unwrap().data)
        .collect();
    assert_eq!(notes, [br#"{"a": 1}"#.to_vec(), br#"{"a": 2}"#.to_vec()]);
    assert_eq!(reader.messages(None).count(), 17);
    assert_eq!(reader.messages(Some("/nothing")).count(), 0);
    let names: Vec<_> = reader
        .metadata_records()
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(names, [METADATA_NAME, "plugin.fibres"]);
    assert_eq!(reader.metadata(), Some(&metadata()));

    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.truncated, None);
    assert_frames_bitwise_eq(&rec.frames, &frames);
    assert_eq!(rec.channels, channels);
    assert_eq!(rec.metadata_records[1].entries["fibre_count"], "3");
    // The mcap crate reads the custom channels too.
    let bytes = std::fs::read(&path).unwrap();
    let n = mcap::MessageStream::new(&bytes)
        .unwrap()
        .filter(|m| m.as_ref().unwrap().channel.topic == "/energy")
        .count();
    assert_eq!(n, 5);
}

#[test]
fn record_killed_writer_keeps_every_custom_message() {
    let path = TempFile::new("custom-killed.mcap");
    let frames = write_with_channels(&path, false);
    let mut reader = RecordingReader::open(&path).unwrap();
    assert!(!reader.is_indexed());
    let msg = reader.truncated().unwrap().to_string();
    assert!(
        msg.contains("after a complete record") && msg.contains("5 complete frames"),
        "{msg}"
    );
    assert_eq!(reader.messages(Some("/energy")).count(), 5);
    assert_eq!(reader.messages(Some("/notes")).count(), 2);
    let got: Vec<_> = reader.frames().map(|f| f.unwrap()).collect();
    assert_frames_bitwise_eq(&got, &frames);
    assert_eq!(reader.metadata_records().len(), 2);
}

#[test]
fn record_writer_refuses_reserved_and_duplicate_channels() {
    let path = TempFile::new("custom-refused.mcap");
    let mut w = RecordingWriter::create(&path, &metadata()).unwrap();
    for topic in [STATE_TOPIC, SCENE_TOPIC, ""] {
        let err = w.add_channel(topic, "x", "", &[], "json").unwrap_err();
        assert!(matches!(err, RecordError::InvalidInput { .. }), "{err}");
    }
    let a = w.add_channel("/a", "", "", &[], "json").unwrap();
    assert!(w.add_channel("/a", "", "", &[], "cbor").is_err());
    for name in [METADATA_NAME, SUMMARY_METADATA_NAME, ""] {
        assert!(w.add_metadata(name, BTreeMap::new()).is_err());
    }
    let path2 = TempFile::new("custom-other.mcap");
    let mut other = RecordingWriter::create(&path2, &metadata()).unwrap();
    let b = other.add_channel("/b", "", "", &[], "json").unwrap();
    let c = other.add_channel("/c", "", "", &[], "json").unwrap();
    assert!(
        w.write_message(c, 0, b"{}").is_err(),
        "a handle of another writer"
    );
    other.write_message(b, 0, b"{}").unwrap();
    w.write_message(a, 0, b"{}").unwrap();
    w.finish().unwrap();
    other.finish().unwrap();
}

#[test]
fn record_protobuf_schema_validates_and_documents_fields() {
    let bad: [&[ProtoField]; 5] = [
        &[ProtoField::new("1x", 1, ProtoType::Double, "")],
        &[ProtoField::new("a", 0, ProtoType::Double, "")],
        &[ProtoField::new("a", 19_500, ProtoType::Double, "")],
        &[
            ProtoField::new("a", 1, ProtoType::Double, ""),
            ProtoField::new("b", 1, ProtoType::Double, ""),
        ],
        &[ProtoField::new("a", 1, ProtoType::Message, "")],
    ];
    for fields in bad {
        let err = protobuf_schema("p", "M", "", fields).unwrap_err();
        assert!(matches!(err, RecordError::InvalidInput { .. }), "{err}");
    }
    assert!(protobuf_schema("p..q", "M", "", &[]).is_err());
    assert!(protobuf_schema("p", "M-1", "", &[]).is_err());

    // The /state descriptor documents every field with its layout and unit.
    let (_, _, data) = crate::proto::state_schema().unwrap();
    let fds = FileDescriptorSet::decode(data.as_slice()).unwrap();
    let comments = field_comments(&fds);
    assert_eq!(comments.len(), 10);
    for (name, comment) in &comments {
        assert!(
            comment.contains('[') || comment.contains("no unit"),
            "field {name} has no unit: {comment:?}"
        );
    }
    assert!(comments[4].1.contains("[m]"), "{:?}", comments[4]);
    let file = &fds.file[0];
    assert_eq!(file.name(), "magsep/particle_state.proto");
    assert_eq!(file.syntax(), "proto3");
    let doc = file.source_code_info.as_ref().unwrap().location[0]
        .leading_comments
        .clone()
        .unwrap();
    assert!(doc.contains("metres") && doc.contains("ns"), "{doc}");
}

#[test]
fn record_metadata_plugins_and_extra_round_trip() {
    let meta = metadata();
    assert!(!meta.plugins.is_empty() && !meta.extra.is_empty());
    let path = TempFile::new("meta-plugins.mcap");
    RecordingWriter::create(&path, &meta)
        .unwrap()
        .finish()
        .unwrap();
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.metadata.as_ref(), Some(&meta));
    let entries = &rec.metadata_records[0].entries;
    let plugins: serde_json::Value = serde_json::from_str(&entries["plugins"]).unwrap();
    assert_eq!(plugins[0]["name"], "brownian_forces");
    assert_eq!(plugins[0]["params"]["temperature_k"], 293.15);
    // As JSON, older serialisations without the new fields still deserialise.
    let old = r#"{"scene_text": "", "seed": 1, "version": "0", "pipeline": "packing",
                  "schedule": {}, "dt": 0.0}"#;
    let parsed: RecordingMetadata = serde_json::from_str(old).unwrap();
    assert!(parsed.plugins.is_empty() && parsed.extra.is_empty());
}

/// Writes a recording with plugin channels (`/energy`: protobuf `magsep.test.Energy`; `/notes`:
/// JSON) and a plugin metadata record, and checks it reads back: to the `.mcap` path in
/// `MAGSEP_WRITE_CUSTOM_SAMPLE` (for the Python check), else to a temporary file.
#[test]
fn record_write_custom_channel_sample_for_python_check() {
    let (target, _temp) = sample_target("MAGSEP_WRITE_CUSTOM_SAMPLE", "custom.mcap");
    write_with_channels(&target, true);
    let rec = crate::read_recording(&target).unwrap();
    assert!(rec.truncated.is_none());
    let topics: Vec<&str> = rec.channels.iter().map(|c| c.topic.as_str()).collect();
    assert!(
        topics.contains(&"/energy") && topics.contains(&"/notes"),
        "{topics:?}"
    );
}
