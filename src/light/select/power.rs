//! `power`: one light with probability proportional to its power ([`Emitter::power`]), drawn in
//! O(1) from Vose's alias table over the positive-power lights; uniform when no light has
//! positive power.

use super::uniform::Uniform;
use super::{LightRule, RuleInfo, ONE_MINUS};
use crate::light::emitters::Emitter;
use crate::simd::{mask_to_bools, Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// Its entry in the registry [`super::RULES`].
pub(super) const INFO: RuleInfo =
    RuleInfo::new("power", "one light in proportion to its power, by an alias table", build);

fn build(emitters: &[Emitter]) -> Box<dyn LightRule> {
    let (pmf, alias) = build_alias(emitters);
    Box::new(Power { pmf, alias, uniform: Uniform::new(emitters.len()) })
}

/// One slot of the alias table: stay with `light` when the fraction is below `q`, else `alias`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct AliasSlot {
    q: f32,
    light: u32,
    alias: u32,
}

/// The power pmf and its alias table.
#[derive(Debug)]
struct Power {
    /// probability of each light
    pmf: Vec<f32>,
    /// alias table over the positive-power lights (empty: every light dark, `uniform` instead)
    alias: Vec<AliasSlot>,
    /// the fallback when every light is dark
    uniform: Uniform,
}

impl Power {
    /// The light of `u`'s slot and `u` remapped to [0, 1) within the light's part of the slot.
    #[inline]
    fn pick(&self, u: f32) -> (u32, f32) {
        let m = self.alias.len();
        let x = u * m as f32;
        let j = (x as usize).min(m - 1);
        let frac = (x - j as f32).clamp(0.0, ONE_MINUS);
        let s = &self.alias[j];
        if frac < s.q {
            (s.light, frac / s.q)
        } else {
            (s.alias, (frac - s.q) / (1.0 - s.q))
        }
    }
}

impl LightRule for Power {
    #[inline]
    fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        if self.alias.is_empty() {
            return self.uniform.sample(u, p, n);
        }
        let (i, _) = self.pick(u);
        Some((i, self.pmf[i as usize]))
    }

    #[inline]
    fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        if self.alias.is_empty() {
            return self.uniform.sample_remap(u, p, n);
        }
        let (i, rest) = self.pick(u);
        Some((i, self.pmf[i as usize], rest.clamp(0.0, ONE_MINUS)))
    }

    #[inline]
    fn pmf(&self, p: Vec3, n: Vec3, i: u32) -> f32 {
        if self.alias.is_empty() {
            return self.uniform.pmf(p, n, i);
        }
        self.pmf[i as usize]
    }

    fn needs_point(&self) -> bool {
        false
    }

    /// Lane by lane, without the lanes' points (the choice does not look at them).
    fn pmf_x8(&self, _: Vec3x8, _: Vec3x8, light: U8, active: Mask8) -> F8 {
        let (on, ids) = (mask_to_bools(active), light.to_array());
        F8::new(std::array::from_fn(|l| if on[l] { self.pmf(Vec3::ZERO, Vec3::ZERO, ids[l]) } else { 0.0 }))
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
