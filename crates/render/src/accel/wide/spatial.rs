//! Spatial splits (Stich, Friedrich and Dietrich, "Spatial Splits in Bounding Volume
//! Hierarchies", 2009): a node's space cut by a plane, the primitives the plane crosses going
//! to both sides, each side's reference bounded by its part of the primitive.
//!
//! The binning: the node's box is cut into [`BINS`] slabs per axis; a primitive crossing
//! several slabs is clipped at each boundary (by the caller's [`SplitPrim`]) and each piece's
//! box goes to its slab; the primitive counts once where it starts (left sides) and once where
//! it ends (right sides). The sweep over the planes is the object split's
//! ([`super::build::sah_sweep`]).

use super::build::{sah_sweep, BINS, PARALLEL_THRESHOLD};
use crate::accel::bvh::{partition, BuildPrim, BvhParams};
use crate::geometry::Aabb;

/// Spatial splits are tried where the best object split's two boxes overlap by more than this
/// fraction of the whole tree's surface area (Stich et al.'s α).
pub(super) const SPLIT_OVERLAP: f32 = 1e-5;

/// Spatial splits are tried in nodes of at least this many references. Near the root is where
/// they pay: the course's bunny in its box is traced through as few nodes with splits tried
/// from 4096 references up as from 2, and the build takes a fifth of the time.
pub(super) const SPLIT_MIN_REFS: usize = 4096;

/// At most this many references more than primitives, as a fraction of the primitives (the
/// tree's memory for triangle blocks grows by as much).
pub const SPLIT_BUDGET: f32 = 0.3;

/// The boxes of a primitive's parts on either side of a plane, for spatial splits:
/// `split(prim, bounds, axis, pos)` bounds the part of primitive `prim` inside `bounds` below
/// `pos` on `axis`, and the part above it. Each box must hold its part (an empty box when
/// there is none); [`split_box`] is right for any primitive, a tighter one (a triangle's
/// clipped polygon) makes better trees.
pub type SplitPrim<'a> = &'a (dyn Fn(u32, &Aabb, usize, f32) -> (Aabb, Aabb) + Sync);

/// The split of a primitive that is known only by its box: the box cut at the plane.
pub fn split_box(_prim: u32, bounds: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let (mut below, mut above) = (*bounds, *bounds);
    below.max[axis] = below.max[axis].min(pos);
    above.min[axis] = above.min[axis].max(pos);
    (below, above)
}

/// The best plane cutting a node's space.
pub(super) struct SpatialSplit {
    axis: usize,
    pos: f32,
    /// SAH cost, relative to one leaf block test.
    pub(super) cost: f32,
}

/// The slab of `x` among the [`BINS`] that cut `[lo, lo + BINS · width]`.
#[inline]
fn slab_of(x: f32, lo: f32, width: f32) -> usize {
    (((x - lo) / width) as usize).min(BINS - 1)
}

/// The plane of lowest SAH cost among the slab boundaries of every axis of `bounds` (the
/// node's box). The axes are binned in parallel in large nodes (the first ones, where the
/// build has no subtrees to run side by side yet); the choice is the same either way.
pub(super) fn find_spatial_split(
    prims: &[BuildPrim],
    params: &BvhParams,
    bounds: &Aabb,
    split: SplitPrim,
) -> Option<SpatialSplit> {
    let on = |axis| best_plane_on(axis, prims, params, bounds, split);
    let [x, y, z] = if prims.len() > PARALLEL_THRESHOLD {
        let (x, (y, z)) = rayon::join(|| on(0), || rayon::join(|| on(1), || on(2)));
        [x, y, z]
    } else {
        [on(0), on(1), on(2)]
    };
    // The first axis of lowest cost.
    [x, y, z]
        .into_iter()
        .flatten()
        .fold(None, |best: Option<SpatialSplit>, s| match best {
            Some(b) if b.cost <= s.cost => Some(b),
            _ => Some(s),
        })
}

/// The plane of lowest SAH cost among the slab boundaries on `axis`.
fn best_plane_on(
    axis: usize,
    prims: &[BuildPrim],
    params: &BvhParams,
    bounds: &Aabb,
    split: SplitPrim,
) -> Option<SpatialSplit> {
    let extent = bounds.extent()[axis];
    if extent <= 0.0 {
        return None;
    }
    let area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let (lo, width) = (bounds.min[axis], extent / BINS as f32);
    let mut bin_bounds = [Aabb::EMPTY; BINS];
    let mut starts = [0usize; BINS];
    let mut ends = [0usize; BINS];
    for p in prims {
        let first = slab_of(p.bounds.min[axis], lo, width);
        let last = slab_of(p.bounds.max[axis], lo, width).max(first);
        starts[first] += 1;
        ends[last] += 1;
        let mut rest = p.bounds;
        for (slab, boxes) in bin_bounds.iter_mut().enumerate().take(last).skip(first) {
            let (piece, above) = split(p.index, &rest, axis, lo + (slab + 1) as f32 * width);
            *boxes = boxes.union(piece);
            rest = above;
        }
        bin_bounds[last] = bin_bounds[last].union(rest);
    }
    let (slab, cost) = sah_sweep(&bin_bounds, &starts, &ends, params, area)?;
    Some(SpatialSplit {
        axis,
        pos: lo + (slab + 1) as f32 * width,
        cost,
    })
}

/// Cuts the first `n` references of `refs` at the plane of `s` in place: a reference the plane
/// crosses becomes the box of its part below (in its place) and that of its part above (after
/// the `n`, in the room `refs` has there); then those below come first. Returns how many are
/// below and how many there are in all, or `None` (with `refs` untouched) when the plane would
/// add more references than there is room for, or leave a side with as many as the node.
pub(super) fn spatial_partition(
    refs: &mut [BuildPrim],
    n: usize,
    s: &SpatialSplit,
    split: SplitPrim,
) -> Option<(usize, usize)> {
    let (axis, pos) = (s.axis, s.pos);
    let crosses = |p: &BuildPrim| p.bounds.min[axis] < pos && p.bounds.max[axis] > pos;
    let (mut below, mut crossing) = (0, 0);
    for p in &refs[..n] {
        below += usize::from(p.bounds.max[axis] <= pos);
        crossing += usize::from(crosses(p));
    }
    // Every reference on the left (crossing ones included), or on the right (none wholly
    // below), would make no progress.
    if crossing > refs.len() - n || below + crossing >= n || below == 0 {
        return None;
    }
    let piece = |bounds: Aabb, index: u32| BuildPrim {
        bounds,
        centroid: bounds.centroid(),
        index,
    };
    let mut m = n;
    for i in 0..n {
        let p = refs[i];
        if !crosses(&p) {
            continue;
        }
        let (lo, hi) = split(p.index, &p.bounds, axis, pos);
        match (lo.is_empty(), hi.is_empty()) {
            (false, false) => {
                refs[i] = piece(lo, p.index);
                refs[m] = piece(hi, p.index);
                m += 1;
            }
            (false, true) => refs[i] = piece(lo, p.index),
            (true, false) => refs[i] = piece(hi, p.index),
            // No part on either side (a split that found nothing): kept whole, on the right.
            (true, true) => {}
        }
    }
    let mid = partition(&mut refs[..m], |p| p.bounds.max[axis] <= pos);
    Some((mid, m))
}
