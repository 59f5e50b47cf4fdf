//! `<bsdf type="twosided">` of a `diffuse`: strata shades diffuse surfaces on both sides already.

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
        [one] if one.attr("type") == Some("diffuse") => b.bsdf(one),
        [one] => Err(one.at.err(format!("twosided of {} is not supported (only of diffuse)", one.what()))),
        _ => Err(p.elem.at.err("twosided takes one nested <bsdf> (two different sides are not supported)")),
    }
}
