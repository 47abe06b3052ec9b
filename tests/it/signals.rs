//! Kill tests of `magsep run --record`: SIGINT and SIGTERM end the run gracefully (exit 130 /
//! 143, the partial summary on stdout marked interrupted, a complete recording that `magsep
//! info` reports as interrupted), a second signal exits at once (a repeat of the first within a
//! second is the same request), and a recording write
//! failure (a file-size limit) stops the run at once with exit 1.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use magsep::plugins::record::read_recording;
use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_magsep");

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("signals");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn spawn(cmd: &mut Command) -> Child {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("magsep starts")
}

fn run_recorded(scene: &str, record: &Path) -> Child {
    spawn(Command::new(BIN).args([
        "run",
        &data(scene),
        "--record",
        record.to_str().unwrap(),
        "--quiet",
    ]))
}

/// Everything the child printed, once it has exited (killed and reported if it outlives
/// `limit`).
fn finish(mut child: Child, limit: Duration) -> (Output, Duration) {
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "magsep did not exit within {limit:?} of the signal; stderr:\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let took = start.elapsed();
    let mut stdout = Vec::new();
    let mut stderr = Vec::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_end(&mut stdout)
        .unwrap();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_end(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    (
        Output {
            status,
            stdout,
            stderr,
        },
        took,
    )
}

/// Wait until the recording holds `frames` frames (the run is stepping).
fn wait_for_frames(child: &mut Child, record: &Path, frames: usize) {
    let start = Instant::now();
    loop {
        if let Ok(rec) = read_recording(record)
            && rec.frames.len() >= frames
        {
            return;
        }
        if let Some(status) = child.try_wait().expect("wait") {
            let mut err = String::new();
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            panic!("magsep exited ({status}) before recording {frames} frames:\n{err}");
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no {frames} frames in {} after 120 s",
            record.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn kill(child: &Child, signal: &str) {
    let ok = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .expect("kill runs")
        .success();
    assert!(ok, "kill -{signal} failed");
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn summary_of(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not one JSON summary ({e}):\n{}\nstderr:\n{}",
            String::from_utf8_lossy(&o.stdout),
            stderr(o)
        )
    })
}

/// `magsep info --json` of a recording left by an interrupted run: complete, interrupted by
/// `signal`, and the text form says so too.
fn assert_info_interrupted(record: &Path, signal: &str) -> Value {
    let out = Command::new(BIN)
        .args(["info", "--json", record.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "info failed: {}", stderr(&out));
    let info: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["complete"], true, "{info}");
    assert_eq!(info["truncated"], Value::Null, "{info}");
    assert_eq!(info["interrupted"], signal, "{info}");
    assert_eq!(info["summary"]["interrupted"], true, "{info}");
    let text = Command::new(BIN)
        .args(["info", record.to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("status     complete"), "{text}");
    assert!(text.contains(&format!("interrupted by {signal}")), "{text}");
    info
}

#[test]
fn sigint_ends_a_packing_run_with_a_partial_summary_and_a_complete_recording() {
    let record = tmp("sigint.mcap");
    let mut child = run_recorded("packing_long.toml", &record);
    wait_for_frames(&mut child, &record, 2);
    kill(&child, "INT");
    let (out, took) = finish(child, Duration::from_secs(10));
    assert_eq!(out.status.code(), Some(130), "stderr: {}", stderr(&out));
    let summary = summary_of(&out);
    assert_eq!(summary["interrupted"], true, "{summary}");
    assert_eq!(summary["interrupted_by"], "SIGINT", "{summary}");
    let steps = summary["compression_steps"]
        .as_u64()
        .expect("compression_steps")
        + summary["failed_steps"].as_u64().expect("failed_steps");
    assert!(steps >= 2, "{summary}");
    assert!(
        stderr(&out).contains("interrupted by SIGINT"),
        "{}",
        stderr(&out)
    );
    assert!(took < Duration::from_secs(5), "graceful stop took {took:?}");

    let info = assert_info_interrupted(&record, "SIGINT");
    // the final frame is the step where the run stopped, and the recorded summary is the
    // printed one
    let rec = read_recording(&record).unwrap();
    let last = rec.frames.last().unwrap();
    assert_eq!(info["last_step"], last.step);
    assert_eq!(last.step, steps);
    assert_eq!(info["summary"], summary);
}

#[test]
fn sigint_during_a_slow_random_insertion_ends_the_run() {
    // the insertion polls the stop request every 1024 trials: the signal ends it at once
    // instead of after its minutes of trials
    let record = tmp("sigint_spawn.mcap");
    let child = run_recorded("packing_slow_insertion.toml", &record);
    // time for the handlers to be installed (the insertion itself runs for minutes)
    std::thread::sleep(Duration::from_secs(2));
    kill(&child, "INT");
    let (out, took) = finish(child, Duration::from_secs(20));
    assert_eq!(out.status.code(), Some(130), "stderr: {}", stderr(&out));
    assert!(
        stderr(&out).contains("interrupted by SIGINT while spawning the scene (nothing ran)"),
        "{}",
        stderr(&out)
    );
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    // the recording opens after spawning: there is none
    assert!(!record.exists());
    assert!(took < Duration::from_secs(5), "the stop took {took:?}");
}

#[test]
fn sigterm_stops_every_replicate_of_a_brownian_ensemble() {
    let record = tmp("sigterm.mcap");
    let mut child = run_recorded("brownian_long.toml", &record);
    wait_for_frames(&mut child, &record, 3);
    kill(&child, "TERM");
    let (out, took) = finish(child, Duration::from_secs(10));
    assert_eq!(out.status.code(), Some(143), "stderr: {}", stderr(&out));
    assert!(took < Duration::from_secs(5), "graceful stop took {took:?}");
    let summary = summary_of(&out);
    assert_eq!(summary["interrupted"], true, "{summary}");
    assert_eq!(summary["interrupted_by"], "SIGTERM", "{summary}");
    assert_eq!(summary["runs_requested"], 4, "{summary}");
    let runs = summary["runs"].as_u64().unwrap();
    assert!((1..=4).contains(&runs), "{summary}");
    // the curves end at the fewest steps any replicate made, far before the scene's 10^7
    let steps = summary["steps"].as_u64().unwrap();
    assert!(steps < 10_000_000, "{summary}");

    let info = assert_info_interrupted(&record, "SIGTERM");
    // replicate 0's recording ends with its final frame, at or after the ensemble's steps
    assert!(info["last_step"].as_u64().unwrap() >= steps, "{info}");
    assert!(info["frames"].as_u64().unwrap() >= 3, "{info}");
}

#[test]
fn a_repeat_of_the_signal_within_a_second_is_the_same_request() {
    // as `timeout -s TERM` sends it, to the process and then to its group
    let record = tmp("echo.mcap");
    let mut child = run_recorded("brownian_slow_steps.toml", &record);
    wait_for_frames(&mut child, &record, 1);
    kill(&child, "TERM");
    std::thread::sleep(Duration::from_millis(100));
    kill(&child, "TERM");
    let (out, _) = finish(child, Duration::from_secs(20));
    assert_eq!(out.status.code(), Some(143), "stderr: {}", stderr(&out));
    assert!(
        !stderr(&out).contains("exiting at once"),
        "{}",
        stderr(&out)
    );
    let summary = summary_of(&out);
    assert_eq!(summary["interrupted_by"], "SIGTERM", "{summary}");
    assert_info_interrupted(&record, "SIGTERM");
}

#[test]
fn a_second_signal_exits_at_once() {
    let record = tmp("twice.mcap");
    let mut child = run_recorded("brownian_slow_steps.toml", &record);
    // frame 0 is written just before the first step, which takes about a second; a different
    // signal is a second request however soon it comes
    wait_for_frames(&mut child, &record, 1);
    kill(&child, "TERM");
    std::thread::sleep(Duration::from_millis(100));
    kill(&child, "INT");
    let (out, took) = finish(child, Duration::from_secs(10));
    assert_eq!(out.status.code(), Some(130), "stderr: {}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("SIGINT after SIGTERM: exiting at once"),
        "{err}"
    );
    // no graceful end: no summary, and the recording has no footer but its frames are readable
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(took < Duration::from_secs(2), "exit took {took:?}");
    let rec = read_recording(&record).unwrap();
    assert!(rec.truncated.is_some());
    assert_eq!(rec.frames.first().map(|f| f.step), Some(0));
}

#[test]
fn a_write_failure_stops_the_run_at_once_with_exit_1() {
    // A 2 MiB file-size limit, on a run that would write frames for minutes. The binary
    // itself keeps SIGXFSZ from killing it, so writes past the limit fail with EFBIG.
    let record = tmp("limited.mcap");
    let child = spawn(Command::new("bash").args([
        "-c",
        "ulimit -f 2048 && exec \"$@\"",
        "magsep",
        BIN,
        "run",
        &data("packing_long.toml"),
        "--record",
        record.to_str().unwrap(),
        "--quiet",
    ]));
    let (out, _) = finish(child, Duration::from_secs(120));
    assert_eq!(out.status.code(), Some(1), "stderr: {}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains(record.to_str().unwrap()), "{err}");
    assert!(err.contains("File too large"), "{err}");
    let summary = summary_of(&out);
    assert_eq!(summary["interrupted"], true, "{summary}");
    assert!(
        summary["run_error"]
            .as_str()
            .is_some_and(|e| e.contains("File too large")),
        "{summary}"
    );
    // stopped at the frame that failed: a few steps into a run of thousands
    let steps =
        summary["compression_steps"].as_u64().unwrap() + summary["failed_steps"].as_u64().unwrap();
    assert!(steps < 100, "{summary}");
    let size = std::fs::metadata(&record).unwrap().len();
    assert!(size <= 2048 * 1024, "{size}");
    // what was written stays readable
    let rec = read_recording(&record).unwrap();
    assert!(!rec.frames.is_empty());
    assert!(rec.frames.last().unwrap().step <= steps);
}
