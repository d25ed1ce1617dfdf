//! Wide bounding volume hierarchies ([`Bvh4`], [`Bvh8`]): each node holds the boxes of up to
//! four or eight children in structure-of-arrays form, so that one ray is tested against all of
//! them with the same instructions, and the hit children are visited nearest first. The box
//! test is a [`BoxTest`]: loops over the lanes that the compiler vectorises ([`Portable`]), or
//! on x86-64 CPUs with AVX2 eight lanes in one AVX register ([`crate::simd::Avx2`]), which the
//! caller picks at run time.
//!
//! Built in two steps: a binary tree by the binned surface area heuristic (subtrees built in
//! parallel with rayon, no allocation per binning step), then collapsed into wide nodes by
//! repeatedly opening the child of largest surface area (Wald et al., "Getting Rid of Packets",
//! 2008; the same construction as Embree's BVH4 from a binary SAH tree).
//!
//! The traversal takes the leaf test as a closure, so the same structure serves any
//! primitives: one primitive at a time ([`WideBvh::intersect`], as [`super::Bvh`] does), or
//! blocks the caller packs the leaves into ([`WideBvh::remap_leaves`]; the scene's blocks of
//! four triangles).
//!
//! One concept per file: the node layout (`node`), the box tests (`box_test`), the traversal
//! stack (`stack`), the build (`build`: binned SAH binary tree, collapsed into wide nodes), its
//! spatial splits (`spatial`), the traversals of one ray (`traverse`) and of eight rays
//! together (`packet`).

mod box_test;
mod build;
mod node;
mod packet;
mod spatial;
mod stack;
mod traverse;

pub use box_test::{BoxTest, Portable, FAR_SCALE};
use node::{leaf_range, leaf_word, LEAF, MAX_LEAF};
pub use node::{Node, MAX_PRIMITIVES};
pub(crate) use packet::{PacketBounds, RayBoxLanes};
pub use spatial::{split_box, SplitPrim, SPLIT_BUDGET};

use crate::geometry::Aabb;

/// A BVH of width `W` (4 or 8) over primitives given by their bounding boxes.
#[derive(Clone, Debug)]
pub struct WideBvh<const W: usize> {
    pub(super) nodes: Vec<Node<W>>,
    /// Primitive indices in leaf order.
    pub(super) prim_indices: Vec<u32>,
    pub(super) bounds: Aabb,
}

/// Four children per node: one SSE register per plane.
pub type Bvh4 = WideBvh<4>;
/// Eight children per node: one AVX register per plane.
pub type Bvh8 = WideBvh<BVH_WIDTH>;

/// Children per node of the BVH the scene traces through ([`Bvh8`]): one AVX register of box
/// tests.
pub const BVH_WIDTH: usize = 8;

impl<const W: usize> Default for WideBvh<W> {
    fn default() -> Self {
        WideBvh {
            nodes: Vec::new(),
            prim_indices: Vec::new(),
            bounds: Aabb::EMPTY,
        }
    }
}

impl<const W: usize> WideBvh<W> {
    /// Number of wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Primitive indices in leaf order (empty after [`WideBvh::take_leaf_order`]).
    pub fn primitive_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Hands the leaf order to the caller, who lays its primitives out in it: from then on the
    /// traversal reports leaf slots (slot `i` is the primitive that was `order[i]`), and the
    /// primitives of a leaf sit next to each other in the caller's memory.
    pub fn take_leaf_order(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.prim_indices)
    }

    /// The primitive in leaf slot `slot`.
    #[inline(always)]
    fn prim(&self, slot: u32) -> u32 {
        if self.prim_indices.is_empty() {
            slot
        } else {
            self.prim_indices[slot as usize]
        }
    }

    /// Bounds of the whole tree.
    pub fn bounds(&self) -> Aabb {
        if self.nodes.is_empty() {
            Aabb::EMPTY
        } else {
            self.bounds
        }
    }

    /// Bytes held by the nodes and the primitive index list.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.prim_indices.as_slice())
    }

    /// The (first slot, count) a leaf's word names: what [`WideBvh::intersect_leaves`] and
    /// [`WideBvh::occluded_leaves`] hand to their leaf test, in slots of the leaf order or in
    /// the units [`WideBvh::remap_leaves`] gave.
    #[inline(always)]
    pub fn leaf_range(leaf: u32) -> (u32, u32) {
        leaf_range(leaf)
    }

    /// Renames every leaf's range: `f(first slot, count)` returns the leaf's new (first,
    /// count), in whatever units the caller's leaf test uses (blocks of primitives, say).
    /// Counts must be 1 to 16 and firsts below [`MAX_PRIMITIVES`].
    pub fn remap_leaves(&mut self, mut f: impl FnMut(u32, u32) -> (u32, u32)) {
        for n in &mut self.nodes {
            for lane in 0..W {
                let word = n.child[lane];
                if n.valid & (1 << lane) != 0 && word & LEAF != 0 {
                    let (start, count) = leaf_range(word);
                    let (start, count) = f(start, count);
                    assert!(
                        (1..=MAX_LEAF as u32).contains(&count) && (start as usize) < MAX_PRIMITIVES,
                        "leaf range ({start}, {count}) does not fit a leaf word"
                    );
                    n.child[lane] = leaf_word(start as usize, count as usize);
                }
            }
        }
    }

    /// Every lane's box contains its subtree's primitives (for tests).
    #[cfg(test)]
    fn check(&self, prim_bounds: &[Aabb]) {
        fn contains(outer: &Aabb, inner: &Aabb) -> bool {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        }
        for n in &self.nodes {
            for lane in 0..W {
                let word = n.child[lane];
                if word == node::EMPTY_LANE {
                    continue;
                }
                let b = n.bounds(lane);
                if word & LEAF != 0 {
                    let (start, count) = leaf_range(word);
                    for slot in start..start + count {
                        let p = self.prim_indices[slot as usize] as usize;
                        assert!(contains(&b, &prim_bounds[p]));
                    }
                } else {
                    let c = &self.nodes[word as usize];
                    for l in 0..W {
                        if c.child[l] != node::EMPTY_LANE {
                            assert!(contains(&b, &c.bounds(l)));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
