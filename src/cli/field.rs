//! `magsep field SCENE --points FILE [--gradient] [--out FILE.csv]` and
//! `magsep field SCENE --slice z=0 --extent ... --out map.svg [--resolution N] [--moment M
//! [--cutoff F]]`. An option that does not apply to the mode given is refused (exit 2), never
//! silently ignored.

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
    /// Map output (SVG), or the points' CSV instead of stdout.
    pub out: Option<PathBuf>,
    /// Map resolution (cells per side; default [`DEFAULT_RESOLUTION`]).
    pub resolution: Option<usize>,
    /// Map the force on a particle of this saturated moment [A m²] instead of |B|.
    pub moment: Option<f64>,
    /// Capture cut-off force [N] (with `moment`; default [`DEFAULT_CUTOFF`]).
    pub cutoff: Option<f64>,
    /// Overwrite an existing `out` (never an input).
    pub force: bool,
}

/// Cells per side of a map when `--resolution` is not given.
pub const DEFAULT_RESOLUTION: usize = 200;
/// Capture cut-off force [N] when `--cutoff` is not given (thesis: 0.5e-15 N).
pub const DEFAULT_CUTOFF: f64 = 0.5e-15;

/// The options given that do not apply to the mode (`--points` or `--slice`), as an error
/// naming each and why (they would otherwise be ignored).
fn inapplicable(a: &FieldArgs) -> Result<(), CliError> {
    const MAP_ONLY: &str = "applies to maps (--slice) only, not to --points";
    let wrong: Vec<(&str, &str)> = if a.points.is_some() {
        [
            (a.extent.is_some(), "--extent"),
            (a.resolution.is_some(), "--resolution"),
            (a.moment.is_some(), "--moment"),
            (a.cutoff.is_some(), "--cutoff"),
        ]
        .into_iter()
        .filter(|w| w.0)
        .map(|w| (w.1, MAP_ONLY))
        .collect()
    } else if a.slice.is_some() {
        [
            (a.gradient, "--gradient", "applies to --points only"),
            (
                a.cutoff.is_some() && a.moment.is_none(),
                "--cutoff",
                "is the capture contour of a force map: it needs --moment",
            ),
        ]
        .into_iter()
        .filter(|w| w.0)
        .map(|w| (w.1, w.2))
        .collect()
    } else {
        Vec::new()
    };
    if wrong.is_empty() {
        return Ok(());
    }
    let lines: Vec<String> = (wrong.iter())
        .map(|(name, why)| format!("{name} {why}"))
        .collect();
    Err(CliError::input(format!(
        "options that would be ignored: {}",
        lines.join("; ")
    )))
}

/// `magsep field` with `threads` worker threads: the options and `--out` are checked before
/// anything runs.
pub fn field(a: FieldArgs, threads: Option<usize>) -> Result<(), CliError> {
    inapplicable(&a)?;
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
        (Some(points), None) => points_csv(&fs, points, a.gradient, a.out.as_deref()),
        (None, Some(slice)) => map(&fs, &a, slice),
        _ => Err(CliError::input(
            "give either --points FILE or --slice AXIS=VALUE (with --extent and --out)",
        )),
    }
}

/// The field at the points of the CSV at `path`, as CSV on stdout, or into `file` (checked
/// by the caller: never an input) with a JSON line on stdout.
fn points_csv(
    fs: &FieldScene,
    path: &Path,
    gradient: bool,
    file: Option<&Path>,
) -> Result<(), CliError> {
    let text = read_text(path, MAX_POINTS_BYTES).map_err(CliError::input)?;
    let points =
        read_points(&text).map_err(|e| CliError::input(format!("{}:\n{e}", path.display())))?;
    let rows = field_rows(fs, &points, gradient);
    let write = |out: &mut dyn Write| -> std::io::Result<()> {
        writeln!(out, "{}", csv_header(gradient))?;
        for r in &rows {
            writeln!(out, "{r}")?;
        }
        out.flush()
    };
    let Some(file) = file else {
        let stdout = std::io::stdout();
        return write(&mut std::io::BufWriter::new(stdout.lock())).map_err(stdout_error);
    };
    let runtime = |e: std::io::Error| CliError::runtime(format!("{}: {e}", file.display()));
    let f = std::fs::File::create(file).map_err(runtime)?;
    write(&mut std::io::BufWriter::new(f)).map_err(runtime)?;
    print(serde_json::json!({
        "out": file.display().to_string(),
        "points": rows.len(),
        "gradient": gradient,
    }))
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
    let resolution = a.resolution.unwrap_or(DEFAULT_RESOLUTION);
    if !(4..=2000).contains(&resolution) {
        return Err(CliError::input(format!(
            "--resolution must be in 4..=2000, got {resolution}"
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
    let cutoff = a.cutoff.unwrap_or(DEFAULT_CUTOFF);
    if !(cutoff.is_finite() && cutoff > 0.0) {
        return Err(CliError::input(format!(
            "--cutoff must be > 0 [N], got {cutoff}"
        )));
    }
    let m = field_map(fs, slice, extent, resolution, quantity);
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
    let (x0, dx) = (extent[0], (extent[1] - extent[0]) / resolution as f64);
    let (y0, dy) = (extent[2], (extent[3] - extent[2]) / resolution as f64);
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
        hm = hm.contour(cutoff, format!("capture: F > {:e} N", cutoff));
        let cells = m.values.iter().flatten().filter(|v| **v > cutoff).count();
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
        "cells": resolution * resolution,
        "quantity": label,
        "max": max,
        "capture_area_m2": capture_area,
    }))
}
