//! (b) Disable a built-in plugin of a pipeline group and add your own.
//!
//! The packing pipeline's `McmOverlapRemovalPlugin` is swapped for a plugin that removes
//! overlaps with the thesis's original Williams-Philipse rule at beta = 0.9, reusing the public
//! kernel `remove_overlaps`. Run: `cargo run --release --example replace_plugin`.

use bevy_ecs::prelude::*;
use magsep::prelude::*;
use magsep::scene::parse_scene;
use magsep::systems::packing::moves::MoveRule;
use magsep::systems::packing::removal::remove_overlaps;
use magsep::systems::packing::systems::McmWorkspace;

/// How many times the custom removal ran (to show it is the one in the schedule).
#[derive(Resource, Debug, Default)]
pub struct AggressiveRemovalRuns(pub u64);

/// Constraints: original rule with beta = 0.9.
pub fn remove_overlaps_aggressive(
    mut ws: ResMut<McmWorkspace>,
    status: Res<PackingStatus>,
    mut runs: ResMut<AggressiveRemovalRuns>,
) {
    if status.stopped.is_some() {
        return;
    }
    let ws = &mut *ws;
    let p = ws.params;
    ws.outcome = Some(remove_overlaps(
        &mut ws.state,
        &mut ws.list,
        MoveRule::Original {
            beta: 0.9,
            xi: None,
        },
        p.tolerance,
        p.max_attempts,
        &mut ws.rng,
    ));
    runs.0 += 1;
}

/// The replacement overlap-removal plugin.
#[derive(Debug, Clone, Copy, Default)]
pub struct AggressiveRemovalPlugin;

impl SimPlugin for AggressiveRemovalPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<AggressiveRemovalRuns>();
        app.schedule
            .add_systems(remove_overlaps_aggressive.in_set(SimSystems::Constraints));
    }
}

const SCENE: &str = r#"
[simulation]
pipeline = "packing"
seed = 5
[container]
kind = "periodic_box"
[[particles]]
count = 60
shape = { kind = "sphere", radius = 0.5 }
[packing]
max_attempts = 12000
"#;

/// Runs the packing with the replacement; returns (summary, custom removal runs, resolved
/// schedule of the Constraints set).
pub fn demo() -> (serde_json::Value, u64, Vec<String>) {
    let scene = parse_scene(SCENE, &Default::default()).expect("valid scene");
    let pipeline = packing_pipeline()
        .disable::<McmOverlapRemovalPlugin>()
        .add(AggressiveRemovalPlugin);
    let mut sim = Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        },
    )
    .expect("builds");
    let constraints = sim
        .app
        .resolved_schedule()
        .get("Constraints")
        .cloned()
        .unwrap_or_default();
    let summary = sim.run(|_| {}).expect("runs");
    (
        summary,
        sim.app.world.resource::<AggressiveRemovalRuns>().0,
        constraints,
    )
}

fn main() {
    let (summary, runs, constraints) = demo();
    println!("Constraints set: {constraints:?}; custom removal ran {runs} times");
    println!("{summary:#}");
}
