//! App-level tests of the brownian pipeline: free diffusion, determinism across thread counts,
//! the stability of the fixed and adaptive steps on one scene, capture, record/replay/resume.

use magsep::prelude::*;
use magsep::scene::{Scene, parse_scene};

use crate::common;
use common::sorted_positions as positions;

fn scene(text: &str) -> Scene {
    parse_scene(text, &Default::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn free_scene(n: u64, dt: f64, steps: u64, extra: &str) -> String {
    format!(
        r#"
[simulation]
pipeline = "brownian"
seed = 11
[brownian]
time_step = {dt}
duration = {duration}
mobility = "free_draining"
contact = {{ kind = "none" }}
dipole_cutoff = 0
{extra}
[[particles]]
count = {n}
shape = {{ kind = "sphere", radius = 100e-9 }}
placement = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [1e-3, 1e-3, 1e-3] }}
"#,
        duration = dt * steps as f64
    )
}

#[test]
fn free_particles_diffuse_with_msd_6dt() {
    // 2e4 particles: the MSD estimate has relative standard error sqrt(2/3/2e4) = 0.6 %
    let (dt, steps) = (1e-3, 10);
    let s = scene(&free_scene(20_000, dt, steps, ""));
    let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
    let x0 = positions(&mut sim);
    sim.run(|_| {}).unwrap();
    let x1 = positions(&mut sim);
    let msd = x0
        .iter()
        .zip(&x1)
        .map(|(a, b)| (*a - *b).length_squared())
        .sum::<f64>()
        / x0.len() as f64;
    let d = 1.380649e-23 * 298.0 / (6.0 * std::f64::consts::PI * 1e-3 * 100e-9);
    let ratio = msd / (6.0 * d * dt * steps as f64);
    assert!((ratio - 1.0).abs() < 0.02, "MSD / 6Dt = {ratio}");
}

/// Two 75 nm particles (table 6.1 moment) head to tail along a uniform 1 T field, starting
/// just outside Mie contact.
fn pair_scene(dt: f64, steps: u64, control: &str) -> String {
    format!(
        r#"
[simulation]
pipeline = "brownian"
seed = 5
[external_field]
flux_density = [0.0, 0.0, 1.0]
[brownian]
time_step = {dt}
duration = {duration}
mobility = "free_draining"
step_control = {control}
[[particles]]
count = 2
shape = {{ kind = "sphere", radius = 75e-9 }}
moment = {{ kind = "saturated", moment = 0.87e-16 }}
placement = {{ kind = "points", positions = [[0.0, 0.0, 0.0], [0.0, 0.0, 157.5e-9]] }}
"#,
        duration = dt * steps as f64
    )
}

/// (min, max) pair separation in radii over the run (NaN-safe: non-finite -> (0, inf)).
fn separation_range(text: &str) -> (f64, f64) {
    let s = scene(text);
    let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    while !sim.is_finished() {
        sim.step();
        let x = positions(&mut sim);
        let r = (x[0] - x[1]).length() / 75e-9;
        if !r.is_finite() {
            return (0.0, f64::INFINITY);
        }
        lo = lo.min(r);
        hi = hi.max(r);
    }
    eprintln!("separation {lo:.4}..{hi:.4} radii");
    (lo, hi)
}

#[test]
fn dipole_pair_fixed_step_fails_at_thesis_dt_adaptive_does_not() {
    // D-000-10: at dt = 5e-5 s the dipole contact force moves a 75 nm particle by several
    // radii per step and D dt U''/kT at the Mie contact is 356 (explicit Euler needs < 2).
    let fixed = r#"{ kind = "fixed" }"#;
    let (lo, hi) = separation_range(&pair_scene(5e-5, 100, fixed));
    assert!(
        lo < 1.5 || hi > 4.0,
        "fixed step at 5e-5 s should fail (deep overlap or a torn pair): {lo}..{hi} radii"
    );
    // the same scene with error control: the pair stays in contact, never overlapping
    let adaptive =
        r#"{ kind = "adaptive", tolerance = 1e-2, max_displacement = 0.2, max_depth = 30 }"#;
    let (lo, hi) = separation_range(&pair_scene(5e-5, 100, adaptive));
    assert!(lo > 1.98 && hi < 2.4, "adaptive: {lo}..{hi} radii");
    // and with multirate error control (only the pair is refined)
    let multirate =
        r#"{ kind = "multirate", tolerance = 1e-2, max_displacement = 0.2, max_depth = 30 }"#;
    let (lo, hi) = separation_range(&pair_scene(5e-5, 100, multirate));
    assert!(lo > 1.98 && hi < 2.4, "multirate: {lo}..{hi} radii");
    // where the fixed step becomes stable: D dt U''/kT = 0.71 at dt = 1e-7 s
    let (lo, hi) = separation_range(&pair_scene(1e-7, 300, fixed));
    assert!(lo > 1.98 && hi < 2.4, "fixed at 1e-7 s: {lo}..{hi} radii");
}

fn dense_scene(control: &str) -> String {
    // 600 particles (above the parallel threshold of the force kernels) with dipoles and Mie
    format!(
        r#"
[simulation]
pipeline = "brownian"
seed = 2
[external_field]
flux_density = [0.0, 0.0, 1.0]
[brownian]
time_step = 1e-6
duration = 1e-5
mobility = "free_draining"
step_control = {control}
[[particles]]
count = 600
shape = {{ kind = "sphere", radius = 75e-9 }}
moment = {{ kind = "saturated", moment = 0.87e-16 }}
placement = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [6e-6, 6e-6, 6e-6] }}
"#
    )
}

#[test]
fn bitwise_identical_for_one_and_two_threads() {
    for kind in ["adaptive", "multirate"] {
        identical_for_one_and_two_threads(kind);
    }
}

/// `f` on a rayon pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(f)
}

/// The fixed step on the LAMMPS-mirror configuration (WCA core, dipoles cut at 4 sigma) with
/// 1331 particles: enough for every parallel path of the step (cell binning, list checks,
/// pair forces, drift, noise and update split among the threads), each run on one thread and
/// on two, on both executors and stepped inside and outside rayon's pool, and every trajectory
/// is bitwise the same.
#[test]
fn the_fixed_step_is_bitwise_identical_for_one_and_two_threads() {
    let s = scene(&magsep::studies::bench_brownian::lammps_mirror_scene(11, 3).unwrap());
    let run = |threads: usize, single: bool| {
        on_threads(threads, || {
            let options = RunOptions {
                single_threaded: single,
                ..Default::default()
            };
            let mut sim = Simulation::from_scene(&s, options).unwrap();
            let start = positions(&mut sim);
            for _ in 0..40 {
                sim.step();
            }
            (start, positions(&mut sim))
        })
    };
    let (start, a) = run(1, true);
    let (_, b) = run(2, true);
    let (_, c) = run(2, false);
    assert_eq!(a.len(), 1331);
    // the particles moved, and by the Brownian step's order (√(2e-4) σ per step, σ = 150 nm)
    let moved = a.iter().zip(&start).filter(|(p, q)| p != q).count();
    assert_eq!(moved, a.len());
    let bits = |x: &[glam::DVec3]| -> Vec<[u64; 3]> {
        x.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
    };
    assert!(bits(&a) == bits(&b), "1 vs 2 threads");
    assert!(
        bits(&a) == bits(&c),
        "1 vs 2 threads, multi-threaded executor"
    );
    // stepped from this (non-pool) thread: each step inside the global pool (what the driver
    // asks for from 256 particles) and each parallel loop handed to the pool from here
    let outside = |in_pool: bool| {
        let options = RunOptions {
            single_threaded: true,
            ..Default::default()
        };
        let mut sim = Simulation::from_scene(&s, options).unwrap();
        sim.app.set_single_threaded(in_pool);
        for _ in 0..40 {
            sim.step();
        }
        positions(&mut sim)
    };
    assert!(bits(&a) == bits(&outside(true)), "stepping inside the pool");
    assert!(
        bits(&a) == bits(&outside(false)),
        "stepping outside the pool"
    );
}

/// The forces kept in the workspace only (what a scene run without extra plugins asks for)
/// and written to the components at every step give bitwise the same trajectory, on one and
/// two threads; only the second fills the components.
#[test]
fn forces_in_the_workspace_only_give_the_trajectory_of_forces_in_components() {
    use magsep_components::prelude::{DipoleForce, NetForce};
    use magsep_systems::forces::ForceComponents;
    let s = scene(&magsep::studies::bench_brownian::lammps_mirror_scene(9, 5).unwrap());
    let run = |threads: usize, every_step: bool| {
        on_threads(threads, || {
            // the library's default keeps the components
            let kept = Simulation::from_scene(&s, RunOptions::default()).unwrap();
            assert_eq!(kept.app.world.get_resource::<ForceComponents>(), None);
            let options = RunOptions {
                single_threaded: true,
                forces_unread: true,
                ..Default::default()
            };
            let mut sim = Simulation::from_scene(&s, options).unwrap();
            assert_eq!(
                sim.app.world.get_resource::<ForceComponents>(),
                Some(&ForceComponents::WorkspaceOnly)
            );
            if every_step {
                sim.app.world.insert_resource(ForceComponents::EveryStep);
            }
            for _ in 0..30 {
                sim.step();
            }
            let written = sim
                .app
                .world
                .query::<(&DipoleForce, &NetForce)>()
                .iter(&sim.app.world)
                .filter(|(d, f)| d.0 != glam::DVec3::ZERO && f.0 != glam::DVec3::ZERO)
                .count();
            (positions(&mut sim), written)
        })
    };
    let bits = |x: &[glam::DVec3]| -> Vec<[u64; 3]> {
        x.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
    };
    let (a, written_a) = run(1, false);
    let (b, written_b) = run(1, true);
    let (c, _) = run(2, false);
    let (d, _) = run(2, true);
    assert_eq!(
        written_a, 0,
        "workspace only: the components keep their defaults"
    );
    assert!(written_b > a.len() / 2, "{written_b} of {}", a.len());
    assert!(
        bits(&a) == bits(&b),
        "workspace only vs components, 1 thread"
    );
    assert!(bits(&a) == bits(&c), "1 vs 2 threads, workspace only");
    assert!(bits(&a) == bits(&d), "1 vs 2 threads, components");
}

fn identical_for_one_and_two_threads(kind: &str) {
    let s = scene(&dense_scene(&format!(
        r#"{{ kind = "{kind}", tolerance = 1e-3, max_displacement = 0.2, max_depth = 24 }}"#
    )));
    let run = |threads: usize, single: bool| {
        on_threads(threads, || {
            let mut sim = Simulation::from_scene(
                &s,
                RunOptions {
                    single_threaded: single,
                    ..Default::default()
                },
            )
            .unwrap();
            sim.run(|_| {}).unwrap();
            positions(&mut sim)
        })
    };
    let a = run(1, true);
    let b = run(2, false);
    assert!(
        a.iter()
            .zip(&b)
            .all(|(p, q)| p.to_array().map(f64::to_bits) == q.to_array().map(f64::to_bits))
    );
}

#[test]
fn every_mobility_runs_in_the_pipeline_and_is_reported() {
    for (method, expect) in [
        ("cholesky", "cholesky"),
        ("tea", "tea"),
        ("krylov", "krylov"),
        ("auto", "cholesky"),
    ] {
        let text = dense_scene(
            r#"{ kind = "adaptive", tolerance = 1e-3, max_displacement = 0.2, max_depth = 24 }"#,
        )
        .replace("count = 600", "count = 40")
        .replace(
            "mobility = \"free_draining\"",
            &format!("mobility = \"{method}\""),
        )
        .replace("duration = 1e-5", "duration = 3e-6");
        let s = scene(&text);
        let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
        let summary = sim.run(|_| {}).unwrap();
        assert_eq!(summary["mobility"]["method"], expect, "{method}: {summary}");
        assert!(
            summary["mobility"]["reason"]
                .as_str()
                .is_some_and(|r| !r.is_empty())
        );
        let x = positions(&mut sim);
        assert!(x.iter().all(|p| p.is_finite()));
    }
}

#[test]
fn shipped_brownian_scenes_run() {
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if !(name.starts_with("brownian_") && name.ends_with(".toml")) {
            continue;
        }
        let mut s = magsep::scene::load_scene(&path, &Default::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        // a few steps of one replicate (the scenes' own durations are long)
        let mut b = s
            .section::<magsep::brownian::BrownianSection>()
            .unwrap()
            .clone();
        b.duration = 3.0 * b.time_step;
        b.runs = Some(1);
        s.set_section(b);
        for g in &mut s.particles {
            g.count = g.count.min(20);
        }
        let summary = magsep::brownian::run_ensemble(&s, 1, &RunOptions::default(), &|_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(summary["steps"], 3, "{name}");
    }
}

#[test]
fn hard_cores_never_overlap_in_a_dipolar_cloud() {
    // the dipolar cloud of 600 particles with the thesis's explicit 5e-5 s step: close pairs
    // jump radii per step into each other, and the hard cores must push them back to contact
    let text = dense_scene(r#"{ kind = "fixed" }"#)
        .replace(
            "mobility = \"free_draining\"",
            "mobility = \"free_draining\"\ncontact = { kind = \"hard_core\" }",
        )
        .replace("time_step = 1e-6", "time_step = 5e-5")
        .replace("duration = 1e-5", "duration = 5e-4");
    let s = scene(&text);
    let mut sim = Simulation::from_scene(&s, RunOptions::default()).unwrap();
    let a = 75e-9;
    let mut closest = f64::INFINITY;
    while !sim.is_finished() {
        sim.step();
        let x = positions(&mut sim);
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                closest = closest.min((x[i] - x[j]).length());
            }
        }
    }
    assert!(
        closest >= 2.0 * a * (1.0 - 1e-9),
        "closest pair {} radii",
        closest / a
    );
    assert!(
        closest < 2.2 * a,
        "no contact formed: {} radii",
        closest / a
    );
}
