//! Whole-chart tests: well-formed output, degenerate input, determinism.

use super::*;

/// Minimal XML well-formedness check: balanced tags, quoted attributes,
/// no stray `<` or `&` in text. Returns the element names in document order.
fn check_xml(doc: &str) -> Result<Vec<String>, String> {
    let mut stack: Vec<String> = Vec::new();
    let mut names = Vec::new();
    let mut rest = doc;
    let check_text = |t: &str| -> Result<(), String> {
        let mut parts = t.split('&');
        parts.next();
        for p in parts {
            let ok = ["amp;", "lt;", "gt;", "quot;", "apos;"]
                .iter()
                .any(|e| p.starts_with(e));
            if !ok {
                return Err(format!("bad entity in {t:?}"));
            }
        }
        if t.contains('>') {
            Err(format!("raw '>' in text {t:?}"))
        } else {
            Ok(())
        }
    };
    while let Some(start) = rest.find('<') {
        check_text(&rest[..start])?;
        let end = rest[start..].find('>').ok_or("unclosed tag")? + start;
        let tag = &rest[start + 1..end];
        if tag.contains('<') {
            return Err(format!("'<' inside tag {tag:?}"));
        }
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().ok_or(format!("unmatched </{name}>"))?;
            if open != name {
                return Err(format!("<{open}> closed by </{name}>"));
            }
        } else {
            let self_closing = tag.ends_with('/');
            let body = tag.trim_end_matches('/');
            let name: String = body.chars().take_while(|c| !c.is_whitespace()).collect();
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == ':')
            {
                return Err(format!("bad tag name in {tag:?}"));
            }
            // Attributes: name="value" pairs.
            let mut attrs = body[name.len()..].trim();
            while !attrs.is_empty() {
                let eq = attrs
                    .find("=\"")
                    .ok_or(format!("bad attribute in {tag:?}"))?;
                let close = attrs[eq + 2..].find('"').ok_or("unterminated attribute")? + eq + 2;
                check_text(&attrs[eq + 2..close])?;
                attrs = attrs[close + 1..].trim_start();
            }
            names.push(name.clone());
            if !self_closing {
                stack.push(name);
            }
        }
        rest = &rest[end + 1..];
    }
    check_text(rest)?;
    if !stack.is_empty() {
        return Err(format!("unclosed elements {stack:?}"));
    }
    Ok(names)
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
fn xml_checker_works() {
    assert!(check_xml("<a x=\"1\"><b/>t &amp; u</a>").is_ok());
    assert!(check_xml("<a><b></a>").is_err());
    assert!(check_xml("<a>x & y</a>").is_err());
    assert!(check_xml("<a x=1></a>").is_err());
}

#[test]
fn chart_is_well_formed() {
    let svg = sample_chart().to_svg(640.0, 420.0);
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    let names = check_xml(&svg).unwrap();
    assert_eq!(names[0], "svg");
    assert!(names.iter().any(|n| n == "clipPath"));
}

#[test]
fn each_series_is_drawn() {
    let svg = sample_chart().to_svg(640.0, 420.0);
    // Line + markers for "a", with error bars (a second path in its colour).
    assert_eq!(
        svg.matches("stroke=\"#0072B2\"").count(),
        3,
        "line, error bars, legend sample"
    );
    assert!(svg.contains("<g fill=\"#0072B2\""));
    // Markers only for "b": no line in the plot, only in the legend (none).
    assert!(!svg.contains("stroke=\"#D55E00\""));
    assert!(svg.contains("<g fill=\"#D55E00\""));
    // Dashed series and dashed reference line.
    assert!(svg.contains("stroke=\"#009E73\" stroke-width=\"1.8\" stroke-dasharray"));
    assert!(svg.contains("stroke=\"#555555\" stroke-width=\"1.3\" stroke-dasharray"));
    for name in ["a", "b", "c", "ref"] {
        assert!(
            svg.contains(&format!(">{name}</text>")),
            "legend entry {name}"
        );
    }
}

#[test]
fn text_is_escaped() {
    let chart = Chart::new("<T&C> \"q\" 'a'")
        .x_label("x < 1 & y > 2")
        .series(Series::new("a<b>", vec![(0.0, 0.0), (1.0, 1.0)]).color("\"><script>"));
    let svg = chart.to_svg(500.0, 300.0);
    check_xml(&svg).unwrap();
    assert!(svg.contains("&lt;T&amp;C&gt; &quot;q&quot; &apos;a&apos;"));
    assert!(svg.contains("x &lt; 1 &amp; y &gt; 2"));
    assert!(svg.contains(">a&lt;b&gt;</text>"));
    assert!(!svg.contains("<script>"));
}

#[test]
fn output_is_deterministic() {
    let fig = Figure::new("fig", 2)
        .panel(sample_chart())
        .panel(sample_chart().x_log(false));
    assert_eq!(fig.to_svg(400.0, 300.0), fig.to_svg(400.0, 300.0));
    assert_eq!(
        sample_chart().to_svg(640.0, 420.0),
        sample_chart().clone().to_svg(640.0, 420.0)
    );
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let odd = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1e-320,
        5e-324,
        1e300,
        -1e300,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
    ];
    let sizes = [
        (0.0, 0.0),
        (f64::NAN, -5.0),
        (1.0, 1.0),
        (61.0, 61.0),
        (1e9, 1e9),
        (640.0, 420.0),
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
                        .series(Series::new("s", pts.clone()).y_err(vec![b, a, f64::NAN, 1.0]))
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
        for &(w, h) in &sizes {
            check_xml(&c.to_svg(w, h)).unwrap();
        }
    }
    check_xml(&Figure::new("", 0).to_svg(f64::NAN, 0.0)).unwrap();
    check_xml(
        &Figure::new("many", 3)
            .panel(Chart::default())
            .to_svg(100.0, 80.0),
    )
    .unwrap();
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
    let line = svg
        .lines()
        .find(|l| l.contains("stroke=\"#0072B2\" stroke-width=\"1.8\""))
        .unwrap();
    assert_eq!(line.matches('M').count(), 2, "{line}");
    // A single point with a line style still shows up (as a dot).
    let svg = Chart::new("")
        .series(Series::new("s", vec![(1.0, 1.0)]).style(Style::Line))
        .to_svg(400.0, 300.0);
    assert!(svg.contains("<circle"));
}

#[test]
fn log_axis_falls_back_to_linear() {
    let chart = Chart::new("").x_log(true).y_log(true).series(Series::new(
        "s",
        vec![(-2.0, 1.0), (-1.0, 10.0), (0.0, 100.0)],
    ));
    let svg = chart.to_svg(500.0, 300.0);
    // x is linear (negative tick labels), y stays logarithmic (decades).
    assert!(
        svg.contains(">-2.0</text>") || svg.contains(">-2</text>"),
        "{svg}"
    );
    assert!(svg.contains(">100</text>") && svg.contains(">10</text>"));
    // Non-positive values alone on a log axis: skipped, others kept.
    let chart = Chart::new("")
        .y_log(true)
        .series(Series::new("s", vec![(0.0, -1.0), (1.0, 1.0), (2.0, 10.0)]));
    let svg = chart.to_svg(500.0, 300.0);
    assert_eq!(
        svg.matches("<circle").count(),
        2 + 1,
        "two data markers and the legend"
    );
}

#[test]
fn legend_positions() {
    let base = sample_chart();
    let hidden = base
        .clone()
        .legend(LegendPosition::Hidden)
        .to_svg(640.0, 420.0);
    assert!(!hidden.contains(">ref</text>"));
    for pos in [
        LegendPosition::Outside,
        LegendPosition::TopLeft,
        LegendPosition::BottomRight,
    ] {
        let svg = base.clone().legend(pos).to_svg(640.0, 420.0);
        assert!(svg.contains(">ref</text>"));
        check_xml(&svg).unwrap();
    }
    // Many long entries: truncated and summarised, still well-formed.
    let mut busy = Chart::new("busy");
    for i in 0..40 {
        busy = busy.series(Series::new(
            format!("series number {i} with a very long name indeed"),
            vec![(0.0, i as f64), (1.0, -(i as f64))],
        ));
    }
    let svg = busy.to_svg(500.0, 300.0);
    check_xml(&svg).unwrap();
    assert!(svg.contains(" more</text>"));
    assert!(svg.contains('…'));
}

#[test]
fn figure_grid() {
    let fig = Figure::new("F & G", 2)
        .panel(sample_chart())
        .panel(sample_chart())
        .panel(sample_chart());
    let svg = fig.to_svg(300.0, 200.0);
    check_xml(&svg).unwrap();
    assert!(svg.contains("width=\"600\" height=\"434\""));
    assert!(svg.contains("translate(300 34)") && svg.contains("translate(0 234)"));
    assert!(svg.contains("F &amp; G"));
    for i in 0..3 {
        assert_eq!(svg.matches(&format!("id=\"p{i}-clip\"")).count(), 1);
    }
}

#[test]
fn write_creates_directories() {
    let dir = std::env::temp_dir().join(format!("magsep-chart-test-{}", std::process::id()));
    let path = dir.join("sub").join("c.svg");
    write_svg(&path, "<svg/>").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "<svg/>");
    std::fs::remove_dir_all(&dir).unwrap();
}
