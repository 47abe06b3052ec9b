//! Outputs fail fast and never destroy inputs (issue 13, item 4): output paths checked before
//! anything runs, `--force`, same-file detection through hard and symbolic links, bad
//! `--record` paths as bad input (exit 2), a closed or full standard output as an error
//! rather than a panic, `--threads` capped; inputs that are not regular files refused.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_magsep"))
}

fn magsep(args: &[&str]) -> Output {
    bin().args(args).output().expect("binary runs")
}

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("outputs")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit code 2, no panic, and `fragment` in stderr.
#[track_caller]
fn assert_bad_input(o: &Output, fragment: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(fragment), "expected {fragment:?} in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// The short brownian scene (4 particles, 100 steps), copied into `d`.
fn scene_in(d: &Path) -> PathBuf {
    let p = d.join("scene.toml");
    std::fs::copy("tests/data/brownian_short.toml", &p).unwrap();
    p
}

/// A finished recording of the short brownian scene in `d`.
fn recording_in(d: &Path) -> PathBuf {
    let scene = scene_in(d);
    let rec = d.join("run.mcap");
    let o = magsep(&["run", s(&scene), "--record", s(&rec), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    rec
}

#[test]
fn outputs_never_overwrite_inputs_even_with_force() {
    let d = dir("same_file");
    let scene = scene_in(&d);
    let text = std::fs::read(&scene).unwrap();
    let hard = d.join("hard.mcap");
    std::fs::hard_link(&scene, &hard).unwrap();
    let soft = d.join("soft.mcap");
    std::os::unix::fs::symlink(&scene, &soft).unwrap();
    let dotted = d.join(".").join("scene.toml");
    for out in [&scene, &hard, &soft, &dotted] {
        for force in [false, true] {
            let mut args = vec!["run", s(&scene), "--record", s(out), "--quiet"];
            if force {
                args.push("--force");
            }
            let o = magsep(&args);
            assert_bad_input(&o, "same file as the scene");
            assert_eq!(
                std::fs::read(&scene).unwrap(),
                text,
                "{out:?} touched the scene"
            );
        }
    }
    // the recording being resumed, directly and through a hard link
    let rec = recording_in(&d);
    let bytes = std::fs::read(&rec).unwrap();
    let rec_link = d.join("rec_link.mcap");
    std::fs::hard_link(&rec, &rec_link).unwrap();
    for out in [&rec, &rec_link] {
        let o = magsep(&[
            "replay",
            s(&rec),
            "--resume",
            "--record",
            s(out),
            "--force",
            "--quiet",
        ]);
        assert_bad_input(&o, "same file as the recording being resumed");
        assert_eq!(std::fs::read(&rec).unwrap(), bytes);
    }
    // a recording the scene names
    let named = d.join("named.toml");
    let text = format!(
        "{}\n[[fibre_packings]]\nrecording = \"{}\"\nsaturation_magnetisation = 1.7e6\n",
        std::fs::read_to_string(&scene).unwrap(),
        s(&rec)
    );
    std::fs::write(&named, text).unwrap();
    let o = magsep(&["run", s(&named), "--record", s(&rec_link), "--force"]);
    assert_bad_input(&o, "same file as the recording named in the scene");
    assert_eq!(std::fs::read(&rec).unwrap(), bytes);
    // field --out against the points file
    let points = d.join("points.csv");
    std::fs::write(&points, "x,y,z\n0,0,1e-3\n").unwrap();
    let o = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        s(&points),
        "--out",
        s(&points),
        "--force",
    ]);
    assert_bad_input(&o, "same file as the points file");
    assert_eq!(
        std::fs::read_to_string(&points).unwrap(),
        "x,y,z\n0,0,1e-3\n"
    );
}

#[test]
fn existing_outputs_need_force_and_bad_paths_exit_2() {
    let d = dir("force");
    let scene = scene_in(&d);
    let out = d.join("out.mcap");
    std::fs::write(&out, "keep me").unwrap();
    let o = magsep(&["run", s(&scene), "--record", s(&out), "--quiet"]);
    assert_bad_input(&o, "pass --force");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me");
    let o = magsep(&["run", s(&scene), "--record", s(&out), "--quiet", "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&out).unwrap().starts_with(b"\x89MCAP0\r\n"));
    // bad --record paths are bad input, never a runtime failure
    let sub = d.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let dangling = d.join("dangling.mcap");
    std::os::unix::fs::symlink(d.join("nowhere/x"), &dangling).unwrap();
    let cases = [
        (sub.clone(), "is a directory"),
        (d.join("missing/x.mcap"), "does not exist"),
        (scene.join("x.mcap"), "Not a directory"),
        (
            PathBuf::from("/proc/magsep-test.mcap"),
            "cannot create files in /proc",
        ),
        (PathBuf::from("/dev/null"), "not a regular file"),
        (dangling, "symbolic link"),
    ];
    for (path, fragment) in &cases {
        let o = magsep(&["run", s(&scene), "--record", s(path), "--quiet", "--force"]);
        assert_bad_input(&o, fragment);
        let o = magsep(&[
            "replay",
            s(&out),
            "--resume",
            "--record",
            s(path),
            "--quiet",
            "--force",
        ]);
        assert_bad_input(&o, fragment);
    }
    assert!(std::fs::read_dir(&sub).unwrap().next().is_none());
    // chart output directories: a file is not a directory; nothing ran
    let o = magsep(&["chart", "field", "--quick", "--out", s(&out)]);
    assert_bad_input(&o, "exists and is not a directory");
    let o = magsep(&["chart", "field", "--quick", "--out", "/proc/magsep/charts"]);
    assert_bad_input(&o, "cannot create files in /proc");
}

#[test]
fn a_bad_record_path_stops_an_ensemble_before_any_replicate_runs() {
    let d = dir("ensemble");
    // 8 replicates of 200000 steps: minutes of work if anything ran
    let text = std::fs::read_to_string("tests/data/brownian_short.toml")
        .unwrap()
        .replace("duration = 0.005", "duration = 10.0\nruns = 8");
    let scene = d.join("long.toml");
    std::fs::write(&scene, text).unwrap();
    let ok = magsep(&["validate", s(&scene)]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let started = Instant::now();
    let o = magsep(&[
        "run",
        s(&scene),
        "--record",
        "/nonexistent/dir/x.mcap",
        "--quiet",
    ]);
    assert_bad_input(&o, "does not exist");
    let took = started.elapsed();
    assert!(took < Duration::from_secs(10), "took {took:?}");
}

#[test]
fn threads_are_capped_before_any_is_spawned() {
    let started = Instant::now();
    let o = magsep(&[
        "run",
        "tests/data/brownian_short.toml",
        "--threads",
        "100000",
    ]);
    assert_bad_input(&o, "--threads must be in 1..=1024");
    assert!(started.elapsed() < Duration::from_secs(5));
    let o = magsep(&["run", "tests/data/brownian_short.toml", "--threads", "0"]);
    assert_bad_input(&o, "--threads must be in 1..=1024");
    let o = magsep(&[
        "field",
        "scenes/fibres_three.toml",
        "--points",
        "scenes/points_example.csv",
        "--threads",
        "1025",
    ]);
    assert_bad_input(&o, "--threads must be in 1..=1024");
}

/// Runs `args` with standard output a pipe whose read end is already closed.
fn with_closed_stdout(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    bin()
        .args(args)
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

/// Runs `args` with standard output `/dev/full` (every write fails with ENOSPC).
fn with_full_stdout(args: &[&str]) -> Output {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    bin().args(args).stdout(full).output().unwrap()
}

#[test]
fn closed_or_full_stdout_is_an_error_not_a_panic() {
    let d = dir("stdout");
    let rec = recording_in(&d);
    let scene = scene_in(&d);
    let out = d.join("again.mcap");
    let commands: Vec<Vec<&str>> = vec![
        vec!["info", s(&rec)],
        vec!["info", s(&rec), "--json"],
        vec!["validate", s(&scene)],
        vec!["replay", s(&rec)],
        vec!["run", s(&scene), "--quiet", "--record", s(&out), "--force"],
        vec!["bench", "field", "--quick", "--json"],
        vec![
            "field",
            "scenes/fibres_three.toml",
            "--points",
            "scenes/points_example.csv",
        ],
    ];
    for args in &commands {
        // a closed pipe (`magsep info f.mcap | head -0`): exit 1, quietly
        let o = with_closed_stdout(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.trim().is_empty(), "{args:?}: {err}");
        // a full disk: exit 1 with the reason
        let o = with_full_stdout(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("cannot write to standard output") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    // the run's recording was finished before its summary failed to print
    let o = magsep(&["info", s(&out), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(info["complete"], true, "{info}");
}

/// Waits for `child` at most `limit`; kills it and fails if it takes longer.
fn wait_bounded(mut child: std::process::Child, limit: Duration) -> Output {
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            panic!("still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn inputs_must_be_regular_files_and_are_never_echoed() {
    let d = dir("inputs");
    let fifo = d.join("fifo.toml");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let big = d.join("big.toml");
    std::fs::write(&big, vec![b'#'; (16 << 20) + 1]).unwrap();
    let cases = [
        ("/dev/zero", "not a regular file"),
        (s(&fifo), "not a regular file"),
        (s(&d), "not a regular file"),
        (s(&big), "more than the limit of 16777216 bytes"),
    ];
    for (path, fragment) in cases {
        for cmd in ["validate", "run"] {
            let child = bin()
                .args([cmd, path])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap();
            let o = wait_bounded(child, Duration::from_secs(20));
            assert_bad_input(&o, fragment);
        }
    }
    // a recording a scene names: regular files only, its bytes never in the message
    let secret = d.join("secret.txt");
    std::fs::write(&secret, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let base = std::fs::read_to_string("tests/data/brownian_short.toml").unwrap();
    for (named, fragment) in [
        (s(&secret), "not an MCAP file"),
        ("/dev/zero", "not a regular file"),
        (s(&fifo), "not a regular file"),
        (s(&d), "not a regular file"),
    ] {
        let scene = d.join("named.toml");
        std::fs::write(
            &scene,
            format!(
                "{base}\n[[fibre_packings]]\nrecording = \"{named}\"\n\
                 saturation_magnetisation = 1.7e6\n"
            ),
        )
        .unwrap();
        let child = bin()
            .args(["validate", s(&scene)])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let o = wait_bounded(child, Duration::from_secs(20));
        assert_bad_input(&o, fragment);
        assert_bad_input(&o, "fibre_packings[0].recording");
        let err = stderr(&o);
        for leak in ["root:x", "72 6f 6f 74", "bin/bash"] {
            assert!(!err.contains(leak), "{leak} in: {err}");
        }
    }
}
