//! Ray and packet counters of a render, and the optional log of every packet traced (for
//! `strata rays`). Counted and logged in one place: [`super::context::Tracer`].

use crate::accel::{Ray8, RayHit8};
use crate::simd::Mask8;
use serde::Serialize;

/// Ray and packet counters of a render (summed over threads).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq, Eq)]
pub struct Counters {
    /// camera rays traced
    pub camera: u64,
    /// shadow rays traced
    pub shadow: u64,
    /// bounce rays traced
    pub bounce: u64,
    /// camera packets sent to Embree
    pub camera_packets: u64,
    /// shadow packets sent to Embree
    pub shadow_packets: u64,
    /// bounce packets sent to Embree
    pub bounce_packets: u64,
    /// samples whose value was not finite (replaced by zero; must stay 0)
    pub nonfinite: u64,
}

/// Which kind of ray a packet carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// primary rays from the camera
    Camera,
    /// path continuation rays
    Bounce,
    /// occlusion rays towards light samples
    Shadow,
}

impl Counters {
    /// Adds another set of counters.
    pub fn merge(&mut self, o: &Counters) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.bounce += o.bounce;
        self.camera_packets += o.camera_packets;
        self.shadow_packets += o.shadow_packets;
        self.bounce_packets += o.bounce_packets;
        self.nonfinite += o.nonfinite;
    }
    /// All rays traced.
    pub fn total_rays(&self) -> u64 {
        self.camera + self.shadow + self.bounce
    }
    /// All packets sent to Embree.
    pub fn packets(&self) -> u64 {
        self.camera_packets + self.shadow_packets + self.bounce_packets
    }
    /// Mean fraction of active lanes over all packets sent to Embree.
    pub fn occupancy(&self) -> f64 {
        ratio(self.total_rays(), 8 * self.packets())
    }
    /// Mean fraction of active lanes in bounce packets (paths past the first bounce).
    pub fn bounce_occupancy(&self) -> f64 {
        ratio(self.bounce, 8 * self.bounce_packets)
    }
    /// Mean fraction of active lanes in shadow packets.
    pub fn shadow_occupancy(&self) -> f64 {
        ratio(self.shadow, 8 * self.shadow_packets)
    }
    /// Mean number of rays traced per camera ray along a path (camera + bounce segments).
    pub fn mean_path_length(&self) -> f64 {
        ratio(self.camera + self.bounce, self.camera)
    }
    /// Counts one packet of `kind` whose traced lanes are `traced`.
    pub(crate) fn packet(&mut self, kind: RayKind, traced: Mask8) {
        self.count(kind, u64::from(traced.to_bitmask().count_ones()), 1);
    }

    /// Counts `packets` packets of `kind` that traced `rays` lanes in all.
    #[inline]
    pub(crate) fn count(&mut self, kind: RayKind, rays: u64, packets: u64) {
        let (r, p) = match kind {
            RayKind::Camera => (&mut self.camera, &mut self.camera_packets),
            RayKind::Bounce => (&mut self.bounce, &mut self.bounce_packets),
            RayKind::Shadow => (&mut self.shadow, &mut self.shadow_packets),
        };
        *r += rays;
        *p += packets;
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// Optional capture of every packet traced, for measuring Embree's raw rate on the same rays.
#[derive(Default)]
pub struct RayLog {
    /// camera packets (rays and their active masks)
    pub camera: Vec<(RayHit8, Mask8)>,
    /// bounce packets (path continuation rays)
    pub bounce: Vec<(RayHit8, Mask8)>,
    /// shadow packets
    pub shadow: Vec<(Ray8, Mask8)>,
}
