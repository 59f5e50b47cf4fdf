//! `<bsdf type="principled">`: Mitsuba's principled BSDF (`bsdf::principled`): `base_color`
//! (0.5; rgb or texture), `roughness` (0.5), `anisotropic`, `metallic`, `spec_trans`,
//! `spec_tint`, `sheen`, `sheen_tint`, `flatness`, `clearcoat`, `clearcoat_gloss` (0; floats or
//! textures, read as Mitsuba's `eval_1`; strata takes at most four textured scalars per BSDF),
//! `eta` or `specular` (0.5; eta = 2 / (1 - sqrt(0.08 specular)) - 1; not both), and the
//! sampling rates `main_specular_sampling_rate`, `clearcoat_sampling_rate`,
//! `diffuse_reflectance_sampling_rate` (1). As Mitsuba, with a `spec_trans` given (and not the
//! float 0) an eta of 1 becomes 1.001 and a specular of 0 becomes 0.001. Both sides: from inside
//! the object only the dielectric lobes remain.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::{Slot, SCALARS};
use crate::bsdf::microfacet::principled::{Entry, CONSTANT, N};
use crate::bsdf::principled::{eta_of_specular, params, PARAMS};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "principled", run: Run::Bsdf(run) };

/// The scalars of a principled BSDF listed in `list` (name, default, texture allowed), but those
/// in `skip`, as a table entry: floats as constants, textures (where allowed) in the row's next
/// free scalar slot, at most [`SCALARS`] of them.
pub(super) fn scalars<'e>(
    b: &mut Build<'e>,
    p: &Props<'e>,
    list: &[(&str, f32, bool)],
    skip: &[&str],
) -> Result<Entry, SceneError> {
    let mut e = Entry { values: [0.0; N], slots: [CONSTANT; N] };
    let mut next = 0u8;
    for (j, &(name, default, texture)) in list.iter().enumerate() {
        if skip.contains(&name) {
            continue;
        }
        let given = p.get(name);
        let at = given.map_or(&p.elem.at, |g| &g.at);
        let textured = texture && given.is_some_and(|g| g.tag == "texture");
        if textured && next as usize >= SCALARS {
            return Err(at.err(format!(
                "{}: strata takes at most {SCALARS} textured scalar parameters per BSDF; \"{name}\" is one more",
                p.elem.what()
            )));
        }
        let v = b.float_param(p, name, default, textured.then_some(Slot::Scalar(next)))?;
        if !v.is_finite() {
            return Err(at.err(format!("{}: \"{name}\" must be finite, not {v}", p.elem.what())));
        }
        if textured {
            e.slots[j] = next;
            next += 1;
        }
        e.values[j] = v;
    }
    Ok(e)
}

/// Mitsuba's `get_flag`: the property is given, and not as the float 0.
pub(super) fn given_nonzero(p: &Props, name: &str) -> bool {
    p.has(name)
        && p.get(name).is_some_and(|e| {
            e.tag == "texture" || e.attr("value").and_then(|v| v.trim().parse::<f32>().ok()) != Some(0.0)
        })
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let base = b.color_param(p, "base_color", Vec3::splat(0.5), Slot::Color(0))?;
    let mut entry = scalars(b, p, &PARAMS, &["eta"])?;
    let spec_trans = given_nonzero(p, "spec_trans");
    let eta_at = p.get("eta").map_or(&p.elem.at, |e| &e.at);
    let eta = match (p.has("eta"), p.has("specular")) {
        (true, true) => {
            return Err(eta_at.err(format!("{}: give \"eta\" or \"specular\", not both (as Mitsuba)", p.elem.what())))
        }
        (true, false) => {
            let eta = p.float("eta", 1.5)?;
            if spec_trans && eta == 1.0 {
                1.001
            } else {
                eta
            }
        }
        (false, _) => {
            let mut s = p.float("specular", 0.5)?;
            if spec_trans && s == 0.0 {
                s = 1e-3;
            }
            if !(0.0..12.5).contains(&s) {
                let at = p.get("specular").map_or(&p.elem.at, |e| &e.at);
                return Err(at.err(format!("{}: \"specular\" must be in [0, 12.5), not {s}", p.elem.what())));
            }
            eta_of_specular(s)
        }
    };
    if !(eta.is_finite() && eta > 0.0) {
        return Err(eta_at.err(format!("{}: \"eta\" must be a finite index > 0, not {eta}", p.elem.what())));
    }
    let j = PARAMS.iter().position(|q| q.0 == "eta").unwrap_or(0);
    entry.values[j] = eta;
    Ok(super::diffuse::registry_material(params(base, entry)))
}

#[cfg(test)]
mod tests {
    use crate::bsdf::interface::{Bsdf, Slot};
    use crate::scene::limits::Limits;
    use crate::scene::xml::load;

    fn checker(name: &str, a: f32, b: f32) -> String {
        format!("<texture name=\"{name}\" type=\"checkerboard\"><float name=\"color0\" value=\"{a}\"/><float name=\"color1\" value=\"{b}\"/></texture>")
    }

    /// The rectangle's material row, its textured slots, the warnings.
    type Loaded = (crate::bsdf::BsdfParams, Vec<(Slot, u32)>, Vec<String>);

    /// Loads a rectangle with `bsdf`.
    fn load_bsdf(bsdf: &str) -> Result<Loaded, String> {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("s.xml");
        let text = format!(
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><rfilter type=\"box\"/></film></sensor>\n<shape type=\"rectangle\">\n{bsdf}\n</shape>\n</scene>\n"
        );
        std::fs::write(&path, text).unwrap();
        let l = load(&path, &Limits::default(), &[]).map_err(|e| e.to_string())?;
        let m = l.desc.triangles[0].material as usize;
        let slots = l.desc.param_textures.get(m).cloned().unwrap_or_default();
        Ok((l.desc.materials[m].bsdf, slots, l.warnings))
    }

    /// Textured scalars take the scalar slots in order, the constants stay in the table.
    #[test]
    fn textured_scalars_take_slots_in_order() {
        let bsdf = format!(
            "<bsdf type=\"principled\"><rgb name=\"base_color\" value=\"0.2,0.8,0.1\"/><float name=\"roughness\" value=\"0.15\"/>{}{}{}{}<float name=\"specular\" value=\"0.7\"/></bsdf>",
            checker("anisotropic", 0.05, 0.8),
            checker("metallic", 0.7, 0.1),
            checker("clearcoat", 0.9, 0.1),
            checker("sheen", 0.2, 0.9)
        );
        let (row, slots, warnings) = load_bsdf(&bsdf).unwrap();
        assert_eq!(row.kind, crate::bsdf::principled::Principled::ID);
        assert_eq!(slots.iter().map(|s| s.0).collect::<Vec<_>>(), (0..4).map(Slot::Scalar).collect::<Vec<_>>());
        assert!(warnings.is_empty(), "{warnings:?}");
    }

    /// A fifth textured scalar (in Mitsuba's parameter order: `clearcoat` after `spec_tint`
    /// and `sheen`), `eta` with `specular`, and an unknown parameter: clear errors
    /// and warnings naming the property and the line.
    #[test]
    fn refusals_name_the_property() {
        let five: String = ["anisotropic", "metallic", "clearcoat", "sheen", "spec_tint"]
            .iter()
            .map(|n| checker(n, 0.1, 0.2))
            .collect();
        let e = load_bsdf(&format!("<bsdf type=\"principled\">{five}</bsdf>")).unwrap_err();
        assert!(e.contains("\"clearcoat\" is one more") && e.contains("s.xml:"), "{e}");
        let e = load_bsdf("<bsdf type=\"principled\"><float name=\"eta\" value=\"1.5\"/><float name=\"specular\" value=\"0.5\"/></bsdf>")
            .unwrap_err();
        assert!(e.contains("not both"), "{e}");
        let e = load_bsdf(&format!("<bsdf type=\"principled\">{}</bsdf>", checker("eta", 1.2, 1.4))).unwrap_err();
        assert!(e.contains("\"eta\""), "{e}");
        let (_, _, warnings) =
            load_bsdf("<bsdf type=\"principledthin\"><float name=\"clearcoat\" value=\"0.5\"/></bsdf>").unwrap();
        assert!(warnings.iter().any(|w| w.contains("clearcoat")), "{warnings:?}");
        // principledthin textures its eta.
        let (row, slots, _) =
            load_bsdf(&format!("<bsdf type=\"principledthin\">{}</bsdf>", checker("eta", 1.2, 1.4))).unwrap();
        assert_eq!((row.kind, slots.len()), (crate::bsdf::principledthin::PrincipledThin::ID, 1));
    }
}
