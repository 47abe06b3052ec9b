//! Python values to TOML (scenes and overrides given as dicts), JSON to Python values.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::Value;

/// Deepest nesting of a scene given as Python values (a scene is a few levels deep).
const MAX_DEPTH: usize = 64;

/// `key` appended to the key path `path` (`a.b`, `a[3]`).
fn child(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The TOML value of `obj` (found at key path `path`): dicts become tables (string keys),
/// lists, tuples and numpy arrays become arrays, bools, ints, floats (numpy scalars too) and
/// strings stay what they are.
///
/// # Errors
/// A [`crate::SceneError`] naming `path` for anything else (None, objects, non-string keys,
/// integers beyond 64 bits).
pub fn to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    to_toml_at(obj, path, 0)
}

fn to_toml_at(obj: &Bound<'_, PyAny>, path: &str, depth: usize) -> PyResult<Value> {
    let py = obj.py();
    let bad =
        |what: String| crate::key_error(py, if path.is_empty() { "(scene)" } else { path }, what);
    if depth > MAX_DEPTH {
        return Err(bad(format!("nested more than {MAX_DEPTH} levels deep")));
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj.extract::<i64>().map(Value::Integer).map_err(|_| {
            bad(format!(
                "integer {} does not fit in 64 bits",
                obj.str().map(|s| s.to_string()).unwrap_or_default()
            ))
        });
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract()?));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_str()?.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let Ok(key) = k.cast::<PyString>() else {
                return Err(bad(format!("keys must be strings, got {}", type_name(&k))));
            };
            let key = key.to_str()?.to_string();
            let value = to_toml_at(&v, &child(path, &key), depth + 1)?;
            table.insert(key, value);
        }
        return Ok(Value::Table(table));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() || is_ndarray(obj) {
        let mut items = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            items.push(to_toml_at(&v?, &format!("{path}[{i}]"), depth + 1)?);
        }
        return Ok(Value::Array(items));
    }
    // numpy scalars (float64, int64, bool_) and other number-likes
    if let Some(v) = numpy_scalar(obj)? {
        return Ok(v);
    }
    Err(bad(format!(
        "expected a number, string, bool, list or dict, got {}",
        type_name(obj)
    )))
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "an object".into())
}

fn is_ndarray(obj: &Bound<'_, PyAny>) -> bool {
    type_name(obj) == "ndarray"
}

/// A numpy scalar (`numpy.float64`, `numpy.int32`, `numpy.bool_`) as a TOML value.
fn numpy_scalar(obj: &Bound<'_, PyAny>) -> PyResult<Option<Value>> {
    let module = obj
        .get_type()
        .module()
        .map(|m| m.to_string())
        .unwrap_or_default();
    if module != "numpy" {
        return Ok(None);
    }
    let item = obj.call_method0("item")?;
    if item.is_instance_of::<PyBool>() {
        return Ok(Some(Value::Boolean(item.extract()?)));
    }
    if item.is_instance_of::<PyInt>() {
        return Ok(item.extract::<i64>().ok().map(Value::Integer));
    }
    if item.is_instance_of::<PyFloat>() {
        return Ok(Some(Value::Float(item.extract()?)));
    }
    Ok(None)
}

/// TOML text of a table (what the scene parser reads; floats are written so that they read
/// back bit for bit).
pub fn table_text(py: Python<'_>, table: &toml::Table) -> PyResult<String> {
    toml::to_string(table)
        .map_err(|e| crate::key_error(py, "(scene)", format!("cannot be written as TOML: {e}")))
}

/// A Python value from JSON text (through the `json` module: dicts, lists, floats, ints).
pub fn from_json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A Python value from a JSON value.
pub fn json_value<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    from_json(py, &text)
}
