//! `<emitter type="projector">`: an image (`irradiance`: a bitmap texture or a constant)
//! projected from `to_world`'s origin along +z with `fov` along `fov_axis` (against the image's
//! aspect ratio, as Mitsuba resolves it), or Mitsuba's `focal_length` (default `50mm`: the angle
//! of a 36 x 24 mm film's diagonal), times `scale`.

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
    let focal = p.string("focal_length")?;
    let (fov, axis_name) = if fov != 0.0 && focal.is_some() {
        return Err(p.elem.at.err("projector: give either `fov` or `focal_length`, not both"));
    } else if fov == 0.0 {
        // Mitsuba's default: a 50 mm lens on 36 x 24 mm film, the angle along the diagonal.
        {
            let text = focal.unwrap_or("50mm");
            let mm: f64 = text
                .trim_end_matches("mm")
                .trim()
                .parse()
                .map_err(|_| p.elem.at.err(format!("projector focal_length \"{text}\" is not <x>mm with x > 0")))?;
            if !(mm > 0.0 && mm.is_finite()) {
                return Err(p.elem.at.err(format!("projector focal_length \"{text}\" is not <x>mm with x > 0")));
            }
            ((2.0 * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm)).atan()).to_degrees() as f32, "diagonal")
        }
    } else {
        (fov, p.string("fov_axis")?.unwrap_or("x"))
    };
    if !(fov > 0.0 && fov < 180.0) {
        return Err(p.elem.at.err(format!("projector fov {fov} must be in (0, 180) degrees")));
    }
    let axis = FovAxis::parse(axis_name).ok_or_else(|| {
        p.elem.at.err(format!("fov_axis \"{axis_name}\" is not one of x, y, diagonal, smaller, larger"))
    })?;
    let aspect = f64::from(irradiance.width) / f64::from(irradiance.height);
    let fov_x_deg = axis.fov_x_deg(f64::from(fov), aspect) as f32;
    p.ignore("id");
    b.desc.delta_lights.push(DeltaLightDesc::Projector { to_world, irradiance, scale, fov_x_deg });
    Ok(())
}
