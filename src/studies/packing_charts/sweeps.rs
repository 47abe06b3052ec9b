//! The three sweeps and their charts.

use std::path::Path;

use serde_json::json;

use super::{Point, PointSpec, half_width, point, point_with, points, rod};
use crate::chart::{Chart, Figure, Heatmap, Line, Series, Style, write_svg};
use crate::pipelines::packing::ContainerSpec;
use crate::studies::bench::BenchError;
use magsep_systems::analysis::confinement::{
    bulk_extrapolation, rescaled_contact_number as rescaled_contacts,
    rescaled_packing_fraction as rescaled_phi, rescaled_packing_fraction_wedge,
};
use magsep_systems::analysis::wall_order::orientation_histogram;
use magsep_systems::packing::walls::{wedge_min_length, wedge_min_packing_fraction};

fn save(path: &Path, svg: &str) -> Result<(), BenchError> {
    write_svg(path, svg).map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))
}

fn out_dir(out: &Path) -> Result<(), BenchError> {
    std::fs::create_dir_all(out).map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))
}

/// Sizes of a sweep: particles, runs per point.
fn sizes(quick: bool, n_full: usize, runs_full: u64) -> (usize, u64) {
    if quick { (60, 1) } else { (n_full, runs_full) }
}

/// Cylinder confinement (thesis figs. 2.10-2.11; target V-PK-16): phi*, \<C\>* against D_cyl,
/// S against D_cyl / aspect, and the 1/D_cyl extrapolation of phi.
pub fn chart_cylinder(out: &Path, quick: bool) -> Result<(), BenchError> {
    out_dir(out)?;
    let (n, runs) = sizes(quick, 120, 2);
    let lambdas: Vec<f64> = if quick {
        vec![1.0, 3.0]
    } else {
        vec![1.0, 2.0, 3.0, 5.0]
    };
    let diameters: Vec<f64> = if quick {
        vec![1.5, 2.0, 3.0, 4.0, 6.0]
    } else {
        vec![1.05, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0, 10.0]
    };
    let mut phi_star = Chart::new("phi* = phi / phi_periodic")
        .x_label("D_cyl / D")
        .y_label("phi*");
    let mut c_star = Chart::new("<C>* = (<C> - 2) / (<C>_periodic - 2)")
        .x_label("D_cyl / D")
        .y_label("<C>*");
    let mut nem = Chart::new("nematic order")
        .x_label("D_cyl / aspect ratio")
        .y_label("S")
        .x_log(true);
    let mut extrap = Chart::new("phi against 1 / D_cyl (linear fit over D_cyl >= 3 D)")
        .x_label("D / D_cyl")
        .y_label("phi");
    let mut summary = Vec::new();
    for &l in &lambdas {
        let phi0 = 0.05;
        let per = point(
            format!("aspect {l} periodic"),
            n,
            rod(l),
            &ContainerSpec::PeriodicBox {},
            phi0,
            runs,
        )?;
        let mut pts: Vec<(f64, Point)> = Vec::new();
        // random insertion needs room to turn: rods start at D_cyl >= 1.25 D
        for &d in diameters
            .iter()
            .filter(|d| **d > 1.0 && (l == 1.0 || **d >= 1.25))
        {
            let spec = ContainerSpec::Cylinder { radius: 0.5 * d };
            let p = point(
                format!("aspect {l} D_cyl {d}"),
                n,
                rod(l),
                &spec,
                phi0,
                runs,
            )?;
            pts.push((d, p));
        }
        let name = format!("aspect {l}");
        let ps: Vec<(f64, f64)> = pts
            .iter()
            .map(|(d, p)| (*d, rescaled_phi(p.phi.mean, per.phi.mean)))
            .collect();
        let pe: Vec<f64> = pts
            .iter()
            .map(|(_, p)| half_width(&p.phi) / per.phi.mean)
            .collect();
        phi_star = phi_star.series(Series::new(name.clone(), ps).y_err(pe));
        let cs: Vec<(f64, f64)> = pts
            .iter()
            .map(|(d, p)| (*d, rescaled_contacts(p.contacts.mean, per.contacts.mean)))
            .collect();
        c_star = c_star.series(Series::new(name.clone(), cs));
        if l > 1.0 {
            nem = nem.series(Series::new(
                name.clone(),
                pts.iter()
                    .map(|(d, p)| (*d / l, p.nematic.mean))
                    .collect::<Vec<_>>(),
            ));
        }
        let (wd, wp): (Vec<f64>, Vec<f64>) = pts
            .iter()
            .filter(|(d, _)| *d >= 3.0)
            .map(|(d, p)| (*d, p.phi.mean))
            .unzip();
        let fit = bulk_extrapolation(&wd, &wp).map_err(|e| {
            BenchError::Runtime(format!("aspect {l}: 1/D_cyl fit over D_cyl >= 3: {e}"))
        })?;
        extrap = extrap
            .series(
                Series::new(
                    name.clone(),
                    pts.iter()
                        .map(|(d, p)| (1.0 / d, p.phi.mean))
                        .collect::<Vec<_>>(),
                )
                .style(Style::Markers),
            )
            .line(
                Line::new(
                    format!(
                        "{name}: fit, bulk {:.3} (periodic {:.3})",
                        fit.intercept, per.phi.mean
                    ),
                    vec![
                        (0.0, fit.intercept),
                        (1.0 / 3.0, fit.intercept + fit.slope / 3.0),
                    ],
                )
                .dashed(true),
            );
        summary.push(json!({
            "aspect_ratio": l,
            "periodic": per,
            "extrapolated_bulk_phi": fit.intercept,
            "extrapolated_bulk_phi_stderr": fit.intercept_stderr,
            "extrapolation_vs_periodic": fit.intercept / per.phi.mean - 1.0,
            "points": pts.iter().map(|(d, p)| json!({"d_cyl": d, "point": p})).collect::<Vec<_>>(),
        }));
    }
    nem = nem
        .line(Line::new("1.5", vec![(1.5, 0.0), (1.5, 1.0)]).dashed(true))
        .line(Line::new("0.75", vec![(0.75, 0.0), (0.75, 1.0)]).dashed(true));
    let fig = Figure::new(
        format!(
            "Spherocylinders in a hard cylinder, N = {n} or more (final length >= 3 particle lengths), {}", crate::studies::stats::runs_per_point(runs, true)
        ),
        2,
    )
    .panel(phi_star)
    .panel(c_star)
    .panel(nem)
    .panel(extrap);
    let path = out.join("cylinder_confinement.svg");
    save(&path, &fig.to_svg(560.0, 420.0))?;
    crate::studies::bench::say(
        json!({"charts": [path.display().to_string()], "particles": n, "runs": runs, "sweeps": summary}),
    )
}

/// Wedge confinement (thesis figs. 2.12-2.16; target V-PK-17): phi*, \<C\>* against l_w / l_w,min and
/// the wall-aligned fraction against the aspect ratio.
pub fn chart_wedge(out: &Path, quick: bool) -> Result<(), BenchError> {
    out_dir(out)?;
    let (n, runs) = sizes(quick, 120, 2);
    let deg = std::f64::consts::PI / 180.0;
    let angles: Vec<f64> = if quick {
        vec![9.0, 45.0]
    } else {
        vec![9.0, 30.0, 45.0]
    };
    let lambdas: Vec<f64> = if quick {
        vec![1.25, 3.0]
    } else {
        vec![1.25, 2.0, 3.0, 5.0]
    };
    let ratios: Vec<f64> = if quick {
        vec![2.0]
    } else {
        vec![1.5, 3.0, 5.0]
    };
    let mut phi_star =
        Chart::new("phi* = (phi - phi_min) / (phi_periodic - phi_min), alpha = 9 deg")
            .x_label("l_w / l_w,min")
            .y_label("phi*");
    let mut c_star = Chart::new("<C>*, alpha = 9 deg")
        .x_label("l_w / l_w,min")
        .y_label("<C>*");
    let mut align = Chart::new("wall-aligned fraction (4 deg, within 1 D), largest l_w")
        .x_label("aspect ratio")
        .y_label("f_align");
    let mut summary = Vec::new();
    // every run of the sweep (and the orientation map's) in one parallel pass
    let mut specs: Vec<PointSpec> = lambdas
        .iter()
        .map(|&l| {
            PointSpec::fire(
                format!("aspect {l} periodic"),
                n,
                rod(l),
                ContainerSpec::PeriodicBox {},
                0.05,
                runs,
            )
        })
        .collect();
    for &a in &angles {
        for &l in &lambdas {
            let lmin = wedge_min_length(0.5, l - 1.0, a * deg);
            for &r in &ratios {
                specs.push(PointSpec::fire(
                    format!("alpha {a} aspect {l} l/lmin {r}"),
                    n,
                    rod(l),
                    ContainerSpec::Wedge {
                        angle: a * deg,
                        length: r * lmin,
                    },
                    0.05,
                    runs,
                ));
            }
        }
    }
    let map_ratio = *ratios.last().unwrap_or(&3.0);
    let (computed, map_run) = rayon::join(
        || points(&specs),
        || magsep_systems::par::on_one_thread(|| orientation_run(n, angles[0] * deg, map_ratio)),
    );
    let mut computed = computed?.into_iter();
    let mut next = || {
        computed
            .next()
            .ok_or_else(|| BenchError::Runtime("wedge sweep: a point is missing".into()))
    };
    let periodic: Vec<Point> = lambdas.iter().map(|_| next()).collect::<Result<_, _>>()?;
    for &a in &angles {
        let mut fa = Vec::new();
        for (k, &l) in lambdas.iter().enumerate() {
            let lmin = wedge_min_length(0.5, l - 1.0, a * deg);
            let phimin = wedge_min_packing_fraction(0.5, l - 1.0, a * deg);
            let mut pts = Vec::new();
            for &r in &ratios {
                pts.push((r, next()?));
            }
            if a == angles[0] {
                let per = &periodic[k];
                phi_star = phi_star.series(Series::new(
                    format!("aspect {l}"),
                    pts.iter()
                        .map(|(r, p)| {
                            (
                                *r,
                                rescaled_packing_fraction_wedge(p.phi.mean, per.phi.mean, phimin),
                            )
                        })
                        .collect::<Vec<_>>(),
                ));
                c_star = c_star.series(Series::new(
                    format!("aspect {l}"),
                    pts.iter()
                        .map(|(r, p)| (*r, rescaled_contacts(p.contacts.mean, per.contacts.mean)))
                        .collect::<Vec<_>>(),
                ));
            }
            if let Some((_, p)) = pts.last() {
                fa.push((l, p.aligned.mean, half_width(&p.aligned)));
            }
            summary.push(json!({"angle_deg": a, "aspect_ratio": l, "l_w_min": lmin, "phi_l_w_min": phimin, "periodic": periodic[k], "points": pts.iter().map(|(r, p)| json!({"l_w_over_min": r, "point": p})).collect::<Vec<_>>()}));
        }
        align = align.series(
            Series::new(
                format!("alpha = {a} deg"),
                fa.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(),
            )
            .y_err(fa.iter().map(|p| p.2).collect::<Vec<_>>()),
        );
    }
    align = align
        .line(Line::new("thesis: 0.5 (aspect <= 2)", vec![(1.0, 0.5), (2.0, 0.5)]).dashed(true))
        .line(Line::new("thesis: > 0.8 (aspect >= 3)", vec![(3.0, 0.8), (5.0, 0.8)]).dashed(true));
    let fig = Figure::new(
        format!("Spherocylinders in a hard wedge, N = {n} or more (final width >= 3 particle lengths), {}", crate::studies::stats::runs_per_point(runs, false)),
        3,
    )
    .panel(phi_star)
    .panel(c_star)
    .panel(align);
    let path = out.join("wedge_confinement.svg");
    save(&path, &fig.to_svg(520.0, 420.0))?;
    let (hpath, histogram) = orientation_map(out, angles[0] * deg, map_ratio, &map_run?)?;
    crate::studies::bench::say(
        json!({"charts": [path.display().to_string(), hpath.display().to_string()], "particles": n, "runs": runs, "sweeps": summary, "orientation_density": histogram}),
    )
}

/// The run of fig. 2.15: aspect-3 rods in the wedge of angle `alpha` [rad] and length
/// `ratio` l_w,min (one run, seed 1).
fn orientation_run(
    n: usize,
    alpha: f64,
    ratio: f64,
) -> Result<crate::studies::bench::PackingRun, BenchError> {
    let l = 3.0;
    let spec = ContainerSpec::Wedge {
        angle: alpha,
        length: ratio * wedge_min_length(0.5, l - 1.0, alpha),
    };
    let mut cfg = magsep_components::packing::PackingConfig::defaults_for(n, 1.0);
    cfg.initial_packing_fraction = 0.05;
    let n = super::particles_for(&spec, rod(l), n);
    crate::studies::bench::packing_run_in(n, rod(l), &cfg, 1, f64::INFINITY, &spec)
}

/// Fig. 2.15: the orientation density of the rods of [`orientation_run`].
fn orientation_map(
    out: &Path,
    alpha: f64,
    ratio: f64,
    run: &crate::studies::bench::PackingRun,
) -> Result<(std::path::PathBuf, serde_json::Value), BenchError> {
    let l = 3.0;
    let axes: Vec<glam::DVec3> = (0..run.state.len()).map(|i| run.state.axis(i)).collect();
    let h = orientation_histogram(&axes, 10, 9);
    let d = h.density();
    let pb = h.phi_bins();
    let rows: Vec<Vec<f64>> = (0..d.len() / pb)
        .map(|i| d[i * pb..(i + 1) * pb].to_vec())
        .collect();
    let deg = alpha.to_degrees();
    let map = Heatmap::new(
        format!("Orientation density, aspect 3, alpha = {deg:.0} deg, l_w = {ratio} l_w,min (1 = isotropic)"),
        (0.0, 90.0),
        (0.0, 1.0),
        rows,
    )
    .x_label("azimuth phi from x in the xy plane [deg]")
    .y_label("cos theta from the periodic axis z")
    .colour_label("density");
    let path = out.join("wedge_orientations.svg");
    save(&path, &map.to_svg(640.0, 480.0))?;
    Ok((
        path,
        json!({"aspect_ratio": l, "angle_deg": deg, "cos_theta_edges": h.cos_theta_edges, "phi_edges_rad": h.phi_edges, "counts": h.counts}),
    ))
}

/// Superballs (thesis figs. 4.5-4.6; target V-PK-18): phi, \<C\>, S_4 and the nematic order against
/// the exponent, with the thesis's values.
pub fn chart_superballs(out: &Path, quick: bool) -> Result<(), BenchError> {
    out_dir(out)?;
    let (n, runs) = if quick { (40, 1) } else { (60, 2) };
    let exponents: Vec<f64> = if quick {
        vec![2.0, 3.0]
    } else {
        vec![2.0, 2.5, 3.0, 4.0, 5.0]
    };
    let mut fire = Vec::new();
    let mut revised = Vec::new();
    for &g in &exponents {
        let shape = magsep_components::shape::Shape::Superquadric {
            semi_axes: glam::DVec3::splat(0.5),
            exponents: glam::DVec3::splat(g),
        };
        let cube = ContainerSpec::PeriodicBox {};
        fire.push((
            g,
            point(
                format!("superball g = {g}, FIRE"),
                n,
                shape,
                &cube,
                0.05,
                runs,
            )?,
        ));
        revised.push((
            g,
            point_with(
                format!("superball g = {g}, revised"),
                n,
                shape,
                &cube,
                0.05,
                runs,
                super::Scheme::Revised,
            )?,
        ));
    }
    let series =
        |pts: &[(f64, Point)], f: fn(&Point) -> (f64, f64)| -> (Vec<(f64, f64)>, Vec<f64>) {
            (
                pts.iter().map(|(g, p)| (*g, f(p).0)).collect(),
                pts.iter().map(|(_, p)| f(p).1).collect(),
            )
        };
    let (phi, phie) = series(&fire, |p| (p.phi.mean, half_width(&p.phi)));
    let (c, ce) = series(&fire, |p| (p.contacts.mean, half_width(&p.contacts)));
    let (s4, _) = series(&fire, |p| (p.cubatic.mean, half_width(&p.cubatic)));
    let (rphi, _) = series(&revised, |p| (p.phi.mean, half_width(&p.phi)));
    let (rc, _) = series(&revised, |p| (p.contacts.mean, half_width(&p.contacts)));
    let (rs4, _) = series(&revised, |p| (p.cubatic.mean, half_width(&p.cubatic)));
    // S_4 of isotropic orientations is biased upwards by about 1/sqrt(N): the floor of this N
    let floor = magsep_systems::analysis::cubatic::isotropic_floor(n, 16, 7);
    let fig = Figure::new(
        format!(
            "Superballs, N = {n}, periodic, {}",
            crate::studies::stats::runs_per_point(runs, false)
        ),
        3,
    )
    .panel(
        Chart::new("packing fraction")
            .x_label("exponent g")
            .y_label("phi")
            .series(Series::new("FIRE (jammed)", phi).y_err(phie))
            .series(Series::new("revised (thesis scheme)", rphi).style(Style::Dashed))
            .line(Line::new("thesis, g = 2: 0.61", vec![(2.0, 0.61), (2.3, 0.61)]).dashed(true))
            .line(Line::new("RCP 0.64", vec![(2.0, 0.64), (5.0, 0.64)]).dashed(true)),
    )
    .panel(
        Chart::new("mean contact number")
            .x_label("exponent g")
            .y_label("<C> (extrapolated)")
            .series(Series::new("FIRE", c).y_err(ce))
            .series(Series::new("revised (thesis)", rc).style(Style::Dashed))
            .line(
                Line::new(
                    "thesis: 5.84 - 1.25 (g - 2)",
                    vec![(2.0, 5.84), (5.0, 2.09)],
                )
                .dashed(true),
            ),
    )
    .panel(
        Chart::new("cubatic order S_4")
            .x_label("exponent g")
            .y_label("S_4")
            .series(Series::new("FIRE", s4))
            .series(Series::new("revised (thesis)", rs4).style(Style::Dashed))
            .line(
                Line::new(
                    format!("isotropic floor (N = {n})"),
                    vec![(2.0, floor), (5.0, floor)],
                )
                .dashed(true),
            ),
    );
    let path = out.join("superballs.svg");
    save(&path, &fig.to_svg(520.0, 420.0))?;
    crate::studies::bench::say(
        json!({"charts": [path.display().to_string()], "particles": n, "runs": runs, "isotropic_s4_floor": floor, "fire": fire.iter().map(|(g, p)| json!({"exponent": g, "point": p})).collect::<Vec<_>>(), "revised": revised.iter().map(|(g, p)| json!({"exponent": g, "point": p})).collect::<Vec<_>>()}),
    )
}
