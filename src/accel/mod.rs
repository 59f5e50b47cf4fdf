//! The one module that talks to Embree 4, and the only `unsafe` in strata.
//!
//! Embree 4.4 (the library we link) is built with instance arrays, so its ray/hit structs carry an
//! `instPrimID` field that the 4.2-era structs of `embree4-sys` lack: `RTCRayHit8` is 672 bytes, not
//! 640, and a hit written into the crate's struct would run past its end. We therefore define the
//! packet structs here with the 4.4 layout, check their sizes at compile time, and cast at the call.
//!
//! Geometry layout of a built scene (the ids `scene::build` relies on):
//! - geometry [`GEOM_TRIANGLES`]: one triangle mesh holding every triangle (quad lights included);
//! - geometry [`GEOM_SPHERES`]: spheres placed by similarity transforms, as Embree sphere points
//!   (centre, radius) in world space: Embree's own vectorized intersector;
//! - geometry [`GEOM_ELLIPSOIDS`]: spheres under any other affine map, as one Embree user geometry
//!   whose primitive i is the unit sphere under that map (no instancing; f64 object-space
//!   intersection, accurate at extreme scales; slower than sphere points);
//! - geometries from [`GEOM_FIRST_INSTANCE`] on: instances (hits report `inst_id`).
//! Geometry kinds must be added in this order; a kind may be skipped.

pub mod alloc;
pub mod ellipsoid;

use crate::simd::{mask_to_valid, Mask8, Vec3x8, F8, U8};
use embree4_sys as sys;
use glam::{Mat4, Vec3, Vec4};
use std::ffi::{c_char, c_void, CStr};
use std::sync::Mutex;

/// Embree's invalid geometry / instance id.
pub const INVALID_ID: u32 = u32::MAX;
/// Geometry id of the triangle mesh.
pub const GEOM_TRIANGLES: u32 = 0;
/// Geometry id of the world-space sphere points.
pub const GEOM_SPHERES: u32 = 1;
/// Geometry id of the ellipsoid user geometry.
pub const GEOM_ELLIPSOIDS: u32 = 2;
/// First geometry id of instances.
pub const GEOM_FIRST_INSTANCE: u32 = 3;

/// A packet of 8 rays, Embree 4.4 `RTCRay8` layout (384 bytes, 32-byte aligned).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug)]
pub struct Ray8 {
    /// origin x, world space
    pub org_x: [f32; 8],
    /// origin y
    pub org_y: [f32; 8],
    /// origin z
    pub org_z: [f32; 8],
    /// start of the ray interval (distance in units of |dir|)
    pub tnear: [f32; 8],
    /// direction x (need not be unit; t is in units of |dir|)
    pub dir_x: [f32; 8],
    /// direction y
    pub dir_y: [f32; 8],
    /// direction z
    pub dir_z: [f32; 8],
    /// motion-blur time (unused, 0)
    pub time: [f32; 8],
    /// end of the interval; on return the hit distance (intersect) or -inf if occluded (occluded)
    pub tfar: [f32; 8],
    /// ray mask, always u32::MAX
    pub mask: [u32; 8],
    /// ray id (unused)
    pub id: [u32; 8],
    /// ray flags (unused, 0)
    pub flags: [u32; 8],
}

/// Hit record of 8 rays, Embree 4.4 `RTCHit8` layout with one instance level (288 bytes).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug)]
pub struct Hit8 {
    /// unnormalized geometric normal x (object space of the hit geometry)
    pub ng_x: [f32; 8],
    /// normal y
    pub ng_y: [f32; 8],
    /// normal z
    pub ng_z: [f32; 8],
    /// barycentric u
    pub u: [f32; 8],
    /// barycentric v
    pub v: [f32; 8],
    /// primitive id within the geometry
    pub prim_id: [u32; 8],
    /// geometry id (within the instanced scene for instance hits)
    pub geom_id: [u32; 8],
    /// instance geometry id in the top scene, or INVALID_ID
    pub inst_id: [[u32; 8]; 1],
    /// instance-array primitive id (Embree 4.4 field; the reason these structs exist)
    pub inst_prim_id: [[u32; 8]; 1],
}

/// Ray and hit of 8 rays, Embree 4.4 `RTCRayHit8` layout (672 bytes).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug)]
pub struct RayHit8 {
    /// rays
    pub ray: Ray8,
    /// hits
    pub hit: Hit8,
}

/// Embree 4.4 `RTCRayQueryContext` with one instance level (8 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RayQueryContext {
    /// instance id stack
    pub inst_id: [u32; 1],
    /// instance primitive id stack
    pub inst_prim_id: [u32; 1],
}

/// The valid-lane array of an 8-wide query: Embree loads it with an aligned 32-byte AVX load, so it
/// must be 32-byte aligned (an unaligned `[i32; 8]` on the stack segfaults inside Embree).
#[repr(C, align(32))]
struct Valid8([i32; 8]);

/// `RTCIntersectArguments` / `RTCOccludedArguments` (identical layout), with room for the optional
/// `minWidthDistanceFactor` of builds that enable it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
struct QueryArgs {
    flags: u32,
    feature_mask: u32,
    context: *mut RayQueryContext,
    filter: *const c_void,
    callback: *const c_void,
    min_width_distance_factor: f32,
}

const _: () = assert!(std::mem::size_of::<Ray8>() == 384);
const _: () = assert!(std::mem::size_of::<Hit8>() == 288);
const _: () = assert!(std::mem::size_of::<RayHit8>() == 672);
const _: () = assert!(std::mem::align_of::<RayHit8>() == 32);
const _: () = assert!(std::mem::size_of::<RayQueryContext>() == 8);
const _: () = assert!(std::mem::align_of::<Valid8>() == 32 && std::mem::align_of::<Ray8>() == 32);
// The crate's args structs are a prefix of ours; we pass a pointer to ours.
const _: () = assert!(std::mem::size_of::<sys::RTCIntersectArguments>() <= std::mem::size_of::<QueryArgs>());
const _: () = assert!(std::mem::size_of::<sys::RTCOccludedArguments>() <= std::mem::size_of::<QueryArgs>());

impl Default for Ray8 {
    fn default() -> Self {
        Self {
            org_x: [0.0; 8],
            org_y: [0.0; 8],
            org_z: [0.0; 8],
            tnear: [0.0; 8],
            dir_x: [0.0; 8],
            dir_y: [0.0; 8],
            dir_z: [1.0; 8],
            time: [0.0; 8],
            tfar: [0.0; 8],
            mask: [u32::MAX; 8],
            id: [0; 8],
            flags: [0; 8],
        }
    }
}

impl Default for Hit8 {
    fn default() -> Self {
        Self {
            ng_x: [0.0; 8],
            ng_y: [0.0; 8],
            ng_z: [0.0; 8],
            u: [0.0; 8],
            v: [0.0; 8],
            prim_id: [INVALID_ID; 8],
            geom_id: [INVALID_ID; 8],
            inst_id: [[INVALID_ID; 8]],
            inst_prim_id: [[INVALID_ID; 8]],
        }
    }
}

impl Default for RayHit8 {
    fn default() -> Self {
        Self { ray: Ray8::default(), hit: Hit8::default() }
    }
}

impl Ray8 {
    /// The packet's origins, world space (zero in lanes that were inactive when it was set).
    #[inline]
    pub fn org(&self) -> Vec3x8 {
        Vec3x8::new(F8::new(self.org_x), F8::new(self.org_y), F8::new(self.org_z))
    }

    /// The packet's directions as set, world space (zero in lanes that were inactive).
    #[inline]
    pub fn dir(&self) -> Vec3x8 {
        Vec3x8::new(F8::new(self.dir_x), F8::new(self.dir_y), F8::new(self.dir_z))
    }

    /// Fills the packet from SoA origins/directions and the interval [tnear, tfar]; returns the
    /// lanes that are `active` and finite (NaN must never reach Embree). Inactive lanes get a
    /// harmless ray. Resets mask, id, flags.
    #[inline]
    pub fn set(&mut self, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, active: Mask8) -> Mask8 {
        let (ray, ok) = Self::new(org, dir, tnear, tfar, active);
        *self = ray;
        ok
    }

    /// A packet from SoA origins/directions and the interval [tnear, tfar], as [`Ray8::set`]:
    /// also returns the lanes that are `active` and finite.
    #[inline]
    pub fn new(org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, active: Mask8) -> (Self, Mask8) {
        let ok = active & org.is_finite() & dir.is_finite() & tnear.is_finite() & !tfar.is_nan();
        let z = F8::ZERO;
        let ray = Self {
            org_x: ok.select(org.x, z).to_array(),
            org_y: ok.select(org.y, z).to_array(),
            org_z: ok.select(org.z, z).to_array(),
            tnear: ok.select(tnear, z).to_array(),
            dir_x: ok.select(dir.x, z).to_array(),
            dir_y: ok.select(dir.y, z).to_array(),
            dir_z: ok.select(dir.z, F8::ONE).to_array(),
            time: [0.0; 8],
            tfar: ok.select(tfar, z).to_array(),
            mask: [u32::MAX; 8],
            id: [0; 8],
            flags: [0; 8],
        };
        (ray, ok)
    }
}

/// Sets flush-to-zero and denormals-are-zero on the calling thread (x86_64; no-op elsewhere).
pub fn set_ftz_daz() {
    #[cfg(target_arch = "x86_64")]
    {
        // MXCSR bit 15 = FTZ, bit 6 = DAZ. Read-modify-write through inline asm-free intrinsics
        // is deprecated in std; use stmxcsr/ldmxcsr via core::arch::asm. Embree asks
        // for both in every rendering thread.
        let mut csr: u32 = 0;
        // SAFETY: stmxcsr/ldmxcsr only read/write the MXCSR control register of this thread and
        // the 4-byte local `csr`; setting FTZ/DAZ changes denormal handling only.
        unsafe {
            core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack));
            csr |= (1 << 15) | (1 << 6);
            core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack));
        }
    }
}

/// Errors from Embree, with its message.
#[derive(Debug, Clone, PartialEq)]
pub struct AccelError(pub String);

impl std::fmt::Display for AccelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Embree: {}", self.0)
    }
}
impl std::error::Error for AccelError {}

/// Collects messages from Embree's error callback.
struct ErrorSink(Mutex<Vec<String>>);

unsafe extern "C" fn error_callback(user: *mut c_void, code: sys::RTCError, msg: *const c_char) {
    // SAFETY: `user` is the `ErrorSink` boxed in `Device`, which outlives the device handle
    // (released in Device::drop before the box); `msg` is NUL-terminated or null per Embree's API.
    let (sink, text) = unsafe {
        let sink = &*(user as *const ErrorSink);
        let text = if msg.is_null() { String::new() } else { CStr::from_ptr(msg).to_string_lossy().into_owned() };
        (sink, text)
    };
    if let Ok(mut v) = sink.0.lock() {
        v.push(format!("{code:?}: {text}"));
    }
}

/// An Embree device with an error callback that turns errors into Rust errors.
pub struct Device {
    raw: sys::RTCDevice,
    sink: Box<ErrorSink>,
}

// SAFETY: Embree devices are thread-safe for the calls we make (scene creation and commit happen on
// one thread; queries on committed scenes are concurrent-safe per Embree's documentation).
unsafe impl Send for Device {}
// SAFETY: as above; the error sink is behind a Mutex.
unsafe impl Sync for Device {}

impl Device {
    /// Creates a device with the error callback installed. The Embree configuration string is
    /// `verbose=0`, or `$STRATA_EMBREE_CONFIG` when set (e.g. `isa=avx2`).
    pub fn new() -> Result<Self, AccelError> {
        let config = std::env::var("STRATA_EMBREE_CONFIG").unwrap_or_else(|_| "verbose=0".into());
        let config = std::ffi::CString::new(config)
            .map_err(|_| AccelError("STRATA_EMBREE_CONFIG contains a NUL byte".into()))?;
        // SAFETY: a NUL-terminated config string; a null return is checked.
        let raw = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            return Err(AccelError("rtcNewDevice failed (is libembree4 usable on this CPU?)".into()));
        }
        let sink = Box::new(ErrorSink(Mutex::new(Vec::new())));
        // SAFETY: `raw` is a live device; the sink pointer stays valid until after rtcReleaseDevice.
        unsafe { sys::rtcSetDeviceErrorFunction(raw, Some(error_callback), &*sink as *const ErrorSink as *mut c_void) };
        Ok(Self { raw, sink })
    }

    /// Returns (and clears) the errors Embree reported since the last call.
    pub fn take_errors(&self) -> Result<(), AccelError> {
        let mut v = self.sink.0.lock().map_err(|_| AccelError("error sink poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            Err(AccelError(std::mem::take(&mut *v).join("; ")))
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device was created by rtcNewDevice and is released once; all scenes hold
        // their own reference so releasing here is safe even if a Scene outlives this handle.
        unsafe { sys::rtcReleaseDevice(self.raw) };
    }
}

/// Builds a scene: add geometry in the documented id order, then [`SceneBuilder::commit`].
pub struct SceneBuilder<'d> {
    device: &'d Device,
    scene: sys::RTCScene,
    children: Vec<sys::RTCScene>,
    user_data: Vec<Box<Vec<Ellipsoid>>>,
    next_id: u32,
    quality: sys::RTCBuildQuality,
}

/// A committed Embree scene, safe to query from many threads.
pub struct Scene {
    raw: sys::RTCScene,
    children: Vec<sys::RTCScene>,
    // Read by the ellipsoid callbacks; dropped after `raw` is released (see Drop).
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
        let data = Box::new(prims);
        let count = u32::try_from(data.len()).map_err(|_| AccelError("too many spheres".into()))?;
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
    /// id, `geom_id` = 0 and `prim_id` the child's triangle.
    pub fn add_mesh_instance(
        &mut self,
        vertices: &[Vec3],
        indices: &[[u32; 3]],
        object_to_world: &Mat4,
    ) -> Result<u32, AccelError> {
        let id = self.next_id.max(GEOM_FIRST_INSTANCE);
        self.reserve(id, "instance")?;
        let mut child = SceneBuilder::new(self.device)?;
        child.add_triangles(vertices, indices)?;
        let child = child.commit()?;
        let xfm = affine_3x4_column_major(object_to_world);
        // SAFETY: instance of a committed child scene whose handle we keep (and release after the
        // parent); the transform pointer is valid for 12 floats during the call (Embree copies it).
        unsafe {
            let g = sys::rtcNewGeometry(self.device.raw, sys::RTCGeometryType::INSTANCE);
            sys::rtcSetGeometryInstancedScene(g, child.raw);
            sys::rtcSetGeometryTransform(g, 0, sys::RTCFormat::FLOAT3X4_COLUMN_MAJOR, xfm.as_ptr() as *const c_void);
            sys::rtcCommitGeometry(g);
            self.attach(g, id)?;
        }
        let mut child = std::mem::ManuallyDrop::new(child);
        self.children.push(child.raw);
        self.children.append(&mut child.children);
        self.user_data.append(&mut child._user_data);
        Ok(id)
    }

    /// Commits (builds the BVH) and returns the queryable scene.
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

/// One ellipsoid: the unit sphere under an affine map, stored as the world-to-object map in f64.
#[derive(Clone, Copy, Debug)]
struct Ellipsoid {
    /// world-to-object linear part (row-major 3x3) and translation
    inv: [[f64; 4]; 3],
    lower: [f32; 3],
    upper: [f32; 3],
    fast: ellipsoid::Fast,
}

impl Ellipsoid {
    fn new(m: &Mat4) -> Option<Self> {
        let md = glam::DMat4::from_cols_array(&m.to_cols_array().map(f64::from));
        let det = md.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return None;
        }
        let inv = md.inverse();
        let r = |i: usize| {
            let row = inv.row(i);
            [row.x, row.y, row.z, row.w]
        };
        // Bounds of the image of the unit ball: centre +- the row norms of the linear part.
        let (mut lower, mut upper) = ([0f32; 3], [0f32; 3]);
        for i in 0..3 {
            let row = md.row(i);
            let ext = (row.x * row.x + row.y * row.y + row.z * row.z).sqrt() * (1.0 + 1e-6);
            lower[i] = (row.w - ext) as f32;
            upper[i] = (row.w + ext) as f32;
        }
        let inv = [r(0), r(1), r(2)];
        Some(Self { inv, lower, upper, fast: ellipsoid::Fast::new(&inv) })
    }

    /// Nearest root t in (tnear, tfar) of |o' + t d'| = 1 in object space, if any.
    #[inline]
    fn hit(&self, o: [f32; 3], d: [f32; 3], tnear: f32, tfar: f32) -> Option<f32> {
        let m = &self.inv;
        let (o, d) = (o.map(f64::from), d.map(f64::from));
        let oo: [f64; 3] = std::array::from_fn(|i| m[i][0] * o[0] + m[i][1] * o[1] + m[i][2] * o[2] + m[i][3]);
        let dd: [f64; 3] = std::array::from_fn(|i| m[i][0] * d[0] + m[i][1] * d[1] + m[i][2] * d[2]);
        let a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
        if !(a > 0.0) {
            return None;
        }
        // Numerically robust form: the discriminant from the distance of the closest approach.
        let b = -(oo[0] * dd[0] + oo[1] * dd[1] + oo[2] * dd[2]) / a; // t of the closest approach
        let f: [f64; 3] = std::array::from_fn(|i| oo[i] + b * dd[i]);
        let disc = 1.0 - (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        if disc < 0.0 {
            return None;
        }
        let h = (disc / a).sqrt();
        let (t0, t1) = (b - h, b + h);
        let (tn, tf) = (f64::from(tnear), f64::from(tfar));
        let t = if t0 > tn && t0 < tf {
            t0
        } else if t1 > tn && t1 < tf {
            t1
        } else {
            return None;
        };
        Some(t as f32).filter(|t| *t > tnear && *t < tfar)
    }
}

unsafe extern "C" fn ellipsoid_bounds(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments; the user pointer is the Vec<Ellipsoid> set in
    // add_ellipsoids and primID < its length (the primitive count we declared).
    unsafe {
        let a = &*args;
        let prims = &*(a.geometryUserPtr as *const Vec<Ellipsoid>);
        let e = &prims[a.primID as usize];
        let b = &mut *a.bounds_o;
        (b.lower_x, b.lower_y, b.lower_z) = (e.lower[0], e.lower[1], e.lower[2]);
        (b.upper_x, b.upper_y, b.upper_z) = (e.upper[0], e.upper[1], e.upper[2]);
    }
}

/// Float at 4-byte word `field * n + lane` of an Embree SoA ray/hit block of width `n`.
#[inline]
unsafe fn soa(base: *mut u32, n: usize, field: usize, lane: usize) -> *mut u32 {
    // SAFETY: the caller guarantees base points to an RTCRayHitN/RTCRayN of width n with at least
    // `field + 1` fields.
    unsafe { base.add(field * n + lane) }
}

/// Runs the ellipsoid `prim` against every valid lane of an Embree SoA ray block of width `n` and
/// calls `on_hit(lane, t)` for each lane it hits inside (tnear, tfar).
///
/// # Safety
/// `valid` must hold `n` ints and `base` point to an RTCRayN (or the ray part of an RTCRayHitN) of
/// width `n`; `user` must be the Vec<Ellipsoid> set in add_ellipsoids with `prim` < its length.
unsafe fn each_ellipsoid_hit(
    valid: *const i32,
    user: *mut c_void,
    prim: u32,
    base: *mut u32,
    n: usize,
    mut on_hit: impl FnMut(usize, f32),
) {
    // SAFETY: guaranteed by the caller (see the function's contract).
    unsafe {
        let prims = &*(user as *const Vec<Ellipsoid>);
        let e = &prims[prim as usize];
        for start in (0..n).step_by(8) {
            let m = (n - start).min(8);
            let load = |field: usize| {
                let p = soa(base, n, field, start) as *const f32;
                if m == 8 {
                    return std::ptr::read_unaligned(p as *const [f32; 8]);
                }
                let mut v = [0f32; 8];
                std::ptr::copy_nonoverlapping(p, v.as_mut_ptr(), m);
                v
            };
            let valid = |i: usize| *valid.add(start + i) == -1;
            ellipsoid::packet_hits(e, m, load, valid, |i, t| on_hit(start + i, t));
        }
    }
}

unsafe extern "C" fn ellipsoid_intersect(args: *const sys::RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes `valid` with N ints, `rayhit` as an RTCRayHitN of width N in the 4.4
    // layout (12 ray fields then 9 hit fields, one instance level), the user pointer set in
    // add_ellipsoids, and primID < the primitive count.
    unsafe {
        let a = &*args;
        let (n, base) = (a.N as usize, a.rayhit as *mut u32);
        let ctx = &*(a.context as *const RayQueryContext);
        each_ellipsoid_hit(a.valid, a.geometryUserPtr, a.primID, base, n, |lane, t| {
            *soa(base, n, 8, lane) = t.to_bits();
            for field in 12..17 {
                *soa(base, n, field, lane) = 0; // Ng and u, v: strata computes its own normals
            }
            *soa(base, n, 17, lane) = a.primID;
            *soa(base, n, 18, lane) = a.geomID;
            *soa(base, n, 19, lane) = ctx.inst_id[0];
            *soa(base, n, 20, lane) = ctx.inst_prim_id[0];
        });
    }
}

unsafe extern "C" fn ellipsoid_occluded(args: *const sys::RTCOccludedFunctionNArguments) {
    // SAFETY: as in ellipsoid_intersect, with `ray` an RTCRayN of width N (12 fields).
    unsafe {
        let a = &*args;
        let (n, base) = (a.N as usize, a.ray as *mut u32);
        each_ellipsoid_hit(a.valid, a.geometryUserPtr, a.primID, base, n, |lane, _| {
            *soa(base, n, 8, lane) = f32::NEG_INFINITY.to_bits();
        });
    }
}

fn query_args(coherent: bool, ctx: &mut RayQueryContext) -> QueryArgs {
    QueryArgs {
        flags: if coherent { sys::RTCRayQueryFlags::COHERENT.0 } else { sys::RTCRayQueryFlags::INCOHERENT.0 },
        feature_mask: u32::MAX,
        context: ctx,
        filter: std::ptr::null(),
        callback: std::ptr::null(),
        min_width_distance_factor: 0.0,
    }
}

#[inline]
fn finite_ray(r: &Ray8) -> Mask8 {
    let f = |a: &[f32; 8]| F8::new(*a).is_finite();
    f(&r.org_x)
        & f(&r.org_y)
        & f(&r.org_z)
        & f(&r.dir_x)
        & f(&r.dir_y)
        & f(&r.dir_z)
        & f(&r.tnear)
        & !F8::new(r.tfar).is_nan()
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
}

impl Hits8 {
    /// Reads the hit record after [`Scene::intersect8`]; `traced` is the mask it returned.
    #[inline]
    pub fn from_rayhit(rh: &RayHit8, traced: Mask8) -> Self {
        let geom = U8::new(rh.hit.geom_id);
        let valid_bits = !geom.simd_eq(U8::splat(INVALID_ID));
        let hit = traced & F8::from_bits(valid_bits);
        Self { hit, t: F8::new(rh.ray.tfar), prim: U8::new(rh.hit.prim_id), geom, inst: U8::new(rh.hit.inst_id[0]) }
    }
}

/// Path of the Embree library this binary was linked against (from build.rs).
pub const EMBREE_LIBDIR: &str = env!("STRATA_EMBREE_LIBDIR");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{mask_all, mask_to_bools};

    #[repr(C, align(32))]
    struct Canaried<T> {
        value: T,
        canary: [u32; 64],
    }
    const CANARY: u32 = 0xDEAD_BEEF;

    fn build(dev: &Device, with_instance: bool) -> Scene {
        let mut b = SceneBuilder::new(dev).unwrap();
        // A quad at z = 5 spanning [-1,1]^2, two triangles.
        let v = [
            Vec3::new(-1.0, -1.0, 5.0),
            Vec3::new(1.0, -1.0, 5.0),
            Vec3::new(1.0, 1.0, 5.0),
            Vec3::new(-1.0, 1.0, 5.0),
        ];
        b.add_triangles(&v, &[[0, 1, 2], [0, 2, 3]]).unwrap();
        // A sphere point of radius 0.5 at (3, 0, 5); a user-geometry sphere of radius 0.5 at
        // (3, 3, 5) and an ellipsoid (0.5, 0.25, 0.5) at (0, 3, 5).
        b.add_spheres(&[Vec4::new(3.0, 0.0, 5.0, 0.5)]).unwrap();
        let sphere = Mat4::from_translation(Vec3::new(3.0, 3.0, 5.0)) * Mat4::from_scale(Vec3::splat(0.5));
        let ellipsoid = Mat4::from_translation(Vec3::new(0.0, 3.0, 5.0)) * Mat4::from_scale(Vec3::new(0.5, 0.25, 0.5));
        b.add_ellipsoids(&[sphere, ellipsoid]).unwrap();
        if with_instance {
            // The quad again, instanced: scaled by 0.5 and moved to (-3, 0, 0) (so at z = 2.5).
            let m = Mat4::from_translation(Vec3::new(-3.0, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(0.5));
            assert_eq!(b.add_mesh_instance(&v, &[[0, 1, 2], [0, 2, 3]], &m).unwrap(), GEOM_FIRST_INSTANCE);
        }
        let s = b.commit().unwrap();
        dev.take_errors().unwrap();
        s
    }

    fn packet(xs: [f32; 8], ys: [f32; 8]) -> (Vec3x8, Vec3x8) {
        let org = Vec3x8::new(F8::new(xs), F8::new(ys), F8::ZERO);
        (org, Vec3x8::splat(Vec3::Z))
    }

    /// Embree 4.4 writes instPrimID after the 4.2-era hit struct: canary words after our structs
    /// must survive hits on plain and instanced geometry, for intersect and occluded.
    #[test]
    fn abi_canaries_survive_plain_and_instanced_hits() {
        let dev = Device::new().unwrap();
        let scene = build(&dev, true);
        let xs = [0.0, 3.0, 3.0, 0.0, -3.0, -3.1, 10.0, 0.0];
        let ys = [0.0, 3.0, 0.0, 3.1, 0.0, 0.05, 0.0, -0.9];
        let (org, dir) = packet(xs, ys);
        let mut c = Canaried { value: RayHit8::default(), canary: [CANARY; 64] };
        c.value.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
        let traced = scene.intersect8(&mut c.value, false, mask_all());
        assert!(c.canary.iter().all(|&w| w == CANARY), "Embree wrote past RayHit8");
        let h = Hits8::from_rayhit(&c.value, traced);
        assert_eq!(mask_to_bools(h.hit), [true, true, true, true, true, true, false, true]);
        let geom = h.geom.to_array();
        let inst = h.inst.to_array();
        assert_eq!([geom[0], geom[7]], [GEOM_TRIANGLES; 2]);
        assert_eq!(geom[2], GEOM_SPHERES);
        assert_eq!([geom[1], geom[3]], [GEOM_ELLIPSOIDS; 2]);
        assert_eq!([h.prim.to_array()[1], h.prim.to_array()[3]], [0, 1]);
        assert_eq!(&inst[4..6], &[GEOM_FIRST_INSTANCE; 2]);
        assert_eq!(&geom[4..6], &[0, 0]);
        assert_eq!(inst[0], INVALID_ID);
        let t = h.t.to_array();
        assert!((t[0] - 5.0).abs() < 1e-5);
        assert!((t[2] - 4.5).abs() < 1e-5, "sphere point front at z = 4.5: {}", t[2]);
        assert!((t[1] - 4.5).abs() < 1e-5, "user sphere front at z = 4.5: {}", t[1]);
        // ellipsoid at (0, 3): z half-axis 0.5; at y offset 0.1 of a 0.25 half-axis, z = 5 - 0.5 sqrt(1 - 0.16).
        assert!((t[3] - (5.0 - 0.5 * 0.84f32.sqrt())).abs() < 1e-5, "ellipsoid: {}", t[3]);
        assert!((t[4] - 2.5).abs() < 1e-5, "instanced quad at z = 2.5: {}", t[4]);
        // The 4.4-only field lands inside our struct: Embree writes it (0 for a plain instance hit)
        // over the INVALID_ID that intersect8 put there.
        assert_eq!(c.value.hit.inst_prim_id[0][4], 0);

        let mut r = Canaried { value: Ray8::default(), canary: [CANARY; 64] };
        r.value.set(org, dir, F8::ZERO, F8::splat(100.0), mask_all());
        let occ = scene.occluded8(&mut r.value, mask_all());
        assert!(r.canary.iter().all(|&w| w == CANARY), "Embree wrote past Ray8");
        assert_eq!(mask_to_bools(occ), [true, true, true, true, true, true, false, true]);
        dev.take_errors().unwrap();
    }

    #[test]
    fn inactive_and_nan_lanes_are_not_traced() {
        let dev = Device::new().unwrap();
        let scene = build(&dev, false);
        let mut xs = [0.0; 8];
        xs[3] = f32::NAN;
        let (org, dir) = packet(xs, [0.0; 8]);
        let mut rh = RayHit8::default();
        let active = crate::simd::mask_first(6);
        rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), active);
        // A NaN smuggled in after set() must still be dropped by intersect8.
        rh.ray.org_x[3] = f32::NAN;
        let traced = scene.intersect8(&mut rh, true, active);
        assert_eq!(mask_to_bools(traced), [true, true, true, false, true, true, false, false]);
        let h = Hits8::from_rayhit(&rh, traced);
        assert_eq!(mask_to_bools(h.hit), [true, true, true, false, true, true, false, false]);
        assert!(h.t.to_array()[..3].iter().all(|t| (t - 5.0).abs() < 1e-5));
        dev.take_errors().unwrap();
    }

    #[test]
    fn tfar_limits_shadow_rays() {
        let dev = Device::new().unwrap();
        let scene = build(&dev, false);
        let (org, dir) = packet([0.0; 8], [0.0; 8]);
        let mut r = Ray8::default();
        let tf = F8::new([4.9, 5.1, 4.9, 5.1, 100.0, 0.1, 4.99, 5.01]);
        r.set(org, dir, F8::ZERO, tf, mask_all());
        let occ = scene.occluded8(&mut r, mask_all());
        assert_eq!(mask_to_bools(occ), [false, true, false, true, true, false, false, true]);
    }

    #[test]
    fn embree_errors_become_rust_errors() {
        let dev = Device::new().unwrap();
        let mut b = SceneBuilder::new(&dev).unwrap();
        let err = b.add_triangles(&[Vec3::ZERO], &[[0, 1, 2]]).unwrap_err();
        assert!(err.0.contains("out of range"), "{err}");
        dev.take_errors().unwrap();
        // Setting a buffer type a triangle mesh does not have is an Embree error, reported through
        // the callback and turned into an Err.
        // SAFETY: a fresh geometry of a live device, given an invalid buffer on purpose, released.
        unsafe {
            let g = sys::rtcNewGeometry(dev.raw, sys::RTCGeometryType::TRIANGLE);
            sys::rtcSetNewGeometryBuffer(g, sys::RTCBufferType::GRID, 0, sys::RTCFormat::UINT3, 12, 1);
            sys::rtcReleaseGeometry(g);
        }
        let err = dev.take_errors().unwrap_err();
        assert!(!err.0.is_empty(), "{err}");
        dev.take_errors().unwrap();
    }
}
