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

use super::bvh::{partition, BvhParams};
use crate::geometry::{Aabb, Ray};
use glam::Vec3;
use std::mem::MaybeUninit;

/// Number of SAH bins per axis (fixed, so that binning needs no allocation).
const BINS: usize = 32;
/// Subtrees with more primitives than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;
/// Depth of the binary tree from which splits are at the median: below it, at most 32 more
/// levels for up to 2^32 primitives.
const MEDIAN_DEPTH: usize = 32;
/// Traversal stack entries for any tree: the binary tree is at most 64 levels deep, the wide
/// tree made from it no deeper, and each level leaves at most seven siblings on the stack.
/// (The stack is not initialised, so its size costs nothing per ray.)
const STACK_SIZE: usize = 7 * 64 + 8;
/// Relative widening of the far distance of a box test, so that rounding never culls a box
/// the ray touches (pbrt-v4's 1 + 2γ₃).
const FAR_SCALE: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON * 0.5 / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// A lane's child word marks a leaf with this bit; the leaf's primitive count minus one sits
/// in the next four bits and its first primitive slot in the low 27.
const LEAF: u32 = 1 << 31;
/// Bits of the first primitive slot of a leaf.
const SLOT_BITS: u32 = 27;
/// The most primitives a tree can hold (a leaf word has 27 bits for its first slot).
pub const MAX_PRIMITIVES: usize = 1 << SLOT_BITS;
/// The most primitives one leaf can hold.
const MAX_LEAF: usize = 16;
/// The child word of an empty lane (whose box is inverted, so no ray enters it).
const EMPTY_LANE: u32 = u32::MAX;

#[inline]
fn leaf_word(start: usize, count: usize) -> u32 {
    LEAF | ((count as u32 - 1) << SLOT_BITS) | start as u32
}

/// (first slot, count) of a leaf word.
#[inline]
fn leaf_range(word: u32) -> (u32, u32) {
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
    planes: [[f32; W]; 6],
    /// Child words.
    child: [u32; W],
    /// Bit per lane that holds a child. Empty lanes have inverted boxes, which no ray with
    /// finite parameters enters; a ray with infinite or NaN parameters can make the slab test
    /// pass for them (NaN bounds are ignored so that the test stays conservative), so the
    /// traversal masks them out.
    valid: u32,
}

impl<const W: usize> Node<W> {
    const EMPTY: Node<W> = Node {
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

    fn set_bounds(&mut self, lane: usize, b: &Aabb) {
        for axis in 0..3 {
            self.planes[axis][lane] = b.min[axis];
            self.planes[axis + 3][lane] = b.max[axis];
        }
    }

    #[cfg(test)]
    fn bounds(&self, lane: usize) -> Aabb {
        Aabb {
            min: Vec3::new(
                self.planes[0][lane],
                self.planes[1][lane],
                self.planes[2][lane],
            ),
            max: Vec3::new(
                self.planes[3][lane],
                self.planes[4][lane],
                self.planes[5][lane],
            ),
        }
    }
}

/// A BVH of width `W` (4 or 8) over primitives given by their bounding boxes.
#[derive(Clone, Debug)]
pub struct WideBvh<const W: usize> {
    nodes: Vec<Node<W>>,
    /// Primitive indices in leaf order.
    prim_indices: Vec<u32>,
    bounds: Aabb,
}

/// Four children per node: one SSE register per plane.
pub type Bvh4 = WideBvh<4>;
/// Eight children per node: one AVX register per plane.
pub type Bvh8 = WideBvh<8>;

impl<const W: usize> Default for WideBvh<W> {
    fn default() -> Self {
        WideBvh {
            nodes: Vec::new(),
            prim_indices: Vec::new(),
            bounds: Aabb::EMPTY,
        }
    }
}

#[derive(Clone, Copy)]
struct BuildPrim {
    bounds: Aabb,
    centroid: Vec3,
    index: u32,
}

/// The binary tree the builder makes before collapsing it.
enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Inner {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
    },
}

impl BuildNode {
    fn bounds(&self) -> &Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => bounds,
        }
    }
}

/// The ray quantities every box test uses.
#[doc(hidden)]
pub struct RayBoxes {
    /// Where entry distances start: the ray's `t_min` (+0 if not positive, -0 and NaN
    /// included), so that boxes the ray leaves before it are culled (a ray leaving a surface
    /// with `t_min` > 0 does not descend into the boxes around its origin). Never negative,
    /// not even -0, whose bits would sort the stack entries as the largest distances.
    t_min: f32,
    o: [f32; 3],
    inv_d: [f32; 3],
    /// `inv_d` widened by [`FAR_SCALE`], for far planes.
    inv_far: [f32; 3],
    /// Per axis, the index in [`Node::planes`] of the plane the ray enters by (the upper one
    /// when the direction is negative) and of the one it leaves by.
    near: [usize; 3],
    far: [usize; 3],
}

impl RayBoxes {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let inv_d = ray.d.recip();
        // Written out rather than with `array::map`, which is not inlined here.
        let plane = |axis: usize, upper: bool| axis + 3 * usize::from(upper);
        // The planes come from the direction's signs, which 1/d keeps (-0 gives -∞), rather
        // than from 1/d: the node's loads then need not wait for the division. (A NaN
        // component makes every distance on its axis NaN, whichever planes it picks.)
        let neg = [
            ray.d.x.is_sign_negative(),
            ray.d.y.is_sign_negative(),
            ray.d.z.is_sign_negative(),
        ];
        RayBoxes {
            t_min: if ray.t_min > 0.0 { ray.t_min } else { 0.0 },
            o: ray.o.to_array(),
            inv_d: inv_d.to_array(),
            inv_far: (inv_d * FAR_SCALE).to_array(),
            near: [plane(0, neg[0]), plane(1, neg[1]), plane(2, neg[2])],
            far: [plane(0, !neg[0]), plane(1, !neg[1]), plane(2, !neg[2])],
        }
    }

    /// Entry distances of the `W` lanes and the mask (bit per lane) of those the ray meets
    /// within (t_min, t_max).
    #[inline(always)]
    fn test<const W: usize>(&self, n: &Node<W>, t_max: f32) -> ([f32; W], u32) {
        let mut t_near = [self.t_min; W];
        let mut t_far = [t_max; W];
        for axis in 0..3 {
            let near = &n.planes[self.near[axis]];
            let far = &n.planes[self.far[axis]];
            let (o, inv, inv_far) = (self.o[axis], self.inv_d[axis], self.inv_far[axis]);
            for lane in 0..W {
                // Comparisons rather than f32::max/min: they compile to single SIMD min/max
                // instructions, and a NaN (0 · ∞ for a ray in a box's plane) leaves the
                // running value unchanged, which keeps the test conservative.
                let tn = (near[lane] - o) * inv;
                let tf = (far[lane] - o) * inv_far;
                t_near[lane] = if tn > t_near[lane] { tn } else { t_near[lane] };
                t_far[lane] = if tf < t_far[lane] { tf } else { t_far[lane] };
            }
        }
        let mut mask = 0u32;
        for lane in 0..W {
            mask |= u32::from(t_near[lane] <= t_far[lane]) << lane;
        }
        (t_near, mask & n.valid)
    }
}

/// How a traversal tests a ray against a node's `W` boxes: [`Portable`] on any CPU, or with
/// the instructions a CPU extension offers (on x86-64, [`crate::simd::Avx2`] for eight lanes).
/// Every implementation gives the same entry distances and mask.
pub trait BoxTest<const W: usize>: Copy {
    /// Entry distances of the lanes and the mask of those `ray` meets within
    /// `(t_min, t_max)` (`t_min` the ray's).
    #[doc(hidden)]
    fn test(self, ray: &RayBoxes, node: &Node<W>, t_max: f32) -> ([f32; W], u32);
}

/// The box test written as loops over lanes, which the compiler vectorises for the target's
/// baseline instructions.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl<const W: usize> BoxTest<W> for Portable {
    #[inline(always)]
    fn test(self, ray: &RayBoxes, node: &Node<W>, t_max: f32) -> ([f32; W], u32) {
        ray.test(node, t_max)
    }
}

#[cfg(target_arch = "x86_64")]
impl BoxTest<8> for crate::simd::Avx2 {
    #[inline(always)]
    fn test(self, ray: &RayBoxes, node: &Node<8>, t_max: f32) -> ([f32; 8], u32) {
        // SAFETY: `self` exists only where the CPU has AVX2 and FMA, all that
        // `test8_avx2` requires.
        unsafe { test8_avx2(ray, node, t_max) }
    }
}

/// [`RayBoxes::test`] for eight lanes in AVX registers: the same operations in the same order
/// (`max`/`min` keep their second operand when the first is NaN, as the portable comparisons
/// do), so the results are identical.
///
/// # Safety
///
/// The CPU must have AVX. (Not a `#[target_feature]` function, so that it can be inlined
/// into its callers, which are.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn test8_avx2(ray: &RayBoxes, n: &Node<8>, t_max: f32) -> ([f32; 8], u32) {
    use std::arch::x86_64::*;
    // SAFETY: the caller guarantees AVX; the loads and the store go through pointers to
    // `[f32; 8]`, valid for exactly the 32 bytes each moves.
    unsafe {
        let mut t_near = _mm256_set1_ps(ray.t_min);
        let mut t_far = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let o = _mm256_set1_ps(ray.o[axis]);
            let near = _mm256_loadu_ps(n.planes[ray.near[axis]].as_ptr());
            let far = _mm256_loadu_ps(n.planes[ray.far[axis]].as_ptr());
            let tn = _mm256_mul_ps(_mm256_sub_ps(near, o), _mm256_set1_ps(ray.inv_d[axis]));
            let tf = _mm256_mul_ps(_mm256_sub_ps(far, o), _mm256_set1_ps(ray.inv_far[axis]));
            t_near = _mm256_max_ps(tn, t_near);
            t_far = _mm256_min_ps(tf, t_far);
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (out, mask & n.valid)
    }
}

/// A stack of at most `N` entries whose storage is left uninitialised until pushed to, so
/// that setting one up for every ray costs nothing. Pushing past `N` panics.
struct Stack<T: Copy, const N: usize> {
    items: [MaybeUninit<T>; N],
    /// Entries `items[..len]` have been written.
    len: usize,
}

impl<T: Copy + Ord, const N: usize> Stack<T, N> {
    #[inline(always)]
    fn new() -> Self {
        Stack {
            items: [const { MaybeUninit::uninit() }; N],
            len: 0,
        }
    }

    #[inline(always)]
    fn len(&self) -> usize {
        self.len
    }

    #[inline(always)]
    fn push(&mut self, item: T) {
        self.items[self.len].write(item);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: `items[..len]` were written (invariant), and `len` was above this index.
        Some(unsafe { self.items[self.len].assume_init() })
    }

    /// Sorts the entries from `base` to the top, largest deepest, by insertion (few entries).
    #[inline(always)]
    fn sort_descending_from(&mut self, base: usize) {
        // SAFETY: every index read is below `len`, so written (invariant).
        let at = |items: &[MaybeUninit<T>; N], i: usize| unsafe { items[i].assume_init() };
        for i in base + 1..self.len {
            let e = at(&self.items, i);
            let mut j = i;
            while j > base && at(&self.items, j - 1) < e {
                let moved = at(&self.items, j - 1);
                self.items[j].write(moved);
                j -= 1;
            }
            self.items[j].write(e);
        }
    }
}

/// A traversal stack entry: a child's entry distance (high half) and word (low half). Entry
/// distances are non-negative, so entries order as their distances do.
#[inline(always)]
fn stack_entry(word: u32, t: f32) -> u64 {
    (u64::from(t.to_bits()) << 32) | u64::from(word)
}

/// `(min, max)` of two stack entries, without branches.
#[inline(always)]
fn order(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

impl<const W: usize> WideBvh<W> {
    /// Builds the tree over `bounds` (primitive `i` has box `bounds[i]`); primitives with an
    /// empty or non-finite box are left out. Uses `params.max_leaf_size` (at most 16),
    /// `params.traversal_cost` (relative to one leaf block test), `params.leaf_block` and 32
    /// bins. At most
    /// [`MAX_PRIMITIVES`] primitives: the caller checks.
    pub fn build(bounds: &[Aabb], params: BvhParams) -> WideBvh<W> {
        assert!(W == 4 || W == 8, "wide BVHs have 4 or 8 lanes");
        assert!(
            bounds.len() <= MAX_PRIMITIVES,
            "too many primitives for a wide BVH"
        );
        let params = BvhParams {
            max_leaf_size: params.max_leaf_size.clamp(1, MAX_LEAF),
            ..params
        };
        let mut prims: Vec<BuildPrim> = bounds
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.is_empty() && b.min.is_finite() && b.max.is_finite())
            .map(|(i, b)| BuildPrim {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        if prims.is_empty() {
            return WideBvh::default();
        }
        let root = build_binary(&mut prims, 0, &params, 0);
        let mut bvh = WideBvh {
            nodes: Vec::with_capacity(prims.len() / 2 + 1),
            prim_indices: prims.iter().map(|p| p.index).collect(),
            bounds: *root.bounds(),
        };
        match &root {
            BuildNode::Leaf { .. } => {
                let mut node = Node::EMPTY;
                bvh.set_lane(&mut node, 0, &root);
                bvh.nodes.push(node);
            }
            BuildNode::Inner { .. } => {
                bvh.collapse(&root);
            }
        }
        bvh
    }

    fn set_lane(&mut self, node: &mut Node<W>, lane: usize, child: &BuildNode) {
        node.set_bounds(lane, child.bounds());
        node.valid |= 1 << lane;
        node.child[lane] = match child {
            BuildNode::Leaf { start, count, .. } => leaf_word(*start, *count),
            BuildNode::Inner { .. } => self.collapse(child) as u32,
        };
    }

    /// Makes the wide node of an inner binary node: its two children, opened (the largest
    /// inner one first) until there are `W`; returns the node's index.
    fn collapse(&mut self, inner: &BuildNode) -> usize {
        let BuildNode::Inner { children, .. } = inner else {
            unreachable!("collapse is called on inner nodes only");
        };
        let mut lanes: Vec<&BuildNode> = vec![&children[0], &children[1]];
        while lanes.len() < W {
            let widest = lanes
                .iter()
                .enumerate()
                .filter(|(_, n)| matches!(n, BuildNode::Inner { .. }))
                .max_by(|a, b| {
                    a.1.bounds()
                        .surface_area()
                        .total_cmp(&b.1.bounds().surface_area())
                })
                .map(|(i, _)| i);
            let Some(i) = widest else { break };
            let BuildNode::Inner { children, .. } = lanes.swap_remove(i) else {
                unreachable!("filtered to inner nodes");
            };
            lanes.push(&children[0]);
            lanes.push(&children[1]);
        }
        let index = self.nodes.len();
        self.nodes.push(Node::EMPTY);
        let mut node = Node::EMPTY;
        for (lane, child) in lanes.into_iter().enumerate() {
            self.set_lane(&mut node, lane, child);
        }
        self.nodes[index] = node;
        index
    }

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

    /// Finds the nearest primitive hit by `ray`. `hit(prim, ray)` tests one primitive and, when
    /// it hits closer than `ray.t_max`, shortens `ray.t_max` to the hit and returns true.
    /// Returns whether anything was hit and how many nodes were visited. For trees whose
    /// leaves have not been remapped.
    #[inline]
    pub fn intersect(
        &self,
        ray: &mut Ray,
        mut hit: impl FnMut(u32, &mut Ray) -> bool,
    ) -> (bool, u32) {
        self.intersect_leaves(ray, |leaf, ray| {
            let (start, count) = Self::leaf_range(leaf);
            let mut any = false;
            for slot in start..start + count {
                any |= hit(self.prim(slot), ray);
            }
            any
        })
    }

    /// Whether any primitive blocks `ray` (any hit, stopping at the first). For trees whose
    /// leaves have not been remapped.
    #[inline]
    pub fn occluded(&self, ray: &Ray, mut hit: impl FnMut(u32, &Ray) -> bool) -> bool {
        self.occluded_leaves(ray, |leaf, ray| {
            let (start, count) = Self::leaf_range(leaf);
            (start..start + count).any(|slot| hit(self.prim(slot), ray))
        })
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

    /// Finds the nearest hit by `ray`, nearest boxes first. `leaf(word, ray)` tests the leaf
    /// whose range [`WideBvh::leaf_range`] decodes from `word` and, when something in it hits
    /// closer than `ray.t_max`, shortens `ray.t_max` to the hit and returns true. Returns
    /// whether anything was hit and how many nodes were visited.
    #[inline(always)]
    pub fn intersect_leaves(
        &self,
        ray: &mut Ray,
        leaf: impl FnMut(u32, &mut Ray) -> bool,
    ) -> (bool, u32) {
        self.intersect_leaves_with(Portable, ray, leaf)
    }

    /// [`WideBvh::intersect_leaves`] with the box test `boxes`.
    #[inline(always)]
    pub fn intersect_leaves_with(
        &self,
        boxes: impl BoxTest<W>,
        ray: &mut Ray,
        mut leaf: impl FnMut(u32, &mut Ray) -> bool,
    ) -> (bool, u32) {
        if self.nodes.is_empty() {
            return (false, 0);
        }
        let rb = RayBoxes::new(ray);
        let mut stack = Stack::<u64, STACK_SIZE>::new();
        let mut word = 0u32; // the root, an inner node
        let mut visited = 0u32;
        let mut any = false;
        'walk: loop {
            if word & LEAF == 0 {
                visited += 1;
                let n = &self.nodes[word as usize];
                let (t_near, mut mask) = boxes.test(&rb, n, ray.t_max);
                if mask != 0 {
                    let next = |mask: &mut u32| {
                        let lane = mask.trailing_zeros() as usize;
                        *mask &= *mask - 1;
                        stack_entry(n.child[lane], t_near[lane])
                    };
                    let a = next(&mut mask);
                    if mask == 0 {
                        word = a as u32;
                        continue 'walk;
                    }
                    // Two or more: keep the farther ones on the stack, farthest deepest, and
                    // go to the nearest (a sorting network, no branches on distances).
                    let (a, b) = order(a, next(&mut mask));
                    if mask == 0 {
                        stack.push(b);
                        word = a as u32;
                        continue 'walk;
                    }
                    let c = next(&mut mask);
                    if mask == 0 {
                        let (b, c) = order(b, c);
                        let (a, b) = order(a, b);
                        stack.push(c);
                        stack.push(b);
                        word = a as u32;
                        continue 'walk;
                    }
                    let (c, d) = order(c, next(&mut mask));
                    let (a, c) = order(a, c);
                    let (b, d) = order(b, d);
                    let (b, c) = order(b, c);
                    if mask == 0 {
                        stack.push(d);
                        stack.push(c);
                        stack.push(b);
                        word = a as u32;
                        continue 'walk;
                    }
                    // More than four (eight-wide nodes): push them all and sort the pushed
                    // entries, farthest deepest, by insertion.
                    let base = stack.len();
                    for e in [a, b, c, d] {
                        stack.push(e);
                    }
                    while mask != 0 {
                        stack.push(next(&mut mask));
                    }
                    stack.sort_descending_from(base);
                    // The nearest is on top now (the stack holds at least the four pushed).
                    word = stack.pop().unwrap_or(a) as u32;
                    continue 'walk;
                }
            } else {
                any |= leaf(word, ray);
            }
            // Next: the nearest kept entry that can still hold a closer hit.
            loop {
                let Some(e) = stack.pop() else {
                    break 'walk;
                };
                if f32::from_bits((e >> 32) as u32) <= ray.t_max {
                    word = e as u32;
                    continue 'walk;
                }
            }
        }
        (any, visited)
    }

    /// Whether `leaf(word, ray)` (see [`WideBvh::intersect_leaves`]) reports a hit for any leaf
    /// `ray` reaches; stops at the first.
    #[inline(always)]
    pub fn occluded_leaves(&self, ray: &Ray, leaf: impl FnMut(u32, &Ray) -> bool) -> bool {
        self.occluded_leaves_with(Portable, ray, leaf)
    }

    /// [`WideBvh::occluded_leaves`] with the box test `boxes`.
    #[inline(always)]
    pub fn occluded_leaves_with(
        &self,
        boxes: impl BoxTest<W>,
        ray: &Ray,
        mut leaf: impl FnMut(u32, &Ray) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let rb = RayBoxes::new(ray);
        let mut stack = Stack::<u32, STACK_SIZE>::new();
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            let (_, mut mask) = boxes.test(&rb, n, ray.t_max);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let word = n.child[lane];
                if word & LEAF == 0 {
                    stack.push(word);
                } else if leaf(word, ray) {
                    return true;
                }
            }
            match stack.pop() {
                Some(next) => node = next,
                None => return false,
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
                if word == EMPTY_LANE {
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
                        if c.child[l] != EMPTY_LANE {
                            assert!(contains(&b, &c.bounds(l)));
                        }
                    }
                }
            }
        }
    }
}

/// Builds the binary SAH tree over `prims` (which sit at `offset` in the whole array),
/// reordering them into leaf order.
fn build_binary(
    prims: &mut [BuildPrim],
    offset: usize,
    params: &BvhParams,
    depth: usize,
) -> BuildNode {
    let n = prims.len();
    let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
    let leaf = || BuildNode::Leaf {
        bounds,
        start: offset,
        count: n,
    };
    if n <= 1 {
        return leaf();
    }
    let centroids = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
    let split = if depth < MEDIAN_DEPTH {
        find_split(prims, params, &bounds, &centroids)
    } else {
        None
    };
    let mid = match split {
        Some((axis, bin, cost)) => {
            // Splitting a small set makes two leaves that the collapse puts side by side in
            // one wide node: what it adds is `leaf_split_cost`, not a traversal step.
            let split_cost = cost - params.traversal_cost + params.leaf_split_cost;
            if n <= params.max_leaf_size && split_cost >= blocks(n, params) {
                return leaf();
            }
            let (lo, extent) = (centroids.min[axis], centroids.extent()[axis]);
            partition(prims, |p| bin_of(p.centroid[axis], lo, extent) <= bin)
        }
        // All centroids coincide: no plane separates them.
        None if n <= params.max_leaf_size.max(1) => return leaf(),
        // Past the SAH depth, or when all centroids coincide (no plane separates them): halve
        // along the widest centroid axis.
        None => {
            let axis = centroids.largest_axis();
            let half = n / 2;
            prims
                .select_nth_unstable_by(half, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
            half
        }
    };
    let mid = if mid == 0 || mid == n { n / 2 } else { mid };
    let (left, right) = prims.split_at_mut(mid);
    let (a, b) = if n > PARALLEL_THRESHOLD {
        rayon::join(
            || build_binary(left, offset, params, depth + 1),
            || build_binary(right, offset + mid, params, depth + 1),
        )
    } else {
        (
            build_binary(left, offset, params, depth + 1),
            build_binary(right, offset + mid, params, depth + 1),
        )
    };
    BuildNode::Inner {
        bounds,
        children: Box::new([a, b]),
    }
}

/// SAH cost of testing `n` primitives, in blocks of `params.leaf_block`.
#[inline]
fn blocks(n: usize, params: &BvhParams) -> f32 {
    n.div_ceil(params.leaf_block.max(1)) as f32
}

#[inline]
fn bin_of(c: f32, lo: f32, extent: f32) -> usize {
    let b = ((c - lo) / extent * BINS as f32) as usize;
    b.min(BINS - 1)
}

/// The best SAH split: (axis, last bin on the left, cost relative to one primitive test).
fn find_split(
    prims: &[BuildPrim],
    params: &BvhParams,
    bounds: &Aabb,
    centroids: &Aabb,
) -> Option<(usize, usize, f32)> {
    let extent = centroids.extent();
    let area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let mut best: Option<(usize, usize, f32)> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let lo = centroids.min[axis];
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_count = [0usize; BINS];
        for p in prims {
            let b = bin_of(p.centroid[axis], lo, extent[axis]);
            bin_bounds[b] = bin_bounds[b].union(p.bounds);
            bin_count[b] += 1;
        }
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..BINS).rev() {
            acc = acc.union(bin_bounds[i]);
            cnt += bin_count[i];
            right_area[i] = acc.surface_area();
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 0..BINS - 1 {
            acc = acc.union(bin_bounds[i]);
            cnt += bin_count[i];
            if cnt == 0 || right_count[i + 1] == 0 {
                continue;
            }
            let cost = params.traversal_cost
                + (acc.surface_area() * blocks(cnt, params)
                    + right_area[i + 1] * blocks(right_count[i + 1], params))
                    / area;
            if best.is_none_or(|b| cost < b.2) {
                best = Some((axis, i, cost));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{box_hit, check_against_brute_force, random_boxes};
    use super::*;
    use pathlab_mc::rng::Pcg32;

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_box_test_gives_the_portable_results_to_the_bit() {
        let Some(avx2) = crate::simd::Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: only the portable box test runs here");
            return;
        };
        let boxes = random_boxes(3000, 11);
        let bvh = Bvh8::build(&boxes, BvhParams::default());
        let mut rng = Pcg32::new(12, 1);
        let mut tested = 0;
        for k in 0..2000 {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 14.0 - 2.0;
            let mut d = Vec3::new(
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
            );
            // Axis-parallel, zero, infinite and NaN components: the NaN handling must match.
            match k % 8 {
                1 => d.x = 0.0,
                2 => d = Vec3::new(0.0, 0.0, d.z),
                3 => d.y = f32::NAN,
                4 => d.z = f32::INFINITY,
                _ => {}
            }
            let rb = RayBoxes::new(&Ray::new(o, d));
            for node in &bvh.nodes {
                for t_max in [f32::INFINITY, 3.0] {
                    let (tp, mp) = Portable.test(&rb, node, t_max);
                    let (ta, ma) = avx2.test(&rb, node, t_max);
                    assert_eq!(mp, ma);
                    assert_eq!(tp.map(f32::to_bits), ta.map(f32::to_bits));
                    tested += 1;
                }
            }
        }
        assert!(tested > 1000);
    }

    #[test]
    fn entry_distances_start_at_a_non_negative_t_min() {
        // Stack entries order by the bits of their distances, so the start must be +0 for
        // -0, negative and NaN `t_min` alike.
        for (t_min, start) in [(-0.0, 0.0), (-1.0, 0.0), (f32::NAN, 0.0), (0.5, 0.5)] {
            let ray = Ray {
                t_min,
                ..Ray::new(Vec3::ZERO, Vec3::X)
            };
            assert_eq!(RayBoxes::new(&ray).t_min.to_bits(), f32::to_bits(start));
        }
    }

    #[test]
    fn boxes_left_before_t_min_are_culled_at_the_root() {
        let boxes = random_boxes(2000, 3);
        let bvh = Bvh8::build(&boxes, BvhParams::default());
        // From the middle of the boxes ([0, 10]³), starting past all of them.
        let mut ray = Ray {
            t_min: 20.0,
            ..Ray::new(Vec3::splat(5.0), Vec3::new(0.3, -0.5, 0.8).normalize())
        };
        let (any, visited) = bvh.intersect(&mut ray, box_hit(&boxes));
        assert!(!any);
        assert_eq!(visited, 1);
        // The same ray from t = 0 descends.
        let mut ray = Ray { t_min: 0.0, ..ray };
        assert!(bvh.intersect(&mut ray, box_hit(&boxes)).1 > 1);
    }

    #[test]
    fn stack_pops_what_was_pushed_and_sorts_its_top() {
        let mut stack = Stack::<u64, 8>::new();
        assert_eq!(stack.pop(), None);
        for e in [5, 1, 9, 3, 7] {
            stack.push(e);
        }
        stack.sort_descending_from(1);
        let popped: Vec<u64> = std::iter::from_fn(|| stack.pop()).collect();
        assert_eq!(popped, [1, 3, 7, 9, 5]);
        assert_eq!(stack.len(), 0);
    }

    #[test]
    #[should_panic]
    fn stack_refuses_to_overflow() {
        let mut stack = Stack::<u32, 2>::new();
        for e in 0..3 {
            stack.push(e);
        }
    }

    #[test]
    fn finds_the_same_nearest_hit_as_brute_force() {
        nearest_hits_match_brute_force::<4>();
        nearest_hits_match_brute_force::<8>();
    }

    fn nearest_hits_match_brute_force<const W: usize>() {
        // Sizes around the parallel threshold and the leaf size, and one large tree.
        for (n, seed) in [
            (1, 1),
            (3, 2),
            (5, 3),
            (9, 10),
            (17, 4),
            (2000, 5),
            (20_000, 6),
        ] {
            let boxes = random_boxes(n, seed);
            let bvh = WideBvh::<W>::build(&boxes, BvhParams::default());
            bvh.check(&boxes);
            let mut seen: Vec<u32> = bvh.primitive_indices().to_vec();
            seen.sort();
            assert_eq!(seen, (0..n as u32).collect::<Vec<u32>>());
            check_against_brute_force(
                &boxes,
                1000,
                (seed, 9),
                |r, h| bvh.intersect(r, h),
                |r, h| bvh.occluded(r, h),
            );
        }
    }

    #[test]
    fn rays_with_infinite_or_nan_parameters_never_reach_empty_lanes() {
        bad_rays_never_reach_empty_lanes::<4>();
        bad_rays_never_reach_empty_lanes::<8>();
    }

    fn bad_rays_never_reach_empty_lanes<const W: usize>() {
        // Five boxes leave empty lanes; infinite and NaN origins and directions make the slab
        // test's products NaN, which must not open those lanes.
        let boxes = random_boxes(5, 8);
        let bvh = WideBvh::<W>::build(&boxes, BvhParams::default());
        let (inf, nan) = (f32::INFINITY, f32::NAN);
        for (o, d) in [
            (Vec3::splat(inf), Vec3::X),
            (Vec3::new(1.0, inf, -inf), Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::ZERO, Vec3::new(inf, 0.0, 0.0)),
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::splat(nan), Vec3::Y),
            (Vec3::ONE, Vec3::new(nan, 1.0, 0.0)),
            (Vec3::splat(1e38), Vec3::splat(-1e38)),
        ] {
            let mut ray = Ray::new(o, d);
            let (any, _) = bvh.intersect(&mut ray, |i, _| {
                assert!((i as usize) < boxes.len());
                false
            });
            assert!(!any);
            assert!(!bvh.occluded(&Ray::new(o, d), |i, _| {
                assert!((i as usize) < boxes.len());
                false
            }));
        }
    }

    #[test]
    fn axis_parallel_rays_and_degenerate_input() {
        axis_parallel_and_degenerate::<4>();
        axis_parallel_and_degenerate::<8>();
    }

    fn axis_parallel_and_degenerate<const W: usize>() {
        let boxes = random_boxes(500, 7);
        let bvh = WideBvh::<W>::build(&boxes, BvhParams::default());
        for d in [Vec3::X, Vec3::NEG_Y, Vec3::Z] {
            for k in 0..50 {
                let o = Vec3::new(k as f32 * 0.2, 5.0, 5.0) - d * 20.0;
                let mut brute = Ray::new(o, d);
                let f = box_hit(&boxes);
                let any_brute = (0..boxes.len() as u32).fold(false, |a, i| f(i, &mut brute) | a);
                let mut ray = Ray::new(o, d);
                assert_eq!(bvh.intersect(&mut ray, box_hit(&boxes)).0, any_brute);
                assert_eq!(ray.t_max, brute.t_max);
            }
        }
        let empty = WideBvh::<W>::build(&[], BvhParams::default());
        assert_eq!(empty.node_count(), 0);
        assert!(!empty.occluded(&Ray::new(Vec3::ZERO, Vec3::X), |_, _| true));
        let same = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE
            };
            100
        ];
        let bvh = WideBvh::<W>::build(&same, BvhParams::default());
        assert_eq!(bvh.primitive_indices().len(), 100);
        let mut ray = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        assert!(bvh.intersect(&mut ray, box_hit(&same)).0);
        let bad = vec![
            Aabb {
                min: Vec3::splat(f32::NAN),
                max: Vec3::ONE,
            },
            Aabb::EMPTY,
        ];
        assert_eq!(
            WideBvh::<W>::build(&bad, BvhParams::default())
                .primitive_indices()
                .len(),
            0
        );
    }
}
