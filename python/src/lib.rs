//! `magsep._magsep`: the Rust side of the Python package `magsep` (the pure-Python wrapper
//! `magsep/__init__.py` re-exports it with docstrings and type stubs).
//!
//! Every number comes from the magsep library: the field from
//! [`magsep::fieldtool`], runs from [`magsep::sim::run_scene`], recordings from
//! [`magsep_record::RecordingReader`]. No Rust panic crosses into Python: every error becomes a
//! Python exception ([`SceneError`], a `ValueError`, names the key path of bad input).

use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyList;

mod contacts;
mod convert;
mod field;
mod recording;
mod run;

create_exception!(
    magsep,
    SceneError,
    PyValueError,
    "Bad input: a scene, fibres, points or overrides. `errors` lists (key path, message) pairs, \
     e.g. ('fibres[0].radius', 'must be in ...')."
);
create_exception!(
    magsep,
    RunError,
    PyRuntimeError,
    "A run failed (a numerical failure, a recording that could not be written). `summary` is \
     the summary of the steps that ran, or None."
);
create_exception!(
    magsep,
    RunInterrupted,
    PyKeyboardInterrupt,
    "Ctrl-C stopped a run: the current step ended, the recording was closed (complete, with \
     its interrupted record), and `summary` is the summary of the steps that ran."
);
create_exception!(
    magsep,
    RecordingError,
    PyValueError,
    "A recording could not be read (not MCAP, damaged before its first frame, unreadable)."
);

/// A [`SceneError`] with the given (path, message) pairs; its message lists them one per line
/// after `what`.
pub(crate) fn scene_error(py: Python<'_>, what: &str, errors: Vec<(String, String)>) -> PyErr {
    let lines: Vec<String> = errors.iter().map(|(p, m)| format!("{p}: {m}")).collect();
    let message = if what.is_empty() {
        lines.join("\n")
    } else {
        format!("{what}:\n{}", lines.join("\n"))
    };
    let err = SceneError::new_err(message);
    if let Ok(list) = PyList::new(py, errors) {
        let _ = err.value(py).setattr("errors", list);
    }
    err
}

/// A [`SceneError`] from the library's scene errors.
pub(crate) fn scene_errors(py: Python<'_>, what: &str, e: &magsep::scene::SceneErrors) -> PyErr {
    scene_error(
        py,
        what,
        e.0.iter()
            .map(|e| (e.path.clone(), e.message.clone()))
            .collect(),
    )
}

/// One [`SceneError`] at `path`.
pub(crate) fn key_error(py: Python<'_>, path: &str, message: impl Into<String>) -> PyErr {
    scene_error(py, "", vec![(path.to_string(), message.into())])
}

#[pymodule]
fn _magsep(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("RunError", py.get_type::<RunError>())?;
    m.add("RunInterrupted", py.get_type::<RunInterrupted>())?;
    m.add("RecordingError", py.get_type::<RecordingError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(field::field, m)?)?;
    m.add_function(wrap_pyfunction!(field::field_scene_text, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::validate, m)?)?;
    m.add_function(wrap_pyfunction!(contacts::contact_numbers, m)?)?;
    m.add_class::<recording::Recording>()?;
    m.add_function(wrap_pyfunction!(recording::open_recording, m)?)?;
    m.add_function(wrap_pyfunction!(recording::read_recording_frames, m)?)?;
    Ok(())
}
