//! `<sensor type="perspective">`: `to_world` (a rigid motion: Mitsuba's look-at frame), `fov` and
//! `fov_axis` (x, y, diagonal, smaller, larger) or `focal_length`, `near_clip`/`far_clip`; its
//! nested `film` and `sampler`.

use super::{Build, Plugin, Run};
use crate::scene::desc::CameraDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::doc::Loc;
use crate::scene::xml::props::Props;
use glam::{Mat4, Vec3};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "sensor", kind: "perspective", run: Run::Scene(run) };

/// The field of view as given, resolved once the film's size is known.
pub struct Pending {
    fov_deg: f32,
    axis: String,
    to_world: Mat4,
    at: Loc,
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    if b.pending_camera.is_some() || b.desc.camera.is_some() {
        return Err(p.elem.at.err("a second <sensor> is not supported (strata renders one camera)"));
    }
    let fov_deg = match (p.has("fov"), p.string("focal_length")?) {
        (true, Some(_)) => return Err(p.elem.at.err("give `fov` or `focal_length`, not both")),
        (true, None) => p.float("fov", 0.0)?,
        (false, f) => {
            // Mitsuba's default is 50mm on a 36mm-wide frame, along x.
            let f = f.unwrap_or("50mm");
            let mm: f32 = f
                .trim()
                .trim_end_matches("mm")
                .parse()
                .map_err(|_| p.elem.at.err(format!("focal_length \"{f}\" is not like \"50mm\"")))?;
            if !(mm > 0.0) {
                return Err(p.elem.at.err(format!("focal_length \"{f}\" must be positive")));
            }
            2.0 * (36.0 / (2.0 * mm)).atan().to_degrees()
        }
    };
    if !(fov_deg > 0.0 && fov_deg < 180.0) {
        return Err(p.elem.at.err(format!("fov {fov_deg} must be in (0, 180) degrees")));
    }
    let axis = p.string("fov_axis")?.unwrap_or("x").to_string();
    if !["x", "y", "diagonal", "smaller", "larger"].contains(&axis.as_str()) {
        return Err(p.elem.at.err(format!("fov_axis \"{axis}\" is not one of x, y, diagonal, smaller, larger")));
    }
    let to_world = p.transform("to_world")?;
    let l = glam::Mat3::from_mat4(to_world);
    let ortho = (l.transpose() * l - glam::Mat3::IDENTITY).to_cols_array().iter().all(|x| x.abs() < 1e-3);
    if !ortho || l.determinant() < 0.0 {
        return Err(p.elem.at.err("a perspective sensor's to_world must be a rotation and translation (a <lookat>); scaling or mirroring it is not supported"));
    }
    let near = p.float("near_clip", 0.01)?;
    p.float("far_clip", 1e4)?;
    if near > 0.01 {
        b.warn(&p.elem.at, format!("near_clip {near} is not applied: strata starts camera rays at the eye (same image unless geometry lies within {near} of it)"));
    }
    p.refuse("principal_point_offset_x", "off-centre projections are not supported")?;
    p.refuse("principal_point_offset_y", "off-centre projections are not supported")?;
    p.refuse("shutter_open_time", "motion blur is not supported")?;
    b.pending_camera = Some(Pending { fov_deg, axis, to_world, at: p.elem.at.clone() });
    if let Some(f) = p.object("film")? {
        b.run_scene(f)?;
    }
    if let Some(s) = p.object("sampler")? {
        b.run_scene(s)?;
    }
    p.ignore("id");
    resolve(b);
    Ok(())
}

/// Turns the pending field of view into strata's camera (eye, look-at point, up, vertical fov)
/// for the film's aspect ratio.
pub fn resolve(b: &mut Build) {
    let Some(pc) = b.pending_camera.take() else { return };
    let _ = &pc.at;
    let (w, h) = (b.desc.width as f32, b.desc.height as f32);
    let aspect = w / h;
    let t = (pc.fov_deg.to_radians() * 0.5).tan();
    let ty = match pc.axis.as_str() {
        "x" => t / aspect,
        "y" => t,
        "diagonal" => t * h / (w * w + h * h).sqrt(),
        "smaller" if w < h => t / aspect,
        "smaller" => t,
        "larger" if w > h => t / aspect,
        _ => t,
    };
    let m = pc.to_world;
    let eye = m.transform_point3(Vec3::ZERO);
    let dir = m.transform_vector3(Vec3::Z).normalize();
    let up = m.transform_vector3(Vec3::Y).normalize();
    b.desc.camera = Some(CameraDesc { eye, center: eye + dir, up, fovy_deg: 2.0 * ty.atan().to_degrees() });
}
