//! Mitsuba's `diffuse` is one-sided unless wrapped in `twosided`: the loader lists the one-sided
//! materials (`SceneDesc::one_sided`) and gives every course material its two-sided flag back.

use super::*;

#[test]
fn plain_diffuse_is_one_sided_and_twosided_diffuse_is_not() {
    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("s.xml");
    let shape = |bsdf: &str| format!("<shape type=\"rectangle\">{bsdf}</shape>\n");
    let text = format!(
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><rfilter type=\"box\"/></film></sensor>\n{}{}{}{}</scene>\n",
        shape("<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.3\"/></bsdf>"),
        shape("<bsdf type=\"twosided\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.3\"/></bsdf></bsdf>"),
        shape(""),
        shape("<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.3\"/></bsdf>"),
    );
    std::fs::write(&path, text).unwrap();
    let desc = load(&path, &Limits::default(), &[]).expect("loads").desc;
    let mat = |i: usize| desc.triangles.iter().filter(|t| t.material == desc.triangles[2 * i].material).count();
    assert_eq!(mat(0), 4, "the two plain diffuse rectangles share one material");
    let (plain, two, default) = (desc.triangles[0].material, desc.triangles[2].material, desc.triangles[4].material);
    assert_ne!(plain, two);
    let mut want = vec![plain, default];
    want.sort();
    assert_eq!(desc.one_sided, want, "one-sided: the plain diffuse and the default material");
    assert!(desc.materials.iter().all(|m| m.bsdf.twosided), "course materials keep their two-sided flag");
}

#[test]
fn sdfgrid_uv_origin_is_not_the_no_uv_sentinel() {
    use crate::scene::texturing::{is_no_uv, triangle_uv, ZERO_UV};
    let none = [glam::Vec2::ZERO; 3];
    assert!(is_no_uv(&none) && !is_no_uv(&[ZERO_UV; 3]));
    // The origin reads as 0 wherever the hit lies (not the barycentrics).
    let uv = triangle_uv(Some(&[ZERO_UV; 3]), 0.3, 0.6);
    assert_eq!((uv.x, uv.y), (0.0, 0.0));
}
