//! The particle-fluid pipeline end to end: scenes, the ECS path against the single-sphere
//! kernel, closed forms through the summary, validation errors, replay and determinism.

use crate::common;

use magsep::prelude::*;
use magsep::scene::{Scene, parse_scene};
use magsep_systems::fluid::history::HistoryKernel;
use magsep_systems::fluid::levitation::levitation_time;
use magsep_systems::fluid::single::SphereInLiquid;

fn scene(text: &str) -> Scene {
    parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn shipped(name: &str) -> String {
    std::fs::read_to_string(format!("scenes/{name}")).unwrap()
}

/// The shipped single-particle scene with `duration` and extra `[particle_fluid]` keys.
fn levitation_scene(duration: f64, extra: &str) -> String {
    shipped("levitation_single.toml")
        .replace("duration = 8.0 ", &format!("duration = {duration} "))
        .replace(
            "observe_every = 10",
            &format!("observe_every = 10\n{extra}"),
        )
}

fn run(text: &str, options: RunOptions) -> (Simulation, serde_json::Value) {
    let mut sim = Simulation::from_scene(&scene(text), options).unwrap();
    let summary = sim.run(|_| {}).unwrap();
    (sim, summary)
}

#[test]
fn the_pipeline_follows_the_single_sphere_kernel() {
    // same kernels, same step: the ECS glue must not change the trajectory
    for extra in [
        "",
        "terms = { history = false }",
        "integrator = \"explicit\"",
    ] {
        let (mut sim, summary) = run(&levitation_scene(1.5, extra), RunOptions::default());
        let z = common::sorted_positions(&mut sim)[0].z;
        let mut s = SphereInLiquid::table_2_1(5e-3);
        s.terms.history = !extra.contains("history = false");
        if extra.contains("explicit") {
            s.integrator = magsep_systems::fluid::config::Integrator::Explicit;
        }
        s.history = HistoryKernel::window(0.2, 1e-3, true);
        let t = s.simulate(-0.9 * 0.075, 0.0, 1e-3, 1.5, 1500).unwrap();
        let y = t.heights.last().unwrap() + 0.075;
        assert!(
            (z - y).abs() < 1e-9 * y,
            "{extra}: pipeline {z}, kernel {y}"
        );
        assert!(
            summary["terms_used"].to_string().contains("history")
                != extra.contains("history = false")
        );
    }
}

#[test]
fn levitation_time_with_and_without_history_through_the_pipeline() {
    // D-002-5: rising 5 mm PVC-U from -0.9 L: 4.15 s with history, 2.15 s without
    let (_, with) = run(&levitation_scene(6.0, ""), RunOptions::default());
    let (_, without) = run(
        &levitation_scene(6.0, "terms = { history = false }"),
        RunOptions::default(),
    );
    let t = |s: &serde_json::Value| {
        s["particle_details"][0]["levitation_time"]
            .as_f64()
            .unwrap()
    };
    let (th, tn) = (t(&with), t(&without));
    assert!(
        (th - 4.15).abs() < 0.05 && (tn - 2.15).abs() < 0.05,
        "{th} {tn}"
    );
    assert!((tn / th - 0.53).abs() < 0.05, "ratio {}", tn / th);
    let z_e = with["particle_details"][0]["equilibrium_height"]
        .as_f64()
        .unwrap();
    assert!(((z_e - 0.075) / 0.075 + 0.344).abs() < 0.01, "{z_e}");
}

#[test]
fn the_summary_states_terms_closed_forms_and_stability() {
    let text = shipped("mds_case1a.toml")
        .replace("duration = 5.0 ", "duration = 0.0009 ")
        .replace(
            "volume_fraction = 0.02      # count = floor(0.02 V / V_p) = 8835",
            "count = 20",
        );
    let (_, s) = run(&text, RunOptions::default());
    let rho_f = 1400.0;
    assert!((s["sorting_range"].as_f64().unwrap() / rho_f - 0.4046).abs() < 1e-3);
    assert!((s["max_density_gradient"].as_f64().unwrap() * 0.075 / rho_f - 0.9705).abs() < 1e-3);
    assert_eq!(s["particles"], 20);
    let terms = s["terms_used"].to_string();
    // quiescent liquid: the undisturbed-flow force is not modelled
    assert!(
        !terms.contains("undisturbed_flow") && terms.contains("collisions"),
        "{terms}"
    );
    // spheres only: no spheroid term is listed (none is registered)
    for t in ["lift", "pitching_torque", "magnetic_torque"] {
        assert!(!terms.contains(t), "{terms}");
    }
    // the explicit scheme at the thesis's step is flagged for small particles only
    let small = shipped("levitation_single.toml")
        .replace("radius = 2.5e-3", "radius = 0.15e-3")
        .replace("duration = 8.0 ", "duration = 0.01 ")
        .replace(
            "observe_every = 10",
            "observe_every = 10\nintegrator = \"explicit\"",
        );
    let (_, s) = run(&small, RunOptions::default());
    assert!(
        s["warnings"].to_string().contains("explicit scheme"),
        "{}",
        s["warnings"]
    );
}

#[test]
fn particle_counts_follow_the_volume_fraction_exactly() {
    for (name, n) in [
        ("mds_case1a.toml", 8835),
        ("mds_case2.toml", 70685),
        ("mds_case3.toml", 17671),
        ("mds_case4.toml", 8835),
    ] {
        assert_eq!(scene(&shipped(name)).total_particles(), n, "{name}");
    }
}

#[test]
fn bad_scenes_report_every_error_with_its_key_path() {
    let text = shipped("levitation_single.toml")
        .replace("viscosity = 5.54e-3 ", "viscosity = -1.0 ")
        .replace("density = 1434.0 ", "density = 0.0 ")
        .replace("pole_size = 0.1181", "pole_size = 0.0")
        .replace("window = 0.2", "window = 1e-5")
        .replace("edges = [0.15, 0.15, 0.15]", "edges = [0.15, 0.15, 0.004]");
    let errors = parse_scene(&text, &Default::default()).unwrap_err();
    let paths: Vec<&str> = errors.0.iter().map(|e| e.path.as_str()).collect();
    for p in [
        "liquid.viscosity",
        "particles[0].density",
        "magnet.pole_size",
        "particle_fluid.history.window",
        "container",
    ] {
        assert!(paths.contains(&p), "{p} missing in {paths:?}");
    }
    // pipeline-specific keys elsewhere are rejected, unknown keys named
    let packing = shipped("spheres_500.toml") + "\n[liquid]\ndensity = 1.0\nviscosity = 1.0\n";
    let e = parse_scene(&packing, &Default::default()).unwrap_err();
    assert!(e.0.iter().any(|e| e.path == "liquid"), "{e}");
    let typo = shipped("levitation_single.toml").replace("surface_field", "surface_feld");
    let e = parse_scene(&typo, &Default::default()).unwrap_err();
    assert!(e.0.iter().any(|e| e.path == "magnet.surface_feld"), "{e}");
}

#[test]
fn replay_recomputes_the_separation_curve_of_the_run() {
    let dir = std::env::temp_dir().join(format!("magsep-pf-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lev.mcap");
    // without history the sphere settles at ~2.15 s: the replay sees the levitation
    let text =
        levitation_scene(3.0, "terms = { history = false }").replace("every = 100", "every = 10");
    let (_, summary) = run(
        &text,
        RunOptions {
            record: Some(path.clone()),
            ..Default::default()
        },
    );
    let (replayed, _) = magsep::replay::replay(&path).unwrap();
    let a = &summary["separation"];
    let b = &replayed["separation"];
    assert_eq!(a["times"], b["times"]);
    let (ea, eb) = (
        a["error"].as_array().unwrap(),
        b["error"].as_array().unwrap(),
    );
    assert_eq!(ea.len(), eb.len());
    for (x, y) in ea.iter().zip(eb) {
        assert!((x.as_f64().unwrap() - y.as_f64().unwrap()).abs() < 1e-14);
    }
    // levitation times at frame resolution: the last frame outside the band is at most one
    // frame interval before the run's last step outside
    let res = replayed["levitation_time_resolution_s"].as_f64().unwrap();
    assert!((res - 10.0 * 1e-3).abs() < 1e-9, "{res}");
    let (ta, tb) = (
        summary["particle_details"][0]["levitation_time"].as_f64(),
        replayed["particle_details"][0]["levitation_time"].as_f64(),
    );
    let (ta, tb) = (
        ta.expect("the run settles"),
        tb.expect("the replay sees it"),
    );
    assert!(tb <= ta && ta - tb <= res + 1e-12, "run {ta}, replay {tb}");
    assert_eq!(replayed["settled_particles"], summary["settled_particles"]);
    // what frames cannot give is null and listed, never a made-up zero
    for key in ["max_reynolds", "collisions", "liquid_solver"] {
        assert!(replayed[key].is_null(), "{key}: {}", replayed[key]);
    }
    assert!(replayed["particle_details"][0]["velocity"].is_null());
    assert_eq!(replayed["not_recomputed"].as_array().unwrap().len(), 4);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn levitation_time_kernel_matches_the_pipeline_bookkeeping() {
    // the pipeline tracks the last step outside the band; the kernel interpolates samples
    let mut s = SphereInLiquid::table_2_1(3e-3);
    s.terms.history = false;
    let y_e = s
        .magnet
        .equilibrium_height(&s.liquid, 9.81, 1434.0)
        .unwrap();
    let t = s.simulate(0.9 * 0.075, 0.0, 1e-3, 20.0, 1).unwrap();
    let tl = levitation_time(&t.times, &t.heights, y_e, 0.5e-3);
    let text = levitation_scene(20.0, "terms = { history = false }")
        .replace("radius = 2.5e-3", "radius = 1.5e-3")
        .replace("[[0.075, 0.075, 0.0075]]", "[[0.075, 0.075, 0.1425]]");
    let (_, summary) = run(&text, RunOptions::default());
    let tp = summary["particle_details"][0]["levitation_time"]
        .as_f64()
        .unwrap();
    assert!(
        (tp - tl).abs() <= 1.0e-3 + 1e-9,
        "pipeline {tp}, kernel {tl}"
    );
}

#[test]
fn shipped_particle_fluid_scenes_run() {
    // every shipped particle_fluid scene spawns, runs two steps and summarises
    let mut n = 0;
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        if !text.contains("pipeline = \"particle_fluid\"") {
            continue;
        }
        let dt = scene(&text)
            .section::<magsep::particle_fluid::ParticleFluidScene>()
            .unwrap()
            .section
            .time_step;
        let short = with_duration(&text, 2.0 * dt);
        let (_, summary) = run(&short, RunOptions::default());
        assert_eq!(summary["steps"], 2, "{}", path.display());
        n += 1;
    }
    assert!(n >= 8, "{n} particle_fluid scenes");
}

/// The scene text with its `duration = ...` line replaced.
fn with_duration(text: &str, duration: f64) -> String {
    text.lines()
        .map(|l| {
            if l.trim_start().starts_with("duration =") {
                format!("duration = {duration}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}
