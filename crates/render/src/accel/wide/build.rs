//! The build: a binary tree by the binned surface area heuristic (subtrees in parallel), then
//! collapsed into wide nodes by opening the child of largest surface area.

use super::node::{leaf_word, Node, MAX_LEAF, MAX_PRIMITIVES};
use super::WideBvh;
use crate::accel::bvh::{build_prims, partition, BuildPrim, BvhParams};
use crate::geometry::Aabb;

/// Number of SAH bins per axis (fixed, so that binning needs no allocation).
const BINS: usize = 32;
/// Subtrees with more primitives than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;
/// Depth of the binary tree from which splits are at the median: below it, at most 32 more
/// levels for up to 2^32 primitives.
const MEDIAN_DEPTH: usize = 32;

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
        let mut prims = build_prims(bounds);
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
