//! The build: a binary tree by the binned surface area heuristic (subtrees in parallel), with
//! spatial splits where the caller bounds its primitives' parts ([`super::spatial`]), then
//! collapsed into wide nodes by opening the child of largest surface area.

use super::node::{leaf_word, Node, MAX_LEAF, MAX_PRIMITIVES};
use super::spatial::{
    find_spatial_split, spatial_partition, SplitPrim, SPLIT_BUDGET, SPLIT_MIN_REFS, SPLIT_OVERLAP,
};
use super::WideBvh;
use crate::accel::bvh::{build_prims, partition, BuildPrim, BvhParams};
use crate::geometry::Aabb;

/// Number of SAH bins per axis (fixed, so that binning needs no allocation).
pub(super) const BINS: usize = 32;
/// Subtrees with more primitives than this are built in parallel.
pub(super) const PARALLEL_THRESHOLD: usize = 4096;
/// Depth of the binary tree from which splits are at the median: below it, at most 32 more
/// levels for up to 2^32 primitives.
const MEDIAN_DEPTH: usize = 32;

/// The binary tree the builder makes before collapsing it.
enum BuildNode {
    Leaf {
        bounds: Aabb,
        /// Its first reference in the builder's array, then (after [`number_leaves`]) its
        /// first slot in the leaf order.
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

/// What every step of one build reads.
struct Builder<'a> {
    params: BvhParams,
    split: Option<SplitPrim<'a>>,
    /// Surface area of the whole tree's box: spatial splits are tried where the object
    /// split's children overlap by more than [`SPLIT_OVERLAP`] of it.
    root_area: f32,
}

impl<const W: usize> WideBvh<W> {
    /// Builds the tree over `bounds` (primitive `i` has box `bounds[i]`); primitives with an
    /// empty or non-finite box are left out. Uses `params.max_leaf_size` (at most 16),
    /// `params.traversal_cost` (relative to one leaf block test), `params.leaf_block` and 32
    /// bins. At most
    /// [`MAX_PRIMITIVES`] primitives: the caller checks.
    pub fn build(bounds: &[Aabb], params: BvhParams) -> WideBvh<W> {
        Self::build_with(bounds, params, None)
    }

    /// [`WideBvh::build`] with spatial splits (Stich, Friedrich and Dietrich, "Spatial Splits
    /// in Bounding Volume Hierarchies", 2009; what Embree's high-quality build does): where
    /// the best partition of the primitives leaves two boxes that overlap, a plane may cut
    /// the node's space instead, the primitives it crosses going to both sides, each bounded
    /// by `split` to its part. A primitive may then sit in several leaves (at most
    /// [`SPLIT_BUDGET`] more references than primitives in all), and the tree's boxes are
    /// tighter: fewer nodes visited per ray where large and small primitives mix.
    pub fn build_with_splits(bounds: &[Aabb], params: BvhParams, split: SplitPrim) -> WideBvh<W> {
        Self::build_with(bounds, params, Some(split))
    }

    fn build_with(bounds: &[Aabb], params: BvhParams, split: Option<SplitPrim>) -> WideBvh<W> {
        assert!(W == 4 || W == 8, "wide BVHs have 4 or 8 lanes");
        assert!(
            bounds.len() <= MAX_PRIMITIVES,
            "too many primitives for a wide BVH"
        );
        let params = BvhParams {
            max_leaf_size: params.max_leaf_size.clamp(1, MAX_LEAF),
            ..params
        };
        let mut refs = build_prims(bounds);
        if refs.is_empty() {
            return WideBvh::default();
        }
        let n = refs.len();
        let root_bounds = refs.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
        // Room for the references spatial splits add, within what a leaf word can name.
        let budget = match split {
            Some(_) => ((n as f32 * SPLIT_BUDGET) as usize).min(MAX_PRIMITIVES - n),
            None => 0,
        };
        refs.resize(n + budget, refs[0]);
        let builder = Builder {
            params,
            split,
            root_area: root_bounds.surface_area(),
        };
        let mut root = build_binary(&builder, &mut refs, n, 0, 0);
        let mut prim_indices = Vec::with_capacity(n);
        number_leaves(&mut root, &refs, &mut prim_indices);
        let mut bvh = WideBvh {
            nodes: Vec::with_capacity(prim_indices.len() / 2 + 1),
            prim_indices,
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

/// Gives the leaves their slots, depth first, left before right, and lists their primitives
/// (from the builder's array `refs`) in that order.
fn number_leaves(node: &mut BuildNode, refs: &[BuildPrim], order: &mut Vec<u32>) {
    match node {
        BuildNode::Leaf { start, count, .. } => {
            let first = order.len();
            order.extend(refs[*start..*start + *count].iter().map(|p| p.index));
            *start = first;
        }
        BuildNode::Inner { children, .. } => {
            let [a, b] = &mut **children;
            number_leaves(a, refs, order);
            number_leaves(b, refs, order);
        }
    }
}

/// Builds the binary SAH tree over the first `n` references of `refs` (which sit at `offset`
/// in the builder's array), reordering them into leaf order; the rest of `refs` is room for
/// the references spatial splits add.
fn build_binary(
    builder: &Builder,
    refs: &mut [BuildPrim],
    n: usize,
    offset: usize,
    depth: usize,
) -> BuildNode {
    let params = &builder.params;
    let budget = refs.len() - n;
    let prims = &mut refs[..n];
    let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
    let leaf = BuildNode::Leaf {
        bounds,
        start: offset,
        count: n,
    };
    if n <= 1 {
        return leaf;
    }
    let centroids = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
    let object = if depth < MEDIAN_DEPTH {
        find_split(prims, params, &bounds, &centroids)
    } else {
        None
    };
    // Spatial splits: tried in nodes of many references whose best partition leaves two
    // boxes that overlap.
    let spatial = match (&object, builder.split) {
        (Some(o), Some(split))
            if budget > 0
                && n >= SPLIT_MIN_REFS
                && o.overlap > SPLIT_OVERLAP * builder.root_area =>
        {
            find_spatial_split(prims, params, &bounds, split).filter(|s| s.cost < o.cost)
        }
        _ => None,
    };
    if let Some(cost) = spatial
        .as_ref()
        .map(|s| s.cost)
        .or(object.as_ref().map(|o| o.cost))
    {
        // Splitting a small set makes two leaves that the collapse puts side by side in one
        // wide node: what it adds is `leaf_split_cost`, not a traversal step.
        let split_cost = cost - params.traversal_cost + params.leaf_split_cost;
        if n <= params.max_leaf_size && split_cost >= blocks(n, params) {
            return leaf;
        }
    }
    // `mid` references on the left, then `m - mid` on the right.
    let spatial = match (spatial, builder.split) {
        (Some(s), Some(split)) => spatial_partition(refs, n, &s, split),
        _ => None,
    };
    let (mid, m) = match (spatial, object) {
        (Some(sides), _) => sides,
        (None, Some(o)) => {
            let (lo, extent) = (centroids.min[o.axis], centroids.extent()[o.axis]);
            let prims = &mut refs[..n];
            (
                partition(prims, |p| bin_of(p.centroid[o.axis], lo, extent) <= o.bin),
                n,
            )
        }
        (None, None) if n <= params.max_leaf_size.max(1) => return leaf,
        // Past the SAH depth, or when all centroids coincide (no plane separates them): halve
        // along the widest centroid axis.
        (None, None) => {
            let axis = centroids.largest_axis();
            let half = n / 2;
            refs[..n]
                .select_nth_unstable_by(half, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
            (half, n)
        }
    };
    let mid = if mid == 0 || mid == m { m / 2 } else { mid };
    // The room left goes to the children in proportion to their references, none to a child
    // too small to split spatially; the right side's references move up to make the left
    // side's room.
    let room = refs.len() - m;
    let left_room = match (mid >= SPLIT_MIN_REFS, m - mid >= SPLIT_MIN_REFS) {
        (false, _) => 0,
        (true, false) => room,
        (true, true) => (room as u64 * mid as u64 / m as u64) as usize,
    };
    if left_room > 0 {
        refs[mid..m + left_room].rotate_right(left_room);
    }
    let (left, right) = refs.split_at_mut(mid + left_room);
    let right_offset = offset + mid + left_room;
    let (a, b) = if n > PARALLEL_THRESHOLD {
        rayon::join(
            || build_binary(builder, left, mid, offset, depth + 1),
            || build_binary(builder, right, m - mid, right_offset, depth + 1),
        )
    } else {
        (
            build_binary(builder, left, mid, offset, depth + 1),
            build_binary(builder, right, m - mid, right_offset, depth + 1),
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

/// The best partition of a node's primitives by their centroids.
pub(super) struct ObjectSplit {
    axis: usize,
    /// The last bin on the left.
    bin: usize,
    /// SAH cost, relative to one leaf block test.
    pub(super) cost: f32,
    /// Surface area of the box where the two sides' boxes overlap.
    overlap: f32,
}

/// The best SAH split of `prims` by their centroids' bins.
fn find_split(
    prims: &[BuildPrim],
    params: &BvhParams,
    bounds: &Aabb,
    centroids: &Aabb,
) -> Option<ObjectSplit> {
    let extent = centroids.extent();
    let area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let mut best: Option<ObjectSplit> = None;
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
        let sweep = sah_sweep(&bin_bounds, &bin_count, &bin_count, params, area);
        if let Some((bin, cost)) = sweep.filter(|s| best.as_ref().is_none_or(|b| s.1 < b.cost)) {
            // The sides' boxes: the unions of their bins' boxes.
            let side = |bins: &[Aabb]| bins.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
            let (left, right) = (side(&bin_bounds[..=bin]), side(&bin_bounds[bin + 1..]));
            best = Some(ObjectSplit {
                axis,
                bin,
                cost,
                overlap: left.intersection(right).surface_area(),
            });
        }
    }
    best
}

/// The plane between bins of lowest SAH cost: (last bin on the left, cost relative to one
/// leaf block test), where the left side holds `left_count[..=i]` primitives and the right
/// `right_count[i + 1..]` (the same counts for an object split; for a spatial split those
/// that start and those that end in each bin); `None` if every plane leaves a side empty.
pub(super) fn sah_sweep(
    bin_bounds: &[Aabb; BINS],
    left_count: &[usize; BINS],
    right_count: &[usize; BINS],
    params: &BvhParams,
    area: f32,
) -> Option<(usize, f32)> {
    let mut right_area = [0.0f32; BINS];
    let mut right_total = [0usize; BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for i in (1..BINS).rev() {
        acc = acc.union(bin_bounds[i]);
        cnt += right_count[i];
        right_area[i] = acc.surface_area();
        right_total[i] = cnt;
    }
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    let mut best: Option<(usize, f32)> = None;
    for i in 0..BINS - 1 {
        acc = acc.union(bin_bounds[i]);
        cnt += left_count[i];
        if cnt == 0 || right_total[i + 1] == 0 {
            continue;
        }
        let cost = params.traversal_cost
            + (acc.surface_area() * blocks(cnt, params)
                + right_area[i + 1] * blocks(right_total[i + 1], params))
                / area;
        if best.is_none_or(|b| cost < b.1) {
            best = Some((i, cost));
        }
    }
    best
}
