//! Ad-hoc step timing (ignored; run with `--ignored --nocapture`), not a timed assertion.

use super::grid::ChannelGrid;
use super::solver::ChannelParams;
use super::solver_tests::Rng;
use super::stepper::ChannelSolver;
use std::time::Instant;

#[test]
#[ignore = "release tier: timing report, prints seconds per step"]
fn step_timing_report() {
    for (n, nz, steps) in [(32, 33, 20), (64, 65, 5), (128, 129, 2)] {
        let g = ChannelGrid::new([n, n, nz], [1.0, 1.0, 0.5]).unwrap();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut s = ChannelSolver::new(ChannelParams::new(g, 1e-3, 1e-4)).unwrap();
                let mut rng = Rng(5);
                let u: Vec<Vec<f64>> = (0..3)
                    .map(|_| (0..g.len()).map(|_| 0.01 * rng.next()).collect())
                    .collect();
                s.set_velocity([&u[0], &u[1], &u[2]]).unwrap();
                s.step();
                let t = Instant::now();
                for _ in 0..steps {
                    s.step();
                }
                let per = t.elapsed().as_secs_f64() / steps as f64;
                println!(
                    "{n}x{n}x{nz}, {threads} thread(s): {:.1} ms per step",
                    per * 1e3
                );
            });
        }
    }
}
