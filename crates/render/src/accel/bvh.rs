//! A binary bounding volume hierarchy built with the binned surface area heuristic and
//! flattened into depth-first order for traversal.
//!
//! The builder needs only the primitives' bounding boxes; the traversal takes the primitive
//! test as a closure, so the same BVH serves triangles, spheres or anything else.
//!
//! References: Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies" (2007)
//! for binning; pbrt-v4 §7.3 for the flattened layout and ordered traversal.

use crate::geometry::{Aabb, Ray};
use glam::Vec3;

/// Build parameters of a [`Bvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhParams {
    /// Leaves hold at most this many primitives unless they cannot be split.
    pub max_leaf_size: usize,
    /// Bins per axis for evaluating the SAH.
    pub bins: usize,
    /// Cost of a traversal step relative to one primitive test.
    pub traversal_cost: f32,
    /// Primitives a leaf test handles together (the wide trees' SAH counts a leaf's cost in
    /// blocks of this many; 1 counts primitives, as the binary tree always does).
    pub leaf_block: usize,
    /// The wide trees' cost of splitting a set that could be a leaf into two leaves (which the
    /// collapse puts in the same wide node), in place of `traversal_cost` for that decision;
    /// relative to one leaf block test. The binary tree ignores it.
    pub leaf_split_cost: f32,
}

impl Default for BvhParams {
    fn default() -> Self {
        BvhParams {
            max_leaf_size: 4,
            bins: 16,
            traversal_cost: 1.0,
            leaf_block: 1,
            leaf_split_cost: 1.0,
        }
    }
}

/// One node of the flattened tree: a leaf when `count > 0` (primitives
/// `prim_indices[offset .. offset + count]`), otherwise an interior node whose first child is
/// the next node and whose second child is `offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    /// Bounds of everything below.
    pub bounds: Aabb,
    /// First primitive (leaf) or second child (interior).
    pub offset: u32,
    /// Number of primitives (0 for interior nodes).
    pub count: u16,
    /// Split axis of an interior node.
    pub axis: u8,
}

/// A BVH over primitives given by their bounding boxes.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    prim_indices: Vec<u32>,
}

/// A primitive as the builders (this binary tree's and the wide trees') see it.
#[derive(Clone, Copy)]
pub(super) struct BuildPrim {
    pub(super) bounds: Aabb,
    pub(super) centroid: Vec3,
    pub(super) index: u32,
}

/// The primitives a tree is built over: those whose box (`bounds[i]` for primitive `i`) is
/// neither empty nor non-finite.
pub(super) fn build_prims(bounds: &[Aabb]) -> Vec<BuildPrim> {
    bounds
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.is_empty() && b.min.is_finite() && b.max.is_finite())
        .map(|(i, b)| BuildPrim {
            bounds: *b,
            centroid: b.centroid(),
            index: i as u32,
        })
        .collect()
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
}

/// Depth from which nodes become leaves (when they fit one); below it only the median splits
/// of more than 65 535 primitives remain, which adds at most 16 levels.
const MAX_DEPTH: usize = 64;
/// Traversal stack size: enough for any tree the builder makes.
const STACK_SIZE: usize = MAX_DEPTH + 32;

impl Bvh {
    /// Builds the tree over `bounds` (primitive `i` has box `bounds[i]`). Primitives with an
    /// empty or non-finite box are left out.
    pub fn build(bounds: &[Aabb], params: BvhParams) -> Bvh {
        let mut prims = build_prims(bounds);
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * prims.len() / params.max_leaf_size.max(1) + 1),
            prim_indices: Vec::with_capacity(prims.len()),
        };
        if !prims.is_empty() {
            bvh.build_node(&mut prims, &params, 0);
        }
        bvh
    }

    /// Bytes held by the nodes and the primitive index list.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.prim_indices.as_slice())
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The nodes in depth-first order.
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Primitive indices in leaf order (back to the caller's numbering).
    pub fn primitive_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Bounds of the whole tree.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map(|n| n.bounds).unwrap_or(Aabb::EMPTY)
    }

    fn make_leaf(&mut self, prims: &[BuildPrim], bounds: Aabb) -> usize {
        let index = self.nodes.len();
        self.nodes.push(BvhNode {
            bounds,
            offset: self.prim_indices.len() as u32,
            count: prims.len() as u16,
            axis: 0,
        });
        self.prim_indices.extend(prims.iter().map(|p| p.index));
        index
    }

    fn build_node(&mut self, prims: &mut [BuildPrim], params: &BvhParams, depth: usize) -> usize {
        let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
        let n = prims.len();
        if n <= 1 || (depth >= MAX_DEPTH && n <= u16::MAX as usize) {
            return self.make_leaf(prims, bounds);
        }
        let centroid_bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
        let split = self.find_split(prims, params, &bounds, &centroid_bounds);
        let mid = match split {
            Some((axis, bin, cost)) => {
                let leaf_cost = n as f32;
                if cost >= leaf_cost && n <= params.max_leaf_size {
                    return self.make_leaf(prims, bounds);
                }
                let (lo, extent) = (centroid_bounds.min[axis], centroid_bounds.extent()[axis]);
                let bins = params.bins;
                let mid = partition(prims, |p| bin_of(p.centroid[axis], lo, extent, bins) <= bin);
                (axis, mid)
            }
            None => {
                // All centroids coincide: no plane separates them.
                if n <= u16::MAX as usize {
                    return self.make_leaf(prims, bounds);
                }
                (0, n / 2)
            }
        };
        let (axis, mid) = mid;
        let mid = if mid == 0 || mid == n { n / 2 } else { mid };
        let index = self.nodes.len();
        self.nodes.push(BvhNode {
            bounds,
            offset: 0,
            count: 0,
            axis: axis as u8,
        });
        let (left, right) = prims.split_at_mut(mid);
        self.build_node(left, params, depth + 1);
        let second = self.build_node(right, params, depth + 1);
        self.nodes[index].offset = second as u32;
        index
    }

    /// The best SAH split: (axis, last bin on the left, cost relative to one primitive test).
    fn find_split(
        &self,
        prims: &[BuildPrim],
        params: &BvhParams,
        bounds: &Aabb,
        centroid_bounds: &Aabb,
    ) -> Option<(usize, usize, f32)> {
        let bins = params.bins.max(2);
        let extent = centroid_bounds.extent();
        let area = bounds.surface_area();
        let mut best: Option<(usize, usize, f32)> = None;
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            let lo = centroid_bounds.min[axis];
            let mut table = vec![
                Bin {
                    bounds: Aabb::EMPTY,
                    count: 0
                };
                bins
            ];
            for p in prims {
                let b = &mut table[bin_of(p.centroid[axis], lo, extent[axis], bins)];
                b.bounds = b.bounds.union(p.bounds);
                b.count += 1;
            }
            // Sweep from the right to get the cost of every right side, then from the left.
            let mut right_area = vec![0.0f32; bins];
            let mut right_count = vec![0usize; bins];
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            for i in (1..bins).rev() {
                acc = acc.union(table[i].bounds);
                cnt += table[i].count;
                right_area[i] = acc.surface_area();
                right_count[i] = cnt;
            }
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            for i in 0..bins - 1 {
                acc = acc.union(table[i].bounds);
                cnt += table[i].count;
                if cnt == 0 || right_count[i + 1] == 0 {
                    continue;
                }
                let cost = params.traversal_cost
                    + (acc.surface_area() * cnt as f32
                        + right_area[i + 1] * right_count[i + 1] as f32)
                        / area.max(f32::MIN_POSITIVE);
                if best.is_none_or(|b| cost < b.2) {
                    best = Some((axis, i, cost));
                }
            }
        }
        best
    }

    /// Finds the nearest primitive hit by `ray`. `hit(prim, ray)` tests one primitive and, when
    /// it hits closer than `ray.t_max`, shortens `ray.t_max` to the hit and returns true.
    /// Returns whether anything was hit and how many nodes were visited.
    #[inline]
    pub fn intersect(
        &self,
        ray: &mut Ray,
        mut hit: impl FnMut(u32, &mut Ray) -> bool,
    ) -> (bool, u32) {
        if self.nodes.is_empty() {
            return (false, 0);
        }
        let inv_d = ray.d.recip();
        let neg = [inv_d.x < 0.0, inv_d.y < 0.0, inv_d.z < 0.0];
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0usize;
        let mut node = 0usize;
        let mut visited = 0u32;
        let mut any = false;
        loop {
            visited += 1;
            let n = &self.nodes[node];
            if n.bounds.hit(ray.o, inv_d, ray.t_max).is_some() {
                if n.count > 0 {
                    let start = n.offset as usize;
                    for &p in &self.prim_indices[start..start + n.count as usize] {
                        any |= hit(p, ray);
                    }
                } else {
                    // Visit the child on the near side of the split first.
                    let (first, second) = if neg[n.axis as usize] {
                        (n.offset as usize, node + 1)
                    } else {
                        (node + 1, n.offset as usize)
                    };
                    stack[sp] = second as u32;
                    sp += 1;
                    node = first;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
        (any, visited)
    }

    /// Whether any primitive blocks `ray` (any hit, stopping at the first).
    #[inline]
    pub fn occluded(&self, ray: &Ray, mut hit: impl FnMut(u32, &Ray) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_d = ray.d.recip();
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.bounds.hit(ray.o, inv_d, ray.t_max).is_some() {
                if n.count > 0 {
                    let start = n.offset as usize;
                    if self.prim_indices[start..start + n.count as usize]
                        .iter()
                        .any(|&p| hit(p, ray))
                    {
                        return true;
                    }
                } else {
                    stack[sp] = n.offset;
                    sp += 1;
                    node += 1;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }
}

#[inline]
fn bin_of(c: f32, lo: f32, extent: f32, bins: usize) -> usize {
    let b = ((c - lo) / extent * bins as f32) as usize;
    b.min(bins - 1)
}

/// Moves the elements satisfying `pred` to the front; returns how many there are.
pub(super) fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{check_against_brute_force, random_boxes};
    use super::*;

    #[test]
    fn finds_the_same_nearest_hit_as_brute_force() {
        let boxes = random_boxes(2000, 3);
        let bvh = Bvh::build(&boxes, BvhParams::default());
        let mut seen: Vec<u32> = bvh.primitive_indices().to_vec();
        seen.sort();
        assert_eq!(seen, (0..2000).collect::<Vec<u32>>());
        check_against_brute_force(
            &boxes,
            2000,
            (4, 4),
            |r, h| bvh.intersect(r, h),
            |r, h| bvh.occluded(r, h),
        );
    }

    #[test]
    fn edge_cases() {
        let empty = Bvh::build(&[], BvhParams::default());
        assert_eq!(empty.node_count(), 0);
        assert_eq!(
            empty.intersect(&mut Ray::new(Vec3::ZERO, Vec3::X), |_, _| true),
            (false, 0)
        );
        // Identical boxes (all centroids equal) and non-finite ones.
        let same = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE
            };
            100
        ];
        let bvh = Bvh::build(&same, BvhParams::default());
        assert_eq!(bvh.primitive_indices().len(), 100);
        let bad = vec![
            Aabb {
                min: Vec3::splat(f32::NAN),
                max: Vec3::ONE,
            },
            Aabb::EMPTY,
        ];
        assert_eq!(
            Bvh::build(&bad, BvhParams::default())
                .primitive_indices()
                .len(),
            0
        );
    }
}
