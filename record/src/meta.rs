//! The `magsep` metadata record: [`RecordingMetadata`] as an MCAP string map and back.

use crate::{METADATA_NAME, RecordError, RecordingMetadata};
use std::collections::BTreeMap;

/// The entries of the `magsep` metadata record of `meta`: `scene_text` (verbatim), `seed`
/// (decimal), `version`, `pipeline`, `dt` (seconds, shortest round-trip decimal), `schedule`
/// (JSON object: set name -> system names), `plugins` (JSON array of `{"name", "params"}`)
/// and `extra` (JSON object of strings).
pub(crate) fn metadata_entries(
    meta: &RecordingMetadata,
) -> Result<BTreeMap<String, String>, RecordError> {
    let json = |what: &str, value: Result<String, serde_json::Error>| {
        value.map_err(|e| RecordError::InvalidInput {
            detail: format!("{what} is not serialisable as JSON: {e}"),
        })
    };
    let entries = [
        ("scene_text", meta.scene_text.clone()),
        ("seed", meta.seed.to_string()),
        ("version", meta.version.clone()),
        ("pipeline", meta.pipeline.clone()),
        ("dt", format!("{:?}", meta.dt)),
        (
            "schedule",
            json("schedule", serde_json::to_string(&meta.schedule))?,
        ),
        (
            "plugins",
            json("plugins", serde_json::to_string(&meta.plugins))?,
        ),
        ("extra", json("extra", serde_json::to_string(&meta.extra))?),
    ];
    Ok(entries
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect())
}

/// Parses the `magsep` metadata map. `plugins` and `extra` are optional (files written before
/// they existed lack them); the other keys are required.
pub(crate) fn parse_metadata(map: &BTreeMap<String, String>) -> Result<RecordingMetadata, String> {
    let get = |key: &str| {
        map.get(key)
            .ok_or_else(|| format!("metadata {METADATA_NAME:?} lacks key {key:?}"))
    };
    let bad = |key: &str, value: &str, e: &dyn std::fmt::Display| {
        let value = crate::parse::clip(value);
        format!("metadata {METADATA_NAME:?} key {key:?} has value {value:?}: {e}")
    };
    let seed = get("seed")?;
    let dt = get("dt")?;
    let schedule = get("schedule")?;
    let plugins = match map.get("plugins") {
        Some(text) => serde_json::from_str(text).map_err(|e| bad("plugins", text, &e))?,
        None => Vec::new(),
    };
    let extra = match map.get("extra") {
        Some(text) => serde_json::from_str(text).map_err(|e| bad("extra", text, &e))?,
        None => BTreeMap::new(),
    };
    Ok(RecordingMetadata {
        scene_text: get("scene_text")?.clone(),
        seed: seed.parse().map_err(|e| bad("seed", seed, &e))?,
        version: get("version")?.clone(),
        pipeline: get("pipeline")?.clone(),
        schedule: serde_json::from_str(schedule).map_err(|e| bad("schedule", schedule, &e))?,
        dt: dt.parse().map_err(|e| bad("dt", dt, &e))?,
        plugins,
        extra,
    })
}
