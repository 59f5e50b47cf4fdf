//! PNG contact sheets: images side by side in a grid, each with up to a few lines of label text
//! drawn in a built-in 5x7 bitmap font (upper case, digits and `-.,:=+/()%_?<>[]`; lower-case
//! letters are drawn as upper case, anything else as `?`).

use std::io;
use std::path::Path;

/// One image of a sheet: 8-bit RGB pixels, row-major, and the label lines drawn under it.
#[derive(Clone, Debug)]
pub struct Tile {
    /// width in pixels
    pub width: u32,
    /// height in pixels
    pub height: u32,
    /// `width * height` pixels, row-major
    pub rgb: Vec<[u8; 3]>,
    /// label lines drawn under the image (clipped to the tile width)
    pub label: Vec<String>,
}

/// Glyph cell: 5x7 pixels plus one column and two rows of spacing.
pub const GLYPH_W: u32 = 6;
/// Height of one label line in pixels.
pub const LINE_H: u32 = 9;
/// Gap between tiles and around the sheet, in pixels.
pub const GAP: u32 = 4;

/// A laid-out sheet: `width * height` 8-bit RGB pixels, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Sheet {
    /// width in pixels
    pub width: u32,
    /// height in pixels
    pub height: u32,
    /// pixels, row-major
    pub rgb: Vec<[u8; 3]>,
}

/// The 5x7 bitmap of `c`: seven rows, bit 4 the leftmost pixel.
pub fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        ' ' => [0; 7],
        '0' => [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e],
        '1' => [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e],
        '2' => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f],
        '3' => [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e],
        '4' => [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02],
        '5' => [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e],
        '6' => [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e],
        '7' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e],
        '9' => [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c],
        'A' => [0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11],
        'B' => [0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e],
        'C' => [0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e],
        'D' => [0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c],
        'E' => [0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f],
        'F' => [0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10],
        'G' => [0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f],
        'H' => [0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11],
        'I' => [0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f],
        'M' => [0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e],
        'P' => [0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10],
        'Q' => [0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d],
        'R' => [0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11],
        'S' => [0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e],
        'T' => [0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a],
        'X' => [0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0a, 0x04, 0x04, 0x04],
        'Z' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f],
        '-' => [0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c],
        ',' => [0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08],
        ':' => [0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00],
        '=' => [0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00],
        '+' => [0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00],
        '/' => [0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '[' => [0x0e, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0e],
        ']' => [0x0e, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0e],
        '<' => [0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02],
        '>' => [0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '_' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f],
        _ => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04],
    }
}

/// Draws `text` with its top-left corner at (x, y) in `color`, clipped to the `w x h` image and to
/// x < `clip_x`.
#[allow(clippy::too_many_arguments)]
fn draw_text(rgb: &mut [[u8; 3]], w: u32, h: u32, x: u32, y: u32, clip_x: u32, text: &str, color: [u8; 3]) {
    for (i, c) in text.chars().enumerate() {
        let gx = x + i as u32 * GLYPH_W;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..5u32 {
                let (px, py) = (gx + col, y + row as u32);
                if bits & (0x10 >> col) != 0 && px < w.min(clip_x) && py < h {
                    rgb[(py * w + px) as usize] = color;
                }
            }
        }
    }
}

/// Lays `tiles` out in rows of `columns` (at least 1) under an optional title line: every cell is
/// as large as the largest tile plus its label lines; background dark grey, text white.
pub fn layout(tiles: &[Tile], columns: usize, title: Option<&str>) -> Sheet {
    let columns = columns.max(1);
    let cell_w = tiles.iter().map(|t| t.width).max().unwrap_or(0);
    let lines = tiles.iter().map(|t| t.label.len() as u32).max().unwrap_or(0);
    let cell_h = tiles.iter().map(|t| t.height).max().unwrap_or(0) + lines * LINE_H;
    let rows = tiles.len().div_ceil(columns) as u32;
    let cols = columns.min(tiles.len().max(1)) as u32;
    let top = if title.is_some() { GAP + LINE_H } else { 0 };
    let mut width = GAP + cols * (cell_w + GAP);
    if let Some(t) = title {
        width = width.max(2 * GAP + t.chars().count() as u32 * GLYPH_W);
    }
    let height = top + GAP + rows * (cell_h + GAP);
    let mut rgb = vec![[40u8, 40, 40]; (width * height) as usize];
    if let Some(t) = title {
        draw_text(&mut rgb, width, height, GAP, GAP, width, t, [255, 255, 255]);
    }
    for (i, t) in tiles.iter().enumerate() {
        let x0 = GAP + (i % columns) as u32 * (cell_w + GAP);
        let y0 = top + GAP + (i / columns) as u32 * (cell_h + GAP);
        for y in 0..t.height {
            let src = &t.rgb[(y * t.width) as usize..((y + 1) * t.width) as usize];
            let d = ((y0 + y) * width + x0) as usize;
            rgb[d..d + t.width as usize].copy_from_slice(src);
        }
        for (l, line) in t.label.iter().enumerate() {
            let y = y0 + t.height + 1 + l as u32 * LINE_H;
            draw_text(&mut rgb, width, height, x0, y, x0 + cell_w, line, [255, 255, 255]);
        }
    }
    Sheet { width, height, rgb }
}

/// A tile from linear RGB, box-downsampled by `factor` ([`box_downsample`]), encoded with `gamma`
/// (as the renderer's PNGs) and labelled.
pub fn tile_from_linear(
    width: u32,
    height: u32,
    linear: &[[f32; 3]],
    factor: u32,
    gamma: f32,
    label: Vec<String>,
) -> Tile {
    let (width, height, small) = box_downsample(width, height, linear, factor);
    let rgb = small.iter().map(|p| p.map(|v| crate::film::to_u8(v, gamma))).collect();
    Tile { width, height, rgb, label }
}

/// Box-filters linear RGB `rgb` (`width x height`) by an integer `factor` (at least 1): each output
/// pixel is the mean of a `factor x factor` block; a partial block at the right or bottom edge is
/// dropped. Returns the new width, height and pixels.
pub fn box_downsample(width: u32, height: u32, rgb: &[[f32; 3]], factor: u32) -> (u32, u32, Vec<[f32; 3]>) {
    let f = factor.max(1);
    let (w, h) = (width / f, height / f);
    let mut out = vec![[0.0f32; 3]; (w * h) as usize];
    let norm = 1.0 / (f * f) as f32;
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0.0f32; 3];
            for dy in 0..f {
                for dx in 0..f {
                    let p = rgb[((y * f + dy) * width + x * f + dx) as usize];
                    for c in 0..3 {
                        acc[c] += p[c];
                    }
                }
            }
            out[(y * w + x) as usize] = acc.map(|v| v * norm);
        }
    }
    (w, h, out)
}

/// Encodes `sheet` as an 8-bit RGB PNG (best compression) and writes it atomically.
pub fn write_sheet(path: &Path, sheet: &Sheet) -> io::Result<()> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, sheet.width, sheet.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::High);
        let mut w = enc.write_header().map_err(io::Error::other)?;
        let flat: Vec<u8> = sheet.rgb.iter().flatten().copied().collect();
        w.write_image_data(&flat).map_err(io::Error::other)?;
    }
    crate::film::write_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile(w: u32, h: u32, c: [u8; 3], label: &[&str]) -> Tile {
        Tile {
            width: w,
            height: h,
            rgb: vec![c; (w * h) as usize],
            label: label.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn glyphs_are_distinct_and_lowercase_maps_to_uppercase() {
        let set = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ-.,:=+/()[]<>%_";
        let gl: Vec<[u8; 7]> = set.chars().map(glyph).collect();
        for i in 0..gl.len() {
            assert!(gl[i].iter().all(|&r| r < 32), "5 pixels wide");
            for j in 0..i {
                assert_ne!(gl[i], gl[j], "{:?} and {:?} look the same", set.chars().nth(i), set.chars().nth(j));
            }
        }
        assert_eq!(glyph('a'), glyph('A'));
        assert_eq!(glyph('~'), glyph('?'));
    }

    #[test]
    fn tiles_land_in_their_cells_and_labels_are_drawn_below() {
        let tiles =
            [tile(10, 8, [255, 0, 0], &["A"]), tile(10, 8, [0, 255, 0], &[]), tile(6, 4, [0, 0, 255], &["1", "L"])];
        let s = layout(&tiles, 2, None);
        let cell_h = 8 + 2 * LINE_H;
        assert_eq!((s.width, s.height), (GAP + 2 * (10 + GAP), GAP + 2 * (cell_h + GAP)));
        let at = |x: u32, y: u32| s.rgb[(y * s.width + x) as usize];
        assert_eq!(at(GAP, GAP), [255, 0, 0]);
        assert_eq!(at(GAP + 9, GAP + 7), [255, 0, 0]);
        assert_eq!(at(2 * GAP + 10, GAP), [0, 255, 0]);
        assert_eq!(at(GAP, 2 * GAP + cell_h), [0, 0, 255]);
        assert_eq!(at(GAP + 6, 2 * GAP + cell_h), [40, 40, 40], "smaller tile leaves background");
        // "A" under tile 0: its glyph's rows, pixel for pixel.
        let (lx, ly) = (GAP, GAP + 8 + 1);
        for (row, bits) in glyph('A').iter().enumerate() {
            for col in 0..5 {
                let on = bits & (0x10 >> col) != 0;
                assert_eq!(at(lx + col, ly + row as u32) == [255, 255, 255], on, "row {row} col {col}");
            }
        }
        // second line of tile 2's label: "L" has its bottom row full.
        let (lx, ly) = (GAP, 2 * GAP + cell_h + 4 + 1 + LINE_H);
        assert!((0..5).all(|c| at(lx + c, ly + 6) == [255, 255, 255]));
    }

    #[test]
    fn labels_are_clipped_to_their_cell() {
        let tiles = [tile(7, 3, [0, 0, 0], &["MMMM"]), tile(7, 3, [9, 9, 9], &[])];
        let s = layout(&tiles, 2, None);
        // The second glyph would start at x = GAP + 6 and spill into the gap and the next cell.
        for y in 0..s.height {
            for x in GAP + 7..s.width {
                assert_ne!(s.rgb[(y * s.width + x) as usize], [255, 255, 255], "({x}, {y})");
            }
        }
    }

    #[test]
    fn box_downsample_averages_blocks_and_drops_partial_edges() {
        let rgb: Vec<[f32; 3]> = (0..5 * 3).map(|i| [i as f32, 2.0 * i as f32, 1.0]).collect();
        let (w, h, d) = box_downsample(5, 3, &rgb, 2);
        assert_eq!((w, h), (2, 1));
        // block (0,0): pixels 0, 1, 5, 6 -> mean 3; block (1,0): 2, 3, 7, 8 -> mean 5
        assert_eq!(d, vec![[3.0, 6.0, 1.0], [5.0, 10.0, 1.0]]);
        assert_eq!(box_downsample(5, 3, &rgb, 1), (5, 3, rgb.clone()));
    }

    #[test]
    fn written_png_decodes_to_the_sheet() {
        let tiles = [tile(12, 5, [10, 200, 30], &["X=1"]), tile(12, 5, [1, 2, 3], &["Y"])];
        let s = layout(&tiles, 1, Some("TITLE"));
        let p = std::env::temp_dir().join(format!("strata-contact-{}.png", std::process::id()));
        write_sheet(&p, &s).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&p).unwrap()));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        std::fs::remove_file(&p).ok();
        assert_eq!((info.width, info.height), (s.width, s.height));
        let flat: Vec<u8> = s.rgb.iter().flatten().copied().collect();
        assert_eq!(&buf[..info.buffer_size()], &flat[..]);
    }
}
