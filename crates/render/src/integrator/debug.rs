//! Debug views of the first surface a camera ray meets ([`DebugView`]): normals, depth,
//! and the BVH's cost (nodes visited).

use super::{trace, Integrator, PathStats};
use crate::desc::{RayKind, Rgb};
use crate::geometry::Ray;
use crate::scene::Scene;
use pathlab_mc::sampler::AnySampler;

/// Debug views of the first surface a camera ray meets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    /// Shading normal mapped to colour, (n + 1)/2; black where rays escape.
    Normals,
    /// Distance along the camera ray, divided by the distance from the camera to the far side of
    /// the scene's bounding sphere (so the scene spans [0, 1]); black where rays escape.
    Depth,
    /// BVH nodes visited by the camera ray, as a raw count in every channel (`pathlab render`
    /// writes a PNG of it as a heat map scaled to the image's range).
    BvhHeat,
}

impl Integrator for DebugView {
    fn li(&self, scene: &Scene, ray: Ray, _sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        let before = stats.nodes_visited;
        let hit = trace(scene, &ray, RayKind::Camera, stats);
        match self {
            DebugView::Normals => hit.map_or(Rgb::ZERO, |si| 0.5 * (si.ns + Rgb::ONE)),
            DebugView::Depth => hit.map_or(Rgb::ZERO, |si| {
                let b = scene.bounds();
                let far =
                    (scene.camera().origin() - b.centroid()).length() + 0.5 * b.extent().length();
                Rgb::splat(si.t / far.max(f32::MIN_POSITIVE))
            }),
            DebugView::BvhHeat => Rgb::splat((stats.nodes_visited - before) as f32),
        }
    }
}
