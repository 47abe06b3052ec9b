//! The framework around the pipelines: the registry lookup, scene keys owned by pipelines,
//! recordings that start at step 0 and end with the final step whatever `record.every` is,
//! the builder, summary keys added by plugins, and resume refusing a recording made with
//! plugins the program lacks.

use bevy_ecs::prelude::*;
use magsep::plugins::record::read_recording;
use magsep::prelude::*;
use magsep::replay::resume;
use magsep::scene::NoProgress;
use magsep::scene::parse_scene;
use magsep_systems::sets::SimSystems;

/// A short brownian scene (4 particles, 100 steps, a frame every 30 steps), also read by
/// the Python reader check of CI.
fn brownian() -> String {
    std::fs::read_to_string("tests/data/brownian_short.toml").unwrap()
}

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("magsep-framework-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn an_unknown_pipeline_is_an_error_naming_the_registered_ones() {
    let text = brownian().replace("pipeline = \"brownian\"", "pipeline = \"brownain\"");
    let e = parse_scene(&text, &Default::default()).unwrap_err();
    let err =
        e.0.iter()
            .find(|e| e.path == "simulation.pipeline")
            .unwrap();
    assert!(err.message.contains("brownain"), "{err}");
    for name in ["packing", "brownian", "particle_fluid"] {
        assert!(err.message.contains(name), "{err}");
    }
}

#[test]
fn sections_and_particle_keys_of_other_pipelines_are_errors_naming_their_pipeline() {
    let text = format!(
        "{}\n[packing]\nscheme = \"fire\"\n[liquid]\ndensity = 1000.0\n",
        brownian()
    );
    let text = text.replace("count = 4\n", "count = 4\ndensity = 1200.0\nwhatever = 1\n");
    let e = parse_scene(&text, &Default::default()).unwrap_err().0;
    let at = |p: &str| e.iter().find(|x| x.path == p).map(|x| x.message.clone());
    assert_eq!(
        at("packing").as_deref(),
        Some("only for pipeline = \"packing\"")
    );
    assert_eq!(
        at("liquid").as_deref(),
        Some("only for pipeline = \"particle_fluid\"")
    );
    assert_eq!(
        at("particles[0].density").as_deref(),
        Some("only for pipeline = \"particle_fluid\"")
    );
    assert!(
        at("particles[0].whatever")
            .unwrap()
            .starts_with("unknown key")
    );
}

#[test]
fn a_particle_fluid_run_records_step_0_and_its_final_step() {
    // 37 steps, a frame every 10: frames at 0, 10, 20, 30 and the final 37
    let text = std::fs::read_to_string("scenes/levitation_single.toml")
        .unwrap()
        .replace("duration = 8.0 ", "duration = 0.037 ")
        .replace("every = 100", "every = 10");
    let scene = parse_scene(&text, &Default::default()).unwrap();
    let path = tmp("pf_final.mcap");
    let summary = Simulation::builder(&scene)
        .record(&path)
        .build()
        .unwrap()
        .run(|_| {})
        .unwrap();
    assert_eq!(summary["steps"], 37);
    let rec = read_recording(&path).unwrap();
    let steps: Vec<u64> = rec.frames.iter().map(|f| f.step).collect();
    assert_eq!(steps, vec![0, 10, 20, 30, 37]);
    assert!(rec.truncated.is_none());
}

/// A user observer: counts steps and adds its count to the summary.
#[derive(Resource, Default)]
struct Counted(u64);

fn count_steps(mut c: ResMut<Counted>) {
    c.0 += 1;
}

#[derive(Clone)]
struct CountPlugin;

impl SimPlugin for CountPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<Counted>();
        app.world
            .get_resource_or_init::<SummaryExtras>()
            .0
            .push(("counted_steps".into(), |w| {
                w.get_resource::<Counted>().map(|c| c.0.into())
            }));
        app.schedule
            .add_systems(count_steps.in_set(SimSystems::Observe));
    }
}

#[test]
fn builder_plugins_act_and_add_summary_keys() {
    let scene = parse_scene(&brownian(), &Default::default()).unwrap();
    let summary = Simulation::builder(&scene)
        .add_plugin(CountPlugin)
        .build()
        .unwrap()
        .run(|_| {})
        .unwrap();
    assert_eq!(summary["counted_steps"], summary["steps"]);
    assert_eq!(summary["steps"], 100);
}

#[test]
fn resume_refuses_a_recording_made_with_a_plugin_the_program_lacks() {
    let scene = parse_scene(&brownian(), &Default::default()).unwrap();
    let path = tmp("with_plugin.mcap");
    let mut sim = Simulation::builder(&scene)
        .add_plugin(CountPlugin)
        .record(&path)
        .build()
        .unwrap();
    // stop half-way, as a killed run would: the recording ends at step 60
    while sim.app.world.resource::<StepClock>().step < 60 {
        sim.step();
    }
    drop(sim);
    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.frames.last().unwrap().step, 60);
    let plugins: Vec<String> = rec
        .metadata
        .as_ref()
        .unwrap()
        .plugins
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert!(plugins.contains(&"CountPlugin".to_string()), "{plugins:?}");
    // without the plugin: refused, naming the missing system
    let err = resume(&path, &Default::default(), None, &[], &NoProgress).unwrap_err();
    assert!(
        matches!(err, magsep::error::ReplayError::MissingPlugins(ref m) if m.contains("count_steps")),
        "{err}"
    );
    // with it: the run continues to its end
    let plugin: std::sync::Arc<dyn SimPlugin> = std::sync::Arc::new(CountPlugin);
    let summary = resume(&path, &Default::default(), None, &[plugin], &NoProgress).unwrap();
    assert_eq!(summary["steps"], 100);
}
