//! The `magsep` binary: exit codes, validation messages with key paths, record / info /
//! replay, truncated and corrupt recordings, determinism across thread counts.

use crate::common::{magsep, stderr};
use std::path::PathBuf;
use std::process::Output;

use magsep::plugins::record::read_recording;

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp_path("cli", name)
}

const GOOD: &str = r#"
[simulation]
pipeline = "packing"
seed = 4
[container]
kind = "periodic_box"
[[particles]]
count = 40
shape = { kind = "sphere", radius = 0.5 }
[[particles]]
count = 10
shape = { kind = "spherocylinder", radius = 0.5, cylinder_length = 1.0 }
[record]
every = 5
"#;

fn write(name: &str, text: &str) -> PathBuf {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn bad_input_gives_exit_2_and_names_the_key() {
    let cases = [
        (
            "unknown_key",
            GOOD.replace("seed = 4", "seed = 4\nsed = 5"),
            "simulation.sed",
        ),
        (
            "negative_radius",
            GOOD.replace("radius = 0.5 }\n[[", "radius = -1e-9 }\n[["),
            "particles[0].shape.radius",
        ),
        (
            "fraction_above_1",
            format!("{GOOD}\n[packing]\ninitial_packing_fraction = 1.5\n"),
            "packing.initial_packing_fraction",
        ),
        (
            "count_zero",
            GOOD.replace("count = 40", "count = 0"),
            "particles[0].count",
        ),
        (
            "non_numeric",
            GOOD.replace("count = 10", "count = \"ten\""),
            "particles[1].count",
        ),
    ];
    for (name, text, key) in cases {
        let p = write(&format!("{name}.toml"), &text);
        for cmd in ["validate", "run"] {
            let o = magsep(&[cmd, p.to_str().unwrap()]);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{name} {cmd}: {err}");
            assert!(
                err.contains(key),
                "{name} {cmd}: expected key {key} in: {err}"
            );
            assert!(!err.contains("panicked"), "{name}: {err}");
        }
    }
    // several errors in one file are all reported
    let p = write(
        "many.toml",
        &GOOD
            .replace("count = 40", "count = 0")
            .replace("count = 10", "count = \"ten\""),
    );
    let err = stderr(&magsep(&["validate", p.to_str().unwrap()]));
    assert!(
        err.contains("particles[0].count") && err.contains("particles[1].count"),
        "{err}"
    );
    // a missing file and unknown subcommands are bad input too
    assert_eq!(
        magsep(&["validate", "/nonexistent/scene.toml"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(magsep(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(magsep(&["bench", "nothing"]).status.code(), Some(2));
}

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}): {}",
            String::from_utf8_lossy(&o.stdout)
        )
    })
}

#[test]
fn record_info_replay_truncation_and_determinism() {
    let scene = write("good.toml", GOOD);
    let rec1 = tmp("t1.mcap");
    let rec2 = tmp("t2.mcap");
    let o1 = magsep(&[
        "run",
        scene.to_str().unwrap(),
        "--record",
        rec1.to_str().unwrap(),
        "--quiet",
        "--threads",
        "1",
        "--force",
    ]);
    assert!(o1.status.success(), "{}", stderr(&o1));
    let o2 = magsep(&[
        "run",
        scene.to_str().unwrap(),
        "--record",
        rec2.to_str().unwrap(),
        "--quiet",
        "--threads",
        "2",
        "--force",
    ]);
    assert!(o2.status.success(), "{}", stderr(&o2));
    let (s1, s2) = (json(&o1), json(&o2));
    for key in [
        "pipeline",
        "particles",
        "packing_fraction",
        "mean_contact_number",
        "nematic_order",
        "compression_steps",
        "wall_time_s",
    ] {
        assert!(!s1[key].is_null(), "summary lacks {key}: {s1}");
    }
    // determinism: identical state frames at 1 and 2 threads
    let (r1, r2) = (
        read_recording(&rec1).unwrap(),
        read_recording(&rec2).unwrap(),
    );
    assert!(r1.frames.len() >= 2);
    assert_eq!(
        r1.frames, r2.frames,
        "state channel differs between 1 and 2 threads"
    );
    assert_eq!(s1["packing_fraction"], s2["packing_fraction"]);
    // replay reproduces every summary key exactly (wall time comes from the recording)
    let replay = magsep(&["replay", rec1.to_str().unwrap()]);
    assert!(replay.status.success(), "{}", stderr(&replay));
    let sr = json(&replay);
    for key in magsep::packing::PACKING_SUMMARY_KEYS {
        assert_eq!(sr[*key], s1[*key], "replay differs in {key}");
    }
    assert_eq!(sr["wall_time_s"], s1["wall_time_s"]);
    // info names channels, frames and metadata
    let info = magsep(&["info", rec1.to_str().unwrap(), "--json"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let vi = json(&info);
    assert_eq!(vi["complete"], true);
    assert_eq!(vi["frames"].as_u64().unwrap() as usize, r1.frames.len());
    let topics: Vec<_> = vi["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["topic"].as_str().unwrap().to_string())
        .collect();
    assert!(topics.contains(&"/state".to_string()) && topics.contains(&"/scene".to_string()));
    assert!(
        vi["metadata"]["scene_text"]
            .as_str()
            .unwrap()
            .contains("periodic_box")
    );
    // a recording cut short still yields its finished frames and says so
    let bytes = std::fs::read(&rec1).unwrap();
    let cut = tmp("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let info = magsep(&["info", cut.to_str().unwrap(), "--json"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let vi = json(&info);
    assert_eq!(vi["complete"], false);
    assert!(vi["truncated"].as_str().unwrap().len() > 10);
    let n_cut = vi["frames"].as_u64().unwrap() as usize;
    assert!(n_cut >= 1 && n_cut < r1.frames.len());
    assert_eq!(read_recording(&cut).unwrap().frames[..], r1.frames[..n_cut]);
    // a corrupt file is reported precisely, with exit 2
    let junk = write("junk.mcap", "this is not an mcap file at all");
    let o = magsep(&["info", junk.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("junk.mcap"), "{}", stderr(&o));
}

#[test]
fn every_executor_records_the_same_frames() {
    let scene = write("exec.toml", GOOD);
    let mut frames = Vec::new();
    for executor in ["auto", "single", "multi"] {
        let rec = tmp(&format!("exec_{executor}.mcap"));
        let o = magsep(&[
            "run",
            scene.to_str().unwrap(),
            "--record",
            rec.to_str().unwrap(),
            "--quiet",
            "--threads",
            "2",
            "--executor",
            executor,
            "--force",
        ]);
        assert!(o.status.success(), "{executor}: {}", stderr(&o));
        frames.push(read_recording(&rec).unwrap().frames);
    }
    assert!(frames[0].len() >= 2);
    assert_eq!(frames[0], frames[1], "auto and single differ");
    assert_eq!(frames[0], frames[2], "auto and multi differ");
    let o = magsep(&["run", scene.to_str().unwrap(), "--executor", "fast"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--executor"), "{}", stderr(&o));
}

#[test]
fn progress_goes_to_a_log_as_plain_lines_and_quiet_silences_it() {
    // stderr is a pipe here, not a terminal: the bar becomes a line every interval
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spheres_500.toml");
    let run = |quiet: bool| {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_magsep"));
        cmd.args(["run", scene])
            .env(magsep::cli::progress::INTERVAL_ENV, "0.05");
        if quiet {
            cmd.arg("--quiet");
        }
        cmd.output().expect("binary runs")
    };
    let o = run(false);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains(" steps")).collect();
    assert!(!lines.is_empty(), "no progress line in: {err}");
    assert!(lines.iter().all(|l| l.starts_with('[')), "{err}");
    assert!(json(&o)["packing_fraction"].as_f64().unwrap() > 0.6);
    let o = run(true);
    assert!(o.status.success());
    assert!(!stderr(&o).contains(" steps"), "{}", stderr(&o));
}

#[test]
fn an_unusable_progress_interval_is_warned_about_once() {
    let scene = write("interval.toml", GOOD);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_magsep"))
        .args(["run", scene.to_str().unwrap()])
        .env(magsep::cli::progress::INTERVAL_ENV, "abc")
        .output()
        .expect("binary runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let warned = err.matches("MAGSEP_PROGRESS_INTERVAL=\"abc\"").count();
    assert_eq!(warned, 1, "{err}");
}
