//! Hard-spheroid collisions through the particle-fluid pipeline (thesis 002, §4.2.1.3, §4.3.2):
//! the 1:2 binary collision of figs. 4.10-4.12, dense 1:10 flakes with collisions (which the
//! thesis had to switch off), and determinism across executors.

use glam::{DQuat, DVec3};
use magsep::prelude::*;
use magsep::scene::parse_scene;
use serde_json::Value;

fn shipped(name: &str) -> String {
    std::fs::read_to_string(format!("scenes/{name}")).unwrap()
}

fn simulation(text: &str, single_threaded: bool) -> Simulation {
    let scene = parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}"));
    Simulation::from_scene(
        &scene,
        RunOptions {
            single_threaded,
            ..Default::default()
        },
    )
    .unwrap()
}

/// Positions and orientations in `ParticleId` order.
fn state(sim: &mut Simulation) -> Vec<(DVec3, DQuat)> {
    let mut rows: Vec<(ParticleId, DVec3, DQuat)> = sim
        .app
        .world
        .query::<(&ParticleId, &Position, &Orientation)>()
        .iter(&sim.app.world)
        .map(|(i, p, o)| (*i, p.0, o.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| (r.1, r.2)).collect()
}

#[test]
fn binary_one_to_two_collision_turns_the_flakes_less_than_ninety_degrees() {
    // I = 0.06: the pair meets near t = 4.5 s, slides in contact, separates and both
    // levitate; the thesis's simulation (with the 5:2 prolate rotational resistance, kept
    // here) under-predicts the experiment's rotation: under 90° (V-SP-M11)
    let text = shipped("flakes_binary_i006.toml").replace("duration = 12.0 ", "duration = 20.0 ");
    let mut sim = simulation(&text, false);
    let mut max_tilt = [0.0f64; 2];
    let summary: Value = sim
        .run(|w| {
            for e in w.iter_entities() {
                if let (Some(id), Some(o)) = (e.get::<ParticleId>(), e.get::<Orientation>()) {
                    let tilt = (o.0 * DVec3::Z).z.clamp(-1.0, 1.0).acos().to_degrees();
                    let k = id.0 as usize;
                    max_tilt[k] = max_tilt[k].max(tilt);
                }
            }
        })
        .unwrap();
    let c = &summary["collisions"];
    assert!(c["particle_collisions"].as_u64().unwrap() > 0, "{c}");
    assert!(c["max_overlap"].as_f64().unwrap() < 1e-3, "{c}");
    for (k, t) in max_tilt.iter().enumerate() {
        assert!(*t > 2.0 && *t < 90.0, "particle {k}: max tilt {t}°");
    }
    // after the collision both head for their own equilibria (PVC-U 1436: y_e = -0.360 L;
    // POM 1407: +0.168 L)
    let z: Vec<f64> = summary["particle_details"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["position"][2].as_f64().unwrap())
        .collect();
    let ye = [0.075 * (1.0 - 0.360), 0.075 * (1.0 + 0.168)];
    for k in 0..2 {
        assert!(
            (z[k] - ye[k]).abs() < 2.5e-3,
            "particle {k}: z {} vs {}",
            z[k],
            ye[k]
        );
    }
}

/// Table 4.3 case 5 (1:10 flakes) with collisions on, reduced to `fraction` and `duration`.
fn flakes_with_collisions(fraction: f64, duration: f64) -> String {
    shipped("flakes_case5.toml")
        .replace(
            "terms = { collisions = false }",
            "terms = { collisions = true }",
        )
        .replace(
            "volume_fraction = 0.01 ",
            &format!("volume_fraction = {fraction} "),
        )
        .replace("duration = 6.0 ", &format!("duration = {duration} "))
}

#[test]
fn dense_one_to_ten_flakes_collide_without_overlap_or_failure() {
    // the thesis switched collisions off for w = 0.1 because detection and sequencing did not
    // converge; 220 flakes injected broadside into dense bands collide thousands of times
    let mut sim = simulation(&flakes_with_collisions(0.002, 0.4), false);
    let summary = sim.run(|_| {}).unwrap();
    let c = &summary["collisions"];
    assert!(c["particle_collisions"].as_u64().unwrap() > 1000, "{c}");
    assert!(c["max_overlap"].as_f64().unwrap() < 1e-4, "{c}");
    assert!(
        summary["separation"]["final_error"]
            .as_f64()
            .unwrap()
            .is_finite()
    );
    for (x, q) in state(&mut sim) {
        assert!(x.is_finite() && (q.length() - 1.0).abs() < 1e-12);
        assert!(x.z > 0.0 && x.z < 0.15);
    }
}

#[test]
fn spheroid_collisions_are_the_same_on_one_thread_and_on_many() {
    let text = flakes_with_collisions(0.002, 0.1);
    let mut one = simulation(&text, true);
    let mut many = simulation(&text, false);
    one.run(|_| {}).unwrap();
    many.run(|_| {}).unwrap();
    let (a, b) = (state(&mut one), state(&mut many));
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p.0.to_array(), q.0.to_array());
        assert_eq!(p.1.to_array(), q.1.to_array());
    }
}

#[test]
#[ignore = "release tier: six 220-particle runs over 3 s (the thesis's density)"]
fn collisions_raise_the_separation_error_of_spheres_and_flakes() {
    // thesis: ignoring collisions under-estimates e_m(3 s) by about 2x (spheres) and 1.35x
    // (1:2); one-way magsep: 2.6x, 1.8x and 2.2x (1:10, which the thesis could not run)
    for w in [1.0, 0.5, 0.1] {
        let e: Vec<f64> = [false, true]
            .iter()
            .map(|on| {
                let text = shipped("flakes_case4.toml")
                    .replace("aspect_ratio = 0.5", &format!("aspect_ratio = {w}"))
                    // the channel's periods / √5: 220 particles at the thesis's density
                    .replace(
                        "[0.15707963267948966, 0.15707963267948966]",
                        "[0.07024814731040727, 0.07024814731040727]",
                    )
                    .replace("duration = 6.0 ", "duration = 3.0 ")
                    .replace(
                        "terms = { collisions = false }",
                        &format!("terms = {{ collisions = {on} }}"),
                    );
                let mut sim = simulation(&text, false);
                let s = sim.run(|_| {}).unwrap();
                s["separation"]["final_error"].as_f64().unwrap()
            })
            .collect();
        let factor = e[1] / e[0];
        assert!(factor > 1.2 && factor < 4.0, "w = {w}: {e:?}");
    }
}
