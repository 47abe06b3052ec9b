//! Heatmap tests: well-formed output, contours, scales, masks, determinism.

use super::draw::{MASKED, NO_DATA};
use super::*;

/// Checks that every element is closed in the right order and that the
/// document is one `<svg>` element ending in a newline.
fn check_balanced(doc: &str) {
    assert!(doc.starts_with("<svg"), "{}", &doc[..doc.len().min(80)]);
    assert!(doc.ends_with("</svg>\n"));
    let mut stack: Vec<&str> = Vec::new();
    let mut rest = doc;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unclosed tag") + start;
        let tag = &rest[start + 1..end];
        assert!(!tag.contains('<'), "'<' inside {tag:?}");
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop(), Some(name), "mismatched </{name}>");
        } else if !tag.ends_with('/') {
            stack.push(tag.split_whitespace().next().unwrap_or(""));
        }
        rest = &rest[end + 1..];
        if stack.is_empty() {
            assert_eq!(rest, "\n", "content after the root element");
        }
    }
    assert!(stack.is_empty(), "unclosed {stack:?}");
    assert_eq!(doc.matches("<g").count(), doc.matches("</g>").count());
}

/// Value of attribute `name` in the first tag of `doc` containing `marker`.
fn attr(doc: &str, marker: &str, name: &str) -> f64 {
    let at = doc.find(marker).expect("marker");
    let start = doc[..at].rfind('<').expect("tag start");
    let tag = &doc[start..start + doc[start..].find('>').expect("tag end")];
    let key = format!(" {name}=\"");
    let v = &tag[tag.find(&key).expect("attribute") + key.len()..];
    v[..v.find('"').expect("quote")].parse().expect("number")
}

/// Vertices of every `<path class="contour" d="...">` (one list per path).
fn contour_paths(doc: &str) -> Vec<Vec<(f64, f64)>> {
    doc.split("<path class=\"contour\" d=\"")
        .skip(1)
        .map(|s| {
            let d = &s[..s.find('"').expect("end of d")];
            let nums: Vec<f64> = d
                .split(['M', 'L', 'Z', ' '])
                .filter(|t| !t.is_empty())
                .map(|t| t.parse().expect("coordinate"))
                .collect();
            assert_eq!(nums.len() % 2, 0);
            nums.chunks(2).map(|c| (c[0], c[1])).collect()
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
    assert_eq!(viridis(0.0), "#440154");
    assert_eq!(viridis(0.5), "#21918c");
    assert_eq!(viridis(1.0), "#fde725");
    assert_eq!(viridis(2.0), "#fde725");
    assert_eq!(viridis(f64::NAN), "#440154");
    assert_eq!(viridis(1.0 / 16.0), "#461365");
}

#[test]
fn well_formed_and_labelled() {
    let svg = Heatmap {
        title: "a < b & c".into(),
        ..radial()
    }
    .to_svg(600.0, 500.0);
    check_balanced(&svg);
    assert!(svg.contains(">a &lt; b &amp; c<"));
    assert!(svg.contains(">r = 0.5<"));
    assert!(svg.contains(">r² [m²]<"));
    assert!(svg.contains("fill=\"#440154\""), "minimum colour present");
    assert!(svg.contains("fill=\"#fde725\""), "maximum colour present");
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
    assert_eq!(paths.len(), 1);
    assert_eq!(
        svg.matches("Z\"").count(),
        2,
        "one closed loop (halo + line)"
    );
    let frame = "fill=\"none\" stroke=\"#444444\"";
    let (x0, y0) = (attr(&svg, frame, "x"), attr(&svg, frame, "y"));
    let (w, h) = (attr(&svg, frame, "width"), attr(&svg, frame, "height"));
    assert!(
        (w - h).abs() < 0.02,
        "square data keep a square plot: {w} x {h}"
    );
    let (cx, cy, cell) = (x0 + w / 2.0, y0 + h / 2.0, w / 50.0);
    let pts = &paths[0];
    assert!(pts.len() >= 40);
    for &(x, y) in pts {
        let r = (x - cx).hypot(y - cy);
        assert!((r - w / 4.0).abs() <= cell, "pixel ({x}, {y}) at r = {r}");
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
    check_balanced(&svg);
    assert_eq!(contour_paths(&svg).len(), 3);
    assert!(svg.contains("stroke-dasharray"), "second level is dashed");
    assert!(svg.contains(">half<") && svg.contains(">quarter<"));
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
    check_balanced(&svg);
    for bad in ["NaN", "inf"] {
        assert!(!svg.contains(bad), "{bad} in output");
    }
    assert!(svg.contains(NO_DATA));
    assert!(svg.contains(">no data<"), "legend explains the grey cells");
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
    check_balanced(&svg);
    assert!(svg.contains(NO_DATA));
    for decade in [">0.01<", ">1<", ">100<", ">1e4<"] {
        assert!(svg.contains(decade), "decade label {decade}");
    }
    // Fixed range, even if partly non-positive, and an all-zero map.
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
        check_balanced(&svg);
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
    check_balanced(&svg);
    assert!(svg.contains(MASKED));
    assert!(!svg.contains(NO_DATA), "masked cells are not 'no data'");
    assert!(
        !svg.contains("1e9") && !svg.contains("1e8"),
        "the range ignores masked cells"
    );
    assert!(svg.contains(">5.0<") || svg.contains(">5<"));
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
            check_balanced(&svg);
            assert!(!svg.contains("NaN") && !svg.contains("inf"), "{hm:?}");
        }
    }
    let svg = cases[0].to_svg(400.0, 300.0);
    assert!(svg.contains(">no data<"));
    assert!(!svg.contains("<rect x=\"0\""), "no cells");
    assert!(cases[0].contour_segments(0.0).is_empty());
}

#[test]
fn plot_keeps_the_data_aspect_ratio() {
    let frame = "fill=\"none\" stroke=\"#444444\"";
    let hm = Heatmap::new("", (0.0, 2.0), (0.0, 1.0), vec![vec![1.0, 2.0]; 3]);
    for (w, h) in [(800.0, 800.0), (500.0, 900.0), (1200.0, 300.0)] {
        let svg = hm.to_svg(w, h);
        let (pw, ph) = (attr(&svg, frame, "width"), attr(&svg, frame, "height"));
        assert!((pw / ph - 2.0).abs() < 0.01, "{w}x{h}: {pw} x {ph}");
        assert!(attr(&svg, frame, "x") >= 0.0 && attr(&svg, frame, "x") + pw <= w);
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
    check_balanced(&svg);
    assert!(svg.len() < 4_000_000, "{} bytes", svg.len());
    // A field constant along x: one merged rect per row.
    let rows = Heatmap::new(
        "",
        (0.0, 1.0),
        (0.0, 1.0),
        sample(200, (0.0, 1.0), |_, y| y),
    )
    .to_svg(600.0, 600.0);
    let cells = rows.matches("<rect").count();
    assert!((200..220).contains(&cells), "{cells} rects");
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
    let low = attr(&svg, "fill=\"#440154\"", "y");
    let high = attr(&svg, "fill=\"#fde725\"", "y");
    assert!(low > high, "row 0 drawn below row 1: {low} vs {high}");
    let three = vec![vec![0.0], vec![1.0], vec![2.0]];
    let masked = Heatmap::new("", (0.0, 1.0), (10.0, 20.0), three)
        .mask(|_, y| y > 18.0)
        .to_svg(400.0, 400.0);
    let mask_y = attr(&masked, &format!("fill=\"{MASKED}\""), "y");
    assert!(
        mask_y < attr(&masked, "fill=\"#440154\"", "y"),
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
