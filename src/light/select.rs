//! Light selection as a sampling technique: which emitter next-event estimation samples at a
//! shading point, and with what probability.
//!
//! - [`LightSelection::All`]: every emitter, `lightsamples` points each (the course's convention).
//!   There is no choice: the integrator loops over `0..len()`; [`LightSampler::pmf`] is 1 and
//!   [`LightSampler::sample`] returns `None`.
//! - [`LightSelection::Uniform`]: `floor(u N)`, pmf `1/N`.
//! - [`LightSelection::Power`]: pmf proportional to [`Emitter::power`] (an alias table over the
//!   positive-power emitters, O(1)); uniform if every power is 0.
//! - [`LightSelection::Spatial`]: a light tree ([`tree`]) descended stochastically by an importance
//!   bound at `(p, n)`; lights that cannot contribute at `p` may get pmf 0 and the sample may be
//!   `None` (no light can contribute: a zero contribution, not a failure).
//!
//! In every case `pmf(p, n, i)` is exactly (bit for bit) the probability `sample(u, p, n)` reports
//! when it returns `i`, and the x8 twins are bit-identical to the scalar functions per lane. `n` is
//! the normal whose cosine `max(0, n . wi)` clamps the integrand (the shading normal facing `wo`, as
//! the integrators use it), unit length, or `Vec3::ZERO` for no receiver-side bound (a surface
//! that transmits). Only `Spatial` looks at `p` and `n`.

#[path = "tree.rs"]
mod tree;
#[path = "wide.rs"]
mod wide;

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;

use super::emitters::{Emitter, Emitters, LightSample8};
use crate::simd::{mask_to_bools, Mask8, Vec3x8, F8, U8};
use glam::Vec3;
use tree::LightTree;

/// How next-event estimation chooses among the emitters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightSelection {
    /// every emitter, `lightsamples` points each (no selection)
    All,
    /// one emitter, uniformly
    Uniform,
    /// one emitter, in proportion to its power
    Power,
    /// one emitter, by a light tree's importance at the shading point
    Spatial,
}

/// Name and one-line description of a light-selection technique (CLI, `.test`, stats).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SelectionInfo {
    /// the technique
    pub selection: LightSelection,
    /// its name on the command line, in `.test` files and in stats
    pub name: &'static str,
    /// one line for `--help`
    pub description: &'static str,
}

/// Every light-selection technique, in a fixed order.
pub const LIGHT_SELECTIONS: [SelectionInfo; 4] = [
    SelectionInfo {
        selection: LightSelection::All,
        name: "all",
        description: "every light, `lightsamples` points each (the course's convention)",
    },
    SelectionInfo {
        selection: LightSelection::Uniform,
        name: "uniform",
        description: "one light, uniformly (pmf 1/N)",
    },
    SelectionInfo {
        selection: LightSelection::Power,
        name: "power",
        description: "one light in proportion to its power (alias table)",
    },
    SelectionInfo {
        selection: LightSelection::Spatial,
        name: "spatial",
        description: "one light by a light tree's importance at the shading point (Conty Estevez & Kulla 2018)",
    },
];

impl LightSelection {
    /// Registry entry of this technique.
    pub fn info(self) -> &'static SelectionInfo {
        LIGHT_SELECTIONS.iter().find(|i| i.selection == self).expect("every selection is registered")
    }
    /// Name (`all`, `uniform`, `power`, `spatial`).
    pub fn name(self) -> &'static str {
        self.info().name
    }
    /// One-line description.
    pub fn description(self) -> &'static str {
        self.info().description
    }
    /// Technique of a name (case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        LIGHT_SELECTIONS.iter().find(|i| i.name.eq_ignore_ascii_case(name.trim())).map(|i| i.selection)
    }
    /// Every name, in registry order.
    pub fn names() -> impl Iterator<Item = &'static str> {
        LIGHT_SELECTIONS.iter().map(|i| i.name)
    }
    /// Picks one light per sample (everything but `All`).
    pub fn picks_one(self) -> bool {
        self != LightSelection::All
    }
}

impl std::fmt::Display for LightSelection {
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

/// One slot of the alias table: stay with `light` when the fraction is below `q`, else `alias`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct AliasSlot {
    q: f32,
    light: u32,
    alias: u32,
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Light selection built once per scene from its emitters; no allocation per call.
#[derive(Clone, Debug, PartialEq)]
pub struct LightSampler {
    selection: LightSelection,
    /// index in the scene's emitter list of this sampler's light 0 (see [`LightSampler::over_range`])
    first: u32,
    n: u32,
    inv_n: f32,
    /// `Power`: probability of each light
    power_pmf: Vec<f32>,
    /// `Power`: alias table over the positive-power lights (empty: uniform fallback)
    alias: Vec<AliasSlot>,
    /// `Spatial`: the light tree
    tree: LightTree,
}

impl LightSampler {
    /// Sampler of `selection` over `emitters` (indices are positions in `emitters`).
    pub fn new(emitters: &[Emitter], selection: LightSelection) -> Self {
        let n = emitters.len() as u32;
        let inv_n = if n > 0 { 1.0 / n as f32 } else { 0.0 };
        let mut s = Self {
            selection,
            first: 0,
            n,
            inv_n,
            power_pmf: Vec::new(),
            alias: Vec::new(),
            tree: LightTree::default(),
        };
        match selection {
            LightSelection::Power => (s.power_pmf, s.alias) = build_alias(emitters),
            LightSelection::Spatial => s.tree = LightTree::build(emitters),
            LightSelection::All | LightSelection::Uniform => {}
        }
        s
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

    /// The technique.
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

    /// The choice depends on the shading point (`Spatial`): the MIS weight at a light hit needs the
    /// previous vertex's `p` and `n`.
    pub fn depends_on_point(&self) -> bool {
        self.selection == LightSelection::Spatial
    }

    /// Light chosen by `u` in [0, 1) for a receiver at `p` with normal `n`, and its probability
    /// (> 0). `None` for `All` (loop over the lights instead), without lights, or when no light can
    /// contribute at `p` (`Spatial`).
    #[inline]
    pub fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        if self.n == 0 {
            return None;
        }
        match self.selection {
            LightSelection::All => None,
            LightSelection::Uniform => Some((self.uniform_index(u), self.inv_n)),
            LightSelection::Power => {
                if self.alias.is_empty() {
                    return Some((self.uniform_index(u), self.inv_n));
                }
                let i = self.alias_pick(u);
                Some((i, self.power_pmf[i as usize]))
            }
            LightSelection::Spatial => self.tree.sample(u, p, n),
        }
    }

    /// [`LightSampler::sample`] for reuse of `u`: the light, its probability, and `u` remapped to
    /// [0, 1) within the light's interval of u (uniform given the light; stratified u stays
    /// stratified per light). The light and pmf equal `sample`'s for uniform and spatial choice;
    /// for power choice they follow the same alias table (same pmf).
    #[inline]
    pub fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        if self.n == 0 {
            return None;
        }
        let uniform = |u: f32| {
            let x = u * self.n as f32;
            let i = (x as u32).min(self.n - 1);
            (i, self.inv_n, (x - i as f32).clamp(0.0, ONE_MINUS))
        };
        match self.selection {
            LightSelection::All => None,
            LightSelection::Uniform => Some(uniform(u)),
            LightSelection::Power if self.alias.is_empty() => Some(uniform(u)),
            LightSelection::Power => {
                let m = self.alias.len();
                let x = u * m as f32;
                let j = (x as usize).min(m - 1);
                let frac = (x - j as f32).clamp(0.0, ONE_MINUS);
                let s = &self.alias[j];
                let (i, rest) = if frac < s.q { (s.light, frac / s.q) } else { (s.alias, (frac - s.q) / (1.0 - s.q)) };
                Some((i, self.power_pmf[i as usize], rest.clamp(0.0, ONE_MINUS)))
            }
            LightSelection::Spatial => self.tree.sample_remap(u, p, n),
        }
    }

    /// [`LightSampler::sample_point_x8`] with the choice reused from the light point: the light
    /// chosen by `u` ([`LightSampler::sample_remap`]) and the point `(u', v)` on it, u' the
    /// remapped u. Inactive lanes and lanes without a light get light 0 and are off in the mask.
    #[inline]
    pub fn sample_point_reuse_x8(
        &self,
        emitters: &Emitters,
        p: Vec3x8,
        n: Vec3x8,
        active: Mask8,
        (u, v): (F8, F8),
    ) -> (LightSample8, Mask8) {
        let on = mask_to_bools(active);
        let (idx, pmf, rest) = if self.selection == LightSelection::Uniform && self.n > 0 {
            // Lane-wise, the scalar arithmetic.
            let x = u * F8::splat(self.n as f32);
            let i = x.to_array().map(|x| (x as u32).min(self.n - 1));
            let fi = F8::new(i.map(|i| i as f32));
            let rest = (x - fi).max(F8::ZERO).min(F8::splat(ONE_MINUS));
            (U8::new(i), active.select(F8::splat(self.inv_n), F8::ZERO), rest)
        } else {
            let (us, ps, ns) = (u.to_array(), p.to_lanes(), n.to_lanes());
            let (mut idx, mut pmf, mut rest) = ([0u32; 8], [0f32; 8], [0f32; 8]);
            for l in 0..8 {
                if on[l] {
                    if let Some((i, q, r)) = self.sample_remap(us[l], ps[l], ns[l]) {
                        (idx[l], pmf[l], rest[l]) = (i, q, r);
                    }
                }
            }
            (U8::new(idx), F8::new(pmf), F8::new(rest))
        };
        let ok = active & pmf.simd_gt(F8::ZERO);
        let inv_pmf = ok.select(F8::ONE / pmf, F8::ONE);
        (emitters.place_x8(idx + U8::splat(self.first), inv_pmf, rest, v), ok)
    }

    /// Probability that [`LightSampler::sample`] picks light `i` at `(p, n)`: bit-identical to
    /// the probability it returns (0 for an index out of range; 1 for `All`, whose loop samples
    /// every light).
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, i: u32) -> f32 {
        if i >= self.n {
            return 0.0;
        }
        match self.selection {
            LightSelection::All => 1.0,
            LightSelection::Uniform => self.inv_n,
            LightSelection::Power => {
                if self.alias.is_empty() {
                    self.inv_n
                } else {
                    self.power_pmf[i as usize]
                }
            }
            LightSelection::Spatial => self.tree.pmf(p, n, i),
        }
    }

    /// A light per lane chosen by [`LightSampler::sample_x8`] with `u_choice`, and the point
    /// `(u, v)` on it (`emitters.place_x8`, with 1 / pmf in the sample); the mask is the `active`
    /// lanes that got a light (pmf > 0).
    #[inline]
    pub fn sample_point_x8(
        &self,
        emitters: &Emitters,
        u_choice: F8,
        p: Vec3x8,
        n: Vec3x8,
        active: Mask8,
        (u, v): (F8, F8),
    ) -> (LightSample8, Mask8) {
        let (idx, pmf) = self.sample_x8(u_choice, p, n, active);
        let ok = active & pmf.simd_gt(F8::ZERO);
        let inv_pmf = ok.select(F8::ONE / pmf, F8::ONE);
        (emitters.place_x8(idx + U8::splat(self.first), inv_pmf, u, v), ok)
    }

    /// Eight-lane [`LightSampler::sample`]: `(light, pmf)` per lane; lanes that are inactive or
    /// got `None` give light 0 and pmf 0 (test `pmf > 0` before using the light).
    pub fn sample_x8(&self, u: F8, p: Vec3x8, n: Vec3x8, active: Mask8) -> (U8, F8) {
        let on = mask_to_bools(active);
        if self.n == 0 || self.selection == LightSelection::All {
            return (U8::splat(0), F8::ZERO);
        }
        if self.selection == LightSelection::Uniform
            || (self.selection == LightSelection::Power && self.alias.is_empty())
        {
            // The scalar arithmetic, lane-wise: x = u * N rounds the same way.
            let x = (u * F8::splat(self.n as f32)).to_array();
            let idx = std::array::from_fn(|l| if on[l] { (x[l] as u32).min(self.n - 1) } else { 0 });
            return (U8::new(idx), active.select(F8::splat(self.inv_n), F8::ZERO));
        }
        let (us, ps, ns) = (u.to_array(), p.to_lanes(), n.to_lanes());
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

    /// Eight-lane [`LightSampler::pmf`]; 0 on inactive lanes.
    pub fn pmf_x8(&self, p: Vec3x8, n: Vec3x8, light: U8, active: Mask8) -> F8 {
        let on = mask_to_bools(active);
        let ids = light.to_array();
        if self.selection != LightSelection::Spatial {
            return F8::new(std::array::from_fn(
                |l| if on[l] { self.pmf(Vec3::ZERO, Vec3::ZERO, ids[l]) } else { 0.0 },
            ));
        }
        let (ps, ns) = (p.to_lanes(), n.to_lanes());
        F8::new(std::array::from_fn(|l| if on[l] { self.tree.pmf(ps[l], ns[l], ids[l]) } else { 0.0 }))
    }

    #[inline]
    fn uniform_index(&self, u: f32) -> u32 {
        ((u * self.n as f32) as u32).min(self.n - 1)
    }

    #[inline]
    fn alias_pick(&self, u: f32) -> u32 {
        let m = self.alias.len();
        let x = u * m as f32;
        let j = (x as usize).min(m - 1);
        let frac = (x - j as f32).clamp(0.0, ONE_MINUS);
        let s = &self.alias[j];
        if frac < s.q {
            s.light
        } else {
            s.alias
        }
    }
}

/// Power pmf of every light and Vose's alias table over the positive-power ones (f64 while
/// building; a light of power 0 is in no slot). Both empty when no light has positive power.
fn build_alias(emitters: &[Emitter]) -> (Vec<f32>, Vec<AliasSlot>) {
    let w: Vec<f64> = emitters
        .iter()
        .map(|e| {
            let p = e.power();
            if p.is_finite() && p > 0.0 {
                p as f64
            } else {
                0.0
            }
        })
        .collect();
    let total: f64 = w.iter().sum();
    if !(total > 0.0) {
        return (Vec::new(), Vec::new());
    }
    let pmf: Vec<f32> = w.iter().map(|&x| (x / total) as f32).collect();
    let live: Vec<u32> = (0..w.len() as u32).filter(|&i| w[i as usize] > 0.0).collect();
    let m = live.len();
    // Scaled probabilities: mean 1 over the m slots.
    let mut scaled: Vec<f64> = live.iter().map(|&i| w[i as usize] / total * m as f64).collect();
    let mut slots: Vec<AliasSlot> = live.iter().map(|&i| AliasSlot { q: 1.0, light: i, alias: i }).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..m).partition(|&k| scaled[k] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        slots[s].q = scaled[s] as f32;
        slots[s].alias = live[l];
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // Leftovers (rounding) keep themselves with probability 1; all have positive power.
    for k in small.into_iter().chain(large) {
        slots[k].q = 1.0;
        slots[k].alias = live[k];
    }
    (pmf, slots)
}
