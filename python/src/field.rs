//! `magsep.field`: B (and its gradient) of fibres and an external field at numpy points,
//! through [`magsep::fieldtool::field_values`] / [`magsep::fieldtool::gradient_values`] (the
//! values `magsep field --points` prints), with the GIL released and the library's threads.

use glam::DVec3;
use magsep::fieldtool::{FieldScene, field_values, gradient_values};
use magsep::scene::parse_scene;
use numpy::{PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert::{table_text, to_toml};

// `DVec3` is `#[repr(C)] { x, y, z: f64 }`: three f64 without padding.
const _: () = assert!(std::mem::size_of::<DVec3>() == 24 && std::mem::align_of::<DVec3>() == 8);

/// `xyz` (x, y, z of consecutive points) viewed as points, without copying.
fn as_points(xyz: &[f64]) -> &[DVec3] {
    // SAFETY: DVec3 is repr(C) of three f64 (size 24, alignment 8, checked above), so
    // `len / 3` of them occupy the first `3 * (len / 3)` f64 of `xyz`, which is aligned for f64.
    unsafe { std::slice::from_raw_parts(xyz.as_ptr().cast::<DVec3>(), xyz.len() / 3) }
}

/// `xyz` viewed as mutable points, without copying.
fn as_points_mut(xyz: &mut [f64]) -> &mut [DVec3] {
    // SAFETY: as in `as_points`; the borrow of `xyz` is exclusive.
    unsafe { std::slice::from_raw_parts_mut(xyz.as_mut_ptr().cast::<DVec3>(), xyz.len() / 3) }
}

/// The scene TOML of `fibres` (a list of `[[fibres]]` tables) and `external` (the
/// `[external_field]` table, or B_ext \[T\] as three numbers).
fn scene_table(
    fibres: &Bound<'_, PyAny>,
    external: Option<&Bound<'_, PyAny>>,
) -> PyResult<toml::Table> {
    let py = fibres.py();
    let mut table = toml::Table::new();
    let fibres = to_toml(fibres, "fibres")?;
    if !fibres.is_array() {
        return Err(crate::key_error(
            py,
            "fibres",
            format!(
                "expected a list of fibres (dicts of the scene's [[fibres]] keys), got {}",
                fibres.type_str()
            ),
        ));
    }
    table.insert("fibres".into(), fibres);
    if let Some(ext) = external.filter(|e| !e.is_none()) {
        let value = if ext.is_instance_of::<PyDict>() {
            to_toml(ext, "external_field")?
        } else {
            let mut t = toml::Table::new();
            t.insert(
                "flux_density".into(),
                to_toml(ext, "external_field.flux_density")?,
            );
            toml::Value::Table(t)
        };
        table.insert("external_field".into(), value);
    }
    Ok(table)
}

/// The field sources of `fibres` and `external`, validated as a scene's (key paths in errors).
fn field_scene(
    fibres: &Bound<'_, PyAny>,
    external: Option<&Bound<'_, PyAny>>,
) -> PyResult<FieldScene> {
    let py = fibres.py();
    let text = table_text(py, &scene_table(fibres, external)?)?;
    let scene = parse_scene(&text, &Default::default())
        .map_err(|e| crate::scene_errors(py, "invalid fibres or external field", &e))?;
    if scene.fibres.is_empty() && scene.external_field.is_none() {
        return Err(crate::key_error(
            py,
            "fibres",
            "no fibres and no external field: nothing to evaluate",
        ));
    }
    Ok(FieldScene::from_scene(&scene))
}

/// The scene file text (`[[fibres]]`, `[external_field]`) that `field` evaluates: run
/// `magsep field` on it to get the same numbers from the CLI.
#[pyfunction]
#[pyo3(signature = (fibres, external=None))]
pub fn field_scene_text(
    fibres: &Bound<'_, PyAny>,
    external: Option<&Bound<'_, PyAny>>,
) -> PyResult<String> {
    let text = table_text(fibres.py(), &scene_table(fibres, external)?)?;
    // validated like `field`, so that bad input fails here too
    field_scene(fibres, external)?;
    Ok(text)
}

/// The (N, 3) float64 output array: `out` when given (C-contiguous, writeable, of that shape),
/// else a new one.
fn output<'py>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    n: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let Some(out) = out.filter(|o| !o.is_none()) else {
        return Ok(PyArray2::<f64>::zeros(py, [n, 3], false));
    };
    let out = out
        .cast::<PyArray2<f64>>()
        .map_err(|_| {
            crate::key_error(
                py,
                "out",
                format!("expected a float64 array of shape ({n}, 3)"),
            )
        })?
        .clone();
    let aligned: bool = out.getattr("flags")?.getattr("aligned")?.extract()?;
    if out.shape() != [n, 3] || !out.is_c_contiguous() || !aligned {
        return Err(crate::key_error(
            py,
            "out",
            format!(
                "expected a C-contiguous, aligned float64 array of shape ({n}, 3), got shape {:?}",
                out.shape()
            ),
        ));
    }
    Ok(out)
}

/// B \[T\] at `points` (an (N, 3) array \[m\]) as an (N, 3) float64 array (written into `out`
/// when given); with `gradient`, a tuple (B, G) where G\[n, i, j\] = ∂B_i/∂x_j \[T/m\].
#[pyfunction]
#[pyo3(signature = (fibres, points, external=None, gradient=false, out=None))]
pub fn field<'py>(
    py: Python<'py>,
    fibres: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    external: Option<&Bound<'py, PyAny>>,
    gradient: bool,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let scene = field_scene(fibres, external)?;
    // the array itself when it is already C-contiguous, aligned float64 (no copy)
    let array = py
        .import("numpy")?
        .call_method1("require", (points, "float64", "CA"))
        .map_err(|e| {
            crate::key_error(
                py,
                "points",
                format!("expected an (N, 3) array of float64 [m]: {e}"),
            )
        })?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(crate::key_error(
            py,
            "points",
            format!("expected an (N, 3) array [m], got shape {shape:?}"),
        ));
    }
    let array: PyReadonlyArray2<'py, f64> = array.extract()?;
    let xyz = array
        .as_slice()
        .map_err(|e| crate::key_error(py, "points", format!("not contiguous: {e}")))?;
    if let Some(k) = xyz
        .chunks_exact(3)
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(crate::key_error(
            py,
            &format!("points[{k}]"),
            format!("must be finite [m], got {:?}", &xyz[3 * k..3 * k + 3]),
        ));
    }
    let n = array.shape()[0];
    let b = output(py, out, n)?;
    let mut b_rw = b
        .try_readwrite()
        .map_err(|e| crate::key_error(py, "out", format!("cannot be written: {e}")))?;
    let b_out = b_rw
        .as_slice_mut()
        .map_err(|e| crate::key_error(py, "out", format!("not contiguous: {e}")))?;
    let pts = as_points(xyz);
    if gradient {
        let g = PyArray3::<f64>::zeros(py, [n, 3, 3], false);
        // SAFETY: as for `b`.
        let g_out = unsafe { g.as_slice_mut() }
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        let (rows, _) = g_out.as_chunks_mut::<9>();
        py.detach(|| gradient_values(&scene, pts, as_points_mut(b_out), rows));
        drop(b_rw);
        Ok(PyTuple::new(py, [b.into_any(), g.into_any()])?.into_any())
    } else {
        py.detach(|| field_values(&scene, pts, as_points_mut(b_out)));
        drop(b_rw);
        Ok(b.into_any())
    }
}
