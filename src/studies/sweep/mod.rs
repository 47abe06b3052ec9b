//! Parameter sweeps: a sweep file names a base scene, axes of override values, replicates
//! and the summary values to collect; `magsep sweep` runs its points (in-process, in
//! parallel, resumable), `--shard I/N` one shard of them, `magsep sweep merge` builds the
//! results table and charts from whatever is finished, and `magsep sweep slurm` writes a
//! Slurm job array that runs the shards on a cluster. The format is in README.md
//! ("Studies").
//!
//! A sweep directory holds `sweep.json` (the manifest: the sweep file's and base scene's
//! text), `points/<index>/` (`point.json`, `summary.json`, `error.json` if it failed,
//! `recording.mcap` with `--record`), `results.csv` and `charts/*.svg`.

pub mod chart;
pub mod curves;
pub mod file;
pub mod run;
pub mod slurm;
pub mod table;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use indicatif::ProgressBar;
use magsep_plugins::app::SimPlugin;
use serde_json::{Value, json};

use crate::scene::Registry;
pub use file::{Axis, Point, Sweep};
use run::{MANIFEST, Runner, check_points, open_dir, outcome, shard_points, write_atomic};

/// A sweep failure: bad input (exit 2) or a runtime failure (exit 1).
#[derive(Debug)]
pub enum SweepError {
    /// Bad input.
    Input(String),
    /// Runtime failure.
    Runtime(String),
}

/// The options of a sweep run.
pub struct SweepRun {
    /// The sweep file.
    pub sweep: PathBuf,
    /// The sweep directory.
    pub out: PathBuf,
    /// Points run at once.
    pub jobs: usize,
    /// Write each point's recording.
    pub record: bool,
    /// Run only shard I of N (1-based): the points with index % N == I - 1.
    pub shard: Option<(usize, usize)>,
    /// Run failed points again (a finished point is otherwise never redone).
    pub retry_failed: bool,
    /// Memory budget \[bytes\] of the points running at once.
    pub memory_budget: u64,
    /// Stop gracefully when set (the CLI sets it on SIGINT / SIGTERM): see [`Runner::stop`].
    pub stop: Option<crate::sim::StopFlag>,
}

/// Load and validate `path` (the sweep file): bad input at its key path.
///
/// # Errors
/// [`SweepError::Input`] naming the file.
pub fn load(path: &Path) -> Result<Sweep, SweepError> {
    Sweep::load(path).map_err(|e| SweepError::Input(format!("{} is invalid:\n{e}", path.display())))
}

/// Load the sweep and validate every point's scene (all of them, also when sharded, so a
/// bad axis value fails every shard up front).
///
/// # Errors
/// [`SweepError::Input`] with the failing points and key paths.
pub fn load_checked(
    path: &Path,
    registry: &Registry,
) -> Result<(Sweep, Vec<run::PointMemory>), SweepError> {
    let sweep = load(path)?;
    let all: Vec<usize> = (0..sweep.len()).collect();
    let memory = check_points(&sweep, registry, &all).map_err(|e| {
        // an axis's own fault (a path naming no key) is the sweep file's, not a point's
        let what = if e.starts_with("axes[") {
            ""
        } else {
            " a point's scene does not validate:"
        };
        SweepError::Input(format!("{} is invalid:{what}\n{e}", path.display()))
    })?;
    Ok((sweep, memory))
}

/// The files of `out` a sweep writes, which must not be its inputs.
fn check_inputs(sweep_path: &Path, sweep: &Sweep, out: &Path) -> Result<(), SweepError> {
    let written = |p: &Path| -> bool {
        let (Ok(p), Ok(o)) = (p.canonicalize(), out.canonicalize()) else {
            return false;
        };
        let Ok(rel) = p.strip_prefix(&o) else {
            return false;
        };
        let first = rel.components().next().map(|c| c.as_os_str().to_owned());
        let first = first.as_ref().and_then(|c| c.to_str()).unwrap_or("");
        [
            MANIFEST,
            "results.csv",
            "points",
            "charts",
            "slurm",
            "sweep.sbatch",
            "merge.sbatch",
            "submit.sh",
        ]
        .contains(&first)
    };
    for (what, p) in [("sweep file", sweep_path), ("scene", &sweep.scene_path)] {
        if written(p) {
            return Err(SweepError::Input(format!(
                "--out {}: the sweep would overwrite its {what} {}",
                out.display(),
                p.display()
            )));
        }
    }
    Ok(())
}

/// Run a sweep (or one shard of it); `bar` shows the points. Unsharded, the results table
/// and charts are written at the end; a shard leaves them to `magsep sweep merge`.
///
/// # Errors
/// Bad input (the sweep, a point's scene, another sweep in `out`) or an I/O failure of the
/// sweep directory. A point's own failure is recorded as its error, not returned.
pub fn run_sweep(
    args: &SweepRun,
    registry: &Registry,
    plugins: Vec<Arc<dyn SimPlugin>>,
    bar: &ProgressBar,
) -> Result<Value, SweepError> {
    let started = Instant::now();
    let (sweep, memory) = load_checked(&args.sweep, registry)?;
    check_inputs(&args.sweep, &sweep, &args.out)?;
    open_dir(&sweep, &args.out).map_err(|(input, m)| {
        if input {
            SweepError::Input(m)
        } else {
            SweepError::Runtime(m)
        }
    })?;
    let mine = shard_points(sweep.len(), args.shard);
    let todo: Vec<usize> = (mine.iter().copied())
        .filter(|&i| match outcome(&args.out, i) {
            run::Outcome::Missing => true,
            run::Outcome::Failed { .. } if args.retry_failed => {
                std::fs::remove_dir_all(run::point_dir(&args.out, i)).is_ok()
            }
            _ => false,
        })
        .collect();
    let (jobs, largest) =
        run::jobs_within_budget(&sweep, &memory, &todo, args.jobs, args.memory_budget).map_err(
            |e| {
                SweepError::Input(format!(
                    "{}: a point's scene needs more memory than the budget:\n{e}",
                    args.sweep.display()
                ))
            },
        )?;
    bar.set_length(mine.len() as u64);
    bar.set_position((mine.len() - todo.len()) as u64);
    let runner = Runner {
        sweep: &sweep,
        registry,
        plugins,
        out: &args.out,
        record: args.record,
        stop: args.stop.clone(),
    };
    let ran = runner
        .run_all(&todo, jobs, &|| bar.inc(1))
        .map_err(SweepError::Runtime)?;
    bar.finish_and_clear();
    let stopped_by = (args.stop.as_ref()).and_then(crate::sim::StopFlag::reason);
    let seconds = started.elapsed().as_secs_f64();
    let mut out = json!({
        "sweep": args.sweep.display().to_string(),
        "out": args.out.display().to_string(),
        "points": sweep.len(),
        "shard": args.shard.map(|(i, n)| format!("{i}/{n}")),
        "shard_points": mine.len(),
        "ran": ran.finished,
        "skipped": mine.len() - todo.len(),
        "failed_now": ran.failed,
        "jobs": jobs,
        "jobs_limited_by_memory": jobs < args.jobs.min(todo.len()),
        "largest_point_memory_estimate_bytes": largest.round() as u64,
        "memory_budget_bytes": args.memory_budget,
        "wall_time_s": seconds,
        "points_per_second": ran.finished as f64 / seconds.max(1e-9),
    });
    if let Some(reason) = stopped_by {
        // no table: the same command finishes the sweep; `merge` tabulates what is done
        out["interrupted"] = json!(true);
        out["interrupted_by"] = json!(reason);
        out["unfinished"] = json!(todo.len() - ran.finished);
        out["resume"] = json!(format!(
            "run the same command again to finish the {} unfinished points \
             (`magsep sweep merge {}` tabulates the finished ones)",
            todo.len() - ran.finished,
            args.out.display()
        ));
    } else if args.shard.is_none() {
        let results = finish(&sweep, &args.out)?;
        if let (Value::Object(a), Value::Object(b)) = (&mut out, results) {
            a.extend(b);
        }
    } else {
        out["merge"] = json!(format!(
            "magsep sweep merge {} (after every shard)",
            args.out.display()
        ));
    }
    Ok(out)
}

/// Write `results.csv` and the charts of `sweep` from the points finished in `out`.
///
/// # Errors
/// An I/O failure.
pub fn finish(sweep: &Sweep, out: &Path) -> Result<Value, SweepError> {
    let outcomes = run::outcomes(sweep, out);
    let rows = table::gather(sweep, &outcomes);
    let csv = table::csv_text(sweep, &rows).map_err(SweepError::Runtime)?;
    let results = out.join("results.csv");
    write_atomic(&results, &csv).map_err(SweepError::Runtime)?;
    let charts =
        chart::write_charts(sweep, &rows, &out.join("charts")).map_err(SweepError::Runtime)?;
    let (curve_files, left_out) =
        curves::write_curves(sweep, &outcomes, out).map_err(SweepError::Runtime)?;
    let (ok, error, missing) = table::counts(&rows);
    let absent: serde_json::Map<String, Value> = table::absent_values(sweep, &rows)
        .into_iter()
        .map(|(k, n)| (k, json!(n)))
        .collect();
    Ok(json!({
        "results": results.display().to_string(),
        "charts": charts.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "ok": ok,
        "failed": error,
        "missing": missing,
        "collected_values_absent": absent,
        "curves": curve_files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "curve_points_left_out": left_out
            .into_iter()
            .map(|(k, n)| (k, json!(n)))
            .collect::<serde_json::Map<String, Value>>(),
    }))
}

/// `magsep sweep merge DIR`: the results table and charts from the points finished so far.
///
/// # Errors
/// Bad input when `out` is no sweep directory; an I/O failure.
pub fn merge(out: &Path) -> Result<Value, SweepError> {
    let path = out.join(MANIFEST);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        SweepError::Input(format!(
            "{} is not a sweep directory (cannot read {}: {e})",
            out.display(),
            path.display()
        ))
    })?;
    let m: Value = serde_json::from_str(&text)
        .map_err(|e| SweepError::Input(format!("{}: not a sweep manifest: {e}", path.display())))?;
    let field = |k: &str| {
        m[k].as_str().map(str::to_string).ok_or_else(|| {
            SweepError::Input(format!("{}: not a sweep manifest (no {k})", path.display()))
        })
    };
    let sweep = Sweep::from_texts(
        &field("sweep_text")?,
        PathBuf::from(field("scene_path")?),
        field("scene_text")?,
    )
    .map_err(|e| SweepError::Input(format!("{}: the sweep is invalid:\n{e}", path.display())))?;
    let mut result = finish(&sweep, out)?;
    result["points"] = json!(sweep.len());
    Ok(result)
}

/// `magsep sweep slurm`: validate the sweep and every point, create `out` with its manifest,
/// and write `sweep.sbatch`, `merge.sbatch` and `submit.sh` there; `exe` is the magsep binary
/// the tasks run.
///
/// # Errors
/// Bad input (the sweep, the options) or an I/O failure.
pub fn write_slurm(
    sweep_path: &Path,
    out: &Path,
    exe: &Path,
    options: &slurm::SlurmOptions,
    registry: &Registry,
) -> Result<Value, SweepError> {
    if options.shards == 0 || options.cpus_per_task == 0 {
        return Err(SweepError::Input(
            "--shards and --cpus-per-task must be at least 1".into(),
        ));
    }
    for (flag, v) in [
        ("--partition", &options.partition),
        ("--time", &options.time),
    ] {
        if let Some(v) = v {
            slurm::check_word(flag, v).map_err(SweepError::Input)?;
        }
    }
    let (sweep, _) = load_checked(sweep_path, registry)?;
    check_inputs(sweep_path, &sweep, out)?;
    let abs = |p: &Path| {
        std::path::absolute(p).map_err(|e| SweepError::Runtime(format!("{}: {e}", p.display())))
    };
    let (sweep_abs, out_abs) = (abs(sweep_path)?, abs(out)?);
    open_dir(&sweep, out).map_err(|(input, m)| {
        if input {
            SweepError::Input(m)
        } else {
            SweepError::Runtime(m)
        }
    })?;
    std::fs::create_dir_all(out.join("slurm"))
        .map_err(|e| SweepError::Runtime(format!("{}: {e}", out.display())))?;
    let files = [
        (
            "sweep.sbatch",
            slurm::array_script(exe, &sweep_abs, &out_abs, options),
        ),
        ("merge.sbatch", slurm::merge_script(exe, &out_abs, options)),
        ("submit.sh", slurm::submit_script(&out_abs)),
    ];
    for (name, text) in &files {
        write_atomic(&out.join(name), text).map_err(SweepError::Runtime)?;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(out.join("submit.sh"), PermissionsExt::from_mode(0o755));
    }
    let points = sweep.len();
    Ok(json!({
        "sweep": sweep_abs.display().to_string(),
        "out": out_abs.display().to_string(),
        "points": points,
        "shards": options.shards,
        "points_per_shard": points.div_ceil(options.shards),
        "array": out_abs.join("sweep.sbatch").display().to_string(),
        "merge": out_abs.join("merge.sbatch").display().to_string(),
        "submit": format!(
            "jid=$(sbatch --parsable {}) && sbatch --dependency=afterany:${{jid%%;*}} {}  \
             (or run {})",
            slurm::shell_quote(&out_abs.join("sweep.sbatch").display().to_string()),
            slurm::shell_quote(&out_abs.join("merge.sbatch").display().to_string()),
            slurm::shell_quote(&out_abs.join("submit.sh").display().to_string()),
        ),
    }))
}
