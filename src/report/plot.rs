//! Log-log convergence plots (error against time) as self-contained SVG.

use std::fmt::Write;

/// One named curve of `(seconds, error)` points, drawn in the given order.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// legend label
    pub name: String,
    /// `(x, y)` = (seconds, error)
    pub points: Vec<(f64, f64)>,
}

/// Guide slope for RMSE against time: Monte Carlo error falls as `time^(-1/2)`.
pub const RMSE_SLOPE: f64 = -0.5;
/// Guide slope for MSE (or variance) against time.
pub const MSE_SLOPE: f64 = -1.0;

/// A log10 axis over whole decades `10^lo ..= 10^hi`, mapped linearly in `log10(v)` onto pixels:
/// `10^lo` lands on `px_lo` and `10^hi` on `px_hi` (so `px_lo > px_hi` gives an upward y axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogScale {
    /// exponent of the first decade
    pub lo: i32,
    /// exponent of the last decade (> `lo`)
    pub hi: i32,
    /// pixel coordinate of `10^lo`
    pub px_lo: f64,
    /// pixel coordinate of `10^hi`
    pub px_hi: f64,
}

impl LogScale {
    /// The smallest whole-decade axis covering `values` (non-positive and non-finite ones are
    /// ignored), at least one decade wide; `10^0 ..= 10^1` when no value is usable.
    pub fn covering(values: impl IntoIterator<Item = f64>, px_lo: f64, px_hi: f64) -> Self {
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        for l in values.into_iter().filter(|v| v.is_finite() && *v > 0.0).map(f64::log10) {
            (min, max) = (min.min(l), max.max(l));
        }
        // A value within 1e-9 decades of a power of ten counts as that power (log10 rounding).
        let (lo, hi) = if min <= max { ((min + 1e-9).floor() as i32, (max - 1e-9).ceil() as i32) } else { (0, 1) };
        LogScale { lo, hi: hi.max(lo + 1), px_lo, px_hi }
    }

    /// Pixel coordinate of `v > 0`.
    pub fn map(&self, v: f64) -> f64 {
        self.map_log10(v.log10())
    }

    /// Pixel coordinate of the value whose log10 is `l`.
    fn map_log10(&self, l: f64) -> f64 {
        self.px_lo + (l - self.lo as f64) / (self.hi - self.lo) as f64 * (self.px_hi - self.px_lo)
    }
}

// Layout in SVG pixels: the plot area, then the legend to its right.
const WIDTH: f64 = 780.0;
const HEIGHT: f64 = 480.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 560.0;
const TOP: f64 = 50.0;
const BOTTOM: f64 = 410.0;
const LEGEND_X: f64 = 580.0;

/// A self-contained SVG log-log plot: decade grid, ticks and `10^k` labels on both axes, one
/// polyline with circle markers per series in distinct colours, a legend, and a dashed guide line
/// of slope `guide_slope` (in decades per decade, e.g. [`RMSE_SLOPE`] or [`MSE_SLOPE`]) through the
/// first plottable point of the first series, clipped to the plot area. Points with a
/// non-positive or non-finite coordinate are skipped and listed in an SVG comment; the guide is
/// left out (with a comment) when the first series has no plottable point or the slope is not
/// finite. Axes span whole decades covering all plottable points.
pub fn loglog_svg(series: &[Series], title: &str, x_label: &str, y_label: &str, guide_slope: f64) -> String {
    loglog_svg_annotated(series, &[], title, x_label, y_label, guide_slope)
}

/// What is drawn at each point of a series besides its marker, index-aligned with its points.
#[derive(Clone, Debug, Default)]
pub struct Annotation {
    /// a vertical error bar from `lo` to `hi` per point (a non-positive `lo` is drawn to the axis)
    pub y_range: Vec<(f64, f64)>,
    /// a text label per point (e.g. its spp)
    pub labels: Vec<String>,
}

/// [`loglog_svg`] with error bars and point labels: `annotations[i]` belongs to `series[i]`.
pub fn loglog_svg_annotated(
    series: &[Series],
    annotations: &[Annotation],
    title: &str,
    x_label: &str,
    y_label: &str,
    guide_slope: f64,
) -> String {
    loglog_svg_guided(series, annotations, title, x_label, y_label, guide_slope, None)
}

/// [`loglog_svg_annotated`] with the guide through `anchor` (x, y) instead of the first point
/// (e.g. a spectrum's white-noise level, slope 0 at power 1); the y axis then covers it too.
pub fn loglog_svg_guided(
    series: &[Series],
    annotations: &[Annotation],
    title: &str,
    x_label: &str,
    y_label: &str,
    guide_slope: f64,
    anchor: Option<(f64, f64)>,
) -> String {
    let plottable = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
    let kept: Vec<Vec<(f64, f64)>> =
        series.iter().map(|s| s.points.iter().copied().filter(plottable).collect()).collect();
    let (xs, mut ys) = scales(&kept);
    if let Some((_, y)) = anchor.filter(|a| plottable(a)) {
        let with = LogScale::covering(kept.iter().flatten().map(|p| p.1).chain([y]), BOTTOM, TOP);
        ys = with;
    }
    let mut svg = String::new();
    let mut put = |s: String| svg.push_str(&s);

    put(format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{WIDTH}\" height=\"{HEIGHT}\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"sans-serif\" font-size=\"12\">\n"
    ));
    for (i, s) in series.iter().enumerate() {
        let skipped: Vec<String> =
            s.points.iter().filter(|p| !plottable(p)).map(|(x, y)| format!("({x}, {y})")).collect();
        if !skipped.is_empty() {
            let shown = skipped.iter().take(8).cloned().collect::<Vec<_>>().join(" ");
            let more = if skipped.len() > 8 { " ..." } else { "" };
            put(format!(
                "<!-- series {i}: skipped {} point(s) with non-positive or non-finite coordinates: {shown}{more} -->\n",
                skipped.len()
            ));
        }
    }
    put(format!("<rect width=\"{WIDTH}\" height=\"{HEIGHT}\" fill=\"white\"/>\n"));
    put(format!(
        "<defs><clipPath id=\"plot-area\"><rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\"/></clipPath></defs>\n",
        RIGHT - LEFT,
        BOTTOM - TOP
    ));
    put(axis(&xs, true));
    put(axis(&ys, false));
    put(format!(
        "<rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n",
        RIGHT - LEFT,
        BOTTOM - TOP
    ));
    put(format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"16\" font-weight=\"bold\">{}</text>\n",
        (LEFT + RIGHT) / 2.0,
        TOP - 20.0,
        escape(title)
    ));
    put(format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"14\">{}</text>\n",
        (LEFT + RIGHT) / 2.0,
        BOTTOM + 50.0,
        escape(x_label)
    ));
    put(format!(
        "<text transform=\"translate({} {}) rotate(-90)\" text-anchor=\"middle\" font-size=\"14\">{}</text>\n",
        LEFT - 55.0,
        (TOP + BOTTOM) / 2.0,
        escape(y_label)
    ));

    // Guide: log y = log y0 + slope (log x - log x0), drawn across the x axis.
    let first = kept.first().and_then(|p| p.first()).copied();
    let anchor = anchor.filter(|a| plottable(a)).or(first);
    let anchor = anchor.as_ref().filter(|_| guide_slope.is_finite());
    let mut legend_y = TOP + 10.0;
    if let Some(&(x0, y0)) = anchor {
        let at = |l: f64| (xs.map_log10(l), ys.map_log10(y0.log10() + guide_slope * (l - x0.log10())));
        let ((ax, ay), (bx, by)) = (at(xs.lo as f64), at(xs.hi as f64));
        put(format!(
            "<polyline class=\"guide\" points=\"{ax:.2},{ay:.2} {bx:.2},{by:.2}\" fill=\"none\" stroke=\"#555\" \
             stroke-width=\"1.5\" stroke-dasharray=\"6 4\" clip-path=\"url(#plot-area)\"/>\n"
        ));
        put(format!(
            "<line x1=\"{LEGEND_X}\" y1=\"{legend_y}\" x2=\"{}\" y2=\"{legend_y}\" stroke=\"#555\" stroke-width=\"1.5\" \
             stroke-dasharray=\"6 4\"/>\n<text x=\"{}\" y=\"{}\">slope {guide_slope}</text>\n",
            LEGEND_X + 30.0,
            LEGEND_X + 38.0,
            legend_y + 4.0
        ));
        legend_y += 20.0;
    } else {
        put("<!-- no guide line: the first series has no plottable point or the slope is not finite -->\n".into());
    }

    // Point labels placed so far: (x, y of the baseline start, width).
    let mut placed: Vec<(f64, f64, f64)> = Vec::new();
    for (i, s) in series.iter().enumerate() {
        let colour = colour(i);
        let mut coords = String::new();
        let mut markers = String::new();
        let ann = annotations.get(i);
        for (j, &(x, y)) in s.points.iter().enumerate().filter(|(_, p)| plottable(p)) {
            let (px, py) = (xs.map(x), ys.map(y));
            if let Some(&(lo, hi)) = ann.and_then(|a| a.y_range.get(j)) {
                let clamp = |v: f64| if v > 0.0 && v.is_finite() { ys.map(v).clamp(TOP, BOTTOM) } else { BOTTOM };
                let (a, b) = (clamp(lo), clamp(hi));
                let _ = writeln!(
                    markers,
                    "<line class=\"error-bar\" x1=\"{px:.2}\" y1=\"{a:.2}\" x2=\"{px:.2}\" y2=\"{b:.2}\" stroke=\"{colour}\" stroke-width=\"1.5\"/>\n\
                     <line x1=\"{:.2}\" y1=\"{a:.2}\" x2=\"{:.2}\" y2=\"{a:.2}\" stroke=\"{colour}\"/><line x1=\"{:.2}\" y1=\"{b:.2}\" x2=\"{:.2}\" y2=\"{b:.2}\" stroke=\"{colour}\"/>",
                    px - 4.0,
                    px + 4.0,
                    px - 4.0,
                    px + 4.0
                );
            }
            if let Some(label) = ann.and_then(|a| a.labels.get(j)) {
                // Above right, below right, above left, below left: the first place no label
                // holds yet; none free, the label is left out (the point and the legend stay).
                let w = 5.5 * label.chars().count() as f64;
                let spots =
                    [(px + 5.0, py - 5.0), (px + 5.0, py + 14.0), (px - 5.0 - w, py - 5.0), (px - 5.0 - w, py + 14.0)];
                let free = |&(x, y): &(f64, f64)| {
                    placed
                        .iter()
                        .all(|&(a, b, aw): &(f64, f64, f64)| x + w < a || a + aw < x || y < b - 11.0 || b < y - 11.0)
                };
                if let Some(&(x, y)) = spots.iter().find(|p| free(p)) {
                    placed.push((x, y, w));
                    let _ = writeln!(
                        markers,
                        "<text class=\"point-label\" x=\"{x:.2}\" y=\"{y:.2}\" font-size=\"10\" fill=\"{colour}\">{}</text>",
                        escape(label)
                    );
                }
            }
            let sep = if coords.is_empty() { "" } else { " " };
            let _ = write!(coords, "{sep}{px:.2},{py:.2}");
            let _ = writeln!(markers, "<circle cx=\"{px:.2}\" cy=\"{py:.2}\" r=\"3.5\" fill=\"{colour}\"/>");
        }
        put(format!(
            "<g class=\"series\">\n<polyline points=\"{coords}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>\n{markers}</g>\n"
        ));
        put(format!(
            "<line x1=\"{LEGEND_X}\" y1=\"{legend_y}\" x2=\"{}\" y2=\"{legend_y}\" stroke=\"{colour}\" stroke-width=\"2\"/>\n\
             <circle cx=\"{}\" cy=\"{legend_y}\" r=\"3.5\" fill=\"{colour}\"/>\n<text x=\"{}\" y=\"{}\">{}</text>\n",
            LEGEND_X + 30.0,
            LEGEND_X + 15.0,
            LEGEND_X + 38.0,
            legend_y + 4.0,
            escape(&s.name)
        ));
        legend_y += 20.0;
    }
    if kept.iter().all(Vec::is_empty) {
        put(format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"#888\">no plottable data</text>\n",
            (LEFT + RIGHT) / 2.0,
            (TOP + BOTTOM) / 2.0
        ));
    }
    svg + "</svg>\n"
}

/// The x and y scales covering the plottable points.
fn scales(kept: &[Vec<(f64, f64)>]) -> (LogScale, LogScale) {
    let all = || kept.iter().flatten();
    (LogScale::covering(all().map(|p| p.0), LEFT, RIGHT), LogScale::covering(all().map(|p| p.1), BOTTOM, TOP))
}

/// Grid lines, ticks and labels of one axis: labelled decades (every decade, or every n-th when
/// there are more than 10), and ticks at 2..9 times each decade when there are at most 8; an axis
/// of at most 2 decades also labels the ticks at 2 and 5 times each decade in plain numbers (a
/// budget ladder's 0.25..2 s would otherwise show one label).
fn axis(scale: &LogScale, horizontal: bool) -> String {
    let decades = scale.hi - scale.lo;
    let step = (decades + 9) / 10;
    let mut s = String::new();
    // (position, tick length, label: a decade's exponent, or a plain number)
    let mut ticks: Vec<(f64, f64, Option<i32>, Option<String>)> = Vec::new();
    let plain = |k: i32, e: i32| {
        if e >= 0 {
            format!("{}", f64::from(k) * 10f64.powi(e))
        } else {
            format!("{}", f64::from(k) / 10f64.powi(-e))
        }
    };
    for e in scale.lo..=scale.hi {
        ticks.push((scale.map_log10(e as f64), 6.0, ((e - scale.lo) % step == 0).then_some(e), None));
        if decades <= 8 && e < scale.hi {
            ticks.extend((2..10).map(|k| {
                let label = (decades <= 2 && (k == 2 || k == 5)).then(|| plain(k, e));
                (scale.map_log10(e as f64 + (k as f64).log10()), if label.is_some() { 4.5 } else { 3.0 }, None, label)
            }));
        }
    }
    for (p, len, label, minor) in ticks {
        if horizontal {
            if len > 3.0 {
                let _ = writeln!(s, "<line x1=\"{p:.2}\" y1=\"{TOP}\" x2=\"{p:.2}\" y2=\"{BOTTOM}\" stroke=\"#ddd\"/>");
            }
            let _ = writeln!(
                s,
                "<line x1=\"{p:.2}\" y1=\"{BOTTOM}\" x2=\"{p:.2}\" y2=\"{}\" stroke=\"black\"/>",
                BOTTOM - len
            );
        } else {
            if len > 3.0 {
                let _ = writeln!(s, "<line x1=\"{LEFT}\" y1=\"{p:.2}\" x2=\"{RIGHT}\" y2=\"{p:.2}\" stroke=\"#ddd\"/>");
            }
            let _ =
                writeln!(s, "<line x1=\"{LEFT}\" y1=\"{p:.2}\" x2=\"{}\" y2=\"{p:.2}\" stroke=\"black\"/>", LEFT + len);
        }
        if let Some(text) = minor {
            let (x, y, anchor) = if horizontal { (p, BOTTOM + 18.0, "middle") } else { (LEFT - 8.0, p + 4.0, "end") };
            let _ = writeln!(s, "<text class=\"minor\" x=\"{x:.2}\" y=\"{y:.2}\" text-anchor=\"{anchor}\" font-size=\"10\" fill=\"#444\">{text}</text>");
        }
        if let Some(e) = label {
            let (x, y, anchor) = if horizontal { (p, BOTTOM + 20.0, "middle") } else { (LEFT - 8.0, p + 4.0, "end") };
            let _ = writeln!(
                s,
                "<text x=\"{x:.2}\" y=\"{y:.2}\" text-anchor=\"{anchor}\">10<tspan dy=\"-6\" font-size=\"9\">{e}</tspan></text>"
            );
        }
    }
    s
}

/// Series colour: a colour-blind-safe palette, then hues spaced by the golden angle.
pub(super) fn colour(i: usize) -> String {
    const PALETTE: [&str; 7] = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"];
    PALETTE.get(i).map_or_else(|| format!("hsl({:.0}, 70%, 40%)", (i as f64 * 137.508) % 360.0), |c| c.to_string())
}

/// Escapes text for XML content and attribute values.
pub(super) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks that elements nest properly (skipping the XML declaration and comments, and
    /// rejecting `--` inside comments and stray `<`/`&` in text); returns the element names.
    fn check_xml(svg: &str) -> Vec<String> {
        let (mut stack, mut names, mut rest) = (Vec::<String>::new(), Vec::new(), svg);
        while let Some(start) = rest.find('<') {
            let text = &rest[..start];
            assert!(!text.contains('>'), "stray '>' in text {text:?}");
            for (i, _) in text.match_indices('&') {
                assert!(["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"].iter().any(|e| text[i..].starts_with(e)));
            }
            rest = &rest[start..];
            if let Some(body) = rest.strip_prefix("<!--") {
                let end = body.find("-->").expect("unterminated comment");
                assert!(!body[..end].contains("--") && !body[..end].ends_with('-'), "bad comment");
                rest = &body[end + 3..];
                continue;
            }
            let end = rest.find('>').expect("unterminated tag");
            let tag = &rest[1..end];
            rest = &rest[end + 1..];
            if tag.starts_with('?') {
                assert!(tag.ends_with('?'));
            } else if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
            } else {
                assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
                let name = tag.split_whitespace().next().unwrap().trim_end_matches('/').to_string();
                names.push(name.clone());
                if !tag.ends_with('/') {
                    stack.push(name);
                }
            }
        }
        assert!(rest.trim().is_empty() && stack.is_empty(), "unclosed {stack:?}");
        assert_eq!(names.first().map(String::as_str), Some("svg"));
        names
    }

    /// The coordinates in the `points` attribute of every polyline, in document order.
    fn polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
        svg.split("<polyline")
            .skip(1)
            .map(|p| {
                let attr = p.split("points=\"").nth(1).unwrap().split('"').next().unwrap();
                attr.split_whitespace()
                    .map(|xy| {
                        let (x, y) = xy.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect()
            })
            .collect()
    }

    fn series() -> Vec<Series> {
        vec![
            Series { name: "independent".into(), points: vec![(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)] },
            Series {
                name: "a < b & \"c\"".into(),
                points: vec![(2.0, 0.5), (0.0, 1.0), (20.0, f64::NAN), (30.0, 0.02)],
            },
            Series { name: "empty".into(), points: vec![(-1.0, 1.0)] },
        ]
    }

    #[test]
    fn log_scale_decades() {
        let s = LogScale::covering([1.0, 100.0], 80.0, 560.0);
        assert_eq!((s.lo, s.hi), (0, 2));
        let decade = s.map(10.0) - s.map(1.0);
        assert!((decade - 240.0).abs() < 1e-9 && (s.map(100.0) - s.map(10.0) - decade).abs() < 1e-9);
        assert!((s.map(1.0) - 80.0).abs() < 1e-9 && (s.map(100.0) - 560.0).abs() < 1e-9);
        assert!((s.map(10f64.sqrt()) - 200.0).abs() < 1e-9);
        let s = LogScale::covering([0.003, 0.07, f64::NAN, -1.0, 0.0], 0.0, 1.0);
        assert_eq!((s.lo, s.hi), (-3, -1));
        assert_eq!((LogScale::covering([1000.0], 0.0, 1.0).lo, LogScale::covering([1000.0], 0.0, 1.0).hi), (3, 4));
        assert_eq!(LogScale::covering([], 0.0, 1.0), LogScale { lo: 0, hi: 1, px_lo: 0.0, px_hi: 1.0 });
        // Inverted pixel range for a y axis: larger values are higher up (smaller y).
        let y = LogScale::covering([1e-4, 1.0], 400.0, 50.0);
        assert!(y.map(1e-2) < y.map(1e-3) && (y.map(1.0) - 50.0).abs() < 1e-9);
    }

    #[test]
    fn svg_structure_and_content() {
        let svg = loglog_svg(&series(), "Cornell <box>", "time [s]", "RMSE", RMSE_SLOPE);
        let names = check_xml(&svg);
        assert_eq!(names.iter().filter(|n| *n == "polyline").count(), 3 + 1);
        assert_eq!(svg.matches("class=\"guide\"").count(), 1);
        assert!(
            svg.contains(">time [s]</text>") && svg.contains(">RMSE</text>") && svg.contains("Cornell &lt;box&gt;")
        );
        assert!(svg.contains("a &lt; b &amp; &quot;c&quot;") && svg.contains(">empty</text>"));
        assert!(svg.contains(
            "<!-- series 1: skipped 2 point(s) with non-positive or non-finite coordinates: (0, 1) (20, NaN) -->"
        ));
        assert!(svg.contains("<!-- series 2: skipped 1 point(s)"));
        assert!(!svg.contains("series 0: skipped"));
        assert!(svg.contains("slope -0.5"));
        // No external resources.
        assert!(!svg.contains("href") && !svg.contains("<script") && !svg.contains("@import"));
        // Distinct colours.
        let strokes: Vec<&str> = svg
            .split("<polyline points=")
            .skip(1)
            .map(|p| p.split("stroke=\"").nth(1).unwrap().split('"').next().unwrap())
            .collect();
        assert_eq!(strokes.len(), 3);
        assert!(strokes[0] != strokes[1] && strokes[1] != strokes[2] && strokes[0] != strokes[2]);
        assert!((0..20).map(colour).collect::<std::collections::HashSet<_>>().len() == 20);
    }

    #[test]
    fn svg_positions_follow_the_log_scales() {
        let svg = loglog_svg(&series(), "t", "x", "y", RMSE_SLOPE);
        // x spans 1..100 (two decades), y spans 0.01..1.
        let xs = LogScale::covering([1.0, 100.0], LEFT, RIGHT);
        let ys = LogScale::covering([0.01, 1.0], BOTTOM, TOP);
        assert_eq!(scales(&[vec![(1.0, 1.0), (100.0, 0.01)], vec![(30.0, 0.02)]]), (xs, ys));
        let lines = polylines(&svg);
        let (guide, first) = (&lines[0], &lines[1]);
        let near = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 0.006 && (a.1 - b.1).abs() < 0.006;
        for (p, &(x, y)) in first.iter().zip(&[(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)]) {
            assert!(near(*p, (xs.map(x), ys.map(y))), "{p:?}");
        }
        // x = 10 is exactly one decade right of x = 1, and the decades are equally wide.
        assert!((first[1].0 - first[0].0 - (RIGHT - LEFT) / 2.0).abs() < 0.006);
        assert!((first[2].0 - first[1].0 - (first[1].0 - first[0].0)).abs() < 0.012);
        // Second series keeps only its two plottable points.
        assert_eq!(lines[2].len(), 2);
        assert!(lines[3].is_empty());
        // Guide through (1, 1) with slope -1/2: at x = 100 it is at y = 0.1.
        assert!(near(guide[0], (xs.map(1.0), ys.map(1.0))) && near(guide[1], (xs.map(100.0), ys.map(0.1))));
        // With slope -1 it reaches y = 0.01.
        let guide = polylines(&loglog_svg(&series(), "t", "x", "y", MSE_SLOPE))[0].clone();
        assert!(near(guide[1], (xs.map(100.0), ys.map(0.01))));
        // Anchored at the first plottable point, (2, 0.5) here: y = 0.5 (x / 2)^slope at both ends.
        let s = Series { name: "s".into(), points: vec![(0.0, 1.0), (2.0, 0.5), (30.0, 0.02)] };
        let (xs, ys) = scales(&[vec![(2.0, 0.5), (30.0, 0.02)]]);
        let guide = polylines(&loglog_svg(&[s], "t", "x", "y", -0.5))[0].clone();
        assert!(near(guide[0], (xs.map(1.0), ys.map(0.5 * 0.5f64.powf(-0.5)))), "{guide:?}");
        assert!(near(guide[1], (xs.map(100.0), ys.map(0.5 * 50f64.powf(-0.5)))), "{guide:?}");
    }

    #[test]
    fn svg_degenerate_inputs() {
        for svg in [
            loglog_svg(&[], "t", "x", "y", RMSE_SLOPE),
            loglog_svg(&[Series { name: "bad".into(), points: vec![(f64::INFINITY, 1.0)] }], "t", "x", "y", -0.5),
            loglog_svg(&series(), "t", "x", "y", f64::NAN),
        ] {
            check_xml(&svg);
            assert!(svg.contains("<!-- no guide line") && !svg.contains("class=\"guide\""));
        }
        // Many decades: labels thin out but every decade keeps its grid line.
        let wide = Series { name: "w".into(), points: vec![(1e-30, 1.0), (1e30, 2.0)] };
        let svg = loglog_svg(&[wide], "t", "x", "y", -1.0);
        check_xml(&svg);
        assert!(svg.contains(">-30</tspan>") && svg.contains(">30</tspan>") && !svg.contains(">-29</tspan>"));
    }

    #[test]
    fn point_labels_do_not_collide_and_short_axes_are_labelled() {
        // A budget ladder's seconds (0.25..2: one decade) and labels of two variants at nearly the
        // same points: before, every label sat 5 px above-right of its point, on top of the other.
        let s = vec![
            Series { name: "a".into(), points: vec![(0.25, 1e-2), (0.5, 7e-3), (1.0, 5e-3), (2.0, 3.5e-3)] },
            Series {
                name: "b".into(),
                points: vec![(0.251, 1.01e-2), (0.502, 7.05e-3), (1.0, 5.02e-3), (2.01, 3.5e-3)],
            },
        ];
        let labels = |n: &str| Annotation {
            y_range: Vec::new(),
            labels: ["70 spp", "141 spp", "283 spp", "570 spp"].iter().map(|l| format!("{n} {l}")).collect(),
        };
        let svg = loglog_svg_annotated(&s, &[labels("a"), labels("b")], "t", "x", "y", RMSE_SLOPE);
        let boxes: Vec<(f64, f64, f64)> = svg
            .lines()
            .filter(|l| l.contains("class=\"point-label\""))
            .map(|l| {
                let attr = |k: &str| {
                    l.split(&format!("{k}=\"")).nth(1).unwrap().split('"').next().unwrap().parse::<f64>().unwrap()
                };
                let text = l.split('>').nth(1).unwrap().split('<').next().unwrap();
                (attr("x"), attr("y"), 5.5 * text.chars().count() as f64)
            })
            .collect();
        assert!(boxes.len() >= 6, "most labels are kept: {}", boxes.len());
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                let apart = a.0 + a.2 < b.0 || b.0 + b.2 < a.0 || (a.1 - b.1).abs() > 11.0;
                assert!(apart, "labels overlap: {a:?} {b:?}");
            }
        }
        // The x axis spans one decade (0.1..1 and 1..10: two): 0.2, 0.5, 2 and 5 are written out.
        for t in [">0.2<", ">0.5<", ">2<", ">5<"] {
            assert!(svg.contains(t), "no tick label {t}");
        }
    }
}
