//! Tests of the wide BVHs: nearest and any hits against brute force, for both widths and both
//! box tests (portable and AVX2), with degenerate, axis-parallel and non-finite rays.

use super::box_test::RayBoxes;
use super::stack::Stack;
use super::*;
use crate::accel::bvh::BvhParams;
use crate::accel::test_util::{box_hit, check_against_brute_force, random_boxes};
use crate::geometry::Ray;
use glam::Vec3;
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

/// Whether `ray` meets the box `[lo, hi]` within its extent, at a distance below 10²⁰ (the
/// box test takes direction components below 10⁻³⁰ as that size, which bounds the distances
/// at which it is exact), computed in `f64` from the ray's `f32` values: exact but for the
/// divisions' rounding (2⁻⁵³ of each distance), far below the box test's margins.
fn meets_exactly(ray: &Ray, lo: Vec3, hi: Vec3) -> bool {
    let (mut t0, mut t1) = (f64::from(ray.t_min.max(0.0)), f64::from(ray.t_max));
    for axis in 0..3 {
        let (o, d) = (f64::from(ray.o[axis]), f64::from(ray.d[axis]));
        let (lo, hi) = (f64::from(lo[axis]), f64::from(hi[axis]));
        if d == 0.0 {
            if o < lo || o > hi {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo - o) / d, (hi - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1 && t0 < 1e20
}

#[test]
fn the_box_test_meets_every_box_the_ray_meets() {
    // The fused distances p · (1/d) - o/d with o/d rounded away from the box: wherever the
    // exact slab test meets a box, the box test does. Hard cases on purpose: origins on a
    // box's planes, boxes of zero thickness, directions with zero, tiny and -0 components,
    // rays starting at or ending on a box.
    let mut rng = Pcg32::new(21, 5);
    let (mut met, mut tested) = (0usize, 0usize);
    for k in 0..20_000 {
        let mut u = || rng.uniform_f32();
        let mut node = Node::<8>::EMPTY;
        let mut boxes = [(Vec3::ZERO, Vec3::ZERO); 8];
        for (lane, b) in boxes.iter_mut().enumerate() {
            let lo = Vec3::new(u(), u(), u()) * 8.0 - 4.0;
            let mut size = Vec3::new(u(), u(), u()) * 2.0;
            if u() < 0.3 {
                // Flat on one axis, like the box of a wall.
                size[(u() * 3.0) as usize % 3] = 0.0;
            }
            *b = (lo, lo + size);
            node.set_bounds(lane, &Aabb { min: b.0, max: b.1 });
            node.child[lane] = lane as u32;
            node.valid |= 1 << lane;
        }
        // From a random point or from a plane of some box, mostly towards a point of some
        // box (the origin's own, for a ray that starts on it).
        let mut o = Vec3::new(u(), u(), u()) * 10.0 - 5.0;
        if k % 2 == 0 {
            let (lane, axis) = ((u() * 8.0) as usize % 8, (u() * 3.0) as usize % 3);
            o[axis] = if u() < 0.5 {
                boxes[lane].0[axis]
            } else {
                boxes[lane].1[axis]
            };
        }
        let (to, a) = (&boxes[(u() * 8.0) as usize % 8], Vec3::new(u(), u(), u()));
        let mut d = if k % 4 == 3 {
            Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5)
        } else {
            to.0 + (to.1 - to.0) * a - o
        };
        // One or two axes flat (zero, -0 or tiny components), along the target box's slab or
        // one of its planes.
        for axis in 0..3 {
            if (k / 2 + axis) % 3 == 0 || u() < 0.1 {
                o[axis] = match k % 3 {
                    0 => to.0[axis],
                    1 => to.1[axis],
                    _ => to.0[axis] + (to.1[axis] - to.0[axis]) * a[axis],
                };
                d[axis] = match (u() * 4.0) as u32 {
                    0 => 0.0,
                    1 => -0.0,
                    2 => 1e-35 * d[axis].signum(),
                    _ => 1e-20 * d[axis].signum(),
                };
            }
        }
        let mut ray = Ray::new(o, d);
        if u() < 0.3 {
            ray.t_min = u() * 2.0;
        }
        if u() < 0.3 {
            ray.t_max = u() * 6.0;
        }
        let (_, mask) = Portable.test(&RayBoxes::new(&ray), &node, ray.t_max);
        for (lane, b) in boxes.iter().enumerate() {
            if meets_exactly(&ray, b.0, b.1) {
                assert!(
                    mask & (1 << lane) != 0,
                    "ray {k} ({ray:?}) meets box {lane} {b:?}, the test culls it"
                );
                met += 1;
            }
            tested += 1;
        }
    }
    assert!(met > tested / 20, "only {met} of {tested} boxes met");
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

/// Small boxes among long slabs that cross the whole domain on each axis: where the best
/// partition's two sides overlap, so that spatial splits cut the slabs (enough boxes for the
/// nodes where splits are tried).
fn boxes_with_slabs(seed: u64) -> Vec<Aabb> {
    let mut boxes = random_boxes(3 * super::spatial::SPLIT_MIN_REFS, seed);
    for k in 0..12 {
        let (axis, at) = (k % 3, 1.0 + 0.7 * k as f32);
        let mut min = Vec3::splat(at);
        let mut max = Vec3::splat(at + 0.2);
        min[axis] = -1.0;
        max[axis] = 11.0;
        boxes.push(Aabb { min, max });
    }
    boxes
}

#[test]
fn spatial_splits_find_the_same_hits_as_brute_force() {
    spatial_splits_match_brute_force::<4>();
    spatial_splits_match_brute_force::<8>();
}

fn spatial_splits_match_brute_force<const W: usize>() {
    for seed in [21, 22] {
        let boxes = boxes_with_slabs(seed);
        let n = boxes.len();
        let bvh = WideBvh::<W>::build_with_splits(&boxes, BvhParams::default(), &split_box);
        // The slabs were cut: more references than boxes, within the budget, every box
        // referenced.
        let refs = bvh.primitive_indices().len();
        assert!(refs > n, "no spatial split in {refs} references");
        assert!(refs <= n + (n as f32 * SPLIT_BUDGET) as usize);
        let mut seen: Vec<u32> = bvh.primitive_indices().to_vec();
        seen.sort();
        seen.dedup();
        assert_eq!(seen, (0..n as u32).collect::<Vec<u32>>());
        check_against_brute_force(
            &boxes,
            2000,
            (seed, 3),
            |r, h| bvh.intersect(r, h),
            |r, h| bvh.occluded(r, h),
        );
        // Fewer nodes visited than without the splits, on the same rays.
        let plain = WideBvh::<W>::build(&boxes, BvhParams::default());
        let visits = |tree: &WideBvh<W>| {
            let mut rng = Pcg32::new(seed, 4);
            (0..2000)
                .map(|_| {
                    let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), -2.0) * 10.0;
                    let mut ray = Ray::new(o, Vec3::new(0.1, 0.2, 1.0));
                    tree.intersect(&mut ray, box_hit(&boxes)).1 as u64
                })
                .sum::<u64>()
        };
        assert!(visits(&bvh) < visits(&plain));
    }
}

#[test]
fn spatial_splits_build_the_same_tree_on_any_number_of_threads() {
    let boxes: Vec<Aabb> = (0..2).flat_map(boxes_with_slabs).collect();
    let build = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Bvh8::build_with_splits(&boxes, BvhParams::default(), &split_box))
    };
    let one = build(1);
    for threads in [2, 3] {
        let other = build(threads);
        assert_eq!(one.primitive_indices(), other.primitive_indices());
        assert_eq!(one.node_count(), other.node_count());
        for (a, b) in one.nodes.iter().zip(&other.nodes) {
            assert_eq!(a.child, b.child);
            for lane in 0..8 {
                assert_eq!(a.bounds(lane), b.bounds(lane));
            }
        }
    }
}
