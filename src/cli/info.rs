//! `magsep info` and `magsep replay`.

use std::path::Path;

use crate::plugins::record::{RecordError, read_recording};
use crate::replay::{ReplayError, replay_with};
use serde_json::json;

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

pub fn info(path: &Path, as_json: bool) -> Result<(), CliError> {
    let rec = read_recording(path).map_err(|e| record_error(path, e))?;
    let channels: Vec<_> = rec
        .channels
        .iter()
        .map(|c| json!({"topic": c.topic, "schema": c.schema_name, "encoding": c.message_encoding, "messages": c.message_count}))
        .collect();
    let meta = rec.metadata.as_ref();
    let v = json!({
        "file": path.display().to_string(),
        "bytes": rec.file_bytes,
        "frames": rec.frames.len(),
        "first_step": rec.frames.first().map(|f| f.step),
        "last_step": rec.frames.last().map(|f| f.step),
        "particles": rec.frames.last().map(|f| f.ids.len()),
        "channels": channels,
        "truncated": rec.truncated,
        "complete": rec.truncated.is_none(),
        "metadata": meta.map(|m| json!({"seed": m.seed, "version": m.version, "pipeline": m.pipeline, "dt": m.dt, "schedule": m.schedule, "scene_text": m.scene_text})),
        "summary": rec.summary_json.as_deref().and_then(|s| serde_json::from_str::<serde_json::Value>(s).ok()),
    });
    if as_json {
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        return Ok(());
    }
    println!("file       {} ({} bytes)", path.display(), rec.file_bytes);
    match &rec.truncated {
        Some(t) => println!("status     TRUNCATED: {t}"),
        None => println!("status     complete"),
    }
    println!(
        "frames     {} (steps {:?}..{:?})",
        rec.frames.len(),
        rec.frames.first().map(|f| f.step),
        rec.frames.last().map(|f| f.step)
    );
    println!("channels");
    for c in &rec.channels {
        println!(
            "  {:<10} {:<24} {:<10} {} messages",
            c.topic, c.schema_name, c.message_encoding, c.message_count
        );
    }
    if let Some(m) = meta {
        println!(
            "metadata   pipeline {}  seed {}  magsep {}  dt {} s",
            m.pipeline, m.seed, m.version, m.dt
        );
        println!("schedule");
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
        for (set, systems) in sets {
            let short: Vec<String> = systems
                .iter()
                .map(|s| s.rsplit("::").next().unwrap_or(s).to_string())
                .collect();
            println!("  {set:<12} {}", short.join(", "));
        }
        println!("scene text ({} lines)", m.scene_text.lines().count());
    } else {
        println!("metadata   none");
    }
    Ok(())
}

pub fn replay(ext: &Extensions, path: &Path) -> Result<(), CliError> {
    let (summary, _) = replay_with(path, &ext.registry).map_err(|e| replay_error(path, e))?;
    println!(
        "{}",
        serde_json::to_string_pretty(&summary).unwrap_or_default()
    );
    Ok(())
}

fn replay_error(path: &Path, e: ReplayError) -> CliError {
    match e {
        ReplayError::Record(r) => record_error(path, r),
        ReplayError::Sim(e) => CliError::runtime(e.to_string()),
        other => CliError::input(format!("{}: {other}", path.display())),
    }
}

pub fn resume(
    ext: &Extensions,
    path: &Path,
    record: Option<std::path::PathBuf>,
    quiet: bool,
) -> Result<(), CliError> {
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new_spinner()
    };
    let summary = crate::replay::resume(path, &ext.registry, record, &ext.plugins, |w| {
        if let Some(c) = w.get_resource::<crate::components::clock::StepClock>()
            && c.step % 1000 == 0
        {
            bar.set_message(format!("step {}", c.step));
            bar.tick();
        }
    })
    .map_err(|e| replay_error(path, e))?;
    bar.finish_and_clear();
    println!(
        "{}",
        serde_json::to_string_pretty(&summary).unwrap_or_default()
    );
    Ok(())
}
