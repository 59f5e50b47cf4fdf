//! `<emitter type="spot">`: `intensity` from `to_world`'s origin along its +z, `cutoff_angle`
//! (20), `beam_width` (3/4 of the cutoff), an optional bitmap `texture` over the cone.

use super::{Build, Plugin, Run};
use crate::scene::desc::DeltaLightDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "spot", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let to_world = p.transform("to_world")?;
    let intensity = b.emitter_rgb(p, "intensity")?;
    let cutoff_deg = p.float("cutoff_angle", 20.0)?;
    let beam_width_deg = p.float("beam_width", cutoff_deg * 0.75)?;
    if !(cutoff_deg > 0.0 && cutoff_deg <= 90.0 && beam_width_deg > 0.0 && beam_width_deg <= cutoff_deg) {
        return Err(p
            .elem
            .at
            .err(format!("spot: need 0 < beam_width ({beam_width_deg}) <= cutoff_angle ({cutoff_deg}) <= 90")));
    }
    let texture = match p.color("texture", true)? {
        None => None,
        Some(Color::Rgb(c)) => Some(std::sync::Arc::new(crate::scene::desc::RgbImage::constant(c))),
        Some(Color::Texture(t)) => Some(b.bitmap_image(t)?),
    };
    p.ignore("id");
    b.desc.delta_lights.push(DeltaLightDesc::Spot { to_world, intensity, cutoff_deg, beam_width_deg, texture });
    Ok(())
}
