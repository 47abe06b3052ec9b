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
    crate::common::tmp_path("pipeline_framework", name)
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

/// A user observer: counts steps and adds its count to the summary; its count is written to
/// every frame's status and read back when a run resumes.
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
        app.world
            .get_resource_or_init::<magsep::plugins::recorder::FrameStatusProviders>()
            .set("counted_steps", |w| {
                w.get_resource::<Counted>().map(|c| c.0.into())
            });
        app.schedule
            .add_systems(count_steps.in_set(SimSystems::Observe));
    }

    fn restore(&self, world: &mut World, status: &serde_json::Value) -> Result<(), String> {
        let n = status["counted_steps"]
            .as_u64()
            .ok_or("the frame has no counted_steps")?;
        world.insert_resource(Counted(n));
        Ok(())
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
    // through the pipeline's own run (`magsep run`): the key is there too, replicate 0's
    // under `replicate_0` when the scene runs several replicates
    let plugin: std::sync::Arc<dyn SimPlugin> = std::sync::Arc::new(CountPlugin);
    let options = RunOptions {
        plugins: vec![plugin],
        ..Default::default()
    };
    let one = magsep::sim::run_scene(&scene, &options, &NoProgress).unwrap();
    assert_eq!(one["counted_steps"], 100, "{one}");
    let text = brownian().replace("duration = 0.005", "duration = 0.005\nruns = 2");
    let two = parse_scene(&text, &Default::default()).unwrap();
    let two = magsep::sim::run_scene(&two, &options, &NoProgress).unwrap();
    assert_eq!(two["runs"], 2);
    assert_eq!(two["replicate_0"]["counted_steps"], 100, "{two}");
    assert!(two.get("counted_steps").is_none());
}

/// The brownian scene recorded (with `plugin` if any) and stopped after step 60, as a killed
/// run would be: its last frame is step 60.
fn recorded_to_step_60(name: &str, plugin: Option<CountPlugin>) -> std::path::PathBuf {
    let scene = parse_scene(&brownian(), &Default::default()).unwrap();
    let path = tmp(name);
    let mut builder = Simulation::builder(&scene).record(&path);
    if let Some(p) = plugin {
        builder = builder.add_plugin(p);
    }
    let mut sim = builder.build().unwrap();
    while sim.app.world.resource::<StepClock>().step < 60 {
        sim.step();
    }
    path
}

#[test]
fn resume_refuses_a_recording_made_with_a_plugin_the_program_lacks() {
    let path = recorded_to_step_60("with_plugin.mcap", Some(CountPlugin));
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
    // with it: the run continues to its end, and the plugin's count from the frame's status
    // (60) on, as if never interrupted
    let plugin: std::sync::Arc<dyn SimPlugin> = std::sync::Arc::new(CountPlugin);
    let summary = resume(&path, &Default::default(), None, &[plugin], &NoProgress).unwrap();
    assert_eq!(summary["steps"], 100);
    assert_eq!(summary["counted_steps"], 100, "{summary}");
}

/// [`CountPlugin`] without a restore: its count starts afresh on resume.
#[derive(Clone)]
struct ForgetfulCountPlugin;

impl SimPlugin for ForgetfulCountPlugin {
    fn build(&self, app: &mut SimApp) {
        CountPlugin.build(app);
    }
    fn name(&self) -> String {
        "CountPlugin".into()
    }
}

#[test]
fn a_plugin_that_does_not_restore_its_state_starts_afresh_and_a_refusal_names_it() {
    let path = recorded_to_step_60("forgetful.mcap", Some(CountPlugin));
    let plugin: std::sync::Arc<dyn SimPlugin> = std::sync::Arc::new(ForgetfulCountPlugin);
    let summary = resume(&path, &Default::default(), None, &[plugin], &NoProgress).unwrap();
    assert_eq!(summary["counted_steps"], 40, "{summary}");
    // a recording whose frames lack the plugin's key: the resume fails naming the plugin
    let bare = recorded_to_step_60("bare.mcap", None);
    let plugin: std::sync::Arc<dyn SimPlugin> = std::sync::Arc::new(CountPlugin);
    let err = resume(&bare, &Default::default(), None, &[plugin], &NoProgress).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("CountPlugin") && text.contains("no counted_steps"),
        "{text}"
    );
}

/// The handle of [`StepChannelPlugin`]'s channel, once added.
#[derive(Resource, Clone, Copy)]
struct StepChannel(magsep::plugins::record::ChannelHandle);

/// A plugin channel on a shipped pipeline: one message (the step, little-endian) per frame,
/// through a frame writer; `fail_at` makes the writer fail at that step.
#[derive(Clone)]
struct StepChannelPlugin {
    fail_at: Option<u64>,
}

impl SimPlugin for StepChannelPlugin {
    fn build(&self, app: &mut SimApp) {
        let fail_at = self.fail_at;
        magsep::plugins::recorder::FrameWriters::register(
            &mut app.world,
            "/test/step",
            move |world: &mut World| {
                let step = world.resource::<StepClock>().step;
                if Some(step) == fail_at {
                    return Err("the disk is full (test)".into());
                }
                let known = world.get_resource::<StepChannel>().map(|c| c.0);
                let mut rec = world.resource_mut::<magsep::plugins::recorder::Recorder>();
                let Some(w) = rec.writer.as_mut() else {
                    return Ok(());
                };
                let h = match known {
                    Some(h) => h,
                    None => w
                        .add_channel("/test/step", "", "", &[], "u64le")
                        .map_err(|e| e.to_string())?,
                };
                w.write_message(h, step, &step.to_le_bytes())
                    .map_err(|e| e.to_string())?;
                world.insert_resource(StepChannel(h));
                Ok(())
            },
        );
    }
}

fn step_messages(path: &std::path::Path) -> Vec<u64> {
    let mut reader = magsep::plugins::record::RecordingReader::open(path).unwrap();
    reader
        .messages(Some("/test/step"))
        .map(|m| u64::from_le_bytes(m.unwrap().data.as_slice().try_into().unwrap()))
        .collect()
}

#[test]
fn a_plugin_channel_has_one_message_per_frame_step_0_final_and_interrupted_included() {
    let scene = parse_scene(&brownian(), &Default::default()).unwrap();
    // the whole run: frames 0, 30, 60, 90 and the final 100
    let path = tmp("step_channel.mcap");
    Simulation::builder(&scene)
        .add_plugin(StepChannelPlugin { fail_at: None })
        .record(&path)
        .build()
        .unwrap()
        .run(|_| {})
        .unwrap();
    let frames: Vec<u64> = read_recording(&path)
        .unwrap()
        .frames
        .iter()
        .map(|f| f.step)
        .collect();
    assert_eq!(frames, [0, 30, 60, 90, 100]);
    assert_eq!(step_messages(&path), frames);
    // stopped after step 45: its last frame has its message too
    let path = tmp("step_channel_stopped.mcap");
    let stop = magsep::sim::StopFlag::new();
    let mut sim = Simulation::builder(&scene)
        .add_plugin(StepChannelPlugin { fail_at: None })
        .record(&path)
        .stop_flag(stop.clone())
        .build()
        .unwrap();
    sim.run(|w| {
        if w.resource::<StepClock>().step == 45 {
            stop.request_stop("test");
        }
    })
    .unwrap();
    assert_eq!(step_messages(&path), [0, 30, 45]);
    // a failing channel stops the run as a frame's write error does, naming the channel
    let path = tmp("step_channel_failed.mcap");
    let err = Simulation::builder(&scene)
        .add_plugin(StepChannelPlugin { fail_at: Some(60) })
        .record(&path)
        .build()
        .unwrap()
        .run(|_| {})
        .unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("/test/step at step 60") && msg.contains("disk is full"),
        "{msg}"
    );
    assert_eq!(err.partial_summary().unwrap()["steps"], 60);
    assert_eq!(step_messages(&path), [0, 30]);
    // and the file says why it ends early
    let rec = read_recording(&path).unwrap();
    let why = rec
        .metadata_records
        .iter()
        .find(|m| m.name == magsep::plugins::record::INTERRUPTED_METADATA_NAME)
        .expect("interrupted record");
    assert!(
        why.entries["reason"].contains("/test/step at step 60"),
        "{:?}",
        why.entries
    );
}

/// Uniform force kernel along -z \[N\] (for the forces check of a resume).
struct Sink;

impl magsep::systems::forces::ExternalForce for Sink {
    fn force_torque(
        &self,
        _p: &magsep::systems::forces::ParticleState,
    ) -> (glam::DVec3, glam::DVec3) {
        (glam::DVec3::new(0.0, 0.0, -1e-15), glam::DVec3::ZERO)
    }
}

/// Adds [`Sink`] as kernel `sink`, a summary key named as the pipeline's `steps`, and (with
/// `status_key`) a frame-status key of the given name.
#[derive(Clone)]
struct SinkPlugin {
    status_key: Option<&'static str>,
}

impl SimPlugin for SinkPlugin {
    fn build(&self, app: &mut SimApp) {
        app.add_external_force("sink", std::sync::Arc::new(Sink));
        app.world
            .get_resource_or_init::<SummaryExtras>()
            .0
            .push(("steps".into(), |_| Some(7.into())));
        if let Some(key) = self.status_key {
            app.world
                .get_resource_or_init::<magsep::plugins::recorder::FrameStatusProviders>()
                .set(key, |_| Some(1.into()));
        }
    }
}

#[test]
fn a_resume_with_other_forces_is_refused_and_plugin_keys_never_replace_the_summarys() {
    let scene = parse_scene(
        &brownian().replace(
            "time_step = 5e-5",
            "time_step = 5e-5\nstep_control = { kind = \"fixed\" }",
        ),
        &Default::default(),
    )
    .unwrap();
    let path = tmp("forces.mcap");
    let mut sim = Simulation::builder(&scene).record(&path).build().unwrap();
    while sim.app.world.resource::<StepClock>().step < 60 {
        sim.step();
    }
    drop(sim);
    // a kernel more than the recorded run had: refused before anything runs
    let plugin: std::sync::Arc<dyn SimPlugin> =
        std::sync::Arc::new(SinkPlugin { status_key: None });
    let err = resume(
        &path,
        &Default::default(),
        None,
        std::slice::from_ref(&plugin),
        &NoProgress,
    )
    .unwrap_err();
    assert!(
        matches!(err, magsep::error::ReplayError::ForcesDiffer { ref recorded, ref here }
            if !recorded.contains("sink") && here.contains("\"sink\"")),
        "{err}"
    );
    // the plugin's `steps` does not replace the pipeline's: left out, with a warning
    let summary = Simulation::builder(&scene)
        .add_plugin(SinkPlugin { status_key: None })
        .build()
        .unwrap()
        .run(|_| {})
        .unwrap();
    assert_eq!(summary["steps"], 100);
    assert_eq!(summary["force_kernels"], serde_json::json!(["sink"]));
    let warnings = summary["warnings"].to_string();
    assert!(warnings.contains("summary key `steps`"), "{warnings}");
    // a frame-status key named as the pipeline's: refused when the recording opens
    let clash = tmp("clash.mcap");
    let err = Simulation::builder(&scene)
        .add_plugin(SinkPlugin {
            status_key: Some("brownian"),
        })
        .record(&clash)
        .build()
        .err()
        .expect("a clashing status key is refused");
    assert!(
        matches!(err, SimError::Schedule(ref m) if m.contains("`brownian`")),
        "{err}"
    );
    assert!(!clash.exists());
}
