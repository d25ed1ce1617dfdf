//! A 4-wide bounding volume hierarchy: each node holds the boxes of up to four children in
//! structure-of-arrays form, so that one ray is tested against all four with the same
//! instructions (the compiler turns the loops over the four lanes into SIMD), and the hit
//! children are visited nearest first.
//!
//! Built in two steps: a binary tree by the binned surface area heuristic (subtrees built in
//! parallel with rayon, no allocation per binning step), then collapsed into 4-wide nodes by
//! repeatedly opening the child of largest surface area (Wald et al., "Getting Rid of Packets",
//! 2008; the same construction as Embree's BVH4 from a binary SAH tree).
//!
//! The traversal takes the primitive test as a closure, as [`super::Bvh`] does, so the same
//! structure serves triangles and spheres.

use super::bvh::{partition, BvhParams};
use crate::geometry::{Aabb, Ray};
use glam::Vec3;

/// Number of SAH bins per axis (fixed, so that binning needs no allocation).
const BINS: usize = 16;
/// Subtrees with more primitives than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;
/// Depth of the binary tree from which splits are at the median: below it, at most 32 more
/// levels for up to 2^32 primitives.
const MEDIAN_DEPTH: usize = 32;
/// Traversal stack entries: the binary tree is at most 64 levels deep, the 4-wide tree made
/// from it no deeper, and each level leaves at most three siblings on the stack.
const STACK_SIZE: usize = 3 * 64 + 4;
/// Trees at most this deep (nearly all) are traversed with a smaller stack, which is cheaper
/// to set up for every ray.
const SHALLOW_DEPTH: usize = 20;
/// The stack of a shallow tree.
const SHALLOW_STACK: usize = 3 * SHALLOW_DEPTH + 4;
/// Relative widening of the far distance of a box test, so that rounding never culls a box
/// the ray touches (pbrt-v4's 1 + 2γ₃).
const FAR_SCALE: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON * 0.5 / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// A lane's child word marks a leaf with this bit; the leaf's primitive count minus one sits
/// in the next four bits and its first primitive slot in the low 27.
const LEAF: u32 = 1 << 31;
/// Bits of the first primitive slot of a leaf.
const SLOT_BITS: u32 = 27;
/// The most primitives a tree can hold (slots must fit [`SLOT_BITS`]).
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

/// One node: four children's boxes (lanes), each an inner node (the child word is the node
/// index), a leaf (the word has [`LEAF`] set), or empty (an inverted box).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node4 {
    /// Lower corners: `lo[axis][lane]`.
    lo: [[f32; 4]; 3],
    /// Upper corners: `hi[axis][lane]`.
    hi: [[f32; 4]; 3],
    /// Child words.
    child: [u32; 4],
    /// Bit per lane that holds a child. Empty lanes have inverted boxes, which no ray with
    /// finite parameters enters; a ray with infinite or NaN parameters can make the slab test
    /// pass for them (NaN bounds are ignored so that the test stays conservative), so the
    /// traversal masks them out.
    valid: u32,
}

impl Node4 {
    const EMPTY: Node4 = Node4 {
        lo: [[f32::INFINITY; 4]; 3],
        hi: [[f32::NEG_INFINITY; 4]; 3],
        child: [EMPTY_LANE; 4],
        valid: 0,
    };

    fn set_bounds(&mut self, lane: usize, b: &Aabb) {
        for axis in 0..3 {
            self.lo[axis][lane] = b.min[axis];
            self.hi[axis][lane] = b.max[axis];
        }
    }

    #[cfg(test)]
    fn bounds(&self, lane: usize) -> Aabb {
        Aabb {
            min: Vec3::new(self.lo[0][lane], self.lo[1][lane], self.lo[2][lane]),
            max: Vec3::new(self.hi[0][lane], self.hi[1][lane], self.hi[2][lane]),
        }
    }
}

/// A 4-wide BVH over primitives given by their bounding boxes.
#[derive(Clone, Debug, Default)]
pub struct Bvh4 {
    nodes: Vec<Node4>,
    /// Levels of 4-wide nodes on the longest path from the root.
    depth: usize,
    /// Primitive indices in leaf order.
    prim_indices: Vec<u32>,
    bounds: Aabb,
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
struct RayBoxes {
    o: Vec3,
    inv_d: Vec3,
    /// `inv_d` widened by [`FAR_SCALE`], for far planes.
    inv_far: Vec3,
    /// Whether each direction component is negative (the near plane is then the upper one).
    neg: [bool; 3],
}

impl RayBoxes {
    fn new(ray: &Ray) -> Self {
        let inv_d = ray.d.recip();
        RayBoxes {
            o: ray.o,
            inv_d,
            inv_far: inv_d * FAR_SCALE,
            neg: [inv_d.x < 0.0, inv_d.y < 0.0, inv_d.z < 0.0],
        }
    }

    /// Entry distances of the four lanes and the mask (bit per lane) of those the ray meets
    /// within (0, t_max).
    #[inline(always)]
    fn test(&self, n: &Node4, t_max: f32) -> ([f32; 4], u32) {
        let mut t_near = [0.0f32; 4];
        let mut t_far = [t_max; 4];
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] {
                (&n.hi[axis], &n.lo[axis])
            } else {
                (&n.lo[axis], &n.hi[axis])
            };
            let (o, inv, inv_far) = (self.o[axis], self.inv_d[axis], self.inv_far[axis]);
            for lane in 0..4 {
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
        for lane in 0..4 {
            mask |= u32::from(t_near[lane] <= t_far[lane]) << lane;
        }
        (t_near, mask & n.valid)
    }
}

impl Bvh4 {
    /// Builds the tree over `bounds` (primitive `i` has box `bounds[i]`); primitives with an
    /// empty or non-finite box are left out. Uses `params.max_leaf_size` (at most 16),
    /// `params.traversal_cost` (relative to one primitive test) and 16 bins. At most
    /// [`MAX_PRIMITIVES`] primitives: the caller checks.
    pub fn build(bounds: &[Aabb], params: BvhParams) -> Bvh4 {
        assert!(
            bounds.len() <= MAX_PRIMITIVES,
            "too many primitives for a Bvh4"
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
            return Bvh4::default();
        }
        let root = build_binary(&mut prims, 0, &params, 0);
        let mut bvh = Bvh4 {
            nodes: Vec::with_capacity(prims.len() / 2 + 1),
            depth: 0,
            prim_indices: prims.iter().map(|p| p.index).collect(),
            bounds: *root.bounds(),
        };
        match &root {
            BuildNode::Leaf { .. } => {
                let mut node = Node4::EMPTY;
                bvh.set_lane(&mut node, 0, &root, 1);
                bvh.depth = 1;
                bvh.nodes.push(node);
            }
            BuildNode::Inner { .. } => {
                bvh.collapse(&root, 1);
            }
        }
        bvh
    }

    fn set_lane(&mut self, node: &mut Node4, lane: usize, child: &BuildNode, depth: usize) {
        node.set_bounds(lane, child.bounds());
        node.valid |= 1 << lane;
        node.child[lane] = match child {
            BuildNode::Leaf { start, count, .. } => leaf_word(*start, *count),
            BuildNode::Inner { .. } => self.collapse(child, depth + 1) as u32,
        };
    }

    /// Makes the 4-wide node of an inner binary node: its two children, opened (the largest
    /// inner one first) until there are four; returns the node's index.
    fn collapse(&mut self, inner: &BuildNode, depth: usize) -> usize {
        self.depth = self.depth.max(depth);
        let BuildNode::Inner { children, .. } = inner else {
            unreachable!("collapse is called on inner nodes only");
        };
        let mut lanes: Vec<&BuildNode> = vec![&children[0], &children[1]];
        while lanes.len() < 4 {
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
        self.nodes.push(Node4::EMPTY);
        let mut node = Node4::EMPTY;
        for (lane, child) in lanes.into_iter().enumerate() {
            self.set_lane(&mut node, lane, child, depth);
        }
        self.nodes[index] = node;
        index
    }

    /// Number of 4-wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Primitive indices in leaf order (empty after [`Bvh4::take_leaf_order`]).
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
    /// Returns whether anything was hit and how many nodes were visited.
    #[inline]
    pub fn intersect(&self, ray: &mut Ray, hit: impl FnMut(u32, &mut Ray) -> bool) -> (bool, u32) {
        if self.nodes.is_empty() {
            return (false, 0);
        }
        if self.depth <= SHALLOW_DEPTH {
            self.intersect_with::<SHALLOW_STACK>(ray, hit)
        } else {
            self.intersect_with::<STACK_SIZE>(ray, hit)
        }
    }

    /// [`Bvh4::intersect`] with a stack of `N` entries (at least 3 × depth + 1).
    #[inline(always)]
    fn intersect_with<const N: usize>(
        &self,
        ray: &mut Ray,
        mut hit: impl FnMut(u32, &mut Ray) -> bool,
    ) -> (bool, u32) {
        let rb = RayBoxes::new(ray);
        // Entries: the lane's entry distance (high half) and child word (low half), packed in
        // one word so that the stack is cheap to set up.
        let mut stack = [0u64; N];
        let entry = |word: u32, t: f32| (u64::from(t.to_bits()) << 32) | u64::from(word);
        let mut sp = 0usize;
        let mut word = 0u32; // the root, an inner node
        let mut visited = 0u32;
        let mut any = false;
        'walk: loop {
            if word & LEAF == 0 {
                visited += 1;
                let n = &self.nodes[word as usize];
                let (t_near, mut mask) = rb.test(n, ray.t_max);
                if mask != 0 {
                    let a = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        word = n.child[a];
                        continue 'walk;
                    }
                    let b = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        // Two children: go to the nearer, keep the other.
                        let (near, far) = if t_near[a] <= t_near[b] {
                            (a, b)
                        } else {
                            (b, a)
                        };
                        stack[sp] = entry(n.child[far], t_near[far]);
                        sp += 1;
                        word = n.child[near];
                        continue 'walk;
                    }
                    // Three or four: push all, sorted so that the nearest is on top; take it.
                    let base = sp;
                    for lane in [a, b] {
                        stack[sp] = entry(n.child[lane], t_near[lane]);
                        sp += 1;
                    }
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        stack[sp] = entry(n.child[lane], t_near[lane]);
                        sp += 1;
                    }
                    // Entry distances are non-negative, so their bit patterns sort as values.
                    stack[base..sp].sort_unstable_by(|x, y| y.cmp(x));
                    sp -= 1;
                    word = stack[sp] as u32;
                    continue 'walk;
                }
            } else {
                let (start, count) = leaf_range(word);
                for slot in start..start + count {
                    any |= hit(self.prim(slot), ray);
                }
            }
            // Next: the nearest kept entry that can still hold a closer hit.
            loop {
                if sp == 0 {
                    break 'walk;
                }
                sp -= 1;
                let e = stack[sp];
                if f32::from_bits((e >> 32) as u32) <= ray.t_max {
                    word = e as u32;
                    continue 'walk;
                }
            }
        }
        (any, visited)
    }

    /// Whether any primitive blocks `ray` (any hit, stopping at the first).
    #[inline]
    pub fn occluded(&self, ray: &Ray, hit: impl FnMut(u32, &Ray) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        if self.depth <= SHALLOW_DEPTH {
            self.occluded_with::<SHALLOW_STACK>(ray, hit)
        } else {
            self.occluded_with::<STACK_SIZE>(ray, hit)
        }
    }

    /// [`Bvh4::occluded`] with a stack of `N` entries (at least 3 × depth + 1).
    #[inline(always)]
    fn occluded_with<const N: usize>(
        &self,
        ray: &Ray,
        mut hit: impl FnMut(u32, &Ray) -> bool,
    ) -> bool {
        let rb = RayBoxes::new(ray);
        let mut stack = [0u32; N];
        let mut sp = 0usize;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            let (_, mut mask) = rb.test(n, ray.t_max);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let word = n.child[lane];
                if word & LEAF == 0 {
                    stack[sp] = word;
                    sp += 1;
                } else {
                    let (start, count) = leaf_range(word);
                    if (start..start + count).any(|slot| hit(self.prim(slot), ray)) {
                        return true;
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp];
        }
    }

    /// Every lane's box contains its subtree's primitives (for tests).
    #[cfg(test)]
    fn check(&self, prim_bounds: &[Aabb]) {
        fn contains(outer: &Aabb, inner: &Aabb) -> bool {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        }
        for n in &self.nodes {
            for lane in 0..4 {
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
                    for l in 0..4 {
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
            if n <= params.max_leaf_size && cost >= n as f32 {
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
                + (acc.surface_area() * cnt as f32 + right_area[i + 1] * right_count[i + 1] as f32)
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

    #[test]
    fn finds_the_same_nearest_hit_as_brute_force() {
        // Sizes around the parallel threshold and the leaf size, and one large tree.
        for (n, seed) in [(1, 1), (3, 2), (5, 3), (17, 4), (2000, 5), (20_000, 6)] {
            let boxes = random_boxes(n, seed);
            let bvh = Bvh4::build(&boxes, BvhParams::default());
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
        // Five boxes leave empty lanes; infinite and NaN origins and directions make the slab
        // test's products NaN, which must not open those lanes.
        let boxes = random_boxes(5, 8);
        let bvh = Bvh4::build(&boxes, BvhParams::default());
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
        let boxes = random_boxes(500, 7);
        let bvh = Bvh4::build(&boxes, BvhParams::default());
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
        let empty = Bvh4::build(&[], BvhParams::default());
        assert_eq!(empty.node_count(), 0);
        assert!(!empty.occluded(&Ray::new(Vec3::ZERO, Vec3::X), |_, _| true));
        let same = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE
            };
            100
        ];
        let bvh = Bvh4::build(&same, BvhParams::default());
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
            Bvh4::build(&bad, BvhParams::default())
                .primitive_indices()
                .len(),
            0
        );
    }
}
