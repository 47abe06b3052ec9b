//! Recordings of brownian runs: captured particles coloured in the scene channel, replay
//! recomputes the capture curve, resume from a cut recording continues bitwise.

use magsep::plugins::record::read_recording;
use magsep::prelude::*;
use magsep::replay::resume;
use magsep::scene::NoProgress;
use magsep::scene::parse_scene;

const SCENE: &str = r#"
[simulation]
pipeline = "brownian"
seed = 3
[external_field]
flux_density = [1.0, 0.0, 0.0]
[[fibres]]
kind = "cylinder"
radius = 300e-6
half_length = 6e-3
axis = [1.0, 0.0, 0.0]
saturation_magnetisation = 985e3
[brownian]
time_step = 5e-5
duration = 0.03
observe_every = 20
[[particles]]
count = 12
shape = { kind = "sphere", radius = 125e-9 }
moment = { kind = "saturated", moment = 5.151e-16 }
placement = { kind = "fibre_top", fibre = 0, gap = 1e-6, height = 20e-6 }
[record]
every = 60
flush_every_frame = true   # one chunk per frame, so that a cut in the middle keeps frames
"#;

fn bits(f: &magsep::plugins::record::ParticleFrame) -> Vec<u64> {
    f.positions
        .iter()
        .flat_map(|p| p.to_array().map(f64::to_bits))
        .chain(f.rng_states.iter().flatten().copied())
        .collect()
}

#[test]
fn replay_reproduces_the_capture_curve_and_resume_is_bitwise() {
    let dir = std::env::temp_dir().join(format!("magsep-bd-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let full = dir.join("full.mcap");
    let scene = parse_scene(SCENE, &Default::default()).unwrap();
    let mut sim = Simulation::from_scene(
        &scene,
        RunOptions {
            record: Some(full.clone()),
            ..Default::default()
        },
    )
    .unwrap();
    let summary = sim.run(|_| {}).unwrap();
    let captured = summary["captured_fraction"]["mean"].as_f64().unwrap();
    assert!(
        captured > 0.0 && captured < 1.0,
        "want a partly captured run, got {captured}"
    );

    // replay: the same curve and fractions
    let rec = read_recording(&full).unwrap();
    let (replayed, _) = magsep::replay::replay(&full).unwrap();
    for key in [
        "capture_curve",
        "captured_fraction",
        "brownian_fraction",
        "groups",
        "steps",
    ] {
        assert_eq!(replayed[key], summary[key], "{key}");
    }
    // captured particles are coloured in the viewer channel: the status says who
    let last = rec.frames.last().unwrap();
    assert!(last.status_json.contains("\"captured\""));

    // cut the file in the middle: the reader keeps the complete frames; resume from there
    let bytes = std::fs::read(&full).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 5]).unwrap();
    let partial = read_recording(&cut).unwrap();
    assert!(partial.truncated.is_some());
    let k = partial.frames.len();
    assert!(
        k >= 2 && k < rec.frames.len(),
        "{k} of {}",
        rec.frames.len()
    );
    let resumed_path = dir.join("resumed.mcap");
    let resumed = resume(
        &cut,
        &Default::default(),
        Some(resumed_path.clone()),
        &[],
        &NoProgress,
    )
    .unwrap();
    for key in [
        "capture_curve",
        "captured_fraction",
        "brownian_fraction",
        "steps",
        "stepper",
    ] {
        let (mut a, mut b) = (resumed[key].clone(), summary[key].clone());
        // a cost counter, not state: the resumed run builds its lists afresh
        for v in [&mut a, &mut b] {
            if let Some(o) = v.as_object_mut() {
                o.remove("neighbour_list_builds");
            }
        }
        assert_eq!(a, b, "{key}");
    }
    let again = read_recording(&resumed_path).unwrap();
    let (a, b) = (rec.frames.last().unwrap(), again.frames.last().unwrap());
    assert_eq!(a.step, b.step);
    assert_eq!(
        bits(a),
        bits(b),
        "resumed run differs from the uninterrupted one"
    );
    assert_eq!(a.status_json, b.status_json);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn resume_of_an_ensemble_gives_the_whole_runs_summary_and_replay_says_it_has_one_replicate() {
    let dir = std::env::temp_dir().join(format!("magsep-bd-ensemble-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let full = dir.join("full.mcap");
    let text = SCENE.replace("observe_every = 20", "observe_every = 20\nruns = 3");
    let scene = parse_scene(&text, &Default::default()).unwrap();
    let options = RunOptions {
        record: Some(full.clone()),
        ..Default::default()
    };
    let summary = magsep::sim::run_scene(&scene, &options, &NoProgress).unwrap();
    assert_eq!(summary["runs"], 3);

    // replay has replicate 0 only, and says so
    let (replayed, _) = magsep::replay::replay(&full).unwrap();
    assert_eq!(replayed["runs"], 1);
    assert_eq!(replayed["runs_in_scene"], 3);
    assert!(replayed["note"].as_str().unwrap().contains("replicate 0"));

    // resume from a cut file: replicate 0 continues, the others run again: the whole run
    let bytes = std::fs::read(&full).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert!(read_recording(&cut).unwrap().frames.len() >= 2);
    let resumed = resume(&cut, &Default::default(), None, &[], &NoProgress).unwrap();
    for key in [
        "runs",
        "capture_curve",
        "captured_fraction",
        "brownian_fraction",
        "steps",
    ] {
        assert_eq!(resumed[key], summary[key], "{key}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `replay` on the committed bad recordings (a brownian run): damage is reported under
/// `damaged` (a CRC mismatch, bytes after the footer), a cut under `truncated` only, and the
/// values that frames cannot give (the neighbour-list builds; the wall time of a file without
/// run summary) are `null` and listed in `not_recomputed`.
#[test]
fn replay_names_damage_and_what_frames_cannot_give() {
    let dir = std::path::Path::new("tests/data/bad_recordings");
    let replay = |name: &str| magsep::replay::replay(&dir.join(name)).unwrap().0;
    let listed = |s: &serde_json::Value, key: &str| {
        (s["not_recomputed"].as_array()).is_some_and(|l| l.iter().any(|k| k == key))
    };
    let base = replay("base.mcap");
    assert!(base.get("damaged").is_none() && base.get("truncated").is_none());
    assert!(base["stepper"]["neighbour_list_builds"].is_null(), "{base}");
    assert!(listed(&base, "stepper.neighbour_list_builds"), "{base}");
    assert!(base["wall_time_s"].as_f64().is_some());
    assert!(!listed(&base, "wall_time_s"));

    let crc = replay("flip_chunk_data.mcap");
    let d = crc["damaged"].as_str().unwrap_or_default();
    assert!(d.contains("corrupt recording at byte 6265"), "{crc}");
    assert!(crc.get("truncated").is_none(), "{crc}");

    let trailing = replay("trailing_bytes.mcap");
    let d = trailing["damaged"].as_str().unwrap_or_default();
    assert!(
        d.contains("100 trailing bytes after the footer"),
        "{trailing}"
    );
    assert!(trailing.get("truncated").is_none(), "{trailing}");

    let cut = replay("cut_mid_chunk.mcap");
    assert!(
        cut["truncated"].as_str().is_some() && cut.get("damaged").is_none(),
        "{cut}"
    );
    assert!(
        cut["wall_time_s"].is_null() && listed(&cut, "wall_time_s"),
        "{cut}"
    );
}
