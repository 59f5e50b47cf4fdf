//! `<emitter type="projector">`: an image (`irradiance`: a bitmap texture or a constant)
//! projected from `to_world`'s origin along +z with `fov` along `fov_axis` (against the image's
//! aspect ratio, as Mitsuba resolves it), times `scale`.

use super::{Build, Plugin, Run};
use crate::scene::desc::{DeltaLightDesc, FovAxis, RgbImage};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use std::sync::Arc;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "projector", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let to_world = p.transform("to_world")?;
    let irradiance = match p.color("irradiance", true)? {
        None => Arc::new(RgbImage::constant(crate::scene::xml::values::spectrum_default_emitter())),
        Some(Color::Rgb(c)) => Arc::new(RgbImage::constant(c)),
        Some(Color::Texture(t)) => b.bitmap_image(t)?,
    };
    let scale = p.float("scale", 1.0)?;
    let fov = p.float("fov", 0.0)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(p.elem.at.err(format!("projector fov {fov} must be in (0, 180) degrees")));
    }
    let axis_name = p.string("fov_axis")?.unwrap_or("x");
    let axis = FovAxis::parse(axis_name).ok_or_else(|| {
        p.elem.at.err(format!("fov_axis \"{axis_name}\" is not one of x, y, diagonal, smaller, larger"))
    })?;
    let aspect = f64::from(irradiance.width) / f64::from(irradiance.height);
    let fov_x_deg = axis.fov_x_deg(f64::from(fov), aspect) as f32;
    p.ignore("id");
    b.desc.delta_lights.push(DeltaLightDesc::Projector { to_world, irradiance, scale, fov_x_deg });
    Ok(())
}
