//! Tests of accumulation (dyadic blocks, merge) and of the image files.
use super::*;
use std::fs::{self, File};
use std::io;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

/// A fresh, empty scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("strata-film-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

fn tmp_of(path: &Path) -> PathBuf {
    PathBuf::from(format!("{}.tmp-{}", path.display(), std::process::id()))
}

#[test]
fn mean_and_variance_of_known_samples() {
    let mut f = Film::new(3, 2);
    for v in [1.0, 2.0, 3.0] {
        let mut px = [[0.0f32; 3]; 6];
        px[5] = [v, 2.0 * v, -v];
        px[0] = [5.0; 3];
        f.add_sample(10 + v as u32, &px);
    }
    let (m, var) = (f.mean(), f.variance_of_mean());
    assert_eq!(f.samples(), 11..14);
    assert_eq!(m[5], [2.0, 4.0, -2.0]);
    let third = 1.0f32 / 3.0;
    assert!((var[5][0] - third).abs() < 1e-7 && (var[5][1] - 4.0 * third).abs() < 1e-6);
    assert!((var[5][2] - third).abs() < 1e-7);
    assert_eq!((m[0], var[0]), ([5.0; 3], [0.0; 3]), "constant samples: mean, no variance");
    assert_eq!((m[1], var[1]), ([0.0; 3], [0.0; 3]), "zero samples");
    assert_eq!(f.count, vec![3; 6]);
    assert_eq!((Film::new(2, 1).mean(), Film::new(2, 1).count), (vec![[0.0; 3]; 2], vec![0, 0]), "no samples");
    let mut g = Film::new(1, 1);
    (0..4).for_each(|s| g.add_sample(s, &[[0.1; 3]]));
    assert_eq!(g.variance_of_mean()[0], [0.0; 3], "constant samples: no negative round-off");
}

/// A value with many significant bits, different per (sample, pixel, channel).
fn value(s: u32, p: usize) -> [f32; 3] {
    let x = (s as f32 + 1.0) * 0.7310586 + p as f32 * 0.1234567;
    [x.sin() * 3.1 + 3.2, 1.0 / (1.0 + x), (x * 1.618034).fract() * 1e3]
}

fn film_of(r: Range<u32>, w: u32, h: u32) -> Film {
    let mut f = Film::new(w, h);
    for s in r {
        let px: Vec<[f32; 3]> = (0..(w * h) as usize).map(|p| value(s, p)).collect();
        f.add_sample(s, &px);
    }
    f
}

fn bits(f: &Film) -> Vec<u64> {
    f.sum.iter().chain(&f.sum_sq).flat_map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn canonical_blocks_are_the_minimal_aligned_cover() {
    let b = |k, j| Block { k, j };
    assert_eq!(canonical_blocks(0..7), vec![b(2, 0), b(1, 2), b(0, 6)]);
    assert_eq!(canonical_blocks(3..13), vec![b(0, 3), b(2, 1), b(2, 2), b(0, 12)]);
    assert_eq!(canonical_blocks(0..64), vec![b(6, 0)]);
    assert_eq!(canonical_blocks(5..5), vec![]);
    assert_eq!(canonical_blocks(0..u32::MAX).len(), 32);
    assert_eq!(canonical_blocks(1 << 31..(1 << 31) + 1), vec![b(0, 1 << 31)]);
    for lo in 0..40u32 {
        for hi in lo..80 {
            let bl = canonical_blocks(lo..hi);
            // Contiguous cover, and no two neighbours are siblings (else it is not minimal).
            let mut at = u64::from(lo);
            for w in bl.windows(2) {
                assert!(!w[0].is_left_sibling_of(w[1]), "{lo}..{hi}: {bl:?}");
            }
            for x in &bl {
                assert_eq!(x.start(), at);
                at = x.end();
            }
            assert_eq!(at, u64::from(hi));
            let mut counter = Vec::new();
            (lo..hi).for_each(|s| {
                push_block(&mut counter, Block::leaf(s));
            });
            assert_eq!(counter, bl, "{lo}..{hi}: the binary counter builds the canonical blocks");
            assert!(
                bl.len() <= 2 * (32 - (hi - lo).max(1).leading_zeros()) as usize,
                "{lo}..{hi}: {} blocks",
                bl.len()
            );
        }
    }
}

#[test]
fn merge_of_any_split_is_bit_identical_to_one_film() {
    let (w, h) = (3, 2);
    let all = film_of(0..45, w, h);
    for cuts in [vec![1u32], vec![20], vec![7, 8, 9], vec![3, 16, 17, 31, 44], vec![32], (1..45).collect()] {
        let mut edges = vec![0];
        edges.extend(&cuts);
        edges.push(45);
        let parts: Vec<Film> = edges.windows(2).map(|e| film_of(e[0]..e[1], w, h)).collect();
        // Merge left to right, and also right to left: same bits, same blocks.
        let mut l = Film::new(w, h);
        parts.iter().for_each(|p| l.merge(p).unwrap());
        let mut r = Film::new(w, h);
        parts.iter().rev().for_each(|p| r.merge(p).unwrap());
        for m in [&l, &r] {
            assert_eq!(m.samples(), 0..45);
            assert_eq!(m.blocks(), all.blocks(), "cuts {cuts:?}");
            assert_eq!(bits(m), bits(&all), "cuts {cuts:?}");
            assert_eq!(m.count, all.count);
        }
    }
    // Not adjacent, or another size: refused.
    let mut a = film_of(0..4, w, h);
    assert!(a.merge(&film_of(5..9, w, h)).unwrap_err().to_string().contains("not adjacent"));
    assert!(a.merge(&film_of(4..9, 2, 2)).is_err());
    assert_eq!(a.samples(), 0..4, "a refused merge leaves the film as it was");
}

#[test]
fn dyadic_sum_is_close_to_the_plain_sum_and_from_parts_checks_blocks() {
    let f = film_of(0..100, 2, 1);
    for p in 0..2 {
        let plain = (0..100).map(|s| f64::from(value(s, p)[1])).sum::<f64>();
        assert!((f.sum[p][1] - plain).abs() <= 1e-12 * plain.abs(), "{} vs {plain}", f.sum[p][1]);
    }
    let g = Film::from_parts(2, 1, 0..100, f.blocks().to_vec(), f.block_data().to_vec()).unwrap();
    assert_eq!(bits(&g), bits(&f));
    assert!(Film::from_parts(2, 1, 0..99, f.blocks().to_vec(), f.block_data().to_vec()).is_err());
    assert!(Film::from_parts(2, 1, 0..100, f.blocks().to_vec(), f.block_data()[1..].to_vec()).is_err());
}

#[test]
fn exr_round_trip_is_bit_exact_with_variance_and_metadata() {
    let d = scratch("exr");
    let (w, h) = (5u32, 3u32);
    let special = [0.0, -0.0, 1e-45, 1.2e-38, 3.0e38, f32::MAX, f32::INFINITY, f32::NAN, -7.25, 1.0 / 3.0];
    let rgb: Vec<[f32; 3]> = (0..15).map(|i| [special[i % 10], i as f32 * 0.1, special[(i * 7) % 10]]).collect();
    let var: Vec<[f32; 3]> = (0..15).map(|i| [1e-30 * i as f32, 2.5e-12, i as f32]).collect();
    let meta: Metadata = [("spp", "64"), ("sampler", "sobol"), ("seconds", "1.25"), ("note", "grüße, ✓")]
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .to_vec();
    let path = d.join("a.exr");
    write_exr(&path, w, h, &rgb, Some(&var), &meta).unwrap();
    let img = read_exr(&path).unwrap();
    assert_eq!((img.width, img.height), (w, h));
    let bits = |v: &[[f32; 3]]| v.iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&img.rgb), bits(&rgb));
    assert_eq!(bits(img.variance.as_ref().unwrap()), bits(&var));
    let mut sorted = meta.clone();
    sorted.sort();
    assert_eq!(img.meta, sorted);
    assert!(!tmp_of(&path).exists());

    // Without variance, overwriting the previous file.
    write_exr(&path, w, h, &rgb, None, &Vec::new()).unwrap();
    let img = read_exr(&path).unwrap();
    assert_eq!((bits(&img.rgb), img.variance, img.meta), (bits(&rgb), None, vec![]));
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn exr_rejects_bad_input_without_touching_the_target() {
    let d = scratch("exr-bad");
    let path = d.join("b.exr");
    assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 3], None, &Vec::new()).is_err());
    assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 4], Some(&[[0.0; 3]; 1]), &Vec::new()).is_err());
    let dup = vec![("k".to_string(), "1".to_string()), ("k".to_string(), "2".to_string())];
    assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 4], None, &dup).is_err());
    let reserved = vec![("channels".to_string(), "x".to_string())];
    let e = write_exr(&path, 2, 2, &[[0.0; 3]; 4], None, &reserved).unwrap_err();
    assert!(e.to_string().contains("channels"), "{e}");
    assert!(!path.exists() && !tmp_of(&path).exists());
    fs::write(&path, b"not an exr").unwrap();
    assert!(read_exr(&path).is_err());
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn tone_mapping() {
    assert_eq!(to_u8(0.5, 2.2), (255.0 * 0.5f32.powf(1.0 / 2.2)).round() as u8);
    assert_eq!(to_u8(0.5, 1.0), 128);
    assert_eq!([to_u8(f32::NAN, 2.2), to_u8(f32::INFINITY, 2.2), to_u8(f32::NEG_INFINITY, 2.2)], [0; 3]);
    assert_eq!([to_u8(-0.5, 2.2), to_u8(0.0, 2.2), to_u8(1.0, 2.2), to_u8(7.0, 2.2)], [0, 0, 255, 255]);
    let t = |v: f32| to_u8_quantized(v, 1.0, Quantize::Truncate);
    assert_eq!(
        [t(0.5), t(0.999 / 255.0), t(254.99 / 255.0), t(1.0), t(7.0), t(-1.0), t(f32::NAN)],
        [127, 0, 254, 255, 255, 0, 0]
    );
    assert_eq!(to_u8_quantized(0.5, 2.2, Quantize::Round), to_u8(0.5, 2.2));
}

#[test]
fn png_round_trip_gives_to_u8_values() {
    let d = scratch("png");
    let (w, h) = (4u32, 3u32);
    let rgb: Vec<[f32; 3]> = (0..12).map(|i| [i as f32 / 11.0, f32::NAN, 2.0 - i as f32 * 0.2]).collect();
    let path = d.join("p.png");
    write_png(&path, w, h, &rgb, 2.2).unwrap();
    let decoder = png::Decoder::new(io::BufReader::new(File::open(&path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(
        (info.width, info.height, info.color_type, info.bit_depth),
        (w, h, png::ColorType::Rgb, png::BitDepth::Eight)
    );
    let expected: Vec<u8> = rgb.iter().flat_map(|p| p.map(|v| to_u8(v, 2.2))).collect();
    assert_eq!(&buf[..info.buffer_size()], &expected[..]);
    assert!(write_png(&path, w, h, &rgb[..11], 2.2).is_err());
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn atomic_write_failures_leave_nothing_and_keep_the_old_file() {
    let d = scratch("atomic");
    // Parent directory does not exist: error, nothing created.
    let missing = d.join("no-such-dir").join("x.bin");
    assert!(write_atomic(&missing, b"data").is_err());
    assert!(!d.join("no-such-dir").exists());
    // Parent is a regular file: error.
    fs::write(d.join("file"), b"f").unwrap();
    assert!(write_atomic(&d.join("file").join("x.bin"), b"data").is_err());
    // A link planted at the old predictable temporary name (`<path>.tmp-<pid>`) is never followed:
    // the temporary file is created exclusively under an unpredictable name.
    let target = d.join("keep.exr");
    fs::write(&target, b"old").unwrap();
    let victim = d.join("victim.txt");
    fs::write(&victim, b"victim").unwrap();
    std::os::unix::fs::symlink(&victim, tmp_of(&target)).unwrap();
    write_atomic(&target, b"new").unwrap();
    assert_eq!(fs::read(&victim).unwrap(), b"victim", "the link's target is untouched");
    assert!(fs::symlink_metadata(&target).unwrap().file_type().is_file(), "the output is a regular file");
    assert_eq!(fs::read(&target).unwrap(), b"new");
    fs::remove_file(tmp_of(&target)).unwrap();
    // A target that is a link, a directory or a device is refused, saying what it is, and stays.
    let link = d.join("link.exr");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    fs::create_dir(d.join("dir.exr")).unwrap();
    for (path, what) in
        [(link.clone(), "a symbolic link"), (d.join("dir.exr"), "a directory"), ("/dev/null".into(), "a device")]
    {
        let e = write_atomic(&path, b"x").unwrap_err().to_string();
        assert!(e.contains(what) && e.contains("regular files or new names"), "{}: {e}", path.display());
        assert!(write_png(&path, 1, 1, &[[1.0; 3]], 2.2).is_err());
    }
    assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(fs::read(&victim).unwrap(), b"victim");
    assert!(fs::symlink_metadata("/dev/null").unwrap().file_type().is_char_device());
    fs::remove_file(&link).unwrap();
    fs::remove_dir(d.join("dir.exr")).unwrap();
    // Success replaces the old file and leaves no temporary behind.
    write_atomic(&target, b"newer").unwrap();
    assert_eq!(fs::read(&target).unwrap(), b"newer");
    assert_eq!(fs::read_dir(&d).unwrap().count(), 3, "only `file`, `keep.exr` and `victim.txt`");
    fs::remove_dir_all(&d).unwrap();
}
