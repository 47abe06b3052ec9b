//! Smoke tests of `magsep chart levitation`, `history`, `separation`, `collisions`,
//! `spheroid-model` and `magsep bench
//! particle-fluid` in their quick versions: they run, write non-empty SVGs into a fresh
//! directory, and return Ok. Physics numbers are tested in the kernels' own tests; timings are
//! never asserted.

use std::path::{Path, PathBuf};

/// A fresh, empty directory under the system temp dir for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("magsep_fluid_charts_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Every file in `names` exists in `dir`, is a non-empty SVG document.
fn assert_svgs(dir: &Path, names: &[&str]) {
    for name in names {
        let path = dir.join(name);
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            text.starts_with("<svg") && text.trim_end().ends_with("</svg>") && text.len() > 500,
            "{} is not a non-empty SVG",
            path.display()
        );
    }
}

#[test]
fn quick_levitation_chart_writes_its_svgs() {
    let dir = temp_dir("levitation");
    magsep::studies::fluid_charts::chart_levitation(&dir, true).unwrap();
    assert_svgs(
        &dir,
        &[
            "levitation_trajectories.svg",
            "levitation_time.svg",
            "critical_diameter.svg",
            "sink_rise.svg",
            "force_budget.svg",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quick_history_chart_writes_its_svgs() {
    let dir = temp_dir("history");
    magsep::studies::fluid_charts::chart_history(&dir, true).unwrap();
    assert_svgs(
        &dir,
        &[
            "history_accuracy_cost.svg",
            "history_window_levitation.svg",
            "history_cost_per_step.svg",
            "history_stability.svg",
        ],
    );
    let rows = std::fs::read_to_string(dir.join("history_cost_per_step.json")).unwrap();
    for line in rows.lines() {
        let row: serde_json::Value = serde_json::from_str(line).unwrap();
        assert!(row["seconds_per_step"].as_f64().is_some(), "{row}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quick_spheroid_model_chart_writes_its_svg() {
    let dir = temp_dir("spheroid_model");
    magsep::studies::fluid_charts::chart_spheroid_model(&dir, true).unwrap();
    assert_svgs(&dir, &["spheroid_model.svg"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quick_flakes_chart_writes_its_svgs() {
    let dir = temp_dir("flakes");
    magsep::studies::fluid_charts::chart_flakes(&dir, true).unwrap();
    assert_svgs(
        &dir,
        &[
            "flakes_levitation.svg",
            "flakes_orientation.svg",
            "flakes_force_budget.svg",
            "flakes_separation.svg",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quick_particle_fluid_bench_runs() {
    magsep::studies::fluid_charts::bench_particle_fluid(true, true).unwrap();
}

/// Release tier (about 40 s): the six reduced many-particle cases and the binary collisions.
#[test]
#[ignore = "release tier: cargo test --release -- --ignored"]
fn quick_separation_and_collision_charts_write_their_svgs() {
    let dir = temp_dir("separation");
    magsep::studies::fluid_charts::chart_separation(&dir, true).unwrap();
    assert_svgs(&dir, &["separation_cases.svg", "separation_groups.svg"]);
    magsep::studies::fluid_charts::chart_collisions(&dir, true).unwrap();
    assert_svgs(&dir, &["collisions_trajectories.svg"]);
    let _ = std::fs::remove_dir_all(&dir);
}
