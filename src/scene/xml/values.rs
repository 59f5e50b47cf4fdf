//! Property values: numbers (finite, in range), vectors, `rgb`, `spectrum` (a value, or
//! wavelength:value pairs turned into linear sRGB as Mitsuba's RGB variants do), transforms in
//! Mitsuba's order, and the named IOR and conductor tables.

use super::doc::Elem;
use super::tables;
use crate::scene::error::SceneError;
use glam::{Mat4, Vec3, Vec4};

/// Largest magnitude a scene number may have: beyond it (or not finite) it is refused.
pub const MAX_MAGNITUDE: f64 = 1e30;

/// A finite float, as Mitsuba spells them.
pub fn float(e: &Elem, s: &str) -> Result<f32, SceneError> {
    let v: f64 = s.trim().parse().map_err(|_| e.at.err(format!("\"{s}\" is not a number")))?;
    if !v.is_finite() || v.abs() > MAX_MAGNITUDE {
        return Err(e.at.err(format!("{s} is out of range (numbers must be finite and within ±{MAX_MAGNITUDE:e})")));
    }
    Ok(v as f32)
}

/// An integer within i32 range.
pub fn integer(e: &Elem, s: &str) -> Result<i64, SceneError> {
    let v: i64 = s.trim().parse().map_err(|_| e.at.err(format!("\"{s}\" is not an integer")))?;
    if i32::try_from(v).is_err() {
        return Err(e.at.err(format!("{s} is out of range (integers must fit in 32 bits)")));
    }
    Ok(v)
}

/// `true` / `false`.
pub fn boolean(e: &Elem, s: &str) -> Result<bool, SceneError> {
    match s.trim() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(e.at.err(format!("\"{s}\" is not a boolean (true or false)"))),
    }
}

/// A list of numbers separated by commas and/or blanks.
pub fn floats(e: &Elem, s: &str) -> Result<Vec<f32>, SceneError> {
    s.split(|c: char| c == ',' || c.is_whitespace()).filter(|t| !t.is_empty()).map(|t| float(e, t)).collect()
}

/// A 3-vector from `value="x,y,z"` (one number: all three when `splat`) or `x=`, `y=`, `z=`
/// attributes (missing ones `default`).
pub fn vec3(e: &Elem, default: f32, splat: bool) -> Result<Vec3, SceneError> {
    if let Some(v) = e.attr("value") {
        let xs = floats(e, v)?;
        return match xs.len() {
            3 => Ok(Vec3::new(xs[0], xs[1], xs[2])),
            1 if splat => Ok(Vec3::splat(xs[0])),
            _ => Err(e.at.err(format!("\"{v}\" is not three numbers"))),
        };
    }
    let c = |n: &str| e.attr(n).map_or(Ok(default), |s| float(e, s));
    Ok(Vec3::new(c("x")?, c("y")?, c("z")?))
}

/// `<rgb value="r,g,b">` or `<rgb value="v">`.
pub fn rgb(e: &Elem) -> Result<Vec3, SceneError> {
    let v = e.need("value")?;
    let xs = floats(e, v)?;
    match xs.len() {
        1 => Ok(Vec3::splat(xs[0])),
        3 => Ok(Vec3::new(xs[0], xs[1], xs[2])),
        _ => Err(e.at.err(format!("rgb \"{v}\" is not one or three numbers"))),
    }
}

/// Mitsuba's XYZ to linear sRGB matrix (rows), its published digits.
#[allow(clippy::excessive_precision)]
const XYZ_TO_SRGB: [[f32; 3]; 3] =
    [[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556], [0.055648, -0.204043, 1.057311]];

fn xyz_to_srgb(x: Vec3) -> Vec3 {
    let r = |k: usize| Vec3::from(XYZ_TO_SRGB[k]).dot(x);
    Vec3::new(r(0), r(1), r(2))
}

/// The CIE curves and D65 at wavelength `w` (nm), linearly interpolated in the 1 nm table.
fn cie(w: f32) -> [f32; 4] {
    let t = (w - tables::CIE_MIN).clamp(0.0, tables::CIE_MAX - tables::CIE_MIN);
    let i = (t as usize).min(tables::CIE_XYZ.len() - 2);
    let f = t - i as f32;
    let (a, b) = (tables::CIE_XYZ[i], tables::CIE_XYZ[i + 1]);
    std::array::from_fn(|k| a[k] * (1.0 - f) + b[k] * f)
}

/// A `<spectrum>`: `value="v"` (uniform; inside an emitter Mitsuba's RGB variants make it
/// `v * xyz_to_srgb(1, 1, 1)`, so that they match the spectral ones) or `value="w1:v1, w2:v2, ..."`
/// (wavelengths in nm, increasing), integrated against the CIE 1931 curves over 1000 steps from 360
/// to 830 nm (with the D65 illuminant outside emitters), converted to linear sRGB and clamped to
/// [0, 1] outside emitters (to >= 0 inside).
pub fn spectrum(e: &Elem, in_emitter: bool) -> Result<Vec3, SceneError> {
    if e.attr("filename").is_some() {
        return Err(e.at.err("a <spectrum> read from a file (filename=) is not supported; give value= pairs"));
    }
    let v = e.need("value")?;
    if !v.contains(':') {
        let x = float(e, v)?;
        return Ok(if in_emitter { xyz_to_srgb(Vec3::ONE) * x } else { Vec3::splat(x) });
    }
    let mut ws = Vec::new();
    let mut vs = Vec::new();
    for pair in v.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (w, x) = pair.split_once(':').ok_or_else(|| e.at.err(format!("\"{pair}\" is not wavelength:value")))?;
        let (w, x) = (float(e, w)?, float(e, x)?);
        if ws.last().is_some_and(|&l| w <= l) {
            return Err(e.at.err(format!("spectrum wavelengths must increase (\"{v}\")")));
        }
        ws.push(w);
        vs.push(x);
    }
    if ws.len() < 2 {
        return Err(e.at.err(format!("a spectrum needs at least two wavelength:value pairs (\"{v}\")")));
    }
    Ok(spectrum_to_srgb(&ws, &vs, in_emitter))
}

/// Wavelength:value pairs to linear sRGB (see [`spectrum`]).
pub fn spectrum_to_srgb(ws: &[f32], vs: &[f32], in_emitter: bool) -> Vec3 {
    const STEPS: usize = 1000;
    let mut xyz = Vec3::ZERO;
    let (lo, hi) = (tables::CIE_MIN, tables::CIE_MAX);
    for i in 0..STEPS {
        let w = lo + (i as f32 / (STEPS - 1) as f32) * (hi - lo);
        if w < ws[0] || w > ws[ws.len() - 1] {
            continue;
        }
        let k = ws.partition_point(|&x| x <= w).clamp(1, ws.len() - 1) - 1;
        let (w0, w1, v0, v1) = (ws[k], ws[k + 1], vs[k], vs[k + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let c = cie(w);
        let weight = tables::CIE_Y_NORMALIZATION * if in_emitter { 1.0 } else { c[3] };
        xyz += Vec3::new(c[0], c[1], c[2]) * v * weight;
    }
    xyz *= (hi - lo) / STEPS as f32;
    let rgb = xyz_to_srgb(xyz);
    if in_emitter {
        rgb.max(Vec3::ZERO)
    } else {
        rgb.clamp(Vec3::ZERO, Vec3::ONE)
    }
}

/// Mitsuba's default emitter radiance in its RGB variants: a uniform spectrum of 1, which is
/// RGB (1, 1, 1) there (`mi.load_dict({'type': 'constant'})` in `scalar_rgb`; the
/// orthographic_sensor reference's background is 1.000 in every channel).
pub fn spectrum_default_emitter() -> Vec3 {
    Vec3::ONE
}

/// An index of refraction: a number, or one of Mitsuba's names (`bk7`, `water`, `diamond`, ...).
pub fn ior(e: &Elem, s: &str) -> Result<f32, SceneError> {
    if let Some(&(_, v)) = tables::IORS.iter().find(|(n, _)| *n == s.trim()) {
        return Ok(v);
    }
    float(e, s).map_err(|_| {
        let names: Vec<&str> = tables::IORS.iter().map(|(n, _)| *n).collect();
        e.at.err(format!("\"{s}\" is neither a number nor a known IOR name ({})", names.join(", ")))
    })
}

/// A named conductor's linear-sRGB (eta, k) (`Au`, `Cu`, `Ag`, `Al`, ...).
pub fn conductor(e: &Elem, s: &str) -> Result<(Vec3, Vec3), SceneError> {
    tables::CONDUCTORS.iter().find(|(n, _, _)| *n == s.trim()).map(|&(_, eta, k)| (eta.into(), k.into())).ok_or_else(
        || {
            let names: Vec<&str> = tables::CONDUCTORS.iter().map(|(n, _, _)| *n).collect();
            e.at.err(format!("unknown conductor \"{s}\" (known: {})", names.join(", ")))
        },
    )
}

/// A `<transform>`'s matrix: its operations composed in Mitsuba's order (each later one applied
/// after the earlier ones: `M = op_n * ... * op_1`).
pub fn transform(e: &Elem) -> Result<Mat4, SceneError> {
    let mut m = Mat4::IDENTITY;
    for op in &e.children {
        let t = match op.tag.as_str() {
            "translate" => Mat4::from_translation(vec3(op, 0.0, false)?),
            "scale" => Mat4::from_scale(vec3(op, 1.0, true)?),
            "rotate" => {
                let axis = vec3(op, 0.0, false)?;
                let angle = float(op, op.need("angle")?)?;
                if axis.length_squared() == 0.0 {
                    return Err(op.at.err("<rotate> needs a non-zero axis (x=, y=, z= or value=)"));
                }
                Mat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = op.need("value")?;
                let xs = floats(op, v)?;
                match xs.len() {
                    16 => Mat4::from_cols_array(&xs.try_into().unwrap()).transpose(),
                    9 => Mat4::from_mat3(glam::Mat3::from_cols_array(&xs.try_into().unwrap()).transpose()),
                    n => return Err(op.at.err(format!("<matrix> needs 16 (or 9) numbers, not {n}"))),
                }
            }
            "lookat" => lookat(op)?,
            other => {
                return Err(op.at.err(format!(
                    "unknown transform operation <{other}> (supported: translate, scale, rotate, matrix, lookat)"
                )))
            }
        };
        m = t * m;
    }
    if !m.is_finite() {
        return Err(e.at.err("the transform is not finite"));
    }
    Ok(m)
}

/// Mitsuba's look-at matrix: columns (left, up, direction, origin) with left = up x dir.
fn lookat(op: &Elem) -> Result<Mat4, SceneError> {
    let p = |n: &str| -> Result<Vec3, SceneError> {
        let v = op.need(n)?;
        let xs = floats(op, v)?;
        (xs.len() == 3)
            .then(|| Vec3::new(xs[0], xs[1], xs[2]))
            .ok_or_else(|| op.at.err(format!("{n}=\"{v}\" is not three numbers")))
    };
    let origin = p("origin")?;
    let target = p("target")?;
    let up = if op.attr("up").is_some() { p("up")? } else { Vec3::Y };
    let dir = (target - origin).normalize_or_zero();
    let left = up.normalize_or_zero().cross(dir);
    if dir == Vec3::ZERO || left.length_squared() < 1e-12 {
        return Err(op.at.err("<lookat>: origin equals target, or up is parallel to the view direction"));
    }
    let left = left.normalize();
    let new_up = dir.cross(left);
    Ok(Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        Vec4::new(origin.x, origin.y, origin.z, 1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::super::doc::Loc;
    use super::*;
    use std::sync::Arc;

    fn el(tag: &str, attrs: &[(&str, &str)]) -> Elem {
        Elem {
            tag: tag.into(),
            attrs: attrs.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect(),
            children: Vec::new(),
            at: Loc { file: Arc::new("t.xml".into()), line: 7 },
        }
    }

    #[test]
    fn spectra_match_mitsubas_rgb_variants() {
        for &(text, emitter, want) in tables::SPECTRUM_CHECKS {
            let got = spectrum(&el("spectrum", &[("value", text)]), emitter).unwrap();
            let want = Vec3::from(want);
            assert!((got - want).abs().max_element() < 2e-3 * want.max_element().max(1.0), "{text}: {got} vs {want}");
        }
    }

    #[test]
    fn named_iors_and_conductors() {
        let e = el("float", &[]);
        assert_eq!(ior(&e, "bk7").unwrap(), 1.5046);
        assert_eq!(ior(&e, "1.33").unwrap(), 1.33);
        assert!(ior(&e, "unobtainium").unwrap_err().message.contains("diamond"));
        let (eta, k) = conductor(&e, "Au").unwrap();
        // Gold: small eta in red, large k in red (published optical constants, Palik).
        assert!(eta.x < 0.3 && eta.z > 1.0 && k.x > 3.0, "{eta} {k}");
        assert!(conductor(&e, "Zz").is_err());
    }

    #[test]
    fn transforms_compose_in_mitsubas_order() {
        let mut t = el("transform", &[("name", "to_world")]);
        t.children = vec![el("scale", &[("value", "2")]), el("translate", &[("x", "1")])];
        let m = transform(&t).unwrap();
        // Scale first, then translate.
        assert_eq!(m.transform_point3(Vec3::new(1.0, 0.0, 0.0)), Vec3::new(3.0, 0.0, 0.0));
        let mut r = el("transform", &[]);
        r.children = vec![el("rotate", &[("z", "1"), ("angle", "90")])];
        let p = transform(&r).unwrap().transform_point3(Vec3::X);
        assert!((p - Vec3::Y).length() < 1e-6, "{p}");
        let mut l = el("transform", &[]);
        l.children = vec![el("lookat", &[("origin", "0,0,5"), ("target", "0,0,0"), ("up", "0,1,0")])];
        let m = transform(&l).unwrap();
        assert!((m.transform_vector3(Vec3::Z) - Vec3::NEG_Z).length() < 1e-6);
        assert!((m.transform_point3(Vec3::ZERO) - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-6);
        // Camera x is the left of the view: up x dir.
        assert!((m.transform_vector3(Vec3::X) - Vec3::NEG_X).length() < 1e-6, "{}", m.transform_vector3(Vec3::X));
        let mut mm = el("transform", &[]);
        mm.children = vec![el("matrix", &[("value", "1 0 0 4  0 1 0 5  0 0 1 6  0 0 0 1")])];
        assert_eq!(transform(&mm).unwrap().transform_point3(Vec3::ZERO), Vec3::new(4.0, 5.0, 6.0));
    }

    #[test]
    fn numbers_are_checked() {
        let e = el("float", &[]);
        assert!(float(&e, "1e999").unwrap_err().message.contains("out of range"));
        assert!(float(&e, "nan").is_err());
        assert!(integer(&e, "99999999999").is_err());
        assert_eq!(integer(&e, "-3").unwrap(), -3);
        assert!(boolean(&e, "yes").is_err());
    }
}
