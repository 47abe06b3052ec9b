//! Typed parsing and value checks shared by every scene section: each failure becomes a
//! [`SceneError`] at its innermost key path.

use serde::de::DeserializeOwned;

use super::SceneError;

/// Line and column (1-based) of byte `offset` in `text`.
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

/// Deserialize `value` as `T`; a failure becomes an error at `path` + the inner path.
pub fn typed<T: DeserializeOwned>(
    value: &toml::Value,
    path: &str,
    errors: &mut Vec<SceneError>,
) -> Option<T> {
    match serde_path_to_error::deserialize::<_, T>(value.clone()) {
        Ok(v) => Some(v),
        Err(e) => {
            let inner = e.path().to_string();
            let full = match (path.is_empty(), inner.as_str()) {
                (_, ".") => path.to_string(),
                (true, i) => i.to_string(),
                (false, i) if i.starts_with('[') => format!("{path}{i}"),
                (false, i) => format!("{path}.{i}"),
            };
            let raw = e.into_inner().to_string();
            // toml appends context lines ("in `shape`"); the key path already says where
            let mut message = raw.lines().next().unwrap_or("").trim().to_string();
            // name the key of an unknown or missing field in the path, as users look for it
            let mut full = full;
            for (prefix, unknown) in [("unknown field `", true), ("missing field `", false)] {
                let Some(rest) = message.strip_prefix(prefix) else {
                    continue;
                };
                let Some(end) = rest.find('`') else { continue };
                let key = &rest[..end];
                if !(full == key || full.ends_with(&format!(".{key}"))) {
                    full = if full.is_empty() {
                        key.to_string()
                    } else {
                        format!("{full}.{key}")
                    };
                }
                message = if unknown {
                    format!(
                        "unknown key; {}",
                        rest[end + 1..].trim_start_matches(',').trim()
                    )
                } else {
                    "missing required key".into()
                };
                break;
            }
            errors.push(SceneError::new(full, message));
            None
        }
    }
}

/// An array of tables (`[[key]]`): each entry typed with its index in the path; entries with
/// errors are left out (their errors are pushed).
pub fn typed_array<T: DeserializeOwned>(
    value: &toml::Value,
    key: &str,
    errors: &mut Vec<SceneError>,
) -> Vec<(usize, T)> {
    match value {
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .filter_map(|(i, item)| {
                typed::<T>(item, &format!("{key}[{i}]"), errors).map(|t| (i, t))
            })
            .collect(),
        other => {
            errors.push(SceneError::new(
                key,
                format!(
                    "must be an array of tables ([[{key}]]), got a {}",
                    other.type_str()
                ),
            ));
            Vec::new()
        }
    }
}

/// An error at `path` (with the message made by `message`) unless `ok`.
pub fn check(errors: &mut Vec<SceneError>, ok: bool, path: &str, message: impl FnOnce() -> String) {
    if !ok {
        errors.push(SceneError::new(path, message()));
    }
}

/// An error at `path` unless `v` is finite and > 0.
pub fn finite_positive(errors: &mut Vec<SceneError>, path: &str, v: f64) {
    check(errors, v.is_finite() && v > 0.0, path, || {
        format!("must be a finite number > 0, got {v}")
    });
}

/// An error at `path` unless `v` is finite and in (`lo_open`, `hi`].
pub fn in_range(errors: &mut Vec<SceneError>, path: &str, v: f64, lo_open: f64, hi: f64) {
    check(
        errors,
        v.is_finite() && v > lo_open && v <= hi,
        path,
        || format!("must be in ({lo_open}, {hi}], got {v}"),
    );
}

/// Largest shape exponent accepted (the contact solver is validated up to 10; above 20 the
/// powers lose too many digits).
pub const MAX_EXPONENT: f64 = 20.0;

/// Check a superquadric exponent.
pub fn exponent_in_range(errors: &mut Vec<SceneError>, path: &str, g: f64) {
    check(
        errors,
        g.is_finite() && (2.0..=MAX_EXPONENT).contains(&g),
        path,
        || format!("must be in [2, {MAX_EXPONENT}] (strictly convex shapes), got {g}"),
    );
}
