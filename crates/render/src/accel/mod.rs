//! Acceleration structures. The integrators see only [`crate::scene::Scene::intersect`] and
//! [`crate::scene::Scene::occluded`]; the scene traces through the 4-wide [`Bvh4`], and the
//! binary [`Bvh`] stays as the baseline it is measured against.

mod bvh;
mod wide;

pub use bvh::{Bvh, BvhNode, BvhParams};
pub use wide::{Bvh4, MAX_PRIMITIVES};
