//! Helpers shared by the integration tests.

use glam::DVec3;
use magsep::prelude::*;

/// Particle centres in `ParticleId` order [m].
pub fn sorted_positions(sim: &mut Simulation) -> Vec<DVec3> {
    let mut rows: Vec<(ParticleId, DVec3)> = sim
        .app
        .world
        .query::<(&ParticleId, &Position)>()
        .iter(&sim.app.world)
        .map(|(i, p)| (*i, p.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| r.1).collect()
}

/// Run the `magsep` binary with `args` (in the test's working directory).
pub fn magsep(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_magsep"))
        .args(args)
        .output()
        .expect("binary runs")
}

/// The path `name` in the directory `group` of the tests' temporary directory (created).
pub fn tmp_path(group: &str, name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(group);
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A command's standard error as text.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}
