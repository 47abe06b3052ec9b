//! `magsep chart flakes --out DIR [--quick]`: flat particles in the magnetised liquid (thesis
//! 002, ch. 4), from the shipped scenes (compiled in), one-way coupled:
//!
//! * `flakes_levitation.svg`: (a) the levitation time against the aspect ratio w of the
//!   equal-volume series (d_e = 4 mm, fig. 4.8), beside an independent 1-D model with the same
//!   conventions and the thesis's percentages; (b) their heights against time;
//! * `flakes_orientation.svg`: flakes of w = 0.5, 0.2, 0.1 released tilted 30° at y0 = L/3:
//!   (a) the tilt of the symmetry axis from vertical, (b) the sideways glide, against time;
//! * `flakes_force_budget.svg`: fig. 4.9, the forces on a sphere and a 1:10 flake over their
//!   net weight (ρ_p − ρ_f) V g: drag, Basset history, added mass, and the sum of gravity,
//!   buoyancy and magnetic buoyancy;
//! * `flakes_separation.svg`: e_m(t) of the many-particle cases without collisions for
//!   w = 1, 0.5, 0.1 (fig. 4.17; full: 1104 particles over 6 s, quick: 220 over 3 s).

use std::path::Path;

use glam::DVec3;
use magsep_components::prelude::*;
use rayon::prelude::*;
use serde_json::{Value, json};

use super::runtime;
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use magsep_systems::fluid::observe::SeparationCurve;

const ASPECT: &str = include_str!("../../../scenes/flakes_aspect_series.toml");
const DISC: &str = include_str!("../../../scenes/flake_disc.toml");
const MANY: &str = include_str!("../../../scenes/flakes_case4.toml");

/// The aspect ratios of the equal-volume series (the scene's groups, in order).
const SERIES_W: [f64; 4] = [1.0, 0.4, 0.2, 0.1];
/// Levitation-time increase over the sphere: an independent 1-D model with the same
/// conventions (last exit from the band, ρ_f in the drag, d_e, history) and the thesis.
const ONE_D_MODEL: [f64; 3] = [0.14, 0.23, 0.44];
const THESIS: [f64; 3] = [0.53, 0.90, 1.46];

/// Samples of one particle every `every` steps.
#[derive(Debug, Default, Clone)]
struct Track {
    t: Vec<f64>,
    z: Vec<f64>,
    lateral: Vec<f64>,
    tilt_deg: Vec<f64>,
    /// drag, history, added mass, body (gravity + buoyancy + magnetic) along z [N]
    budget: [Vec<f64>; 4],
}

/// Run `text` step by step, sampling particle `k`'s state every `every` steps.
fn track(text: &str, every: u64) -> Result<(Vec<Track>, Value), BenchError> {
    let mut sim = super::simulation(text)?;
    let n = sim
        .app
        .world
        .query::<&ParticleId>()
        .iter(&sim.app.world)
        .count();
    let mut tracks = vec![Track::default(); n];
    let mut last_v: Vec<Option<DVec3>> = vec![None; n];
    let mut step = 0u64;
    let origin: Vec<DVec3> = sorted(&mut sim.app.world)
        .iter()
        .map(|r| r.position)
        .collect();
    while !sim.is_finished() {
        sim.step();
        step += 1;
        let world = &mut sim.app.world;
        if let Some(h) = world.get_resource::<Health>().filter(|h| h.is_failed()) {
            return Err(runtime(h.messages.join("; ")));
        }
        let t = world.resource::<StepClock>().time();
        let dt = world.resource::<StepClock>().dt;
        let rows = sorted(world);
        for (k, r) in rows.iter().enumerate() {
            let accel = last_v[k].map(|v| (r.velocity - v) / dt);
            last_v[k] = Some(r.velocity);
            if !step.is_multiple_of(every) {
                continue;
            }
            let tr = &mut tracks[k];
            tr.t.push(t);
            tr.z.push(r.position.z);
            tr.lateral
                .push((r.position - origin[k]).truncate().length());
            tr.tilt_deg
                .push(r.axis.z.clamp(-1.0, 1.0).acos().to_degrees());
            let added = accel.map_or(0.0, |a| -0.5 * r.fluid_density * r.volume * a.z);
            for (slot, v) in tr.budget.iter_mut().zip([r.drag, r.history, added, r.body]) {
                slot.push(v);
            }
        }
    }
    let summary = sim.run(|_| {}).map_err(runtime)?;
    Ok((tracks, summary))
}

/// One particle's state.
struct Row {
    position: DVec3,
    velocity: DVec3,
    axis: DVec3,
    volume: f64,
    fluid_density: f64,
    drag: f64,
    history: f64,
    body: f64,
}

fn sorted(world: &mut bevy_ecs::world::World) -> Vec<Row> {
    let rho_f = world
        .get_resource::<magsep_systems::fluid::config::ParticleFluidConfig>()
        .map_or(0.0, |c| c.liquid.density);
    let mut q = world.query::<(
        &ParticleId,
        &Position,
        &Velocity,
        &Orientation,
        &InertialBody,
        Option<&DragForce>,
        Option<&HistoryForce>,
        (
            Option<&GravityForce>,
            Option<&BuoyancyForce>,
            Option<&MagneticBuoyancyForce>,
        ),
    )>();
    let mut rows: Vec<(ParticleId, Row)> = q
        .iter(world)
        .map(|(id, x, v, o, b, d, h, (g, bu, m))| {
            let z = |f: Option<DVec3>| f.map_or(0.0, |f| f.z);
            (
                *id,
                Row {
                    position: x.0,
                    velocity: v.0,
                    axis: o.0 * DVec3::Z,
                    volume: b.volume,
                    fluid_density: rho_f,
                    drag: z(d.map(|d| d.force)),
                    history: z(h.map(|h| h.0)),
                    body: z(g.map(|f| f.0)) + z(bu.map(|f| f.0)) + z(m.map(|f| f.0)),
                },
            )
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|r| r.1).collect()
}

fn pts(x: &[f64], y: &[f64], scale: f64) -> Vec<(f64, f64)> {
    x.iter().zip(y).map(|(a, b)| (*a, b * scale)).collect()
}

fn write(path: &Path, svg: &str) -> Result<String, BenchError> {
    write_svg(path, svg).map_err(runtime)?;
    Ok(path.display().to_string())
}

/// The tilted flakes of the orientation chart (w, scene text).
fn tilted(w: f64, quick: bool) -> String {
    let duration = if quick { 2.0 } else { 6.0 };
    DISC.replace(
        "equivalent_diameter = 2.657e-3, aspect_ratio = 0.1",
        &format!("equivalent_diameter = 4e-3, aspect_ratio = {w}"),
    )
    .replace(
        "orientation = \"broadside\"",
        "orientation = { tilt = 30.0 }",
    )
    .replace("0.075, 0.075, 0.1042", "0.075, 0.075, 0.1")
    .replace("duration = 25.0 ", &format!("duration = {duration} "))
}

/// The many-particle case without collisions at aspect ratio `w`.
fn many(w: f64, quick: bool) -> String {
    let (phi, duration) = if quick { (0.002, 3.0) } else { (0.01, 6.0) };
    MANY.replace("aspect_ratio = 0.5", &format!("aspect_ratio = {w}"))
        .replace(
            "volume_fraction = 0.01 ",
            &format!("volume_fraction = {phi} "),
        )
        .replace("duration = 6.0 ", &format!("duration = {duration} "))
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_flakes(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let aspect = if quick {
        ASPECT.replace("duration = 30.0 ", "duration = 14.0 ")
    } else {
        ASPECT.to_string()
    };
    let tilt_w = [0.5, 0.2, 0.1];
    let ws = [1.0, 0.5, 0.1];
    // the runs are independent: in parallel
    let (series, (tilts, seps)) = rayon::join(
        || track(&aspect, 20),
        || {
            rayon::join(
                || {
                    tilt_w
                        .par_iter()
                        .map(|&w| track(&tilted(w, quick), 5))
                        .collect::<Result<Vec<_>, _>>()
                },
                || {
                    ws.par_iter()
                        .map(|&w| super::separation::run_case(&many(w, quick)))
                        .collect::<Result<Vec<_>, _>>()
                },
            )
        },
    );
    let (series, summary) = series?;
    let (tilts, seps) = (tilts?, seps?);
    let times: Vec<f64> = summary["particle_details"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|p| p["levitation_time"].as_f64().unwrap_or(f64::NAN))
                .collect()
        })
        .unwrap_or_default();
    let t0 = times.first().copied().unwrap_or(f64::NAN);
    let mut charts = Vec::new();
    // 1. levitation time against w, and the trajectories
    let rel = |v: &[f64]| -> Vec<(f64, f64)> {
        std::iter::once((1.0, t0))
            .chain(
                SERIES_W[1..]
                    .iter()
                    .zip(v)
                    .map(|(w, r)| (*w, t0 * (1.0 + r))),
            )
            .collect()
    };
    let a = Chart::new("levitation time against aspect ratio (d_e = 4 mm, from L/3)")
        .x_label("w = d_minor / d_major")
        .y_label("t_l [s]")
        .legend(LegendPosition::TopRight)
        .series(
            Series::new(
                "magsep",
                SERIES_W.iter().copied().zip(times.iter().copied()),
            )
            .style(Style::LineMarkers),
        )
        .series(Series::new("1-D model, same conventions", rel(&ONE_D_MODEL)).style(Style::Markers))
        .series(
            Series::new("thesis fig. 4.8 (not reproducible)", rel(&THESIS)).style(Style::Markers),
        );
    let mut b = Chart::new("height against time")
        .x_label("t [s]")
        .y_label("z [mm]")
        .legend(LegendPosition::TopRight)
        .line(
            Line::new(
                "y_e",
                vec![
                    (0.0, 49.2),
                    (series[0].t.last().copied().unwrap_or(1.0), 49.2),
                ],
            )
            .dashed(true),
        );
    for (tr, w) in series.iter().zip(SERIES_W) {
        b = b.series(Series::new(format!("w = {w}"), pts(&tr.t, &tr.z, 1e3)).style(Style::Line));
    }
    let fig = Figure::new("Equal-volume flakes levitating (thesis 002, fig. 4.8)", 2)
        .panel(a)
        .panel(b);
    charts.push(write(
        &out.join("flakes_levitation.svg"),
        &fig.to_svg(520.0, 380.0),
    )?);
    // 2. orientation and glide
    let mut a = Chart::new("tilt of the symmetry axis")
        .x_label("t [s]")
        .y_label("tilt [deg]")
        .legend(LegendPosition::TopRight);
    let mut b = Chart::new("sideways glide")
        .x_label("t [s]")
        .y_label("lateral displacement [mm]")
        .legend(LegendPosition::TopLeft);
    for ((tracks, _), w) in tilts.iter().zip(tilt_w) {
        let tr = &tracks[0];
        a = a.series(
            Series::new(format!("w = {w}"), pts(&tr.t, &tr.tilt_deg, 1.0)).style(Style::Line),
        );
        b = b.series(
            Series::new(format!("w = {w}"), pts(&tr.t, &tr.lateral, 1e3)).style(Style::Line),
        );
    }
    let fig = Figure::new(
        "Flakes released tilted 30 degrees (d_e = 4 mm, from L/3)",
        2,
    )
    .panel(a)
    .panel(b);
    charts.push(write(
        &out.join("flakes_orientation.svg"),
        &fig.to_svg(520.0, 380.0),
    )?);
    // 3. force budget of the sphere and the 1:10 flake of the series
    let g = 9.81;
    let mut fig = Figure::new(
        "Force budget F / ((rho_p - rho_f) V g) (thesis 002, fig. 4.9)",
        2,
    );
    for (k, name) in [(0, "sphere (w = 1)"), (3, "flake (w = 0.1)")] {
        let tr = &series[k];
        let v = std::f64::consts::PI / 6.0 * 4e-3f64.powi(3);
        let scale = 1.0 / ((1434.0 - 1403.0) * v * g);
        let mut c = Chart::new(name)
            .x_label("t [s]")
            .y_label("F*")
            .legend(LegendPosition::TopRight);
        for (slot, label) in [
            "drag",
            "history",
            "added mass",
            "gravity + buoyancy + magnetic",
        ]
        .iter()
        .enumerate()
        {
            c = c.series(
                Series::new(*label, pts(&tr.t, &tr.budget[slot], scale)).style(Style::Line),
            );
        }
        fig = fig.panel(c);
    }
    charts.push(write(
        &out.join("flakes_force_budget.svg"),
        &fig.to_svg(520.0, 380.0),
    )?);
    // 4. separation error
    let mut c = Chart::new(format!(
        "Separation error without collisions, one-way ({} particles)",
        seps[0].1["particles"]
    ))
    .x_label("t [s]")
    .y_label("e_m")
    .y_log(true)
    .legend(LegendPosition::TopRight);
    for ((curve, _), w) in seps.iter().zip(ws) {
        c = c.series(
            Series::new(
                format!("w = {w}"),
                curve.times.iter().copied().zip(curve.total.iter().copied()),
            )
            .style(Style::Line),
        );
    }
    charts.push(write(
        &out.join("flakes_separation.svg"),
        &c.to_svg(640.0, 420.0),
    )?);
    let at = |curve: &SeparationCurve, t: f64| {
        curve
            .times
            .iter()
            .zip(&curve.total)
            .find(|(s, _)| **s >= t - 1e-9)
            .map(|(_, e)| *e)
    };
    let final_tilts: Vec<f64> = tilts
        .iter()
        .map(|(tr, _)| tr[0].tilt_deg.last().copied().unwrap_or(f64::NAN))
        .collect();
    crate::studies::bench::say(json!({
        "charts": charts,
        "quick": quick,
        "aspect_series": {"w": SERIES_W, "levitation_time": times,
            "increase_over_sphere": times.iter().skip(1).map(|t| t / t0 - 1.0).collect::<Vec<_>>(),
            "one_d_model": ONE_D_MODEL, "thesis": THESIS},
        "tilted": {"w": tilt_w, "final_tilt_deg": final_tilts},
        "separation": ws.iter().zip(&seps).map(|(w, (c, s))| json!({
            "w": w, "particles": s["particles"], "e_m_3s": at(c, 3.0),
            "thesis_e_m_3s": if *w == 1.0 { 0.006 } else if *w == 0.5 { 0.018 } else { 0.193 },
        })).collect::<Vec<_>>(),
    }))
}
