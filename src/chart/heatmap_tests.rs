//! Heatmap tests: XML output, contours, scales, masks, determinism.

use super::draw::{CONTOUR, MASKED, NO_DATA};
use super::*;
use crate::chart::tests::{count, texts};

/// `#RRGGBB` as plotters writes it.
fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// Parses `svg` as XML.
fn doc(svg: &str) -> roxmltree::Document<'_> {
    match roxmltree::Document::parse(svg) {
        Ok(d) => d,
        Err(e) => panic!("not XML: {e}"),
    }
}

/// Vertices of every contour polyline (dark stroke, not the colour bar mark).
fn contour_paths(svg: &str) -> Vec<Vec<(f64, f64)>> {
    doc(svg)
        .descendants()
        .filter(|n| {
            n.has_tag_name("polyline") && n.attribute("stroke") == Some(hex(CONTOUR).as_str())
        })
        .map(|n| {
            n.attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect()
        })
        .collect()
}

/// `(x, y, width, height)` of every rect filled with `fill`.
fn rects(svg: &str, fill: &str) -> Vec<(f64, f64, f64, f64)> {
    let num = |n: &roxmltree::Node<'_, '_>, a: &str| {
        n.attribute(a)
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    };
    doc(svg)
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some(fill))
        .map(|n| {
            (
                num(&n, "x"),
                num(&n, "y"),
                num(&n, "width"),
                num(&n, "height"),
            )
        })
        .collect()
}

/// `f(x, y)` sampled at the cell centres of an `n` x `n` grid on `[a, b]^2`.
fn sample(n: usize, (a, b): (f64, f64), f: impl Fn(f64, f64) -> f64) -> Vec<Vec<f64>> {
    let c = |k: usize| a + (k as f64 + 0.5) * (b - a) / n as f64;
    (0..n)
        .map(|j| (0..n).map(|i| f(c(i), c(j))).collect())
        .collect()
}

fn radial() -> Heatmap {
    Heatmap::new(
        "r²",
        (-1.0, 1.0),
        (-1.0, 1.0),
        sample(50, (-1.0, 1.0), |x, y| x * x + y * y),
    )
    .x_label("x [m]")
    .y_label("y [m]")
    .colour_label("r² [m²]")
    .contour(0.25, "r = 0.5")
}

#[test]
fn viridis_anchors() {
    // plotters' viridis: matplotlib's end points, NaN and overshoot clamped.
    assert_eq!(viridis(0.0), RGBColor(0x44, 0x01, 0x54));
    assert_eq!(viridis(2.0), viridis(1.0));
    assert_eq!(viridis(f64::NAN), viridis(0.0));
    let (lo, hi) = (viridis(0.0), viridis(1.0));
    assert!(hi.1 > 200 && hi.0 > 200 && lo.2 > lo.1, "{hi:?} {lo:?}");
}

#[test]
fn well_formed_and_labelled() {
    let svg = Heatmap {
        title: "a < b & c".into(),
        ..radial()
    }
    .to_svg(600.0, 500.0);
    let t = texts(&svg);
    for want in ["a < b & c", "r = 0.5", "r² [m²]", "x [m]", "y [m]"] {
        assert!(t.iter().any(|s| s == want), "{want:?} in {t:?}");
    }
    assert!(
        !rects(&svg, &hex(viridis(0.0))).is_empty(),
        "minimum colour present"
    );
    assert!(
        !rects(&svg, &hex(viridis(1.0))).is_empty(),
        "maximum colour present"
    );
}

#[test]
fn radial_contour_segments_lie_on_the_circle() {
    let hm = radial();
    let segs = hm.contour_segments(0.25);
    assert!(segs.len() >= 40, "{} segments", segs.len());
    let cell = 2.0 / 50.0;
    let mut quadrants = [0; 4];
    for &(a, b) in &segs {
        for (x, y) in [a, b] {
            let r = x.hypot(y);
            assert!((r - 0.5).abs() <= cell, "vertex ({x}, {y}) at r = {r}");
            quadrants[usize::from(x > 0.0) + 2 * usize::from(y > 0.0)] += 1;
        }
    }
    assert!(quadrants.iter().all(|&q| q > 10), "{quadrants:?}");
    assert!(hm.contour_segments(5.0).is_empty());
    assert!(hm.contour_segments(f64::NAN).is_empty());
}

#[test]
fn radial_contour_in_the_svg_is_one_closed_circle() {
    let svg = radial().to_svg(600.0, 500.0);
    let paths = contour_paths(&svg);
    // One closed loop plus the legend sample.
    let loops: Vec<_> = paths.iter().filter(|p| p.len() > 3).collect();
    assert_eq!(loops.len(), 1, "{}", paths.len());
    let pts = loops[0];
    assert_eq!(pts.first(), pts.last(), "closed");
    assert!(pts.len() >= 40);
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
    let ext = |v: &[f64]| {
        v.iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)))
    };
    let ((x0, x1), (y0, y1)) = (ext(&xs), ext(&ys));
    let (cx, cy, r) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0, (x1 - x0) / 2.0);
    assert!(
        ((y1 - y0) / 2.0 - r).abs() <= 2.0,
        "round, not squashed: {x0}..{x1} x {y0}..{y1}"
    );
    for &(x, y) in pts {
        assert!(
            ((x - cx).hypot(y - cy) - r).abs() <= 0.06 * r + 1.0,
            "pixel ({x}, {y})"
        );
    }
}

#[test]
fn linear_ramp_contour_is_exact() {
    // Value = x: the level-0.31 contour is the vertical line x = 0.31.
    let hm = Heatmap::new("", (0.0, 1.0), (0.0, 2.0), sample(20, (0.0, 1.0), |x, _| x));
    let segs = hm.contour_segments(0.31);
    assert_eq!(segs.len(), 19);
    for &(a, b) in &segs {
        assert!(
            (a.0 - 0.31).abs() < 1e-12 && (b.0 - 0.31).abs() < 1e-12,
            "{a:?} {b:?}"
        );
    }
    let ys: f64 = segs.iter().map(|(a, b)| (a.1 - b.1).abs()).sum();
    assert!(
        (ys - 1.9).abs() < 1e-9,
        "covers the cell-centre span, got {ys}"
    );
}

#[test]
fn saddles_and_several_levels() {
    let checker: Vec<Vec<f64>> = (0..6)
        .map(|j| (0..6).map(|i| ((i + j) % 2) as f64).collect())
        .collect();
    let hm = Heatmap::new("", (0.0, 1.0), (0.0, 1.0), checker)
        .contour(0.5, "half")
        .contour(0.25, "quarter")
        .contour(0.75, "");
    assert_eq!(hm.contour_segments(0.5).len(), 2 * 25);
    let svg = hm.to_svg(400.0, 400.0);
    // Solid first level, dashed (many short pieces) for the others.
    assert!(contour_paths(&svg).len() > 3 * 25);
    let t = texts(&svg);
    assert!(t.iter().any(|s| s == "half") && t.iter().any(|s| s == "quarter"));
}

#[test]
fn nan_and_inf_cells_are_no_data() {
    let mut v = sample(10, (0.0, 1.0), |x, y| x + y);
    v[3][4] = f64::NAN;
    v[5][5] = f64::INFINITY;
    v[0][0] = f64::NEG_INFINITY;
    v[9].truncate(3);
    let svg = Heatmap::new("nan", (0.0, 1.0), (f64::NAN, 1.0), v)
        .contour(0.7, "c")
        .contour(f64::NAN, "nan level")
        .range(f64::NAN, 1.5)
        .to_svg(500.0, 400.0);
    for bad in ["NaN", "inf"] {
        assert!(!svg.contains(bad), "{bad} in output");
    }
    assert!(!rects(&svg, &hex(NO_DATA)).is_empty());
    assert!(
        texts(&svg).iter().any(|s| s == "no data"),
        "legend explains the grey cells"
    );
}

#[test]
fn log_scale_with_zeros_and_negatives() {
    let v = sample(30, (-1.0, 1.0), |x, y| {
        if x < -0.5 {
            0.0
        } else if y < -0.5 {
            -1.0
        } else {
            10f64.powf(3.0 * (x + y))
        }
    });
    let hm = Heatmap::new("log", (-1.0, 1.0), (-1.0, 1.0), v.clone())
        .scale(ColourScale::Log)
        .colour_label("|B| [T]")
        .contour(1.0, "1 T");
    let svg = hm.to_svg(640.0, 480.0);
    assert!(!rects(&svg, &hex(NO_DATA)).is_empty());
    let t = texts(&svg);
    for decade in ["0.01", "1", "100", "1e4"] {
        assert!(
            t.iter().any(|s| s == decade),
            "decade label {decade} in {t:?}"
        );
    }
    for hm in [
        Heatmap::new("", (0.0, 1.0), (0.0, 1.0), v)
            .scale(ColourScale::Log)
            .range(-1.0, 10.0),
        Heatmap::new("", (0.0, 1.0), (0.0, 1.0), vec![vec![0.0; 4]; 4]).scale(ColourScale::Log),
        Heatmap::new("", (0.0, 1.0), (0.0, 1.0), vec![vec![-3.0; 4]; 4])
            .scale(ColourScale::Log)
            .range(0.0, -1.0),
    ] {
        let svg = hm.to_svg(300.0, 300.0);
        doc(&svg);
        assert!(!svg.contains("NaN"));
    }
}

#[test]
fn mask_is_dark_and_excluded_from_the_range() {
    let v = sample(20, (-1.0, 1.0), |x, y| {
        if x.hypot(y) < 0.3 { 1e9 } else { x + 5.0 }
    });
    let hm = Heatmap::new("", (-1.0, 1.0), (-1.0, 1.0), v).mask(|x, y| x.hypot(y) < 0.3);
    let svg = hm.to_svg(500.0, 400.0);
    assert!(!rects(&svg, &hex(MASKED)).is_empty());
    assert!(
        rects(&svg, &hex(NO_DATA)).is_empty(),
        "masked cells are not 'no data'"
    );
    let t = texts(&svg);
    assert!(
        !t.iter().any(|s| s.contains("e8") || s.contains("e9")),
        "the range ignores masked cells"
    );
    assert!(t.iter().any(|s| s == "5.0" || s == "5"), "{t:?}");
    assert!(format!("{hm:?}").contains("mask: true"));
}

#[test]
fn empty_and_degenerate_inputs_do_not_panic() {
    let cases = [
        Heatmap::new("empty", (0.0, 1.0), (0.0, 1.0), Vec::new()),
        Heatmap::new("empty rows", (0.0, 1.0), (0.0, 1.0), vec![Vec::new(); 3]),
        Heatmap::new(
            "one",
            (f64::NAN, f64::INFINITY),
            (1.0, 1.0),
            vec![vec![7.0]],
        )
        .contour(7.0, "x"),
        Heatmap::new(
            "reversed",
            (1.0, 0.0),
            (5.0, -5.0),
            sample(5, (0.0, 1.0), |x, y| x * y),
        ),
        Heatmap::new(
            "huge",
            (-1e300, 1e300),
            (0.0, 1e-300),
            vec![vec![1e300, -1e300], vec![0.0, 1.0]],
        ),
        Heatmap::new("flat", (0.0, 1e4), (0.0, 1.0), vec![vec![0.0; 3]; 2]).range(2.0, 2.0),
    ];
    for hm in &cases {
        for (w, h) in [
            (640.0, 480.0),
            (10.0, 10.0),
            (f64::NAN, -1.0),
            (5000.0, 80.0),
        ] {
            let svg = hm.to_svg(w, h);
            doc(&svg);
            assert!(!svg.contains("NaN") && !svg.contains("inf"), "{hm:?}");
        }
    }
    let svg = cases[0].to_svg(400.0, 300.0);
    assert!(texts(&svg).iter().any(|s| s == "no data"));
    assert!(cases[0].contour_segments(0.0).is_empty());
}

#[test]
fn plot_keeps_the_data_aspect_ratio() {
    // Two columns of cells over x in [0, 2], three rows over y in [0, 1].
    let hm = Heatmap::new("", (0.0, 2.0), (0.0, 1.0), vec![vec![1.0, 2.0]; 3]);
    for (w, h) in [(800.0, 800.0), (500.0, 900.0), (1200.0, 300.0)] {
        let svg = hm.to_svg(w, h);
        let cells: Vec<_> = [viridis(0.0), viridis(1.0)]
            .iter()
            .flat_map(|c| rects(&svg, &hex(*c)))
            .filter(|r| r.2 < 0.5 * w)
            .collect();
        let x0 = cells.iter().map(|r| r.0).fold(f64::MAX, f64::min);
        let x1 = cells.iter().map(|r| r.0 + r.2).fold(f64::MIN, f64::max);
        let y0 = cells.iter().map(|r| r.1).fold(f64::MAX, f64::min);
        let y1 = cells.iter().map(|r| r.1 + r.3).fold(f64::MIN, f64::max);
        let (pw, ph) = (x1 - x0, y1 - y0);
        assert!((pw / ph - 2.0).abs() < 0.05, "{w}x{h}: {pw} x {ph}");
        assert!(x0 >= 0.0 && x1 <= w);
    }
}

#[test]
fn large_grids_stay_small_and_merge_runs() {
    let hm = Heatmap::new(
        "big",
        (-1.0, 1.0),
        (-1.0, 1.0),
        sample(200, (-1.0, 1.0), |x, y| x.sin() * y.cos()),
    )
    .contour(0.2, "0.2");
    let svg = hm.to_svg(800.0, 700.0);
    doc(&svg);
    assert!(svg.len() < 6_000_000, "{} bytes", svg.len());
    // A field constant along x: one merged rect per row (plus bar and frames).
    let rows = Heatmap::new(
        "",
        (0.0, 1.0),
        (0.0, 1.0),
        sample(200, (0.0, 1.0), |_, y| y),
    )
    .to_svg(600.0, 600.0);
    let cells = rows.matches("<rect").count();
    assert!((200..300).contains(&cells), "{cells} rects");
    assert_eq!(count(&rows, "svg", "width", "600"), 1);
}

#[test]
fn output_is_deterministic() {
    let make = || {
        radial()
            .contour(0.5, "second")
            .mask(|x, y| x.hypot(y) < 0.1)
            .scale(ColourScale::Log)
            .to_svg(640.0, 480.0)
    };
    let a = make();
    assert_eq!(a, make());
    assert_eq!(a.as_bytes(), make().as_bytes());
}

#[test]
fn row_zero_is_at_the_bottom() {
    // Value = y: dark (low) cells at the bottom, yellow at the top.
    let hm = Heatmap::new(
        "",
        (0.0, 1.0),
        (10.0, 20.0),
        vec![vec![0.0; 3], vec![1.0; 3]],
    );
    let svg = hm.to_svg(400.0, 400.0);
    let low = rects(&svg, &hex(viridis(0.0)))[0].1;
    let high = rects(&svg, &hex(viridis(1.0)))[0].1;
    assert!(low > high, "row 0 drawn below row 1: {low} vs {high}");
    let three = vec![vec![0.0], vec![1.0], vec![2.0]];
    let masked = Heatmap::new("", (0.0, 1.0), (10.0, 20.0), three)
        .mask(|_, y| y > 18.0)
        .to_svg(400.0, 400.0);
    let mask_y = rects(&masked, &hex(MASKED))[0].1;
    assert!(
        mask_y < rects(&masked, &hex(viridis(0.0)))[0].1,
        "mask hits the top row"
    );
    let segs = Heatmap::new("", (0.0, 1.0), (0.0, 1.0), sample(10, (0.0, 1.0), |_, y| y))
        .contour_segments(0.42);
    assert_eq!(segs.len(), 9);
    assert!(
        segs.iter()
            .all(|(a, b)| (a.1 - 0.42).abs() < 1e-12 && (b.1 - 0.42).abs() < 1e-12)
    );
}

#[test]
fn a_long_heatmap_title_wraps_onto_lines_instead_of_losing_its_end() {
    let title = "Capture probability around one fibre (thesis fig. 6.9, 30 runs; here 10 runs); \
                 reduced: adaptive steps (tol 0.01 R), no hydrodynamic interactions";
    let svg = Heatmap {
        title: title.into(),
        ..radial()
    }
    .to_svg(480.0, 400.0);
    let t = texts(&svg);
    let joined = t.join(" ");
    for w in title.split(' ') {
        assert!(joined.contains(w), "{w} missing from {t:?}");
    }
    assert!(!t.iter().any(|s| s.ends_with('…')), "{t:?}");
    let lines = t
        .iter()
        .filter(|s| s.len() > 10 && title.contains(s.as_str()))
        .count();
    assert!(lines >= 2, "{t:?}");
    // a title too long for three lines keeps an ellipsis on the last
    let long = [title; 4].join(" ");
    let t = texts(
        &Heatmap {
            title: long,
            ..radial()
        }
        .to_svg(480.0, 400.0),
    );
    assert!(t.iter().any(|s| s.ends_with('…')), "{t:?}");
}
