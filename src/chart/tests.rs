//! Whole-chart tests: the SVG parses as XML, series, ticks and legends are
//! there, degenerate input never panics, output is deterministic.

use super::*;

/// Parses `svg` (panics with the error if it is not well-formed XML).
fn parse(svg: &str) -> roxmltree::Document<'_> {
    match roxmltree::Document::parse(svg) {
        Ok(doc) => doc,
        Err(e) => panic!("not XML: {e}\n{}", &svg[..svg.len().min(400)]),
    }
}

/// Trimmed contents of every `<text>` element.
pub(super) fn texts(svg: &str) -> Vec<String> {
    parse(svg)
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

/// Elements named `tag` whose attribute `attr` is `value`.
pub(super) fn count(svg: &str, tag: &str, attr: &str, value: &str) -> usize {
    parse(svg)
        .descendants()
        .filter(|n| n.has_tag_name(tag) && n.attribute(attr) == Some(value))
        .count()
}

fn sample_chart() -> Chart {
    Chart::new("Error vs cost")
        .x_label("cost [s]")
        .y_label("error [-]")
        .x_log(true)
        .y_log(true)
        .series(
            Series::new("a", vec![(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)])
                .y_err(vec![0.5, 0.05, 0.005]),
        )
        .series(Series::new("b", vec![(1.0, 2.0), (10.0, 0.2)]).style(Style::Markers))
        .series(Series::new("c", vec![(3.0, 0.5), (30.0, 0.05)]).style(Style::Dashed))
        .line(Line::new("ref", vec![(1.0, 0.5), (100.0, 0.005)]).dashed(true))
}

#[test]
fn chart_is_xml_with_title_labels_and_legend() {
    let svg = sample_chart().to_svg(640.0, 420.0);
    let doc = parse(&svg);
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    assert_eq!(doc.root_element().attribute("width"), Some("640"));
    let t = texts(&svg);
    for want in [
        "Error vs cost",
        "cost [s]",
        "error [-]",
        "a",
        "b",
        "c",
        "ref",
    ] {
        assert!(
            t.iter().any(|s| s == want),
            "missing text {want:?} in {t:?}"
        );
    }
}

#[test]
fn log_axes_have_decade_ticks() {
    let t = texts(&sample_chart().to_svg(640.0, 420.0));
    for decade in ["1", "10", "100", "0.01", "0.1"] {
        assert!(t.iter().any(|s| s == decade), "decade {decade} in {t:?}");
    }
    // Sub-decade log range: still labelled (plotters' own log ticks give none).
    let narrow = Chart::new("")
        .y_log(true)
        .series(Series::new("s", vec![(0.0, 2.0), (1.0, 8.0)]));
    let t = texts(&narrow.to_svg(500.0, 400.0));
    assert!(
        t.iter().any(|s| s == "5") && t.iter().any(|s| s == "3"),
        "{t:?}"
    );
}

#[test]
fn each_series_is_drawn() {
    let svg = sample_chart().to_svg(640.0, 420.0);
    // "a": one polyline (line) in blue plus the legend sample.
    assert_eq!(count(&svg, "polyline", "stroke", "#0072B2"), 2);
    // Error bars: a vertical line and two caps per point, in blue.
    assert!(count(&svg, "line", "stroke", "#0072B2") >= 9);
    // "b": markers only (vermillion squares, filled), no line.
    assert_eq!(count(&svg, "polyline", "stroke", "#D55E00"), 0);
    assert!(
        count(&svg, "polygon", "fill", "#D55E00") >= 3,
        "2 markers + legend"
    );
    // "c" and "ref" are dashed: many short segments each.
    assert!(count(&svg, "polyline", "stroke", "#009E73") >= 5);
    assert!(count(&svg, "polyline", "stroke", "#555555") >= 5);
}

#[test]
fn text_is_escaped() {
    let chart = Chart::new("<T&C> \"q\" 'a'\u{1}")
        .x_label("x < 1 & y > 2")
        .series(Series::new("a<b>", vec![(0.0, 0.0), (1.0, 1.0)]).color("\"><script>"));
    let svg = chart.to_svg(500.0, 300.0);
    let t = texts(&svg);
    assert!(t.iter().any(|s| s == "<T&C> \"q\" 'a'\u{FFFD}"), "{t:?}");
    assert!(t.iter().any(|s| s == "x < 1 & y > 2"));
    assert!(t.iter().any(|s| s == "a<b>"));
    assert!(!svg.contains("<script>"));
}

#[test]
fn output_is_deterministic() {
    let fig = Figure::new("fig", 2)
        .panel(sample_chart())
        .panel(sample_chart().x_log(false));
    assert_eq!(fig.to_svg(400.0, 300.0), fig.to_svg(400.0, 300.0));
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let odd = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1e-320,
        1e300,
        -1e300,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
    ];
    let ranges = [
        None,
        Some((1.0, 1.0)),
        Some((f64::NAN, f64::NAN)),
        Some((-1.0, 0.0)),
        Some((5.0, 1.0)),
    ];
    let mut charts = Vec::new();
    for &a in &odd {
        for &b in &odd {
            for (xl, yl) in [(false, false), (true, true), (true, false)] {
                let pts = vec![(a, b), (b, a), (a, a)];
                charts.push(
                    Chart::new("t")
                        .x_log(xl)
                        .y_log(yl)
                        .series(Series::new("s", pts).y_err(vec![b, a, f64::NAN, 1.0]))
                        .line(Line::new("l", vec![(a, b)])),
                );
            }
        }
    }
    for r in ranges {
        let mut c = sample_chart();
        (c.x_range, c.y_range) = (r, r);
        charts.push(c.clone());
        charts.push(c.x_log(false).y_log(false));
    }
    charts.push(Chart::default());
    charts.push(
        Chart::new("")
            .series(Series::default())
            .line(Line::default()),
    );
    charts.push(Chart::new("single").series(Series::new("p", vec![(2.0, 3.0)])));
    charts.push(
        Chart::new("equal")
            .series(Series::new("p", vec![(2.0, 3.0); 5]))
            .y_log(true),
    );
    for c in &charts {
        parse(&c.to_svg(640.0, 420.0));
    }
    for (w, h) in [
        (0.0, 0.0),
        (f64::NAN, -5.0),
        (1.0, 1.0),
        (61.0, 61.0),
        (1e9, 1e9),
    ] {
        parse(&sample_chart().to_svg(w, h));
        parse(&charts[0].to_svg(w, h));
    }
    parse(&Figure::new("", 0).to_svg(f64::NAN, 0.0));
    parse(
        &Figure::new("many", 3)
            .panel(Chart::default())
            .to_svg(100.0, 80.0),
    );
}

#[test]
fn empty_chart_says_no_data() {
    let svg = Chart::new("nothing")
        .series(Series::new("s", Vec::new()))
        .to_svg(400.0, 300.0);
    assert!(texts(&svg).iter().any(|s| s == "no data"));
    let nan = Chart::new("").series(Series::new(
        "s",
        vec![(f64::NAN, 1.0), (1.0, f64::INFINITY)],
    ));
    assert!(
        texts(&nan.to_svg(400.0, 300.0))
            .iter()
            .any(|s| s == "no data")
    );
}

#[test]
fn skipped_points_break_lines() {
    let pts = vec![
        (0.0, 1.0),
        (1.0, 2.0),
        (2.0, f64::NAN),
        (3.0, 2.0),
        (4.0, 1.0),
    ];
    let svg = Chart::new("")
        .series(Series::new("s", pts).style(Style::Line))
        .to_svg(400.0, 300.0);
    assert_eq!(
        count(&svg, "polyline", "stroke", "#0072B2"),
        2 + 1,
        "two runs and the legend"
    );
    // A single point with a line style still shows up (as a dot).
    let svg = Chart::new("")
        .series(Series::new("s", vec![(1.0, 1.0)]).style(Style::Line))
        .to_svg(400.0, 300.0);
    assert_eq!(count(&svg, "circle", "fill", "#0072B2"), 1);
}

#[test]
fn log_axis_falls_back_to_linear() {
    let chart = Chart::new("").x_log(true).y_log(true).series(Series::new(
        "s",
        vec![(-2.0, 1.0), (-1.0, 10.0), (0.0, 100.0)],
    ));
    let t = texts(&chart.to_svg(500.0, 300.0));
    // x is linear (negative tick labels), y stays logarithmic (decades).
    assert!(t.iter().any(|s| s.starts_with("-2")), "{t:?}");
    assert!(t.iter().any(|s| s == "100") && t.iter().any(|s| s == "10"));
    // Non-positive values alone on a log axis: skipped, others kept.
    let chart = Chart::new("")
        .y_log(true)
        .series(Series::new("s", vec![(0.0, -1.0), (1.0, 1.0), (2.0, 10.0)]));
    let svg = chart.to_svg(500.0, 300.0);
    assert_eq!(
        count(&svg, "circle", "fill", "#0072B2"),
        2,
        "two data markers"
    );
}

#[test]
fn legend_positions() {
    let base = sample_chart();
    let hidden = base
        .clone()
        .legend(LegendPosition::Hidden)
        .to_svg(640.0, 420.0);
    assert!(!texts(&hidden).iter().any(|s| s == "ref"));
    for pos in [
        LegendPosition::Outside,
        LegendPosition::TopLeft,
        LegendPosition::BottomRight,
        LegendPosition::BottomLeft,
        LegendPosition::TopRight,
    ] {
        let svg = base.clone().legend(pos).to_svg(640.0, 420.0);
        assert!(texts(&svg).iter().any(|s| s == "ref"), "{pos:?}");
    }
    // Many long entries: wrapped (not cut) and summarised, still XML.
    let mut busy = Chart::new("busy");
    for i in 0..40 {
        busy = busy.series(Series::new(
            format!("series number {i} with a very long name indeed"),
            vec![(0.0, i as f64), (1.0, -(i as f64))],
        ));
    }
    let t = texts(&busy.to_svg(500.0, 300.0));
    assert!(t.iter().any(|s| s.ends_with(" more")), "{t:?}");
    assert!(!t.iter().any(|s| s.ends_with('…')), "{t:?}");
    assert!(t.iter().any(|s| s == "series number 0 with a"), "{t:?}");
}

#[test]
fn auto_legend_avoids_the_data() {
    // Data fill the top right; the legend goes to another corner, which a
    // bottom-right placement check confirms by the legend box position.
    let chart = Chart::new("")
        .series(Series::new(
            "rising",
            vec![(0.0, 0.0), (0.5, 0.1), (1.0, 1.0)],
        ))
        .series(Series::new("flat top", vec![(0.5, 1.0), (1.0, 1.0)]));
    let svg = chart.to_svg(600.0, 400.0);
    let doc = parse(&svg);
    let x_of_name = doc
        .descendants()
        .find(|n| n.has_tag_name("text") && n.text().map(str::trim) == Some("rising"))
        .and_then(|n| n.attribute("x"))
        .and_then(|x| x.parse::<f64>().ok())
        .unwrap_or(f64::NAN);
    assert!(
        x_of_name < 300.0,
        "legend on the left half, at x = {x_of_name}"
    );
}

#[test]
fn figure_grid() {
    let fig = Figure::new("F & G", 2)
        .panel(sample_chart())
        .panel(sample_chart())
        .panel(sample_chart());
    let svg = fig.to_svg(300.0, 200.0);
    let doc = parse(&svg);
    assert_eq!(doc.root_element().attribute("width"), Some("600"));
    assert_eq!(doc.root_element().attribute("height"), Some("434"));
    let t = texts(&svg);
    assert!(t.iter().any(|s| s == "F & G"));
    assert_eq!(t.iter().filter(|s| *s == "Error vs cost").count(), 3);
}

#[test]
fn write_creates_directories() {
    let dir = std::env::temp_dir().join(format!("magsep-chart-test-{}", std::process::id()));
    let path = dir.join("sub").join("c.svg");
    write_svg(&path, "<svg/>").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "<svg/>");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_long_title_wraps_onto_lines_instead_of_losing_its_end() {
    let title = "Concentrated cloud (thesis 500 particles, 30 runs; here 10 runs); reduced: \
                 adaptive steps (tol 0.01 R, max 1e-5 s), no hydrodynamic interactions";
    let chart = Chart::new(title).series(Series::new("a", vec![(0.0, 1.0), (1.0, 2.0)]));
    let t = texts(&chart.to_svg(480.0, 360.0));
    // every word is there, over two or three lines, and nothing is cut
    let words: Vec<&str> = title.split(' ').collect();
    let lines = (t.iter())
        .filter(|s| s.len() > 10 && title.contains(s.as_str()))
        .count();
    let joined = t.join(" ");
    for w in &words {
        assert!(joined.contains(w), "{w} missing from {t:?}");
    }
    assert!(!t.iter().any(|s| s.ends_with('…')), "{t:?}");
    assert!(lines >= 2, "{t:?}");
    // a title too long for three lines keeps an ellipsis on the last
    let long = [title; 4].join(" ");
    let t = texts(&Chart::new(&long).to_svg(480.0, 360.0));
    assert!(t.iter().any(|s| s.ends_with('…')), "{t:?}");
}

#[test]
fn long_legend_entries_wrap_so_that_entries_differing_at_their_end_stay_apart() {
    let a = "spectral Ewald mobility, tolerance 1e-6, 64 grid points per side, 1 thread";
    let b = "spectral Ewald mobility, tolerance 1e-6, 64 grid points per side, 2 threads";
    let chart = Chart::new("cost")
        .series(Series::new(a, vec![(0.0, 1.0), (1.0, 2.0)]))
        .series(Series::new(b, vec![(0.0, 1.5), (1.0, 2.5)]));
    for w in [480.0, 640.0] {
        let t = texts(&chart.to_svg(w, 360.0));
        assert!(!t.iter().any(|s| s.ends_with('…')), "{t:?}");
        // both entries in full, over lines of their own: their ends differ
        let joined = t.join(" ");
        assert!(joined.contains("per side, 1 thread spectral"), "{t:?}");
        assert!(joined.ends_with("per side, 2 threads"), "{t:?}");
        for word in b.split(' ') {
            assert!(joined.contains(word), "{word} missing from {t:?}");
        }
        let spectral = t.iter().filter(|s| s.starts_with("spectral Ewald")).count();
        assert_eq!(spectral, 2, "{t:?}");
    }
    // more entries than rows: the rest summarised, never cut mid-entry
    let mut many = Chart::new("many");
    for k in 0..12 {
        many = many.series(Series::new(
            format!("{a} {k}"),
            vec![(0.0, k as f64), (1.0, k as f64)],
        ));
    }
    let t = texts(&many.to_svg(480.0, 240.0));
    assert!(
        t.iter().any(|s| s.starts_with('+') && s.ends_with("more")),
        "{t:?}"
    );
}
