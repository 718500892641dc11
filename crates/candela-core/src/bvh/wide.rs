//! The four-wide BVH: the binary SAH tree collapsed so that each node holds up to four
//! children, their boxes side by side for [`Ray4::hit4`].

use std::mem::MaybeUninit;

use super::binary::{Bvh, BvhNode};
use super::box4::{Planes4, Ray4, T_MAX_SCALE};
use crate::geometry::{Aabb, Ray};

/// A node of four children. Child `i` is a leaf of `count[i]` primitives from
/// `child[i]` on in leaf order when `count[i] > 0`, otherwise the interior node
/// `child[i]`; an unused slot has an empty box, which no ray enters.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node4 {
    pub planes: Planes4,
    pub child: [u32; 4],
    pub count: [u8; 4],
}

impl Node4 {
    const UNUSED: Node4 = Node4 {
        planes: [
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
        ],
        child: [u32::MAX; 4],
        count: [0; 4],
    };

    fn set_box(&mut self, lane: usize, b: Aabb) {
        for axis in 0..3 {
            self.planes[2 * axis][lane] = b.min[axis];
            self.planes[2 * axis + 1][lane] = b.max[axis];
        }
    }

    /// The box of child `lane` (empty for an unused slot).
    pub fn child_bounds(&self, lane: usize) -> Aabb {
        let p = &self.planes;
        Aabb {
            min: glam::Vec3::new(p[0][lane], p[2][lane], p[4][lane]),
            max: glam::Vec3::new(p[1][lane], p[3][lane], p[5][lane]),
        }
    }
}

/// A four-wide BVH; node 0 is the root. Leaves index the same leaf order as the binary
/// tree it was made from.
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    pub nodes: Vec<Node4>,
    bounds: Aabb,
}

/// One pending subtree: a node or a leaf, and where the ray enters its box.
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    count: u32,
    t: f32,
}

/// Entries a traversal stack holds: at most three pending siblings per level, and the
/// build keeps trees under about 80 levels (`MAX_SAH_DEPTH` + log2 n).
const STACK: usize = 256;

impl WideBvh {
    /// Collapses a binary tree: each wide node takes the binary node's two children and
    /// keeps opening its largest interior child (by surface area) until it has four,
    /// which keeps the SAH tree's cuts.
    pub fn collapse(bvh: &Bvh) -> WideBvh {
        let mut wide = WideBvh {
            nodes: Vec::with_capacity(bvh.nodes.len() / 2 + 1),
            bounds: bvh.bounds(),
        };
        if !bvh.nodes.is_empty() {
            wide.nodes.push(Node4::UNUSED);
            wide.fill(bvh, 0, 0);
        }
        wide
    }

    /// Fills wide node `at` from binary node `node`.
    fn fill(&mut self, bvh: &Bvh, node: usize, at: usize) {
        let children_of = |i: usize| [i + 1, bvh.nodes[i].offset as usize];
        let mut kids: Vec<usize> = if bvh.nodes[node].is_leaf() {
            vec![node]
        } else {
            children_of(node).to_vec()
        };
        while kids.len() < 4 {
            let open = kids
                .iter()
                .enumerate()
                .filter(|(_, &k)| !bvh.nodes[k].is_leaf())
                .max_by(|a, b| {
                    let area = |k: usize| bvh.nodes[k].bounds.surface_area();
                    area(*a.1).total_cmp(&area(*b.1))
                })
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            let k = kids.swap_remove(i);
            kids.extend(children_of(k));
        }
        for (lane, &k) in kids.iter().enumerate() {
            let BvhNode {
                bounds,
                offset,
                count,
                ..
            } = bvh.nodes[k];
            self.nodes[at].set_box(lane, bounds);
            if count > 0 {
                self.nodes[at].child[lane] = offset;
                self.nodes[at].count[lane] = count as u8;
            } else {
                let child = self.nodes.len();
                self.nodes.push(Node4::UNUSED);
                self.nodes[at].child[lane] = child as u32;
                self.fill(bvh, k, child);
            }
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Finds the nearest hit. `leaf(first, count, t_max)` tests the leaf's primitives
    /// and returns the distance of the nearest one hit before `t_max` (or `t_max`).
    /// Children are visited nearest entry first, and subtrees the ray enters beyond
    /// the nearest hit so far are skipped.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, mut t_max: f32, mut leaf: impl FnMut(u32, u32, f32) -> f32) {
        if self.nodes.is_empty() || !(ray.o.is_finite() && ray.d.is_finite()) {
            return;
        }
        let r = Ray4::new(ray);
        // Left uninitialised: zeroing it would cost as much as a shallow traversal.
        let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
        stack[0].write(Entry {
            child: 0,
            count: 0,
            t: 0.0,
        });
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            // SAFETY: every slot below `sp` has been written.
            let e = unsafe { stack[sp].assume_init() };
            if e.t > t_max * T_MAX_SCALE {
                continue;
            }
            if e.count > 0 {
                t_max = leaf(e.child, e.count, t_max);
                continue;
            }
            let node = &self.nodes[e.child as usize];
            let (mut mask, t_near) = r.hit4(&node.planes, t_max * T_MAX_SCALE);
            // Push the hit children farthest first so that the nearest is popped next.
            let base = sp;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let entry = Entry {
                    child: node.child[lane],
                    count: node.count[lane] as u32,
                    t: t_near[lane],
                };
                // Insertion into the (at most four) entries pushed for this node.
                let mut j = sp;
                // SAFETY: slots from `base` to `sp` were written for this node.
                while j > base && unsafe { stack[j - 1].assume_init() }.t < entry.t {
                    stack[j] = stack[j - 1];
                    j -= 1;
                }
                stack[j].write(entry);
                sp += 1;
            }
            debug_assert!(sp + 4 <= STACK, "BVH deeper than the traversal stack");
        }
    }

    /// Whether any leaf reports a blocker: `leaf(first, count, t_max)` returns true to
    /// stop. Children are visited in any order (an any-hit query needs no sorting).
    #[inline(always)]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        mut leaf: impl FnMut(u32, u32, f32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() || !(ray.o.is_finite() && ray.d.is_finite()) {
            return false;
        }
        let r = Ray4::new(ray);
        let t_box = t_max * T_MAX_SCALE;
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
        stack[0].write(0);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            // SAFETY: every slot below `sp` has been written.
            let node = &self.nodes[unsafe { stack[sp].assume_init() } as usize];
            let (mut mask, _) = r.hit4(&node.planes, t_box);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let count = node.count[lane] as u32;
                if count > 0 {
                    if leaf(node.child[lane], count, t_max) {
                        return true;
                    }
                } else {
                    stack[sp].write(node.child[lane]);
                    sp += 1;
                }
            }
            debug_assert!(sp + 4 <= STACK, "BVH deeper than the traversal stack");
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;
    use glam::Vec3;

    /// Every primitive sits in exactly one leaf, and each child box holds what is below.
    #[test]
    fn collapse_keeps_every_primitive_once() {
        let mut rng = Pcg32::new(1, 2);
        let boxes: Vec<Aabb> = (0..3000)
            .map(|_| {
                let c = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                Aabb {
                    min: c,
                    max: c + 0.01,
                }
            })
            .collect();
        let binary = Bvh::build(&boxes);
        let wide = WideBvh::collapse(&binary);
        assert!(wide.nodes.len() < binary.nodes.len() / 2);
        let mut seen = vec![0u32; boxes.len()];
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &wide.nodes[n];
            for lane in 0..4 {
                let b = node.child_bounds(lane);
                if node.count[lane] > 0 {
                    let first = node.child[lane] as usize;
                    for &p in &binary.prims[first..first + node.count[lane] as usize] {
                        seen[p as usize] += 1;
                        assert_eq!(b.union(boxes[p as usize]), b, "leaf box holds its prims");
                    }
                } else if node.child[lane] != u32::MAX {
                    stack.push(node.child[lane] as usize);
                } else {
                    assert!(b.is_empty(), "unused slots are empty");
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
    }
}
