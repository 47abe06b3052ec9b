//! Low-level SVG text helpers: escaping, number formatting, text metrics.

use std::fmt::Write as _;

/// Escapes `text` for use in XML text or attribute values (`&`, `<`, `>`,
/// `"`, `'`). Characters not allowed in XML 1.0 (most control characters)
/// are replaced by U+FFFD.
#[must_use]
pub fn escape_xml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// Formats a pixel coordinate with at most two decimals, no trailing zeros
/// and no negative zero. Non-finite values become `0`.
pub(crate) fn num(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{:.2}", v.clamp(-1e7, 1e7));
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" { "0".to_string() } else { s }
}

/// Clamps a requested image size to something drawable.
pub(crate) fn sanitize_size(v: f64, default: f64) -> f64 {
    if v.is_finite() && v > 0.0 {
        v.clamp(60.0, 20_000.0)
    } else {
        default
    }
}

/// Writes the `<svg>` start tag and a white background.
pub(crate) fn open_document(out: &mut String, w: f64, h: f64) {
    let (w, h) = (num(w), num(h));
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\" font-family=\"Helvetica, Arial, sans-serif\">"
    );
    let _ = writeln!(out, "<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>");
}

/// Writes a `<text>` element whose vertical centre is at `y`.
/// `extra` is inserted verbatim into the start tag (must start with a space).
pub(crate) fn text(
    out: &mut String,
    x: f64,
    y: f64,
    size: f64,
    anchor: &str,
    extra: &str,
    s: &str,
) {
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{anchor}\" fill=\"#222222\"{extra}>{}</text>",
        num(x),
        num(y + 0.35 * size),
        num(size),
        escape_xml(s)
    );
}

/// Approximate advance width of one character, in ems. Deliberately on the
/// wide side (DejaVu Sans metrics) so that layout never underestimates.
fn char_em(c: char) -> f64 {
    match c {
        '0'..='9' => 0.64,
        '.' | ',' | ':' | ';' | '!' | '|' | '\'' => 0.33,
        ' ' => 0.32,
        '-' | '(' | ')' | '[' | ']' | '/' => 0.40,
        'i' | 'j' | 'l' | 'I' | 'f' | 't' | 'r' => 0.40,
        'm' | 'w' | 'M' | 'W' => 0.95,
        'A'..='Z' => 0.74,
        'a'..='z' => 0.62,
        c if c.is_ascii() => 0.70,
        c if (c as u32) >= 0x2E80 => 1.0,
        _ => 0.70,
    }
}

/// Estimated rendered width of `s` in pixels at font size `size`.
pub(crate) fn text_width(s: &str, size: f64) -> f64 {
    s.chars().map(char_em).sum::<f64>() * size
}

/// Shortens `s` with a trailing ellipsis so that it fits in `max_width`.
pub(crate) fn truncate_to_width(s: &str, max_width: f64, size: f64) -> String {
    if text_width(s, size) <= max_width {
        return s.to_string();
    }
    let budget = max_width - text_width("…", size);
    let mut out = String::new();
    let mut used = 0.0;
    for c in s.chars() {
        let w = char_em(c) * size;
        if used + w > budget {
            break;
        }
        used += w;
        out.push(c);
    }
    out.push('…');
    out
}

/// Dash pattern of dashed lines.
pub(crate) const DASH: &str = "7 4";
/// Marker "radius" in pixels.
pub(crate) const MARKER_R: f64 = 3.6;

/// Appends a `<path>` stroke (nothing if `d` is empty).
pub(crate) fn path(out: &mut String, d: &str, color: &str, width: f64, dash: Option<&str>) {
    if d.is_empty() {
        return;
    }
    let dash = dash
        .map(|d| format!(" stroke-dasharray=\"{d}\""))
        .unwrap_or_default();
    let _ = writeln!(
        out,
        "<path d=\"{d}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"{}\"{dash}/>",
        num(width)
    );
}

/// Appends one marker element; the shape cycles circle, square, triangle,
/// diamond, inverted triangle.
pub(crate) fn marker(out: &mut String, shape: usize, x: f64, y: f64, r: f64) {
    let _ = match shape % 5 {
        0 => writeln!(
            out,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>",
            num(x),
            num(y),
            num(r)
        ),
        1 => {
            let s = r * 0.9;
            writeln!(
                out,
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>",
                num(x - s),
                num(y - s),
                num(2.0 * s),
                num(2.0 * s)
            )
        }
        2 | 4 => {
            let k = if shape % 5 == 2 { 1.0 } else { -1.0 };
            let s = r * 1.2;
            writeln!(
                out,
                "<path d=\"M{} {}L{} {}L{} {}Z\"/>",
                num(x),
                num(y - k * s),
                num(x + s * 0.95),
                num(y + k * s * 0.7),
                num(x - s * 0.95),
                num(y + k * s * 0.7)
            )
        }
        _ => {
            let s = r * 1.3;
            writeln!(
                out,
                "<path d=\"M{} {}L{} {}L{} {}L{} {}Z\"/>",
                num(x),
                num(y - s),
                num(x + s),
                num(y),
                num(x),
                num(y + s),
                num(x - s),
                num(y)
            )
        }
    };
}

/// Appends a group of marker elements (from [`marker`]) filled with `color`.
pub(crate) fn marker_group(out: &mut String, color: &str, body: &str) {
    if !body.is_empty() {
        let _ = writeln!(
            out,
            "<g fill=\"{color}\" stroke=\"#ffffff\" stroke-width=\"0.6\">\n{body}</g>"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping() {
        assert_eq!(
            escape_xml(r#"a<b & c>"d" 'e'"#),
            "a&lt;b &amp; c&gt;&quot;d&quot; &apos;e&apos;"
        );
        assert_eq!(escape_xml("µm²\u{1}"), "µm²\u{FFFD}");
        assert_eq!(escape_xml(""), "");
    }

    #[test]
    fn numbers() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(1.234_567), "1.23");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(2.5), "2.5");
        assert_eq!(num(f64::NAN), "0");
        assert_eq!(num(f64::INFINITY), "0");
        assert_eq!(num(1e30), "10000000");
    }

    #[test]
    fn truncation() {
        assert_eq!(truncate_to_width("short", 1000.0, 12.0), "short");
        let t = truncate_to_width(&"x".repeat(200), 100.0, 12.0);
        assert!(t.ends_with('…'));
        assert!(text_width(&t, 12.0) <= 100.0);
        assert_eq!(truncate_to_width("abc", 0.0, 12.0), "…");
    }
}
