//! Shading frames at hits, as Mitsuba 3 (v3.9) builds them, and its `normalmap` and `bumpmap`
//! wrappers ([`FrameMap`]). [`Scene::gather`] runs this (out of line, cold) only in scenes with
//! tangents (`Scene::tangents`: registry BSDFs or maps), so the course's scenes run none of it.
//!
//! - **Tangent.** Mitsuba's `dp/du`: on a triangle with uvs, from its corner positions and uvs
//!   (`dp/du = (duv1.y dp0 - duv0.y dp1) / det`, `dp/dv = (duv0.x dp1 - duv1.x dp0) / det`,
//!   `dp0 = p1 - p0`, `dp1 = p2 - p0`; a zero determinant falls back to the coordinate system of
//!   the face normal); without uvs the barycentric parameterization (`dp/du = p1 - p0`); on a
//!   sphere `2 pi (-y, x, 0)` in object space. The shading tangent is `dp/du` made orthogonal
//!   to the shading normal (Gram-Schmidt), `t = n x s` (`simd::Frame8::from_normal_tangent`).
//! - **Normal map.** The texture's raw RGB `c` gives `m = 2 c - 1` in the shading frame
//!   (s, t, n); where the viewer is not on the side of `m` it faces in the frame
//!   (`wo.z (wo . m) <= 0`) the tangential part is mirrored (Mitsuba's `flip_invalid_normals`);
//!   the perturbed frame is `n' = normalize(m)`, `s' = normalize(x - n' n'.x)`.
//! - **Bump map.** `g = scale` times the uv gradient of the height texture's luminance;
//!   `dp/du' = dp/du + n (g.u - n . dp/du)` (likewise v), `n' = normalize(dp/du' x dp/dv')`
//!   turned to the face normal's side, taken into the shading frame, flipped as above;
//!   `s' = normalize(dp/du - n' (n' . dp/du))` with `dp/du` in world coordinates (Mitsuba mixes
//!   the two here; for an isotropic BSDF only `n'` matters).
//! - The record gets `n` = the perturbed normal (turned as the geometric one: to face the
//!   ray), `s` = the perturbed tangent, `base_n` = the unperturbed normal and `bump_a2` the
//!   shadowing term's `min(tan^2(n') / 8, 1)`; the BSDF side of the wrappers is
//!   `bsdf::FrameMap8`. The lane is `smooth` (directions must also leave the geometric surface).

use super::build::Scene;
use super::gather::{lanes_of, SurfaceHit8};
use super::texturing::{sphere_uv, triangle_uv};
use crate::accel::{Hits8, GEOM_ELLIPSOIDS, GEOM_SPHERES, GEOM_TRIANGLES};
use crate::scene::desc::FrameMap;
use crate::simd::{frame_from_normal, Vec3x8, F8};
use crate::texture::{TexQuery, NO_TRIANGLE};
use glam::{Mat3, Vec2, Vec3};

/// One hit's differential geometry in Mitsuba's orientation (normals as the mesh declares them).
struct Local {
    /// material index
    material: u32,
    /// unit face normal
    ng: Vec3,
    /// unit shading normal (interpolated vertex normals, else `ng`)
    ns: Vec3,
    dp_du: Vec3,
    dp_dv: Vec3,
    /// the texture query (uv, triangle, barycentrics)
    q: TexQuery,
}

/// `v` normalized, or `fallback` where its length is zero or not finite.
fn normalize_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let l2 = v.length_squared();
    if l2 > 0.0 && l2.is_finite() {
        v / l2.sqrt()
    } else {
        fallback
    }
}

impl Scene {
    /// Whether some material has a normal or bump map.
    #[inline]
    pub fn frame_maps(&self) -> bool {
        !self.material_frame.is_empty()
    }

    /// What the gather adds in scenes with textures or tangents ([`Scene::hit_extras`]): the
    /// textured reflectances, then the tangents and maps.
    #[cold]
    #[inline(never)]
    pub(super) fn extras(&self, bits: u32, hits: &Hits8, out: &mut SurfaceHit8) {
        if !self.material_texture.is_empty() {
            self.texture_hits(bits, hits, out);
        }
        if self.tangents {
            self.frame_hits(bits, hits, out);
        }
    }

    /// The differential geometry of hit lane `i` (None for lights and missed lanes).
    fn local(&self, i: usize, hits: &Hits8, p: Vec3) -> Option<Local> {
        let (k, geom) = (hits.prim.as_array()[i] as usize, hits.geom.as_array()[i]);
        let bary = Vec2::new(hits.u.as_array()[i], hits.v.as_array()[i]);
        match geom {
            GEOM_TRIANGLES => {
                let src = *self.tri_source.get(k)?;
                // A group's triangle (group space, mapped by its instance below) or the scene's.
                let group = self.instances.corners(k).filter(|_| !self.instances.is_empty());
                let v = match group {
                    Some(v) => v,
                    None if src == NO_TRIANGLE => return None,
                    None => self.desc.triangles.get(src as usize)?.v,
                };
                let ng = self.tri_normal[k];
                let corners = self.tri_uv.get(k).filter(|c| **c != [Vec2::ZERO; 3]);
                let uv = triangle_uv(corners, bary.x, bary.y);
                let (dp0, dp1) = (v[1] - v[0], v[2] - v[0]);
                let (dp_du, dp_dv) = match corners {
                    None => (dp0, dp1),
                    Some(c) => {
                        let (duv0, duv1) = (c[1] - c[0], c[2] - c[0]);
                        let det = duv0.x * duv1.y - duv0.y * duv1.x;
                        if det != 0.0 {
                            let inv = 1.0 / det;
                            ((duv1.y * dp0 - duv0.y * dp1) * inv, (duv0.x * dp1 - duv1.x * dp0) * inv)
                        } else {
                            frame_from_normal(ng)
                        }
                    }
                };
                let ns = match self.tri_corner_normals.get(k).filter(|c| c[0] != Vec3::ZERO) {
                    Some(c) => {
                        let (b1, b2) = (bary.x, bary.y);
                        normalize_or(c[0] * (1.0 - b1 - b2) + c[1] * b1 + c[2] * b2, ng)
                    }
                    None => ng,
                };
                let q = TexQuery { uv, tri: src, bary };
                let material = self.tri_material[k];
                if group.is_some() {
                    let (inst, x) = (hits.inst.as_array()[i], &self.instances);
                    let (ng, ns) = (x.normal_of(inst, ng), x.normal_of(inst, ns));
                    let (dp_du, dp_dv) = (x.tangent_of(inst, dp_du), x.tangent_of(inst, dp_dv));
                    return Some(Local { material, ng, ns, dp_du, dp_dv, q });
                }
                Some(Local { material, ng, ns, dp_du, dp_dv, q })
            }
            GEOM_SPHERES | GEOM_ELLIPSOIDS => {
                let table = if geom == GEOM_SPHERES { &self.sphere_point_index } else { &self.ellipsoid_index };
                let e = *table.get(k)? as usize;
                let w2o = self.ell_world_to_object[e];
                let obj = w2o.transform_point3(p);
                let ng = (self.ell_normal[e] * obj).normalize_or_zero();
                // Mitsuba's sphere: dp/du = 2 pi (-y, x, 0), dp/dv = pi (z cos phi, z sin phi, -r).
                let o = obj.normalize_or_zero();
                let rd = (o.x * o.x + o.y * o.y).sqrt();
                let dv = if rd > 0.0 { Vec3::new(o.z * o.x / rd, o.z * o.y / rd, -rd) } else { Vec3::X };
                let to_world = Mat3::from_mat4(w2o).inverse();
                let dp_du = to_world * Vec3::new(-o.y, o.x, 0.0) * std::f32::consts::TAU;
                let dp_dv = to_world * dv * std::f32::consts::PI;
                let q = TexQuery { uv: sphere_uv(obj), tri: NO_TRIANGLE, bary };
                Some(Local { material: self.ell_material[e], ng, ns: ng, dp_du, dp_dv, q })
            }
            _ => None,
        }
    }

    /// Sets the tangents of the hit lanes `bits` and applies the materials' normal and bump
    /// maps (see the module docs).
    fn frame_hits(&self, bits: u32, hits: &Hits8, out: &mut SurfaceHit8) {
        let lanes = |v: Vec3x8| [v.x.to_array(), v.y.to_array(), v.z.to_array()];
        let (mut n, mut s, mut base) = (lanes(out.n), lanes(Vec3x8::ZERO), lanes(out.n));
        let (mut a2, mut smooth) = ([0f32; 8], out.smooth.to_array());
        let set = |a: &mut [[f32; 8]; 3], i: usize, v: Vec3| (a[0][i], a[1][i], a[2][i]) = (v.x, v.y, v.z);
        for i in lanes_of(bits) {
            let Some(l) = self.local(i, hits, out.p.lane(i)) else { continue };
            // The sign that turns Mitsuba's orientation to the record's (facing the ray).
            let sign = if out.ng.lane(i).dot(l.ng) < 0.0 { -1.0 } else { 1.0 };
            let s0 = normalize_or(l.dp_du - l.ns * l.ns.dot(l.dp_du), frame_from_normal(l.ns).0);
            let map = self.material_frame.get(l.material as usize).copied().flatten();
            let Some(map) = map else {
                set(&mut s, i, s0);
                continue;
            };
            let t0 = l.ns.cross(s0);
            let to_local = |w: Vec3| Vec3::new(s0.dot(w), t0.dot(w), l.ns.dot(w));
            let to_world = |v: Vec3| s0 * v.x + t0 * v.y + l.ns * v.z;
            let wo = to_local(out.wo.lane(i));
            // Mitsuba's flip_invalid_normals: keep the viewer on the side the normal faces.
            let flip = |m: Vec3| if wo.z * wo.dot(m) <= 0.0 { Vec3::new(-m.x, -m.y, m.z) } else { m };
            let (nl, sl) = match map {
                FrameMap::Normal { texture } => {
                    let c = self.textures[texture as usize].eval(&l.q);
                    let nl = normalize_or(flip(c * 2.0 - Vec3::ONE), Vec3::Z);
                    (nl, normalize_or(Vec3::X - nl * nl.x, Vec3::Y))
                }
                FrameMap::Bump { texture, scale } => {
                    let g = self.textures[texture as usize].grad_luminance(&l.q).unwrap_or(Vec2::ZERO) * scale;
                    let du = l.dp_du + l.ns * (g.x - l.ns.dot(l.dp_du));
                    let dv = l.dp_dv + l.ns * (g.y - l.ns.dot(l.dp_dv));
                    let nw = normalize_or(du.cross(dv), l.ns);
                    let nw = if l.ng.dot(nw) < 0.0 { -nw } else { nw };
                    let nl = flip(to_local(nw));
                    (nl, normalize_or(l.dp_du - nl * nl.dot(l.dp_du), frame_from_normal(nl).0))
                }
            };
            let cos2 = nl.z * nl.z;
            let tan2 = (1.0 - cos2).max(0.0) / cos2;
            a2[i] = (0.125 * tan2).min(1.0);
            set(&mut n, i, to_world(nl) * sign);
            set(&mut s, i, to_world(sl));
            set(&mut base, i, l.ns * sign);
            smooth[i] = f32::from_bits(u32::MAX);
        }
        let v = |a: [[f32; 8]; 3]| Vec3x8::new(F8::new(a[0]), F8::new(a[1]), F8::new(a[2]));
        out.s = v(s);
        if self.frame_maps() {
            out.n = v(n);
            out.base_n = v(base);
            out.bump_a2 = F8::new(a2);
            out.smooth = F8::new(smooth);
        }
    }
}

#[cfg(test)]
#[path = "perturb_tests.rs"]
mod tests;
