//! The particle tracer (`<integrator type="ptracer">`): on a small scene with every emitter kind
//! it samples (a rectangle light, point, spot, projector), its image agrees per pixel with the
//! path tracer's within their noise; its error falls as samples grow; it is bit-identical
//! whatever the thread count and however the samples are split into passes; and what it cannot
//! render is refused by name.

use strata::session::RenderOptions;

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="integrator" value="ptracer"/>
    <default name="filter" value="box"/>
    <integrator type="$integrator"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0, 4, -8" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="32"/><integer name="height" value="16"/>
            <rfilter type="$filter"/>
        </film>
    </sensor>
    <bsdf id="white" type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>
    <shape type="rectangle">
        <ref id="white"/>
        <transform name="to_world"><scale value="6"/><rotate x="1" angle="-90"/></transform>
    </shape>
    <shape type="rectangle">
        <ref id="white"/>
        <transform name="to_world"><scale value="6"/><rotate y="1" angle="180"/><translate z="4"/></transform>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="3" x="1"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="10, 8, 6"/></emitter>
    </shape>
    <emitter type="point">
        <rgb name="intensity" value="5"/>
        <point name="position" x="2.5" y="1.5" z="-1"/>
    </emitter>
    <emitter type="spot">
        <rgb name="intensity" value="20"/>
        <float name="cutoff_angle" value="30"/>
        <float name="beam_width" value="15"/>
        <transform name="to_world"><lookat origin="-2, 3, 0" target="-2, 0, 0.5" up="0, 0, 1"/></transform>
    </emitter>
    <emitter type="projector">
        <rgb name="irradiance" value="0.5, 1, 1"/>
        <float name="scale" value="2"/>
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 4, 2" target="0, 0, 3" up="0, 0, 1"/></transform>
    </emitter>
    $extra
</scene>
"#;

/// The scene with `extra` inserted, written to a fresh directory.
fn scene_file(extra: &str) -> (crate::common::Scratch, std::path::PathBuf) {
    let d = crate::common::tmpdir("ptracer");
    let p = d.join("scene.xml");
    std::fs::write(&p, SCENE.replace("$extra", extra)).unwrap();
    (d, p)
}

fn opts(scene: &std::path::Path, integrator: &str, spp: u32, seed: u64, threads: usize) -> RenderOptions {
    RenderOptions {
        scene: Some(scene.to_path_buf()),
        spp: Some(spp),
        seed,
        threads,
        defines: vec![("integrator".into(), integrator.into())],
        ..Default::default()
    }
}

/// Mean and variance of the mean per pixel channel.
fn render(o: &RenderOptions) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let out = strata::session::render_to_film(o).unwrap();
    (out.film.mean(), out.film.variance_of_mean())
}

#[test]
fn agrees_with_the_path_tracer_per_pixel() {
    let (_dir, scene) = scene_file("");
    let (a, va) = render(&opts(&scene, "ptracer", 256, 1, 2));
    let (b, vb) = render(&opts(&scene, "path", 256, 2, 2));
    let (mut n, mut ok, mut sum_a, mut sum_b) = (0, 0, 0.0f64, 0.0f64);
    for i in 0..a.len() {
        for c in 0..3 {
            let (x, y) = (f64::from(a[i][c]), f64::from(b[i][c]));
            sum_a += x;
            sum_b += y;
            let v = f64::from(va[i][c]) + f64::from(vb[i][c]);
            n += 1;
            if v == 0.0 {
                // Both noiseless (a pixel no light reaches): they must be equal.
                ok += usize::from(x == y);
                continue;
            }
            // |z| < 3.89: two-sided p = 1e-4 per pixel channel.
            ok += usize::from(((x - y) / v.sqrt()).abs() < 3.89);
        }
    }
    assert!(sum_b > 1.0, "the path tracer's image is black");
    let frac = ok as f64 / n as f64;
    eprintln!("ptracer vs path: {ok}/{n} pixel channels within |z| < 3.89, sums {sum_a:.4} / {sum_b:.4}");
    assert!(frac >= 0.995, "only {ok} of {n} pixel channels agree ({:.2} %)", 100.0 * frac);
    let ratio = sum_a / sum_b;
    assert!((ratio - 1.0).abs() < 0.02, "image sums differ: ptracer / path = {ratio}");
}

#[test]
fn error_falls_as_samples_grow() {
    let (_dir, scene) = scene_file("");
    let (r, _) = render(&opts(&scene, "path", 2048, 7, 2));
    let rmse = |spp: u32| {
        let (a, _) = render(&opts(&scene, "ptracer", spp, 3, 2));
        let se: f64 = a.iter().zip(&r).flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c]).powi(2))).sum();
        (se / (3 * a.len()) as f64).sqrt()
    };
    let (e8, e128) = (rmse(8), rmse(128));
    eprintln!("ptracer rmse: {e8:.5} at 8 spp, {e128:.5} at 128 spp");
    // 16x the samples: a quarter of the error for an unbiased estimator (the reference's own
    // error is small beside it).
    assert!(e128 < 0.4 * e8, "rmse {e8} at 8 spp, {e128} at 128 spp");
}

#[test]
fn bit_identical_across_threads_and_passes() {
    let (_dir, scene) = scene_file("");
    let bits =
        |f: &strata::film::Film| f.sum.iter().chain(&f.sum_sq).flat_map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
    let one = strata::session::render_to_film(&opts(&scene, "ptracer", 6, 4, 1)).unwrap();
    let two = strata::session::render_to_film(&opts(&scene, "ptracer", 6, 4, 2)).unwrap();
    assert_eq!(bits(&one.film), bits(&two.film), "1 and 2 threads differ");
    let (scene_b, integ) = strata::session::prepare(&opts(&scene, "ptracer", 6, 4, 2)).unwrap();
    let pool = strata::render::thread_pool(2).unwrap();
    let mut parts = strata::film::Film::new(32, 16);
    strata::render::render(&scene_b, &integ, &mut parts, 0..2, &pool);
    strata::render::render(&scene_b, &integ, &mut parts, 2..6, &pool);
    assert_eq!(bits(&one.film), bits(&parts), "passes 0..2 + 2..6 differ from 0..6");
    // and the image is not empty
    assert!(one.film.mean().iter().any(|p| p[0] > 0.0));
}

#[test]
fn what_it_cannot_render_is_refused_by_name() {
    let cases = [
        (r#"<emitter type="constant"><rgb name="radiance" value="1"/></emitter>"#, "constant"),
        (r#"<emitter type="directional"><vector name="direction" x="0" y="-1" z="0"/></emitter>"#, "directional"),
    ];
    for (extra, what) in cases {
        let (_dir, scene) = scene_file(extra);
        let e = strata::session::render_to_film(&opts(&scene, "ptracer", 1, 0, 1)).err().expect(what).to_string();
        assert!(e.contains("particle tracer") && e.contains(what), "{what}: {e}");
    }
    let (_dir, scene) = scene_file("");
    let mut o = opts(&scene, "ptracer", 1, 0, 1);
    o.defines.push(("filter".into(), "gaussian".into()));
    let e = strata::session::render_to_film(&o).err().expect("gaussian").to_string();
    assert!(e.contains("particle tracer") && e.contains("box"), "{e}");
}

/// Area emitters with a bitmap `radiance` (Mitsuba's various_emitters scene) are the particle
/// tracer's; the other integrators refuse them by name rather than render them untextured.
#[test]
fn textured_area_emitters_are_the_particle_tracers_only() {
    let scene =
        strata::lab::mitsuba::corpus_dir().join("tests/scenes/various_emitters/test_various_emitters_ptracer.xml");
    assert!(scene.is_file(), "{}: the Mitsuba corpus is missing (it comes with ../shared)", scene.display());
    let o = RenderOptions { size: Some((32, 4)), ..opts(&scene, "path", 1, 0, 1) };
    let e = strata::session::render_to_film(&o).err().expect("path on a textured emitter").to_string();
    assert!(e.contains("textured area emitter") && e.contains("ptracer"), "{e}");
    let o = RenderOptions { size: Some((32, 4)), ..opts(&scene, "ptracer", 1, 0, 1) };
    let out = strata::session::render_to_film(&o).unwrap();
    assert!(out.film.mean().iter().any(|p| p[0] > 0.0));
}
