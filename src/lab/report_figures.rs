//! The figures of `compare`'s report that supplementary material needs beyond the flip-books:
//! each variant's mean squared error image over its runs ([`mean_error`], [`mean_error_html`]) and
//! insets of the regions where the variants differ most ([`pick_crops`], [`crops_html`]), with
//! the regions outlined on an overview of the reference. All are static `<img>`s (PNG data URIs)
//! sized to fit a 1200-px page.

use crate::report::flip::{magma, to_srgb8};
use crate::report::html::{escape, png_data_uri};
use std::fmt::Write as _;

/// The width in CSS pixels a row of figures may take (a 1200-px page less its margins).
const ROW_WIDTH: u32 = 1000;

/// How many regions [`crops_html`] shows.
pub const CROPS: usize = 3;

/// The outline colours of the regions on the overview, in order (A, B, C, ...).
const OUTLINE: [[u8; 3]; 4] = [[255, 220, 0], [0, 230, 255], [255, 60, 220], [120, 255, 90]];

/// Per pixel, the squared error against `reference` averaged over the three channels and over
/// `runs` (every run's image, same size): an estimate of the pixel's MSE.
pub fn mean_error(runs: &[Vec<[f32; 3]>], reference: &[[f32; 3]]) -> Vec<f32> {
    let k = runs.len().max(1) as f64;
    (0..reference.len())
        .map(|i| {
            let s: f64 = runs
                .iter()
                .map(|img| (0..3).map(|c| f64::from(img[i][c] - reference[i][c]).powi(2)).sum::<f64>() / 3.0)
                .sum();
            (s / k) as f32
        })
        .collect()
}

/// A square region of the image and what chose it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop {
    /// left column
    pub x: u32,
    /// top row
    pub y: u32,
    /// side in pixels
    pub side: u32,
    /// the spread of the variants' mean squared error over the region (largest minus smallest;
    /// the error itself with one variant)
    pub score: f64,
}

/// The side of the regions for a `w x h` image: a fifth of the shorter side, 4 to 64 pixels
/// (never more than the image).
pub fn crop_side(w: u32, h: u32) -> u32 {
    (w.min(h) / 5).clamp(4, 64).min(w.min(h)).max(1)
}

/// Summed-area table of `v` (`w x h`), `(w + 1) x (h + 1)`, in f64.
fn summed(v: &[f32], w: u32, h: u32) -> Vec<f64> {
    let (w, h) = (w as usize, h as usize);
    let mut s = vec![0.0; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0.0;
        for x in 0..w {
            row += f64::from(v[y * w + x]);
            s[(y + 1) * (w + 1) + x + 1] = s[y * (w + 1) + x + 1] + row;
        }
    }
    s
}

/// The mean of a summed-area table `s` (of a `w`-wide image) over the square at (x, y).
fn region_mean(s: &[f64], w: u32, x: u32, y: u32, side: u32) -> f64 {
    let (w1, x, y, d) = (w as usize + 1, x as usize, y as usize, side as usize);
    (s[(y + d) * w1 + x + d] - s[y * w1 + x + d] - s[(y + d) * w1 + x] + s[y * w1 + x]) / (d * d) as f64
}

/// Candidate corners along one axis: every half side, and the last position.
fn corners(len: u32, side: u32) -> Vec<u32> {
    let mut c: Vec<u32> = (0..=len - side).step_by((side / 2).max(1) as usize).collect();
    if c.last() != Some(&(len - side)) {
        c.push(len - side);
    }
    c
}

/// Up to `n` regions that do not overlap, where the variants' mean squared error images
/// (`errors`, one per variant, `w x h`) differ most: each candidate square (a [`crop_side`] side,
/// corners every half side) scores the largest minus the smallest variant's mean error over it
/// (with one variant, its error). Highest score first; ties go to the top-left one.
pub fn pick_crops(errors: &[&[f32]], w: u32, h: u32, n: usize) -> Vec<Crop> {
    if errors.is_empty() || w == 0 || h == 0 {
        return Vec::new();
    }
    let side = crop_side(w, h);
    let tables: Vec<Vec<f64>> = errors.iter().map(|e| summed(e, w, h)).collect();
    let mut cand = Vec::new();
    for &y in &corners(h, side) {
        for &x in &corners(w, side) {
            let m: Vec<f64> = tables.iter().map(|s| region_mean(s, w, x, y, side)).collect();
            let hi = m.iter().copied().fold(f64::MIN, f64::max);
            let lo = m.iter().copied().fold(f64::MAX, f64::min);
            let score = if m.len() > 1 { hi - lo } else { hi };
            cand.push(Crop { x, y, side, score });
        }
    }
    // Stable: equal scores keep the scan order (top-left first).
    cand.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut out: Vec<Crop> = Vec::new();
    for c in cand {
        let overlaps = out.iter().any(|o| o.x.abs_diff(c.x) < side && o.y.abs_diff(c.y) < side);
        if !overlaps {
            out.push(c);
            if out.len() == n {
                break;
            }
        }
    }
    out
}

/// The `q` quantile (0..1) of the finite values of `v`, 0 when there are none.
fn quantile(v: &[f32], q: f64) -> f32 {
    let mut v: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v.select_nth_unstable_by(i, f32::total_cmp);
    v[i]
}

/// One log scale for every variant's mean error image: (lo, hi) from the 5th percentile of the
/// smallest to the 99.9th of the largest, at most six decades, above 1e-12.
pub fn error_scale(errors: &[&[f32]]) -> (f32, f32) {
    let hi = errors.iter().map(|e| quantile(e, 0.999)).fold(0.0f32, f32::max).max(1e-12);
    let lo = errors.iter().map(|e| quantile(e, 0.05)).fold(f32::MAX, f32::min).clamp(hi * 1e-6, hi * 0.1);
    (lo, hi)
}

/// A mean error image as false colour (magma on log10, `scale` from black to yellow), 8-bit RGB.
fn error_rgb8(err: &[f32], (lo, hi): (f32, f32)) -> Vec<u8> {
    let (a, b) = (lo.max(1e-12).log10(), hi.max(1e-12).log10());
    err.iter().flat_map(|&e| magma(((e.max(1e-30).log10() - a) / (b - a).max(1e-6)).clamp(0.0, 1.0))).collect()
}

/// The square `c` of an 8-bit RGB image `w` wide.
fn cut(rgb8: &[u8], w: u32, c: &Crop) -> Vec<u8> {
    let mut out = Vec::with_capacity((3 * c.side * c.side) as usize);
    for y in c.y..c.y + c.side {
        let start = 3 * (y * w + c.x) as usize;
        out.extend_from_slice(&rgb8[start..start + 3 * c.side as usize]);
    }
    out
}

/// Draws the outline of `c` (one pixel wide) into an 8-bit RGB image `w` wide.
fn outline(rgb8: &mut [u8], w: u32, c: &Crop, colour: [u8; 3]) {
    let mut put = |x: u32, y: u32| {
        let i = 3 * (y * w + x) as usize;
        rgb8[i..i + 3].copy_from_slice(&colour);
    };
    for t in 0..c.side {
        put(c.x + t, c.y);
        put(c.x + t, c.y + c.side - 1);
        put(c.x, c.y + t);
        put(c.x + c.side - 1, c.y + t);
    }
}

/// An `<img>` of an 8-bit RGB image shown `zoom` times its size, pixelated.
fn img(class: &str, attrs: &str, w: u32, h: u32, zoom: u32, rgb8: &[u8], alt: &str) -> String {
    format!(
        "<img class=\"{class}\"{attrs} width=\"{}\" height=\"{}\" alt=\"{}\" src=\"{}\">",
        w * zoom,
        h * zoom,
        escape(alt),
        png_data_uri(w, h, rgb8)
    )
}

/// The region's letter: A, B, C, ...
fn letter(i: usize) -> char {
    char::from(b'A' + (i % 26) as u8)
}

/// The mean squared error images of the variants (`errors`, `w x h`, over `runs` runs) side by
/// side on one log scale, each captioned with its mean.
pub fn mean_error_html(names: &[&str], errors: &[&[f32]], w: u32, h: u32, runs: usize) -> String {
    let scale = error_scale(errors);
    let per_row = names.len().clamp(1, 3) as u32;
    let zoom = (ROW_WIDTH / (per_row * w).max(1)).clamp(1, 3);
    let mut figs = String::new();
    for (name, err) in names.iter().zip(errors) {
        let mean = err.iter().map(|&e| f64::from(e)).sum::<f64>() / err.len().max(1) as f64;
        let attrs = format!(" data-variant=\"{}\"", escape(name));
        let _ = writeln!(
            figs,
            "<figure>{}<figcaption>{}: mean {mean:.3e}</figcaption></figure>",
            img("mean-error", &attrs, w, h, zoom, &error_rgb8(err, scale), &format!("{name}: mean squared error")),
            escape(name)
        );
    }
    format!(
        "<h3>Mean squared error per pixel over the runs</h3>\n<p>Per variant, the squared error against the \
         reference averaged over the channels and over its {runs} runs at the last step: where its error lives. \
         One scale for all: log10 from {:.2e} (black) to {:.2e} (yellow), magma.</p>\n<div class=\"figures\">{figs}</div>\n",
        scale.0, scale.1
    )
}

/// Insets of the regions where the variants differ most ([`pick_crops`] on `errors`): an overview
/// of the reference with the regions outlined, then per region the reference's crop and each
/// variant's crop of run 1 (`images`) with its mean error crop and the region's MSE over the runs.
pub fn crops_html(
    reference: &[[f32; 3]],
    w: u32,
    h: u32,
    names: &[&str],
    images: &[&[[f32; 3]]],
    errors: &[&[f32]],
) -> String {
    let crops = pick_crops(errors, w, h, CROPS);
    if crops.is_empty() {
        return String::new();
    }
    let scale = error_scale(errors);
    let ref8 = to_srgb8(reference);
    let mut over = ref8.clone();
    for (i, c) in crops.iter().enumerate() {
        outline(&mut over, w, c, OUTLINE[i % OUTLINE.len()]);
    }
    let oz = (360 / w.max(1)).clamp(1, 4);
    let mut labels = String::new();
    for (i, c) in crops.iter().enumerate() {
        let _ = write!(labels, "<span style=\"left:{}px;top:{}px\">{}</span>", c.x * oz + 2, c.y * oz + 1, letter(i));
    }
    let side = crops[0].side;
    // At most 128 CSS pixels a crop, and a row of the reference and every variant in ROW_WIDTH.
    let zoom = (ROW_WIDTH / ((names.len() as u32 + 1) * side).max(1)).min(128 / side.max(1)).clamp(1, 8);
    let variants8: Vec<Vec<u8>> = images.iter().map(|i| to_srgb8(i)).collect();
    let errors8: Vec<Vec<u8>> = errors.iter().map(|e| error_rgb8(e, scale)).collect();
    let sums: Vec<Vec<f64>> = errors.iter().map(|e| summed(e, w, h)).collect();
    let mut rows = String::new();
    for (i, c) in crops.iter().enumerate() {
        let l = letter(i);
        let a = |v: &str| format!(" data-crop=\"{l}\" data-crop-variant=\"{}\"", escape(v));
        let _ = write!(
            rows,
            "<div class=\"crop-row\"><div class=\"crop-label\"><b>{l}</b><br>x {}, y {}<br>{}x{} px</div>\
             <figure>{}<figcaption>reference</figcaption></figure>",
            c.x,
            c.y,
            c.side,
            c.side,
            img("crop", &a("reference"), side, side, zoom, &cut(&ref8, w, c), &format!("{l}: reference"))
        );
        for (k, name) in names.iter().enumerate() {
            let mse = region_mean(&sums[k], w, c.x, c.y, c.side);
            let _ = write!(
                rows,
                "<figure>{}{}<figcaption>{}<br>MSE here {mse:.3e}</figcaption></figure>",
                img("crop", &a(name), side, side, zoom, &cut(&variants8[k], w, c), &format!("{l}: {name}")),
                img("crop-err", "", side, side, zoom, &cut(&errors8[k], w, c), &format!("{l}: {name}, mean error")),
                escape(name)
            );
        }
        rows += "</div>\n";
    }
    format!(
        "<h3>Crops where the variants differ most</h3>\n<p>The {} non-overlapping {side}x{side}-pixel regions \
         where the variants' mean squared error (over the runs) differs most, largest spread first. Per region: the \
         reference, then each variant's run 1 (sRGB, clamped) above its mean error (the scale of the mean error \
         images), with the region's MSE over the runs.</p>\n<div class=\"crops\"><figure class=\"crop-overview\">\
         <div class=\"overview\">{}{labels}</div><figcaption>reference, regions outlined</figcaption></figure>\n\
         <div class=\"crop-grid\">{rows}</div></div>\n",
        crops.len(),
        img("overview", "", w, h, oz, &over, "reference with the regions outlined")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_error_averages_channels_and_runs() {
        let reference = vec![[0.5f32; 3]; 2];
        let runs = vec![vec![[0.5, 0.5, 0.5], [1.5, 0.5, 0.5]], vec![[0.5, 0.5, 0.5], [0.5, 0.5, 3.5]]];
        let e = mean_error(&runs, &reference);
        assert_eq!(e[0], 0.0);
        assert!((e[1] - (1.0 / 3.0 + 9.0 / 3.0) / 2.0).abs() < 1e-6, "{}", e[1]);
    }

    /// Two variants equal everywhere but in one square, a third region where both err alike: the
    /// first crop is where they differ, not where the error is largest; crops never overlap.
    #[test]
    fn crops_go_where_variants_differ_not_where_both_err() {
        let (w, h) = (60u32, 40u32);
        let mut a = vec![0.01f32; (w * h) as usize];
        let mut b = a.clone();
        for y in 20..28 {
            for x in 40..48 {
                b[(y * w + x) as usize] = 0.5;
            }
        }
        for y in 0..8 {
            for x in 0..8 {
                a[(y * w + x) as usize] = 5.0;
                b[(y * w + x) as usize] = 5.0;
            }
        }
        let crops = pick_crops(&[&a, &b], w, h, 3);
        assert_eq!(crops.len(), 3);
        let c = crops[0];
        assert_eq!(c.side, 8);
        assert!((40..48).contains(&(c.x + 4)) && (20..28).contains(&(c.y + 4)), "{c:?}");
        assert!(c.score > 0.2, "{c:?}");
        for (i, p) in crops.iter().enumerate() {
            for q in &crops[i + 1..] {
                assert!(p.x.abs_diff(q.x) >= p.side || p.y.abs_diff(q.y) >= p.side, "{p:?} overlaps {q:?}");
            }
        }
        // With one variant, the crop goes to its largest error.
        let one = pick_crops(&[&a], w, h, 1)[0];
        assert_eq!((one.x, one.y), (0, 0));
    }

    #[test]
    fn crops_html_shows_the_reference_and_every_variant_per_region() {
        let (w, h) = (20u32, 20u32);
        let reference = vec![[0.5f32; 3]; 400];
        let img_a = vec![[0.6f32; 3]; 400];
        let mut img_b = reference.clone();
        img_b[0] = [2.0; 3];
        let ea = mean_error(std::slice::from_ref(&img_a), &reference);
        let eb = mean_error(std::slice::from_ref(&img_b), &reference);
        let html = crops_html(&reference, w, h, &["a", "b"], &[&img_a, &img_b], &[&ea, &eb]);
        assert_eq!(html.matches("<img class=\"crop\"").count(), 3 * CROPS);
        assert_eq!(html.matches("data-crop-variant=\"b\"").count(), CROPS);
        assert!(html.contains("class=\"crop-overview\""));
        let m = mean_error_html(&["a", "b"], &[&ea, &eb], w, h, 1);
        assert_eq!(m.matches("<img class=\"mean-error\"").count(), 2);
    }
}
