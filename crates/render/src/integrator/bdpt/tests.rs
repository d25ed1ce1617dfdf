//! The bidirectional path tracer's MIS weights on paths whose strategies are known.

use super::vertex::{Kind, Vertex};
use super::*;
use crate::desc::*;
use glam::Vec3;
use pathlab_mc::sampler::SamplerKind;

/// Inside a sphere that emits everywhere, every camera path x₀ x₁ x₂ ends on the light,
/// and light sampling at x₁ (s = 1, t = 2) could have chosen x₂ too: the two strategies'
/// weights of that path must sum to one, including for the short grazing segments where
/// a sample's own density and the one recomputed from the vertices differ most.
#[test]
fn weights_of_the_strategies_of_one_path_sum_to_one() {
    let desc = SceneDesc {
        spheres: vec![SphereDesc {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
            emission: Some(Emission {
                radiance: Vec3::ONE,
                two_sided: true,
            }),
            ..Default::default()
        }],
        materials: vec![crate::scene::diffuse(Vec3::splat(0.6), true)],
        resolution: [16, 16],
        ..Default::default()
    };
    let scene = Scene::build(&desc).expect("the sphere builds");
    let bdpt = BdptIntegrator {
        max_depth: 1,
        ..Default::default()
    };
    let mut sampler = SamplerKind::Independent.build(1 << 12, 1);
    let mut stats = PathStats::default();
    let origin = Vec3::new(0.1, -0.2, 0.05);
    for i in 0..4096 {
        sampler.start_pixel_sample([3, 4], i, 0);
        let d = pathlab_mc::warp::sample_uniform_sphere(sampler.next_2d());
        let ray = Ray::new(origin, d);
        let paths = bdpt.subpaths(&scene, ray, false, &mut sampler, &mut stats);
        assert_eq!(paths.camera.len(), 3, "every path ends on the sphere");
        let x2 = &paths.camera[2];
        let w_emission = BdptIntegrator::mis_weight(&scene, &paths, None, 0, 3, true, false);
        let mut sampled = Vertex::endpoint(Kind::Light, x2.p, x2.n, x2.light, Rgb::ZERO);
        sampled.pdf_fwd = BdptIntegrator::pdf_light_origin(&scene, &sampled);
        let w_light = BdptIntegrator::mis_weight(&scene, &paths, Some(&sampled), 1, 2, true, false);
        assert!(
            (w_emission + w_light - 1.0).abs() < 1e-4,
            "sample {i}: {w_emission} + {w_light}"
        );
    }
}
