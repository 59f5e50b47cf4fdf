//! Building an Embree scene (geometry in the id order of the module docs), the committed scene, its
//! 8-wide closest-hit and any-hit queries, and their results in SoA form ([`Hits8`]).

use super::device::{AccelError, Device};
use super::ellipsoid::Ellipsoid;
use super::ffi::{
    finite_ray, query_args, QueryArgs, Ray8, RayHit1, RayHit16, RayHit8, RayQueryContext, Valid16, Valid8,
};
use super::user_geometry::{ellipsoid_bounds, ellipsoid_intersect, ellipsoid_occluded};
use super::{GEOM_ELLIPSOIDS, GEOM_FIRST_INSTANCE, GEOM_SPHERES, GEOM_TRIANGLES, INVALID_ID};
use crate::simd::{mask_to_valid, Mask8, F8, U8};
use embree4_sys as sys;
use glam::{Mat4, Vec3, Vec4};
use std::ffi::c_void;

/// Builds a scene: add geometry in the documented id order, then [`SceneBuilder::commit`].
pub struct SceneBuilder<'d> {
    device: &'d Device,
    scene: sys::RTCScene,
    children: Vec<sys::RTCScene>,
    // Boxed: Embree holds a pointer to each Vec (its header), which must not move as this Vec grows.
    #[allow(clippy::vec_box)]
    user_data: Vec<Box<Vec<Ellipsoid>>>,
    next_id: u32,
    quality: sys::RTCBuildQuality,
}

/// A child scene of a [`SceneBuilder`] (a shapegroup's triangles), placed by its instances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GroupId(usize);

/// A committed Embree scene, safe to query from many threads.
pub struct Scene {
    raw: sys::RTCScene,
    children: Vec<sys::RTCScene>,
    // Read by the ellipsoid callbacks; dropped after `raw` is released (see Drop).
    #[allow(clippy::vec_box)]
    _user_data: Vec<Box<Vec<Ellipsoid>>>,
}

// SAFETY: a committed RTCScene is immutable and Embree documents concurrent rtcIntersect*/rtcOccluded*
// calls on it as thread-safe; we never modify it after commit.
unsafe impl Send for Scene {}
// SAFETY: as above.
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: each handle was created by rtcNewScene and is released exactly once, parents first.
        unsafe {
            sys::rtcReleaseScene(self.raw);
            for c in &self.children {
                sys::rtcReleaseScene(*c);
            }
        }
    }
}

impl Drop for SceneBuilder<'_> {
    fn drop(&mut self) {
        if !self.scene.is_null() {
            // SAFETY: an uncommitted builder owns its handles; release each once.
            unsafe {
                sys::rtcReleaseScene(self.scene);
                for c in &self.children {
                    sys::rtcReleaseScene(*c);
                }
            }
        }
    }
}

/// Row-major 3x4 affine part of a column-major `Mat4`, as Embree's FLOAT3X4_COLUMN_MAJOR wants.
fn affine_3x4_column_major(m: &Mat4) -> [f32; 12] {
    let c = m.to_cols_array();
    [c[0], c[1], c[2], c[4], c[5], c[6], c[8], c[9], c[10], c[12], c[13], c[14]]
}

impl<'d> SceneBuilder<'d> {
    /// Starts an empty scene on `device`.
    pub fn new(device: &'d Device) -> Result<Self, AccelError> {
        // SAFETY: live device handle.
        let scene = unsafe { sys::rtcNewScene(device.raw) };
        device.take_errors()?;
        Ok(Self {
            device,
            scene,
            children: Vec::new(),
            user_data: Vec::new(),
            next_id: 0,
            quality: sys::RTCBuildQuality::MEDIUM,
        })
    }

    /// Asks for Embree's high-quality BVH build (SAH with spatial splits) for the scene and the
    /// triangle mesh added after this call: slower to build, faster to trace; worth it for large
    /// static meshes traced many times. Default: Embree's medium quality.
    pub fn high_quality(&mut self) {
        self.quality = sys::RTCBuildQuality::HIGH;
    }

    /// Claims geometry id `id` for the next kind; kinds come in the documented order.
    fn reserve(&mut self, id: u32, what: &str) -> Result<(), AccelError> {
        if self.next_id > id {
            return Err(AccelError(format!("{what} added out of order (geometry id {id} already passed)")));
        }
        self.next_id = id + 1;
        Ok(())
    }

    fn attach(&mut self, geom: sys::RTCGeometry, want: u32) -> Result<u32, AccelError> {
        // SAFETY: `geom` is a committed geometry of this device; attach then drop our reference
        // (the scene keeps its own).
        unsafe {
            sys::rtcAttachGeometryByID(self.scene, geom, want);
            sys::rtcReleaseGeometry(geom);
        }
        self.device.take_errors()?;
        self.next_id = want + 1;
        Ok(want)
    }

    /// Adds the triangle mesh (must be geometry [`GEOM_TRIANGLES`]): world-space vertices and
    /// index triples. An empty mesh is allowed (nothing is attached but the id is reserved).
    pub fn add_triangles(&mut self, vertices: &[Vec3], indices: &[[u32; 3]]) -> Result<u32, AccelError> {
        let id = GEOM_TRIANGLES;
        self.reserve(id, "triangles")?;
        if indices.is_empty() {
            return Ok(id);
        }
        if let Some(bad) = indices.iter().flatten().find(|&&i| i as usize >= vertices.len()) {
            return Err(AccelError(format!("triangle index {bad} out of range ({} vertices)", vertices.len())));
        }
        // SAFETY: new geometry of a live device; the buffers returned by rtcSetNewGeometryBuffer are
        // sized for exactly `len` items of the given stride (Embree pads them), and we write
        // exactly that many before committing.
        unsafe {
            let g = sys::rtcNewGeometry(self.device.raw, sys::RTCGeometryType::TRIANGLE);
            let vb = sys::rtcSetNewGeometryBuffer(
                g,
                sys::RTCBufferType::VERTEX,
                0,
                sys::RTCFormat::FLOAT3,
                12,
                vertices.len(),
            ) as *mut f32;
            let ib =
                sys::rtcSetNewGeometryBuffer(g, sys::RTCBufferType::INDEX, 0, sys::RTCFormat::UINT3, 12, indices.len())
                    as *mut u32;
            self.device.take_errors()?;
            if vb.is_null() || ib.is_null() {
                sys::rtcReleaseGeometry(g);
                return Err(AccelError("could not allocate triangle buffers".into()));
            }
            let vdst = std::slice::from_raw_parts_mut(vb, vertices.len() * 3);
            for (d, v) in vdst.chunks_exact_mut(3).zip(vertices) {
                d.copy_from_slice(&v.to_array());
            }
            let idst = std::slice::from_raw_parts_mut(ib, indices.len() * 3);
            for (d, t) in idst.chunks_exact_mut(3).zip(indices) {
                d.copy_from_slice(t);
            }
            sys::rtcSetGeometryBuildQuality(g, self.quality);
            sys::rtcCommitGeometry(g);
            self.attach(g, id)
        }
    }

    /// Adds world-space spheres (centre xyz, radius w) as geometry [`GEOM_SPHERES`] (Embree
    /// sphere points).
    pub fn add_spheres(&mut self, spheres: &[Vec4]) -> Result<u32, AccelError> {
        let id = GEOM_SPHERES;
        self.reserve(id, "spheres")?;
        if spheres.is_empty() {
            return Ok(id);
        }
        // SAFETY: an Embree-owned buffer of exactly `spheres.len()` FLOAT4s, written fully before
        // the geometry is committed.
        unsafe {
            let g = sys::rtcNewGeometry(self.device.raw, sys::RTCGeometryType::SPHERE_POINT);
            let vb = sys::rtcSetNewGeometryBuffer(
                g,
                sys::RTCBufferType::VERTEX,
                0,
                sys::RTCFormat::FLOAT4,
                16,
                spheres.len(),
            ) as *mut f32;
            self.device.take_errors()?;
            if vb.is_null() {
                sys::rtcReleaseGeometry(g);
                return Err(AccelError("could not allocate sphere buffer".into()));
            }
            let dst = std::slice::from_raw_parts_mut(vb, spheres.len() * 4);
            for (d, s) in dst.chunks_exact_mut(4).zip(spheres) {
                d.copy_from_slice(&s.to_array());
            }
            sys::rtcCommitGeometry(g);
            self.attach(g, id)
        }
    }

    /// Adds every ellipsoid as geometry [`GEOM_ELLIPSOIDS`]: an Embree user geometry whose
    /// primitive `i` is the unit sphere mapped by `object_to_world[i]` (any invertible affine map).
    /// Intersection runs in object space in f64 (robust at huge and tiny scales); `t` is preserved
    /// by affine maps, so hits are reported in world units of the ray.
    pub fn add_ellipsoids(&mut self, object_to_world: &[Mat4]) -> Result<u32, AccelError> {
        let id = GEOM_ELLIPSOIDS;
        self.reserve(id, "ellipsoids")?;
        if object_to_world.is_empty() {
            return Ok(id);
        }
        let mut prims = Vec::with_capacity(object_to_world.len());
        for (i, m) in object_to_world.iter().enumerate() {
            prims.push(Ellipsoid::new(m).ok_or_else(|| AccelError(format!("sphere {i} has a singular transform")))?);
        }
        // Embree makes a one-primitive BVH a bare leaf, whose primitive every ray of every packet
        // reaches without a box test: a lone ellipsoid gets a sentinel primitive (a point box
        // outside its own, never hit: `user_geometry::sentinel_point`), so the BVH has a root
        // node and only packets with a ray crossing the ellipsoid's box call it (cornellSimple:
        // half the callback calls).
        let sentinel = u32::from(prims.len() == 1);
        let data = Box::new(prims);
        let count = u32::try_from(data.len())
            .ok()
            .and_then(|n| n.checked_add(sentinel))
            .ok_or_else(|| AccelError("too many spheres".into()))?;
        // SAFETY: the user pointer is the boxed Vec<Ellipsoid>, moved into the Scene (heap address
        // unchanged) and dropped only after the Embree scene is released; the callbacks read it only.
        unsafe {
            let g = sys::rtcNewGeometry(self.device.raw, sys::RTCGeometryType::USER);
            sys::rtcSetGeometryUserPrimitiveCount(g, count);
            let ptr = &*data as *const Vec<Ellipsoid> as *mut c_void;
            sys::rtcSetGeometryUserData(g, ptr);
            sys::rtcSetGeometryBoundsFunction(g, Some(ellipsoid_bounds), ptr);
            sys::rtcSetGeometryIntersectFunction(g, Some(ellipsoid_intersect));
            sys::rtcSetGeometryOccludedFunction(g, Some(ellipsoid_occluded));
            sys::rtcCommitGeometry(g);
            self.user_data.push(data);
            self.attach(g, id)
        }
    }

    /// Adds an instance (geometry id >= [`GEOM_FIRST_INSTANCE`]) of a child scene holding one
    /// triangle mesh, placed by the affine `object_to_world`. Hits report `inst_id` = the returned
    /// id, `geom_id` = 0 and `prim_id` the child's triangle. (A group with one instance:
    /// [`SceneBuilder::add_group`] then [`SceneBuilder::add_instance`].)
    pub fn add_mesh_instance(
        &mut self,
        vertices: &[Vec3],
        indices: &[[u32; 3]],
        object_to_world: &Mat4,
    ) -> Result<u32, AccelError> {
        let group = self.add_group(vertices, indices)?;
        self.add_instance(group, object_to_world)
    }

    /// Builds and commits a child scene holding one triangle mesh (object space), to be placed
    /// by any number of [`SceneBuilder::add_instance`]s: its BVH and vertices are stored once.
    /// Returns its handle for `add_instance`. Adds no geometry to this scene.
    pub fn add_group(&mut self, vertices: &[Vec3], indices: &[[u32; 3]]) -> Result<GroupId, AccelError> {
        let mut child = SceneBuilder::new(self.device)?;
        child.quality = self.quality;
        child.add_triangles(vertices, indices)?;
        let child = child.commit()?;
        let mut child = std::mem::ManuallyDrop::new(child);
        let id = GroupId(self.children.len());
        self.children.push(child.raw);
        self.children.append(&mut child.children);
        self.user_data.append(&mut child._user_data);
        Ok(id)
    }

    /// Adds an instance (geometry id >= [`GEOM_FIRST_INSTANCE`], in increasing order) of the
    /// group `group`, placed by the affine `object_to_world`. Hits report `inst_id` = the returned
    /// id, `geom_id` = 0 and `prim_id` the group's triangle.
    pub fn add_instance(&mut self, group: GroupId, object_to_world: &Mat4) -> Result<u32, AccelError> {
        let child = *self.children.get(group.0).ok_or_else(|| AccelError(format!("no group {}", group.0)))?;
        let id = self.next_id.max(GEOM_FIRST_INSTANCE);
        self.reserve(id, "instance")?;
        let xfm = affine_3x4_column_major(object_to_world);
        // SAFETY: instance of a committed child scene whose handle this builder keeps (released
        // after the parent); the transform pointer is valid for 12 floats during the call (Embree
        // copies it).
        unsafe {
            let g = sys::rtcNewGeometry(self.device.raw, sys::RTCGeometryType::INSTANCE);
            sys::rtcSetGeometryInstancedScene(g, child);
            sys::rtcSetGeometryTransform(g, 0, sys::RTCFormat::FLOAT3X4_COLUMN_MAJOR, xfm.as_ptr() as *const c_void);
            sys::rtcCommitGeometry(g);
            self.attach(g, id)
        }
    }

    /// Commits (builds the BVH) and returns the queryable scene. No scene flags: measured with
    /// `strata rays` (raw Embree Mrays/s), `RTC_SCENE_FLAG_ROBUST` traced 13-18% slower on hw4/dragon
    /// and ~30% slower on hw3/cornellSimple, `RTC_SCENE_FLAG_COMPACT` ~28% and ~26% slower.
    pub fn commit(mut self) -> Result<Scene, AccelError> {
        // SAFETY: the scene handle is live; set its build quality, then commit builds it.
        unsafe {
            sys::rtcSetSceneBuildQuality(self.scene, self.quality);
            sys::rtcCommitScene(self.scene);
        }
        self.device.take_errors()?;
        let raw = std::mem::replace(&mut self.scene, std::ptr::null_mut());
        Ok(Scene { raw, children: std::mem::take(&mut self.children), _user_data: std::mem::take(&mut self.user_data) })
    }
}

impl Scene {
    /// Intersects the `active` lanes of `rh` (closest hit). `coherent` passes
    /// RTC_RAY_QUERY_FLAG_COHERENT (use it for primary rays from pixel tiles only). Resets the hit
    /// ids of every lane first; lanes with non-finite rays are dropped. Returns the lanes traced.
    #[inline]
    pub fn intersect8(&self, rh: &mut RayHit8, coherent: bool, active: Mask8) -> Mask8 {
        let ok = active & finite_ray(&rh.ray);
        rh.hit.geom_id = [INVALID_ID; 8];
        rh.hit.prim_id = [INVALID_ID; 8];
        rh.hit.inst_id = [[INVALID_ID; 8]];
        rh.hit.inst_prim_id = [[INVALID_ID; 8]];
        if ok.none() {
            return ok;
        }
        let valid = Valid8(mask_to_valid(ok));
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(coherent, &mut ctx);
        // SAFETY: `rh` has the 4.4 RTCRayHit8 layout (size asserted above) and 32-byte alignment;
        // `valid` holds 8 ints, 32-byte aligned; `args` starts with the RTCIntersectArguments layout and points to an
        // 8-byte 4.4 context. Embree writes only within these objects.
        unsafe {
            sys::rtcIntersect8(
                valid.0.as_ptr(),
                self.raw,
                rh as *mut RayHit8 as *mut sys::RTCRayHit8,
                &mut args as *mut QueryArgs as *mut sys::RTCIntersectArguments,
            );
        }
        ok
    }

    /// Any-hit test for the `active` lanes of `ray` over (tnear, tfar); returns the mask of lanes
    /// that are occluded. Non-finite lanes are reported occluded-free and not traced.
    #[inline]
    pub fn occluded8(&self, ray: &mut Ray8, active: Mask8) -> Mask8 {
        let ok = active & finite_ray(ray);
        if ok.none() {
            return ok;
        }
        let valid = Valid8(mask_to_valid(ok));
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(false, &mut ctx);
        // SAFETY: `ray` has the RTCRay8 layout (384 bytes, unchanged since 4.0), 32-byte aligned;
        // `valid` holds 8 ints, 32-byte aligned; args/context as in intersect8.
        unsafe {
            sys::rtcOccluded8(
                valid.0.as_ptr(),
                self.raw,
                ray as *mut Ray8 as *mut sys::RTCRay8,
                &mut args as *mut QueryArgs as *mut sys::RTCOccludedArguments,
            );
        }
        ok & F8::new(ray.tfar).simd_eq(F8::splat(f32::NEG_INFINITY))
    }
}

impl Scene {
    /// Closest hits of the valid lanes of a 16-ray block (`strata rays`' replay at Embree's 16-wide
    /// entry point; rendering traces 8 wide). The rays must be finite ([`RayHit16::new`] of
    /// logged, traced lanes).
    pub fn intersect16(&self, rh: &mut RayHit16, valid: &Valid16, coherent: bool) {
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(coherent, &mut ctx);
        // SAFETY: `rh` has the 4.4 RTCRayHit16 layout (size and 64-byte alignment asserted in
        // ffi.rs); `valid` holds 16 ints, 64-byte aligned; args/context as in intersect8.
        unsafe {
            sys::rtcIntersect16(
                valid.0.as_ptr(),
                self.raw,
                rh as *mut RayHit16 as *mut sys::RTCRayHit16,
                &mut args as *mut QueryArgs as *mut sys::RTCIntersectArguments,
            );
        }
    }

    /// Any-hit test of the valid lanes of a 16-ray block (its ray part); occluded lanes get
    /// `tfar = -inf`. For `strata rays`' replay, as [`Scene::intersect16`].
    pub fn occluded16(&self, r: &mut RayHit16, valid: &Valid16) {
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(false, &mut ctx);
        // SAFETY: the block starts with the RTCRay16 layout (12 fields of 16 lanes), 64-byte
        // aligned; `valid` holds 16 ints, 64-byte aligned; args/context as in intersect8.
        unsafe {
            sys::rtcOccluded16(
                valid.0.as_ptr(),
                self.raw,
                r as *mut RayHit16 as *mut sys::RTCRay16,
                &mut args as *mut QueryArgs as *mut sys::RTCOccludedArguments,
            );
        }
    }

    /// Closest hit of one finite ray (`strata rays`' one-by-one replay).
    pub fn intersect1(&self, rh: &mut RayHit1, coherent: bool) {
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(coherent, &mut ctx);
        // SAFETY: `rh` has the 4.4 RTCRayHit layout (96 bytes, 16-byte aligned, asserted in
        // ffi.rs); args/context as in intersect8.
        unsafe {
            sys::rtcIntersect1(
                self.raw,
                rh as *mut RayHit1 as *mut sys::RTCRayHit,
                &mut args as *mut QueryArgs as *mut sys::RTCIntersectArguments,
            );
        }
    }

    /// Any-hit test of one finite ray (its ray part); occluded: `tfar = -inf`.
    pub fn occluded1(&self, r: &mut RayHit1) {
        let mut ctx = RayQueryContext { inst_id: [INVALID_ID], inst_prim_id: [INVALID_ID] };
        let mut args = query_args(false, &mut ctx);
        // SAFETY: the block starts with the RTCRay layout (12 words), 16-byte aligned;
        // args/context as in intersect8.
        unsafe {
            sys::rtcOccluded1(
                self.raw,
                r as *mut RayHit1 as *mut sys::RTCRay,
                &mut args as *mut QueryArgs as *mut sys::RTCOccludedArguments,
            );
        }
    }
}

/// Closest-hit results of a packet in SoA form.
#[derive(Clone, Copy, Debug)]
pub struct Hits8 {
    /// lanes that hit something
    pub hit: Mask8,
    /// hit distance (tfar), in units of |dir|
    pub t: F8,
    /// primitive id
    pub prim: U8,
    /// geometry id (child id for instances)
    pub geom: U8,
    /// instance geometry id or INVALID_ID
    pub inst: U8,
    /// Embree barycentric u of the hit (triangles: p = (1-u-v) v0 + u v1 + v v2)
    pub u: F8,
    /// Embree barycentric v of the hit
    pub v: F8,
}

impl Hits8 {
    /// Reads the hit record after [`Scene::intersect8`]; `traced` is the mask it returned.
    #[inline]
    pub fn from_rayhit(rh: &RayHit8, traced: Mask8) -> Self {
        let geom = U8::new(rh.hit.geom_id);
        let valid_bits = !geom.simd_eq(U8::splat(INVALID_ID));
        let hit = traced & F8::from_bits(valid_bits);
        Self {
            hit,
            t: F8::new(rh.ray.tfar),
            prim: U8::new(rh.hit.prim_id),
            geom,
            inst: U8::new(rh.hit.inst_id[0]),
            u: F8::new(rh.hit.u),
            v: F8::new(rh.hit.v),
        }
    }
}
