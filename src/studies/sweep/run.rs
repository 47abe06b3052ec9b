//! Running a sweep's points: in-process runs on `jobs` worker threads, each point's directory
//! written to a temporary name and renamed when complete, so a killed sweep restarted skips
//! the finished points and redoes the rest; a stop flag (SIGINT / SIGTERM in the CLI) ends
//! it gracefully, dropping the points cut short.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use magsep_plugins::app::SimPlugin;
use serde_json::{Value, json};
use toml_edit::DocumentMut;

use super::file::{Point, Sweep, value_cell};
use crate::scene::overrides::{Override, apply_to_document, parse_document};
use crate::scene::{NoProgress, Registry, RunOptions, Scene, SceneErrors, parse_scene};
use crate::sim::{SimError, Simulation, StopFlag, run_scene};

/// Name of the manifest in a sweep directory.
pub const MANIFEST: &str = "sweep.json";

/// How a point ended (read back from its directory).
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Finished with this summary.
    Ok(Value),
    /// Failed: the error, and the summary of what ran if any.
    Failed {
        /// The error message.
        error: String,
        /// The (partial) summary, if the run returned one.
        summary: Option<Value>,
    },
    /// Not finished (no directory).
    Missing,
}

/// Point `index`'s directory in `out`.
pub fn point_dir(out: &Path, index: usize) -> PathBuf {
    out.join("points").join(index.to_string())
}

/// The base scene as a document, for applying each point's overrides.
///
/// # Errors
/// The scene's TOML syntax error.
pub fn base_document(sweep: &Sweep) -> Result<DocumentMut, SceneErrors> {
    parse_document(&sweep.scene_text)
}

/// The scene of `point` (overrides applied, parsed and validated).
///
/// # Errors
/// Every problem at its key path.
pub fn point_scene(
    sweep: &Sweep,
    base: &DocumentMut,
    point: &Point,
    registry: &Registry,
) -> Result<Scene, SceneErrors> {
    let mut doc = base.clone();
    let overrides = sweep.overrides(point);
    let errors: Vec<_> = (overrides.iter())
        .filter_map(|o| apply_to_document(&mut doc, o).err())
        .collect();
    if !errors.is_empty() {
        return Err(SceneErrors(errors));
    }
    let mut scene = parse_scene(&doc.to_string(), registry)?;
    scene.overrides = overrides.iter().map(ToString::to_string).collect();
    Ok(scene)
}

/// Most failing points listed in the error of [`check_points`].
const MAX_LISTED: usize = 10;

/// Validate the scene of every point of `indices` before anything runs, and estimate each
/// one's memory (the scenes are built once, here).
///
/// # Errors
/// The failing points (up to ten listed), each with its overrides and key-path errors.
pub fn check_points(
    sweep: &Sweep,
    registry: &Registry,
    indices: &[usize],
) -> Result<Vec<PointMemory>, String> {
    let base = base_document(sweep).map_err(|e| format!("scene: {e}"))?;
    let wrong_paths = axis_path_errors(sweep, &base, registry);
    if !wrong_paths.is_empty() {
        return Err(wrong_paths.join("\n"));
    }
    let mut failing = Vec::new();
    let mut estimates = Vec::with_capacity(indices.len());
    let mut count = 0;
    for &i in indices {
        let point = sweep.point(i);
        match point_scene(sweep, &base, &point, registry) {
            Ok(scene) => estimates.push(PointMemory {
                index: i,
                estimate: crate::scene::memory::estimate(&scene),
            }),
            Err(e) => {
                count += 1;
                if failing.len() < MAX_LISTED {
                    failing.push(format!("point {i} ({}):\n{e}", point_overrides(sweep, i)));
                }
            }
        }
    }
    if count == 0 {
        return Ok(estimates);
    }
    let more = if count > failing.len() {
        format!("\n... and {} more points", count - failing.len())
    } else {
        String::new()
    };
    Err(format!("{}{more}", failing.join("\n")))
}

/// The axes whose path names no key of the base scene (a typo), each reported once at
/// `axes[k].path`: the axis's first value alone is set on the base scene, and an error of the
/// override or an unknown key on the axis's path is the path's fault (every point would
/// repeat it). Errors of the values are left to [`check_points`]'s points.
fn axis_path_errors(sweep: &Sweep, base: &DocumentMut, registry: &Registry) -> Vec<String> {
    let mut out = Vec::new();
    for (k, axis) in sweep.axes.iter().enumerate() {
        let Some(value) = axis.values.first() else {
            continue;
        };
        let mut doc = base.clone();
        let path = axis.path.to_string();
        let ov = Override::new(axis.path.clone(), value.clone());
        let errors = match apply_to_document(&mut doc, &ov) {
            Err(e) => vec![e],
            Ok(()) => match parse_scene(&doc.to_string(), registry) {
                Err(SceneErrors(e)) => (e.into_iter())
                    .filter(|e| e.message.starts_with("unknown key") && on_path(&path, &e.path))
                    .collect(),
                Ok(_) => Vec::new(),
            },
        };
        out.extend(errors.iter().map(|e| {
            let at = if e.path == path {
                String::new()
            } else {
                format!(" (at {})", e.path)
            };
            format!(
                "axes[{k}].path: `{path}` names no key of the scene{at}: {}",
                e.message
            )
        }));
    }
    out
}

/// Whether key path `prefix` is `path` or one of its parents.
fn on_path(path: &str, prefix: &str) -> bool {
    path.strip_prefix(prefix)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with(['.', '[']))
}

/// Spawn the scene of every point of `indices` and build its schedule with `plugins`,
/// stepping nothing and recording nothing: what a run would refuse before its first step (a
/// start region too small for its particles, a plugin's force the integrator cannot use) is
/// found before the sweep runs. `tick` is called after each point.
///
/// # Errors
/// The failing points (up to ten listed), each with its overrides and the refusal.
pub fn build_points(
    sweep: &Sweep,
    registry: &Registry,
    plugins: &[Arc<dyn SimPlugin>],
    indices: &[usize],
    tick: &dyn Fn(),
) -> Result<(), String> {
    let base = base_document(sweep).map_err(|e| format!("scene: {e}"))?;
    let mut failing = Vec::new();
    let mut count = 0;
    for &i in indices {
        let point = sweep.point(i);
        let built = point_scene(sweep, &base, &point, registry)
            .map_err(|e| e.to_string())
            .and_then(|scene| {
                if scene.pipeline.is_none() {
                    return Ok(());
                }
                let options = RunOptions {
                    single_threaded: true,
                    plugins: plugins.to_vec(),
                    ..Default::default()
                };
                Simulation::from_scene(&scene, options)
                    .map(drop)
                    .map_err(|e| e.to_string())
            });
        if let Err(e) = built {
            count += 1;
            if failing.len() < MAX_LISTED {
                failing.push(format!("point {i} ({}): {e}", point_overrides(sweep, i)));
            }
        }
        tick();
    }
    if count == 0 {
        return Ok(());
    }
    let more = if count > failing.len() {
        format!("\n... and {} more points", count - failing.len())
    } else {
        String::new()
    };
    Err(format!("{}{more}", failing.join("\n")))
}

/// One point's memory estimate, from [`check_points`].
#[derive(Debug, Clone)]
pub struct PointMemory {
    /// The point's index in the sweep.
    pub index: usize,
    /// Its scene's estimate.
    pub estimate: crate::scene::memory::MemoryEstimate,
}

/// The overrides of point `i`, space-separated, for messages.
fn point_overrides(sweep: &Sweep, i: usize) -> String {
    let ovs: Vec<String> = (sweep.overrides(&sweep.point(i)).iter())
        .map(ToString::to_string)
        .collect();
    ovs.join(" ")
}

/// How many of `jobs` points may run at once within `budget` \[bytes\]: each of the points
/// `todo` must fit alone (else an error naming the point and the key that drives its
/// estimate), and the `J` largest estimates together, so `J` is lowered until they do.
/// `memory` holds the estimates of [`check_points`] (points missing from it were reported
/// there). Returns `J` (at least 1) and the largest estimate \[bytes\].
///
/// # Errors
/// The points over the budget (up to ten listed).
pub fn jobs_within_budget(
    sweep: &Sweep,
    memory: &[PointMemory],
    todo: &[usize],
    jobs: usize,
    budget: u64,
) -> Result<(usize, f64), String> {
    let mut todo = todo.to_vec();
    todo.sort_unstable();
    let mut estimates = Vec::with_capacity(todo.len());
    let mut failing = Vec::new();
    for m in memory
        .iter()
        .filter(|m| todo.binary_search(&m.index).is_ok())
    {
        let e = &m.estimate;
        if e.bytes <= budget as f64 && e.bytes.is_finite() {
            estimates.push(e.bytes);
        } else if failing.len() < MAX_LISTED {
            let err = crate::scene::memory::over_budget(e, budget);
            failing.push(format!(
                "point {} ({}):\n{err}",
                m.index,
                point_overrides(sweep, m.index)
            ));
        }
    }
    if !failing.is_empty() {
        return Err(failing.join("\n"));
    }
    estimates.sort_by(|a, b| b.total_cmp(a));
    let mut j = jobs.clamp(1, estimates.len().max(1));
    while j > 1 && estimates[..j].iter().sum::<f64>() > budget as f64 {
        j -= 1;
    }
    Ok((j, estimates.first().copied().unwrap_or(0.0)))
}

/// The manifest of a sweep directory: what identifies the sweep.
pub fn manifest(sweep: &Sweep) -> Value {
    json!({
        "format": "magsep-sweep-1",
        "points": sweep.len(),
        "sweep_text": sweep.sweep_text,
        "scene_path": sweep.scene_path.display().to_string(),
        "scene_text": sweep.scene_text,
    })
}

/// Write `text` to `path` atomically (a temporary file beside it, then rename).
///
/// # Errors
/// The I/O error, naming the file.
pub fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Create `out` (and `out/points`) and write the manifest, or check that the one there is of
/// the same sweep.
///
/// # Errors
/// `Err(true, message)` when `out` holds another sweep (bad input), `Err(false, message)` on
/// an I/O failure.
pub fn open_dir(sweep: &Sweep, out: &Path) -> Result<(), (bool, String)> {
    std::fs::create_dir_all(out.join("points"))
        .map_err(|e| (false, format!("cannot create {}: {e}", out.display())))?;
    let path = out.join(MANIFEST);
    let mine = manifest(sweep);
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let theirs: Value = serde_json::from_str(&text).unwrap_or_default();
            let same = ["format", "points", "sweep_text", "scene_text"]
                .iter()
                .all(|k| theirs.get(k) == mine.get(k));
            if same {
                Ok(())
            } else {
                Err((
                    true,
                    format!(
                        "{} holds another sweep (its {MANIFEST} differs from this sweep file \
                         or base scene); use a new --out directory",
                        out.display()
                    ),
                ))
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let text = serde_json::to_string_pretty(&mine).unwrap_or_default();
            write_atomic(&path, &text).map_err(|e| (false, e))
        }
        Err(e) => Err((false, format!("cannot read {}: {e}", path.display()))),
    }
}

/// The outcome of every point of `sweep` in `out`, indexed by point (each summary read once).
pub fn outcomes(sweep: &Sweep, out: &Path) -> Vec<Outcome> {
    (0..sweep.len()).map(|i| outcome(out, i)).collect()
}

/// How point `index` ended, from its directory in `out`.
pub fn outcome(out: &Path, index: usize) -> Outcome {
    let dir = point_dir(out, index);
    if !dir.is_dir() {
        return Outcome::Missing;
    }
    let read = |name: &str| -> Option<Value> {
        let text = std::fs::read_to_string(dir.join(name)).ok()?;
        serde_json::from_str(&text).ok()
    };
    let summary = read("summary.json");
    match (read("error.json"), summary) {
        (None, Some(s)) => Outcome::Ok(s),
        (Some(e), summary) => Outcome::Failed {
            error: e["error"].as_str().unwrap_or("failed").to_string(),
            summary,
        },
        (None, None) => Outcome::Failed {
            error: "the point's directory has no summary.json".into(),
            summary: None,
        },
    }
}

/// `point.json`: the point's index, axis values, replicate, seed and overrides.
pub fn point_json(sweep: &Sweep, point: &Point) -> Value {
    let axes: serde_json::Map<String, Value> = (sweep.axes.iter().zip(&point.values))
        .map(|(a, &v)| (a.name.clone(), Value::String(value_cell(&a.values[v]))))
        .collect();
    json!({
        "index": point.index,
        "axes": axes,
        "replicate": point.replicate,
        "seed": sweep.seed_of(point),
        "overrides": sweep.overrides(point).iter().map(ToString::to_string).collect::<Vec<_>>(),
    })
}

/// The message of a panic payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into())
}

/// What the workers share.
pub struct Runner<'a> {
    /// The sweep.
    pub sweep: &'a Sweep,
    /// Pipelines.
    pub registry: &'a Registry,
    /// Plugins built into every run.
    pub plugins: Vec<Arc<dyn SimPlugin>>,
    /// The sweep directory.
    pub out: &'a Path,
    /// Write each point's recording (`recording.mcap`).
    pub record: bool,
    /// Stop the sweep gracefully when set (e.g. by SIGINT): no new point starts, and the points
    /// running are stopped at their current step and left unfinished (their `.tmp-N`
    /// directories removed), so that a restart runs them again from the start.
    pub stop: Option<StopFlag>,
}

/// How [`Runner::run_point`] left a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointEnd {
    /// Finished without error (its directory is in place).
    Ok,
    /// Finished with an error (recorded in its `error.json`).
    Failed,
    /// Stopped by the sweep's stop flag before it finished: nothing is kept.
    Interrupted,
}

/// What [`Runner::run_all`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunAll {
    /// Points that finished with an error.
    pub failed: usize,
    /// Points that finished (with or without an error).
    pub finished: usize,
    /// Points stopped part-way by the stop flag (left to a restart).
    pub interrupted: usize,
}

impl Runner<'_> {
    /// Run point `index` into its directory.
    ///
    /// # Errors
    /// An I/O failure of the sweep directory (the run's own failures are the point's error).
    pub fn run_point(&self, base: &DocumentMut, index: usize) -> Result<PointEnd, String> {
        let point = self.sweep.point(index);
        let tmp = self.out.join("points").join(format!(".tmp-{index}"));
        let io = |e: std::io::Error| format!("{}: {e}", tmp.display());
        if tmp.exists() {
            std::fs::remove_dir_all(&tmp).map_err(io)?;
        }
        std::fs::create_dir_all(&tmp).map_err(io)?;
        let pretty = |v: &Value| serde_json::to_string_pretty(v).unwrap_or_default();
        std::fs::write(
            tmp.join("point.json"),
            pretty(&point_json(self.sweep, &point)),
        )
        .map_err(io)?;
        let run = || -> (Option<Value>, Option<String>) {
            let base = base.clone();
            let scene = match point_scene(self.sweep, &base, &point, self.registry) {
                Ok(s) => s,
                Err(e) => return (None, Some(e.to_string())),
            };
            let options = RunOptions {
                record: self.record.then(|| tmp.join("recording.mcap")),
                single_threaded: true,
                plugins: self.plugins.clone(),
                stop: self.stop.as_ref().map(StopFlag::child),
                forces_unread: true,
                ..Default::default()
            };
            match run_scene(&scene, &options, &NoProgress) {
                Ok(summary) => {
                    let failure = scene.pipeline.as_ref().and_then(|p| p.failure(&summary));
                    (Some(summary), failure)
                }
                Err(e) => (SimError::partial_summary(&e).cloned(), Some(e.to_string())),
            }
        };
        let (summary, error) = catch_unwind(AssertUnwindSafe(run))
            .unwrap_or_else(|p| (None, Some(format!("panicked: {}", panic_message(&*p)))));
        let stopped = self.stop.as_ref().is_some_and(StopFlag::is_stopped);
        if stopped && summary.as_ref().is_none_or(|s| s["interrupted"] == true) {
            // cut short by the sweep's stop: not a result; a restart runs it again
            std::fs::remove_dir_all(&tmp).map_err(io)?;
            return Ok(PointEnd::Interrupted);
        }
        if let Some(s) = &summary {
            std::fs::write(tmp.join("summary.json"), pretty(s)).map_err(io)?;
        }
        if let Some(e) = &error {
            std::fs::write(tmp.join("error.json"), pretty(&json!({ "error": e }))).map_err(io)?;
        }
        let dir = point_dir(self.out, index);
        std::fs::rename(&tmp, &dir)
            .map_err(|e| format!("cannot move {} to {}: {e}", tmp.display(), dir.display()))?;
        Ok(if error.is_none() {
            PointEnd::Ok
        } else {
            PointEnd::Failed
        })
    }

    /// Run `todo` on `jobs` worker threads, calling `done` after each finished point; once
    /// the stop flag is set no new point starts.
    ///
    /// # Errors
    /// The first I/O failure of the sweep directory (the workers stop taking new points).
    pub fn run_all(
        &self,
        todo: &[usize],
        jobs: usize,
        done: &(dyn Fn() + Sync),
    ) -> Result<RunAll, String> {
        let base = base_document(self.sweep).map_err(|e| e.to_string())?;
        let next = AtomicUsize::new(0);
        let failed = AtomicUsize::new(0);
        let finished = AtomicUsize::new(0);
        let interrupted = AtomicUsize::new(0);
        let io_error: Mutex<Option<String>> = Mutex::new(None);
        std::thread::scope(|s| {
            for _ in 0..jobs.clamp(1, todo.len().max(1)) {
                s.spawn(|| {
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        let Some(&index) = todo.get(k) else { break };
                        if io_error.lock().map(|e| e.is_some()).unwrap_or(true)
                            || self.stop.as_ref().is_some_and(StopFlag::is_stopped)
                        {
                            break;
                        }
                        // one thread per point: the points fill the cores
                        let point = || self.run_point(&base, index);
                        let end = if jobs > 1 {
                            magsep_systems::par::on_one_thread(point)
                        } else {
                            point()
                        };
                        match end {
                            Ok(PointEnd::Ok) => {
                                finished.fetch_add(1, Ordering::Relaxed);
                            }
                            Ok(PointEnd::Failed) => {
                                finished.fetch_add(1, Ordering::Relaxed);
                                failed.fetch_add(1, Ordering::Relaxed);
                            }
                            Ok(PointEnd::Interrupted) => {
                                interrupted.fetch_add(1, Ordering::Relaxed);
                                break;
                            }
                            Err(e) => {
                                if let Ok(mut slot) = io_error.lock() {
                                    slot.get_or_insert(e);
                                }
                                break;
                            }
                        }
                        done();
                    }
                });
            }
        });
        match io_error.into_inner().ok().flatten() {
            Some(e) => Err(e),
            None => Ok(RunAll {
                failed: failed.into_inner(),
                finished: finished.into_inner(),
                interrupted: interrupted.into_inner(),
            }),
        }
    }
}

/// Parse `I/N` (1-based shard I of N).
///
/// # Errors
/// What is wrong.
pub fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--shard must be I/N with 1 <= I <= N (1-based), got `{text}`");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let i: usize = i.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if i == 0 || n == 0 || i > n {
        return Err(bad());
    }
    Ok((i, n))
}

/// The point indices of shard `i` of `n` (1-based): those with index % n == i - 1.
pub fn shard_points(len: usize, shard: Option<(usize, usize)>) -> Vec<usize> {
    match shard {
        Some((i, n)) => (0..len).filter(|k| k % n == i - 1).collect(),
        None => (0..len).collect(),
    }
}
