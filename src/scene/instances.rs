//! Mitsuba's `shapegroup` + `instance` as Embree instances: each group's triangles are stored
//! once (one child BVH, one run of the scene's per-triangle tables in group space) and each
//! instance is an Embree instance of it. A hit on an instance reports the group's triangle and the
//! instance's id; [`Instances::remap`] turns the triangle into its scene index, and the gather
//! maps the group-space normals and tangents to world space with the instance's matrices.

use super::desc::SceneDesc;
use crate::accel::{AccelError, Hits8, SceneBuilder, GEOM_FIRST_INSTANCE, INVALID_ID};
use crate::simd::U8;
use glam::{Mat3, Vec2, Vec3};

/// The instances of a built scene and their groups' stored triangles.
#[derive(Debug, Default)]
pub struct Instances {
    /// per instance (its Embree id minus `GEOM_FIRST_INSTANCE`): the scene index of its group's
    /// first triangle
    pub first: Vec<u32>,
    /// per instance: the linear part of its `to_world` (maps tangents)
    pub linear: Vec<Mat3>,
    /// per instance: the inverse transpose of `linear` (maps normals)
    pub normal: Vec<Mat3>,
    /// scene index of the first group triangle (the groups' triangles come after every other)
    pub base: u32,
    /// per stored group triangle (scene index minus `base`): its group-space corners
    pub tri_v: Vec<[Vec3; 3]>,
}

/// A group's stored triangles in the scene's per-triangle table layout, before the build appends
/// them (every table has one entry per triangle; normals and uvs only when some triangle has them).
#[derive(Debug, Default)]
pub struct GroupTables {
    /// material per triangle
    pub material: Vec<u32>,
    /// unit geometric normal per triangle, group space
    pub normal: Vec<Vec3>,
    /// per-corner shading normals (zero: none), group space
    pub corner_normals: Vec<[Vec3; 3]>,
    /// per-corner uvs (zero: none)
    pub uvs: Vec<[Vec2; 3]>,
    /// zero-area triangles dropped (never hit)
    pub dropped: usize,
}

impl Instances {
    /// Whether the scene has no instances (the gather then skips every instance path).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.first.is_empty()
    }

    /// Stores the groups of `desc` as scene triangles from `base` on (returning their tables),
    /// builds one Embree child scene per group and adds every instance to `b`. Zero-area
    /// triangles are dropped, as for the world mesh. Also returns the world bounds of the
    /// instances' triangles (`lo`, `hi`; infinite when there are none).
    pub fn build(
        desc: &SceneDesc,
        base: u32,
        b: &mut SceneBuilder<'_>,
    ) -> Result<(Self, GroupTables, Vec3, Vec3), AccelError> {
        let mut me = Self { base, ..Self::default() };
        let mut t = GroupTables::default();
        let (mut group_first, mut group_ids, mut group_bounds) = (Vec::new(), Vec::new(), Vec::new());
        let has_normals = desc.groups.iter().any(|g| !g.triangle_normals.is_empty());
        let has_uvs = desc.groups.iter().any(|g| !g.triangle_uvs.is_empty());
        for g in &desc.groups {
            group_first.push(base + me.tri_v.len() as u32);
            let (mut vertices, mut indices) = (Vec::new(), Vec::new());
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for (k, tri) in g.triangles.iter().enumerate() {
                let n = (tri.v[1] - tri.v[0]).cross(tri.v[2] - tri.v[0]).normalize_or_zero();
                if n == Vec3::ZERO || !tri.v.iter().all(|v| v.is_finite()) {
                    t.dropped += 1;
                    continue;
                }
                let b0 = vertices.len() as u32;
                vertices.extend_from_slice(&tri.v);
                indices.push([b0, b0 + 1, b0 + 2]);
                tri.v.iter().for_each(|&v| (lo, hi) = (lo.min(v), hi.max(v)));
                me.tri_v.push(tri.v);
                t.material.push(tri.material);
                t.normal.push(n);
                if has_normals {
                    t.corner_normals.push(g.triangle_normals.get(k).copied().unwrap_or([Vec3::ZERO; 3]));
                }
                if has_uvs {
                    t.uvs.push(g.triangle_uvs.get(k).copied().unwrap_or([Vec2::ZERO; 3]));
                }
            }
            group_ids.push(b.add_group(&vertices, &indices)?);
            group_bounds.push((lo, hi));
        }
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for inst in &desc.instances {
            let g = inst.group as usize;
            let (Some(&id), Some(&first)) = (group_ids.get(g), group_first.get(g)) else {
                return Err(AccelError(format!("instance of unknown shapegroup {g}")));
            };
            b.add_instance(id, &inst.to_world)?;
            let linear = Mat3::from_mat4(inst.to_world);
            me.first.push(first);
            me.linear.push(linear);
            me.normal.push(linear.inverse().transpose());
            let (glo, ghi) = group_bounds[g];
            if glo.x.is_finite() {
                for c in 0..8 {
                    let corner = Vec3::new(
                        if c & 1 == 0 { glo.x } else { ghi.x },
                        if c & 2 == 0 { glo.y } else { ghi.y },
                        if c & 4 == 0 { glo.z } else { ghi.z },
                    );
                    let w = inst.to_world.transform_point3(corner);
                    (lo, hi) = (lo.min(w), hi.max(w));
                }
            }
        }
        Ok((me, t, lo, hi))
    }

    /// `hits` with each instance lane's primitive turned into its scene triangle index.
    #[inline(never)]
    pub fn remap(&self, hits: &Hits8) -> Hits8 {
        let (inst, mut prim) = (hits.inst.to_array(), hits.prim.to_array());
        for i in 0..8 {
            if inst[i] != INVALID_ID {
                let k = inst[i].wrapping_sub(GEOM_FIRST_INSTANCE) as usize;
                prim[i] = prim[i].wrapping_add(self.first.get(k).copied().unwrap_or(0));
            }
        }
        Hits8 { prim: U8::new(prim), ..*hits }
    }

    /// The world-space unit normal of group-space normal `n` on instance `inst` (Embree id).
    #[inline(never)]
    pub fn normal_of(&self, inst: u32, n: Vec3) -> Vec3 {
        let k = inst.wrapping_sub(GEOM_FIRST_INSTANCE) as usize;
        self.normal.get(k).map_or(n, |m| (*m * n).normalize_or_zero())
    }

    /// The world-space tangent of group-space tangent `v` on instance `inst` (Embree id).
    #[inline]
    pub fn tangent_of(&self, inst: u32, v: Vec3) -> Vec3 {
        let k = inst.wrapping_sub(GEOM_FIRST_INSTANCE) as usize;
        self.linear.get(k).map_or(v, |m| *m * v)
    }

    /// The group-space corners of scene triangle `k`, if it is a stored group triangle.
    #[inline]
    pub fn corners(&self, k: usize) -> Option<[Vec3; 3]> {
        k.checked_sub(self.base as usize).and_then(|j| self.tri_v.get(j)).copied()
    }
}
