//! The cylinder field kernel against the project's independent reference: 40-digit mpmath
//! quadrature of the surface-charge integrals (`tests/python/cylinder_field_reference.py`,
//! output committed as `tests/data/cylinder_field_reference.csv`).

use std::collections::BTreeMap;

use glam::DVec3;
use magsep_systems::field::{CylinderSource, EXACT};

struct Row {
    case: String,
    radius: f64,
    half_length: f64,
    m: DVec3,
    p: DVec3,
    h: DVec3,
    inside: bool,
}

fn rows() -> Vec<Row> {
    let text = include_str!("../data/cylinder_field_reference.csv");
    let mut lines = text.lines();
    let header = lines.next().expect("header");
    assert_eq!(
        header,
        "case,radius,half_length,mx,my,mz,x,y,z,hx,hy,hz,inside"
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let n = |i: usize| f[i].trim().parse::<f64>().expect("number");
            Row {
                case: f[0].to_string(),
                radius: n(1),
                half_length: n(2),
                m: DVec3::new(n(3), n(4), n(5)),
                p: DVec3::new(n(6), n(7), n(8)),
                h: DVec3::new(n(9), n(10), n(11)),
                inside: n(12) > 0.5,
            }
        })
        .collect()
}

/// Documented accuracy: relative to |H|, with an absolute floor of a few ulps of |M| (where
/// the field is tiny compared with M, e.g. beside the middle of a long axially magnetised rod,
/// |H| ~ M R²/L², the two end terms cancel and only the absolute error is meaningful).
fn tolerance(case: &str, row: &Row) -> f64 {
    let floor = 4e-16 * row.m.length() / row.h.length().max(1e-300);
    let rel = match case {
        // flat discs: the two end terms nearly cancel, ~1e-16 R/L
        "aspect" if row.half_length < 0.1 * row.radius => 5e-15 * row.radius / row.half_length,
        _ => 1e-12,
    };
    rel + floor
}

#[test]
fn closed_form_agrees_with_high_precision_quadrature() {
    let rows = rows();
    assert!(rows.len() > 200, "{} rows", rows.len());
    let mut worst: BTreeMap<String, f64> = BTreeMap::new();
    let mut failures = vec![];
    for r in &rows {
        let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, r.radius, r.half_length, r.m);
        let f = src.field(r.p, EXACT);
        // B = μ0 (H + M) exactly inside
        assert_eq!(src.contains(r.p), r.inside, "{} {}", r.case, r.p);
        let m_in = f.b / magsep_systems::field::MU0 - f.h;
        let want = if r.inside { r.m } else { DVec3::ZERO };
        assert!((m_in - want).length() <= 1e-9 * (f.h.length() + r.m.length()));
        let err = (f.h - r.h).length() / r.h.length().max(1e-300);
        let w = worst.entry(r.case.clone()).or_insert(0.0);
        *w = w.max(err);
        if err > tolerance(&r.case, r) {
            failures.push(format!(
                "{} L={} M={} p={}: err {err:.2e} (got {} want {})",
                r.case, r.half_length, r.m, r.p, f.h, r.h
            ));
        }
    }
    for (case, w) in &worst {
        println!("{case:<20} worst relative error {w:.2e}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
