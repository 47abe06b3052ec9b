//! Replay and resume of recordings, for any registered pipeline: the recorded scene is parsed
//! with the registry, and its pipeline recomputes the summary ([`Pipeline::replay`]) or
//! continues the run ([`Pipeline::apply_frame`]). The frame helpers here are shared by the
//! pipelines.
//!
//! [`Pipeline::replay`]: crate::scene::Pipeline::replay
//! [`Pipeline::apply_frame`]: crate::scene::Pipeline::apply_frame

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::{SimApp, SimPlugin};
use magsep_plugins::record::{ParticleFrame, Recording, RecordingMetadata, read_recording};
use magsep_plugins::recorder::{FrameStatus, gather_frame};
use magsep_systems::rng::rng_from_state_words;
use serde_json::Value;

pub use crate::error::ReplayError;
use crate::scene::{Progress, Registry, RunOptions, Scene, parse_scene, spawn_scene};
use crate::sim::{SimError, Simulation, run_scene};

/// Spawn the particles of `frame` into `world` and set the container, clock and status.
/// `shapes` (in id order, from the recorded scene) override the frame's radii and half
/// lengths, which cannot describe superquadrics.
///
/// # Errors
/// [`ReplayError::BadFrame`] for non-positive radii or a malformed status.
pub fn load_frame(
    world: &mut World,
    frame: &ParticleFrame,
    shapes: Option<&[Shape]>,
) -> Result<(), ReplayError> {
    let bad = |detail: String| ReplayError::BadFrame {
        step: frame.step,
        detail,
    };
    for (i, id) in frame.ids.iter().enumerate() {
        let (r, h) = (frame.radii[i], frame.half_lengths[i]);
        if !(r.is_finite() && r > 0.0 && h.is_finite() && h >= 0.0) {
            return Err(bad(format!("particle {id}: radius {r}, half length {h}")));
        }
        let scene_shape = shapes.filter(|s| s.len() == frame.ids.len()).map(|s| s[i]);
        let shape = if let Some(s) = scene_shape {
            s
        } else if h == 0.0 {
            Shape::Sphere { radius: r }
        } else {
            Shape::Spherocylinder {
                radius: r,
                half_length: h,
            }
        };
        world.spawn(ParticleBundle {
            id: ParticleId(*id),
            position: Position(frame.positions[i]),
            orientation: Orientation(frame.orientations[i]),
            shape,
            species: Species(0),
            rng: ParticleRng(rng_from_state_words(frame.rng_states[i])),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        });
    }
    let e = frame.box_edges;
    let unbounded = e == glam::DVec3::ZERO || e == glam::DVec3::splat(f64::INFINITY);
    if !(unbounded || e.is_finite() && e.min_element() > 0.0) {
        return Err(bad(format!("box edges {e}")));
    }
    let status: FrameStatus =
        serde_json::from_str(&frame.status_json).map_err(|e| bad(format!("status_json: {e}")))?;
    let container = match status.container {
        Some(Container::Walled { walls, .. }) => Container::Walled { walls, edges: e },
        _ if unbounded => Container::Unbounded,
        _ => Container::PeriodicBox { edges: e },
    };
    world.insert_resource(container);
    world.insert_resource(StepClock {
        step: frame.step,
        dt: if frame.step > 0 {
            frame.time / frame.step as f64
        } else {
            0.0
        },
    });
    Ok(())
}

/// The last complete frame of `rec`, or why there is none.
///
/// # Errors
/// [`ReplayError::NoFrames`], with the truncation found.
pub fn last_frame(rec: &Recording) -> Result<&ParticleFrame, ReplayError> {
    rec.frames.last().ok_or_else(|| {
        ReplayError::NoFrames(
            rec.truncated
                .clone()
                .map(|t| format!(" ({t})"))
                .unwrap_or_default(),
        )
    })
}

/// The run's wall time \[s\] from the recorded summary; NaN (JSON `null`) when the file has
/// none (a killed run's), which [`replay_with`] then lists in `not_recomputed`.
pub fn recorded_wall_time(rec: &Recording) -> f64 {
    recorded_summary_wall_time(rec).unwrap_or(f64::NAN)
}

fn recorded_summary_wall_time(rec: &Recording) -> Option<f64> {
    rec.summary_json
        .as_deref()
        .and_then(|s| serde_json::from_str::<Value>(s).ok())
        .and_then(|v| v.get("wall_time_s").and_then(Value::as_f64))
}

/// Marks the values of a replayed `summary` at `keys` (dotted paths, e.g.
/// `stepper.neighbour_list_builds`) as ones the frames cannot give: each is set to `null`
/// (where its parent object exists) and appended to the summary's `not_recomputed` list.
pub fn not_recomputed(summary: &mut Value, keys: &[&str]) {
    for key in keys {
        let mut parts: Vec<&str> = key.split('.').collect();
        let last = parts.pop().unwrap_or_default();
        let mut node = Some(&mut *summary);
        for p in parts {
            node = node.and_then(|n| n.get_mut(p));
        }
        if let Some(obj) = node.and_then(Value::as_object_mut) {
            obj.insert(last.to_string(), Value::Null);
        }
    }
    let Some(obj) = summary.as_object_mut() else {
        return;
    };
    let list = obj
        .entry("not_recomputed")
        .or_insert_with(|| Value::Array(Vec::new()));
    if let Value::Array(list) = list {
        for key in keys {
            if !list.iter().any(|v| v == key) {
                list.push(Value::from(*key));
            }
        }
    }
}

/// The damage and truncation keys of a replayed summary: `"damaged"` (the reader's message)
/// when a corrupt record stopped the reading or bytes follow the footer, `"truncated"` only
/// when the file was cut short. A pipeline's replay that copied the damage under
/// `"truncated"` (the reader gives a damaged record in both) has that key removed.
fn damage_keys(rec: &Recording, obj: &mut serde_json::Map<String, Value>) {
    let truncation = rec
        .truncated
        .as_ref()
        .filter(|t| rec.damaged.as_ref() != Some(*t));
    if let Some(d) = &rec.damaged {
        if truncation.is_none() && obj.get("truncated").and_then(Value::as_str) == Some(d.as_str())
        {
            obj.remove("truncated");
        }
        obj.entry("damaged").or_insert(Value::String(d.clone()));
    }
    if let Some(t) = truncation {
        obj.entry("truncated").or_insert(Value::String(t.clone()));
    }
}

/// Replay a recording with the built-in pipelines: the summary of its last frame (same keys
/// as `magsep run`), and the recording itself.
///
/// # Errors
/// [`ReplayError`].
pub fn replay(path: &Path) -> Result<(Value, Recording), ReplayError> {
    replay_with(path, &Registry::default())
}

/// Replay a recording with the pipelines of `registry`: the pipeline's
/// [`replay`](crate::scene::Pipeline::replay), with `"truncated"` (where the file was cut)
/// or `"damaged"` (the reader's message: a corrupt record, bytes after the footer) added
/// when the pipeline did not say so, and `wall_time_s` `null` and listed in `not_recomputed`
/// when the file holds no run summary.
///
/// # Errors
/// [`ReplayError`].
pub fn replay_with(path: &Path, registry: &Registry) -> Result<(Value, Recording), ReplayError> {
    let rec = read_recording(path)?;
    let meta = metadata_of(&rec)?;
    let scene = parse_scene(&meta.scene_text, registry)?;
    let pipeline = scene.pipeline.clone().ok_or_else(|| {
        ReplayError::Unsupported("the recorded scene is field-only: nothing to replay".into())
    })?;
    let mut summary = pipeline.replay(&rec, &scene, meta.seed)?;
    // a damaged or cut file says so whatever the pipeline's replay reports
    if let Some(obj) = summary.as_object_mut() {
        damage_keys(&rec, obj);
    }
    // a killed run's file has no summary, so no wall time
    if summary.get("wall_time_s").is_some() && recorded_summary_wall_time(&rec).is_none() {
        not_recomputed(&mut summary, &["wall_time_s"]);
    }
    // the registered forces, as the run's summary lists them, from the recording's metadata
    if let Some(obj) = summary.as_object_mut() {
        recorded_force_keys(&meta, obj);
    }
    Ok((summary, rec))
}

/// The run summary's `force_contributions` and `force_kernels` from the forces a recording's
/// metadata holds ([`crate::sim::FORCES_KEY`]; nothing for files written before it), keeping
/// keys the pipeline's replay set.
fn recorded_force_keys(meta: &RecordingMetadata, obj: &mut serde_json::Map<String, Value>) {
    let Some(Ok(Value::Object(forces))) =
        (meta.extra.get(crate::sim::FORCES_KEY)).map(|text| serde_json::from_str::<Value>(text))
    else {
        return;
    };
    if let Some(Value::Array(names)) = forces.get("force_contributions") {
        let short: Vec<Value> = (names.iter())
            .map(|n| Value::from(crate::names::short_name(n.as_str().unwrap_or(""))))
            .collect();
        obj.entry("force_contributions")
            .or_insert(Value::Array(short));
    }
    if let Some(kernels) = forces.get("force_kernels") {
        obj.entry("force_kernels").or_insert(kernels.clone());
    }
}

/// Systems of the recorded schedule that the schedule `scene` builds here lacks (by name):
/// a run continued without them would silently differ.
pub fn missing_systems(
    recorded: &BTreeMap<String, Vec<String>>,
    here: &BTreeMap<String, Vec<String>>,
) -> Vec<String> {
    let have: BTreeSet<&String> = here.values().flatten().collect();
    let mut missing: Vec<String> = recorded
        .values()
        .flatten()
        .filter(|s| !have.contains(s))
        .cloned()
        .collect();
    missing.sort();
    missing.dedup();
    missing
}

/// Whether `a` and `b` agree to 1e-12 relative (time steps: the recorded `dt` is a decimal
/// round trip of the run's).
fn close(a: f64, b: f64, rel: f64) -> bool {
    a == b || (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// Checks that the recorded scene (parsed from the recording's metadata) fits the frame a
/// resume starts from, the checks `replay` makes and more, before the scene is spawned at
/// its own size:
///
/// 1. the particle count of the scene equals the frame's (a scene text claiming 10^7
///    particles over 10-particle frames is refused without spawning them);
/// 2. the frame's step is within the scene's run (`Pipeline::total_steps`);
/// 3. on the scene spawned once with the recorded seed (as many particles as the frame):
///    its time step equals the recorded `dt` and the frame's time is step x dt (1e-9
///    relative), so a changed `time_step` is refused;
/// 4. when the recording holds its step-0 frame: that spawn reproduces it bitwise (ids,
///    positions, orientations, radii, half lengths, random streams, box), so a different
///    seed or placement is refused.
///
/// The recorded schedule is compared with this program's once the simulation is built
/// ([`missing_systems`]).
///
/// # Errors
/// [`ReplayError::BadFrame`] naming what differs.
pub fn check_resume(
    scene: &Scene,
    meta: &RecordingMetadata,
    rec: &Recording,
    frame: &ParticleFrame,
) -> Result<(), ReplayError> {
    let bad = |detail: String| ReplayError::BadFrame {
        step: frame.step,
        detail,
    };
    let n = scene.total_particles();
    if n != frame.ids.len() as u64 {
        return Err(bad(format!(
            "{} particles, the recorded scene has {n}: the scene text does not belong to \
             these frames",
            frame.ids.len()
        )));
    }
    let Some(pipeline) = &scene.pipeline else {
        return Err(ReplayError::Unsupported(
            "the recorded scene is field-only: nothing to resume".into(),
        ));
    };
    if let Some(total) = pipeline.total_steps(scene)
        && frame.step > total
    {
        return Err(bad(format!(
            "the recorded scene ends at step {total}, before the frame"
        )));
    }
    let mut app = SimApp::new();
    spawn_scene(scene, &mut app.world, meta.seed)
        .map_err(|e| bad(format!("the recorded scene does not spawn: {e}")))?;
    let start = gather_frame(&mut app.world);
    let dt = app.world.get_resource::<StepClock>().map_or(0.0, |c| c.dt);
    if !close(dt, meta.dt, 1e-12) {
        return Err(bad(format!(
            "the recorded scene has time step {dt} s, the recording {} s",
            meta.dt
        )));
    }
    if frame.step > 0 && !close(frame.time, frame.step as f64 * dt, 1e-9) {
        return Err(bad(format!(
            "time {} s is not step x time step = {} s",
            frame.time,
            frame.step as f64 * dt
        )));
    }
    if let Some(first) = rec.frames.first().filter(|f| f.step == 0) {
        let differs = [
            ("particle ids", first.ids != start.ids),
            ("positions", first.positions != start.positions),
            ("orientations", first.orientations != start.orientations),
            ("radii", first.radii != start.radii),
            ("half lengths", first.half_lengths != start.half_lengths),
            ("random streams", first.rng_states != start.rng_states),
            ("box", first.box_edges != start.box_edges),
        ];
        let what: Vec<&str> = differs.iter().filter(|d| d.1).map(|d| d.0).collect();
        if !what.is_empty() {
            return Err(bad(format!(
                "the recorded scene with seed {} does not reproduce the recording's first \
                 frame (step 0): its {} differ; the scene text or the seed is not the run's",
                meta.seed,
                what.join(", ")
            )));
        }
    }
    Ok(())
}

/// Continue the run recorded in `path` from its last complete frame to the end of the scene,
/// optionally recording the continuation to `record`; `plugins` are built after the
/// pipeline's group (a program with user plugins passes the ones it ran with). The recorded
/// scene must fit the frame ([`check_resume`]: particle count, time step, seed, steps),
/// checked before the scene is spawned at its size, and refused when the recorded schedule
/// has systems this program's schedule lacks. Returns the summary of the whole run.
///
/// # Errors
/// [`ReplayError`].
pub fn resume(
    path: &Path,
    registry: &Registry,
    record: Option<PathBuf>,
    plugins: &[Arc<dyn SimPlugin>],
    progress: &dyn Progress,
) -> Result<Value, ReplayError> {
    let rec = read_recording(path)?;
    let meta = metadata_of(&rec)?;
    let mut scene = parse_scene(&meta.scene_text, registry)?;
    scene.overrides = recorded_overrides(&meta);
    let frame = last_frame(&rec)?.clone();
    check_resume(&scene, &meta, &rec, &frame)?;
    let options = RunOptions {
        seed: Some(meta.seed),
        resume_from: Some(frame),
        plugins: plugins.to_vec(),
        // the caller sees the summary and progress only
        forces_unread: true,
        ..Default::default()
    };
    // the frame fits the pipeline and the schedule has the recorded systems: checked on a
    // simulation that records nothing, before the run
    // (a frame that does not fit, a plugin's restore refusing it, a schedule this program
    // refuses: bad input, exit 2 from the CLI)
    let sim = Simulation::from_scene(&scene, options.clone()).map_err(|e| match e {
        SimError::Resume(m) => ReplayError::Unsupported(format!("cannot resume: {m}")),
        SimError::Schedule(m) => ReplayError::Unsupported(m),
        other => ReplayError::Sim(other),
    })?;
    let missing = missing_systems(&meta.schedule, &sim.app.resolved_schedule());
    if !missing.is_empty() {
        return Err(ReplayError::MissingPlugins(missing.join(", ")));
    }
    // force kernels are not systems: a kernel of another name passes the check above
    if let Some(recorded) = meta.extra.get(crate::sim::FORCES_KEY) {
        let here = crate::sim::forces_metadata(&sim.app.world);
        if *recorded != here {
            return Err(ReplayError::ForcesDiffer {
                recorded: recorded.clone(),
                here,
            });
        }
    }
    drop(sim);
    // the pipeline's own way: a brownian ensemble resumes its recorded replicate 0 and runs
    // the others (not recorded, reproducible from the seed) again, so that the summary is
    // the whole run's
    let options = RunOptions { record, ..options };
    Ok(run_scene(&scene, &options, progress)?)
}

/// The recording's `magsep` metadata, or why it has none (cut before it, or not magsep's).
fn metadata_of(rec: &Recording) -> Result<RecordingMetadata, ReplayError> {
    match (&rec.metadata, &rec.truncated) {
        (Some(m), _) => Ok(m.clone()),
        (None, Some(t)) => Err(ReplayError::TruncatedBeforeMetadata(t.clone())),
        (None, None) => Err(ReplayError::NoMetadata),
    }
}

/// The overrides a recording's metadata lists (`extra["overrides"]`; empty when absent).
pub fn recorded_overrides(meta: &RecordingMetadata) -> Vec<String> {
    meta.extra
        .get(crate::sim::OVERRIDES_KEY)
        .and_then(|s| serde_json::from_str(s).ok())
        .unwrap_or_default()
}
