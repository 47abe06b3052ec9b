//! Replay and resume: the summary recomputed from a recording's frames equals the run's, and
//! a run resumed from a recorded frame ends as the uninterrupted run.

use crate::common;

use common::{parse, run, temp_dir, trap_scene, without_wall_time};
use langevin_trap::registry;
use magsep::plugins::recorder::record_now;
use magsep::replay::{replay_with, resume};
use magsep::{RunOptions, Simulation};

#[test]
fn replay_reproduces_the_summary() {
    let dir = temp_dir("replay");
    let path = dir.join("run.mcap");
    let scene = parse(&trap_scene(200, 2e-3, 305, 5, ""));
    let summary = run(
        &scene,
        RunOptions {
            record: Some(path.clone()),
            ..Default::default()
        },
    );
    let (replayed, rec) = replay_with(&path, &registry()).expect("replay");
    // step 0, 61 frames every 5 steps, and the final step 305
    assert_eq!(rec.frames.len(), 62);
    assert!(rec.truncated.is_none());
    eprintln!(
        "run variance {} m², replay variance {} m²",
        summary["variance_m2"], replayed["variance_m2"]
    );
    for key in [
        "variance_m2",
        "msd_m2",
        "mean_displacement_m",
        "samples",
        "steps",
        "relative_error",
        "theory_variance_m2",
    ] {
        assert_eq!(summary[key], replayed[key], "{key}");
    }
    // the wall time is the recorded one: the summaries are equal as a whole
    assert_eq!(summary, replayed);
}

#[test]
fn resume_continues_bit_for_bit() {
    let dir = temp_dir("resume");
    let scene = parse(&trap_scene(100, 1e-3, 200, 10, ""));
    let whole = run(&scene, RunOptions::default());
    // an interrupted run: 120 of 200 steps recorded, then the process "dies"
    let path = dir.join("part.mcap");
    let mut sim = Simulation::builder(&scene).record(&path).build().unwrap();
    record_now(&mut sim.app.world);
    for _ in 0..120 {
        sim.step();
    }
    let partial = sim.summary();
    sim.finish_recording(&partial).unwrap();
    let resumed =
        resume(&path, &registry(), None, &[], &magsep::scene::NoProgress).expect("resume");
    assert_eq!(without_wall_time(resumed), without_wall_time(whole));
}
