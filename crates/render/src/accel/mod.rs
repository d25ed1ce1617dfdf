//! Acceleration structures. The integrators see only [`crate::scene::Scene::intersect`] and
//! [`crate::scene::Scene::occluded`]; the scene traces through the 4-wide [`Bvh4`], and the
//! binary [`Bvh`] stays as the baseline it is measured against.

mod bvh;
mod wide;

pub use bvh::{Bvh, BvhNode, BvhParams};
pub use wide::{Bvh4, MAX_PRIMITIVES};

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

    /// Ray-box "primitive": a hit at the box's entry distance.
    pub fn box_hit(boxes: &[Aabb]) -> impl Fn(u32, &mut Ray) -> bool + '_ {
        move |i, ray: &mut Ray| match boxes[i as usize].hit(ray.o, ray.d.recip(), ray.t_max) {
            Some(t) if t > 0.0 && t < ray.t_max => {
                ray.t_max = t;
                true
            }
            _ => false,
        }
    }
}
