//! The camera of a built scene ([`Camera`]): the `.test` look-at pinhole, or a Mitsuba sensor
//! ([`Lens`]: `perspective`, `orthographic`, from [`SensorDesc`]), with its crop window; its rays
//! of a packet and of one pixel point. `scene::build` makes it for [`super::build::Scene`] and
//! re-exports it, so `scene::build::Camera` still names it.

use crate::scene::desc::{CameraDesc, FilmCrop, Projection, SensorDesc};
use crate::scene::pinhole::Pinhole8;
use crate::simd::{Vec3x8, F8};
use glam::Vec3;

/// The camera: the `.test` look-at pinhole (full vertical field of view), or a Mitsuba sensor
/// ([`Lens`]), with the pixel filter's jitter warp.
#[derive(Clone, Debug)]
pub struct Camera {
    /// eye position
    pub eye: Vec3,
    /// unit view direction
    pub look: Vec3,
    /// unit right vector (look x up)
    pub right: Vec3,
    /// unit up vector (right x look)
    pub up: Vec3,
    /// image plane distance 1/tan(fovy/2) (half-height 1)
    pub plane_dist: f32,
    /// image width in pixels
    pub width: u32,
    /// image height in pixels
    pub height: u32,
    /// the lens: the look-at pinhole above, or a Mitsuba sensor
    pub lens: Lens,
    /// the pixel filter's jitter warp, None for the box filter (uniform jitter)
    pub filter: Option<crate::sampling::filter::FilterWarp>,
}

/// How image positions become rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lens {
    /// the `.test` look-at pinhole ([`Camera::dirs8`], every ray from `eye`)
    Pinhole,
    /// Mitsuba `perspective`: the direction through image position (x, y) is
    /// `base + ax (2x/W - 1) + ay (2y/H - 1)` (world space, camera z = 1), the ray starts at
    /// `origin + near * direction`
    Perspective {
        /// the pinhole
        origin: Vec3,
        /// `to_world` applied to camera +z
        base: Vec3,
        /// world vector per unit of `2x/W - 1`
        ax: Vec3,
        /// world vector per unit of `2y/H - 1`
        ay: Vec3,
        /// near clip distance along camera z
        near: f32,
    },
    /// Mitsuba `orthographic`: rays along `dir` from `centre + ax (2x/W - 1) + ay (2y/H - 1)`
    Orthographic {
        /// `to_world` applied to camera (0, 0, near)
        centre: Vec3,
        /// unit direction, `to_world` applied to camera +z
        dir: Vec3,
        /// world vector per unit of `2x/W - 1`
        ax: Vec3,
        /// world vector per unit of `2y/H - 1`
        ay: Vec3,
    },
}

impl Camera {
    /// Camera of a Mitsuba sensor for a `width` x `height` image (see `scene::sensor` for the
    /// conventions: image x runs along camera -x, image y along camera -y).
    pub fn from_sensor(s: &SensorDesc, width: u32, height: u32) -> Self {
        let aspect = width as f64 / height as f64;
        let m = s.to_world;
        let (cx, cy, cz) = (m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate());
        let lens = match s.projection {
            Projection::Perspective { fov_deg, fov_axis } => {
                let fov_x = fov_axis.fov_x_deg(f64::from(fov_deg), aspect);
                let tx = (fov_x.to_radians() * 0.5).tan();
                let ty = tx / aspect;
                Lens::Perspective {
                    origin: m.w_axis.truncate(),
                    base: cz,
                    ax: -cx * tx as f32,
                    ay: -cy * ty as f32,
                    near: s.near_clip,
                }
            }
            Projection::Orthographic => Lens::Orthographic {
                centre: m.transform_point3(Vec3::new(0.0, 0.0, s.near_clip)),
                dir: cz.normalize_or(Vec3::Z),
                ax: -cx,
                ay: -cy / aspect as f32,
            },
        };
        let eye = m.w_axis.truncate();
        let look = cz.normalize_or(Vec3::Z);
        Self { eye, look, right: -cx, up: cy, plane_dist: 1.0, width, height, lens, filter: None }
    }

    /// This full-frame sensor camera restricted to the `width` x `height` window of `crop`: image
    /// position (x, y) of the window makes the ray of (x + crop.x, y + crop.y) in the full frame
    /// (the lens' affine map rescaled, so the ray code is the same). A pinhole is left as is.
    pub fn cropped(mut self, crop: FilmCrop, width: u32, height: u32) -> Self {
        // 2 (x + ox) / W - 1 = (w / W) (2 x / w - 1) + (w + 2 ox) / W - 1, likewise for y.
        let (sx, tx) = (width as f32 / self.width as f32, (width + 2 * crop.x) as f32 / self.width as f32 - 1.0);
        let (sy, ty) = (height as f32 / self.height as f32, (height + 2 * crop.y) as f32 / self.height as f32 - 1.0);
        match &mut self.lens {
            Lens::Pinhole => return self,
            Lens::Perspective { base: c, ax, ay, .. } | Lens::Orthographic { centre: c, ax, ay, .. } => {
                *c += *ax * tx + *ay * ty;
                *ax *= sx;
                *ay *= sy;
            }
        }
        self.width = width;
        self.height = height;
        self
    }

    /// The camera's rays (origins, unit directions) through image positions (x, y) in pixels,
    /// y down: the pinhole's [`Camera::dirs8`] from `eye`, or the Mitsuba sensor's.
    #[inline]
    pub fn rays8(&self, x: F8, y: F8) -> (Vec3x8, Vec3x8) {
        let (w, h) = (self.width as f32, self.height as f32);
        let s = || (x * F8::splat(2.0 / w) - F8::ONE, y * F8::splat(2.0 / h) - F8::ONE);
        match self.lens {
            Lens::Pinhole => (Vec3x8::splat(self.eye), self.dirs8(x, y)),
            Lens::Perspective { origin, base, ax, ay, near } => {
                let (sx, sy) = s();
                let d = Vec3x8::splat(ay).mul_add(sy, Vec3x8::splat(ax).mul_add(sx, Vec3x8::splat(base)));
                (d.mul_add(F8::splat(near), Vec3x8::splat(origin)), d.normalize_or_zero())
            }
            Lens::Orthographic { centre, dir, ax, ay } => {
                let (sx, sy) = s();
                let o = Vec3x8::splat(ay).mul_add(sy, Vec3x8::splat(ax).mul_add(sx, Vec3x8::splat(centre)));
                (o, Vec3x8::splat(dir))
            }
        }
    }

    /// Scalar twin of [`Camera::rays8`] (the same operations, fused alike, so the same bits per
    /// lane).
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        use crate::sampling::{mul_add3, normalize_or_zero};
        let (w, h) = (self.width as f32, self.height as f32);
        let sx = x * (2.0 / w) - 1.0;
        let sy = y * (2.0 / h) - 1.0;
        match self.lens {
            Lens::Pinhole => (self.eye, self.dir(x, y)),
            Lens::Perspective { origin, base, ax, ay, near } => {
                let d = mul_add3(ay, sy, mul_add3(ax, sx, base));
                (mul_add3(d, near, origin), normalize_or_zero(d))
            }
            Lens::Orthographic { centre, dir, ax, ay } => (mul_add3(ay, sy, mul_add3(ax, sx, centre)), dir),
        }
    }

    /// Camera of `desc` for a `width` x `height` image.
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Self {
        let look = (desc.center - desc.eye).normalize_or(Vec3::NEG_Z);
        let mut right = look.cross(desc.up).normalize_or_zero();
        if right == Vec3::ZERO {
            // Up parallel to the view: pick any perpendicular (the parser refuses this; be safe).
            right = look.any_orthonormal_vector();
        }
        let up = right.cross(look);
        let half = (desc.fovy_deg.to_radians() * 0.5).tan().max(1e-6);
        Self {
            eye: desc.eye,
            look,
            right,
            up,
            plane_dist: 1.0 / half,
            width,
            height,
            lens: Lens::Pinhole,
            filter: None,
        }
    }

    /// Unnormalized-then-normalized directions through image positions (x, y) in pixels, y down.
    #[inline]
    pub fn dirs8(&self, x: F8, y: F8) -> Vec3x8 {
        self.pinhole().dirs8(x, y)
    }

    /// The pinhole's per-image constants, splatted once for many packets ([`Pinhole8::dirs8`]
    /// is [`Camera::dirs8`] bit for bit).
    pub fn pinhole(&self) -> Pinhole8 {
        Pinhole8::new(self.eye, self.look * self.plane_dist, self.right, self.up, self.width, self.height)
    }

    /// Scalar twin of [`Camera::dirs8`].
    pub fn dir(&self, x: f32, y: f32) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let sx = (x * (2.0 / w) - 1.0) * (w / h);
        let sy = 1.0 - y * (2.0 / h);
        (self.look * self.plane_dist + self.right * sx + self.up * sy).normalize_or_zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::CameraDesc;
    use glam::Mat4;

    #[test]
    fn camera_dirs_x8_match_scalar_per_lane() {
        let desc =
            CameraDesc { eye: Vec3::new(0.1, 1.0, 3.0), center: Vec3::new(0.0, 1.0, 0.0), up: Vec3::Y, fovy_deg: 45.0 };
        let cam = Camera::new(&desc, 640, 480);
        let xs = [0.0, 0.5, 639.99, 320.0, 100.25, 7.0, 500.5, 320.5];
        let ys = [0.0, 479.99, 0.5, 240.0, 13.75, 400.0, 99.0, 240.5];
        let d = cam.dirs8(F8::new(xs), F8::new(ys));
        for i in 0..8 {
            assert!((d.lane(i) - cam.dir(xs[i], ys[i])).length() < 1e-6, "lane {i}");
        }
        // The image centre looks along the view direction; the top edge is fovy/2 above it.
        assert!((cam.dir(320.0, 240.0) - cam.look).length() < 1e-6);
        let top = cam.dir(320.0, 0.0);
        assert!((top.dot(cam.look).acos().to_degrees() - 22.5).abs() < 1e-3);
        assert!(top.dot(cam.up) > 0.0, "y grows downwards in the image");
        assert!(cam.dir(639.0, 240.0).dot(cam.right) > 0.0, "x grows to the right");
    }

    /// Mitsuba's `lookat`: columns (left, up, dir, origin) with left = normalize(up x dir).
    fn lookat(origin: Vec3, target: Vec3, up: Vec3) -> Mat4 {
        let dir = (target - origin).normalize();
        let left = up.normalize().cross(dir).normalize();
        let new_up = dir.cross(left);
        Mat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0))
    }

    /// A crop window's camera makes the full frame's rays at the offset pixels, for both lenses.
    #[test]
    fn cropped_camera_makes_the_full_frames_rays() {
        use crate::scene::desc::{FilmCrop, FovAxis, Projection, SensorDesc};
        let m = lookat(Vec3::new(0.3, 1.0, 5.0), Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
        for projection in [Projection::Perspective { fov_deg: 40.0, fov_axis: FovAxis::X }, Projection::Orthographic] {
            let s = SensorDesc { to_world: m, projection, near_clip: 0.5 };
            let full = Camera::from_sensor(&s, 200, 100);
            let crop = FilmCrop { full_width: 200, full_height: 100, x: 30, y: 20 };
            let cam = Camera::from_sensor(&s, 200, 100).cropped(crop, 50, 40);
            assert_eq!((cam.width, cam.height), (50, 40));
            for (x, y) in [(0.0, 0.0), (50.0, 40.0), (12.25, 33.5), (49.9, 0.1)] {
                let (o, d) = cam.ray(x, y);
                let (fo, fd) = full.ray(x + 30.0, y + 20.0);
                assert!(
                    (o - fo).length() < 1e-5 && (d - fd).length() < 1e-6,
                    "{projection:?} ({x}, {y}): {o} {d} vs {fo} {fd}"
                );
                let (o8, d8) = cam.rays8(crate::simd::F8::splat(x), crate::simd::F8::splat(y));
                assert_eq!((o8.lane(3), d8.lane(3)), (o, d), "x8 and scalar agree");
            }
        }
    }

    #[test]
    fn mitsuba_perspective_looks_along_z_with_image_x_to_the_right() {
        use crate::scene::desc::{FovAxis, Projection, SensorDesc};
        let m = lookat(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
        let s = SensorDesc {
            to_world: m,
            projection: Projection::Perspective { fov_deg: 40.0, fov_axis: FovAxis::X },
            near_clip: 0.5,
        };
        let cam = Camera::from_sensor(&s, 200, 100);
        let (o, d) = cam.ray(100.0, 50.0);
        assert!((d - Vec3::NEG_Z).length() < 1e-6, "{d}");
        assert!((o - Vec3::new(0.0, 1.0, 4.5)).length() < 1e-5, "near clip: {o}");
        // Looking down -z with y up, image right is world +x, image down world -y.
        let (_, right) = cam.ray(199.0, 50.0);
        let (_, top) = cam.ray(100.0, 0.0);
        assert!(right.x > 0.0 && top.y > 0.0, "{right} {top}");
        // fov along x: the left and right edges are 20 degrees off the axis.
        let (_, edge) = cam.ray(200.0, 50.0);
        assert!((edge.dot(d).acos().to_degrees() - 20.0).abs() < 1e-3);
        // The same field of view measured along y, for this 2:1 image.
        let y = FovAxis::Y.fov_x_deg(40.0, 2.0);
        let want = 2.0 * (20f64.to_radians().tan() * 2.0).atan().to_degrees();
        assert!((y - want).abs() < 1e-9);
        assert_eq!(FovAxis::Smaller.fov_x_deg(40.0, 2.0), y);
        assert_eq!(FovAxis::Larger.fov_x_deg(40.0, 2.0), 40.0);
        assert_eq!(FovAxis::Smaller.fov_x_deg(40.0, 0.5), 40.0);
        let diag = FovAxis::Diagonal.fov_x_deg(40.0, 1.0);
        assert!((diag - 2.0 * (20f64.to_radians().tan() / 2f64.sqrt()).atan().to_degrees()).abs() < 1e-9);
        // x8 equals scalar per lane, bit for bit.
        let xs = [0.0, 0.5, 199.99, 100.0, 10.25, 7.0, 150.5, 33.3];
        let ys = [0.0, 99.99, 0.5, 50.0, 13.75, 40.0, 99.0, 3.5];
        let (o8, d8) = cam.rays8(F8::new(xs), F8::new(ys));
        for (i, (&x, &y)) in xs.iter().zip(&ys).enumerate() {
            let (o, d) = cam.ray(x, y);
            assert_eq!(o8.lane(i).to_array().map(f32::to_bits), o.to_array().map(f32::to_bits), "lane {i}");
            assert_eq!(d8.lane(i).to_array().map(f32::to_bits), d.to_array().map(f32::to_bits), "lane {i}");
        }
    }

    #[test]
    fn mitsuba_orthographic_view_is_to_worlds_scaled_unit_square() {
        use crate::scene::desc::{Projection, SensorDesc};
        let m = lookat(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y) * Mat4::from_scale(Vec3::new(2.0, 2.0, 1.0));
        let s = SensorDesc { to_world: m, projection: Projection::Orthographic, near_clip: 0.25 };
        let cam = Camera::from_sensor(&s, 64, 32);
        let (o, d) = cam.ray(32.0, 16.0);
        assert!((d - Vec3::NEG_Z).length() < 1e-6 && (o - Vec3::new(0.0, 0.0, 2.75)).length() < 1e-6, "{o} {d}");
        // Half-extent 2 along x, 2 / aspect = 1 along y; image right is +x, image top +y.
        let (o, _) = cam.ray(64.0, 0.0);
        assert!((o - Vec3::new(2.0, 1.0, 2.75)).length() < 1e-5, "{o}");
        let xs = [0.0, 0.5, 63.99, 32.0, 10.25, 7.0, 50.5, 33.3];
        let (o8, d8) = cam.rays8(F8::new(xs), F8::new(xs.map(|x| x * 0.5)));
        for (i, &x) in xs.iter().enumerate() {
            let (o, d) = cam.ray(x, x * 0.5);
            assert_eq!(o8.lane(i).to_array().map(f32::to_bits), o.to_array().map(f32::to_bits), "lane {i}");
            assert_eq!(d8.lane(i), d);
        }
    }
}
