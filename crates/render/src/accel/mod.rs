//! Acceleration structures. The integrators see only [`crate::scene::Scene::intersect`] and
//! [`crate::scene::Scene::occluded`]; the scene traces through the 8-wide [`Bvh8`] (its box
//! test in AVX registers where the CPU has AVX2), whose leaves name [`TriBlock`]s of four
//! triangles tested together. The 4-wide [`Bvh4`] and the binary [`Bvh`] stay as the
//! baselines they are measured against.

mod bvh;
mod tri_block;
mod wide;

pub use bvh::{Bvh, BvhNode, BvhParams};
#[cfg(target_arch = "x86_64")]
pub(crate) use tri_block::{
    nearest_for_rays_pair_avx512, Avx512Nearest, Avx512Rays, AvxNearest, AvxRays,
};
pub use tri_block::{BlockHit, Nearest, RayLanes, TriBlock, TRIS_PER_BLOCK};
pub use wide::{
    split_box, BoxTest, Bvh4, Bvh8, Node, Portable, SplitPrim, WideBvh, BVH_WIDTH, FAR_SCALE,
    MAX_PRIMITIVES, SPLIT_BUDGET,
};
pub(crate) use wide::{PacketBounds, RayBoxLanes};

/// Test helpers shared by the BVHs' tests: random boxes as primitives.
#[cfg(test)]
mod test_util {
    use crate::geometry::{Aabb, Ray};
    use glam::Vec3;
    use pathlab_mc::rng::Pcg32;

    /// `n` random boxes in [0, 10]³ with half-extents up to 0.3.
    pub fn random_boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut rng = Pcg32::new(seed, 1);
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 10.0;
                let e = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 0.3;
                Aabb {
                    min: c - e,
                    max: c + e,
                }
            })
            .collect()
    }

    /// Checks a BVH's closest-hit and any-hit traversals against testing every box, for
    /// `count` random rays from PCG32 stream (`seed`, `stream`), a third of them starting at
    /// a `t_min` above 0 (boxes whose entry lies before it are not hit).
    pub fn check_against_brute_force(
        boxes: &[Aabb],
        count: usize,
        (seed, stream): (u64, u64),
        intersect: impl Fn(&mut Ray, &dyn Fn(u32, &mut Ray) -> bool) -> (bool, u32),
        occluded: impl Fn(&Ray, &dyn Fn(u32, &Ray) -> bool) -> bool,
    ) {
        let mut rng = Pcg32::new(seed, stream);
        let hit = box_hit(boxes);
        for _ in 0..count {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 14.0 - 2.0;
            let d = Vec3::new(
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
            );
            let t_min = if rng.uniform_f32() < 1.0 / 3.0 {
                rng.uniform_f32() * 20.0
            } else {
                0.0
            };
            let start = Ray {
                t_min,
                ..Ray::new(o, d)
            };
            let mut brute = start;
            let any_brute = (0..boxes.len() as u32).fold(false, |a, i| hit(i, &mut brute) | a);
            let mut ray = start;
            let (any, visited) = intersect(&mut ray, &hit);
            assert_eq!(any, any_brute);
            assert_eq!(ray.t_max, brute.t_max);
            assert!(visited >= 1);
            let blocked = occluded(&start, &|i, r| {
                let mut r = *r;
                hit(i, &mut r)
            });
            assert_eq!(blocked, any_brute);
        }
    }

    /// Ray-box "primitive": a hit at the box's entry distance.
    pub fn box_hit(boxes: &[Aabb]) -> impl Fn(u32, &mut Ray) -> bool + '_ {
        move |i, ray: &mut Ray| match boxes[i as usize].hit(ray.o, ray.d.recip(), ray.t_max) {
            Some(t) if t > ray.t_min.max(0.0) && t < ray.t_max => {
                ray.t_max = t;
                true
            }
            _ => false,
        }
    }
}
