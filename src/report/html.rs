//! `report.html`: one self-contained page (no network; images inlined as PNG data URIs) per
//! `strata compare` and `strata experiments` run. Per section (a scene) a flip-book of the
//! reference and every variant's image (keys 1-9/0 pick one, arrows step, `r` the reference),
//! error maps per variant (relative squared error in false colour, signed error, FLIP), all
//! viewports of a section sharing one zoom (wheel) and pan (drag), with the pixel's linear RGB
//! under the cursor; then tables, convergence plots, the profiler's sampler-cost bars and the
//! command lines. The browser draws every text.
//!
//! Self-test: opened with `#selftest`, the page presses each flip-book key of every section and
//! writes what it showed, and any script error, into `<pre id="selftest">` (read with headless
//! Chromium's `--dump-dom`; see `tests/it/report_html.rs`).

use super::flip::{self, magma};
use base64::Engine as _;

/// One image of a flip-book: a label and linear RGB pixels.
pub struct Shot {
    /// the key's label (variant name, "reference")
    pub label: String,
    /// linear RGB, row-major
    pub rgb: Vec<[f32; 3]>,
}

/// A section of the page: one scene's flip-book and error maps, then its text blocks.
pub struct Section {
    /// the heading
    pub title: String,
    /// image width
    pub width: u32,
    /// image height
    pub height: u32,
    /// the reference, if any (error maps need it)
    pub reference: Option<Shot>,
    /// the variants' images
    pub shots: Vec<Shot>,
    /// every run's image (labels `variant run r`): a flip-book of its own, after the error maps
    /// (none: no such book)
    pub runs: Vec<Shot>,
    /// HTML blocks after the images (tables, plots, notes), in order
    pub blocks: Vec<String>,
}

/// The page: a title, sections, and HTML blocks at the end (profile bars, command lines).
pub struct Page {
    /// the `<title>` and top heading
    pub title: String,
    /// an HTML paragraph under the heading
    pub intro: String,
    /// the scenes
    pub sections: Vec<Section>,
    /// HTML blocks after the sections
    pub blocks: Vec<String>,
    /// the command lines that reproduce the page
    pub commands: Vec<String>,
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// An SVG file's text, inlined: the XML declaration dropped.
pub fn inline_svg(svg: &str) -> String {
    svg.trim_start().strip_prefix("<?xml version=\"1.0\" encoding=\"UTF-8\"?>").unwrap_or(svg).trim().to_string()
}

/// An 8-bit RGB image as a PNG data URI.
pub fn png_data_uri(width: u32, height: u32, rgb8: &[u8]) -> String {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        // Writing into a Vec fails only on a size mismatch, which the callers rule out.
        if let Ok(mut w) = enc.write_header() {
            let _ = w.write_image_data(rgb8);
        }
    }
    format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

/// Little-endian IEEE half floats (`half`; 3 significant digits, values to 65504), base64: the
/// linear pixels the page shows on hover, at half the size of f32.
fn values_b64(rgb: &[[f32; 3]]) -> String {
    let bytes: Vec<u8> =
        rgb.iter().flat_map(|p| p.iter().flat_map(|&v| half::f16::from_f32(v).to_le_bytes())).collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Box-filters linear RGB `rgb` (`width x height`) by an integer `factor` (at least 1): each output
/// pixel is the mean of a `factor x factor` block; a partial block at the right or bottom edge is
/// dropped. Returns the new width, height and pixels.
pub fn box_downsample(width: u32, height: u32, rgb: &[[f32; 3]], factor: u32) -> (u32, u32, Vec<[f32; 3]>) {
    let f = factor.max(1);
    let (w, h) = (width / f, height / f);
    let norm = 1.0 / (f * f) as f32;
    let out = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let mut acc = [0.0f32; 3];
            for (dx, dy) in (0..f).flat_map(|dy| (0..f).map(move |dx| (dx, dy))) {
                let p = rgb[((y * f + dy) * width + x * f + dx) as usize];
                (0..3).for_each(|c| acc[c] += p[c]);
            }
            acc.map(|v| v * norm)
        })
        .collect();
    (w, h, out)
}

/// The `q` quantile (0..1) of `v` (NaN-free), 0 when empty.
fn quantile(mut v: Vec<f32>, q: f64) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v.select_nth_unstable_by(i, f32::total_cmp);
    v[i]
}

/// The three error maps of `img` against `reference` as (label, legend, RGB8): relative squared
/// error (mean over channels of `(v - r)^2 / (r + 0.01)^2`, log10 from -4 to 1, magma), signed
/// error (mean over channels of `v - r`, blue negative, red positive, white 0, scaled to the 99th
/// percentile of |error|), and FLIP (magma, 0 to 1).
pub fn error_maps(img: &[[f32; 3]], reference: &[[f32; 3]], w: u32, h: u32) -> Vec<(String, String, Vec<u8>)> {
    let rel: Vec<f32> = img
        .iter()
        .zip(reference)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2) / (q[c].max(0.0) + 0.01).powi(2)).sum::<f32>() / 3.0)
        .collect();
    let rel8 = rel.iter().flat_map(|&e| magma(((e.max(1e-12).log10() + 4.0) / 5.0).clamp(0.0, 1.0))).collect();
    let signed: Vec<f32> =
        img.iter().zip(reference).map(|(p, q)| (0..3).map(|c| p[c] - q[c]).sum::<f32>() / 3.0).collect();
    let scale = quantile(signed.iter().map(|e| e.abs()).collect(), 0.99).max(1e-12);
    let signed8 = signed
        .iter()
        .flat_map(|&e| {
            let t = (e / scale).clamp(-1.0, 1.0);
            let fade = |x: f32| (255.0 * (1.0 - x.abs())).round() as u8;
            if t >= 0.0 {
                [255, fade(t), fade(t)]
            } else {
                [fade(t), fade(t), 255]
            }
        })
        .collect();
    let fl = flip::flip_map(reference, img, w, h);
    let mean_flip = flip::mean(&fl);
    let flip8 = fl.iter().flat_map(|&e| magma(e)).collect();
    vec![
        ("relMSE".into(), "relative squared error, log10 from -4 (black) to 1 (yellow)".into(), rel8),
        ("signed".into(), format!("signed error: blue -{scale:.3e}, white 0, red +{scale:.3e}"), signed8),
        ("FLIP".into(), format!("FLIP, 0 (black) to 1 (yellow); mean {mean_flip:.4}"), flip8),
    ]
}

/// One flip-book entry: the viewport image and its hover data.
fn entry(label: &str, kind: &str, legend: &str, w: u32, h: u32, rgb8: &[u8], values: Option<&[[f32; 3]]>) -> String {
    let vals = values.map_or(String::new(), |v| format!(" data-values=\"{}\"", values_b64(v)));
    format!(
        "<img class=\"shot\" data-label=\"{}\" data-kind=\"{kind}\" data-legend=\"{}\"{vals} width=\"{w}\" height=\"{h}\" alt=\"{}\" src=\"{}\">\n",
        escape(label),
        escape(legend),
        escape(label),
        png_data_uri(w, h, rgb8)
    )
}

/// The HTML of one section.
fn section_html(i: usize, s: &Section) -> String {
    let (w, h) = (s.width, s.height);
    let mut book = String::new();
    if let Some(r) = &s.reference {
        book += &entry(&r.label, "image", "reference", w, h, &flip::to_srgb8(&r.rgb), Some(&r.rgb));
    }
    for shot in &s.shots {
        book +=
            &entry(&shot.label, "image", "render (sRGB, clamped)", w, h, &flip::to_srgb8(&shot.rgb), Some(&shot.rgb));
    }
    let mut maps = String::new();
    if let Some(r) = &s.reference {
        for shot in &s.shots {
            for (kind, legend, rgb8) in error_maps(&shot.rgb, &r.rgb, w, h) {
                maps += &entry(&format!("{}: {kind}", shot.label), &kind, &legend, w, h, &rgb8, None);
            }
        }
    }
    let maps_html = if maps.is_empty() {
        String::new()
    } else {
        format!(
            "<div class=\"book maps\"><div class=\"bar\"></div><div class=\"view\">{maps}</div><div class=\"legend\"></div></div>\n"
        )
    };
    // The runs carry no hover values: half floats of every run would multiply the page's size.
    let runs: String = s
        .runs
        .iter()
        .map(|r| entry(&r.label, "run", "one run's render (sRGB, clamped)", w, h, &flip::to_srgb8(&r.rgb), None))
        .collect();
    let runs_html = if runs.is_empty() {
        String::new()
    } else {
        format!(
            "<div class=\"book runs\"><div class=\"bar\"></div><div class=\"view\">{runs}</div><div class=\"legend\"></div></div>\n"
        )
    };
    format!(
        "<section id=\"s{i}\"><h2>{}</h2>\n<div class=\"books\"><div class=\"book images\"><div class=\"bar\"></div>\
         <div class=\"view\">{book}</div><div class=\"legend\"></div></div>\n{maps_html}{runs_html}</div>\n\
         <p class=\"hover\">&nbsp;</p>\n{}\n</section>\n",
        escape(&s.title),
        s.blocks.join("\n")
    )
}

const STYLE: &str = r#"
body { font-family: sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.5em; }
.books { display: flex; flex-wrap: wrap; gap: 1.5em; align-items: flex-start; }
.view { position: relative; overflow: hidden; border: 1px solid #888; background: #333; cursor: crosshair; }
.view img.shot { position: absolute; left: 0; top: 0; transform-origin: 0 0; image-rendering: pixelated; display: none; }
.view img.shot.on { display: block; }
.bar button { margin: 0 0.3em 0.3em 0; font-size: 0.85em; }
.bar button.on { background: #246; color: white; }
.legend, .hover { font-size: 0.85em; color: #444; min-height: 1.2em; }
table { border-collapse: collapse; font-size: 0.8em; margin: 0.8em 0; max-width: 100%; }
td, th { border: 1px solid #bbb; padding: 0.2em 0.4em; text-align: right; white-space: nowrap; }
th { white-space: normal; vertical-align: bottom; }
td.text { white-space: normal; text-align: left; min-width: 10em; }
td:first-child, th:first-child { text-align: left; }
table.provenance td { white-space: normal; text-align: left; overflow-wrap: anywhere; }
pre { background: #f4f4f4; padding: 0.6em; white-space: pre-wrap; overflow-wrap: anywhere; }
.notes li { color: #842; }
svg { max-width: 100%; height: auto; }
figure img { max-width: 100%; height: auto; }
figure { margin: 0; font-size: 0.8em; color: #444; }
.figures, .crops, .crop-row { display: flex; flex-wrap: wrap; gap: 0.8em; align-items: flex-start; }
.crops { gap: 1.5em; } .crop-row { margin-bottom: 0.8em; }
.crop-label { width: 5.5em; font-size: 0.8em; }
figure img.crop, figure img.crop-err, figure img.overview, figure img.mean-error { display: block; image-rendering: pixelated; }
figure img.crop, figure img.crop-err { border: 1px solid #888; }
figure img.crop-err { margin-top: 2px; }
th.text { text-align: left; }
.overview { position: relative; }
.overview span { position: absolute; color: #fff; font-weight: bold; font-size: 0.9em; text-shadow: 0 0 2px #000; }
"#;

const SCRIPT: &str = r#"
(function () {
  'use strict';
  var errors = [];
  window.addEventListener('error', function (e) { errors.push(String(e.message)); });
  var sections = Array.prototype.slice.call(document.querySelectorAll('section'));
  var books = [];
  sections.forEach(function (sec) {
    var view = { scale: 1, tx: 0, ty: 0 };
    var secBooks = [];
    sec.querySelectorAll('.book').forEach(function (book) {
      var shots = Array.prototype.slice.call(book.querySelectorAll('img.shot'));
      if (!shots.length) { return; }
      var w = shots[0].width, h = shots[0].height;
      var box = book.querySelector('.view');
      // Views of at most 360 px a side (three fit in a row of a 1200-px page): small images
      // enlarged by a whole factor, large ones shrunk.
      var fit = Math.min(360 / w, 360 / h);
      fit = fit >= 1 ? Math.floor(fit) : fit;
      view.scale = fit;
      box.style.width = (w * fit) + 'px';
      box.style.height = (h * fit) + 'px';
      book.style.maxWidth = (w * fit + 2) + 'px';
      var bar = book.querySelector('.bar');
      var b = { sec: sec, shots: shots, index: 0, buttons: [], box: box, legend: book.querySelector('.legend'), w: w, h: h };
      shots.forEach(function (img, i) {
        var btn = document.createElement('button');
        btn.textContent = (i < 10 ? ((i + 1) % 10) + ' ' : '') + img.dataset.label;
        btn.addEventListener('click', function () { show(b, i); });
        bar.appendChild(btn);
        b.buttons.push(btn);
        img.removeAttribute('width');
        img.removeAttribute('height');
        img.style.width = w + 'px';
        img.style.height = h + 'px';
      });
      b.view = view;
      secBooks.push(b);
      books.push(b);
      show(b, 0);
      box.addEventListener('wheel', function (e) {
        e.preventDefault();
        var r = box.getBoundingClientRect(), mx = e.clientX - r.left, my = e.clientY - r.top;
        var f = e.deltaY < 0 ? 1.25 : 0.8;
        var s = Math.min(64, Math.max(0.25, view.scale * f));
        view.tx = mx - (mx - view.tx) * s / view.scale;
        view.ty = my - (my - view.ty) * s / view.scale;
        view.scale = s;
        apply(secBooks);
      }, { passive: false });
      var drag = null;
      box.addEventListener('mousedown', function (e) { drag = { x: e.clientX, y: e.clientY, tx: view.tx, ty: view.ty }; });
      window.addEventListener('mouseup', function () { drag = null; });
      box.addEventListener('mousemove', function (e) {
        if (drag) { view.tx = drag.tx + e.clientX - drag.x; view.ty = drag.ty + e.clientY - drag.y; apply(secBooks); }
        hover(b, e);
      });
    });
    apply(secBooks);
    sec.books = secBooks;
  });
  function apply(list) {
    list.forEach(function (b) {
      b.shots.forEach(function (img) {
        img.style.transform = 'translate(' + b.view.tx + 'px,' + b.view.ty + 'px) scale(' + b.view.scale + ')';
      });
    });
  }
  function show(b, i) {
    b.index = i;
    b.shots.forEach(function (img, j) { img.classList.toggle('on', j === i); });
    b.buttons.forEach(function (btn, j) { btn.classList.toggle('on', j === i); });
    b.legend.textContent = b.shots[i].dataset.label + ': ' + b.shots[i].dataset.legend;
    b.box.dataset.shown = b.shots[i].dataset.label;
  }
  function half(b) {
    var s = b & 0x8000 ? -1 : 1, e = (b >> 10) & 31, m = b & 1023;
    if (e === 0) { return s * m * Math.pow(2, -24); }
    if (e === 31) { return m ? NaN : s * Infinity; }
    return s * (1 + m / 1024) * Math.pow(2, e - 15);
  }
  var decoded = new WeakMap();
  function values(img) {
    if (!img.dataset.values) { return null; }
    if (!decoded.has(img)) {
      var s = atob(img.dataset.values), u = new Uint8Array(s.length);
      for (var i = 0; i < s.length; i++) { u[i] = s.charCodeAt(i); }
      var h = new Uint16Array(u.buffer), f = new Float32Array(h.length);
      for (var j = 0; j < h.length; j++) { f[j] = half(h[j]); }
      decoded.set(img, f);
    }
    return decoded.get(img);
  }
  function hover(b, e) {
    var r = b.box.getBoundingClientRect();
    var x = Math.floor((e.clientX - r.left - b.view.tx) / b.view.scale);
    var y = Math.floor((e.clientY - r.top - b.view.ty) / b.view.scale);
    var out = b.sec.querySelector('.hover');
    if (x < 0 || y < 0 || x >= b.w || y >= b.h) { out.textContent = '\u00a0'; return; }
    var text = 'pixel (' + x + ', ' + y + ')';
    b.sec.books.forEach(function (bk) {
      bk.shots.forEach(function (img) {
        var v = values(img);
        if (!v || (img !== bk.shots[bk.index] && img.dataset.label !== 'reference')) { return; }
        var k = 3 * (y * b.w + x);
        text += '   ' + img.dataset.label + ': ' + [v[k], v[k + 1], v[k + 2]].map(function (c) { return c.toPrecision(3); }).join(' ');
      });
    });
    out.textContent = text;
  }
  var active = books.length ? books[0] : null;
  books.forEach(function (b) { b.box.addEventListener('mouseenter', function () { active = b; }); });
  document.addEventListener('keydown', function (e) {
    if (!active) { return; }
    var n = active.shots.length;
    if (e.key >= '0' && e.key <= '9') {
      var i = (Number(e.key) + 9) % 10;
      if (i < n) { show(active, i); }
    } else if (e.key === 'ArrowRight') { show(active, (active.index + 1) % n); }
    else if (e.key === 'ArrowLeft') { show(active, (active.index + n - 1) % n); }
    else if (e.key === 'r') { show(active, 0); }
  });
  function selftest() {
    var lines = [];
    books.forEach(function (b, bi) {
      active = b;
      for (var i = 0; i < Math.min(b.shots.length, 10); i++) {
        document.dispatchEvent(new KeyboardEvent('keydown', { key: String((i + 1) % 10) }));
        var on = b.shots.filter(function (img) { return img.classList.contains('on'); });
        var v = on.length === 1 ? values(on[0]) : null, k = 3 * ((b.h >> 1) * b.w + (b.w >> 1));
        lines.push('section ' + b.sec.id + ' book ' + bi + ' key ' + ((i + 1) % 10) + ' shows ' + b.box.dataset.shown +
          ' visible ' + on.length + ' loaded ' + (on.length === 1 && on[0].complete && on[0].naturalWidth === b.w) +
          (v ? ' centre ' + [v[k], v[k + 1], v[k + 2]].join(' ') : ''));
      }
    });
    var root = document.documentElement;
    lines.push('layout scroll width ' + root.scrollWidth + ', client width ' + root.clientWidth);
    lines.push('errors ' + errors.length + (errors.length ? ': ' + errors.join(' | ') : ''));
    var pre = document.createElement('pre');
    pre.id = 'selftest';
    pre.textContent = lines.join('\n');
    document.body.appendChild(pre);
  }
  if (location.hash === '#selftest') {
    if (document.readyState === 'complete') { selftest(); } else { window.addEventListener('load', selftest); }
  }
})();
"#;

/// The page's HTML: one self-contained file.
pub fn page_html(p: &Page) -> String {
    let sections: String = p.sections.iter().enumerate().map(|(i, s)| section_html(i, s)).collect();
    let commands = if p.commands.is_empty() {
        String::new()
    } else {
        let lines: Vec<String> = p.commands.iter().map(|c| escape(c)).collect();
        format!("<h2>Reproduce</h2>\n<pre class=\"commands\">{}</pre>\n", lines.join("\n"))
    };
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{title}</title>\n<style>{STYLE}</style></head>\n\
         <body>\n<h1>{title}</h1>\n{intro}\n<p class=\"keys\">Flip-books: click an image, then keys 1-9 and 0 pick an \
         entry, arrows step, r shows the first; the wheel zooms and dragging pans every view of a section together; \
         the line under the views gives the linear RGB under the cursor.</p>\n{sections}{blocks}\n{commands}\
         <script>{SCRIPT}</script>\n</body></html>\n",
        title = escape(&p.title),
        intro = p.intro,
        blocks = p.blocks.join("\n"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_downsample_averages_blocks_and_drops_partial_ones() {
        let rgb: Vec<[f32; 3]> = (0..15).map(|i| [i as f32, 2.0 * i as f32, 1.0]).collect();
        let (w, h, d) = box_downsample(5, 3, &rgb, 2);
        assert_eq!((w, h), (2, 1));
        // block (0,0): pixels 0, 1, 5, 6 -> mean 3; block (1,0): 2, 3, 7, 8 -> mean 5
        assert_eq!(d, vec![[3.0, 6.0, 1.0], [5.0, 10.0, 1.0]]);
        assert_eq!(box_downsample(5, 3, &rgb, 1), (5, 3, rgb.clone()));
    }

    #[test]
    fn page_is_self_contained_and_escapes_text() {
        let shot = |l: &str, v: f32| Shot { label: l.into(), rgb: vec![[v; 3]; 6] };
        let page = Page {
            title: "a <b> & c".into(),
            intro: String::new(),
            sections: vec![Section {
                title: "s".into(),
                width: 3,
                height: 2,
                reference: Some(shot("reference", 0.5)),
                shots: vec![shot("x\"y", 0.25)],
                runs: vec![shot("x\"y run 1", 0.25), shot("x\"y run 2", 0.3)],
                blocks: vec![],
            }],
            blocks: vec![],
            commands: vec!["strata compare --variant 'a=--spp 1'".into()],
        };
        let html = page_html(&page);
        assert!(html.contains("<title>a &lt;b&gt; &amp; c</title>") && html.contains("data-label=\"x&quot;y\""));
        // One image entry per shot and reference, three error maps per shot, one frame per run,
        // PNG data URIs only.
        assert_eq!(html.matches("<img class=\"shot\"").count(), 2 + 3 + 2);
        assert_eq!(html.matches("src=\"data:image/png;base64,").count(), 7);
        assert_eq!(html.matches("data-kind=\"run\"").count(), 2);
        assert!(
            html.contains("strata compare --variant &#x27;a=--spp 1&#x27;") || html.contains("--variant 'a=--spp 1'")
        );
    }

    #[test]
    fn error_maps_are_black_where_equal_and_signed_by_colour() {
        let r = vec![[0.5f32; 3]; 4];
        let mut t = r.clone();
        t[1] = [0.7; 3];
        t[2] = [0.3; 3];
        let maps = error_maps(&t, &r, 2, 2);
        assert_eq!(maps.iter().map(|m| m.0.as_str()).collect::<Vec<_>>(), ["relMSE", "signed", "FLIP"]);
        let signed = &maps[1].2;
        assert_eq!(&signed[0..3], &[255, 255, 255], "no error: white");
        assert_eq!(&signed[3..6], &[255, 0, 0], "positive: red");
        assert_eq!(&signed[6..9], &[0, 0, 255], "negative: blue");
        assert_eq!(&maps[0].2[0..3], &magma(0.0), "no relative error: the bottom of the scale");
    }
}
