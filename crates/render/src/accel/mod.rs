//! Acceleration structures. The integrators see only [`crate::scene::Scene::intersect`] and
//! [`crate::scene::Scene::occluded`], so the BVH here can be replaced (e.g. by a wider SIMD
//! one) without touching them.

mod bvh;

pub use bvh::{Bvh, BvhNode, BvhParams};
