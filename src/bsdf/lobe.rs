//! The lobe interface and lobe sets.
//!
//! A [`Lobe`] is one specular BRDF model of the format (the diffuse kd/pi term is shared by all
//! materials, see [`super::diffuse`]): its value and sampling density (computed together, they
//! share their costly terms) and its sampler, scalar and eight-lane, in the local shading frame.
//!
//! A [`LobeSet`] is a type-level list of lobes, `(A, (B, ()))`, that kernels are monomorphized
//! over: `Material8::eval_pdf_k::<L>` evaluates only the lobes of `L`. [`AllLobes`] is the list of
//! every lobe (the general kernel); [`Diffuse`], [`DiffusePhong`] and [`DiffuseGgx`] are the
//! specialized kernels compiled today (`integrator::kernel::with_lobe_set!` picks one; a scene whose
//! lobes match none of them runs `AllLobes`). [`Lobes`] is the runtime bit set of the lobes a
//! scene's materials have.
//!
//! Adding a lobe: its file (a type implementing [`Lobe`] with a new `BIT`), one entry in
//! [`AllLobes`], its tests (and, for a faster specialized kernel, one line in `with_lobe_set!`).

use super::interface::BsdfSet;
use super::material_types::{Material, Material8};
use crate::bsdf::desc::BrdfKind;
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// One specular lobe: f_spec and its sampler's pdf, and the sampler, in the local shading frame.
pub trait Lobe {
    /// Bit of this lobe in [`Lobes`] (distinct per lobe).
    const BIT: u32;
    /// Name in kernel names and `--stats` features (e.g. `phong`).
    const NAME: &'static str;
    /// The material model using this lobe.
    const KIND: BrdfKind;
    /// Whether a scene material needs this lobe compiled in (an exactly zero lobe does not).
    fn used_by(m: &crate::bsdf::desc::Material) -> bool;
    /// (f_spec RGB before the horizon test, pdf of [`Lobe::sample`] at wi).
    fn eval_pdf(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32);
    /// wi drawn from the lobe for u in [0,1)^2 (may lie below the horizon).
    fn sample(m: &Material, wo: Vec3, u: [f32; 2]) -> Vec3;
    /// Lanes of `m` whose model is this lobe.
    fn lanes(m: &Material8) -> Mask8;
    /// Eight-lane [`Lobe::eval_pdf`].
    fn eval_pdf_x8(m: &Material8, wo: Vec3x8, wi: Vec3x8) -> (Vec3x8, F8);
    /// Eight-lane [`Lobe::sample`] on `active` lanes.
    fn sample_x8(m: &Material8, wo: Vec3x8, u: [F8; 2], active: Mask8) -> Vec3x8;
}

/// A type-level list of lobes: `()` or `(L, Rest)`.
pub trait LobeSet: 'static {
    /// The [`Lobes`] bits of the set (its BSDFs' included).
    const BITS: u32;
    /// The registry BSDFs compiled in with the lobes (`()`: the course's materials only).
    type Bsdfs: BsdfSet;
    /// Scalar f_spec and pdf of the lobe of `m.kind` if it is in the set, else zero.
    fn eval_pdf(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32);
    /// Scalar sample of the lobe of `m.kind` (None if it is not in the set).
    fn sample(m: &Material, wo: Vec3, u: [f32; 2]) -> Option<Vec3>;
    /// Eight-lane f_spec and pdf: on the `active` lanes of each lobe of the set, its value
    /// replaces `acc`; other lanes keep `acc`. A lobe with no active lane costs nothing.
    fn eval_pdf_x8(m: &Material8, wo: Vec3x8, wi: Vec3x8, active: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8);
    /// Eight-lane sample: on the `spec` lanes of each lobe of the set, its sample replaces `wi`.
    fn sample_x8(m: &Material8, wo: Vec3x8, u: [F8; 2], spec: Mask8, wi: Vec3x8) -> Vec3x8;
    /// The lobes of the set that `m` uses, as [`Lobes`] bits.
    fn used_by(m: &crate::bsdf::desc::Material) -> u32;
    /// Appends the names of the lobes whose bit is in `bits`, in list order.
    fn names(bits: u32, out: &mut Vec<&'static str>);
    /// Whether lobe `L` is in the set.
    #[inline]
    fn has<L: Lobe>() -> bool {
        Self::BITS & L::BIT != 0
    }
}

impl LobeSet for () {
    const BITS: u32 = 0;
    type Bsdfs = ();
    #[inline]
    fn eval_pdf(_: &Material, _: Vec3, _: Vec3) -> (Vec3, f32) {
        (Vec3::ZERO, 0.0)
    }
    #[inline]
    fn sample(_: &Material, _: Vec3, _: [f32; 2]) -> Option<Vec3> {
        None
    }
    #[inline]
    fn eval_pdf_x8(_: &Material8, _: Vec3x8, _: Vec3x8, _: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8) {
        acc
    }
    #[inline]
    fn sample_x8(_: &Material8, _: Vec3x8, _: [F8; 2], _: Mask8, wi: Vec3x8) -> Vec3x8 {
        wi
    }
    fn used_by(_: &crate::bsdf::desc::Material) -> u32 {
        0
    }
    fn names(_: u32, _: &mut Vec<&'static str>) {}
}

impl<H: Lobe + 'static, T: LobeSet> LobeSet for (H, T) {
    const BITS: u32 = H::BIT | T::BITS;
    type Bsdfs = T::Bsdfs;
    #[inline]
    fn eval_pdf(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if m.kind == H::KIND {
            H::eval_pdf(m, wo, wi)
        } else {
            T::eval_pdf(m, wo, wi)
        }
    }
    #[inline]
    fn sample(m: &Material, wo: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if m.kind == H::KIND {
            Some(H::sample(m, wo, u))
        } else {
            T::sample(m, wo, u)
        }
    }
    #[inline]
    fn eval_pdf_x8(m: &Material8, wo: Vec3x8, wi: Vec3x8, active: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8) {
        let lanes = active & H::lanes(m);
        let (mut f, mut p) = acc;
        if lanes.any() {
            let (fh, ph) = H::eval_pdf_x8(m, wo, wi);
            (f, p) = (Vec3x8::select(lanes, fh, f), lanes.select(ph, p));
        }
        T::eval_pdf_x8(m, wo, wi, active, (f, p))
    }
    #[inline]
    fn sample_x8(m: &Material8, wo: Vec3x8, u: [F8; 2], spec: Mask8, wi: Vec3x8) -> Vec3x8 {
        let lanes = spec & H::lanes(m);
        let mut wi = wi;
        if lanes.any() {
            wi = Vec3x8::select(lanes, H::sample_x8(m, wo, u, lanes), wi);
        }
        T::sample_x8(m, wo, u, spec, wi)
    }
    fn used_by(m: &crate::bsdf::desc::Material) -> u32 {
        (if H::used_by(m) { H::BIT } else { 0 }) | T::used_by(m)
    }
    fn names(bits: u32, out: &mut Vec<&'static str>) {
        if bits & H::BIT != 0 {
            out.push(H::NAME);
        }
        T::names(bits, out);
    }
}

/// The end of a lobe list that compiles in the registry BSDFs `B` (no course lobe of its own).
pub struct WithBsdfs<B>(std::marker::PhantomData<B>);

impl<B: BsdfSet> LobeSet for WithBsdfs<B> {
    const BITS: u32 = B::BITS;
    type Bsdfs = B;
    #[inline]
    fn eval_pdf(_: &Material, _: Vec3, _: Vec3) -> (Vec3, f32) {
        (Vec3::ZERO, 0.0)
    }
    #[inline]
    fn sample(_: &Material, _: Vec3, _: [f32; 2]) -> Option<Vec3> {
        None
    }
    #[inline]
    fn eval_pdf_x8(_: &Material8, _: Vec3x8, _: Vec3x8, _: Mask8, acc: (Vec3x8, F8)) -> (Vec3x8, F8) {
        acc
    }
    #[inline]
    fn sample_x8(_: &Material8, _: Vec3x8, _: [F8; 2], _: Mask8, wi: Vec3x8) -> Vec3x8 {
        wi
    }
    fn used_by(m: &crate::bsdf::desc::Material) -> u32 {
        let mask = if super::mask::masked(&m.bsdf) { B::bit_of(<super::Mask as super::Bsdf>::ID) } else { 0 };
        B::bit_of(m.bsdf.kind) | mask
    }
    fn names(bits: u32, out: &mut Vec<&'static str>) {
        B::names(bits, out)
    }
}

/// Every lobe and every registry BSDF: the general kernel's set. A new lobe is added here (a new
/// BSDF to the `registry!` of `bsdf/mod.rs`).
pub type AllLobes = (super::Phong, (super::Ggx, WithBsdfs<super::AllBsdfs>));
/// Diffuse only (no specular lobe compiled in).
pub type Diffuse = ();
/// Diffuse and modified Phong.
pub type DiffusePhong = (super::Phong, ());
/// Diffuse and GGX.
pub type DiffuseGgx = (super::Ggx, ());

/// The specular lobes a scene's materials have, decided at load time, as a bit set of
/// [`Lobe::BIT`]s; kernels are compiled for them (`Material8::*_k::<L>`).
///
/// The promise a kernel relies on: a lobe left out of the set is exactly zero and never picked by
/// BRDF sampling on every material of the scene (a Phong material without it has ks = 0, so t = 0;
/// no material is GGX without the GGX lobe). Under that promise the compiled-out lobes change
/// nothing, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lobes(
    /// the [`Lobe::BIT`]s of the lobes present
    pub u32,
);

impl Lobes {
    /// Every lobe compiled in: the general kernel, right for any scene.
    pub const ALL: Self = Self(<AllLobes as LobeSet>::BITS);

    /// The lobes of a set of materials.
    pub fn of<'a>(materials: impl IntoIterator<Item = &'a crate::bsdf::desc::Material>) -> Self {
        Self(materials.into_iter().fold(0, |b, m| b | AllLobes::used_by(m)))
    }

    /// Whether lobe `L` is in the set.
    pub fn has<L: Lobe>(self) -> bool {
        self.0 & L::BIT != 0
    }

    /// Names of the lobes in the set, in [`AllLobes`] order.
    pub fn names(self) -> Vec<&'static str> {
        let mut v = Vec::new();
        AllLobes::names(self.0, &mut v);
        v
    }
}
