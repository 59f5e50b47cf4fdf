//! The BSDF interface: one model per registry entry ([`Bsdf`]), its per-lane parameters
//! ([`BsdfParams`], eight lanes [`Params8`]: what a material row stores and a hit carries), what
//! sampling returns ([`Sample8`]), lobe [`flags`], and the type-level lists ([`BsdfSet`]) kernels
//! are monomorphized over, so a scene pays only for the BSDF kinds it has.
//!
//! Model: pbrt-v4's `BxDF` and Mitsuba 3's `BSDF`, eight lanes with an `active` mask.
//!
//! Conventions (every entry follows them; `bsdf/tests.rs` checks each registered entry):
//! - **Frame.** The local frame of the surface's own orientation: +z is the side its normal points
//!   to, so `wo.z < 0` when the viewer is behind the surface. `wo` points to the viewer, `wi` to the
//!   light or the sampled direction, both unit.
//! - **Sides.** A BSDF is one-sided unless it says otherwise (Mitsuba's `diffuse`, `conductor`,
//!   `plastic` are black from the back). Two-sidedness is explicit: [`BsdfParams::twosided`]
//!   (Mitsuba's `twosided`, the course's materials) mirrors the back onto the front before the BSDF
//!   sees the directions ([`flip_to_surface`]).
//! - **`eval_pdf`** returns `f` (RGB per steradian, **without** the cosine) and the density per
//!   unit solid angle with which `sample` draws `wi`. Delta lobes contribute to neither (f = 0, pdf
//!   = 0): only `sample` finds them.
//! - **`sample(wo, u_lobe, u)`**: `u_lobe` in [0, 1) picks the lobe, `u` in [0, 1)^2 the direction.
//!   It returns `wi`, the **weight** `f |cos wi| / pdf` (for a delta lobe: the lobe's value divided
//!   by the probability of picking it), the pdf (solid angle; for a delta lobe the discrete
//!   probability of the lobe, only meaningful with the [`flags::DELTA`] flag), the sampled lobe's
//!   flags and the relative index `eta` = eta_t / eta_i along `wi` (1 for reflection). A failed
//!   sample has weight 0 and pdf 0. For non-delta lobes `weight == f |cos| / pdf` of `eval_pdf`
//!   at `wi`.
//! - **Radiance transport.** Refraction scales radiance by 1/eta^2 (Mitsuba's convention in its
//!   radiance mode): the transmitted weight and `f` include that factor, so a path through a glass
//!   slab carries its radiance unchanged.
//! - Inactive lanes return zeros; every lane is finite.

use crate::simd::{Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// Lobe flags as bits of a `u32`: a BSDF's [`Bsdf::FLAGS`] is the union of its lobes'; a sample's
/// [`Sample8::flags`] names the lobe drawn (one of reflection/transmission with one of
/// diffuse/glossy/delta).
pub mod flags {
    /// leaves on the side of wo
    pub const REFLECTION: u32 = 1;
    /// crosses the surface
    pub const TRANSMISSION: u32 = 2;
    /// a smooth density over directions, no peak
    pub const DIFFUSE: u32 = 4;
    /// a smooth density with a peak
    pub const GLOSSY: u32 = 8;
    /// a Dirac delta: only sampling finds it (no next event estimation, MIS weight 1)
    pub const DELTA: u32 = 16;
    /// delta reflection
    pub const DELTA_REFLECTION: u32 = REFLECTION | DELTA;
    /// delta transmission
    pub const DELTA_TRANSMISSION: u32 = TRANSMISSION | DELTA;
    /// diffuse reflection
    pub const DIFFUSE_REFLECTION: u32 = REFLECTION | DIFFUSE;
    /// glossy reflection
    pub const GLOSSY_REFLECTION: u32 = REFLECTION | GLOSSY;
    /// glossy transmission
    pub const GLOSSY_TRANSMISSION: u32 = TRANSMISSION | GLOSSY;
    /// Mitsuba's null lobe: the ray continues unchanged (`wi = -wo`, weight 1); sampled with
    /// [`DELTA`] and [`TRANSMISSION`], so integrators treat it as a delta transmission (it is a
    /// vertex of the path: it counts towards the depth, as in Mitsuba's path tracer)
    pub const NULL: u32 = 32;
    /// a null sample's flags
    pub const NULL_TRANSMISSION: u32 = NULL | DELTA | TRANSMISSION;
}

/// A parameter of a BSDF row that a texture can give per hit (the scene evaluates the texture
/// at the hit and writes the lane's slot, `scene/texturing.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Slot {
    /// [`BsdfParams::color`]`[i]`
    Color(u8),
    /// [`BsdfParams::scalar`]`[i]` (a colour texture's luminance)
    Scalar(u8),
    /// [`BsdfParams::opacity`] (luminance, clamped to [0, 1])
    Opacity,
}

/// Colour parameter slots of a BSDF row.
pub const COLORS: usize = 3;
/// Scalar parameter slots of a BSDF row.
pub const SCALARS: usize = 4;

/// Registry id of the course's materials (the format's kd + Phong/GGX, [`super::Material8`]):
/// lanes of this kind are shaded by the lobe sets, the others by the BSDF registry.
pub const COURSE: u32 = 0;

/// One BSDF's parameters, constant over a material: the registry kind, the sides, and slots whose
/// meaning each BSDF file documents (colours: reflectances, eta and k; scalars: IORs, roughness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfParams {
    /// registry id ([`Bsdf::ID`]; [`COURSE`] for the course's materials)
    pub kind: u32,
    /// shaded on both sides (the back mirrored onto the front)
    pub twosided: bool,
    /// colour slots
    pub color: [Vec3; COLORS],
    /// scalar slots
    pub scalar: [f32; SCALARS],
    /// Mitsuba's `mask` around the BSDF: the probability in [0, 1] that a hit scatters (1:
    /// opaque, the BSDF alone); with 1 - opacity the ray passes unchanged (`bsdf::mask`)
    pub opacity: f32,
}

impl BsdfParams {
    /// The course's material (two-sided, slots unused).
    pub const COURSE: Self =
        Self { kind: COURSE, twosided: true, color: [Vec3::ZERO; COLORS], scalar: [0.0; SCALARS], opacity: 1.0 };

    /// A one-sided, opaque row of BSDF `kind` with the given slots.
    pub const fn new(kind: u32, color: [Vec3; COLORS], scalar: [f32; SCALARS]) -> Self {
        Self { kind, twosided: false, color, scalar, opacity: 1.0 }
    }
}

impl Default for BsdfParams {
    /// [`BsdfParams::COURSE`].
    fn default() -> Self {
        Self::COURSE
    }
}

/// Eight lanes of [`BsdfParams`]: what a hit record carries per lane.
#[derive(Clone, Copy, Debug)]
pub struct Params8 {
    /// registry id per lane
    pub kind: U8,
    /// two-sided lanes
    pub twosided: Mask8,
    /// colour slots
    pub color: [Vec3x8; COLORS],
    /// scalar slots
    pub scalar: [F8; SCALARS],
    /// [`BsdfParams::opacity`] per lane
    pub opacity: F8,
}

impl Params8 {
    /// The course's material in every lane.
    pub const COURSE: Self = Self {
        kind: U8::ZERO,
        twosided: F8::ZERO,
        color: [Vec3x8::ZERO; COLORS],
        scalar: [F8::ZERO; SCALARS],
        opacity: F8::ONE,
    };

    /// One row in every lane.
    #[inline]
    pub fn splat(p: &BsdfParams) -> Self {
        Self {
            kind: U8::splat(p.kind),
            twosided: crate::simd::mask_from_bools([p.twosided; 8]),
            color: p.color.map(Vec3x8::splat),
            scalar: p.scalar.map(F8::splat),
            opacity: F8::splat(p.opacity),
        }
    }

    /// Eight rows, one per lane.
    pub fn from_lanes(p: [&BsdfParams; 8]) -> Self {
        Self {
            kind: U8::new(p.map(|p| p.kind)),
            twosided: crate::simd::mask_from_bools(p.map(|p| p.twosided)),
            color: std::array::from_fn(|c| Vec3x8::from_lanes(p.map(|p| p.color[c]))),
            scalar: std::array::from_fn(|c| F8::new(p.map(|p| p.scalar[c]))),
            opacity: F8::new(p.map(|p| p.opacity)),
        }
    }

    /// Lanes of kind `id`.
    #[inline]
    pub fn lanes_of(&self, id: u32) -> Mask8 {
        F8::from_bits(self.kind.simd_eq(U8::splat(id)))
    }
}

/// What [`Bsdf::sample`] returns per lane (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct Sample8 {
    /// sampled direction (unit; 0 on failed and inactive lanes)
    pub wi: Vec3x8,
    /// f |cos wi| / pdf (delta lobes: value / lobe probability); 0 for a failed sample
    pub weight: Vec3x8,
    /// solid-angle pdf (delta lobes: the lobe's probability); 0 for a failed sample
    pub pdf: F8,
    /// the sampled lobe's [`flags`]
    pub flags: U8,
    /// relative index eta_t / eta_i along wi (1 for reflection)
    pub eta: F8,
}

impl Sample8 {
    /// No sample in any lane.
    pub const NONE: Self =
        Self { wi: Vec3x8::ZERO, weight: Vec3x8::ZERO, pdf: F8::ZERO, flags: U8::ZERO, eta: F8::ONE };

    /// `self` on `m` lanes, `o` elsewhere.
    #[inline]
    pub fn select(m: Mask8, a: Self, o: Self) -> Self {
        Self {
            wi: Vec3x8::select(m, a.wi, o.wi),
            weight: Vec3x8::select(m, a.weight, o.weight),
            pdf: m.select(a.pdf, o.pdf),
            flags: m.select(F8::from_bits(a.flags), F8::from_bits(o.flags)).to_bits(),
            eta: m.select(a.eta, o.eta),
        }
    }

    /// Lanes whose sampled lobe has any of the `bits`.
    #[inline]
    pub fn has(&self, bits: u32) -> Mask8 {
        F8::from_bits(!(self.flags & U8::splat(bits)).simd_eq(U8::ZERO))
    }
}

/// One BSDF model, a registry entry (see the module docs for the conventions). Each lives in its
/// own file under `src/bsdf/` with its parameters' meaning, and one line of `registry!` in
/// `src/bsdf/mod.rs` lists it.
pub trait Bsdf: 'static {
    /// Registry id (distinct, 1..24; [`COURSE`] is 0): the value of [`BsdfParams::kind`].
    const ID: u32;
    /// Mitsuba's plugin name (`conductor`, `dielectric`, ...), in kernel names and `--stats`.
    const NAME: &'static str;
    /// Union of its lobes' [`flags`].
    const FLAGS: u32;
    /// The largest white-furnace albedo E[weight] the model may give (1: it gains no energy). A
    /// model that is not energy conserving by design (Burley's diffuse retro-reflection in
    /// `principled`) states its bound; the registry's furnace tests hold it to it.
    const ALBEDO_BOUND: f32 = 1.0;
    /// (f without the cosine, pdf of `sample` per solid angle) at (wo, wi) on `active` lanes.
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8);
    /// A direction from `u_lobe` (the lobe) and `u` (the direction) on `active` lanes.
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8;
    /// Parameter rows that parametrize the BSDF over its range, for the registry's generic tests
    /// (including the stiff cases: extreme indices, large k, roughness limits).
    fn test_params() -> Vec<BsdfParams>;
}

/// A registry entry as data: id, name, flags and its test parameter rows.
#[derive(Clone, Copy, Debug)]
pub struct Member {
    /// [`Bsdf::ID`]
    pub id: u32,
    /// [`Bsdf::NAME`]
    pub name: &'static str,
    /// [`Bsdf::FLAGS`]
    pub flags: u32,
    /// [`Bsdf::test_params`]
    pub test_params: fn() -> Vec<BsdfParams>,
    /// [`Bsdf::ALBEDO_BOUND`]
    pub albedo_bound: f32,
}

/// The [`super::Lobes`] bit of a registry id (the course lobes use the low 8 bits).
pub const fn bit(id: u32) -> u32 {
    1 << (8 + id)
}

/// A type-level list of BSDFs, `(A, (B, ()))`; kernels evaluate only the kinds of their list.
pub trait BsdfSet: 'static {
    /// [`bit`]s of the set.
    const BITS: u32;
    /// Union of the members' [`Bsdf::FLAGS`].
    const FLAGS: u32;
    /// On `active` lanes of each member's kind, its (f, pdf) replaces `acc`.
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8);
    /// On `active` lanes of each member's kind, its sample replaces `acc`.
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8, acc: Sample8) -> Sample8;
    /// The member's [`bit`] whose id is `kind`, or 0.
    fn bit_of(kind: u32) -> u32;
    /// The member's flags whose id is `kind`, or 0.
    fn flags_of(kind: u32) -> u32;
    /// Appends the names of the members whose bit is in `bits`.
    fn names(bits: u32, out: &mut Vec<&'static str>);
    /// Appends every member's entry (for the registry's generic tests and listings).
    fn members(out: &mut Vec<Member>);
}

impl BsdfSet for () {
    const BITS: u32 = 0;
    const FLAGS: u32 = 0;
    #[inline]
    fn eval_pdf(_: &Params8, _: Vec3x8, _: Vec3x8, _: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8) {
        acc
    }
    #[inline]
    fn sample(_: &Params8, _: Vec3x8, _: F8, _: [F8; 2], _: Mask8, acc: Sample8) -> Sample8 {
        acc
    }
    fn bit_of(_: u32) -> u32 {
        0
    }
    fn flags_of(_: u32) -> u32 {
        0
    }
    fn names(_: u32, _: &mut Vec<&'static str>) {}
    fn members(_: &mut Vec<Member>) {}
}

impl<H: Bsdf, T: BsdfSet> BsdfSet for (H, T) {
    const BITS: u32 = bit(H::ID) | T::BITS;
    const FLAGS: u32 = H::FLAGS | T::FLAGS;
    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8) {
        let lanes = active & p.lanes_of(H::ID);
        let (mut f, mut pdf) = acc;
        if lanes.any() {
            let (fh, ph) = H::eval_pdf(p, wo, wi, lanes);
            (f, pdf) = (Vec3x8::select(lanes, fh, f), lanes.select(ph, pdf));
        }
        T::eval_pdf(p, wo, wi, active, (f, pdf))
    }
    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8, acc: Sample8) -> Sample8 {
        let lanes = active & p.lanes_of(H::ID);
        let mut s = acc;
        if lanes.any() {
            s = Sample8::select(lanes, H::sample(p, wo, u_lobe, u, lanes), s);
        }
        T::sample(p, wo, u_lobe, u, active, s)
    }
    fn bit_of(kind: u32) -> u32 {
        if kind == H::ID {
            bit(H::ID)
        } else {
            T::bit_of(kind)
        }
    }
    fn flags_of(kind: u32) -> u32 {
        if kind == H::ID {
            H::FLAGS
        } else {
            T::flags_of(kind)
        }
    }
    fn names(bits: u32, out: &mut Vec<&'static str>) {
        if bits & bit(H::ID) != 0 {
            out.push(H::NAME);
        }
        T::names(bits, out);
    }
    fn members(out: &mut Vec<Member>) {
        out.push(Member {
            id: H::ID,
            name: H::NAME,
            flags: H::FLAGS,
            test_params: H::test_params,
            albedo_bound: H::ALBEDO_BOUND,
        });
        T::members(out);
    }
}

/// The lanes whose directions must be mirrored (z negated) between the shading frame that faces
/// the viewer (where `wo.z >= 0`) and the surface's own frame: the lanes hit from the `back` that
/// are not two-sided.
#[inline]
pub fn flip_to_surface(p: &Params8, back: Mask8) -> Mask8 {
    back & !p.twosided
}

/// `v` with z negated on `flip` lanes.
#[inline]
pub fn flip_z(v: Vec3x8, flip: Mask8) -> Vec3x8 {
    Vec3x8::new(v.x, v.y, flip.select(-v.z, v.z))
}

/// (f, pdf) of the members of `S` on `active` lanes, given in the viewer-facing shading frame
/// (`back`: lanes hit from the surface's back). Other lanes: zeros.
#[inline]
pub fn eval_pdf_x8<S: BsdfSet>(p: &Params8, back: Mask8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
    let flip = flip_to_surface(p, back);
    S::eval_pdf(p, flip_z(wo, flip), flip_z(wi, flip), active, (Vec3x8::ZERO, F8::ZERO))
}

/// A sample of the members of `S` on `active` lanes, in the viewer-facing shading frame (see
/// [`eval_pdf_x8`]). Other lanes: [`Sample8::NONE`].
#[inline]
pub fn sample_x8<S: BsdfSet>(p: &Params8, back: Mask8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
    let flip = flip_to_surface(p, back);
    let mut s = S::sample(p, flip_z(wo, flip), u_lobe, u, active, Sample8::NONE);
    s.wi = flip_z(s.wi, flip);
    s
}

/// `wi` reflected about +z: (-x, -y, z) of `wo`.
#[inline]
pub fn reflect_z(wo: Vec3x8) -> Vec3x8 {
    Vec3x8::new(-wo.x, -wo.y, wo.z)
}

/// `wo` refracted through the plane z = 0 with signed transmitted cosine `cos_t` and eta_i/eta_t
/// `eta_ti` (from [`super::fresnel::dielectric_x8`]).
#[inline]
pub fn refract_z(wo: Vec3x8, cos_t: F8, eta_ti: F8) -> Vec3x8 {
    Vec3x8::new(-eta_ti * wo.x, -eta_ti * wo.y, cos_t)
}

/// Lanes of `m` as `u32` flags: `bits` where set, 0 elsewhere.
#[inline]
pub fn flags_where(m: Mask8, bits: u32) -> U8 {
    m.to_bits() & U8::splat(bits)
}
