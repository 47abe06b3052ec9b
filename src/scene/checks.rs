//! Typed parsing and value checks shared by every scene section: each failure becomes a
//! [`SceneError`] at its innermost key path.

use serde::Serialize;
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
///
/// Two gaps of serde are closed here, so every error names its innermost key:
/// * a key that `T` does not read is an error even where serde ignores it (the variants
///   without fields of an internally tagged enum, `flow = { kind = "quiescent", bogus = 1 }`):
///   `T` is serialized back and every input key missing from the result is reported;
/// * an invalid value inside a tagged table (which serde buffers, losing the path) is looked
///   up in the table by its type and value.
pub fn typed<T: DeserializeOwned + Serialize>(
    value: &toml::Value,
    path: &str,
    errors: &mut Vec<SceneError>,
) -> Option<T> {
    match serde_path_to_error::deserialize::<_, T>(value.clone()) {
        Ok(v) => {
            let before = errors.len();
            if let Ok(back) = toml::Value::try_from(&v) {
                unread_keys(value, &back, path, errors);
            }
            (errors.len() == before).then_some(v)
        }
        Err(e) => {
            let segments: Vec<String> = e.path().iter().map(|s| s.to_string()).collect();
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
            if let Some(at) = value_at(value, &segments)
                && let Some(key) = culprit(at, &message)
            {
                full = join(&full, &key);
            }
            errors.push(SceneError::new(full, message));
            None
        }
    }
}

fn join(path: &str, key: &str) -> String {
    match (path.is_empty(), key.starts_with('[')) {
        (true, _) => key.to_string(),
        (false, true) => format!("{path}{key}"),
        (false, false) => format!("{path}.{key}"),
    }
}

/// The value at serde_path_to_error's segments (`key`, `[i]`) below `value`.
fn value_at<'a>(value: &'a toml::Value, segments: &[String]) -> Option<&'a toml::Value> {
    let mut v = value;
    for s in segments {
        v = match s.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            Some(i) => v.as_array()?.get(i.parse::<usize>().ok()?)?,
            None if s == "?" => return None,
            None => v.as_table()?.get(s)?,
        };
    }
    Some(v)
}

/// Inside the table or array `at`, where serde could not say, the key of the value an
/// `invalid type`/`invalid value`/`unknown variant` message is about (when it is unique).
fn culprit(at: &toml::Value, message: &str) -> Option<String> {
    if let Some(rest) = message.strip_prefix("unknown variant `") {
        // the string key that holds the variant's name (e.g. `around_fibres = "stokes"`
        // beside a good `kind`), else `kind`
        let name = rest.split('`').next().unwrap_or("");
        let mut hits = Vec::new();
        leaves(at, String::new(), &mut |key, v| {
            if v.as_str() == Some(name) {
                hits.push(key.to_string());
            }
        });
        if let [one] = hits.as_slice() {
            return Some(one.clone());
        }
        return at.as_table()?.contains_key("kind").then(|| "kind".into());
    }
    let what = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))?;
    let what = what.split(", expected").next().unwrap_or(what);
    let (kind, text) = what.split_once(' ').unwrap_or((what, ""));
    let text = text.trim_matches(|c| c == '`' || c == '"');
    let mut hits = Vec::new();
    leaves(at, String::new(), &mut |key, v| {
        let same_type = matches!(
            (kind, v),
            ("string", toml::Value::String(_))
                | ("integer", toml::Value::Integer(_))
                | ("floating", toml::Value::Float(_))
                | ("boolean", toml::Value::Boolean(_))
                | ("sequence", toml::Value::Array(_))
                | ("map", toml::Value::Table(_))
        );
        if same_type && key != "kind" {
            let shown = match v {
                toml::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            hits.push((key.to_string(), !text.is_empty() && shown == text));
        }
    });
    let exact: Vec<&String> = hits.iter().filter(|h| h.1).map(|h| &h.0).collect();
    match (exact.as_slice(), hits.as_slice()) {
        ([one], _) => Some((*one).clone()),
        (_, [(one, _)]) => Some(one.clone()),
        _ => None,
    }
}

/// Every value below `v` (tables and arrays too), with its relative key path.
fn leaves(v: &toml::Value, path: String, f: &mut dyn FnMut(&str, &toml::Value)) {
    let children: Vec<(String, &toml::Value)> = match v {
        toml::Value::Table(t) => t.iter().map(|(k, c)| (join(&path, k), c)).collect(),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, c)| (join(&path, &format!("[{i}]")), c))
            .collect(),
        _ => return,
    };
    for (p, c) in children {
        f(&p, c);
        leaves(c, p, f);
    }
}

/// Keys of `input` that the typed value `back` (serialized again) does not hold: keys serde
/// read past without a word.
fn unread_keys(input: &toml::Value, back: &toml::Value, path: &str, errors: &mut Vec<SceneError>) {
    match (input, back) {
        (toml::Value::Table(i), toml::Value::Table(b)) => {
            for (k, v) in i {
                match b.get(k) {
                    Some(bv) => unread_keys(v, bv, &join(path, k), errors),
                    None => {
                        let message = match b.get("kind").and_then(|k| k.as_str()) {
                            Some(kind) => {
                                let keys: Vec<&str> = b
                                    .keys()
                                    .map(String::as_str)
                                    .filter(|k| *k != "kind")
                                    .collect();
                                if keys.is_empty() {
                                    format!("unknown key: kind = \"{kind}\" takes no other key")
                                } else {
                                    format!(
                                        "unknown key for kind = \"{kind}\" (given and read: {})",
                                        keys.join(", ")
                                    )
                                }
                            }
                            None => "unknown key".to_string(),
                        };
                        errors.push(SceneError::new(join(path, k), message));
                    }
                }
            }
        }
        (toml::Value::Array(i), toml::Value::Array(b)) if i.len() == b.len() => {
            for (k, (iv, bv)) in i.iter().zip(b).enumerate() {
                unread_keys(iv, bv, &join(path, &format!("[{k}]")), errors);
            }
        }
        _ => {}
    }
}

/// An array of tables (`[[key]]`): each entry typed with its index in the path; entries with
/// errors are left out (their errors are pushed).
pub fn typed_array<T: DeserializeOwned + Serialize>(
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
        format!("must be a finite number > 0, got {}", num(v))
    });
}

/// An error at `path` unless `v` is finite and in (`lo_open`, `hi`].
pub fn in_range(errors: &mut Vec<SceneError>, path: &str, v: f64, lo_open: f64, hi: f64) {
    check(
        errors,
        v.is_finite() && v > lo_open && v <= hi,
        path,
        || format!("must be in ({}, {}], got {}", num(lo_open), num(hi), num(v)),
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
        || {
            format!(
                "must be in [2, {MAX_EXPONENT}] (strictly convex shapes), got {}",
                num(g)
            )
        },
    );
}

/// An error at `path` unless `v` is finite and in [`lo`, `hi`] (`unit` in brackets, e.g.
/// `"[m]"`, is named in the message).
pub fn within(errors: &mut Vec<SceneError>, path: &str, v: f64, lo: f64, hi: f64, unit: &str) {
    check(errors, v.is_finite() && v >= lo && v <= hi, path, || {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        format!(
            "must be in [{}, {}]{unit}, got {}",
            num(lo),
            num(hi),
            num(v)
        )
    });
}

/// A derived number for a message, to 4 significant digits: plain between 1e-3 and 1e6,
/// scientific outside (a value the user wrote is shown as written, with [`num`]).
pub fn num4(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let rounded: f64 = format!("{v:.3e}").parse().unwrap_or(v);
    num(rounded)
}

/// A number for a message: plain between 1e-3 and 1e6, scientific outside.
pub fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Viscosities a scene may give \[Pa s\] (a gas to a stiff paste), every pipeline.
pub const VISCOSITY_RANGE: (f64, f64) = (1e-6, 1e4);

/// Lengths a scene may give \[m\]: particle sizes, regions, containers (every pipeline).
pub const LENGTH_RANGE: (f64, f64) = (1e-10, 1e3);

/// Largest ratio of the largest to the smallest length of one particle, or of the largest to
/// the smallest particle of a scene: beyond it the contact searches and time steps, sized
/// by the smallest length, would take practically forever (a rod of aspect 10^12 never
/// finishes packing).
pub const MAX_SIZE_RATIO: f64 = 100.0;
