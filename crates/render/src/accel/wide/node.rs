//! The wide node's layout: `W` children's boxes as slabs in structure-of-arrays form, and the
//! child words that name inner nodes, leaves (first slot and count) or empty lanes.

use crate::geometry::Aabb;

/// A lane's child word marks a leaf with this bit; the leaf's primitive count minus one sits
/// in the next four bits and its first primitive slot in the low 27.
pub(super) const LEAF: u32 = 1 << 31;
/// Bits of the first primitive slot of a leaf.
pub(super) const SLOT_BITS: u32 = 27;
/// The most primitives a tree can hold (a leaf word has 27 bits for its first slot).
pub const MAX_PRIMITIVES: usize = 1 << SLOT_BITS;
/// The most primitives one leaf can hold.
pub(super) const MAX_LEAF: usize = 16;
/// The child word of an empty lane (whose box is inverted, so no ray enters it).
pub(super) const EMPTY_LANE: u32 = u32::MAX;

#[inline]
pub(super) fn leaf_word(start: usize, count: usize) -> u32 {
    LEAF | ((count as u32 - 1) << SLOT_BITS) | start as u32
}

/// (first slot, count) of a leaf word.
#[inline]
pub(super) fn leaf_range(word: u32) -> (u32, u32) {
    (
        word & ((1 << SLOT_BITS) - 1),
        ((word >> SLOT_BITS) & 0xf) + 1,
    )
}

/// One node: `W` children's boxes (lanes), each an inner node (the child word is the node
/// index), a leaf (the word has its top bit set), or empty (an inverted box).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node<const W: usize> {
    /// The lanes' slabs: `planes[k][lane]` is the lower corner's coordinate on axis `k` for
    /// `k < 3` and the upper corner's on axis `k - 3` otherwise, so that a ray picks its near
    /// and far planes by index (from the signs of its direction) rather than by branching.
    pub(super) planes: [[f32; W]; 6],
    /// Child words.
    pub(super) child: [u32; W],
    /// Bit per lane that holds a child. Empty lanes have inverted boxes, which no ray with
    /// finite parameters enters; a ray with infinite or NaN parameters can make the slab test
    /// pass for them (NaN bounds are ignored so that the test stays conservative), so the
    /// traversal masks them out.
    pub(super) valid: u32,
}

impl<const W: usize> Node<W> {
    pub(super) const EMPTY: Node<W> = Node {
        planes: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        child: [EMPTY_LANE; W],
        valid: 0,
    };

    pub(super) fn set_bounds(&mut self, lane: usize, b: &Aabb) {
        for axis in 0..3 {
            self.planes[axis][lane] = b.min[axis];
            self.planes[axis + 3][lane] = b.max[axis];
        }
    }

    #[cfg(test)]
    pub(super) fn bounds(&self, lane: usize) -> Aabb {
        Aabb {
            min: glam::Vec3::new(
                self.planes[0][lane],
                self.planes[1][lane],
                self.planes[2][lane],
            ),
            max: glam::Vec3::new(
                self.planes[3][lane],
                self.planes[4][lane],
                self.planes[5][lane],
            ),
        }
    }
}
