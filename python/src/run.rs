//! `magsep.run` and `magsep.validate`: a scene (path, TOML text or dict) with overrides, run
//! through [`magsep::sim::run_scene`] as `magsep run` runs it, with the GIL released and
//! Ctrl-C stopping the run gracefully (the library's [`StopFlag`]).

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use magsep::cli::{Input, check_file};
use magsep::input::{named_inputs, read_scene_text};
use magsep::scene::memory;
use magsep::scene::overrides::{Override, apply_overrides};
use magsep::scene::{Progress, RunOptions, Scene, SceneError, SceneErrors, parse_scene};
use magsep::sim::{SimError, StopFlag, run_scene};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use serde_json::Value;

use crate::convert::{json_value, table_text, to_toml};
use crate::{RunError, RunInterrupted};

/// Most worker threads `threads=` accepts (as `magsep run --threads`).
const MAX_THREADS: usize = 1024;
/// How often the calling thread looks for Ctrl-C while a run goes on.
const POLL: Duration = Duration::from_millis(50);
/// How often a progress callback is called at most.
const PROGRESS_EVERY: Duration = Duration::from_millis(500);
/// Stack of the thread that runs the scene (the CLI runs it on the main thread's 8 MiB).
const RUN_STACK_BYTES: usize = 64 << 20;

/// A scene as given: its text, the file it came from (if any), and a name for messages.
struct Source {
    text: String,
    path: Option<PathBuf>,
    name: String,
}

/// `scene`: a dict (the scene's tables), an `os.PathLike` or a `str` naming a file (no
/// newline, ending in `.toml` or naming an existing file), or TOML text.
fn source(scene: &Bound<'_, PyAny>) -> PyResult<Source> {
    let py = scene.py();
    if scene.is_instance_of::<PyDict>() {
        let toml::Value::Table(table) = to_toml(scene, "")? else {
            return Err(crate::key_error(py, "(scene)", "expected a dict"));
        };
        return Ok(Source {
            text: table_text(py, &table)?,
            path: None,
            name: "the scene dict".into(),
        });
    }
    let path: Option<PathBuf> =
        if let Ok(s) = scene.cast::<PyString>() {
            let s = s.to_str()?;
            let looks_like_path =
                !s.contains('\n') && (s.trim_end().ends_with(".toml") || Path::new(s).is_file());
            if !looks_like_path {
                return Ok(Source {
                    text: s.to_string(),
                    path: None,
                    name: "the scene text".into(),
                });
            }
            Some(PathBuf::from(s))
        } else {
            Some(scene.extract::<PathBuf>().map_err(|_| {
                crate::key_error(py, "(scene)", "expected a path, TOML text or a dict")
            })?)
        };
    let path = path.unwrap_or_default();
    let text = read_scene_text(&path).map_err(|e| {
        crate::scene_error(
            py,
            &format!("{} is invalid", path.display()),
            vec![("(file)".into(), e)],
        )
    })?;
    Ok(Source {
        text,
        name: path.display().to_string(),
        path: Some(path),
    })
}

/// `overrides`: a dict {key path: value} or a list of `PATH=VALUE` strings (VALUE in TOML),
/// as `magsep run --set`.
fn overrides(ov: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(ov) = ov.filter(|o| !o.is_none()) else {
        return Ok(Vec::new());
    };
    let py = ov.py();
    if let Ok(d) = ov.cast::<PyDict>() {
        let mut out = Vec::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| crate::key_error(py, "overrides", "keys must be key paths (str)"))?;
            let value = to_toml(&v, &key)?;
            out.push(format!("{key}={value}"));
        }
        return Ok(out);
    }
    if ov.is_instance_of::<PyString>() {
        return Err(crate::key_error(
            py,
            "overrides",
            "expected a dict or a list of PATH=VALUE strings, got one string",
        ));
    }
    ov.extract::<Vec<String>>().map_err(|_| {
        crate::key_error(
            py,
            "overrides",
            "expected a dict {path: value} or a list of PATH=VALUE strings",
        )
    })
}

/// The scene with the overrides applied and validated, as `magsep run` reads it.
fn load(py: Python<'_>, src: &Source, set: &[String]) -> PyResult<Scene> {
    let what = if set.is_empty() {
        format!("{} is invalid", src.name)
    } else {
        format!("{} with overrides is invalid", src.name)
    };
    let mut parsed = Vec::new();
    let mut errors: Vec<SceneError> = Vec::new();
    for arg in set {
        match Override::parse(arg) {
            Ok(o) => parsed.push(o),
            Err(e) => errors.push(e),
        }
    }
    if !errors.is_empty() {
        return Err(crate::scene_errors(py, &what, &SceneErrors(errors)));
    }
    let text =
        apply_overrides(&src.text, &parsed).map_err(|e| crate::scene_errors(py, &what, &e))?;
    let mut scene =
        parse_scene(&text, &Default::default()).map_err(|e| crate::scene_errors(py, &what, &e))?;
    scene.overrides = parsed.iter().map(Override::to_string).collect();
    Ok(scene)
}

/// The scene's memory estimate against the budget \[GiB\] (bad input when over).
fn check_memory(
    py: Python<'_>,
    scene: &Scene,
    name: &str,
    budget_gib: Option<f64>,
) -> PyResult<()> {
    let budget =
        memory::budget(budget_gib).map_err(|e| crate::key_error(py, "memory_budget", e))?;
    memory::check(scene, budget).map_err(|e| {
        crate::scene_error(py, &format!("{name} is invalid"), vec![(e.path, e.message)])
    })?;
    Ok(())
}

/// Validate `scene` (with `overrides`) as `magsep validate` does; returns what it holds.
#[pyfunction]
#[pyo3(signature = (scene, overrides=None, memory_budget=None))]
pub fn validate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    overrides: Option<&Bound<'py, PyAny>>,
    memory_budget: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let src = source(scene)?;
    let set = self::overrides(overrides)?;
    let scene = load(py, &src, &set)?;
    check_memory(py, &scene, &src.name, memory_budget)?;
    json_value(
        py,
        &serde_json::json!({
            "valid": true,
            "pipeline": scene.pipeline_name(),
            "particles": scene.total_particles(),
            "fibres": scene.fibres.len(),
            "overrides": scene.overrides,
        }),
    )
}

/// Progress of the run, read by the calling thread.
#[derive(Default)]
struct Shared {
    total: AtomicU64,
    done: AtomicU64,
    message: Mutex<Option<String>>,
}

impl Progress for Shared {
    fn set_total(&self, steps: u64) {
        self.total.store(steps, Ordering::Relaxed);
    }
    fn advance(&self, steps: u64) {
        self.done.fetch_add(steps, Ordering::Relaxed);
    }
    fn message(&self, text: String) {
        if let Ok(mut m) = self.message.lock() {
            *m = Some(text);
        }
    }
}

/// The rayon pool of `threads` workers: the global one when this is the first request (so
/// that every part of the library uses it, as `magsep run --threads`), else a pool of its own.
fn pool(py: Python<'_>, threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let Some(n) = threads else { return Ok(None) };
    if !(1..=MAX_THREADS).contains(&n) {
        return Err(crate::key_error(
            py,
            "threads",
            format!("must be in 1..={MAX_THREADS}, got {n}"),
        ));
    }
    if rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .is_ok()
        || rayon::current_num_threads() == n
    {
        return Ok(None);
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map(Some)
        .map_err(|e| RunError::new_err(format!("thread pool: {e}")))
}

/// What stopped the wait for the run besides its end.
struct Watch {
    /// An exception raised while the run went on (KeyboardInterrupt, or the callback's).
    error: Option<PyErr>,
    last_report: Instant,
}

impl Watch {
    /// Look for Ctrl-C (and other signal handlers' exceptions) and report progress.
    fn poll(&mut self, stop: &StopFlag, progress: Option<&Py<PyAny>>, shared: &Shared) {
        Python::attach(|py| {
            if self.error.is_none()
                && let Err(e) = py.check_signals()
            {
                let reason = if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                    "KeyboardInterrupt"
                } else {
                    "exception"
                };
                stop.request_stop(reason);
                self.error = Some(e);
            }
            if let Some(cb) = progress
                && self.error.is_none()
                && self.last_report.elapsed() >= PROGRESS_EVERY
            {
                self.last_report = Instant::now();
                let total = match shared.total.load(Ordering::Relaxed) {
                    0 => None,
                    t => Some(t),
                };
                let message = shared.message.lock().ok().and_then(|m| m.clone());
                if let Err(e) = cb.call1(py, (shared.done.load(Ordering::Relaxed), total, message))
                {
                    stop.request_stop("progress callback raised");
                    self.error = Some(e);
                }
            }
        });
    }
}

/// Run `scene` on a thread of its own while this thread watches for Ctrl-C.
fn run_watched(
    scene: &Scene,
    options: &RunOptions,
    stop: &StopFlag,
    pool: Option<&rayon::ThreadPool>,
    progress: Option<&Py<PyAny>>,
) -> (Result<Value, SimError>, Option<PyErr>) {
    let shared = Shared::default();
    let mut watch = Watch {
        error: None,
        last_report: Instant::now(),
    };
    let result = std::thread::scope(|s| {
        let (tx, rx) = mpsc::channel::<()>();
        let shared = &shared;
        let work = move || {
            let r = match pool {
                Some(p) => p.install(|| run_scene(scene, options, shared)),
                None => run_scene(scene, options, shared),
            };
            let _ = tx.send(());
            r
        };
        let handle = match std::thread::Builder::new()
            .name("magsep-run".into())
            .stack_size(RUN_STACK_BYTES)
            .spawn_scoped(s, work)
        {
            Ok(h) => h,
            Err(e) => {
                return Err(SimError::Schedule(format!(
                    "cannot start the run's thread: {e}"
                )));
            }
        };
        while let Err(mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(POLL) {
            watch.poll(stop, progress, shared);
        }
        handle.join().unwrap_or_else(|_| {
            Err(SimError::Schedule(
                "internal error: the run panicked".into(),
            ))
        })
    });
    (result, watch.error)
}

/// A Python exception carrying `summary` as its `summary` attribute.
fn with_summary(py: Python<'_>, err: PyErr, summary: Option<&Value>) -> PyErr {
    let value = match summary {
        Some(s) => json_value(py, s)
            .map(Bound::unbind)
            .unwrap_or_else(|_| py.None()),
        None => py.None(),
    };
    let _ = err.value(py).setattr("summary", value);
    err
}

/// Run a scene to the end; returns its summary (see the module docs of `magsep`).
#[pyfunction]
#[pyo3(signature = (scene, overrides=None, record=None, threads=None, seed=None, progress=None, force=false, memory_budget=None))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    overrides: Option<&Bound<'py, PyAny>>,
    record: Option<PathBuf>,
    threads: Option<usize>,
    seed: Option<u64>,
    progress: Option<Py<PyAny>>,
    force: bool,
    memory_budget: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let src = source(scene)?;
    let set = self::overrides(overrides)?;
    if let Some(out) = &record {
        let mut inputs: Vec<Input> = named_inputs(&src.text)
            .into_iter()
            .map(|p| Input::new("recording named in the scene", p))
            .collect();
        if let Some(p) = &src.path {
            inputs.push(Input::new("scene", p));
        }
        check_file("record", out, &inputs, force).map_err(|e| {
            let message = e
                .message
                .strip_prefix("record ")
                .unwrap_or(&e.message)
                .to_string();
            crate::key_error(py, "record", message)
        })?;
    }
    let scene = load(py, &src, &set)?;
    check_memory(py, &scene, &src.name, memory_budget)?;
    let pool = pool(py, threads)?;
    let stop = StopFlag::new();
    let options = RunOptions {
        seed,
        record,
        single_threaded: threads == Some(1),
        stop: Some(stop.clone()),
        ..Default::default()
    };
    let progress = progress.filter(|p| !p.is_none(py));
    let (result, raised) =
        py.detach(|| run_watched(&scene, &options, &stop, pool.as_ref(), progress.as_ref()));
    let summary = match result {
        Ok(s) => s,
        Err(e) => {
            let partial = e.partial_summary().cloned();
            let err = match e.cause() {
                SimError::NothingToRun | SimError::Spawn(_) => {
                    crate::key_error(py, "(scene)", e.to_string())
                }
                _ => RunError::new_err(e.to_string()),
            };
            return Err(with_summary(py, raised.unwrap_or(err), partial.as_ref()));
        }
    };
    if let Some(e) = raised {
        let err = if e.is_instance_of::<PyKeyboardInterrupt>(py) {
            RunInterrupted::new_err(format!(
                "interrupted by KeyboardInterrupt: `summary` is of the steps that ran{}",
                if options.record.is_some() {
                    "; the recording is closed and complete"
                } else {
                    ""
                }
            ))
        } else {
            e
        };
        return Err(with_summary(py, err, Some(&summary)));
    }
    if let Some(why) = scene.pipeline.as_ref().and_then(|p| p.failure(&summary)) {
        return Err(with_summary(py, RunError::new_err(why), Some(&summary)));
    }
    json_value(py, &summary)
}
