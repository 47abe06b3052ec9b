//! `--set PATH=VALUE` overrides on `magsep run` and `magsep validate`: typed and validated
//! with key paths like the file itself, equal to editing the file by hand, recorded in the
//! recording's metadata (and `magsep replay` of it works).

use crate::common::{magsep, stderr};
use std::path::PathBuf;
use std::process::Output;

use serde_json::Value;

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp_path("overrides", name)
}

/// One free Brownian particle, 10 steps of 1 ms (SI units).
pub const TRIVIAL: &str = r#"# a comment that must survive
[simulation]
pipeline = "brownian"
seed = 1

[brownian]
time_step = 1e-3          # [s]
duration = 1e-2           # [s]
mobility = "free_draining"
contact = { kind = "none" }
dipole_cutoff = 0

[[particles]]
count = 2
shape = { kind = "sphere", radius = 100e-9 }
placement = { kind = "box", min = [0.0, 0.0, 0.0], max = [1e-6, 1e-6, 1e-6] }
"#;

fn write(name: &str, text: &str) -> PathBuf {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The summary printed by a run, without its wall-clock times.
fn summary(o: &Output) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    let mut v: Value = serde_json::from_slice(&o.stdout).expect("JSON summary");
    if let Value::Object(m) = &mut v {
        m.retain(|k, _| !k.contains("wall"));
    }
    v
}

#[test]
fn bad_overrides_give_exit_2_and_the_key_path() {
    let scene = write("trivial.toml", TRIVIAL);
    let s = scene.to_str().unwrap();
    let cases = [
        ("brownian.duration=-1.0", "brownian.duration:"),
        ("brownian.durration=1.0", "brownian.durration:"),
        (
            "particles[0].shape.radius=fire",
            "particles[0].shape.radius:",
        ),
        ("particles[3].count=1", "particles[3]:"),
        ("simulation.seed.x=1", "simulation.seed.x:"),
        ("particles[0].count=[1,", "particles[0].count:"),
        ("particles[0].count", "PATH=VALUE"),
        ("particles[x].count=1", "particles[x]"),
    ];
    for (arg, key) in cases {
        for cmd in ["validate", "run"] {
            let o = magsep(&[cmd, s, "--set", arg, "--quiet"][..if cmd == "run" { 5 } else { 4 }]);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{cmd} --set {arg}: {}",
                stderr(&o)
            );
            let e = stderr(&o);
            assert!(e.contains(key), "{cmd} --set {arg}: {e}");
            assert!(!e.contains("panicked"), "{e}");
        }
    }
    // a good override validates, and is listed
    let o = magsep(&["validate", s, "--set", "brownian.duration=2e-2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["overrides"][0], "brownian.duration=2e-2");
}

#[test]
fn a_run_with_set_equals_the_hand_edited_file_and_is_recorded() {
    let scene = write("base.toml", TRIVIAL);
    let edited = TRIVIAL
        .replace("duration = 1e-2 ", "duration = 2e-2 ")
        .replace("seed = 1", "seed = 9")
        .replace("radius = 100e-9", "radius = 150e-9");
    assert_ne!(edited, TRIVIAL);
    let by_hand = write("edited.toml", &edited);
    let rec = tmp("set.mcap");
    let _ = std::fs::remove_file(&rec);
    let sets = [
        "brownian.duration=2e-2",
        "simulation.seed=9",
        "particles[0].shape.radius=150e-9",
    ];
    let mut args = vec!["run", scene.to_str().unwrap(), "--quiet"];
    for s in &sets {
        args.extend(["--set", s]);
    }
    args.extend(["--record", rec.to_str().unwrap()]);
    let with_set = summary(&magsep(&args));
    let hand = summary(&magsep(&["run", by_hand.to_str().unwrap(), "--quiet"]));
    assert_eq!(with_set, hand);
    assert_eq!(with_set["steps"], 20, "the duration override took effect");
    let plain = summary(&magsep(&["run", scene.to_str().unwrap(), "--quiet"]));
    assert_ne!(plain, hand, "the overrides change the run");

    // the recording holds the effective scene (comments kept) and the overrides
    let o = magsep(&["info", rec.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: Value = serde_json::from_slice(&o.stdout).unwrap();
    let meta = &info["metadata"];
    let text = meta["scene_text"].as_str().unwrap();
    assert!(text.contains("# a comment that must survive"), "{text}");
    assert!(text.contains("duration = 2e-2 "), "{text}");
    assert!(text.contains("radius = 150e-9"), "{text}");
    let listed: Vec<&str> = (meta["overrides"].as_array().unwrap().iter())
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(listed, sets);
    assert_eq!(meta["seed"], 9);
    // the recorded scene text alone reproduces the run
    let from_meta = write("from_meta.toml", text);
    assert_eq!(
        summary(&magsep(&["run", from_meta.to_str().unwrap(), "--quiet"])),
        hand
    );
    let o = magsep(&["replay", rec.to_str().unwrap()]);
    assert!(o.status.success(), "replay: {}", stderr(&o));
    let replayed: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(replayed["particles"], 2, "{replayed}");
}
