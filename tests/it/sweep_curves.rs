//! `magsep sweep` curves (`[[curves]]`): a summary array against another, averaged over the
//! replicates of each combination, checked against the points' own summaries; axes whose
//! values are tables (a `step_control` table, say) reach the scene whole.

use crate::common::{magsep, stderr};
use std::path::Path;

use serde_json::Value;

/// 12 particles of 212 nm beside a magnetised fibre: some are caught within 20 ms, a
/// different number in each replicate.
const BASE: &str = r#"
[simulation]
pipeline = "brownian"
seed = 1

[brownian]
time_step = 1e-3
duration = 2e-2
mobility = "free_draining"
contact = { kind = "none" }
dipole_cutoff = 0
observe_every = 4

[external_field]
flux_density = [1.0, 0.0, 0.0]

[[fibres]]
kind = "cylinder"
radius = 300e-6
half_length = 6e-3
center = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
saturation_magnetisation = 985e3

[[particles]]
count = 12
shape = { kind = "sphere", radius = 212e-9 }
moment = { kind = "saturated", moment = 19.35e-16 }
placement = { kind = "fibre_side", fibre = 0, gap = 1e-6, thickness = 4e-6 }
"#;

const SWEEP: &str = r#"
scene = "base.toml"
replicates = 3
seed = 5
collect = ["captured_fraction.mean", "step_control.kind"]

[[curves]]
name = "capture"
x = "capture_curve.time_s"
y = "capture_curve.captured_fraction"
x_unit = "s"

[[axes]]
name = "step_control"
path = "brownian.step_control"
values = [{ kind = "adaptive", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 },
          { kind = "multirate", tolerance = 1e-2, max_displacement = 0.5, max_depth = 24 }]
"#;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn curves_are_the_replicates_mean_and_interval_and_table_values_reach_the_scene() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sweep_curves");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    std::fs::write(dir.join("sweep.toml"), SWEEP).unwrap();
    let out = dir.join("out");
    let o = magsep(&[
        "sweep",
        dir.join("sweep.toml").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((v["points"].as_u64(), v["ok"].as_u64()), (Some(6), Some(6)));
    assert_eq!(v["curve_points_left_out"]["capture"], 0);
    assert!(out.join("charts/curve__capture.svg").is_file());
    // each point ran the step control of its axis value
    let table = std::fs::read_to_string(out.join("results.csv")).unwrap();
    for (k, line) in table.lines().skip(1).enumerate() {
        let kind = if k < 3 { "adaptive" } else { "multirate" };
        assert!(line.contains(&format!(",{kind},")), "{line}");
    }
    // the curve's rows, recomputed from the points' summaries
    let csv = std::fs::read_to_string(out.join("curves/capture.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| l.rsplitn(5, ',').map(str::to_string).collect())
        .collect();
    let mut caught_somewhere = false;
    let mut differs = false;
    for combo in 0..2 {
        let summaries: Vec<Value> = (0..3)
            .map(|r| {
                let p = out.join(format!("points/{}/summary.json", 3 * combo + r));
                serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
            })
            .collect();
        let t = numbers(&summaries[0]["capture_curve"]["time_s"]);
        let ys: Vec<Vec<f64>> = (summaries.iter())
            .map(|s| numbers(&s["capture_curve"]["captured_fraction"]))
            .collect();
        let combo_rows = &rows[combo * t.len()..(combo + 1) * t.len()];
        for (i, row) in combo_rows.iter().enumerate() {
            // rsplitn: n, ci95, mean, x, axis values
            let (n, h, m, x): (usize, f64, f64, f64) = (
                row[0].parse().unwrap(),
                row[1].parse().unwrap(),
                row[2].parse().unwrap(),
                row[3].parse().unwrap(),
            );
            let y: Vec<f64> = ys.iter().map(|y| y[i]).collect();
            let mean = y.iter().sum::<f64>() / 3.0;
            let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
            // t quantile 0.975 with 2 degrees of freedom
            let half = 4.302_652_729_911 * sd / 3f64.sqrt();
            assert_eq!((n, x), (3, t[i]));
            assert!((m - mean).abs() < 1e-12, "{m} {mean}");
            assert!((h - half).abs() < 1e-9, "{h} {half}");
            caught_somewhere |= mean > 0.0;
            differs |= sd > 0.0;
        }
    }
    // the test means something: particles were caught, and replicates differ
    assert!(caught_somewhere && differs, "{csv}");
}

#[test]
fn a_bad_curve_path_fails_up_front_at_its_key() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sweep_curves_bad");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    for (text, at) in [
        (
            SWEEP.replace("x = \"capture_curve.time_s\"", "x = \"a..b\""),
            "curves[0].x",
        ),
        (SWEEP.replace("x_unit", "x_units"), "curves[0]"),
    ] {
        std::fs::write(dir.join("sweep.toml"), &text).unwrap();
        let o = magsep(&[
            "sweep",
            dir.join("sweep.toml").to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
            "--quiet",
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(at), "{at}: {}", stderr(&o));
    }
}
