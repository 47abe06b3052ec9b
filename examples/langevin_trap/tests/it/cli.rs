//! The `langevin-trap` binary: `run --record`, `validate`, `info --json`, `replay`, and the
//! same summary on one thread or two.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

use common::{temp_dir, trap_scene, without_wall_time};
use magsep::serde_json::{self, Value};

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_langevin-trap"))
        .args(args)
        .output()
        .expect("run langevin-trap")
}

fn json(out: &Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}):\n{}\nstderr:\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn run_record_info_replay() {
    let dir = temp_dir("cli_run");
    let scene = write(&dir, "trap.toml", &trap_scene(100, 2e-3, 100, 10, ""));
    let rec = dir.join("out.mcap").display().to_string();
    let out = bin(&["run", &scene, "--record", &rec, "--quiet"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = json(&out);
    assert_eq!(summary["pipeline"], "langevin_trap");
    assert_eq!(summary["steps"], 100);

    let out = bin(&["info", &rec, "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = json(&out);
    let text = info.to_string();
    assert!(text.contains("/state"), "{info}");
    assert!(text.contains("langevin_trap"), "{info}");
    let energy = info["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["topic"] == "/langevin_trap/energy")
        .unwrap_or_else(|| panic!("no energy channel: {info}"));
    assert_eq!(energy["schema"], "langevin_trap.Energy");
    assert_eq!(energy["encoding"], "protobuf");
    assert_eq!(energy["messages"], info["frames"]);

    let out = bin(&["replay", &rec]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let replayed = json(&out);
    let keys: Vec<&String> = summary.as_object().unwrap().keys().collect();
    assert_eq!(
        replayed.as_object().unwrap().keys().collect::<Vec<_>>(),
        keys
    );
    assert_eq!(replayed["variance_m2"], summary["variance_m2"]);
    assert_eq!(replayed["msd_m2"], summary["msd_m2"]);
}

#[test]
fn validate_reports_key_paths() {
    let dir = temp_dir("cli_validate");
    let good = write(&dir, "good.toml", &trap_scene(10, 1e-3, 100, 10, ""));
    let out = bin(&["validate", &good]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(json(&out)["pipeline"], "langevin_trap");

    let bad = trap_scene(10, 1e-3, 100, 10, "").replace("stiffness = 1e-6", "stiffness = -1");
    let bad = write(&dir, "bad.toml", &bad);
    let out = bin(&["validate", &bad]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("trap.stiffness: must be a finite number > 0, got -1"),
        "{stderr}"
    );
    // run refuses it the same way
    let out = bin(&["run", &bad, "--quiet"]);
    assert_eq!(out.status.code(), Some(2));
    // a missing file is bad input too
    let out = bin(&["validate", &dir.join("none.toml").display().to_string()]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn one_or_two_threads_same_summary() {
    let dir = temp_dir("cli_threads");
    let scene = write(&dir, "trap.toml", &trap_scene(200, 1e-3, 100, 10, ""));
    let one = bin(&["run", &scene, "--quiet", "--threads", "1"]);
    let two = bin(&["run", &scene, "--quiet", "--threads", "2"]);
    assert!(one.status.success() && two.status.success());
    assert_eq!(without_wall_time(json(&one)), without_wall_time(json(&two)));
}
