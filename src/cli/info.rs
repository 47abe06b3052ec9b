//! `magsep info` and `magsep replay`.

use std::path::Path;

use crate::input::named_inputs;
use crate::names::short_name;
use crate::plugins::record::{
    ChannelInfo, ReadMode, ReaderLimits, RecordError, RecordingMetadata, RecordingReader,
    trailing_message,
};
use crate::replay::{ReplayError, replay_with};
use crate::scene::{Registry, parse_scene};
use serde_json::json;

use super::output::{Input, check_file, eprint, print};
use super::{CliError, Extensions};

fn record_error(path: &Path, e: RecordError) -> CliError {
    match e {
        RecordError::Io { .. } => CliError::input(format!("{}: {e}", path.display())),
        other => CliError::input(format!(
            "{} is not a readable recording: {other}",
            path.display()
        )),
    }
}

/// What `info` reports of a recording, read as a stream (one chunk and one frame in memory).
struct Scan {
    frames: u64,
    first_step: Option<u64>,
    last_step: Option<u64>,
    particles: Option<usize>,
    truncated: Option<String>,
    damaged: Option<String>,
    trailing_bytes: u64,
    channels: Vec<ChannelInfo>,
    metadata: Option<RecordingMetadata>,
    summary_json: Option<String>,
    file_bytes: u64,
    /// Why the run was stopped early (record `magsep.interrupted`), if it was.
    interrupted: Option<String>,
}

/// Reads the recording at `path` linearly, checking every CRC; frames are decoded and
/// counted, not kept. Fails (bad input) when the file cannot be opened as a recording at all
/// (no MCAP magic, unreadable); damage further on is reported in the scan.
fn scan(path: &Path) -> Result<Scan, CliError> {
    let mut reader = RecordingReader::open_with(path, ReadMode::Linear, ReaderLimits::default())
        .map_err(|e| record_error(path, e))?;
    let (mut frames, mut first_step, mut last_step, mut particles) = (0u64, None, None, None);
    let mut failure = None;
    for frame in reader.frames() {
        match frame {
            Ok(f) => {
                frames += 1;
                first_step.get_or_insert(f.step);
                last_step = Some(f.step);
                particles = Some(f.ids.len());
            }
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    let trailing = reader.trailing_bytes();
    let (truncated, damaged) = match failure {
        // damage before the first frame: the header, metadata and channels read before it
        // are still printed (and the exit code says damaged)
        Some(e) => crate::plugins::record::damage_messages(&e, frames),
        None => (
            reader.truncated().map(str::to_string),
            trailing.map(|(at, n)| trailing_message(at, n)),
        ),
    };
    Ok(Scan {
        frames,
        first_step,
        last_step,
        particles,
        truncated,
        damaged,
        trailing_bytes: trailing.map_or(0, |t| t.1),
        channels: reader.channels(),
        metadata: reader.metadata().cloned(),
        summary_json: reader.summary_json().map(str::to_string),
        file_bytes: reader.file_bytes(),
        interrupted: reader
            .metadata_records()
            .iter()
            .find(|m| m.name == crate::plugins::record::INTERRUPTED_METADATA_NAME)
            .and_then(|m| m.entries.get("reason").cloned()),
    })
}

/// `magsep info`: prints what can be read; exit 0 for a complete or a truncated file (a run
/// that was killed), 2 for a damaged one (a corrupt record, bytes after the footer) after
/// printing what could be read.
pub fn info(path: &Path, as_json: bool, registry: &Registry) -> Result<(), CliError> {
    let rec = scan(path)?;
    // the memory the recorded scene needs to run again (when this program can parse it)
    let memory = rec
        .metadata
        .as_ref()
        .and_then(|m| parse_scene(&m.scene_text, registry).ok())
        .map(|scene| crate::scene::memory::estimate(&scene));
    let damaged = || match &rec.damaged {
        Some(d) => Err(CliError::input(format!(
            "{} is damaged: {d}",
            path.display()
        ))),
        None => Ok(()),
    };
    let channels: Vec<_> = rec
        .channels
        .iter()
        .map(|c| json!({"topic": c.topic, "schema": c.schema_name, "encoding": c.message_encoding, "messages": c.message_count}))
        .collect();
    let meta = rec.metadata.as_ref();
    if as_json {
        let v = json!({
            "file": path.display().to_string(),
            "bytes": rec.file_bytes,
            "frames": rec.frames,
            "first_step": rec.first_step,
            "last_step": rec.last_step,
            "particles": rec.particles,
            "channels": channels,
            "truncated": rec.truncated,
            "damaged": rec.damaged,
            "trailing_bytes": rec.trailing_bytes,
            "complete": rec.truncated.is_none() && rec.damaged.is_none(),
            "interrupted": rec.interrupted,
            "memory_estimate_bytes": memory.as_ref().map(|m| m.bytes.round() as u64),
            "metadata": meta.map(|m| json!({"seed": m.seed, "version": m.version, "pipeline": m.pipeline, "dt": m.dt, "schedule": m.schedule, "scene_text": m.scene_text, "overrides": crate::replay::recorded_overrides(m)})),
            "summary": rec.summary_json.as_deref().and_then(|s| serde_json::from_str::<serde_json::Value>(s).ok()),
        });
        print(serde_json::to_string_pretty(&v).unwrap_or_default())?;
        return damaged();
    }
    let mut out = String::new();
    let mut line = |text: String| {
        out.push_str(&text);
        out.push('\n');
    };
    line(format!(
        "file       {} ({} bytes)",
        path.display(),
        rec.file_bytes
    ));
    match (&rec.damaged, &rec.truncated) {
        (Some(d), _) => line(format!("status     DAMAGED: {d}")),
        (None, Some(t)) => line(format!("status     TRUNCATED: {t}")),
        (None, None) => line("status     complete".into()),
    }
    if let Some(why) = &rec.interrupted {
        line(format!(
            "interrupted by {why}: the run was stopped before its end"
        ));
    }
    match (rec.first_step, rec.last_step) {
        (Some(a), Some(b)) => line(format!("frames     {} (steps {a}..{b})", rec.frames)),
        _ => line(format!("frames     {}", rec.frames)),
    }
    line("channels".into());
    for c in &rec.channels {
        line(format!(
            "  {:<10} {:<24} {:<10} {} messages",
            c.topic, c.schema_name, c.message_encoding, c.message_count
        ));
    }
    match meta {
        Some(m) => {
            line(format!(
                "metadata   pipeline {}  seed {}  magsep {}  dt {} s",
                m.pipeline, m.seed, m.version, m.dt
            ));
            line("schedule".into());
            for l in schedule_lines(m) {
                line(l);
            }
            line(format!(
                "scene text ({} lines)",
                m.scene_text.lines().count()
            ));
            let overrides = crate::replay::recorded_overrides(m);
            if !overrides.is_empty() {
                line(format!("overrides  {}", overrides.join(" ")));
            }
            if let Some(e) = &memory {
                line(format!(
                    "memory     about {} to run the scene ({})",
                    crate::scene::memory::gib(e.bytes),
                    e.detail
                ));
            }
        }
        None => line("metadata   none".into()),
    }
    print(out.trim_end())?;
    damaged()
}

/// The recorded schedule, one line per set in run order, system names shortened.
fn schedule_lines(m: &RecordingMetadata) -> Vec<String> {
    let order = [
        "Prepare",
        "Field",
        "Dipole",
        "Contact",
        "Wall",
        "Fluid",
        "Custom",
        "Accumulate",
        "Mobility",
        "Integrate",
        "Constraints",
        "Settle",
        "WriteBack",
        "Flags",
        "Clock",
        "Observe",
        "Record",
    ];
    let rank = |s: &str| {
        order
            .iter()
            .position(|o| s.starts_with(o))
            .unwrap_or(order.len())
    };
    let mut sets: Vec<_> = m.schedule.iter().collect();
    sets.sort_by_key(|(s, _)| (rank(s), s.to_string()));
    // one column for the names, as wide as the longest set name
    let width = sets
        .iter()
        .map(|(s, _)| s.chars().count())
        .max()
        .unwrap_or(0);
    sets.into_iter()
        .map(|(set, systems)| {
            let short: Vec<String> = systems.iter().map(|s| short_name(s)).collect();
            format!("  {set:<width$} {}", short.join(", "))
        })
        .collect()
}

/// `magsep replay`: the summary of the recording's complete frames; a damaged file is
/// replayed up to the damage, with a warning on stderr.
pub fn replay(ext: &Extensions, path: &Path) -> Result<(), CliError> {
    let (summary, rec) = replay_with(path, &ext.registry).map_err(|e| replay_error(path, e))?;
    if let Some(d) = &rec.damaged {
        eprint(format!(
            "warning: {} is damaged: {d}; replayed its {} complete frame{}",
            path.display(),
            rec.frames.len(),
            if rec.frames.len() == 1 { "" } else { "s" }
        ));
    }
    print(serde_json::to_string_pretty(&summary).unwrap_or_default())
}

fn replay_error(path: &Path, e: ReplayError) -> CliError {
    match e {
        ReplayError::Record(r) => record_error(path, r),
        ReplayError::Sim(e) => CliError::runtime(e.to_string()),
        other => CliError::input(format!("{}: {other}", path.display())),
    }
}

/// `magsep replay --resume`: `--record` is checked first against the recording and the files
/// its scene names; the consistency of scene and frame is checked by [`crate::replay::resume`]
/// before the particles are spawned.
pub fn resume(
    ext: &Extensions,
    path: &Path,
    record: Option<std::path::PathBuf>,
    quiet: bool,
    force: bool,
) -> Result<(), CliError> {
    if let Some(out) = &record {
        let mut inputs = vec![Input::new("recording being resumed", path)];
        // the summary section (or a scan) gives the recorded scene without reading frames
        if let Ok(reader) = RecordingReader::open(path)
            && let Some(m) = reader.metadata()
        {
            inputs.extend(
                named_inputs(&m.scene_text)
                    .into_iter()
                    .map(|p| Input::new("recording named in the recorded scene", p)),
            );
        }
        check_file("--record", out, &inputs, force)?;
    }
    let progress = super::progress::StderrProgress::new(quiet, "steps");
    let summary = crate::replay::resume(path, &ext.registry, record, &ext.plugins, &progress)
        .map_err(|e| replay_error(path, e));
    drop(progress);
    let summary = summary?;
    print(serde_json::to_string_pretty(&summary).unwrap_or_default())
}
