//! Where the text of an SVG figure lies, estimated from its `<text>` elements (position,
//! anchor, font size, length, rotation), to check that no two texts overlap and that
//! none is cut off at the figure's edge. The estimate is deliberately independent of
//! the one the figures are laid out with (`unforeseen_harness::reports::figures::text_width`): glyph
//! widths here come in classes (narrow, digits, capitals, wide) of DejaVu Sans, the
//! usual sans-serif.

/// A text's estimated box, in the SVG's pixels.
#[derive(Debug, Clone)]
pub struct TextBox {
    /// The text.
    pub text: String,
    /// Left, top, right, bottom.
    pub rect: [f64; 4],
}

/// Width of one glyph, in em, by class.
fn glyph_em(c: char) -> f64 {
    match c {
        'i' | 'j' | 'l' | '|' | '!' | '.' | ',' | ':' | ';' | '\'' => 0.28,
        ' ' => 0.32,
        'f' | 't' | 'r' | '(' | ')' | '[' | ']' | '{' | '}' | '-' | '/' => 0.4,
        'm' | 'w' | 'M' | 'W' | '%' | '@' => 0.95,
        '0'..='9' => 0.64,
        'A'..='Z' => 0.72,
        'a'..='z' => 0.6,
        _ => 0.84,
    }
}

/// Estimated width of `text` at `size` px.
pub fn width(text: &str, size: f64) -> f64 {
    text.chars().map(glyph_em).sum::<f64>() * size
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(tag[start..end].to_string())
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// A length in em (`0.76em`), ex (`0.5ex`, half an em here) or px, in px at `size`.
fn length(s: &str, size: f64) -> f64 {
    if let Some(v) = s.strip_suffix("em") {
        v.parse::<f64>().unwrap_or(0.0) * size
    } else if let Some(v) = s.strip_suffix("ex") {
        v.parse::<f64>().unwrap_or(0.0) * size * 0.5
    } else {
        s.trim_end_matches("px").parse().unwrap_or(0.0)
    }
}

/// The figure's size from the `<svg>` element.
pub fn size(svg: &str) -> (f64, f64) {
    let tag = &svg[svg.find("<svg").expect("an <svg> element")..];
    let tag = &tag[..tag.find('>').expect("a closed <svg> tag")];
    let w = attr(tag, "width").and_then(|w| w.parse().ok()).expect("svg width");
    let h = attr(tag, "height").and_then(|h| h.parse().ok()).expect("svg height");
    (w, h)
}

/// Every non-empty `<text>` of `svg` with its estimated box.
pub fn boxes(svg: &str) -> Vec<TextBox> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        let after = &rest[start..];
        let open_end = after.find('>').expect("closed <text> tag");
        let tag = &after[..open_end];
        let close = after.find("</text>").expect("</text>");
        let text = unescape(after[open_end + 1..close].trim());
        rest = &after[close + 7..];
        if text.is_empty() {
            continue;
        }
        let num = |name| attr(tag, name).and_then(|v| v.parse::<f64>().ok());
        let (x, y) = (num("x").unwrap_or(0.0), num("y").unwrap_or(0.0));
        let size = num("font-size").unwrap_or(16.0);
        let w = width(&text, size);
        let left = match attr(tag, "text-anchor").as_deref() {
            Some("middle") => x - w / 2.0,
            Some("end") => x - w,
            _ => x,
        };
        // Baseline after the dy shift; glyphs reach 0.76 em above it and 0.24 em below.
        let baseline = y + attr(tag, "dy").map_or(0.0, |d| length(&d, size));
        let (top, bottom) = (baseline - 0.76 * size, baseline + 0.24 * size);
        let mut rect = [left, top, left + w, bottom];
        if let Some(t) = attr(tag, "transform")
            && let Some(args) = t.strip_prefix("rotate(").and_then(|a| a.strip_suffix(')'))
        {
            let v: Vec<f64> = args.split(',').filter_map(|a| a.trim().parse().ok()).collect();
            if let [angle, cx, cy] = v[..] {
                rect = rotate(rect, angle, cx, cy);
            }
        }
        out.push(TextBox { text, rect });
    }
    out
}

/// The box around `rect` rotated by `angle` degrees about `(cx, cy)`.
fn rotate(rect: [f64; 4], angle: f64, cx: f64, cy: f64) -> [f64; 4] {
    let (s, c) = angle.to_radians().sin_cos();
    let corners = [
        (rect[0], rect[1]),
        (rect[2], rect[1]),
        (rect[0], rect[3]),
        (rect[2], rect[3]),
    ];
    let turned: Vec<(f64, f64)> = corners
        .iter()
        .map(|&(x, y)| {
            let (dx, dy) = (x - cx, y - cy);
            (cx + dx * c - dy * s, cy + dx * s + dy * c)
        })
        .collect();
    let fold = |f: fn(f64, f64) -> f64, init: f64, get: fn(&(f64, f64)) -> f64| turned.iter().map(get).fold(init, f);
    [
        fold(f64::min, f64::INFINITY, |p| p.0),
        fold(f64::min, f64::INFINITY, |p| p.1),
        fold(f64::max, f64::NEG_INFINITY, |p| p.0),
        fold(f64::max, f64::NEG_INFINITY, |p| p.1),
    ]
}

/// Problems with the text of `svg`: pairs of texts whose boxes overlap by more than a
/// pixel each way, and texts reaching more than a pixel beyond the figure's edge.
pub fn problems(svg: &str) -> Vec<String> {
    const SLACK: f64 = 1.0;
    let (w, h) = size(svg);
    let boxes = boxes(svg);
    let mut out = Vec::new();
    for b in &boxes {
        let [l, t, r, btm] = b.rect;
        if l < -SLACK || t < -SLACK || r > w + SLACK || btm > h + SLACK {
            out.push(format!(
                "{:?} at {:?} leaves the {w} x {h} figure",
                b.text,
                b.rect.map(|v| v.round())
            ));
        }
    }
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            let dx = a.rect[2].min(b.rect[2]) - a.rect[0].max(b.rect[0]);
            let dy = a.rect[3].min(b.rect[3]) - a.rect[1].max(b.rect[1]);
            if dx > SLACK && dy > SLACK {
                out.push(format!(
                    "{:?} at {:?} overlaps {:?} at {:?}",
                    a.text,
                    a.rect.map(|v| v.round()),
                    b.text,
                    b.rect.map(|v| v.round())
                ));
            }
        }
    }
    out
}

/// Fails with every text problem of the SVG file at `path`.
pub fn assert_text_fits(path: &std::path::Path) {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let problems = problems(&svg);
    assert!(
        problems.is_empty(),
        "{}: {} text problem(s):\n{}",
        path.display(),
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn the_checker_sees_overlaps_clipping_and_rotation() {
    let fig = |texts: &str| format!("<svg width=\"200\" height=\"100\" viewBox=\"0 0 200 100\">{texts}</svg>");
    let t = |x, y, anchor, s| {
        format!("<text x=\"{x}\" y=\"{y}\" dy=\"0.76em\" text-anchor=\"{anchor}\" font-size=\"10\">\n{s}\n</text>")
    };
    // Side by side, apart: fine.
    assert!(problems(&fig(&(t(10, 10, "start", "abc") + &t(60, 10, "start", "def")))).is_empty());
    // The second starts inside the first.
    assert_eq!(
        problems(&fig(&(t(10, 10, "start", "abcdef") + &t(30, 12, "start", "x")))).len(),
        1
    );
    // Centred on the right edge: cut off.
    assert_eq!(problems(&fig(&t(200, 10, "middle", "abcdef"))).len(), 1);
    // Rotated a quarter turn about its anchor: now tall, not wide, so clear of a text beside it.
    let turned = "<text x=\"20\" y=\"50\" dy=\"0.5ex\" text-anchor=\"middle\" font-size=\"10\" transform=\"rotate(270, 20, 50)\">a vertical label</text>";
    let boxes = boxes(&fig(turned));
    let [l, top, r, bottom] = boxes[0].rect;
    assert!(r - l < 15.0 && bottom - top > 60.0, "{:?}", boxes[0].rect);
    assert!(problems(&fig(&(turned.to_string() + &t(40, 40, "start", "beside")))).is_empty());
}
