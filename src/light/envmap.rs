//! Mitsuba's `envmap`: a latitude-longitude image at infinity, importance sampled.
//!
//! Radiance (Mitsuba 3's mapping, to be equal to its images): a world direction `w` is taken to
//! the map's frame, `d = to_world^-1 w`, then `u = atan2(d.x, -d.z) / 2 pi - 0.5 / W` (wrapped to
//! [0, 1)) and `v = acos(d.y) / pi`; the radiance is `scale` times the bilinear interpolation of the
//! texels at `x = u W` (columns wrapping around) and `y = v (H - 1)`: texel rows sit on the
//! latitudes `pi j / (H - 1)`, row 0 on the +y pole.
//!
//! Sampling (a 2D marginal/conditional distribution as pbrt-v4's `PiecewiseConstant2D`): the cell
//! between texel columns `i, i + 1` and rows `j, j + 1` gets the mean luminance of its four corner
//! texels times its solid angle `(2 pi / W) (cos th_j - cos th_(j+1))`; a row is drawn from the
//! marginal, a cell from the row's conditional, and a direction uniform in solid angle within the
//! cell (phi uniform, cos(th) uniform). The pdf per solid angle is the cell's probability over its
//! solid angle. Wherever the radiance is non-zero some corner is, so the pdf is positive there:
//! the estimator is unbiased whatever the image.

use super::desc::RgbImage;
use crate::simd::{mask_to_bools, Mask8, Vec3x8, F8};
use glam::{Mat3, Vec3};
use std::f32::consts::{PI, TAU};

/// An environment map ready to evaluate and sample.
#[derive(Clone, Debug)]
pub struct Envmap {
    width: u32,
    /// texel rows (at least 2: a one-row image is repeated)
    height: u32,
    /// texels times scale
    texels: Vec<Vec3>,
    to_world: Mat3,
    from_world: Mat3,
    /// marginal CDF over the `height - 1` cell rows (length height)
    row_cdf: Vec<f32>,
    /// per cell row, the conditional CDF over its `width` cells (each of length width + 1)
    col_cdf: Vec<f32>,
    /// per cell: probability / solid angle (the pdf inside it)
    cell_pdf: Vec<f32>,
}

/// Why an environment map cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EnvmapError {
    /// No texels, or not width x height of them.
    #[error("envmap: the image is empty or its texel count is not width x height")]
    Empty,
    /// A singular or non-finite `to_world`.
    #[error("envmap: to_world is singular or not finite")]
    Singular,
    /// Negative, NaN or infinite texels, or nothing but black.
    #[error("envmap: the image has {0}")]
    Texels(&'static str),
}

/// Mitsuba's luminance of linear RGB.
fn luminance(c: Vec3) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// Running sums of `w` normalized to a CDF (length `w.len() + 1`, from 0 to 1); None if all zero.
fn cdf(w: &[f64]) -> Option<Vec<f32>> {
    let total: f64 = w.iter().sum();
    if total <= 0.0 {
        return None;
    }
    let mut acc = 0.0;
    let mut out = vec![0.0f32];
    for x in w {
        acc += x;
        out.push((acc / total) as f32);
    }
    *out.last_mut().unwrap() = 1.0;
    Some(out)
}

/// The interval of a CDF holding `u`, and `u` remapped to [0, 1) within it.
fn pick(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let i = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
    // Skip empty intervals (u exactly on an edge of a zero-width one).
    let (a, b) = (cdf[i], cdf[i + 1]);
    let t = if b > a { ((u - a) / (b - a)).clamp(0.0, ONE_MINUS) } else { 0.5 };
    (i, t)
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

impl Envmap {
    /// The map of `image` times `scale`, oriented by `to_world` (its linear part).
    pub fn new(image: &RgbImage, scale: f32, to_world: glam::Mat4) -> Result<Self, EnvmapError> {
        let (w, h0) = (image.width, image.height);
        if w == 0 || h0 == 0 || image.texels.len() != (w as usize) * (h0 as usize) {
            return Err(EnvmapError::Empty);
        }
        if image.texels.iter().any(|t| !t.is_finite() || t.min_element() < 0.0) {
            return Err(EnvmapError::Texels("negative or non-finite texels"));
        }
        let m = Mat3::from_mat4(to_world);
        let inv = m.inverse();
        if !(m.determinant().abs() > 0.0) || !inv.is_finite() {
            return Err(EnvmapError::Singular);
        }
        let mut texels: Vec<Vec3> = image.texels.iter().map(|&t| t * scale).collect();
        let h = if h0 == 1 {
            texels.extend_from_within(..);
            2
        } else {
            h0
        };
        let at = |x: u32, y: u32| texels[(y * w + (x % w)) as usize];
        let theta = |j: u32| f64::from(j) * std::f64::consts::PI / f64::from(h - 1);
        let dphi = std::f64::consts::TAU / f64::from(w);
        let mut cell_w = vec![0.0f64; (w * (h - 1)) as usize];
        let mut omega = vec![0.0f64; (h - 1) as usize];
        for j in 0..h - 1 {
            omega[j as usize] = dphi * (theta(j).cos() - theta(j + 1).cos());
            for i in 0..w {
                let l = [at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)].map(luminance);
                // A corner with colour but zero luminance still needs mass.
                let colour =
                    [at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)].iter().any(|c| c.max_element() > 0.0);
                let mean = f64::from(l.iter().map(|x| x.max(0.0)).sum::<f32>()) / 4.0;
                let mean = if colour { mean.max(1e-6) } else { 0.0 };
                cell_w[(j * w + i) as usize] = mean * omega[j as usize];
            }
        }
        let rows: Vec<f64> =
            (0..h - 1).map(|j| cell_w[(j * w) as usize..((j + 1) * w) as usize].iter().sum()).collect();
        let row_cdf = cdf(&rows).ok_or(EnvmapError::Texels("no light (every texel is black)"))?;
        let total: f64 = rows.iter().sum();
        let mut col_cdf = Vec::with_capacity(((h - 1) * (w + 1)) as usize);
        for j in 0..h - 1 {
            let row = &cell_w[(j * w) as usize..((j + 1) * w) as usize];
            col_cdf.extend(cdf(row).unwrap_or_else(|| (0..=w).map(|i| i as f32 / w as f32).collect()));
        }
        let cell_pdf = cell_w
            .iter()
            .enumerate()
            .map(|(k, c)| (c / total / omega[k / w as usize].max(f64::MIN_POSITIVE)) as f32)
            .collect();
        Ok(Self { width: w, height: h, texels, to_world: m, from_world: inv, row_cdf, col_cdf, cell_pdf })
    }

    /// Continuous texel coordinates `(x, y)` (x in [0, W), y in [0, H - 1]) of the world direction `w`.
    #[inline]
    fn coords(&self, w: Vec3) -> (f32, f32) {
        let d = (self.from_world * w).normalize_or_zero();
        let (wf, hf) = (self.width as f32, self.height as f32);
        let mut u = d.x.atan2(-d.z) * (0.5 / PI) - 0.5 / wf;
        u -= u.floor();
        let v = d.y.clamp(-1.0, 1.0).acos() / PI;
        ((u * wf).min(wf * ONE_MINUS), (v * (hf - 1.0)).clamp(0.0, hf - 1.0))
    }

    /// Radiance arriving from the world direction `w` (towards the scene along `-w`).
    pub fn radiance(&self, w: Vec3) -> Vec3 {
        let (x, y) = self.coords(w);
        let (i, j) = (x.floor() as u32, (y.floor() as u32).min(self.height - 2));
        let (tx, ty) = (x - i as f32, y - j as f32);
        let at = |x: u32, y: u32| self.texels[(y * self.width + (x % self.width)) as usize];
        let top = at(i, j) * (1.0 - tx) + at(i + 1, j) * tx;
        let bottom = at(i, j + 1) * (1.0 - tx) + at(i + 1, j + 1) * tx;
        top * (1.0 - ty) + bottom * ty
    }

    /// Solid-angle pdf of [`Envmap::sample`] drawing the world direction `w`.
    pub fn pdf(&self, w: Vec3) -> f32 {
        let (x, y) = self.coords(w);
        let (i, j) = (x.floor() as u32, (y.floor() as u32).min(self.height - 2));
        self.cell_pdf[(j * self.width + i.min(self.width - 1)) as usize]
    }

    /// A world direction for the unit-square sample `(u1, u2)`, with its solid-angle pdf and the
    /// radiance from it; pdf 0 where nothing can be drawn.
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec3, f32, Vec3) {
        let (j, fv) = pick(&self.row_cdf, u1);
        let w1 = self.width as usize + 1;
        let (i, fu) = pick(&self.col_cdf[j * w1..(j + 1) * w1], u2);
        let pdf = self.cell_pdf[j * self.width as usize + i];
        let hf = (self.height - 1) as f32;
        let (c0, c1) = ((PI * j as f32 / hf).cos(), (PI * (j + 1) as f32 / hf).cos());
        let cos_t = (c0 + fv * (c1 - c0)).clamp(-1.0, 1.0);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let u = (i as f32 + fu) / self.width as f32 + 0.5 / self.width as f32;
        let (sp, cp) = (TAU * u).sin_cos();
        let d = Vec3::new(sin_t * sp, cos_t, -sin_t * cp);
        let w = (self.to_world * d).normalize_or_zero();
        (w, pdf, self.radiance(w))
    }

    /// [`Envmap::sample`] per lane (bit-identical to it); zero on inactive lanes.
    pub fn sample_x8(&self, u1: F8, u2: F8, active: Mask8) -> (Vec3x8, F8, Vec3x8) {
        let (on, a, b) = (mask_to_bools(active), u1.to_array(), u2.to_array());
        let s: [(Vec3, f32, Vec3); 8] =
            std::array::from_fn(|i| if on[i] { self.sample(a[i], b[i]) } else { (Vec3::ZERO, 0.0, Vec3::ZERO) });
        (Vec3x8::from_lanes(s.map(|x| x.0)), F8::new(s.map(|x| x.1)), Vec3x8::from_lanes(s.map(|x| x.2)))
    }

    /// [`Envmap::radiance`] and [`Envmap::pdf`] of the world directions `w` on `active` lanes.
    pub fn radiance_pdf_x8(&self, w: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let on = mask_to_bools(active);
        let r: [(Vec3, f32); 8] = std::array::from_fn(|i| {
            if on[i] {
                let d = w.lane(i);
                (self.radiance(d), self.pdf(d))
            } else {
                (Vec3::ZERO, 0.0)
            }
        });
        (Vec3x8::from_lanes(r.map(|x| x.0)), F8::new(r.map(|x| x.1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{chi2_test, Grid};
    use crate::simd::mask_all;

    /// A 16 x 9 map with a bright spot, a dark band and colour, rotated.
    fn map() -> Envmap {
        let (w, h) = (16u32, 9u32);
        let texels = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| {
                    let base = Vec3::new(0.2 + 0.05 * x as f32, 0.1 * y as f32, 0.3);
                    if (x, y) == (5, 3) {
                        Vec3::splat(40.0)
                    } else if y == 6 {
                        Vec3::ZERO
                    } else {
                        base
                    }
                })
            })
            .collect();
        let rot = glam::Mat4::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.8);
        Envmap::new(&RgbImage { width: w, height: h, texels }, 1.5, rot).unwrap()
    }

    #[test]
    fn envmap_sampling_matches_its_pdf_chi_square() {
        let e = map();
        chi2_test(
            "envmap",
            &Grid::uniform(40, 80),
            0x656e_766d,
            |r| {
                let [a, b] = r.u2();
                let (w, pdf, _) = e.sample(a, b);
                assert!(pdf > 0.0);
                w
            },
            |w| f64::from(e.pdf(w)),
        );
    }

    #[test]
    fn sampled_pdf_and_radiance_agree_with_the_lookups_and_x8() {
        let e = map();
        let mut rng = crate::sampling::chi2::Rng::new(3);
        let us: [[f32; 2]; 8] = std::array::from_fn(|_| rng.u2());
        let (w8, p8, l8) = e.sample_x8(F8::new(us.map(|u| u[0])), F8::new(us.map(|u| u[1])), mask_all());
        for (i, u) in us.iter().enumerate() {
            let (w, p, l) = e.sample(u[0], u[1]);
            assert_eq!((w8.lane(i), p8.to_array()[i], l8.lane(i)), (w, p, l));
            assert!((e.pdf(w) - p).abs() <= 1e-3 * p, "{} vs {p}", e.pdf(w));
            assert_eq!(e.radiance(w), l);
        }
    }

    #[test]
    fn radiance_follows_mitsubas_latitude_longitude_mapping() {
        // Identity frame, scale 2: the +y pole is row 0; texel column i sits at
        // phi = 2 pi (i + 0.5) / W (phi = atan2(d.x, -d.z)), so -z (phi = 0) is half way between
        // the last column and the first.
        let texels: Vec<Vec3> = (0..3).flat_map(|y| (0..4).map(move |x| Vec3::new(x as f32, y as f32, 1.0))).collect();
        let e = Envmap::new(&RgbImage { width: 4, height: 3, texels }, 2.0, glam::Mat4::IDENTITY).unwrap();
        let close = |a: Vec3, b: Vec3| assert!((a - b).length() < 1e-5, "{a} vs {b}");
        // (At the poles the column depends on the sign of zero in atan2, as in Mitsuba.)
        assert_eq!(glam::Vec3Swizzles::yz(e.radiance(Vec3::Y)), glam::Vec2::new(0.0, 2.0));
        assert_eq!(glam::Vec3Swizzles::yz(e.radiance(Vec3::NEG_Y)), glam::Vec2::new(4.0, 2.0));
        close(e.radiance(Vec3::NEG_Z), Vec3::new(3.0, 2.0, 2.0));
        let s = std::f32::consts::FRAC_1_SQRT_2;
        close(e.radiance(Vec3::new(s, 0.0, -s)), Vec3::new(0.0, 2.0, 2.0));
        close(e.radiance(Vec3::X), Vec3::new(1.0, 2.0, 2.0));
        // Refusals.
        let bad = RgbImage { width: 1, height: 1, texels: vec![Vec3::new(-1.0, 0.0, 0.0)] };
        assert!(Envmap::new(&bad, 1.0, glam::Mat4::IDENTITY).is_err());
        let black = RgbImage { width: 1, height: 1, texels: vec![Vec3::ZERO] };
        assert_eq!(
            Envmap::new(&black, 1.0, glam::Mat4::IDENTITY).unwrap_err(),
            EnvmapError::Texels("no light (every texel is black)")
        );
    }
}
