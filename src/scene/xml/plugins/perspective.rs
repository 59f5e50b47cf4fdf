//! `<sensor type="perspective">`: `to_world` (Mitsuba's camera frame), `fov` and `fov_axis` (x,
//! y, diagonal, smaller, larger) or `focal_length`, `near_clip`; its nested `film` and `sampler`.
//! [`sensor`] is shared with `orthographic`.

use super::{Build, Plugin, Run};
use crate::scene::desc::{FovAxis, Projection, SensorDesc};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "sensor", kind: "perspective", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let (fov_deg, default_axis) = match (p.has("fov"), p.string("focal_length")?) {
        (true, Some(_)) => return Err(p.elem.at.err("give `fov` or `focal_length`, not both")),
        (true, None) => (p.float("fov", 0.0)?, "x"),
        (false, f) => {
            // Mitsuba's default is 50mm; a focal length is measured on the diagonal of a 36 x 24 mm
            // frame.
            let f = f.unwrap_or("50mm");
            let mm: f32 = f
                .trim()
                .trim_end_matches("mm")
                .parse()
                .map_err(|_| p.elem.at.err(format!("focal_length \"{f}\" is not like \"50mm\"")))?;
            if !(mm > 0.0) {
                return Err(p.elem.at.err(format!("focal_length \"{f}\" must be positive")));
            }
            let diagonal = (36.0f32 * 36.0 + 24.0 * 24.0).sqrt();
            (2.0 * (diagonal / (2.0 * mm)).atan().to_degrees(), "diagonal")
        }
    };
    if !(fov_deg > 0.0 && fov_deg < 180.0) {
        return Err(p.elem.at.err(format!("fov {fov_deg} must be in (0, 180) degrees")));
    }
    let axis = p.string("fov_axis")?.unwrap_or(default_axis);
    let fov_axis = FovAxis::parse(axis)
        .ok_or_else(|| p.elem.at.err(format!("fov_axis \"{axis}\" is not one of x, y, diagonal, smaller, larger")))?;
    p.refuse("principal_point_offset_x", "off-centre projections are not supported")?;
    p.refuse("principal_point_offset_y", "off-centre projections are not supported")?;
    sensor(b, p, Projection::Perspective { fov_deg, fov_axis })
}

/// The sensor common to both projections: `to_world`, `near_clip`, `far_clip` (read; strata's
/// rays are unbounded), the film and the sampler.
pub fn sensor<'e>(b: &mut Build<'e>, p: &Props<'e>, projection: Projection) -> Result<(), SceneError> {
    if b.desc.sensor.is_some() {
        return Err(p.elem.at.err("a second <sensor> is not supported (strata renders one camera)"));
    }
    let to_world = p.transform("to_world")?;
    let near_clip = p.float("near_clip", crate::scene::sensor::DEFAULT_NEAR_CLIP)?;
    let far = p.float("far_clip", 1e4)?;
    if !(near_clip > 0.0 && far > near_clip) {
        return Err(p.elem.at.err(format!("need 0 < near_clip ({near_clip}) < far_clip ({far})")));
    }
    p.refuse("shutter_open_time", "motion blur is not supported")?;
    p.refuse("shutter_close", "motion blur is not supported")?;
    p.ignore("id");
    b.desc.sensor = Some(SensorDesc { to_world, projection, near_clip });
    match p.object("film")? {
        Some(f) => b.run_scene(f)?,
        None => {
            return Err(p
                .elem
                .at
                .err("the sensor has no <film> (Mitsuba's default 768x576 gaussian hdrfilm: give it explicitly)"))
        }
    }
    if let Some(s) = p.object("sampler")? {
        b.run_scene(s)?;
    }
    Ok(())
}
