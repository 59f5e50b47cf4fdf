//! The upgrade of files written for Mitsuba 0.6 (`version="0.x"` / `"1.x"`), as Mitsuba 3 does it
//! on load: property names from camelCase to snake_case, `<lookAt>` to `<lookat>`, the diffuse
//! BSDF's `diffuse_reflectance` to `reflectance`, and the bitmap texture's `uoffset`/`voffset`/
//! `uscale`/`vscale` to a `to_uv` transform.

use super::elem::Elem;

/// `maxDepth` -> `max_depth`, `toWorld` -> `to_world`, `fovAxis` -> `fov_axis` (a lower-case run
/// after an upper-case letter starts a new word; digits stay attached).
pub fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let chars: Vec<char> = name.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_uppercase() {
            let prev_lower = i > 0 && (chars[i - 1].is_ascii_lowercase() || chars[i - 1].is_ascii_digit());
            let next_lower = chars.get(i + 1).is_some_and(|n| n.is_ascii_lowercase());
            let prev_upper = i > 0 && chars[i - 1].is_ascii_uppercase();
            if i > 0 && (prev_lower || (prev_upper && next_lower)) {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// Upgrades a 0.6-format tree in place.
pub fn upgrade(e: &mut Elem) {
    if e.tag == "lookAt" {
        e.tag = "lookat".to_string();
    }
    for (k, v) in &mut e.attrs {
        if k == "name" {
            *v = snake_case(v);
        }
    }
    if e.tag == "bsdf" && e.attr("type") == Some("diffuse") {
        for c in &mut e.children {
            for (k, v) in &mut c.attrs {
                if k == "name" && v == "diffuseReflectance" {
                    *v = "reflectance".to_string();
                }
            }
        }
    }
    if e.tag == "texture" && e.attr("type") == Some("bitmap") {
        upgrade_uv(e);
    }
    e.children.iter_mut().for_each(upgrade);
}

/// Moves a 0.6 bitmap's `uoffset`, `voffset`, `uscale`, `vscale` floats into `<transform
/// name="to_uv">` (scale, then translate, as Mitsuba 3 does).
fn upgrade_uv(e: &mut Elem) {
    let mut take = |name: &str, default: &str| -> String {
        let i =
            e.children.iter().position(|c| c.tag == "float" && c.attr("name").map(snake_case).as_deref() == Some(name));
        i.map(|i| e.children.remove(i).attr("value").unwrap_or(default).to_string())
            .unwrap_or_else(|| default.to_string())
    };
    let (uo, vo, us, vs) = (take("uoffset", "0"), take("voffset", "0"), take("uscale", "1"), take("vscale", "1"));
    if (uo.as_str(), vo.as_str(), us.as_str(), vs.as_str()) == ("0", "0", "1", "1") {
        return;
    }
    let at = e.at.clone();
    let op = |tag: &str, x: String, y: String| Elem {
        tag: tag.to_string(),
        attrs: vec![("x".into(), x), ("y".into(), y)],
        children: Vec::new(),
        at: at.clone(),
    };
    e.children.push(Elem {
        tag: "transform".into(),
        attrs: vec![("name".into(), "to_uv".into())],
        children: vec![op("scale", us, vs), op("translate", uo, vo)],
        at: at.clone(),
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_becomes_snake_case_as_mitsuba_does() {
        for (a, b) in [
            ("maxDepth", "max_depth"),
            ("toWorld", "to_world"),
            ("fovAxis", "fov_axis"),
            ("sampleCount", "sample_count"),
            ("max_depth", "max_depth"),
            ("intIOR", "int_ior"),
            ("filename", "filename"),
        ] {
            assert_eq!(snake_case(a), b, "{a}");
        }
    }
}
