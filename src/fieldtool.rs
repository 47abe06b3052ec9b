//! `magsep field`: the total magnetic field of a scene's fibres and external field at given
//! points (CSV in, CSV out), and maps of |B| or of the force on a particle in a plane.
//!
//! Points are evaluated in parallel in fixed-size chunks and written in input order, so the
//! output does not depend on the number of threads.

use glam::DVec3;
use magsep_systems::field::{
    CylinderSource, FieldGradient, MomentModel, dipole_force, total_field, total_field_batch,
    total_field_gradient,
};
use rayon::prelude::*;

/// The sources of a scene: fibres, external flux density \[T\], tolerance.
#[derive(Debug, Clone)]
pub struct FieldScene {
    /// Fibres.
    pub sources: Vec<CylinderSource>,
    /// External flux density \[T\].
    pub b_ext: DVec3,
    /// Relative tolerance of each fibre's field.
    pub tolerance: f64,
}

impl FieldScene {
    /// From a parsed scene.
    pub fn from_scene(scene: &crate::scene::Scene) -> Self {
        let (sources, b_ext, tolerance) = scene.field_sources();
        Self {
            sources,
            b_ext,
            tolerance,
        }
    }

    /// B \[T\] at `p` \[m\].
    pub fn b(&self, p: DVec3) -> DVec3 {
        total_field(&self.sources, self.b_ext, p, self.tolerance).b
    }

    /// B \[T\] and its gradient [T/m] at `p` \[m\].
    pub fn gradient(&self, p: DVec3) -> FieldGradient {
        total_field_gradient(&self.sources, self.b_ext, p, self.tolerance)
    }

    /// Whether `p` is inside (or on) a fibre.
    pub fn inside(&self, p: DVec3) -> bool {
        self.sources.iter().any(|s| s.contains(p))
    }
}

/// Read points from CSV text with the header `x,y,z` \[m\]. Blank lines are skipped.
///
/// # Errors
/// Every bad line, with its line number (one message per line, at most 20).
pub fn read_points(text: &str) -> Result<Vec<DVec3>, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let header = match lines.next() {
        Some((_, h)) => h,
        None => return Err("empty file: expected a header line `x,y,z`".into()),
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_lowercase()).collect();
    if cols != ["x", "y", "z"] {
        return Err(format!(
            "line 1: expected the header `x,y,z`, got `{header}`"
        ));
    }
    let mut points = Vec::new();
    let mut errors = Vec::new();
    for (i, line) in lines {
        let vals: Vec<Result<f64, _>> = line.split(',').map(|v| v.trim().parse::<f64>()).collect();
        match vals.as_slice() {
            [Ok(x), Ok(y), Ok(z)] if x.is_finite() && y.is_finite() && z.is_finite() => {
                points.push(DVec3::new(*x, *y, *z))
            }
            [_, _, _] => errors.push(format!(
                "line {}: expected three finite numbers, got `{line}`",
                i + 1
            )),
            _ => errors.push(format!(
                "line {}: expected 3 columns, got {}",
                i + 1,
                vals.len()
            )),
        }
    }
    if errors.is_empty() {
        Ok(points)
    } else {
        let n = errors.len();
        errors.truncate(20);
        if n > 20 {
            errors.push(format!("... and {} more", n - 20));
        }
        Err(errors.join("\n"))
    }
}

/// CSV header of [`field_rows`].
pub fn csv_header(gradient: bool) -> String {
    let mut h = "x,y,z,bx,by,bz".to_string();
    if gradient {
        for c in ["x", "y", "z"] {
            for d in ["x", "y", "z"] {
                h.push_str(&format!(",db{c}_d{d}"));
            }
        }
    }
    h
}

/// One CSV line per point: position \[m\], B \[T\] and (with `gradient`) `∂B_i/∂x_j` [T/m] in the
/// order `dbx_dx, dbx_dy, dbx_dz, dby_dx, ...`. Shortest round-trip formatting.
pub fn field_rows(scene: &FieldScene, points: &[DVec3], gradient: bool) -> Vec<String> {
    points
        .par_chunks(1024)
        .flat_map_iter(|chunk| {
            // B of the whole chunk at once (the four-lane kernel), unless gradients are asked
            let mut b = vec![DVec3::ZERO; if gradient { 0 } else { chunk.len() }];
            if !gradient {
                total_field_batch(&scene.sources, scene.b_ext, chunk, scene.tolerance, &mut b);
            }
            chunk.iter().enumerate().map(move |(k, &p)| {
                let mut row = format!("{},{},{}", p.x, p.y, p.z);
                if gradient {
                    let g = scene.gradient(p);
                    row.push_str(&format!(",{},{},{}", g.b.x, g.b.y, g.b.z));
                    let rows = g.grad_b.transpose(); // column i = ∇B_i
                    for i in 0..3 {
                        let r = rows.col(i);
                        row.push_str(&format!(",{},{},{}", r.x, r.y, r.z));
                    }
                } else {
                    let b = b[k];
                    row.push_str(&format!(",{},{},{}", b.x, b.y, b.z));
                }
                row
            })
        })
        .collect()
}

/// A plane `axis = value` (`axis` 0, 1, 2 for x, y, z), parsed from `z=0`.
///
/// # Errors
/// A message for a malformed slice.
pub fn parse_slice(s: &str) -> Result<(usize, f64), String> {
    let (a, v) = s
        .split_once('=')
        .ok_or_else(|| format!("--slice: expected AXIS=VALUE such as z=0, got `{s}`"))?;
    let axis = match a.trim() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => return Err(format!("--slice: axis must be x, y or z, got `{other}`")),
    };
    let value: f64 = v
        .trim()
        .parse()
        .map_err(|_| format!("--slice: value must be a number [m], got `{v}`"))?;
    if !value.is_finite() {
        return Err(format!("--slice: value must be finite, got {value}"));
    }
    Ok((axis, value))
}

/// `--extent A_MIN,A_MAX,B_MIN,B_MAX` \[m\] of the two in-plane axes.
///
/// # Errors
/// A message for a malformed extent.
pub fn parse_extent(s: &str) -> Result<[f64; 4], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            format!("--extent: expected four numbers MIN1,MAX1,MIN2,MAX2 [m], got `{s}`")
        })?;
    match v.as_slice() {
        [a, b, c, d] if [a, b, c, d].iter().all(|x| x.is_finite()) && a < b && c < d => {
            Ok([*a, *b, *c, *d])
        }
        _ => Err(format!(
            "--extent: expected MIN1 < MAX1 and MIN2 < MAX2 (finite, in metres), got `{s}`"
        )),
    }
}

/// What a map shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MapQuantity {
    /// |B| \[T\].
    FluxDensity,
    /// Attractive magnetic force \[N\] on a particle (`|F|` where `F` points towards the nearest
    /// fibre, 0 where it points away; thesis ch. 6 capture volume).
    Force(MomentModel),
}

/// A computed map: cell values `values[j][i]` on a `n x n` grid.
#[derive(Debug, Clone)]
pub struct FieldMap {
    /// Values (row j = second in-plane axis).
    pub values: Vec<Vec<f64>>,
    /// Whether each cell centre is inside a fibre.
    pub inside: Vec<Vec<bool>>,
    /// In-plane axes (indices into x, y, z).
    pub axes: (usize, usize),
    /// Extent [min1, max1, min2, max2] \[m\].
    pub extent: [f64; 4],
}

/// Sample `quantity` on an `n x n` grid of cell centres in the plane `slice`.
pub fn field_map(
    scene: &FieldScene,
    slice: (usize, f64),
    extent: [f64; 4],
    n: usize,
    quantity: MapQuantity,
) -> FieldMap {
    let axes = match slice.0 {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let point = |i: usize, j: usize| {
        let mut p = DVec3::ZERO;
        p[slice.0] = slice.1;
        p[axes.0] = extent[0] + (i as f64 + 0.5) * (extent[1] - extent[0]) / n as f64;
        p[axes.1] = extent[2] + (j as f64 + 0.5) * (extent[3] - extent[2]) / n as f64;
        p
    };
    let rows: Vec<(Vec<f64>, Vec<bool>)> = (0..n)
        .into_par_iter()
        .map(|j| {
            (0..n)
                .map(|i| {
                    let p = point(i, j);
                    let inside = scene.inside(p);
                    let v = if inside {
                        f64::NAN
                    } else {
                        match quantity {
                            MapQuantity::FluxDensity => scene.b(p).length(),
                            MapQuantity::Force(law) => attractive_force(scene, p, &law),
                        }
                    };
                    (v, inside)
                })
                .unzip()
        })
        .collect();
    let (values, inside) = rows.into_iter().unzip();
    FieldMap {
        values,
        inside,
        axes,
        extent,
    }
}

/// `|F|` if the force on a particle at `p` points towards the nearest fibre, else 0.
pub fn attractive_force(scene: &FieldScene, p: DVec3, law: &MomentModel) -> f64 {
    // the map's moments are saturated; a Langevin law is taken at 298 K
    let f = dipole_force(
        &scene.gradient(p),
        law,
        magsep_components::brownian::BOLTZMANN * 298.0,
    );
    let nearest = scene
        .sources
        .iter()
        .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)));
    match nearest {
        Some(s) if f.dot(s.closest_point(p) - p) <= 0.0 => 0.0,
        _ => f.length(),
    }
}
