//! Smoke tests of `magsep bench brownian` and `magsep chart brownian-cost`: tiny sizes through
//! the library API (rows well formed, rates positive, exponents finite; the chart writes a
//! valid SVG and its JSON data).

use magsep::studies::bench_brownian::{
    BrownianBenchSizes, CostChartSizes, bench_brownian_with, chart_brownian_cost_with,
};
use magsep::systems::brownian::hydro::MobilityMethod;

fn positive(row: &serde_json::Value, key: &str) -> f64 {
    let v = row[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {row}"));
    assert!(v.is_finite() && v > 0.0, "{key} = {v} in {row}");
    v
}

#[test]
fn bench_rows_are_well_formed_with_positive_rates() {
    let sizes = BrownianBenchSizes {
        pipeline_n: 200,
        warmup_steps: 1,
        pipeline_seconds: 0.05,
        threads: vec![1, 2],
        hi_sizes: vec![20, 40],
        hi_methods: vec![
            MobilityMethod::Cholesky,
            MobilityMethod::Tea,
            MobilityMethod::Krylov,
        ],
        spectral_sizes: vec![60],
        mirror_ncell: 4,
    };
    let rows = bench_brownian_with(&sizes, true).unwrap();
    // every row survives a JSON round trip
    for r in &rows {
        let back: serde_json::Value = serde_json::from_str(&r.to_string()).unwrap();
        assert_eq!(&back, r);
        assert_eq!(r["bench"], "brownian");
    }
    let case =
        |c: &str| -> Vec<&serde_json::Value> { rows.iter().filter(|r| r["case"] == c).collect() };
    let pipe = case("free_draining_dipoles");
    assert_eq!(
        pipe.len(),
        6,
        "fixed, adaptive and multirate at 1 and 2 threads"
    );
    for r in &pipe {
        positive(r, "particle_steps_per_s");
        positive(r, "particle_steps_per_s_per_thread");
        assert_eq!(r["n"], 200);
        assert!(r["steps"].as_u64().unwrap() >= 3);
        let sub = positive(r, "substeps_per_step");
        let per_particle = positive(r, "particle_substeps_per_step");
        if r["step_control"] == "fixed" {
            assert_eq!(sub, 1.0);
            assert_eq!(per_particle, 1.0);
        } else {
            assert!(sub >= 2.0);
            assert!(
                per_particle >= 2.0 && per_particle <= sub * (1.0 + 1e-12),
                "{r}"
            );
        }
    }
    let mirror = case("lammps_mirror");
    assert_eq!(mirror.len(), 2, "1 and 2 threads");
    for r in &mirror {
        positive(r, "particle_steps_per_s");
        assert_eq!(r["n"], 64);
        assert_eq!(r["peer"]["impl"], "lammps");
    }
    let nb = case("dipole_neighbours");
    assert_eq!(nb.len(), 1);
    positive(nb[0], "mean_neighbours_start");
    let hi = case("hi");
    assert_eq!(hi.len(), 6);
    for r in &hi {
        positive(r, "s_per_step");
        positive(r, "steps_per_s");
    }
    let spectral = case("hi_spectral");
    assert_eq!(spectral.len(), 2, "1 and 2 threads");
    for r in &spectral {
        positive(r, "steps_per_s");
        assert_eq!(r["n"], 60);
        let e = r["product_error"].as_f64().unwrap();
        assert!(e <= r["ewald_tolerance"].as_f64().unwrap(), "{r}");
    }
    let ex = case("hi_exponent");
    assert_eq!(ex.len(), 3);
    for r in &ex {
        assert!(r["exponent"].as_f64().unwrap().is_finite(), "{r}");
    }
}

#[test]
fn cost_chart_writes_svg_and_data() {
    let dir = std::env::temp_dir().join(format!("magsep_bench_brownian_{}", std::process::id()));
    let sizes = CostChartSizes {
        sizes: vec![10, 20],
        volume_fractions: vec![1e-2, 5e-2],
        krylov_tolerances: vec![1e-2, 1e-6],
        min_time: 0.0,
    };
    let summary = chart_brownian_cost_with(&dir, &sizes).unwrap();
    let svg = std::fs::read_to_string(dir.join("brownian_mobility_cost.svg")).unwrap();
    assert!(svg.trim_start().starts_with("<svg") || svg.trim_start().starts_with("<?xml"));
    assert!(svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("Krylov") && svg.contains("spectral Ewald"));
    let data: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("brownian_mobility_cost.json")).unwrap(),
    )
    .unwrap();
    let pts = data["points"].as_array().unwrap();
    // 2 fractions x 2 sizes x (free draining, Cholesky, TEA, 2 Krylov and 2 spectral Ewald
    // tolerances)
    assert_eq!(pts.len(), 28);
    for p in pts {
        assert!(p["cost_s"].as_f64().unwrap() > 0.0, "{p}");
        let e = p["error"].as_f64().unwrap();
        assert!(e.is_finite() && e >= 0.0, "{p}");
        if p["method"] == "cholesky" {
            assert!(e < 1e-10, "{p}");
        }
        if p["method"] == "free_draining" {
            assert!(e > 1e-4, "{p}");
        }
        if p["method"] == "spectral_ewald" && p["tolerance"].as_f64().unwrap() <= 1e-6 {
            assert!(e < 1e-4, "{p}");
        }
    }
    assert_eq!(summary["points"].as_array().unwrap().len(), 28);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn chart_brownian_quick_writes_every_figure() {
    let dir = std::env::temp_dir().join(format!("magsep-chart-brownian-{}", std::process::id()));
    magsep::studies::brownian_chart::chart_brownian(&dir, true).unwrap();
    for name in [
        "brownian_angle_curves.svg",
        "brownian_final_vs_angle.svg",
        "brownian_aspect.svg",
        "brownian_concentrated.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{name}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
