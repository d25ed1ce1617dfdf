//! The traversals: nearest hit and any hit, nearest boxes first, with the leaf test as a
//! closure.

use super::box_test::{BoxTest, Portable, RayBoxes};
use super::node::LEAF;
use super::stack::{order, stack_entry, Stack, STACK_SIZE};
use super::WideBvh;
use crate::geometry::Ray;

impl<const W: usize> WideBvh<W> {
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
        // The root first: a ray that meets none of its boxes (one that leaves the scene)
        // returns before the walk's own set-up, which the compiler places ahead of its loop.
        let mut n = &self.nodes[0];
        let (mut t_near, mut mask) = boxes.test(&rb, n, ray.t_max);
        if mask == 0 {
            return (false, 1);
        }
        let mut stack = Stack::<u64, STACK_SIZE>::new();
        let mut visited = 1u32;
        let mut any = false;
        'walk: loop {
            // `n`'s children in `mask` (at least one) at entry distances `t_near`: the nearest
            // is next, the others wait on the stack, farthest deepest (a sorting network, no
            // branches on distances).
            let next = |mask: &mut u32| {
                let lane = mask.trailing_zeros() as usize;
                *mask &= *mask - 1;
                stack_entry(n.child[lane], t_near[lane])
            };
            let mut word = 'pick: {
                let a = next(&mut mask);
                if mask == 0 {
                    break 'pick a as u32;
                }
                let (a, b) = order(a, next(&mut mask));
                if mask == 0 {
                    stack.push(b);
                    break 'pick a as u32;
                }
                let c = next(&mut mask);
                if mask == 0 {
                    let (b, c) = order(b, c);
                    let (a, b) = order(a, b);
                    stack.push(c);
                    stack.push(b);
                    break 'pick a as u32;
                }
                let (c, d) = order(c, next(&mut mask));
                let (a, c) = order(a, c);
                let (b, d) = order(b, d);
                let (b, c) = order(b, c);
                if mask == 0 {
                    stack.push(d);
                    stack.push(c);
                    stack.push(b);
                    break 'pick a as u32;
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
                stack.pop().unwrap_or(a) as u32
            };
            // Down to the next node some of whose boxes the ray meets, testing the leaves on
            // the way; the nearest kept entry that can still hold a closer hit after each
            // dead end.
            loop {
                if word & LEAF == 0 {
                    visited += 1;
                    n = &self.nodes[word as usize];
                    (t_near, mask) = boxes.test(&rb, n, ray.t_max);
                    if mask != 0 {
                        continue 'walk;
                    }
                } else {
                    any |= leaf(word, ray);
                }
                loop {
                    let Some(e) = stack.pop() else {
                        break 'walk;
                    };
                    if f32::from_bits((e >> 32) as u32) <= ray.t_max {
                        word = e as u32;
                        break;
                    }
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
        // The root first, as in the nearest-hit walk.
        let mut n = &self.nodes[0];
        let (_, mut mask) = boxes.test(&rb, n, ray.t_max);
        if mask == 0 {
            return false;
        }
        let mut stack = Stack::<u32, STACK_SIZE>::new();
        loop {
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
                Some(next) => {
                    n = &self.nodes[next as usize];
                    mask = boxes.test(&rb, n, ray.t_max).1;
                }
                None => return false,
            }
        }
    }
}
