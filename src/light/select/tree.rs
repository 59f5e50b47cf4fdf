//! The light tree behind the `spatial` rule ([`super::spatial`]): a binary BVH over the emitters whose
//! nodes carry a bound of position (bounding sphere of a box), power and emitting directions, and
//! a stochastic descent that picks a light by an importance bound at the shading point (Conty
//! Estévez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting"; the
//! node importance follows pbrt-v4's `LightBounds::Importance`, with the cosine bounds written so
//! that they are conservative in f32, see [`LightTree::importance`]).
//!
//! Every emitter is one leaf. Emitters of power 0 are left out (their pmf is 0, they never
//! contribute). For light `i`, `path[i]` holds the left/right turns from the root to its leaf.
//! Sampling runs in the tree collapsed to 8 children per node (`wide.rs`), where one 8-lane
//! importance evaluation serves a whole node and the pmf recomputes the descent's products.

use super::node::Node;
#[cfg(test)]
use super::node::{COS_FLOOR, COS_SLACK};
use super::wide::WideTree;
use crate::light::emitters::Emitter;
use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, PI};

/// Extra angle added to every orientation cone at build time (radians).
const CONE_SLACK: f32 = 1e-5;
/// Buckets per axis of the binned SAOH split.
const BUCKETS: usize = 12;
/// Depth from which splits are by median count, so that paths fit in 64 bits.
const MEDIAN_DEPTH: u32 = 40;

/// Light tree over the positive-power emitters of a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct LightTree {
    /// nodes, root first (empty without a positive-power emitter)
    pub nodes: Vec<Node>,
    /// per light: turns from the root (bit k set = right at depth k) and depth; depth `u8::MAX` for
    /// a light outside the tree (power 0)
    pub path: Vec<(u64, u8)>,
    /// the tree as sampled: collapsed to nodes of 8 children ([`super::wide`])
    pub wide: WideTree,
}

/// Build-time record of one emitter.
#[derive(Clone, Copy)]
struct Item {
    lo: Vec3,
    hi: Vec3,
    centroid: Vec3,
    power: f32,
    normal: Vec3,
    /// half angle of the item's own cone of normals: 0 for a polygon, pi for a sphere light
    theta: f32,
    light: u32,
}

/// Direction cone (axis, half angle) used while building.
#[derive(Clone, Copy, Debug)]
struct Cone {
    w: Vec3,
    theta: f32,
}

impl Cone {
    /// Smallest cone around both (the bounding-cone union of Conty Estévez and Kulla / pbrt-v4).
    fn union(a: Cone, b: Cone) -> Cone {
        let d = angle_between(a.w, b.w);
        if (d + b.theta).min(PI) <= a.theta {
            return a;
        }
        if (d + a.theta).min(PI) <= b.theta {
            return b;
        }
        let theta = 0.5 * (a.theta + d + b.theta);
        if theta >= PI {
            return Cone { w: a.w, theta: PI };
        }
        // Rotate a.w towards b.w by theta - theta_a in their common plane.
        let t = b.w - a.w * a.w.dot(b.w);
        if t.length_squared() <= 1e-20 {
            return Cone { w: a.w, theta: PI };
        }
        let t = t.normalize();
        let r = theta - a.theta;
        Cone { w: (a.w * r.cos() + t * r.sin()).normalize(), theta }
    }
}

fn angle_between(a: Vec3, b: Vec3) -> f32 {
    // Numerically stable form (small and near-pi angles).
    if a.dot(b) < 0.0 {
        PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

/// Solid-angle measure of a cone of normals with emission half angle pi/2 (Conty Estévez and
/// Kulla's M_Omega, theta_e = pi/2).
fn m_omega(theta_o: f32) -> f32 {
    let theta_w = (theta_o + FRAC_PI_2).min(PI);
    let (sin_o, cos_o) = theta_o.sin_cos();
    2.0 * PI * (1.0 - cos_o)
        + FRAC_PI_2 * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + cos_o)
}

fn bucket_of(c: f32, lo: f32, hi: f32) -> usize {
    (((c - lo) / (hi - lo) * BUCKETS as f32) as usize).min(BUCKETS - 1)
}

fn surface_area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

/// Build-time bounds of a set of items.
#[derive(Clone, Copy)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
    power: f64,
    cone: Option<Cone>,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { lo: Vec3::INFINITY, hi: Vec3::NEG_INFINITY, power: 0.0, cone: None };

    fn add(&mut self, it: &Item) {
        self.lo = self.lo.min(it.lo);
        self.hi = self.hi.max(it.hi);
        self.power += it.power as f64;
        let c = Cone { w: it.normal, theta: it.theta };
        self.cone = Some(self.cone.map_or(c, |a| Cone::union(a, c)));
    }

    fn merge(&mut self, o: &Bounds) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
        self.power += o.power;
        self.cone = match (self.cone, o.cone) {
            (Some(a), Some(b)) => Some(Cone::union(a, b)),
            (a, b) => a.or(b),
        };
    }

    /// SAOH cost (pbrt-v4's `EvaluateCost` without the axis regularization, applied by the caller).
    fn cost(&self) -> f32 {
        match self.cone {
            None => 0.0,
            Some(c) => self.power as f32 * m_omega(c.theta) * surface_area(self.lo, self.hi),
        }
    }
}

impl LightTree {
    /// Tree over `emitters` (lights of power 0 or with a non-finite power or geometry are left out).
    pub(crate) fn build(emitters: &[Emitter]) -> Self {
        let mut items: Vec<Item> = Vec::with_capacity(emitters.len());
        for (i, e) in emitters.iter().enumerate() {
            let power = e.power();
            let cs = e.corners();
            let finite = cs.iter().all(|c| c.is_finite()) && e.normal.is_finite();
            if !(power.is_finite() && power > 0.0 && finite && e.normal != Vec3::ZERO) {
                continue;
            }
            let lo = cs.iter().fold(Vec3::INFINITY, |m, &c| m.min(c));
            let hi = cs.iter().fold(Vec3::NEG_INFINITY, |m, &c| m.max(c));
            // A sphere light: its box, and normals in every direction.
            let (lo, hi, theta) = if e.sphere { (e.a - e.radius, e.a + e.radius, PI) } else { (lo, hi, 0.0) };
            items.push(Item { lo, hi, centroid: 0.5 * (lo + hi), power, normal: e.normal, theta, light: i as u32 });
        }
        let mut tree = LightTree {
            nodes: Vec::with_capacity(2 * items.len()),
            path: vec![(0, u8::MAX); emitters.len()],
            wide: WideTree::default(),
        };
        if items.is_empty() {
            return tree;
        }
        let total: f64 = items.iter().map(|it| it.power as f64).sum();
        tree.build_rec(&mut items, total, 0, 0);
        tree.wide = WideTree::build(&tree.nodes, emitters.len());
        tree
    }

    /// Appends the subtree of `items` (depth `depth`, turns `bits`) and returns its root index.
    fn build_rec(&mut self, items: &mut [Item], total: f64, depth: u32, bits: u64) -> u32 {
        let at = self.nodes.len() as u32;
        let node = Self::node_for(items, total);
        self.nodes.push(node);
        if items.len() == 1 {
            let light = items[0].light;
            self.nodes[at as usize].link = light;
            self.nodes[at as usize].leaf = true;
            self.path[light as usize] = (bits, depth as u8);
            return at;
        }
        let mid = if depth < MEDIAN_DEPTH { Self::saoh_split(items) } else { None };
        let mid = mid.unwrap_or_else(|| Self::median_split(items));
        let (l, r) = items.split_at_mut(mid);
        self.build_rec(l, total, depth + 1, bits);
        let right = self.build_rec(r, total, depth + 1, bits | (1u64 << depth));
        self.nodes[at as usize].link = right;
        at
    }

    /// Node bounds of `items`: box, relative power, and a cone whose half angle is the largest
    /// angle from its axis to any item's normal (exact for that axis, plus a margin).
    fn node_for(items: &[Item], total: f64) -> Node {
        let mut b = Bounds::EMPTY;
        items.iter().for_each(|it| b.add(it));
        let axis = b.cone.map_or(Vec3::Z, |c| c.w);
        let theta = items.iter().map(|it| angle_between(axis, it.normal) + it.theta).fold(0.0f32, f32::max);
        let theta = (theta + CONE_SLACK).min(PI);
        let (sin_o, cos_o) = if theta >= PI { (0.0, -1.0) } else { theta.sin_cos() };
        let center = 0.5 * (b.lo + b.hi);
        // Inflate the sphere for rounding of the corners and of points sampled on the lights.
        let half_diag = 0.5 * (b.hi - b.lo).length();
        let radius = half_diag * (1.0 + 1e-5) + 1e-6 * center.abs().max_element().max(half_diag);
        let phi = ((b.power / total) as f32).clamp(f32::MIN_POSITIVE, 1.0);
        Node { center, radius, phi, axis, cos_o, sin_o, link: 0, leaf: false }
    }

    /// Binned SAOH split (pbrt-v4 `BVHLightSampler::EvaluateCost` idea); `None` when no bucket
    /// boundary separates the centroids.
    fn saoh_split(items: &mut [Item]) -> Option<usize> {
        let (clo, chi) = items
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), it| (lo.min(it.centroid), hi.max(it.centroid)));
        let mut all = Bounds::EMPTY;
        items.iter().for_each(|it| all.add(it));
        let extent = all.hi - all.lo;
        let max_extent = extent.max_element();
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first bucket on the right)
        for dim in 0..3 {
            let (lo, hi) = (clo[dim], chi[dim]);
            if !(hi > lo) {
                continue;
            }
            let mut buckets = [Bounds::EMPTY; BUCKETS];
            for it in items.iter() {
                buckets[bucket_of(it.centroid[dim], lo, hi)].add(it);
            }
            let kr = if extent[dim] > 0.0 { max_extent / extent[dim] } else { 1.0 };
            // Suffix bounds, then a prefix sweep.
            let mut suffix = [Bounds::EMPTY; BUCKETS];
            let mut acc = Bounds::EMPTY;
            for k in (1..BUCKETS).rev() {
                acc.merge(&buckets[k]);
                suffix[k] = acc;
            }
            let mut bl = Bounds::EMPTY;
            for split in 1..BUCKETS {
                bl.merge(&buckets[split - 1]);
                let br = &suffix[split];
                if bl.cone.is_none() || br.cone.is_none() {
                    continue;
                }
                let cost = kr * (bl.cost() + br.cost());
                if cost.is_finite() && best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, dim, split));
                }
            }
        }
        let (_, dim, split_bucket) = best?;
        let (lo, hi) = (clo[dim], chi[dim]);
        let bucket = |c: f32| bucket_of(c, lo, hi);
        // Stable partition by bucket (keeps the build deterministic).
        let mut left: Vec<Item> = Vec::with_capacity(items.len());
        let mut right: Vec<Item> = Vec::with_capacity(items.len());
        for it in items.iter() {
            if bucket(it.centroid[dim]) < split_bucket {
                left.push(*it);
            } else {
                right.push(*it);
            }
        }
        if left.is_empty() || right.is_empty() {
            return None;
        }
        let mid = left.len();
        items[..mid].copy_from_slice(&left);
        items[mid..].copy_from_slice(&right);
        Some(mid)
    }

    /// Split at the median centroid along the widest centroid axis (coincident lights: by index).
    fn median_split(items: &mut [Item]) -> usize {
        let (lo, hi) = items
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), it| (lo.min(it.centroid), hi.max(it.centroid)));
        let e = hi - lo;
        let dim = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        items.sort_by(|a, b| a.centroid[dim].total_cmp(&b.centroid[dim]).then(a.light.cmp(&b.light)));
        items.len() / 2
    }

    /// Importance of `node` for a receiver at `p` whose integrand carries `max(0, n . wi)` (`n`
    /// unit; `Vec3::ZERO` for no receiver cosine): `phi * cos_e' * cos_i' / max(d^2, r^2)`.
    ///
    /// Why it is conservative: every point `y` of the node's lights lies in its bounding sphere, so
    /// the direction `p - y` is within `theta_b` of `p - c` (`sin theta_b = r / d`), and every
    /// emitting normal is within `theta_o` of the cone axis. By the triangle inequality on the
    /// sphere, the angle between `p - y` and a light's normal is at least `theta_w - theta_o -
    /// theta_b` (`theta_w` = angle from the axis to `p - c`), and the angle between `y - p` and `n`
    /// at least `theta_i - theta_b`. A light emits towards `p` only if the first angle is below
    /// pi/2 (one-sided, theta_e = pi/2), and the integrand is non-zero only if the second is, so
    /// whenever any light of the node can contribute both cosine bounds are positive. Cosines of
    /// differences are computed from cosines and sines (no acos), and a bound is declared 0 only
    /// below `-COS_SLACK`. Inside the bounding sphere both bounds are 1.
    ///
    /// This scalar form is the reference; the sampler evaluates the same bound for the 8 children
    /// of a collapsed node at once (`wide.rs`, `importance8`).
    #[cfg(test)]
    pub(crate) fn importance(node: &Node, p: Vec3, n: Vec3) -> f32 {
        let d = p - node.center;
        let d2 = d.length_squared();
        let r2 = node.radius * node.radius;
        if d2 <= r2 {
            return node.phi / r2.max(f32::MIN_POSITIVE);
        }
        let inv_d = d2.sqrt().recip();
        let wl = d * inv_d; // from the node towards p
        let sin_b = (node.radius * inv_d).min(1.0);
        let cos_b = (1.0 - sin_b * sin_b).max(0.0).sqrt();

        // Emitter side: cos(max(0, theta_w - theta_o - theta_b)).
        let cos_w = wl.dot(node.axis).clamp(-1.0, 1.0);
        let cos_e = if cos_w >= node.cos_o {
            1.0
        } else {
            let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
            let cos_x = cos_w * node.cos_o + sin_w * node.sin_o;
            let sin_x = (sin_w * node.cos_o - cos_w * node.sin_o).max(0.0);
            if cos_x >= cos_b {
                1.0
            } else {
                cos_x * cos_b + sin_x * sin_b
            }
        };
        if cos_e <= -COS_SLACK {
            return 0.0;
        }
        // Receiver side: cos(max(0, theta_i - theta_b)).
        let cos_r = if n == Vec3::ZERO {
            1.0
        } else {
            let cos_i = (-wl).dot(n).clamp(-1.0, 1.0);
            if cos_i >= cos_b {
                1.0
            } else {
                let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
                cos_i * cos_b + sin_i * sin_b
            }
        };
        if cos_r <= -COS_SLACK {
            return 0.0;
        }
        node.phi * cos_e.max(COS_FLOOR) * cos_r.max(COS_FLOOR) / d2
    }

    /// Light chosen by `u` in [0, 1) at `(p, n)` and its probability; `None` when no light of the
    /// tree can contribute (importance 0). Sampled in the collapsed tree ([`super::wide`]).
    #[inline]
    pub(crate) fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        self.wide.sample(u, p, n)
    }

    /// [`LightTree::sample`] with `u` remapped within the chosen light's interval.
    #[inline]
    pub(crate) fn sample_remap(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        self.wide.sample_remap(u, p, n)
    }

    /// Probability that [`LightTree::sample`] picks `light` at `(p, n)` (the same products).
    #[inline]
    pub(crate) fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        self.wide.pmf(p, n, light)
    }
}
