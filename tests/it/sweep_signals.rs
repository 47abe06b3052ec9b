//! `magsep sweep` stopped by SIGINT: the points running are cut short and dropped (a restart
//! runs them again), the finished ones stay, no new point starts, the JSON summary says so,
//! no results table is written, and the exit code is the shell's 130.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use super::overrides::TRIVIAL;

/// Point 0 takes 100 steps, point 1 10⁷ (far longer than the test), point 2 is never started.
const SWEEP: &str = r#"
scene = "base.toml"
[[axes]]
path = "brownian.duration"
values = [1e-3, 100.0, 1e-3]
"#;

#[test]
fn sigint_ends_a_sweep_keeping_finished_points_and_dropping_the_running_one() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sweep_signals");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("base.toml"),
        TRIVIAL.replace("time_step = 1e-3", "time_step = 1e-5"),
    )
    .unwrap();
    std::fs::write(dir.join("sweep.toml"), SWEEP).unwrap();
    let out = dir.join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_magsep"))
        .args([
            "sweep",
            "sweep.toml",
            "--out",
            "out",
            "--jobs",
            "1",
            "--quiet",
        ])
        .current_dir(&dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let points = out.join("points");
    // point 1 runs once point 0 is in place (one job, points in order)
    let start = Instant::now();
    while !points.join("0").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(points.join("0").exists(), "point 0 never finished");
    std::thread::sleep(Duration::from_millis(300));
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let signalled = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if signalled.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            panic!("the sweep did not stop within 20 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let status = child.wait().unwrap();
    let (mut stdout, mut stderr) = (String::new(), String::new());
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut stdout)
        .unwrap();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted by SIGINT"), "{stderr}");
    let v: Value = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"));
    assert_eq!(v["interrupted"], true, "{v}");
    assert_eq!(v["interrupted_by"], "SIGINT", "{v}");
    assert_eq!(
        (v["ran"].as_u64(), v["unfinished"].as_u64()),
        (Some(1), Some(2)),
        "{v}"
    );
    // the finished point is whole; the running one left nothing; the table is not written
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(points.join("0/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["steps"], 100, "{summary}");
    let left: Vec<String> = std::fs::read_dir(&points)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(left, ["0"]);
    assert!(!out.join("results.csv").exists());
}
