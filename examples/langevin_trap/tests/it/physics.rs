//! Physics and determinism of the `langevin_trap` pipeline: the equilibrium variance per axis
//! is k_B T / k, the mean relaxes as e^{-t k/γ}, and a seed gives the same numbers on one
//! thread or several.

use crate::common;

use common::{parse, run, trap_scene, without_wall_time};
use langevin_trap::TrapConfig;
use magsep::components::brownian::BOLTZMANN;
use magsep::components::prelude::*;
use magsep::glam::DVec3;
use magsep::{RunOptions, Simulation};

const K: f64 = 1e-6;
const T: f64 = 293.0;
/// γ/k of the test spheres [s] (radius 0.5 µm, η = 1e-3 Pa s).
fn tau() -> f64 {
    6.0 * std::f64::consts::PI * 1.0e-3 * 0.5e-6 / K
}

#[test]
fn equilibrium_variance_is_kt_over_k() {
    // 2000 particles, Δt = 5 ms, samples every 20 ms ≈ 2.1 γ/k for 4 s: ≈ 4e5 nearly
    // independent values per axis, a relative standard error of ≈ 0.2 %
    let scene = parse(&trap_scene(2000, 5e-3, 800, 4, ""));
    let s = run(&scene, RunOptions::default());
    let theory = BOLTZMANN * T / K;
    assert_eq!(s["theory_variance_m2"].as_f64(), Some(theory));
    assert_eq!(s["steps"], 800);
    let samples = s["samples"].as_u64().unwrap();
    assert!(samples > 190, "{s}");
    let var: Vec<f64> = (0..3)
        .map(|a| s["variance_m2"][a].as_f64().unwrap())
        .collect();
    for (a, v) in var.iter().enumerate() {
        let err = (v - theory) / theory;
        eprintln!("axis {a}: variance {v:.5e} m², kT/k {theory:.5e} m², relative error {err:+.4}");
        assert!(err.abs() < 0.05, "axis {a}: {s}");
        assert_eq!(s["relative_error"][a].as_f64(), Some(err));
    }
    let msd = s["msd_m2"].as_f64().unwrap();
    eprintln!("msd {msd:.5e} m², 3 kT/k {:.5e} m²", 3.0 * theory);
    assert!((msd / (3.0 * theory) - 1.0).abs() < 0.05, "{s}");
    // the mean sits at the centre: within 5 standard errors of 2000 * samples values
    let se = (theory / (2000.0 * samples as f64)).sqrt();
    for a in 0..3 {
        let m = s["mean_displacement_m"][a].as_f64().unwrap();
        assert!(
            m.abs() < 5.0 * se,
            "axis {a}: mean {m} m, standard error {se} m"
        );
    }
}

#[test]
fn mean_relaxes_exponentially() {
    // start 0.2 µm (3 σ) off the centre along x: ⟨x - x0⟩(t) = 0.2 µm e^{-t/τ}
    let n = 4000;
    let scene = parse(&trap_scene(n, 1e-3, 100, 10, ""));
    let mut sim = Simulation::from_scene(&scene, RunOptions::default()).unwrap();
    let centre = sim.app.world.resource::<TrapConfig>().0.centre;
    let offset = 0.2e-6;
    let theory_var = BOLTZMANN * T / K;
    for step in 1..=30u64 {
        sim.step();
        if step % 10 != 0 {
            continue;
        }
        let mut q = sim.app.world.query::<&Position>();
        let mean: DVec3 = q.iter(&sim.app.world).map(|p| p.0 - centre).sum::<DVec3>() / n as f64;
        let t = step as f64 * 1e-3;
        let expected = offset * (-t / tau()).exp();
        // variance at t from a fixed start: kT/k (1 - e^{-2t/τ})
        let se = (theory_var * (1.0 - (-2.0 * t / tau()).exp()) / n as f64).sqrt();
        eprintln!(
            "t = {t} s: mean x {:.4e} m, expected {expected:.4e} m (se {se:.1e})",
            mean.x
        );
        assert!((mean.x - expected).abs() < 5.0 * se, "t = {t}");
        assert!(
            mean.y.abs() < 5.0 * se && mean.z.abs() < 5.0 * se,
            "t = {t}"
        );
    }
}

#[test]
fn same_seed_same_summary_on_one_or_many_threads() {
    let scene = parse(&trap_scene(300, 1e-3, 200, 10, ""));
    let one = run(
        &scene,
        RunOptions {
            single_threaded: true,
            ..Default::default()
        },
    );
    let many = run(&scene, RunOptions::default());
    assert_eq!(without_wall_time(one.clone()), without_wall_time(many));
    let other = run(
        &scene,
        RunOptions {
            seed: Some(8),
            ..Default::default()
        },
    );
    assert_ne!(one["variance_m2"], other["variance_m2"]);
    assert_eq!(other["seed"], 8);
}
