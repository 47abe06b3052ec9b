//! `magsep sweep`: resumable after a kill, shards merged equal the unsharded sweep byte for
//! byte, partial merges, up-front validation of every point, the Slurm scripts (run here
//! task by task with `bash`, as Slurm would), a failing point recorded, not fatal, and run
//! again only with `--retry-failed`, recordings written with `--record`, and `magsep validate`
//! of sweep files.

use crate::common::{magsep, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use super::overrides::TRIVIAL;

fn json(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", stderr(o)))
}

/// A fresh directory for test `name`, with the base scene `base.toml` in it.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("sweeps")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("base.toml"), TRIVIAL).unwrap();
    dir
}

/// 3 radii x 2 durations x 4 replicates = 24 points.
const SWEEP: &str = r#"
scene = "base.toml"
replicates = 4
seed = 100
collect = ["stepper.particle_substeps_per_step", "steps", "no_such_value"]

[[axes]]
name = "radius"
path = "particles[0].shape.radius"
unit = "m"
logspace = { start = 50e-9, stop = 200e-9, num = 3 }

[[axes]]
path = "brownian.duration"
values = [1e-2, 2e-2]
"#;

fn write_sweep(dir: &Path, text: &str) -> String {
    let p = dir.join("sweep.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn out(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

fn csv(out: &str) -> String {
    std::fs::read_to_string(Path::new(out).join("results.csv")).unwrap()
}

/// The uninterrupted sweep: its results.csv.
fn reference(dir: &Path, sweep: &str) -> String {
    let o = magsep(&["sweep", sweep, "--out", &out(dir, "whole"), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(
        (v["points"].as_u64(), v["ok"].as_u64()),
        (Some(24), Some(24))
    );
    assert_eq!(v["collected_values_absent"]["no_such_value"], 24);
    csv(&out(dir, "whole"))
}

#[test]
fn sweep_table_has_one_row_per_point_with_seeds_and_charts() {
    let dir = fresh("table");
    let sweep = write_sweep(&dir, SWEEP);
    let table = reference(&dir, &sweep);
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(
        lines[0],
        "index,radius,brownian.duration,replicate,seed,stepper.particle_substeps_per_step,\
         steps,no_such_value,status,error"
    );
    assert_eq!(lines.len(), 25);
    // replicates innermost, seeds = base + replicate, axes crossed (first slowest)
    assert!(lines[1].starts_with("0,5e-8,0.01,0,100,"), "{}", lines[1]);
    assert!(lines[4].starts_with("3,5e-8,0.01,3,103,"), "{}", lines[4]);
    assert!(lines[5].starts_with("4,5e-8,0.02,0,100,"), "{}", lines[5]);
    assert!(
        lines[24].starts_with("23,2e-7,0.02,3,103,"),
        "{}",
        lines[24]
    );
    // the duration axis is applied: 10 or 20 steps of 1 ms
    for l in &lines[1..] {
        let cells: Vec<&str> = l.split(',').collect();
        let steps = if cells[2] == "0.01" { "10" } else { "20" };
        assert_eq!(cells[6], steps, "{l}");
        assert_eq!(cells[8], "ok", "{l}");
    }
    // the point's own directory: its overrides and summary
    let p: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("whole/points/5/point.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(p["seed"], 101);
    assert_eq!(p["overrides"][2], "simulation.seed=101");
    assert!(dir.join("whole/points/5/summary.json").is_file());
    for c in ["steps__vs__radius.svg", "steps__vs__brownian_duration.svg"] {
        let svg = std::fs::read_to_string(dir.join("whole/charts").join(c)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("95 % CI"), "{c}");
    }
}

/// The last modification time of `path`.
fn mtime(path: &Path) -> std::time::SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

#[test]
fn a_killed_sweep_restarted_redoes_only_unfinished_points() {
    let dir = fresh("resume");
    // longer points (1000 steps) so that the kill lands mid-way
    std::fs::write(
        dir.join("base.toml"),
        TRIVIAL.replace("time_step = 1e-3", "time_step = 1e-5"),
    )
    .unwrap();
    let sweep = write_sweep(
        &dir,
        &SWEEP.replace("values = [1e-2, 2e-2]", "values = [5e-3, 1e-2]"),
    );
    let whole = out(&dir, "whole");
    let o = magsep(&["sweep", &sweep, "--out", &whole, "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let killed = out(&dir, "killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_magsep"))
        .args(["sweep", &sweep, "--out", &killed, "--jobs", "1", "--quiet"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let points = Path::new(&killed).join("points");
    let finished = |p: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(p)
            .map(|d| {
                d.filter_map(|e| e.ok()?.file_name().into_string().ok())
                    .filter(|n| !n.starts_with('.'))
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    };
    let start = Instant::now();
    while finished(&points).len() < 3 && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // whatever the kill left, make sure there is work to redo: drop two finished points and
    // leave a half-written one behind
    let mut done = finished(&points);
    assert!(done.len() >= 3, "{done:?}");
    for name in done.drain(..2) {
        std::fs::remove_dir_all(points.join(name)).unwrap();
    }
    let stale = points.join(".tmp-23");
    if !points.join("23").exists() {
        std::fs::create_dir_all(&stale).unwrap();
        std::fs::write(stale.join("point.json"), "half").unwrap();
    }
    let kept: Vec<(String, std::time::SystemTime)> = (done.iter())
        .map(|n| (n.clone(), mtime(&points.join(n).join("summary.json"))))
        .collect();
    std::thread::sleep(Duration::from_millis(20));
    let o = magsep(&["sweep", &sweep, "--out", &killed, "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["skipped"].as_u64(), Some(kept.len() as u64), "{v}");
    assert_eq!(v["ran"].as_u64(), Some(24 - kept.len() as u64), "{v}");
    for (n, t) in &kept {
        assert_eq!(
            mtime(&points.join(n).join("summary.json")),
            *t,
            "point {n} was redone"
        );
    }
    assert!(!stale.exists());
    assert_eq!(csv(&killed), csv(&whole));
    // a third run has nothing left to do
    let v = json(&magsep(&["sweep", &sweep, "--out", &killed, "--quiet"]));
    assert_eq!(
        (v["ran"].as_u64(), v["skipped"].as_u64()),
        (Some(0), Some(24))
    );
}

#[test]
fn shards_merged_equal_the_unsharded_sweep_and_partial_merges_work() {
    let dir = fresh("shards");
    let sweep = write_sweep(&dir, SWEEP);
    let whole = reference(&dir, &sweep);
    let sharded = out(&dir, "sharded");
    // merging before anything ran: no manifest
    let o = magsep(&["sweep", "merge", &sharded]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let mut ran = 0;
    for i in 1..=5 {
        let shard = format!("{i}/5");
        let o = magsep(&[
            "sweep", &sweep, "--out", &sharded, "--shard", &shard, "--quiet",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v = json(&o);
        ran += v["ran"].as_u64().unwrap();
        assert!(!Path::new(&sharded).join("results.csv").exists() || i > 1);
        if i == 1 {
            // points 0, 5, 10, 15, 20 only; a partial merge reports the rest missing
            let points: Vec<String> = std::fs::read_dir(Path::new(&sharded).join("points"))
                .unwrap()
                .map(|e| e.unwrap().file_name().into_string().unwrap())
                .collect();
            assert_eq!(points.len(), 5, "{points:?}");
            let o = magsep(&["sweep", "merge", &sharded]);
            assert!(o.status.success(), "{}", stderr(&o));
            let m = json(&o);
            assert_eq!(
                (m["ok"].as_u64(), m["missing"].as_u64()),
                (Some(5), Some(19))
            );
            assert!(stderr(&o).contains("19 of 24"), "{}", stderr(&o));
            let partial = csv(&sharded);
            assert_eq!(partial.matches(",missing,").count(), 19);
            assert!(partial.lines().nth(6).unwrap().starts_with("5,"));
        }
    }
    assert_eq!(ran, 24);
    let o = magsep(&["sweep", "merge", &sharded]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o)["missing"], 0);
    assert_eq!(
        csv(&sharded),
        whole,
        "shards merged differ from the unsharded sweep"
    );
    // bad shard specs
    for bad in ["0/3", "4/3", "1/0", "x", "1-3"] {
        let o = magsep(&["sweep", &sweep, "--out", &sharded, "--shard", bad]);
        assert_eq!(o.status.code(), Some(2), "--shard {bad}");
        assert!(stderr(&o).contains("--shard"), "{}", stderr(&o));
    }
    // another sweep in the same directory is refused
    let other = write_sweep(&dir, &SWEEP.replace("replicates = 4", "replicates = 2"));
    let o = magsep(&["sweep", &other, "--out", &sharded]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("another sweep"), "{}", stderr(&o));
}

#[test]
fn slurm_scripts_run_task_by_task_equal_the_local_sweep() {
    let dir = fresh("slurm");
    let sweep = write_sweep(&dir, SWEEP);
    let whole = reference(&dir, &sweep);
    let cluster = out(&dir, "cluster");
    let o = magsep(&[
        "sweep",
        "slurm",
        &sweep,
        "--out",
        &cluster,
        "--shards",
        "3",
        "--partition",
        "debug",
        "--time",
        "00:10:00",
        "--cpus-per-task",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(
        (v["points"].as_u64(), v["shards"].as_u64()),
        (Some(24), Some(3))
    );
    let array = std::fs::read_to_string(Path::new(&cluster).join("sweep.sbatch")).unwrap();
    let exe = std::fs::canonicalize(env!("CARGO_BIN_EXE_magsep")).unwrap();
    let sweep_abs = std::fs::canonicalize(&sweep).unwrap();
    for needle in [
        "#!/bin/bash\n".to_string(),
        "#SBATCH --array=1-3\n".into(),
        "#SBATCH --partition=debug\n".into(),
        "#SBATCH --time=00:10:00\n".into(),
        "#SBATCH --cpus-per-task=2\n".into(),
        format!("'{}' sweep '{}'", exe.display(), sweep_abs.display()),
        "--shard \"${SLURM_ARRAY_TASK_ID}/3\"".into(),
    ] {
        assert!(array.contains(&needle), "{needle} not in\n{array}");
    }
    let merge = std::fs::read_to_string(Path::new(&cluster).join("merge.sbatch")).unwrap();
    assert!(merge.contains("sweep merge '"), "{merge}");
    let submit = std::fs::read_to_string(Path::new(&cluster).join("submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterany:"), "{submit}");
    // run the array tasks as Slurm would (the #SBATCH lines are comments to bash), then merge
    for task in ["3", "1", "2"] {
        let o = Command::new("bash")
            .arg(Path::new(&cluster).join("sweep.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", task)
            .env("SLURM_CPUS_PER_TASK", "2")
            .output()
            .unwrap();
        assert!(o.status.success(), "task {task}: {}", stderr(&o));
    }
    let o = Command::new("bash")
        .arg(Path::new(&cluster).join("merge.sbatch"))
        .output()
        .unwrap();
    assert!(o.status.success(), "merge: {}", stderr(&o));
    assert_eq!(csv(&cluster), whole);
    // options that would break the script are refused
    let o = magsep(&[
        "sweep",
        "slurm",
        &sweep,
        "--out",
        &cluster,
        "--time",
        "1\n#SBATCH -x",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--time"), "{}", stderr(&o));
}

#[test]
fn bad_sweeps_fail_up_front_with_key_paths() {
    let dir = fresh("bad");
    let cases = [
        (
            SWEEP.replace("values = [1e-2, 2e-2]", "values = [1e-2, -2.0]"),
            "brownian.duration",
        ),
        (
            SWEEP.replace("path = \"brownian", "pth = \"brownian"),
            "axes[1]",
        ),
        (SWEEP.replace("num = 3", "num = 0"), "axes[0].logspace.num"),
        (
            SWEEP.replace("start = 50e-9", "start = -1.0"),
            "axes[0].logspace.start",
        ),
        (
            SWEEP.replace("replicates = 4", "replicates = 0"),
            "replicates",
        ),
        (
            SWEEP.replace("scene = \"base.toml\"", "scene = \"none.toml\""),
            "scene",
        ),
        (
            format!("zip = [[\"radius\", \"brownian.duration\"]]\n{SWEEP}"),
            "zip[0][1]",
        ),
        (
            format!("zip = [[\"radius\", \"nope\"]]\n{SWEEP}"),
            "zip[0][1]",
        ),
        (
            SWEEP.replace(
                "values = [1e-2, 2e-2]",
                "range = { start = 1, stop = 3, step = -1 }",
            ),
            "axes[1].range.step",
        ),
        (
            SWEEP.replace(
                "path = \"brownian.duration\"",
                "path = \"particles[4].count\"",
            ),
            "particles[4]",
        ),
    ];
    for (k, (text, key)) in cases.iter().enumerate() {
        let sweep = write_sweep(&dir, text);
        let o_dir = out(&dir, &format!("out{k}"));
        let o = magsep(&["sweep", &sweep, "--out", &o_dir, "--quiet"]);
        assert_eq!(o.status.code(), Some(2), "case {k}: {}", stderr(&o));
        assert!(stderr(&o).contains(key), "case {k}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
        assert!(
            !Path::new(&o_dir).join("points").exists(),
            "case {k} ran points"
        );
        // `magsep validate` checks a sweep file the same way, without running anything
        let v = magsep(&["validate", &sweep]);
        assert_eq!(
            v.status.code(),
            Some(2),
            "validate case {k}: {}",
            stderr(&v)
        );
        assert!(
            stderr(&v).contains(key),
            "validate case {k}: {}",
            stderr(&v)
        );
    }
    let good = write_sweep(&dir, SWEEP);
    let v = json(&magsep(&["validate", &good]));
    assert_eq!(
        (v["valid"].as_bool(), v["points"].as_u64()),
        (Some(true), Some(24))
    );
    let o = magsep(&["validate", &good, "--set", "brownian.duration=1.0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // a point whose scene validates but fails to run is that point's error, not the sweep's
    let text = "scene = \"base.toml\"\ncollect = [\"steps\"]\n[[axes]]\n\
                path = \"particles[0].count\"\nvalues = [1, 20000]\n[[axes]]\n\
                path = \"particles[0].placement.max\"\nvalues = [[1e-7, 1e-7, 1e-7]]\n";
    let sweep = write_sweep(&dir, text);
    let o = magsep(&["sweep", &sweep, "--out", &out(&dir, "failing"), "--quiet"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!((v["ok"].as_u64(), v["failed"].as_u64()), (Some(1), Some(1)));
    let table = csv(&out(&dir, "failing"));
    let row = table.lines().nth(2).unwrap();
    assert!(
        row.contains(",error,") && row.contains("start region"),
        "{row}"
    );
    // `magsep validate` spawns every point, so it finds that point before anything runs
    let v = magsep(&["validate", &sweep]);
    assert_eq!(v.status.code(), Some(2), "{}", stderr(&v));
    let e = stderr(&v);
    assert!(
        e.contains("point 1 (particles[0].count=20000") && e.contains("start region"),
        "{e}"
    );
    assert!(!e.contains("point 0 "), "{e}");
}

/// A typo in an axis path is the axis's error, reported once at `axes[k].path`, not repeated
/// for every point.
#[test]
fn a_typo_in_an_axis_path_is_reported_once_at_the_axis() {
    let dir = fresh("typo");
    let sweep = write_sweep(
        &dir,
        &SWEEP.replace(
            "path = \"brownian.duration\"",
            "path = \"brownian.duraton\"",
        ),
    );
    for args in [
        vec!["sweep", &sweep, "--out", &out(&dir, "o"), "--quiet"],
        vec!["validate", &sweep],
    ] {
        let o = magsep(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains("axes[1].path: `brownian.duraton`"), "{e}");
        assert_eq!(e.matches("duraton").count(), 1, "{e}");
        assert!(!e.contains("point 0"), "{e}");
    }
}

#[test]
fn zipped_axes_vary_together_and_ranges_are_typed() {
    let dir = fresh("zip");
    let text = r#"
scene = "base.toml"
collect = ["steps", "particles"]
zip = [["n", "duration"]]
[[axes]]
name = "n"
path = "particles[0].count"
range = { start = 1, stop = 3, step = 1 }
[[axes]]
name = "radius"
path = "particles[0].shape.radius"
values = [50e-9, 100e-9]
[[axes]]
name = "duration"
path = "brownian.duration"
linspace = { start = 1e-3, stop = 3e-3, num = 3 }
"#;
    let sweep = write_sweep(&dir, text);
    let o_dir = out(&dir, "out");
    let o = magsep(&["sweep", &sweep, "--out", &o_dir, "--quiet", "--jobs", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = csv(&o_dir);
    let rows: Vec<Vec<&str>> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 6, "{table}");
    for r in &rows {
        // n particles for n ms (n steps): the zipped axes move together; replicate 0 and the
        // scene's own seed
        assert_eq!((r[6], r[7]), (r[1], r[1]), "{r:?}");
        assert_eq!((r[4], r[5]), ("0", "1"), "{r:?}");
    }
    assert_eq!(rows[0][..4], ["0", "1", "5e-8", "0.001"]);
    assert_eq!(rows[1][..4], ["1", "1", "1e-7", "0.001"]);
    assert_eq!(rows[5][..4], ["5", "3", "1e-7", "0.003"]);
}

#[test]
fn failed_points_are_kept_until_retried_and_records_are_written_on_request() {
    let dir = fresh("retry");
    // point 0 runs; point 1 cannot place 20000 particles in its tiny box (fails at run time)
    let text = "scene = \"base.toml\"\ncollect = [\"steps\"]\n[[axes]]\n\
                path = \"particles[0].count\"\nvalues = [1, 20000]\n[[axes]]\n\
                path = \"particles[0].placement.max\"\nvalues = [[1e-7, 1e-7, 1e-7]]\n";
    let sweep = write_sweep(&dir, text);
    let o_dir = out(&dir, "out");
    let first = magsep(&["sweep", &sweep, "--out", &o_dir, "--quiet", "--record"]);
    assert_eq!(first.status.code(), Some(1), "{}", stderr(&first));
    let v = json(&first);
    assert_eq!(
        (v["ran"].as_u64(), v["failed"].as_u64()),
        (Some(2), Some(1))
    );
    // --record: the finished point's recording, readable
    let rec = Path::new(&o_dir).join("points/0/recording.mcap");
    let info = magsep(&["info", rec.to_str().unwrap()]);
    assert!(info.status.success(), "{}", stderr(&info));
    // a restart without --retry-failed runs nothing: the failure is kept
    let again = magsep(&["sweep", &sweep, "--out", &o_dir, "--quiet"]);
    let v = json(&again);
    assert_eq!(
        (v["ran"].as_u64(), v["skipped"].as_u64()),
        (Some(0), Some(2)),
        "{v}"
    );
    assert_eq!(v["failed"].as_u64(), Some(1), "{v}");
    // --retry-failed runs the failed point again, and only it
    let retry = magsep(&[
        "sweep",
        &sweep,
        "--out",
        &o_dir,
        "--quiet",
        "--retry-failed",
    ]);
    let v = json(&retry);
    assert_eq!(
        (v["ran"].as_u64(), v["skipped"].as_u64()),
        (Some(1), Some(1)),
        "{v}"
    );
    assert_eq!(
        (v["ok"].as_u64(), v["failed"].as_u64()),
        (Some(1), Some(1)),
        "{v}"
    );
    // without --record a sweep writes no recordings
    let plain = out(&dir, "plain");
    magsep(&["sweep", &sweep, "--out", &plain, "--quiet"]);
    assert!(Path::new(&plain).join("points/0/summary.json").is_file());
    assert!(!Path::new(&plain).join("points/0/recording.mcap").exists());
}
