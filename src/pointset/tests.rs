//! Formats, checks and specs of point-set files.

use super::formats::{self, parse_npy, parse_text, parse_utk_bin};
use super::spec::{resolve_sampler, Options, SamplerSpec};
use super::*;
use crate::sampler::file::Scramble;
use crate::sampler::{PointSet, SamplerKind};

/// `name` in a fresh scratch directory, which goes (with everything in it) when the test drops
/// the directory: keep it bound.
fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::Builder::new().prefix("strata-pointset-").tempdir().unwrap();
    let p = dir.path().join(name);
    (dir, p)
}

fn sample_sets() -> PointSets {
    let data = vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.625, 0.0, 0.999, 0.25, 0.75, 0.125, 0.875];
    PointSets::new("t", 2, 3, 2, data).unwrap()
}

fn err<T: std::fmt::Debug>(r: Result<T, PointSetError>) -> String {
    r.expect_err("refused").to_string()
}

#[test]
fn utk_text_loads_sets_separated_by_hash() {
    let text = "0.1 0.2\n0.3 0.4\n0.5 0.625\n#\n0 0.999\n0.25\t0.75\n0.125 0.875\n#\n";
    let ps = parse_text("pts.txt", text.as_bytes()).unwrap();
    assert_eq!((ps.sets, ps.points, ps.dims), (2, 3, 2));
    assert_eq!(ps.data, sample_sets().data);
    assert_eq!(ps.point(1, 1), &[0.25, 0.75]);
}

#[test]
fn each_format_round_trips() {
    let ps = sample_sets();
    for name in ["a.txt", "a.dat", "a.bin", "a.npy"] {
        let (_dir, p) = tmp(name);
        formats::write(&p, &ps).unwrap();
        let back = formats::read(&p).unwrap();
        assert_eq!((back.sets, back.points, back.dims, &back.data), (2, 3, 2, &ps.data), "{name}");
    }
}

#[test]
fn npy_float32_two_dimensional_and_fortran_order_load() {
    // Hand-written NumPy v1 headers (as numpy.save writes them).
    let npy = |descr: &str, fortran: bool, shape: &str, body: &[u8]| {
        let mut h = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
            if fortran { "True" } else { "False" }
        );
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(' ');
        }
        h.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(h.len() as u16).to_le_bytes());
        b.extend_from_slice(h.as_bytes());
        b.extend_from_slice(body);
        b
    };
    let f32s: Vec<u8> = [0.5f32, 0.25, 0.75, 0.125].iter().flat_map(|v| v.to_le_bytes()).collect();
    let ps = parse_npy("a.npy", &npy("<f4", false, "(2, 2)", &f32s)).unwrap();
    assert_eq!((ps.sets, ps.points, ps.dims, ps.data.clone()), (1, 2, 2, vec![0.5, 0.25, 0.75, 0.125]));
    // Fortran order: the same values column-major mean points (0.5, 0.75) and (0.25, 0.125).
    let ps = parse_npy("a.npy", &npy("<f4", true, "(2, 2)", &f32s)).unwrap();
    assert_eq!(ps.data, vec![0.5, 0.75, 0.25, 0.125]);
    assert!(err(parse_npy("a.npy", &npy("<i8", false, "(1, 2)", &[0; 16]))).contains("expected float32 or float64"));
    assert!(err(parse_npy("a.npy", &npy("<f4", false, "(4,)", &f32s))).contains("expected [sets, points, dims]"));
}

#[test]
fn utk_bin_header_is_checked() {
    let (_dir, p) = tmp("h.bin");
    formats::write(&p, &sample_sets()).unwrap();
    let good = std::fs::read(&p).unwrap();
    assert_eq!(&good[..4], b"UTK!");
    let mut b = good.clone();
    b[0] = b'X';
    assert!(err(parse_utk_bin("h.bin", &b)).contains("no `UTK!` magic"));
    let mut b = good.clone();
    b[4] = 0;
    assert!(err(parse_utk_bin("h.bin", &b)).contains("integer coordinates"));
    assert!(err(parse_utk_bin("h.bin", &good[..good.len() - 1])).contains("the file holds 95 data bytes"));
    assert!(err(parse_utk_bin("h.bin", &good[..10])).contains("shorter than the 20-byte UTK header"));
}

#[test]
fn refusals_name_file_set_point_and_line() {
    let e = err(parse_text("p.txt", b"0.1 0.2\n#\n0.3 1.0\n"));
    assert_eq!(e, "p.txt:3: set 1, point 0, coordinate 1: 1 is outside [0, 1)");
    let e = err(parse_text("p.txt", b"0.1 0.2\n0.3 nan\n"));
    assert!(e.starts_with("p.txt:2: set 0, point 1, coordinate 1: NaN"), "{e}");
    let e = err(parse_text("p.txt", b"0.1 0.2\n0.3 -0.0001\n"));
    assert!(e.contains("-0.0001 is outside [0, 1)"), "{e}");
    let e = err(parse_text("p.txt", b"0.1 0.2\n0.3\n"));
    assert_eq!(e, "p.txt:2: 1 coordinates, the file's first point has 2");
    let e = err(parse_text("p.txt", b"0.1 0.2\n0.3 x\n"));
    assert!(e.starts_with("p.txt:2: `x` is not a number"), "{e}");
    let e = err(parse_text("p.txt", b"0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n"));
    assert!(e.starts_with("p.txt: set 1 has 1 points, set 0 has 2"), "{e}");
    let e = err(parse_text("p.txt", b"# nothing\n"));
    assert!(e.contains("no points"), "{e}");
    // Binary values are named by set, point and coordinate.
    let e = err(PointSets::new("<array points>", 2, 2, 2, vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, f64::NAN, 0.0]));
    assert!(e.starts_with("<array points>: set 1, point 1, coordinate 0: NaN"), "{e}");
    let e = err(PointSets::new("<array points>", 1, 2, 2, vec![0.0; 3]));
    assert!(e.contains("3 values for 1 sets x 2 points x 2 coordinates"), "{e}");
}

#[test]
fn specs_parse_options_and_refuse_unknown_ones() {
    let s = SamplerSpec::parse("file:a b.txt?scramble=owen&sets=pixel&pad=sobol").unwrap().unwrap();
    assert_eq!(s.path, PathBuf::from("a b.txt"));
    assert_eq!(s.options.scramble, Scramble::Owen);
    assert_eq!(s.options.pad, Some(SamplerKind::SOBOL));
    assert_eq!(s.options.suffix(), "?scramble=owen&sets=pixel&pad=sobol");
    assert_eq!(Options::default().suffix(), "");
    assert!(SamplerSpec::parse("sobol").is_none());
    assert!(err(SamplerSpec::parse("file:a?scramble=rot").unwrap()).contains("expected shift, owen, xor or none"));
    assert!(
        err(SamplerSpec::parse("file:a?colour=red").unwrap()).contains("known options: scramble, sets, pad, shuffle")
    );
    assert!(err(resolve_sampler("file:/nonexistent/pts.npy")).starts_with("/nonexistent/pts.npy: "));
    assert!(err(resolve_sampler("sobel")).contains("or file:PATH"));
    assert_eq!(resolve_sampler("pmj").unwrap(), SamplerKind::PMJ02);
}

#[test]
fn one_coordinate_sets_need_pad() {
    let ps = PointSets::new("<array x>", 1, 4, 1, vec![0.0, 0.25, 0.5, 0.75]).unwrap();
    let e = err(sampler_from_sets(&ps, "array", Options::default()));
    assert!(e.contains("1 coordinate per point; a sampler dimension takes 2 (add ?pad=sobol"), "{e}");
    let opts =
        Options { pad: Some(SamplerKind::SOBOL), scramble: Scramble::None, shuffle: false, ..Options::default() };
    let k = sampler_from_sets(&ps, "array", opts).unwrap();
    let set = PointSet::new(k, 4);
    for i in 0..4 {
        let [x, y] = set.point(9, 0, 0, i, 1);
        assert_eq!(x, i as f32 * 0.25);
        assert_eq!(y, PointSet::new(SamplerKind::SOBOL, 4).point(9, 0, 0, i, 1)[1]);
    }
}

#[test]
fn a_loaded_file_is_a_sampler() {
    let (_dir, p) = tmp("s.txt");
    formats::write(&p, &sample_sets()).unwrap();
    let k = resolve_sampler(&format!("file:{}?scramble=none&sets=pixel&shuffle=none", p.display())).unwrap();
    assert!(k.name().starts_with("file:") && k.name().ends_with("s.txt?scramble=none&sets=pixel&shuffle=none"));
    assert_eq!(PointSet::new(k, 3).point(1, 0, 0, 1, 0), [0.25, 0.75]);
    assert_eq!(crate::sampler::file::file_info(k).map(|(_, s, p)| (s, p)), Some((2, 3)));
}

#[test]
fn pointset_plots_floor_the_spectrum_guide_white_noise_and_write_round_trip_csv() {
    // A lattice's spectrum has exact zeros that come out as 1e-31 of rounding: the plot's power
    // axis stops at the floor, the slope-0 guide sits at power 1 (white noise), not at the first
    // point, and the CSV writes 4.5e-31 in a form that reads back, not 0.000...045.
    use super::command::{write_outputs, Report, SPECTRUM_FLOOR};
    let conv = super::analysis::Convergence { integrand: "disk", points: vec![(144.0, 1.25e-3)], slope: None };
    let r = Report {
        name: "fib".into(),
        sampler: "file:fib".into(),
        sets: Vec::new(),
        spectrum: vec![f64::NAN, 0.004, 4.5e-31, 0.1 + 0.2, 2.5],
        convergence: vec![conv],
        progressive: None,
    };
    let (_scratch, dir) = tmp("plots");
    write_outputs(&dir, &r).unwrap();
    let csv = std::fs::read_to_string(dir.join("spectrum.csv")).unwrap();
    assert!(csv.contains("2,4.5e-31\n") && !csv.contains("0.0000"), "{csv}");
    for line in csv.lines().skip(1) {
        let (f, p) = line.split_once(',').unwrap();
        let f: usize = f.parse().unwrap();
        assert_eq!(p.parse::<f64>().unwrap().to_bits(), r.spectrum[f].to_bits(), "{line}");
    }
    let svg = std::fs::read_to_string(dir.join("spectrum.svg")).unwrap();
    let exps: Vec<i32> = svg
        .split("<tspan dy=\"-6\" font-size=\"9\">")
        .skip(1)
        .map(|t| t.split('<').next().unwrap().parse().unwrap())
        .collect();
    assert!(exps.iter().all(|&e| f64::from(e) >= SPECTRUM_FLOOR.log10()), "axis decades {exps:?}");
    // The guide (slope 0) is horizontal at power 1: the y of 10^0 on the axis.
    let guide = svg.split("class=\"guide\" points=\"").nth(1).unwrap().split('"').next().unwrap();
    let ys: Vec<f64> = guide.split(' ').map(|p| p.split(',').nth(1).unwrap().parse().unwrap()).collect();
    let scale = crate::report::LogScale::covering([SPECTRUM_FLOOR, 2.5, 1.0], 410.0, 50.0);
    assert!(ys.iter().all(|y| (y - scale.map(1.0)).abs() < 0.01), "guide at {ys:?}, power 1 at {}", scale.map(1.0));
    let int = std::fs::read_to_string(dir.join("integration.csv")).unwrap();
    assert!(int.contains("disk,144,1.25e-3"), "{int}");
}
