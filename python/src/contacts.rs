//! `magsep.contact_numbers`: the packing pipeline's contact-number analysis
//! ([`magsep::systems::analysis::contacts::contact_numbers`]) of one recorded frame.

use glam::{DQuat, DVec3};
use magsep::components::container::Container;
use magsep::components::shape::Shape;
use magsep::systems::analysis::contacts::contact_numbers as library_contact_numbers;
use magsep::systems::packing::systems::{reference_diameter, state_from_si};
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Largest box edge accepted, in reference diameters (the neighbour grid has a cell per
/// diameter).
const MAX_EDGE_DIAMETERS: f64 = 200.0;

fn rows<const K: usize>(
    py: Python<'_>,
    a: &PyReadonlyArray2<'_, f64>,
    key: &str,
    n: usize,
) -> PyResult<Vec<[f64; K]>> {
    if a.shape() != [n, K] {
        return Err(crate::key_error(
            py,
            key,
            format!("expected shape ({n}, {K}), got {:?}", a.shape()),
        ));
    }
    let v = a.as_array();
    let out: Vec<[f64; K]> = v
        .rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect();
    if let Some(i) = out.iter().position(|r| !r.iter().all(|x| x.is_finite())) {
        return Err(crate::key_error(
            py,
            &format!("{key}[{i}]"),
            "must be finite",
        ));
    }
    Ok(out)
}

/// Contact numbers of spheres (half length 0) and spherocylinders in a periodic box.
#[pyfunction]
pub fn contact_numbers<'py>(
    py: Python<'py>,
    positions: PyReadonlyArray2<'py, f64>,
    orientations: PyReadonlyArray2<'py, f64>,
    radii: PyReadonlyArray1<'py, f64>,
    half_lengths: PyReadonlyArray1<'py, f64>,
    box_edges: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = radii.len();
    let positions: Vec<DVec3> = rows::<3>(py, &positions, "positions", n)?
        .into_iter()
        .map(DVec3::from_array)
        .collect();
    let orientations: Vec<DQuat> = rows::<4>(py, &orientations, "orientations", n)?
        .into_iter()
        .map(|q| DQuat::from_array(q).normalize())
        .collect();
    let radii = radii.as_array();
    let half = half_lengths.as_array();
    if half.len() != n {
        return Err(crate::key_error(
            py,
            "half_lengths",
            format!("expected {n} values, got {}", half.len()),
        ));
    }
    let mut shapes = Vec::with_capacity(n);
    for i in 0..n {
        let (r, h) = (radii[i], half[i]);
        if !(r.is_finite() && r > 0.0) {
            return Err(crate::key_error(
                py,
                &format!("radii[{i}]"),
                format!("must be > 0 [m], got {r}"),
            ));
        }
        if !(h.is_finite() && h >= 0.0) {
            return Err(crate::key_error(
                py,
                &format!("half_lengths[{i}]"),
                format!("must be >= 0 [m], got {h}"),
            ));
        }
        shapes.push(if h > 0.0 {
            Shape::Spherocylinder {
                radius: r,
                half_length: h,
            }
        } else {
            Shape::Sphere { radius: r }
        });
    }
    let d = reference_diameter(shapes.iter());
    let edges = box_edges.as_array();
    if edges.len() != 3
        || !edges
            .iter()
            .all(|e| e.is_finite() && *e > 0.0 && *e <= MAX_EDGE_DIAMETERS * d)
    {
        return Err(crate::key_error(
            py,
            "box_edges",
            format!(
                "expected three edges in (0, {MAX_EDGE_DIAMETERS} particle diameters] [m], got {edges:?}"
            ),
        ));
    }
    let container = Container::PeriodicBox {
        edges: DVec3::new(edges[0], edges[1], edges[2]),
    };
    let cn = py.detach(|| {
        let state = state_from_si(&container, &positions, &orientations, &shapes, d);
        library_contact_numbers(&state)
    });
    let out = PyDict::new(py);
    out.set_item("mean", cn.extrapolated)?;
    out.set_item("mean_at_1e-4", cn.at_1e_4)?;
    out.set_item("histogram", cn.histogram)?;
    out.set_item("samples", cn.samples)?;
    out.set_item("max_overlap", cn.max_overlap)?;
    out.set_item("reference_diameter", d)?;
    Ok(out)
}
