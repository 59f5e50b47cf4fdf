//! Light selection as a sampling technique: which emitter next-event estimation samples at a
//! shading point, and with what probability. pbrt-v4's `LightSampler` is the model: one type per
//! rule behind one trait, [`LightRule`] (`sample`, `pmf` at the shading point, `needs_point`),
//! one file per rule and one line per rule in the registry [`RULES`], which the CLI
//! (`--light-selection`: values and help), the `.test` parser and `--stats` read.
//!
//! - `all` ([`all`]): every emitter, `lightsamples` points each. There is no choice: the
//!   integrator loops over `0..len()`; `pmf` is 1 and `sample` returns `None`.
//! - `uniform` ([`uniform`]): `floor(u N)`, pmf `1/N`.
//! - `power` ([`power`]): pmf proportional to [`Emitter::power`] (an alias table over the
//!   positive-power emitters, O(1)); uniform if every power is 0.
//! - `spatial` ([`spatial`]): a light tree ([`tree`], sampled collapsed to 8 children per node,
//!   [`wide`]) descended stochastically by an importance bound at `(p, n)`; lights that cannot
//!   contribute at `p` may get pmf 0 and the sample may be `None` (no light can contribute: a
//!   zero contribution, not a failure).
//!
//! In every case `pmf(p, n, i)` is exactly (bit for bit) the probability `sample(u, p, n)` reports
//! when it returns `i`, and the x8 twins are bit-identical to the scalar functions per lane
//! (`tests.rs` checks both over the registry). `n` is the normal whose cosine `max(0, n . wi)`
//! clamps the integrand (the shading normal facing `wo`, as the integrators use it), unit length,
//! or `Vec3::ZERO` for no receiver-side bound (a surface that transmits). A rule that looks at `p`
//! and `n` says so with `needs_point` (the path tracer then keeps the previous vertex for the MIS
//! weight at a light hit); the x8 functions give every rule the lanes' own points.

mod node;
mod tree;
mod wide;

#[cfg(test)]
mod tests;

use super::emitters::{Emitter, Emitters, LightSample8};
use crate::simd::{mask_from_bools, mask_to_bools, Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// Declares the rule modules and lists their registry entries ([`RULES`]), in this order (the
/// CLI's and `--help`'s order).
macro_rules! registry {
    ($($module:ident: [$entry:ident]),+ $(,)?) => {
        $(mod $module;)+
        /// Every light-selection rule, in a fixed order.
        pub const RULES: &[RuleInfo] = &[$($module::$entry),+];
    };
}

registry! {
    all: [INFO],
    uniform: [INFO],
    power: [INFO],
    spatial: [INFO],
}

/// One light-selection rule built over a scene's emitters (numbered `0..N`, N > 0: the
/// [`LightSampler`] around it answers for an empty list and for indices out of range).
pub trait LightRule: Send + Sync + std::fmt::Debug {
    /// Light chosen by `u` in [0, 1) for a receiver at `p` with normal `n`, and its probability
    /// (> 0); `None` when the rule picks no light (`all`, or no light can contribute at `p`).
    fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)>;

    /// [`LightRule::sample`] for reuse of `u`: the light, its probability, and `u` remapped to
    /// [0, 1) within the light's interval of u (uniform given the light; stratified u stays
    /// stratified per light). The light's probability is `pmf`'s.
    fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)>;

    /// Probability that `sample` picks light `i < N` at `(p, n)`: bit-identical to the probability
    /// it returns (1 for `all`, whose loop samples every light).
    fn pmf(&self, p: Vec3, n: Vec3, i: u32) -> f32;

    /// The choice depends on the shading point `(p, n)`.
    fn needs_point(&self) -> bool;

    /// Eight-lane [`LightRule::sample`] over the `active` lanes, each at its own point: `(light,
    /// pmf)` per lane; lanes that are inactive or got `None` have pmf 0. The default runs the
    /// scalar function lane by lane; a rule may override it with the same arithmetic over 8 lanes.
    fn sample_x8(&self, u: F8, p: Vec3x8, n: Vec3x8, active: Mask8) -> (U8, F8) {
        let (on, us, ps, ns) = (mask_to_bools(active), u.to_array(), p.to_lanes(), n.to_lanes());
        let (mut idx, mut pmf) = ([0u32; 8], [0f32; 8]);
        for l in 0..8 {
            if on[l] {
                if let Some((i, q)) = self.sample(us[l], ps[l], ns[l]) {
                    (idx[l], pmf[l]) = (i, q);
                }
            }
        }
        (U8::new(idx), F8::new(pmf))
    }

    /// Eight-lane [`LightRule::sample_remap`]: `(light, pmf, remapped u)` per lane, pmf 0 on the
    /// lanes that are inactive or got `None` (see [`LightRule::sample_x8`] for the default).
    fn sample_remap_x8(&self, u: F8, p: Vec3x8, n: Vec3x8, active: Mask8) -> (U8, F8, F8) {
        let (on, us, ps, ns) = (mask_to_bools(active), u.to_array(), p.to_lanes(), n.to_lanes());
        let (mut idx, mut pmf, mut rest) = ([0u32; 8], [0f32; 8], [0f32; 8]);
        for l in 0..8 {
            if on[l] {
                if let Some((i, q, r)) = self.sample_remap(us[l], ps[l], ns[l]) {
                    (idx[l], pmf[l], rest[l]) = (i, q, r);
                }
            }
        }
        (U8::new(idx), F8::new(pmf), F8::new(rest))
    }

    /// Eight-lane [`LightRule::pmf`] at each lane's own point; 0 on inactive lanes (whose light
    /// may be out of range).
    fn pmf_x8(&self, p: Vec3x8, n: Vec3x8, light: U8, active: Mask8) -> F8 {
        let (on, ids, ps, ns) = (mask_to_bools(active), light.to_array(), p.to_lanes(), n.to_lanes());
        F8::new(std::array::from_fn(|l| if on[l] { self.pmf(ps[l], ns[l], ids[l]) } else { 0.0 }))
    }
}

/// A rule's registry entry: its name, its one line of help, and how to build it.
#[derive(Clone, Copy)]
pub struct RuleInfo {
    /// its name on the command line, in `.test` files and in stats
    pub name: &'static str,
    /// one line for `--help`
    pub description: &'static str,
    /// picks one light per sample (every rule but `all`, which loops over the lights)
    pub picks_one: bool,
    /// the rule over a scene's emitters (at least one)
    build: fn(&[Emitter]) -> Box<dyn LightRule>,
}

impl RuleInfo {
    /// Entry of a rule that picks one light per sample.
    pub const fn new(
        name: &'static str,
        description: &'static str,
        build: fn(&[Emitter]) -> Box<dyn LightRule>,
    ) -> Self {
        Self { name, description, picks_one: true, build }
    }

    /// The same entry for a rule that picks no light: the integrator samples every light.
    pub const fn every_light(self) -> Self {
        Self { picks_one: false, ..self }
    }
}

impl std::fmt::Debug for RuleInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// How next-event estimation chooses among the emitters: a handle into [`RULES`].
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct LightSelection(u8);

impl LightSelection {
    /// Every emitter, `lightsamples` points each (no selection).
    pub const ALL: Self = Self::named("all");
    /// One emitter, uniformly.
    pub const UNIFORM: Self = Self::named("uniform");

    /// The registered rule named `name` (a compile-time error in consts if there is none).
    pub const fn named(name: &str) -> Self {
        let mut i = 0;
        while i < RULES.len() {
            if crate::registry::same_name(RULES[i].name, name) {
                return Self(i as u8);
            }
            i += 1;
        }
        panic!("no light-selection rule of that name is registered")
    }

    /// Every registered rule, in registry order.
    pub fn every() -> impl Iterator<Item = Self> {
        (0..RULES.len() as u8).map(Self)
    }

    /// Registry entry of this rule.
    pub fn info(self) -> &'static RuleInfo {
        &RULES[self.0 as usize]
    }
    /// Name (`all`, `uniform`, ...).
    pub fn name(self) -> &'static str {
        self.info().name
    }
    /// One-line description.
    pub fn description(self) -> &'static str {
        self.info().description
    }
    /// Rule of a name (case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::every().find(|s| s.name().eq_ignore_ascii_case(name.trim()))
    }
    /// Every name, in registry order.
    pub fn names() -> impl Iterator<Item = &'static str> {
        RULES.iter().map(|i| i.name)
    }
    /// Picks one light per sample (everything but `all`).
    pub fn picks_one(self) -> bool {
        self.info().picks_one
    }
    /// The names with their descriptions, for help text ("all (every light ...), uniform (...)").
    pub fn help_list() -> String {
        RULES.iter().map(|i| format!("{} ({})", i.name, i.description)).collect::<Vec<_>>().join(", ")
    }
}

impl std::fmt::Display for LightSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Debug for LightSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A light-selection rule or light-choice mode name that is not registered.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} '{name}' (expected one of: {known})")]
pub struct UnknownName {
    /// what was named ("light selection", "light choice")
    pub what: &'static str,
    /// the name given
    pub name: String,
    /// the registered names, comma-separated
    pub known: String,
}

impl std::str::FromStr for LightSelection {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        Self::from_name(s).ok_or_else(|| UnknownName {
            what: "light selection",
            name: s.into(),
            known: Self::names().collect::<Vec<_>>().join(", "),
        })
    }
}

/// Where a one-light selection takes its choice from (`--light-choice`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightChoice {
    /// a 1D sampler dimension of its own, decorrelated from the light point's
    Dimension,
    /// Mitsuba's reuse: the light point's first coordinate u picks the light, and is remapped to
    /// [0, 1) within the light's interval of u, so the light point's 2D set stays stratified per
    /// light (one dimension fewer; the default)
    Reuse,
}

impl LightChoice {
    /// Every choice mode with its name, in a fixed order.
    pub const ALL: [(LightChoice, &'static str); 2] = [(Self::Reuse, "reuse"), (Self::Dimension, "dimension")];

    /// Name (`dimension`, `reuse`).
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(c, _)| *c == self).map(|(_, n)| *n).unwrap_or("reuse")
    }
}

impl std::str::FromStr for LightChoice {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        Self::ALL.iter().find(|(_, n)| n.eq_ignore_ascii_case(s.trim())).map(|(c, _)| *c).ok_or_else(|| UnknownName {
            what: "light choice",
            name: s.into(),
            known: Self::ALL.map(|(_, n)| n).join(", "),
        })
    }
}

/// Largest f32 below 1.
pub(crate) const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Light selection built once per scene from its emitters: a rule of the registry and the
/// emitters it numbers; no allocation per call.
#[derive(Debug)]
pub struct LightSampler {
    selection: LightSelection,
    /// index in the scene's emitter list of this sampler's light 0 (see [`LightSampler::over_range`])
    first: u32,
    n: u32,
    /// the rule (`None` without emitters)
    rule: Option<Box<dyn LightRule>>,
}

impl LightSampler {
    /// Sampler of `selection` over `emitters` (indices are positions in `emitters`).
    pub fn new(emitters: &[Emitter], selection: LightSelection) -> Self {
        let rule = (!emitters.is_empty()).then(|| (selection.info().build)(emitters));
        Self { selection, first: 0, n: emitters.len() as u32, rule }
    }

    /// Sampler of `selection` over the emitters `range` of the scene's list `emitters` (e.g.
    /// `direct`'s power choice among the emissive triangles under `all`). `sample`, `pmf` and
    /// `sample_remap` number the lights from the range's start; the `sample_point` functions
    /// place points on the right lights of the whole list. Not for MIS at a light hit, whose
    /// light ids are the whole list's.
    pub fn over_range(emitters: &[Emitter], range: std::ops::Range<usize>, selection: LightSelection) -> Self {
        let mut s = Self::new(&emitters[range.clone()], selection);
        s.first = range.start as u32;
        s
    }

    /// The rule.
    pub fn selection(&self) -> LightSelection {
        self.selection
    }

    /// Number of emitters.
    pub fn len(&self) -> usize {
        self.n as usize
    }

    /// No emitters.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The choice depends on the shading point: the MIS weight at a light hit needs the previous
    /// vertex's `p` and `n`.
    pub fn depends_on_point(&self) -> bool {
        self.rule.as_ref().is_some_and(|r| r.needs_point())
    }

    /// The choice is certain: one light, which the rule picks with pmf 1 wherever the shading
    /// point is. The integrators then place the point on it directly and draw no choice.
    pub fn certain(&self) -> bool {
        self.n == 1
            && self.selection.picks_one()
            && !self.depends_on_point()
            && self.pmf(Vec3::ZERO, Vec3::ZERO, 0) == 1.0
    }

    /// [`LightRule::sample`]; `None` without lights.
    #[inline]
    pub fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        self.rule.as_ref()?.sample(u, p, n)
    }

    /// [`LightRule::sample_remap`]; `None` without lights.
    #[inline]
    pub fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        self.rule.as_ref()?.sample_remap(u, p, n)
    }

    /// [`LightRule::pmf`]: 0 for an index out of range.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, i: u32) -> f32 {
        match &self.rule {
            Some(r) if i < self.n => r.pmf(p, n, i),
            _ => 0.0,
        }
    }

    /// [`LightSampler::sample_point_x8`] with the choice reused from the light point: the light
    /// chosen by `u` ([`LightSampler::sample_remap`]) and the point `(u', v)` on it, u' the
    /// remapped u, written into `out` (in place: the 448-byte sample is not copied out of a
    /// return). Inactive lanes and lanes without a light are off in the mask returned.
    #[inline]
    pub fn sample_point_reuse_x8(
        &self,
        emitters: &Emitters,
        p: Vec3x8,
        n: Vec3x8,
        active: Mask8,
        (u, v): (F8, F8),
        out: &mut LightSample8,
    ) -> Mask8 {
        let (idx, pmf, rest) = match &self.rule {
            Some(r) => r.sample_remap_x8(u, p, n, active),
            None => (U8::splat(0), F8::ZERO, F8::ZERO),
        };
        self.place_x8(emitters, idx, pmf, active, (rest, v), out)
    }

    /// A light per lane chosen by [`LightSampler::sample_x8`] with `u_choice`, and the point
    /// `(u, v)` on it (`emitters.place_into_x8`, with 1 / pmf in the sample), written into `out`; the
    /// mask returned is the `active` lanes that got a light (pmf > 0).
    #[inline]
    #[allow(clippy::too_many_arguments)] // the reuse form's six and the choice
    pub fn sample_point_x8(
        &self,
        emitters: &Emitters,
        u_choice: F8,
        p: Vec3x8,
        n: Vec3x8,
        active: Mask8,
        (u, v): (F8, F8),
        out: &mut LightSample8,
    ) -> Mask8 {
        let (idx, pmf) = self.sample_x8(u_choice, p, n, active);
        self.place_x8(emitters, idx, pmf, active, (u, v), out)
    }

    /// The chosen lights' points (`(u, v)` on light `idx`, 1 / pmf in the sample) into `out`;
    /// returns the active lanes that got a light (pmf > 0).
    #[inline]
    fn place_x8(
        &self,
        emitters: &Emitters,
        idx: U8,
        pmf: F8,
        active: Mask8,
        (u, v): (F8, F8),
        out: &mut LightSample8,
    ) -> Mask8 {
        let ok = active & pmf.simd_gt(F8::ZERO);
        let inv_pmf = ok.select(F8::ONE / pmf, F8::ONE);
        emitters.place_into_x8(idx + U8::splat(self.first), inv_pmf, u, v, out);
        ok
    }

    /// [`LightRule::sample_x8`]: `(light, pmf)` per lane; lanes that are inactive or got `None`
    /// give pmf 0 (test `pmf > 0` before using the light).
    pub fn sample_x8(&self, u: F8, p: Vec3x8, n: Vec3x8, active: Mask8) -> (U8, F8) {
        match &self.rule {
            Some(r) => r.sample_x8(u, p, n, active),
            None => (U8::splat(0), F8::ZERO),
        }
    }

    /// [`LightRule::pmf_x8`] at each lane's own point `(p, n)`; 0 on inactive lanes and for
    /// lights out of range.
    pub fn pmf_x8(&self, p: Vec3x8, n: Vec3x8, light: U8, active: Mask8) -> F8 {
        let Some(r) = &self.rule else { return F8::ZERO };
        let ids = light.to_array();
        let in_range = mask_from_bools(std::array::from_fn(|l| ids[l] < self.n));
        r.pmf_x8(p, n, light, active & in_range)
    }
}
