//! Stacked bar charts as self-contained SVG (the style of [`super::plot`]: no fonts embedded,
//! sans-serif text, the same palette): one horizontal bar per variant, split into segments (e.g.
//! the phases of `strata profile`), with a legend of the segments and their shares in %.

use super::plot::{colour, escape};
use std::fmt::Write;

/// One bar: a label, a length and its segments.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    /// label left of the bar (the variant)
    pub label: String,
    /// drawn length relative to the other bars (e.g. ns per sample); the longest fills the plot
    pub total: f64,
    /// text right of the bar (e.g. "812 ns/sample")
    pub total_label: String,
    /// each segment's share of the bar, in legend order (non-finite or negative shares draw nothing)
    pub shares: Vec<f64>,
}

// Layout in SVG pixels: each bar under its label (so no label is clipped), an axis of the totals
// under the bars, the legend to their right.
const WIDTH: f64 = 1000.0;
const LEFT: f64 = 20.0;
const RIGHT: f64 = 620.0;
const TOP: f64 = 50.0;
const BAR_H: f64 = 26.0;
const BAR_GAP: f64 = 28.0;
const LEGEND_X: f64 = 650.0;
const LEGEND_DY: f64 = 18.0;
/// Segments at least this wide (pixels) carry their share as text.
const LABEL_MIN_PX: f64 = 34.0;

/// A self-contained SVG stacked bar chart: bar `i` is drawn from the left edge with length
/// `total / max total`, its segments in the order of `segments` and coloured like the legend
/// entries, each with a `<title>` (segment name and share) and, where wide enough, its share in %
/// as text. The legend lists every segment; with a single bar it gives the segment's share too.
/// Bars without a positive finite total are drawn empty (and said so in a comment). Each bar's
/// label and total label are written above it; under the bars an axis of the totals with round
/// ticks and `axis_label`.
pub fn stacked_bars_svg(bars: &[Bar], segments: &[&str], title: &str, axis_label: &str) -> String {
    let max = bars.iter().map(|b| b.total).filter(|t| t.is_finite() && *t > 0.0).fold(0.0, f64::max);
    let bars_h = TOP + bars.len() as f64 * (BAR_H + BAR_GAP) + 60.0;
    let legend_h = TOP + segments.len() as f64 * LEGEND_DY + 30.0;
    let height = bars_h.max(legend_h).ceil();
    let mut svg = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{WIDTH}\" height=\"{height}\" viewBox=\"0 0 {WIDTH} {height}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{WIDTH}\" height=\"{height}\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"16\" font-weight=\"bold\">{}</text>\n",
        WIDTH / 2.0,
        TOP - 24.0,
        escape(title)
    );
    for (i, b) in bars.iter().enumerate() {
        let y = TOP + 18.0 + i as f64 * (BAR_H + BAR_GAP);
        let len = if max > 0.0 && b.total.is_finite() && b.total > 0.0 { b.total / max * (RIGHT - LEFT) } else { 0.0 };
        if len == 0.0 {
            let _ = writeln!(svg, "<!-- bar {i}: total {} is not positive: drawn empty -->", b.total);
        }
        let _ = writeln!(svg, "<g class=\"bar\">");
        let _ = writeln!(
            svg,
            "<text x=\"{LEFT}\" y=\"{:.2}\"><tspan font-weight=\"bold\">{}</tspan>  {}</text>",
            y - 6.0,
            escape(&b.label),
            escape(&b.total_label)
        );
        let sum: f64 = b.shares.iter().filter(|s| s.is_finite() && **s > 0.0).sum();
        let mut x = LEFT;
        for (j, &share) in b.shares.iter().enumerate() {
            if !(share.is_finite() && share > 0.0) || len == 0.0 {
                continue;
            }
            let w = share / sum.max(1e-300) * len;
            let name = segments.get(j).copied().unwrap_or("?");
            let _ = writeln!(
                svg,
                "<rect class=\"segment\" x=\"{x:.2}\" y=\"{y:.2}\" width=\"{w:.2}\" height=\"{BAR_H}\" fill=\"{}\" \
                 stroke=\"white\" stroke-width=\"0.5\"><title>{}: {:.1}%</title></rect>",
                colour(j),
                escape(name),
                100.0 * share
            );
            if w >= LABEL_MIN_PX {
                let _ = writeln!(
                    svg,
                    "<text x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"middle\" fill=\"white\" font-size=\"10\">{:.0}%</text>",
                    x + w / 2.0,
                    y + BAR_H / 2.0 + 3.5,
                    100.0 * share
                );
            }
            x += w;
        }
        let _ = writeln!(svg, "</g>");
    }
    if max > 0.0 {
        svg += &axis(max, TOP + 18.0 + bars.len() as f64 * (BAR_H + BAR_GAP) - BAR_GAP + 8.0, axis_label);
    }
    let one = (bars.len() == 1).then(|| &bars[0]);
    for (j, name) in segments.iter().enumerate() {
        let y = TOP + j as f64 * LEGEND_DY;
        let share = one.and_then(|b| b.shares.get(j)).map(|s| format!(" {:.1}%", 100.0 * s)).unwrap_or_default();
        let _ = writeln!(
            svg,
            "<g class=\"legend-entry\"><rect x=\"{LEGEND_X}\" y=\"{y:.2}\" width=\"12\" height=\"12\" fill=\"{}\"/>\
             <text x=\"{}\" y=\"{:.2}\" font-size=\"11\">{}{}</text></g>",
            colour(j),
            LEGEND_X + 18.0,
            y + 10.0,
            escape(name),
            share
        );
    }
    svg + "</svg>\n"
}

/// The axis of the totals under the bars: a line, ticks at a round step (1, 2 or 5 x 10^k, about
/// five of them) with their values, and the label.
fn axis(max: f64, y: f64, label: &str) -> String {
    let raw = max / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
    let mut out = format!(
        "<g class=\"axis\"><line x1=\"{LEFT}\" y1=\"{y:.2}\" x2=\"{RIGHT}\" y2=\"{y:.2}\" stroke=\"black\"/>\n"
    );
    let mut v = 0.0;
    while v <= max * (1.0 + 1e-9) {
        let x = LEFT + v / max * (RIGHT - LEFT);
        let _ = writeln!(
            out,
            "<line x1=\"{x:.2}\" y1=\"{y:.2}\" x2=\"{x:.2}\" y2=\"{:.2}\" stroke=\"black\"/><text x=\"{x:.2}\" y=\"{:.2}\" \
             text-anchor=\"middle\" font-size=\"10\">{}</text>",
            y + 5.0,
            y + 17.0,
            super::table::g3(v).trim_end_matches(".000")
        );
        v += step;
    }
    let _ = writeln!(
        out,
        "<text x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"middle\">{}</text></g>",
        (LEFT + RIGHT) / 2.0,
        y + 34.0,
        escape(label)
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Element names in document order, checking that tags nest and close (comments and the XML
    /// declaration skipped; attribute values without `<`, `>`).
    fn elements(svg: &str) -> Vec<String> {
        let (mut stack, mut names, mut rest) = (Vec::<String>::new(), Vec::new(), svg);
        while let Some(i) = rest.find('<') {
            assert!(!rest[..i].contains('>'), "stray > in text: {}", &rest[..i]);
            rest = &rest[i..];
            if let Some(r) = rest.strip_prefix("<!--") {
                let end = r.find("-->").expect("unclosed comment");
                rest = &r[end + 3..];
                continue;
            }
            let end = rest.find('>').expect("unclosed tag");
            let tag = &rest[1..end];
            rest = &rest[end + 1..];
            if tag.starts_with('?') {
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
                continue;
            }
            assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
            let name = tag.split_whitespace().next().unwrap_or("").trim_end_matches('/').to_string();
            names.push(name.clone());
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed elements {stack:?}");
        names
    }

    fn bar(label: &str, total: f64, shares: &[f64]) -> Bar {
        Bar { label: label.into(), total, total_label: format!("{total} ns"), shares: shares.to_vec() }
    }

    /// Well-formed, one `bar` group per bar, one legend entry per segment, segment widths in
    /// proportion to the shares and bar lengths in proportion to the totals; names are escaped.
    #[test]
    fn bars_legend_and_proportions() {
        let segs = ["sampler: a", "b & c", "other"];
        let bars = [bar("x<1>", 100.0, &[0.5, 0.25, 0.25]), bar("y", 50.0, &[0.0, 1.0, 0.0])];
        let svg = stacked_bars_svg(&bars, &segs, "t", "ns");
        let names = elements(&svg);
        assert_eq!(svg.matches("<g class=\"bar\">").count(), 2);
        assert_eq!(svg.matches("<g class=\"legend-entry\">").count(), 3);
        assert_eq!(names.iter().filter(|n| *n == "rect").count(), 1 + 3 + 1 + 3, "background, segments, legend");
        assert!(svg.contains("x&lt;1&gt;") && svg.contains("b &amp; c"));
        let widths: Vec<f64> = svg
            .lines()
            .filter(|l| l.contains("class=\"segment\""))
            .map(|l| l.split("width=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap())
            .collect();
        let full = RIGHT - LEFT;
        assert_eq!(widths.len(), 4);
        for (w, want) in widths.iter().zip([full / 2.0, full / 4.0, full / 4.0, full / 2.0]) {
            assert!((w - want).abs() < 0.01, "{w} vs {want}");
        }
        assert!(svg.contains("50%") && svg.contains("b &amp; c: 25.0%"));
        // Labels start at the left margin (never clipped), the bars span 60% of the width, and an
        // axis of the totals runs under them: ticks 0, 20, ..., 100 and its label.
        assert!(svg.contains(&format!("<text x=\"{LEFT}\" y=")) && (RIGHT - LEFT) / WIDTH >= 0.6);
        let axis = &svg[svg.find("<g class=\"axis\">").expect("an axis")..];
        for t in [">0<", ">20<", ">100<", ">ns<"] {
            assert!(axis.contains(t), "{t} in {axis}");
        }
    }

    /// A single bar's legend shows the shares; a bar without a positive total is drawn empty.
    #[test]
    fn single_bar_legend_shares_and_empty_bars() {
        let svg = stacked_bars_svg(&[bar("only", 10.0, &[0.75, 0.25])], &["a", "b"], "t", "ns");
        elements(&svg);
        assert!(svg.contains(">a 75.0%<") && svg.contains(">b 25.0%<"));
        let svg = stacked_bars_svg(&[bar("none", 0.0, &[1.0])], &["a"], "t", "ns");
        elements(&svg);
        assert_eq!(svg.matches("class=\"segment\"").count(), 0);
        assert!(svg.contains("drawn empty"));
    }
}
