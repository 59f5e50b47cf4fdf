//! The light tree as sampled: the binary tree of [`super::tree`] collapsed into nodes of up to 8
//! children whose bounds are stored lane by lane, so that one 8-lane evaluation gives the
//! importance of every child of a node (the same bound as
//! [`super::tree::LightTree::importance`], written over [`F8`]). A descent of the 2500-light scene
//! takes ~4 such steps instead of ~12 binary steps of two scalar importances each.
//!
//! A node's children are found by repeatedly opening the interior node of highest power among
//! them, starting from the binary node's two children, until there are 8 (or only leaves). The
//! probability of child `c` of a node is `imp[c] / sum(imp)`; the descent and [`WideTree::pmf`]
//! compute the very same products, so the pmf stays exact.

use super::node::{Node, COS_FLOOR, COS_SLACK};
use super::ONE_MINUS;
use crate::simd::{Vec3x8, F8};
use glam::Vec3;

/// Children per node (the lane count).
const WIDTH: usize = 8;

/// Lane-wise dot product in glam's scalar order, without fused multiply-adds, so that every lane
/// equals the scalar bound bit for bit.
#[inline]
fn dot(a: Vec3x8, b: Vec3x8) -> F8 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// One node: its children's bounds, lane by lane (empty lanes have power 0, importance 0).
#[derive(Clone, Debug)]
pub(crate) struct WideNode {
    center: Vec3x8,
    radius: F8,
    phi: F8,
    axis: Vec3x8,
    cos_o: F8,
    sin_o: F8,
    /// per child: index of its node, or the light for a leaf
    pub(crate) child: [u32; WIDTH],
    /// bit c set: child c is a leaf (one light)
    pub(crate) leaf: u8,
}

impl PartialEq for WideNode {
    fn eq(&self, o: &Self) -> bool {
        let v = |a: &Vec3x8| a.to_lanes();
        let f = |a: &F8| a.to_array().map(f32::to_bits);
        (v(&self.center), v(&self.axis)) == (v(&o.center), v(&o.axis))
            && [f(&self.radius), f(&self.phi), f(&self.cos_o), f(&self.sin_o)]
                == [f(&o.radius), f(&o.phi), f(&o.cos_o), f(&o.sin_o)]
            && (self.child, self.leaf) == (o.child, o.leaf)
    }
}

/// The collapsed tree: nodes (root first) and, per light, its slots from the root.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct WideTree {
    pub(crate) nodes: Vec<WideNode>,
    /// per light: (start in `slots`, depth); depth `u8::MAX` for a light outside the tree
    path: Vec<(u32, u8)>,
    slots: Vec<u8>,
}

impl WideTree {
    /// Collapses the binary tree `bin` (depth-first, left child of `k` at `k + 1`) over `n_lights`.
    pub(crate) fn build(bin: &[Node], n_lights: usize) -> Self {
        let mut t = WideTree { nodes: Vec::new(), path: vec![(0, u8::MAX); n_lights], slots: Vec::new() };
        if bin.is_empty() {
            return t;
        }
        let mut stack = Vec::new();
        t.build_rec(bin, 0, &mut stack);
        t
    }

    /// The children of binary node `k`: itself if it is a leaf, else its subtree opened up to 8.
    pub(crate) fn frontier(bin: &[Node], k: usize) -> Vec<usize> {
        if bin[k].leaf {
            return vec![k];
        }
        let mut f = vec![k + 1, bin[k].link as usize];
        while f.len() < WIDTH {
            // Open the interior child of highest power (first on ties).
            let best =
                f.iter().enumerate().filter(|(_, &j)| !bin[j].leaf).fold(None, |b: Option<(usize, f32)>, (i, &j)| {
                    if b.is_none_or(|(_, phi)| bin[j].phi > phi) {
                        Some((i, bin[j].phi))
                    } else {
                        b
                    }
                });
            let Some((i, _)) = best else { break };
            let j = f[i];
            f.splice(i..=i, [j + 1, bin[j].link as usize]);
        }
        f
    }

    fn build_rec(&mut self, bin: &[Node], k: usize, stack: &mut Vec<u8>) -> u32 {
        let at = self.nodes.len() as u32;
        let kids = Self::frontier(bin, k);
        let lane =
            |f: &dyn Fn(&Node) -> f32| F8::new(std::array::from_fn(|c| kids.get(c).map_or(0.0, |&j| f(&bin[j]))));
        let v3 = |f: &dyn Fn(&Node) -> Vec3| {
            Vec3x8::from_lanes(std::array::from_fn(|c| kids.get(c).map_or(Vec3::ZERO, |&j| f(&bin[j]))))
        };
        let leaf = kids.iter().enumerate().filter(|(_, &j)| bin[j].leaf).fold(0u8, |m, (c, _)| m | (1 << c));
        self.nodes.push(WideNode {
            center: v3(&|n| n.center),
            radius: lane(&|n| n.radius),
            phi: lane(&|n| n.phi),
            axis: v3(&|n| n.axis),
            cos_o: lane(&|n| n.cos_o),
            sin_o: lane(&|n| n.sin_o),
            child: [0; WIDTH],
            leaf,
        });
        for (c, &j) in kids.iter().enumerate() {
            stack.push(c as u8);
            let child = if bin[j].leaf {
                let light = bin[j].link;
                self.path[light as usize] = (self.slots.len() as u32, stack.len() as u8);
                self.slots.extend_from_slice(stack);
                light
            } else {
                self.build_rec(bin, j, stack)
            };
            self.nodes[at as usize].child[c] = child;
            stack.pop();
        }
        at
    }

    /// Importance of each child of `node` at `(p, n)`: the bound of `LightTree::importance`,
    /// lane-wise (`n` zero: no receiver cosine).
    #[inline]
    pub(crate) fn importance8(node: &WideNode, p: Vec3, n: Vec3) -> [f32; WIDTH] {
        let (one, zero) = (F8::ONE, F8::ZERO);
        let d = Vec3x8::splat(p) - node.center;
        let d2 = dot(d, d);
        let r2 = node.radius * node.radius;
        let inside = d2.simd_le(r2);
        let inv_d = one / d2.sqrt();
        let wl = d.scale(inv_d);
        let sin_b = (node.radius * inv_d).min(one);
        let cos_b = (one - sin_b * sin_b).max(zero).sqrt();
        let cos_w = dot(wl, node.axis).max(F8::splat(-1.0)).min(one);
        let sin_w = (one - cos_w * cos_w).max(zero).sqrt();
        let cos_x = cos_w * node.cos_o + sin_w * node.sin_o;
        let sin_x = (sin_w * node.cos_o - cos_w * node.sin_o).max(zero);
        let inner = cos_w.simd_ge(node.cos_o) | cos_x.simd_ge(cos_b);
        let cos_e = inner.select(one, cos_x * cos_b + sin_x * sin_b);
        let cos_r = if n == Vec3::ZERO {
            one
        } else {
            let cos_i = dot(-wl, Vec3x8::splat(n)).max(F8::splat(-1.0)).min(one);
            let sin_i = (one - cos_i * cos_i).max(zero).sqrt();
            cos_i.simd_ge(cos_b).select(one, cos_i * cos_b + sin_i * sin_b)
        };
        let dead = cos_e.simd_le(F8::splat(-COS_SLACK)) | cos_r.simd_le(F8::splat(-COS_SLACK));
        let floor = F8::splat(COS_FLOOR);
        let outside = dead.select(zero, node.phi * cos_e.max(floor) * cos_r.max(floor) / d2);
        inside.select(node.phi / r2.max(F8::splat(f32::MIN_POSITIVE)), outside).to_array()
    }

    /// Light chosen by `u` in [0, 1) at `(p, n)` and its probability; `None` when no light can
    /// contribute (every importance 0 at some node on the way).
    pub(crate) fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        self.sample_remap(u, p, n).map(|(i, pmf, _)| (i, pmf))
    }

    /// [`WideTree::sample`] with `u` remapped to [0, 1) within the chosen light's interval of
    /// the descent (u rescaled at every level), for reuse as a sample coordinate.
    pub(crate) fn sample_remap(&self, mut u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let (mut k, mut pmf) = (0usize, 1.0f32);
        loop {
            let node = &self.nodes[k];
            let imp = Self::importance8(node, p, n);
            let sum = imp.iter().fold(0.0f32, |s, &x| s + x);
            if !(sum > 0.0) {
                return None;
            }
            // Child whose interval of the running CDF holds u (the last positive one if rounding
            // leaves u beyond the end).
            let (mut lo, mut pick) = (0.0f32, None);
            for (c, &x) in imp.iter().enumerate() {
                if x > 0.0 {
                    let q = x / sum;
                    pick = Some((c, lo, q));
                    if u < lo + q {
                        break;
                    }
                    lo += q;
                }
            }
            let (c, lo, q) = pick?;
            u = ((u - lo) / q).clamp(0.0, ONE_MINUS);
            pmf *= q;
            if node.leaf & (1 << c) != 0 {
                return if pmf > 0.0 { Some((node.child[c], pmf, u)) } else { None };
            }
            k = node.child[c] as usize;
        }
    }

    /// Probability that [`WideTree::sample`] picks `light` at `(p, n)` (the same products).
    pub(crate) fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        let Some(&(start, depth)) = self.path.get(light as usize) else { return 0.0 };
        if depth == u8::MAX {
            return 0.0;
        }
        let (mut k, mut pmf) = (0usize, 1.0f32);
        for &c in &self.slots[start as usize..start as usize + depth as usize] {
            let node = &self.nodes[k];
            let imp = Self::importance8(node, p, n);
            let sum = imp.iter().fold(0.0f32, |s, &x| s + x);
            let c = c as usize;
            if !(sum > 0.0) || !(imp[c] > 0.0) {
                return 0.0;
            }
            pmf *= imp[c] / sum;
            k = node.child[c] as usize;
        }
        pmf
    }

    /// Probability that the descent at `(p, n)` stops at a node whose children all have
    /// importance 0 (for the tests: the pmfs sum to 1 minus this).
    #[cfg(test)]
    pub(crate) fn lost_mass(&self, p: Vec3, n: Vec3) -> f64 {
        fn rec(t: &WideTree, k: usize, mass: f64, p: Vec3, n: Vec3) -> f64 {
            let node = &t.nodes[k];
            let imp = WideTree::importance8(node, p, n);
            let sum = imp.iter().fold(0.0f32, |s, &x| s + x);
            if !(sum > 0.0) {
                return mass;
            }
            (0..WIDTH)
                .filter(|&c| imp[c] > 0.0 && node.leaf & (1 << c) == 0)
                .map(|c| rec(t, node.child[c] as usize, mass * f64::from(imp[c] / sum), p, n))
                .sum()
        }
        if self.nodes.is_empty() {
            1.0
        } else {
            rec(self, 0, 1.0, p, n)
        }
    }
}
