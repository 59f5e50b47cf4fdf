//! `<bsdf type="twosided">` of one BSDF: its back mirrored onto its front
//! (`BsdfParams::twosided`); for a `diffuse` it keeps the material off `SceneDesc::one_sided`.
//! Two different BSDFs for the two sides are refused.

use super::{Build, Plugin, Run};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "twosided", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let inner = p.objects("bsdf");
    match inner.as_slice() {
        [one] => {
            let mut m = b.bsdf(one)?;
            m.bsdf.twosided = true;
            Ok(m)
        }
        _ => Err(p.elem.at.err("twosided takes one nested <bsdf> (two different sides are not supported)")),
    }
}
