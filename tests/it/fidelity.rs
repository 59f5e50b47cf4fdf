//! Fidelity to the CSE168 course's images: strata's PNG of each `.test` scene against the per-pixel
//! median of independent student renders (`../shared/corpora/cse168-images`, see its SOURCES.md;
//! skipped when absent; `STRATA_CSE168_IMAGES` overrides the path), set against the students'
//! leave-one-out spread (each student against the median of the others).
//!
//! By default hw1 and hw2 are rendered at their own size and spp (a few seconds in all) and checked;
//! hw3/hw4 (64-128 spp, 40-120 s each on 2 cores) only with `STRATA_FIDELITY_FULL=1`.
//! `STRATA_FIDELITY_RENDERS=DIR` compares the PNGs `DIR/<hw>-<name>.png` instead of rendering (e.g.
//! from another build), and `STRATA_FIDELITY_FLAGS` adds render flags. The table is printed
//! (`cargo test --release --test fidelity -- --nocapture`).

use crate::common;

use common::{corpus_required, strata, tmpdir};
use std::path::{Path, PathBuf};

/// hw1 scenes that must match the consensus on >= 99.9% of pixels (the others: >= 99%).
const HW1_STRICT: &[&str] = &["hw1/scene1", "hw1/scene2", "hw1/scene3"];

/// Scenes that cannot be within the students' spread yet, with the deviation (MAE, 8-bit) recorded
/// as an upper bound so regressions still fail. Flip an entry (delete it) when its cause is fixed.
/// Empty: hw4/mis (8.6 with one light of 5 per NEE sample) and hw4/dragon (1.74) left it when
/// `--light-selection all` became the `.test` default (0.78 and 1.35, within the spread).
const EXPECTED_TO_FAIL: &[(&str, f64, &str)] = &[];

/// The consensus set of each scene: the student renders SOURCES.md section 5 lists as agreeing (the
/// canonical render of the scene as shipped), and why others are left out.
const CONSENSUS: &[(&str, &str, &[&str])] = &[
    (
        "hw1/scene1",
        "renders of the shipped camera #4 (other files are of the commented-out cameras)",
        &["sophia-vo__CSE-168-Website/assets/scene1-camera4.png", "kevl0317__CSE167-HW4/scene1-camera4.png"],
    ),
    (
        "hw1/scene2",
        "renders of the shipped camera #1 (whlee503 scene2.png is camera #3)",
        &["sophia-vo__CSE-168-Website/assets/scene2-camera1.png", "kevl0317__CSE167-HW4/scene2-camera1.png"],
    ),
    (
        "hw1/scene3",
        "all three",
        &[
            "whlee503__cpp_path_tracer/Docs/scene3.png",
            "sophia-vo__CSE-168-Website/assets/scene3.png",
            "kevl0317__CSE167-HW4/scene3.png",
        ],
    ),
    (
        "hw1/scene4-ambient",
        "all ten",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene4-ambient.png",
            "whlee503__cpp_path_tracer/Docs/scene4-ambient.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene4-ambient.png",
            "ZeshanRasul__CPU_PathTracer/scene4-ambient.png",
            "sophia-vo__CSE-168-Website/assets/scene4-ambient.png",
            "ken2576__cse168/images/scene4-ambient.png",
            "elaine-ch__personal-site/images/scene4-ambient.png",
            "lucyhu798__rayTracing/scene4-ambient.png",
            "pao214__CSE167x-hw3/scene4-ambient.png",
            "kevl0317__CSE167-HW4/scene4-ambient.png",
        ],
    ),
    (
        "hw1/scene4-diffuse",
        "bailyachen left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene4-diffuse.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene4-diffuse.png",
            "ZeshanRasul__CPU_PathTracer/scene4-diffuse.png",
            "sophia-vo__CSE-168-Website/assets/scene4-diffuse.png",
            "ken2576__cse168/images/scene4-diffuse.png",
            "elaine-ch__personal-site/images/scene4-diffuse.png",
            "lucyhu798__rayTracing/scene4-diffuse.png",
            "pao214__CSE167x-hw3/scene4-diffuse.png",
            "kevl0317__CSE167-HW4/scene4-diffuse.png",
        ],
    ),
    (
        "hw1/scene4-emission",
        "all eleven",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene4-emission.png",
            "whlee503__cpp_path_tracer/Docs/scene4-emission.png",
            "bailyachen__Pathtracer/hw1/scene4-emission.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene4-emission.png",
            "ZeshanRasul__CPU_PathTracer/scene4-emission.png",
            "sophia-vo__CSE-168-Website/assets/scene4-emission.png",
            "ken2576__cse168/images/scene4-emission.png",
            "elaine-ch__personal-site/images/scene4-emission.png",
            "lucyhu798__rayTracing/scene4-emission.png",
            "pao214__CSE167x-hw3/scene4-emission.png",
            "kevl0317__CSE167-HW4/scene4-emission.png",
        ],
    ),
    (
        "hw1/scene4-specular",
        "elaine-ch left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene4-specular.png",
            "whlee503__cpp_path_tracer/Docs/scene4-specular.png",
            "bailyachen__Pathtracer/hw1/scene4-specular.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene4-specular.png",
            "ZeshanRasul__CPU_PathTracer/scene4-specular.png",
            "sophia-vo__CSE-168-Website/assets/scene4-specular.png",
            "ken2576__cse168/images/scene4-specular.png",
            "lucyhu798__rayTracing/scene4-specular.png",
            "pao214__CSE167x-hw3/scene4-specular.png",
            "kevl0317__CSE167-HW4/scene4-specular.png",
        ],
    ),
    (
        "hw1/scene5",
        "ZeshanRasul, ken2576, lucyhu798, pao214 left out (means disagree)",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene5.png",
            "whlee503__cpp_path_tracer/Docs/scene5.png",
            "bailyachen__Pathtracer/hw1/scene5.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene5.png",
            "sophia-vo__CSE-168-Website/assets/scene5.png",
            "kevl0317__CSE167-HW4/scene5.png",
        ],
    ),
    (
        "hw1/scene6",
        "pao214 left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene6.png",
            "whlee503__cpp_path_tracer/Docs/scene6.png",
            "bailyachen__Pathtracer/hw1/scene6.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene6.png",
            "ZeshanRasul__CPU_PathTracer/scene6.png",
            "sophia-vo__CSE-168-Website/assets/scene6.png",
            "ken2576__cse168/images/scene6.png",
            "lucyhu798__rayTracing/scene6.png",
            "kevl0317__CSE167-HW4/scene6.png",
        ],
    ),
    (
        "hw1/scene7",
        "all ten",
        &[
            "ssl105__Raytracing-Images/images/hw1/scene7.png",
            "whlee503__cpp_path_tracer/Docs/scene7.png",
            "bailyachen__Pathtracer/hw1/scene7.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/scene7.png",
            "ZeshanRasul__CPU_PathTracer/scene7.png",
            "sophia-vo__CSE-168-Website/assets/scene7.png",
            "ken2576__cse168/images/scene7.png",
            "lucyhu798__rayTracing/scene7.png",
            "pao214__CSE167x-hw3/scene7.png",
            "kevl0317__CSE167-HW4/scene7.png",
        ],
    ),
    (
        "hw2/analytic",
        "Haruto2017 left out (off in every hw2-hw4 scene)",
        &[
            "lucyhu798__rendering-direct-indirect-lighting-importance-sampling/analytic.png",
            "ssl105__Raytracing-Images/images/hw2/analytic.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/analytic.png",
            "whlee503__cpp_path_tracer/Docs/analytic.png",
            "bailyachen__Pathtracer/hw2/analytic.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/analytic.png",
            "ZeshanRasul__CPU_PathTracer/analytic.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/analytic.png",
            "sophia-vo__CSE-168-Website/assets/analytic.png",
        ],
    ),
    (
        "hw2/cornell",
        "Haruto2017, ZeshanRasul, lucyhu798 left out (means disagree)",
        &[
            "ssl105__Raytracing-Images/images/hw2/cornell.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornell.png",
            "whlee503__cpp_path_tracer/Docs/cornell.png",
            "bailyachen__Pathtracer/hw2/cornell.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornell.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/cornell.png",
            "sophia-vo__CSE-168-Website/assets/cornell.png",
            "TonyZYT2000__ImageHost/cornell.png",
            "yuyingyeh__OptiX-PathTracer/point/cornell_ori.png",
            "Shuyang19__CSE168_hw2_extra/cornell.png",
        ],
    ),
    (
        "hw2/direct3x3",
        "Haruto2017 left out",
        &[
            "lucyhu798__rendering-direct-indirect-lighting-importance-sampling/direct3x3.png",
            "ssl105__Raytracing-Images/images/hw2/direct3x3.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/direct3x3.png",
            "whlee503__cpp_path_tracer/Docs/direct3x3.png",
            "bailyachen__Pathtracer/hw2/direct3x3.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/direct3x3.png",
            "ZeshanRasul__CPU_PathTracer/direct3x3.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/direct3x3.png",
            "sophia-vo__CSE-168-Website/assets/direct3x3.png",
            "TonyZYT2000__ImageHost/direct3x3.png",
            "yuyingyeh__OptiX-PathTracer/rv/direct3x3_ori.png",
        ],
    ),
    (
        "hw2/direct9",
        "Haruto2017 left out",
        &[
            "lucyhu798__rendering-direct-indirect-lighting-importance-sampling/direct9.png",
            "ssl105__Raytracing-Images/images/hw2/direct9.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/direct9.png",
            "whlee503__cpp_path_tracer/Docs/direct9.png",
            "bailyachen__Pathtracer/hw2/direct9.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/direct9.png",
            "ZeshanRasul__CPU_PathTracer/direct9.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/direct9.png",
            "sophia-vo__CSE-168-Website/assets/direct9.png",
            "TonyZYT2000__ImageHost/direct9.png",
        ],
    ),
    (
        "hw2/dragon",
        "lucyhu798 left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw2/dragon.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/dragon.png",
            "bailyachen__Pathtracer/hw2/dragon.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/dragon.png",
            "ZeshanRasul__CPU_PathTracer/dragon.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/dragon.png",
            "TonyZYT2000__ImageHost/dragon.png",
        ],
    ),
    (
        "hw2/sphere",
        "lucyhu798 left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw2/sphere.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/sphere.png",
            "whlee503__cpp_path_tracer/Docs/sphere.png",
            "bailyachen__Pathtracer/hw2/sphere.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/sphere.png",
            "ZeshanRasul__CPU_PathTracer/sphere.png",
            "ayakak172__CSE168-HW2-Website/hw2-images/sphere.png",
            "sophia-vo__CSE-168-Website/assets/sphere.png",
            "TonyZYT2000__ImageHost/sphere.png",
            "yuyingyeh__OptiX-PathTracer/rv/sphere_ori.png",
        ],
    ),
    (
        "hw3/cornellNEE",
        "Haruto2017 left out",
        &[
            "ssl105__Raytracing-Images/images/hw3/cornellNEE.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornellNEE.png",
            "whlee503__cpp_path_tracer/Docs/cornellNEE.png",
            "bailyachen__Pathtracer/hw3/cornellNEE.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornellNEE.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/cornellNEE.png",
            "ZeshanRasul__CPU_PathTracer/cornellNEE.png",
            "yuyingyeh__OptiX-PathTracer-Indirect-Lighting/importancesampling/cornellNEE.png",
        ],
    ),
    (
        "hw3/cornellRR",
        "Haruto2017 left out",
        &[
            "ssl105__Raytracing-Images/images/hw3/cornellRR.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornellRR.png",
            "whlee503__cpp_path_tracer/Docs/cornellRR.png",
            "bailyachen__Pathtracer/hw3/cornellRR.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornellRR.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/cornellRR.png",
            "ZeshanRasul__CPU_PathTracer/cornellRR.png",
            "yuyingyeh__OptiX-PathTracer-Indirect-Lighting/importancesampling/cornellRR.png",
        ],
    ),
    (
        "hw3/cornellSimple",
        "the five OptiX renders; the CPU ports whlee503, ZeshanRasul are ~2% brighter (less clipping)",
        &[
            "ssl105__Raytracing-Images/images/hw3/cornellSimple.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornellSimple.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornellSimple.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/cornellSimple.png",
            "yuyingyeh__OptiX-PathTracer-Indirect-Lighting/importancesampling/cornellSimple.png",
        ],
    ),
    (
        "hw3/dragon",
        "all seven (ZeshanRasul's older HW1/ copy, the one that agrees)",
        &[
            "ssl105__Raytracing-Images/images/hw3/dragon.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/dragonNEERR.png",
            "whlee503__cpp_path_tracer/Docs/dragon.png",
            "bailyachen__Pathtracer/hw3/dragon.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/dragonRR.png",
            "ZeshanRasul__CPU_PathTracer/HW1/CPU_PathTracer/dragon.png",
            "yuyingyeh__OptiX-PathTracer-Indirect-Lighting/importancesampling/dragon.png",
        ],
    ),
    (
        "hw4/cornellBRDF",
        "Haruto2017, whlee503 left out",
        &[
            "ssl105__Raytracing-Images/images/hw4/cornellBRDF.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornellBRDF.png",
            "bailyachen__Pathtracer/hw4/cornellBRDF.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornellBRDF.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/cornellBRDF.png",
            "ZeshanRasul__CPU_PathTracer/cornellBRDF.png",
        ],
    ),
    (
        "hw4/cornellCosine",
        "Haruto2017, whlee503 left out",
        &[
            "ssl105__Raytracing-Images/images/hw4/cornellCosine.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/cornellCosine.png",
            "bailyachen__Pathtracer/hw4/cornellCosine.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/cornellCosine.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/cornellCosine.png",
            "ZeshanRasul__CPU_PathTracer/cornellCosine.png",
        ],
    ),
    (
        "hw4/cornellMIS",
        "one render only (abhinandansharma1999's is a copy of its cornellBRDF): no spread",
        &["whlee503__cpp_path_tracer/Docs/cornellMIS.png"],
    ),
    (
        "hw4/dragon",
        "TobeyPineda, bailyachen left out (means disagree)",
        &[
            "ssl105__Raytracing-Images/images/hw4/dragon.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/dragon_MIS.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/dragon.png",
        ],
    ),
    (
        "hw4/ggx",
        "the ~176/161/156 cluster; Haruto2017, wuhaoqi98 (~142) and TobeyPineda (181) left out",
        &[
            "ssl105__Raytracing-Images/images/hw4/ggx.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/ggx.png",
            "ZeshanRasul__CPU_PathTracer/ggx.png",
        ],
    ),
    (
        "hw4/mis",
        "bailyachen left out (mean disagrees)",
        &[
            "ssl105__Raytracing-Images/images/hw4/mis.png",
            "TobeyPineda__Raytracer-with-Optix-and-Wood-Simulation/Images/mis.png",
            "abhinandansharma1999__CSE-168-Graphics-Rendering-II/images/mis.png",
            "wuhaoqi98__Realtime_Ray_Tracer/output/mis.png",
            "ZeshanRasul__CPU_PathTracer/mis.png",
        ],
    ),
];

/// Decodes an 8-bit PNG to (width, height, RGB bytes), dropping alpha.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut buf = vec![0; reader.output_buffer_size().expect("PNG size")];
    let info = reader.next_frame(&mut buf).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let channels = info.color_type.samples();
    let bytes = &buf[..info.buffer_size()];
    let rgb = match channels {
        3 => bytes.to_vec(),
        4 => bytes.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
        1 => bytes.iter().flat_map(|&g| [g; 3]).collect(),
        2 => bytes.chunks_exact(2).flat_map(|p| [p[0]; 3]).collect(),
        c => panic!("{}: {c} channels", path.display()),
    };
    (info.width, info.height, rgb)
}

/// Per-value median of `images` (all the same length); an even count gives the mean of the middle two.
fn median(images: &[&[u8]]) -> Vec<f64> {
    let n = images.len();
    let mut v = vec![0u8; n];
    (0..images[0].len())
        .map(|i| {
            for (k, im) in images.iter().enumerate() {
                v[k] = im[i];
            }
            v.sort_unstable();
            if n % 2 == 1 {
                f64::from(v[n / 2])
            } else {
                0.5 * (f64::from(v[n / 2 - 1]) + f64::from(v[n / 2]))
            }
        })
        .collect()
}

/// Deviation of one image from a consensus, in 8-bit units over all channels.
#[derive(Clone, Copy, Debug, Default)]
struct Dev {
    /// mean |image - consensus|
    mae: f64,
    /// mean (image - consensus)
    bias: f64,
    /// percent of pixels whose three channels all equal the consensus (within 0.5)
    equal: f64,
    /// percent of pixels with some channel off by more than 8
    off8: f64,
}

fn deviation(img: &[u8], cons: &[f64]) -> Dev {
    let (mut abs, mut sum, mut eq, mut off) = (0.0, 0.0, 0usize, 0usize);
    for (p, c) in img.chunks_exact(3).zip(cons.chunks_exact(3)) {
        let d: Vec<f64> = (0..3).map(|k| f64::from(p[k]) - c[k]).collect();
        abs += d.iter().map(|x| x.abs()).sum::<f64>();
        sum += d.iter().sum::<f64>();
        eq += usize::from(d.iter().all(|x| x.abs() <= 0.5));
        off += usize::from(d.iter().any(|x| x.abs() > 8.0));
    }
    let (n, px) = (img.len() as f64, (img.len() / 3) as f64);
    Dev { mae: abs / n, bias: sum / n, equal: 100.0 * eq as f64 / px, off8: 100.0 * off as f64 / px }
}

/// One scene's result: strata's deviation and the students' leave-one-out MAE (median, max).
struct Row {
    scene: &'static str,
    students: usize,
    dev: Dev,
    loo: Option<(f64, f64)>,
}

fn compare(images: &Path, scene: &'static str, files: &[&str], png: &Path) -> Row {
    let students: Vec<(u32, u32, Vec<u8>)> = files.iter().map(|f| read_png(&images.join(f))).collect();
    let (w, h, ours) = read_png(png);
    for (f, s) in files.iter().zip(&students) {
        assert_eq!((s.0, s.1), (w, h), "{scene}: {f} is {}x{}, strata's {w}x{h}", s.0, s.1);
    }
    let all: Vec<&[u8]> = students.iter().map(|s| s.2.as_slice()).collect();
    let cons = median(&all);
    let loo = (all.len() >= 3).then(|| {
        let mut m: Vec<f64> = (0..all.len())
            .map(|i| {
                let others: Vec<&[u8]> = all.iter().enumerate().filter(|&(j, _)| j != i).map(|(_, s)| *s).collect();
                deviation(all[i], &median(&others)).mae
            })
            .collect();
        m.sort_by(f64::total_cmp);
        let mid = if m.len() % 2 == 1 { m[m.len() / 2] } else { 0.5 * (m[m.len() / 2 - 1] + m[m.len() / 2]) };
        (mid, m[m.len() - 1])
    });
    Row { scene, students: files.len(), dev: deviation(&ours, &cons), loo }
}

#[test]
fn strata_matches_the_course_images() {
    let images = common::shared_required("STRATA_CSE168_IMAGES", "corpora/cse168-images", "SOURCES.md");
    let scenes = corpus_required();
    let given = std::env::var_os("STRATA_FIDELITY_RENDERS").map(PathBuf::from);
    let full = given.is_some() || std::env::var_os("STRATA_FIDELITY_FULL").is_some();
    let flags = std::env::var("STRATA_FIDELITY_FLAGS").unwrap_or_default();
    let d = tmpdir("fidelity");
    let mut rows = Vec::new();
    for &(scene, _why, files) in CONSENSUS {
        if !full && !scene.starts_with("hw1/") && !scene.starts_with("hw2/") {
            continue;
        }
        let stem = scene.replace('/', "-");
        let png = match &given {
            Some(dir) if !dir.join(format!("{stem}.png")).is_file() => {
                eprintln!("{scene}: no {stem}.png in {}", dir.display());
                continue;
            }
            Some(dir) => dir.join(format!("{stem}.png")),
            None => {
                let out = d.join(&stem);
                let t = std::time::Instant::now();
                let r = strata()
                    .arg("render")
                    .arg(scenes.join(format!("{scene}.test")))
                    .args(["--threads", "2", "--quiet"])
                    .args(flags.split_whitespace())
                    .arg("-o")
                    .arg(&out)
                    .output()
                    .unwrap();
                assert!(r.status.success(), "{scene}: {}", String::from_utf8_lossy(&r.stderr));
                eprintln!("{scene}: rendered in {:.1} s", t.elapsed().as_secs_f64());
                out.with_extension("png")
            }
        };
        rows.push(compare(&images, scene, files, &png));
    }

    println!("| scene | students | strata MAE | bias | equal % | off >8 % | students' LOO MAE median / max |");
    println!("|---|---|---|---|---|---|---|");
    let mut bad = Vec::new();
    for r in &rows {
        let loo = r.loo.map_or("-".to_string(), |(m, x)| format!("{m:.2} / {x:.2}"));
        let Dev { mae, bias, equal, off8 } = r.dev;
        println!("| {} | {} | {mae:.2} | {bias:+.2} | {equal:.2} | {off8:.2} | {loo} |", r.scene, r.students);
        if r.scene.starts_with("hw1/") {
            let need = if HW1_STRICT.contains(&r.scene) { 99.9 } else { 99.0 };
            if equal < need {
                bad.push(format!("{}: {equal:.2}% of pixels equal to the consensus, need {need}%", r.scene));
            }
        } else if let Some(&(_, bound, why)) = EXPECTED_TO_FAIL.iter().find(|e| e.0 == r.scene) {
            if mae > bound {
                bad.push(format!("{}: MAE {mae:.2} above its recorded bound {bound} ({why})", r.scene));
            }
            if r.loo.is_some_and(|(_, max)| mae <= max) {
                println!("  note: {} is now within the students' spread: remove it from EXPECTED_TO_FAIL", r.scene);
            }
        } else if let Some((_, max)) = r.loo {
            if mae > max {
                bad.push(format!(
                    "{}: MAE {mae:.2} outside the students' leave-one-out spread (max {max:.2})",
                    r.scene
                ));
            }
        }
    }
    assert!(bad.is_empty(), "fidelity:\n{}", bad.join("\n"));
}

/// The conventions are recorded (stats JSON) and part of the checkpoint identity: a resume with
/// another `--first-sample` or `--quantize` is refused.
#[test]
fn conventions_are_recorded_and_guard_resumes() {
    let d = tmpdir("fidelity-flags");
    let run = |extra: &[&str]| {
        let mut c = strata();
        c.args(["render", "--size", "12x8", "--spp", "2", "--threads", "1", "--quiet"]).args(extra);
        c.output().unwrap()
    };
    let stats = d.join("s.json");
    let r = run(&["-o", d.join("a").to_str().unwrap(), "--stats", stats.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!((j["first_sample"].as_str(), j["quantize"].as_str()), (Some("centre"), Some("truncate")));
    let ckpt = d.join("part.ckpt");
    let (o, c) = (d.join("b"), ckpt.to_str().unwrap().to_string());
    let r = run(&["--samples", "0..1", "--checkpoint", &c, "-o", o.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for flags in [["--first-sample", "jittered"], ["--quantize", "round"]] {
        let r = run(&[&["--samples", "0..1", "--resume", &c, "-o", o.to_str().unwrap()], &flags[..]].concat());
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success() && err.contains(&flags[0][2..].replace('-', "_")), "{flags:?}: {err}");
    }
}
