//! Flat particles in the particle-fluid pipeline (thesis 002, ch. 3-4) through the shipped
//! scenes: the equal-volume aspect-ratio series (V2/M10), the 1:10 disc's levitation (V10),
//! the Table 4.1 particles (V1/M9), the corrected lift and pitching directions, the magnetic
//! torque's flat-horizontal stability, and the many-particle separation error without
//! collisions (V6/M12, one-way).

use glam::{DQuat, DVec3};
use magsep::prelude::*;
use magsep::scene::parse_scene;
use serde_json::Value;

fn shipped(name: &str) -> String {
    std::fs::read_to_string(format!("scenes/{name}")).unwrap()
}

fn run(text: &str) -> (Simulation, Value) {
    let scene = parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::from_scene(&scene, RunOptions::default()).unwrap();
    let summary = sim.run(|_| {}).unwrap();
    (sim, summary)
}

fn details(summary: &Value) -> &Vec<Value> {
    summary["particle_details"].as_array().unwrap()
}

fn levitation_times(summary: &Value) -> Vec<f64> {
    details(summary)
        .iter()
        .map(|p| p["levitation_time"].as_f64().unwrap())
        .collect()
}

/// Orientations in `ParticleId` order.
fn orientations(sim: &mut Simulation) -> Vec<DQuat> {
    let mut rows: Vec<(ParticleId, DQuat)> = sim
        .app
        .world
        .query::<(&ParticleId, &Orientation)>()
        .iter(&sim.app.world)
        .map(|(i, o)| (*i, o.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| r.1).collect()
}

#[test]
fn v2_levitation_time_grows_as_the_flake_gets_flatter() {
    // w = 1, 0.4, 0.2, 0.1 at d_e = 4 mm from y0 = L/3. Convention: ρ_f in the drag, d_e as
    // the reference length, the bottom magnet of the experiments, the levitation time as the
    // last exit from the 0.5 mm band. An independent 1-D model with these conventions (the
    // digest of the thesis, its appendix B) gives 7.5 s for the sphere and +14 %, +23 %, +44 %;
    // the thesis's +53/+90/+146 % are not reproducible from its stated conventions.
    let (_, summary) = run(&shipped("flakes_aspect_series.toml"));
    let t = levitation_times(&summary);
    assert!(t.windows(2).all(|p| p[1] > p[0]), "not monotone: {t:?}");
    assert!((t[0] - 7.5).abs() < 0.3, "sphere {}", t[0]);
    for (k, want) in [(1, 0.14), (2, 0.23), (3, 0.44)] {
        let rise = t[k] / t[0] - 1.0;
        assert!(
            (rise - want).abs() < 0.04,
            "w index {k}: +{rise:.3}, want +{want}"
        );
    }
    // every one at the point-formula equilibrium, y_e = -0.344 L (z = 49.2 mm)
    for p in details(&summary) {
        let z = p["position"][2].as_f64().unwrap();
        assert!((z - 0.0492).abs() < 0.5e-3, "{p}");
    }
}

#[test]
fn v10_the_one_to_ten_disc_levitates_at_its_equilibrium_height() {
    let (mut sim, summary) = run(&shipped("flake_disc.toml"));
    // a flake: the spheroid terms act and are listed
    let terms = summary["terms_used"].to_string();
    assert!(
        terms.contains("lift") && terms.contains("pitching_torque"),
        "{terms}"
    );
    let z = details(&summary)[0]["position"][2].as_f64().unwrap();
    assert!((0.0487..=0.0492).contains(&z), "equilibrium {z}");
    // largest Reynolds number on the experiment's 5 mm disc diameter: thesis 7.6 (the
    // summary's is on d_e)
    let re = summary["max_reynolds"].as_f64().unwrap() * 5e-3 / 2.657e-3;
    assert!((re - 7.6).abs() < 0.15 * 7.6, "Re_max = {re}");
    // broadside throughout: no lift or torque can act on a symmetric fall
    let axis = orientations(&mut sim)[0] * DVec3::Z;
    assert!((axis - DVec3::Z).length() < 1e-12, "{axis}");
}

#[test]
fn v1_table_4_1_particles_reach_equilibrium_and_the_spheroid_is_fastest() {
    let (_, summary) = run(&shipped("flakes_table_4_1.toml"));
    let t = levitation_times(&summary);
    for p in details(&summary) {
        let z = p["position"][2].as_f64().unwrap();
        assert!((z - 0.0492).abs() < 1e-3, "M9: y_e within 1 mm: {p}");
    }
    // p1 (w = 0.5) levitates first in both directions; the thesis's p2/p3 order (p2 slowest)
    // is not reproduced with spheroid correlations for the two cylindrical discs
    for dir in 0..2 {
        assert!(t[dir] < t[2 + dir] && t[dir] < t[4 + dir], "{t:?}");
    }
}

/// The disc scene with extra `[particle_fluid]` lines, an orientation and a duration.
fn disc(orientation: &str, duration: f64, z0: f64, extra: &str) -> String {
    shipped("flake_disc.toml")
        .replace(
            "orientation = \"broadside\"",
            &format!("orientation = {orientation}"),
        )
        .replace("duration = 25.0 ", &format!("duration = {duration} "))
        .replace("0.075, 0.075, 0.1042", &format!("0.075, 0.075, {z0}"))
        .replace(
            "observe_every = 25",
            &format!("observe_every = 25\n{extra}"),
        )
}

#[test]
fn a_tilted_flake_glides_towards_its_lower_edge_and_rights_itself() {
    // tilted 30° about x, the symmetry axis leans to -y, the lower edge is at -y: the
    // corrected lift (a flat plate's) pushes it to -y while the pitching torque turns it back
    // to broadside; the thesis's printed directions would do the opposite
    let (mut sim, summary) = run(&disc("{ tilt = 30.0 }", 3.0, 0.1042, ""));
    let p = &details(&summary)[0]["position"];
    let dy = p[1].as_f64().unwrap() - 0.075;
    assert!(dy < -1e-4, "drift {dy}");
    let axis = orientations(&mut sim)[0] * DVec3::Z;
    let tilt = axis.z.clamp(-1.0, 1.0).acos().to_degrees();
    assert!(tilt < 3.0, "still tilted {tilt}°");
    // without lift and pitching torque it neither glides nor rights itself (the magnetic
    // torque is weak far from equilibrium)
    let (mut sim, summary) = run(&disc(
        "{ tilt = 30.0 }",
        3.0,
        0.1042,
        "terms = { lift = false, pitching_torque = false }",
    ));
    let p = &details(&summary)[0]["position"];
    assert!((p[1].as_f64().unwrap() - 0.075).abs() < 1e-9);
    let axis = orientations(&mut sim)[0] * DVec3::Z;
    assert!(axis.z.acos().to_degrees() > 25.0);
}

#[test]
fn the_magnetic_torque_lays_a_flake_flat_at_equilibrium() {
    // released tilted at rest at its equilibrium height: only the magnetic torque (and the
    // rotational resistance) act on the orientation
    let ze = 0.0492006;
    let (mut sim, _) = run(&disc("{ tilt = 40.0 }", 20.0, ze, ""));
    let axis = orientations(&mut sim)[0] * DVec3::Z;
    let tilt = axis.z.acos().to_degrees();
    assert!(tilt < 10.0, "magnetic torque did not flatten: {tilt}°");
    let (mut sim, _) = run(&disc(
        "{ tilt = 40.0 }",
        20.0,
        ze,
        "terms = { magnetic_torque = false }",
    ));
    let axis = orientations(&mut sim)[0] * DVec3::Z;
    assert!(axis.z.acos().to_degrees() > 35.0);
}

/// The Table 4.3 case `case` (w = `w`, no collisions) with `count` particles over `duration`.
fn many(w: f64, fraction: f64, duration: f64) -> String {
    shipped("flakes_case4.toml")
        .replace("aspect_ratio = 0.5", &format!("aspect_ratio = {w}"))
        .replace(
            "volume_fraction = 0.01 ",
            &format!("volume_fraction = {fraction} "),
        )
        .replace("duration = 6.0 ", &format!("duration = {duration} "))
}

fn separation_at_end(summary: &Value) -> f64 {
    summary["separation"]["final_error"].as_f64().unwrap()
}

#[test]
fn v6_flatter_flakes_separate_worse_fast_tier() {
    // 220 particles, 3 s: the ordering of the thesis (w = 1 < 0.5 < 0.1) must hold
    let e: Vec<f64> = [1.0, 0.5, 0.1]
        .iter()
        .map(|&w| separation_at_end(&run(&many(w, 0.002, 3.0)).1))
        .collect();
    assert!(e[0] < e[1] && e[1] < e[2], "{e:?}");
}

#[test]
#[ignore = "release tier: 3 x 1104 particles over 3 s"]
fn v6_separation_error_at_three_seconds_full_size() {
    // thesis (two-way coupled, no collisions) 0.006 / 0.018 / 0.193. One-way, magsep gives
    // about 0.0072 / 0.0118 / 0.0236: spheres within the ±30 % band, the 1:2 flakes 35 % low
    // and the 1:10 flakes 8 times low, because in a liquid at rest a flake released
    // broadside stays broadside (no flow-induced rotation: the thesis's two-way torque
    // coupling is what disperses them, see the coupled scenes). The ordering holds.
    let e: Vec<f64> = [1.0, 0.5, 0.1]
        .iter()
        .map(|&w| separation_at_end(&run(&many(w, 0.01, 3.0)).1))
        .collect();
    assert!(e[0] < e[1] && e[1] < e[2], "{e:?}");
    assert!((e[0] - 0.006).abs() < 0.3 * 0.006, "spheres {e:?}");
    assert!((e[1] - 0.0118).abs() < 0.1 * 0.0118, "1:2 regression {e:?}");
    assert!(
        (e[2] - 0.0236).abs() < 0.1 * 0.0236,
        "1:10 regression {e:?}"
    );
}
