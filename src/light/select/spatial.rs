//! `spatial`: one light by a light tree's importance at the shading point (Conty Estévez and
//! Kulla 2018): the tree is [`super::tree`], sampled collapsed to 8 children per node
//! ([`super::wide`]). Lights that cannot contribute at `p` may get pmf 0, and the sample may be
//! `None` (no light can contribute: a zero contribution, not a failure).

use super::tree::LightTree;
use super::{LightRule, RuleInfo};
use crate::light::emitters::Emitter;
use glam::Vec3;

/// Its entry in the registry [`super::RULES`].
pub(super) const INFO: RuleInfo = RuleInfo::new(
    "spatial",
    "one light by a light tree's importance at the shading point, after Conty Estevez & Kulla 2018",
    build,
);

fn build(emitters: &[Emitter]) -> Box<dyn LightRule> {
    Box::new(Spatial { tree: LightTree::build(emitters) })
}

/// The light tree over the emitters.
#[derive(Debug)]
struct Spatial {
    tree: LightTree,
}

impl LightRule for Spatial {
    #[inline]
    fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        self.tree.sample(u, p, n)
    }
    #[inline]
    fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        self.tree.sample_remap(u, p, n)
    }
    #[inline]
    fn pmf(&self, p: Vec3, n: Vec3, i: u32) -> f32 {
        self.tree.pmf(p, n, i)
    }
    fn needs_point(&self) -> bool {
        true
    }
}
