//! `all`: no choice. Next-event estimation samples every emitter, `lightsamples` points each
//! (the integrator loops over the lights): `sample` picks nothing and `pmf` is 1.

use super::{LightRule, RuleInfo};
use crate::light::emitters::Emitter;
use glam::Vec3;

/// Its entry in the registry [`super::RULES`].
pub(super) const INFO: RuleInfo =
    RuleInfo::new("all", "every light, `lightsamples` points each", build).every_light();

fn build(_: &[Emitter]) -> Box<dyn LightRule> {
    Box::new(All)
}

/// Every light, sampled by the integrator's loop.
#[derive(Debug)]
struct All;

impl LightRule for All {
    fn sample(&self, _: f32, _: Vec3, _: Vec3) -> Option<(u32, f32)> {
        None
    }
    fn sample_remap(&self, _: f32, _: Vec3, _: Vec3) -> Option<(u32, f32, f32)> {
        None
    }
    fn pmf(&self, _: Vec3, _: Vec3, _: u32) -> f32 {
        1.0
    }
    fn needs_point(&self) -> bool {
        false
    }
}
