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
    // a leading UTF-8 byte-order mark (Excel writes one) is not part of the header
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
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

/// Points per parallel work item of [`field_values`] and [`gradient_values`] (the chunks
/// start at point 0 whatever the thread count, so the values do not depend on it).
pub const FIELD_CHUNK: usize = 1024;

/// B \[T\] at every point \[m\] into `b` (`b[k]` for `points[k]`), in parallel chunks of
/// [`FIELD_CHUNK`] points through the four-lane kernel: the values `magsep field --points`
/// writes. Only `min(points.len(), b.len())` values are written.
pub fn field_values(scene: &FieldScene, points: &[DVec3], b: &mut [DVec3]) {
    b.par_chunks_mut(FIELD_CHUNK)
        .zip(points.par_chunks(FIELD_CHUNK))
        .for_each(|(out, chunk)| {
            let n = out.len().min(chunk.len());
            total_field_batch(
                &scene.sources,
                scene.b_ext,
                &chunk[..n],
                scene.tolerance,
                &mut out[..n],
            );
        });
}

/// B \[T\] and its gradient \[T/m\] at every point \[m\]: `b[k]`, and `grad[k][3 * i + j]` =
/// `∂B_i/∂x_j` (row-major), in parallel chunks of [`FIELD_CHUNK`] points: the values
/// `magsep field --points --gradient` writes. Only as many points as the shortest of the
/// three slices are evaluated.
pub fn gradient_values(
    scene: &FieldScene,
    points: &[DVec3],
    b: &mut [DVec3],
    grad: &mut [[f64; 9]],
) {
    b.par_chunks_mut(FIELD_CHUNK)
        .zip(grad.par_chunks_mut(FIELD_CHUNK))
        .zip(points.par_chunks(FIELD_CHUNK))
        .for_each(|((b, grad), chunk)| {
            for ((b, grad), &p) in b.iter_mut().zip(grad.iter_mut()).zip(chunk) {
                let g = scene.gradient(p);
                *b = g.b;
                // grad_b's row i is ∇B_i (its transpose's column i)
                let rows = g.grad_b.transpose();
                for i in 0..3 {
                    grad[3 * i..3 * i + 3].copy_from_slice(&rows.col(i).to_array());
                }
            }
        });
}

/// One CSV line per point: position \[m\], B \[T\] and (with `gradient`) `∂B_i/∂x_j` [T/m] in the
/// order `dbx_dx, dbx_dy, dbx_dz, dby_dx, ...` (the values of [`field_values`] and
/// [`gradient_values`]). Shortest round-trip formatting.
pub fn field_rows(scene: &FieldScene, points: &[DVec3], gradient: bool) -> Vec<String> {
    let mut b = vec![DVec3::ZERO; points.len()];
    let mut grad = vec![[0.0; 9]; if gradient { points.len() } else { 0 }];
    if gradient {
        gradient_values(scene, points, &mut b, &mut grad);
    } else {
        field_values(scene, points, &mut b);
    }
    points
        .par_iter()
        .enumerate()
        .map(|(k, p)| {
            let mut row = format!("{},{},{},{},{},{}", p.x, p.y, p.z, b[k].x, b[k].y, b[k].z);
            if let Some(g) = grad.get(k) {
                for v in g {
                    row.push_str(&format!(",{v}"));
                }
            }
            row
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leading_byte_order_mark_is_accepted() {
        let points = read_points("\u{feff}x,y,z\r\n1,2,3\r\n").unwrap();
        assert_eq!(points, vec![DVec3::new(1.0, 2.0, 3.0)]);
        // elsewhere it is still an error
        assert!(read_points("x,y,z\n\u{feff}1,2,3\n").is_err());
    }

    fn three_fibres() -> FieldScene {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/fibres_three.toml"
        ))
        .unwrap();
        FieldScene::from_scene(&crate::scene::parse_scene(&text, &Default::default()).unwrap())
    }

    /// Points spread through and around the fibres, over several chunks and a partial one.
    fn points(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let t = k as f64;
                DVec3::new(
                    1e-3 * (0.37 * t).sin(),
                    1e-3 * (0.23 * t).cos(),
                    2e-3 * (0.011 * t).sin(),
                )
            })
            .collect()
    }

    #[test]
    fn field_values_match_the_one_point_field_and_not_the_thread_count() {
        let fs = three_fibres();
        let p = points(2 * FIELD_CHUNK + 77);
        let on = |threads: usize| {
            let mut b = vec![DVec3::NAN; p.len()];
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| field_values(&fs, &p, &mut b));
            b
        };
        let b = on(2);
        assert_eq!(b, on(1));
        // the four-lane kernel against the one-point reference (they may differ in the last bit)
        for (k, (&p, b)) in p.iter().zip(&b).enumerate() {
            let want = fs.b(p);
            assert!(
                (*b - want).length() <= 1e-12 * want.length(),
                "point {k}: {b} against {want}"
            );
        }
    }

    #[test]
    fn gradient_values_are_the_one_point_gradient_row_major() {
        let fs = three_fibres();
        let p = points(FIELD_CHUNK + 5);
        let mut b = vec![DVec3::NAN; p.len()];
        let mut grad = vec![[f64::NAN; 9]; p.len()];
        gradient_values(&fs, &p, &mut b, &mut grad);
        for (k, &p) in p.iter().enumerate() {
            let g = fs.gradient(p);
            assert_eq!(b[k], g.b);
            for i in 0..3 {
                for j in 0..3 {
                    // grad_b's row i, column j: ∂B_i/∂x_j
                    assert_eq!(
                        grad[k][3 * i + j],
                        g.grad_b.row(i)[j],
                        "point {k} ({i}, {j})"
                    );
                }
            }
        }
        // shorter outputs: only their points, no panic
        let mut short = vec![DVec3::ZERO; 3];
        field_values(&fs, &p, &mut short);
        assert_eq!(short[2], fs.b(p[2]));
    }
}
