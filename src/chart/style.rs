//! Colours, fonts, markers and text clean-up shared by the line charts and
//! the heatmaps.

use plotters::element::{DashedPathElement, PathElement, Polygon};
use plotters::prelude::{RGBColor, ShapeStyle};
use plotters::style::{Color, FontDesc, FontFamily, FontStyle, IntoFont};

use super::axis::text_width;

/// Font size of a figure's overall title, px.
pub(crate) const FS_FIGURE_TITLE: f64 = 16.0;
/// Font size of a panel title, px.
pub(crate) const FS_TITLE: f64 = 14.0;
/// Font size of axis labels, px.
pub(crate) const FS_LABEL: f64 = 12.0;
/// Font size of tick labels and legend entries, px.
pub(crate) const FS_TICK: f64 = 11.0;
/// Marker "radius", px.
pub(crate) const MARKER_R: i32 = 4;
/// Text colour.
pub(crate) const INK: RGBColor = RGBColor(0x22, 0x22, 0x22);
/// Frame and tick colour.
pub(crate) const FRAME: RGBColor = RGBColor(0x44, 0x44, 0x44);
/// Dash pattern `(on, off)` of dashed lines, px.
pub(crate) const DASH: (u32, u32) = (7, 4);
/// Colour of reference lines without an explicit colour.
pub(crate) const REF_COLOR: RGBColor = RGBColor(0x55, 0x55, 0x55);

/// A sans-serif font of `px` pixels. Plotters' SVG backend writes
/// `font-size = size / 1.24`, so the size is scaled up to match.
pub(crate) fn font(px: f64) -> FontDesc<'static> {
    (FontFamily::SansSerif, px * 1.24).into_font()
}

/// A bold sans-serif font of `px` pixels.
pub(crate) fn bold(px: f64) -> FontDesc<'static> {
    font(px).style(FontStyle::Bold)
}

/// Parses an SVG colour: `#rgb`, `#rrggbb` or a basic colour name;
/// anything else gives `None`.
pub(crate) fn parse_color(s: &str) -> Option<RGBColor> {
    let s = s.trim();
    if let Some(hex) = s.strip_prefix('#') {
        let v = |i: usize, n: usize| u8::from_str_radix(hex.get(i..i + n)?, 16).ok();
        return match hex.len() {
            6 => Some(RGBColor(v(0, 2)?, v(2, 2)?, v(4, 2)?)),
            3 => Some(RGBColor(v(0, 1)? * 17, v(1, 1)? * 17, v(2, 1)? * 17)),
            _ => None,
        };
    }
    let rgb = match s.to_ascii_lowercase().as_str() {
        "black" => (0, 0, 0),
        "white" => (255, 255, 255),
        "red" => (255, 0, 0),
        "green" => (0, 128, 0),
        "blue" => (0, 0, 255),
        "grey" | "gray" => (128, 128, 128),
        "orange" => (255, 165, 0),
        "purple" => (128, 0, 128),
        _ => return None,
    };
    Some(RGBColor(rgb.0, rgb.1, rgb.2))
}

/// `s` without control characters (not allowed in XML), trimmed.
pub(crate) fn clean(s: &str) -> String {
    s.trim()
        .chars()
        .map(|c| {
            if c.is_control() || c == '\u{FFFE}' || c == '\u{FFFF}' {
                '\u{FFFD}'
            } else {
                c
            }
        })
        .collect()
}

/// `s` cleaned and shortened with an ellipsis to fit `max_px` at font size `px`.
pub(crate) fn fit(s: &str, max_px: f64, px: f64) -> String {
    let s = clean(s);
    if text_width(&s, px) <= max_px {
        return s;
    }
    let budget = max_px - text_width("…", px);
    let mut out = String::new();
    for c in s.chars() {
        out.push(c);
        if text_width(&out, px) > budget {
            out.pop();
            break;
        }
    }
    out.push('…');
    out
}

/// Most lines a panel's or a heatmap's title wraps to (the rest is shortened with an
/// ellipsis).
pub(crate) const TITLE_LINES: usize = 3;
/// Distance between wrapped title lines, px.
pub(crate) const TITLE_LINE_H: f64 = 1.25 * FS_TITLE;

/// A panel's or a heatmap's `title` wrapped to `max_px` ([`wrap`] at [`FS_TITLE`], at most
/// [`TITLE_LINES`] lines; none when the title is blank).
pub(crate) fn title_lines(title: &str, max_px: f64) -> Vec<String> {
    if title.trim().is_empty() {
        return Vec::new();
    }
    wrap(title, max_px, FS_TITLE, TITLE_LINES)
}

/// `s` cleaned and broken at spaces into at most `max_lines` lines that each fit `max_px`
/// at font size `px` (a word longer than a line is shortened); only the last line is
/// shortened with an ellipsis when the text does not fit in `max_lines`. Titles carry the
/// scene's reductions, which an ellipsis on one line would hide.
pub(crate) fn wrap(s: &str, max_px: f64, px: f64, max_lines: usize) -> Vec<String> {
    let s = clean(s);
    let mut lines: Vec<String> = Vec::new();
    let mut words = s.split(' ').filter(|w| !w.is_empty()).peekable();
    while let Some(word) = words.next() {
        if lines.len() + 1 == max_lines.max(1) {
            // the last line takes the rest
            let rest: Vec<&str> = std::iter::once(word).chain(words).collect();
            lines.push(fit(&rest.join(" "), max_px, px));
            break;
        }
        let mut line = word.to_string();
        while let Some(next) = words.peek() {
            let longer = format!("{line} {next}");
            if text_width(&longer, px) > max_px {
                break;
            }
            line = longer;
            words.next();
        }
        lines.push(fit(&line, max_px, px));
    }
    lines
}

/// Outline of marker `shape` (cycling circle, square, triangle, diamond,
/// inverted triangle) around pixel offset `(cx, cy)`.
fn marker_outline(shape: usize, (cx, cy): (i32, i32)) -> Vec<(i32, i32)> {
    let r = MARKER_R;
    let pts = match shape % 5 {
        0 => (0..12)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::PI / 6.0;
                let r = f64::from(r);
                ((r * a.cos()).round() as i32, (r * a.sin()).round() as i32)
            })
            .collect(),
        1 => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        2 => vec![(0, -r - 1), (r + 1, r), (-r - 1, r)],
        3 => vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
        _ => vec![(0, r + 1), (r + 1, -r), (-r - 1, -r)],
    };
    pts.into_iter().map(|(x, y)| (x + cx, y + cy)).collect()
}

/// Legend sample: a 24 px solid line from the anchor.
pub(crate) fn sample_solid(style: ShapeStyle) -> PathElement<(i32, i32)> {
    PathElement::new(vec![(0, 0), (24, 0)], style)
}

/// Legend sample: a 24 px line dashed `(on, off)` px from the anchor.
pub(crate) fn sample_dashed(
    style: ShapeStyle,
    (on, off): (u32, u32),
) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, u32> {
    DashedPathElement::new(vec![(0, 0), (24, 0)], on.max(1), off, style)
}

/// Legend sample: marker `shape` in the middle of the 24 px sample.
pub(crate) fn sample_marker(shape: usize, color: RGBColor) -> Polygon<(i32, i32)> {
    Polygon::new(marker_outline(shape, (12, 0)), color.filled())
}

/// Marker outline `shape` around a data point, as pixel offsets.
pub(crate) fn marker_offsets(shape: usize) -> Vec<(i32, i32)> {
    marker_outline(shape, (0, 0))
}
