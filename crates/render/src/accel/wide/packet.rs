//! Eight rays walking the tree together. The packet is bounded by one interval ray: per axis
//! the extreme origins and the range of 1/d, whose slab test against a node's eight boxes
//! costs about what one ray's does and bounds every ray's entry and exit distances (interval
//! arithmetic; the rounded operations are monotone, so the bounds hold for each ray's
//! distances computed as `(p - o) · (1/d)`, rounded and widened as pbrt-v4's slab test, which
//! is conservative). A child is visited when the interval ray meets it, nearest first, and a
//! leaf is handed to the caller once for all eight. For rays that go the same way (the camera
//! rays of one pixel, neighbouring primary rays) the walk, its stack and its branches are paid
//! once instead of eight times; each ray still finds its own nearest hit, since the packet
//! visits every box any of its rays meets, and a ray that misses a box the packet enters only
//! costs its lane of the leaf's tests.
//!
//! [`RayBoxLanes`] tests eight rays exactly against one box (the small scenes' block culling).

use super::box_test::met_mask;
use super::node::LEAF;
use super::stack::{stack_entry, Stack, STACK_SIZE};
use super::{Node, WideBvh, FAR_SCALE};
use crate::accel::RayLanes;
use crate::geometry::Aabb;
use crate::simd::lanes::{F8, M8, W as LANES};

/// Eight rays set up for testing boxes, a lane each: the BVH's slab test ([`super::BoxTest`]'s
/// portable one, far distances widened by [`FAR_SCALE`]), with the lanes being rays instead
/// of boxes. A lane whose `t_max` is -∞ meets no box.
pub(crate) struct RayBoxLanes {
    o: [F8; 3],
    inv_d: [F8; 3],
    /// `inv_d` widened by [`FAR_SCALE`], for far planes.
    inv_far: [F8; 3],
    /// Lanes whose direction is negative on the axis (they enter by the upper plane).
    negative: [M8; 3],
    /// Where entry distances start: `t_min`, or +0 where it is not positive.
    t_min: F8,
}

impl RayBoxLanes {
    #[inline(always)]
    pub(crate) fn new(rays: &RayLanes) -> RayBoxLanes {
        // Plain loops rather than `array::map`: its closures are not always inlined, and
        // where they are not, each lane's sign is a call.
        let d = [rays.d.x, rays.d.y, rays.d.z];
        let (mut inv_d, mut inv_far) = ([F8::splat(0.0); 3], [F8::splat(0.0); 3]);
        let mut negative = [M8::default(); 3];
        for axis in 0..3 {
            inv_d[axis] = F8::splat(1.0) / d[axis];
            inv_far[axis] = inv_d[axis] * F8::splat(FAR_SCALE);
            for (m, x) in negative[axis].0.iter_mut().zip(d[axis].0) {
                *m = if x.is_sign_negative() { !0 } else { 0 };
            }
        }
        let zero = F8::splat(0.0);
        RayBoxLanes {
            o: [rays.o.x, rays.o.y, rays.o.z],
            inv_d,
            inv_far,
            negative,
            t_min: rays.t_min.gt(zero).select(rays.t_min, zero),
        }
    }

    /// Whether some lane's ray meets `bounds` between its `t_min` and `t_max`.
    #[inline(always)]
    pub(crate) fn meets(&self, bounds: &Aabb, t_max: F8) -> bool {
        let (mut t_near, mut t_far) = (self.t_min, t_max);
        for axis in 0..3 {
            let (lo, hi) = (F8::splat(bounds.min[axis]), F8::splat(bounds.max[axis]));
            let near = self.negative[axis].select(hi, lo);
            let far = self.negative[axis].select(lo, hi);
            let tn = (near - self.o[axis]) * self.inv_d[axis];
            let tf = (far - self.o[axis]) * self.inv_far[axis];
            // As the BVH's test: a NaN (0 · ∞ for a ray in a box's plane) leaves the running
            // value unchanged.
            t_near = tn.gt(t_near).select(tn, t_near);
            t_far = tf.lt(t_far).select(tf, t_far);
        }
        t_near.le(t_far).0.iter().fold(0, |any, &m| any | m) != 0
    }
}

/// The interval ray that bounds a packet of rays going the same way (see the module notes).
pub(crate) struct PacketBounds {
    /// Per axis, the index in [`super::Node::planes`] of the plane every ray enters by and of
    /// the one it leaves by (the rays' directions share their signs).
    near: [usize; 3],
    far: [usize; 3],
    /// Per axis, the origin coordinate that gives the smallest entry distance (the largest
    /// for a positive direction) and the one that gives the largest exit distance.
    o_near: [f32; 3],
    o_far: [f32; 3],
    /// Per axis, the smallest and largest 1/d, and of 1/d widened by [`FAR_SCALE`].
    inv: [[f32; 2]; 3],
    inv_far: [[f32; 2]; 3],
    /// The smallest start of the rays' extents (+0 where not positive, as one ray's test).
    t_min: f32,
}

impl PacketBounds {
    /// The interval ray of the lanes `active` of `rays`; none where their directions differ
    /// in sign on some axis, or a direction or origin component is zero or not finite (the
    /// bounds would need NaN's rules; such packets walk one ray at a time). Written over whole
    /// lanes (one division of all eight per axis), not lane by lane.
    pub(crate) fn new(rays: &RayLanes, active: u32) -> Option<PacketBounds> {
        if active == 0 {
            return None;
        }
        let on = M8(std::array::from_fn(|l| {
            if active & (1 << l) != 0 {
                !0
            } else {
                0
            }
        }));
        let o = [rays.o.x, rays.o.y, rays.o.z];
        let d = [rays.d.x, rays.d.y, rays.d.z];
        let mut b = PacketBounds {
            near: [0; 3],
            far: [0; 3],
            o_near: [0.0; 3],
            o_far: [0.0; 3],
            inv: [[0.0; 2]; 3],
            inv_far: [[0.0; 2]; 3],
            t_min: 0.0,
        };
        let (inf, neg_inf) = (F8::splat(f32::INFINITY), F8::splat(f32::NEG_INFINITY));
        // Smallest and largest of the active lanes (idle lanes give way).
        let range = |x: F8| (min_of(on.select(x, inf)), max_of(on.select(x, neg_inf)));
        for axis in 0..3 {
            let inv = F8::splat(1.0) / d[axis];
            let inv_far = inv * F8::splat(FAR_SCALE);
            // Every active lane's 1/d and origin finite, and its direction's sign the same.
            let (inv_ok, o_ok) = (inv.is_finite().0, o[axis].is_finite().0);
            let mut bad = 0u32;
            let (mut negative, mut positive) = (0u32, 0u32);
            for (l, (fi, fo)) in inv_ok.into_iter().zip(o_ok).enumerate() {
                let neg = d[axis].0[l].to_bits() >> 31;
                negative |= on.0[l] & neg;
                positive |= on.0[l] & (neg ^ 1);
                bad |= on.0[l] & !(fi & fo);
            }
            if bad != 0 || negative & positive != 0 {
                return None;
            }
            let negative = negative != 0;
            let (i0, i1) = range(inv);
            let (f0, f1) = range(inv_far);
            let (o_min, o_max) = range(o[axis]);
            b.inv[axis] = [i0, i1];
            b.inv_far[axis] = [f0, f1];
            // A positive direction enters by the lower plane: its entry distance falls as the
            // origin grows, its exit distance too; a negative one the other way round.
            let plane = |upper: bool| axis + 3 * usize::from(upper);
            (b.near[axis], b.far[axis]) = (plane(negative), plane(!negative));
            (b.o_near[axis], b.o_far[axis]) = if negative {
                (o_min, o_max)
            } else {
                (o_max, o_min)
            };
        }
        let zero = F8::splat(0.0);
        b.t_min = min_of(on.select(rays.t_min.gt(zero).select(rays.t_min, zero), inf));
        Some(b)
    }

    /// Lower bounds of the rays' entry distances into a node's `W` boxes, and the mask of the
    /// boxes that some ray may meet before `t_max` (the largest of the rays' far ends).
    #[inline(always)]
    fn test<const W: usize>(&self, n: &Node<W>, t_max: f32) -> ([f32; W], u32) {
        let mut t_near = [self.t_min; W];
        let mut t_far = [t_max; W];
        for axis in 0..3 {
            let near = &n.planes[self.near[axis]];
            let far = &n.planes[self.far[axis]];
            let [i0, i1] = self.inv[axis];
            let [f0, f1] = self.inv_far[axis];
            for lane in 0..W {
                // Products are monotone in each factor: the smallest entry is at an end of
                // the range of 1/d, from the origin that minimises it; likewise the largest
                // exit.
                let x = near[lane] - self.o_near[axis];
                let (a, b) = (x * i0, x * i1);
                let tn = if a < b { a } else { b };
                let y = far[lane] - self.o_far[axis];
                let (c, e) = (y * f0, y * f1);
                let tf = if c > e { c } else { e };
                t_near[lane] = if tn > t_near[lane] { tn } else { t_near[lane] };
                t_far[lane] = if tf < t_far[lane] { tf } else { t_far[lane] };
            }
        }
        (t_near, met_mask(&t_near, &t_far, n.valid))
    }
}

/// The largest lane, by halves (a NaN lane may or may not be skipped).
#[inline(always)]
fn max_of(t: F8) -> f32 {
    let max = |a: f32, b: f32| if a > b { a } else { b };
    let t = t.0;
    let four: [f32; 4] = std::array::from_fn(|i| max(t[i], t[i + 4]));
    max(max(four[0], four[2]), max(four[1], four[3]))
}

/// The smallest lane, by halves (a NaN lane may or may not be skipped).
#[inline(always)]
fn min_of(t: F8) -> f32 {
    let min = |a: f32, b: f32| if a < b { a } else { b };
    let t = t.0;
    let four: [f32; 4] = std::array::from_fn(|i| min(t[i], t[i + 4]));
    min(min(four[0], four[2]), min(four[1], four[3]))
}

impl WideBvh<LANES> {
    /// Walks the tree with the packet `rays` (bounded by one interval ray), whose nearest hits
    /// so far `nearest` holds (`t_max(nearest)`: each ray's far end, shortened as hits are
    /// found). `leaf(nearest, word)` tests the leaf whose range [`WideBvh::leaf_range`]
    /// decodes from `word` against the rays and records their nearer hits in `nearest`. A
    /// child is visited when the interval ray meets its box before the farthest far end,
    /// nearest entry first, and a stacked child is skipped when its entry lies beyond every
    /// ray's far end. Returns the number of nodes visited.
    #[inline(always)]
    pub(crate) fn packet_leaves<N>(
        &self,
        rays: &PacketBounds,
        nearest: &mut N,
        t_max: impl Fn(&N) -> F8,
        mut leaf: impl FnMut(&mut N, u32),
    ) -> u32 {
        if self.nodes.is_empty() {
            return 0;
        }
        let mut stack = Stack::<u64, STACK_SIZE>::new();
        let mut word = 0u32; // the root, an inner node
        let mut visited = 0u32;
        'walk: loop {
            if word & LEAF == 0 {
                visited += 1;
                let n = &self.nodes[word as usize];
                let (t_near, mut mask) = rays.test(n, max_of(t_max(nearest)));
                if mask != 0 {
                    // The met children, farthest deepest; go to the nearest.
                    let base = stack.len();
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        stack.push(stack_entry(n.child[lane], t_near[lane]));
                    }
                    stack.sort_descending_from(base);
                    if let Some(e) = stack.pop() {
                        word = e as u32;
                        continue 'walk;
                    }
                }
            } else {
                leaf(nearest, word);
            }
            // Next: the nearest kept entry that some ray can still reach before its far end.
            let far = max_of(t_max(nearest));
            loop {
                let Some(e) = stack.pop() else {
                    break 'walk;
                };
                if f32::from_bits((e >> 32) as u32) <= far {
                    word = e as u32;
                    continue 'walk;
                }
            }
        }
        visited
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;
    use glam::Vec3;
    use pathlab_mc::rng::Pcg32;

    /// Eight rays: from one point or from points spread over a region, towards directions
    /// close together or anywhere in one octant (or, with `mixed`, anywhere), some with a
    /// finite extent or a start past zero, some lanes idle.
    fn packet(rng: &mut Pcg32, mixed: bool) -> ([Ray; 8], u32) {
        let mut u = || rng.uniform_f32();
        let base = Vec3::new(u() + 0.05, u() + 0.05, u() + 0.05)
            * Vec3::new(
                if u() < 0.5 { -1.0 } else { 1.0 },
                if u() < 0.5 { -1.0 } else { 1.0 },
                if u() < 0.5 { -1.0 } else { 1.0 },
            );
        let (spread_o, spread_d) = (u() * 2.0, if u() < 0.5 { 0.01 } else { 1.0 });
        let o0 = Vec3::new(u(), u(), u()) * 6.0 - 3.0;
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::X); 8];
        for ray in &mut rays {
            let o = o0 + (Vec3::new(u(), u(), u()) - 0.5) * spread_o;
            let mut d = base + (Vec3::new(u(), u(), u()) - 0.5) * spread_d;
            if !mixed {
                // Keep the octant.
                d = d.abs().max(Vec3::splat(1e-3)) * base.signum();
            }
            *ray = Ray::new(o, d);
            if u() < 0.2 {
                ray.t_max = u() * 4.0;
            }
            if u() < 0.2 {
                ray.t_min = u();
            }
        }
        let active = ((u() * 255.0) as u32 | 1) & 0xff;
        (rays, active)
    }

    fn lanes(rays: &[Ray; 8]) -> RayLanes {
        let mut l = RayLanes::default();
        for (i, r) in rays.iter().enumerate() {
            l.set(i, r);
        }
        l
    }

    /// One ray's slab test with its distances as `(p - o) · (1/d)`, each operation rounded
    /// (the far ones widened by [`FAR_SCALE`]): the arithmetic whose results the interval
    /// ray bounds, conservative as pbrt-v4's test is. (The traversal of one ray computes its
    /// distances with fused operations, [`super::super::box_test::RayBoxes`].)
    fn slab_test(ray: &Ray, n: &Node<8>) -> ([f32; 8], u32) {
        let t_min = if ray.t_min > 0.0 { ray.t_min } else { 0.0 };
        let (mut t_near, mut t_far) = ([t_min; 8], [ray.t_max; 8]);
        for axis in 0..3 {
            let inv = 1.0 / ray.d[axis];
            let upper = usize::from(ray.d[axis].is_sign_negative());
            let (near, far) = (
                &n.planes[axis + 3 * upper],
                &n.planes[axis + 3 * (1 - upper)],
            );
            for lane in 0..8 {
                let tn = (near[lane] - ray.o[axis]) * inv;
                let tf = (far[lane] - ray.o[axis]) * (inv * FAR_SCALE);
                t_near[lane] = if tn > t_near[lane] { tn } else { t_near[lane] };
                t_far[lane] = if tf < t_far[lane] { tf } else { t_far[lane] };
            }
        }
        (t_near, met_mask(&t_near, &t_far, n.valid))
    }

    #[test]
    fn the_interval_ray_meets_every_box_a_ray_of_the_packet_meets() {
        // Against random nodes of eight boxes: wherever one ray's slab test meets a box, the
        // packet's test meets it too, with an entry bound at most that ray's entry distance.
        // Packets whose directions differ in sign have no interval ray.
        let mut rng = Pcg32::new(11, 3);
        let (mut bounded, mut met, mut unmixed) = (0, 0, 0);
        for k in 0..4000 {
            let mut node = Node::<8>::EMPTY;
            for lane in 0..8 {
                if rng.uniform_f32() < 0.9 {
                    let c = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                    let e = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                    let (c, e) = (c * 8.0 - 4.0, e * 2.5);
                    node.set_bounds(
                        lane,
                        &Aabb {
                            min: c - e,
                            max: c + e * 0.5,
                        },
                    );
                    node.child[lane] = lane as u32;
                    node.valid |= 1 << lane;
                }
            }
            let mixed = k % 4 == 0;
            let (rays, active) = packet(&mut rng, mixed);
            let Some(bounds) = PacketBounds::new(&lanes(&rays), active) else {
                assert!(mixed, "a packet in one octant is bounded");
                continue;
            };
            unmixed += usize::from(!mixed);
            bounded += 1;
            let far = (0..8)
                .filter(|&i| active & (1 << i) != 0)
                .map(|i| rays[i].t_max)
                .fold(f32::NEG_INFINITY, f32::max);
            let (lower, mask) = bounds.test(&node, far);
            for (i, ray) in rays.iter().enumerate() {
                if active & (1 << i) == 0 {
                    continue;
                }
                let (t_near, own) = slab_test(ray, &node);
                assert_eq!(
                    own & !mask,
                    0,
                    "packet {k}, ray {i}: a box it meets is culled"
                );
                for lane in (0..8).filter(|&l| own & (1 << l) != 0) {
                    assert!(
                        lower[lane] <= t_near[lane],
                        "packet {k}, ray {i}, box {lane}"
                    );
                    met += 1;
                }
            }
        }
        assert!(
            unmixed > 2000 && bounded > unmixed,
            "{bounded} bounded, {unmixed} in one octant"
        );
        assert!(met > 4000, "only {met} boxes met");
    }

    #[test]
    fn zero_or_infinite_components_and_no_active_lane_have_no_interval_ray() {
        let ray = Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.25));
        let ok = lanes(&[ray; 8]);
        assert!(PacketBounds::new(&ok, 0xff).is_some());
        assert!(PacketBounds::new(&ok, 0).is_none());
        let mut flat = [ray; 8];
        flat[3].d.y = 0.0;
        assert!(PacketBounds::new(&lanes(&flat), 0xff).is_none());
        // An idle lane does not count.
        assert!(PacketBounds::new(&lanes(&flat), 0xf7).is_some());
        let mut far = [ray; 8];
        far[5].o.x = f32::INFINITY;
        assert!(PacketBounds::new(&lanes(&far), 0xff).is_none());
        let mut turned = [ray; 8];
        turned[0].d.z = -0.25;
        assert!(PacketBounds::new(&lanes(&turned), 0xff).is_none());
    }
}
