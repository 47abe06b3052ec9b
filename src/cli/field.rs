//! `magsep field SCENE --points FILE [--gradient]` and
//! `magsep field SCENE --slice z=0 --extent ... --out map.svg`.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::chart::{ColourScale, Heatmap};
use crate::fieldtool::{
    FieldScene, MapQuantity, csv_header, field_map, field_rows, parse_extent, parse_slice,
    read_points,
};
use crate::input::{MAX_POINTS_BYTES, read_text};
use crate::scene::parse_scene;
use magsep_systems::field::MomentModel;

use super::CliError;
use super::output::{Input, check_file, print, stdout_error};

/// Options of `magsep field`.
pub struct FieldArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// Points CSV (header `x,y,z`).
    pub points: Option<PathBuf>,
    /// Also write the gradient.
    pub gradient: bool,
    /// Map plane `AXIS=VALUE`.
    pub slice: Option<String>,
    /// Map extent.
    pub extent: Option<String>,
    /// Map output.
    pub out: Option<PathBuf>,
    /// Map resolution (cells per side).
    pub resolution: usize,
    /// Map the force on a particle of this saturated moment [A m²] instead of |B|.
    pub moment: Option<f64>,
    /// Capture cut-off force [N].
    pub cutoff: f64,
    /// Overwrite an existing `out` (never an input).
    pub force: bool,
}

/// `magsep field` with `threads` worker threads: `--out` is checked before anything runs.
pub fn field(a: FieldArgs, threads: Option<usize>) -> Result<(), CliError> {
    let text = super::run::scene_text(&a.scene)?;
    if let Some(out) = &a.out {
        let mut inputs = super::run::scene_inputs(&a.scene, &text);
        if let Some(points) = &a.points {
            inputs.push(Input::new("points file", points));
        }
        check_file("--out", out, &inputs, a.force)?;
    }
    super::run::set_threads(threads)?;
    let scene = parse_scene(&text, &Default::default())
        .map_err(|e| CliError::input(format!("{} is invalid:\n{e}", a.scene.display())))?;
    if scene.fibres.is_empty() && scene.external_field.is_none() {
        return Err(CliError::input(format!(
            "{}: no [[fibres]] and no [external_field]: nothing to evaluate",
            a.scene.display()
        )));
    }
    let fs = FieldScene::from_scene(&scene);
    match (&a.points, &a.slice) {
        (Some(points), None) => points_csv(&fs, points, a.gradient),
        (None, Some(slice)) => map(&fs, &a, slice),
        _ => Err(CliError::input(
            "give either --points FILE or --slice AXIS=VALUE (with --extent and --out)",
        )),
    }
}

fn points_csv(fs: &FieldScene, path: &Path, gradient: bool) -> Result<(), CliError> {
    let text = read_text(path, MAX_POINTS_BYTES).map_err(CliError::input)?;
    let points =
        read_points(&text).map_err(|e| CliError::input(format!("{}:\n{e}", path.display())))?;
    let rows = field_rows(fs, &points, gradient);
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let mut write = || -> std::io::Result<()> {
        writeln!(out, "{}", csv_header(gradient))?;
        for r in &rows {
            writeln!(out, "{r}")?;
        }
        out.flush()
    };
    write().map_err(stdout_error)
}

fn map(fs: &FieldScene, a: &FieldArgs, slice: &str) -> Result<(), CliError> {
    let slice = parse_slice(slice).map_err(CliError::input)?;
    let extent = parse_extent(
        a.extent
            .as_deref()
            .ok_or_else(|| CliError::input("--slice needs --extent MIN1,MAX1,MIN2,MAX2 [m]"))?,
    )
    .map_err(CliError::input)?;
    let out = a
        .out
        .as_ref()
        .ok_or_else(|| CliError::input("--slice needs --out FILE.svg"))?;
    if !(4..=2000).contains(&a.resolution) {
        return Err(CliError::input(format!(
            "--resolution must be in 4..=2000, got {}",
            a.resolution
        )));
    }
    let quantity = match a.moment {
        Some(m) if m.is_finite() && m > 0.0 => {
            MapQuantity::Force(MomentModel::Saturated { moment: m })
        }
        Some(m) => {
            return Err(CliError::input(format!(
                "--moment must be > 0 [A m²], got {m}"
            )));
        }
        None => MapQuantity::FluxDensity,
    };
    if !(a.cutoff.is_finite() && a.cutoff > 0.0) {
        return Err(CliError::input(format!(
            "--cutoff must be > 0 [N], got {}",
            a.cutoff
        )));
    }
    let m = field_map(fs, slice, extent, a.resolution, quantity);
    let names = ["x [m]", "y [m]", "z [m]"];
    let plane = ["x", "y", "z"][slice.0];
    let (title, label) = match quantity {
        MapQuantity::FluxDensity => (
            format!("|B| in the plane {plane} = {} m", slice.1),
            "|B| [T]",
        ),
        MapQuantity::Force(_) => (
            format!("Attractive force in the plane {plane} = {} m", slice.1),
            "|F| [N]",
        ),
    };
    let inside = m.inside.clone();
    let (x0, dx) = (extent[0], (extent[1] - extent[0]) / a.resolution as f64);
    let (y0, dy) = (extent[2], (extent[3] - extent[2]) / a.resolution as f64);
    let mut hm = Heatmap::new(
        title,
        (extent[0], extent[1]),
        (extent[2], extent[3]),
        m.values.clone(),
    )
    .x_label(names[m.axes.0])
    .y_label(names[m.axes.1])
    .colour_label(label)
    .scale(ColourScale::Log)
    .mask(move |x, y| {
        let i = ((x - x0) / dx).floor() as usize;
        let j = ((y - y0) / dy).floor() as usize;
        inside
            .get(j)
            .and_then(|r| r.get(i))
            .copied()
            .unwrap_or(false)
    });
    let mut capture_area = None;
    if let MapQuantity::Force(_) = quantity {
        hm = hm.contour(a.cutoff, format!("capture: F > {:e} N", a.cutoff));
        let cells = m.values.iter().flatten().filter(|v| **v > a.cutoff).count();
        capture_area = Some(cells as f64 * dx * dy);
    }
    std::fs::write(out, hm.to_svg(720.0, 600.0))
        .map_err(|e| CliError::runtime(format!("{}: {e}", out.display())))?;
    let finite: Vec<f64> = m
        .values
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let max = finite.iter().copied().fold(0.0, f64::max);
    print(serde_json::json!({
        "out": out.display().to_string(),
        "plane": format!("{plane}={}", slice.1),
        "cells": a.resolution * a.resolution,
        "quantity": label,
        "max": max,
        "capture_area_m2": capture_area,
    }))
}
