//! What the integrator and render-loop tests share: scenes with known answers, renders, and
//! the assertions that compare them with their standard errors.
#![allow(dead_code)]

use glam::Vec3;
use pathlab_mc::sampler::{AnySampler, SamplerKind};
use pathlab_render::desc::*;
use pathlab_render::film::Film;
use pathlab_render::geometry::Ray;
use pathlab_render::integrator::*;
use pathlab_render::scene::{diffuse, Scene};

#[allow(unused_imports)] // each test file uses a part
pub use pathlab_testkit::render::{assert_mean, assert_same_image, path, MAX_Z};

pub fn run(desc: &SceneDesc, integrator: IntegratorKind, spp: u32, seed: u64) -> Film {
    pathlab_testkit::render::render_desc(desc, integrator, spp, seed)
}

/// The camera at the centre of a closed sphere that emits 1 everywhere and reflects albedo a.
pub fn closed_furnace(albedo: f32) -> SceneDesc {
    SceneDesc {
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
        materials: vec![diffuse(Vec3::splat(albedo), true)],
        camera: CameraDesc {
            origin: Vec3::new(0.1, -0.2, 0.05),
            target: Vec3::new(1.0, 0.3, 0.2),
            fov_degrees: 90.0,
            ..Default::default()
        },
        resolution: [16, 16],
        ..Default::default()
    }
}

/// An albedo-0.8 sphere filling the view under a uniform white sky.
pub fn sky_sphere() -> SceneDesc {
    SceneDesc {
        spheres: vec![SphereDesc {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
            emission: None,
            ..Default::default()
        }],
        materials: vec![diffuse(Vec3::splat(0.8), false)],
        environment: Some(Vec3::ONE),
        camera: CameraDesc {
            origin: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            fov_degrees: 8.0,
            ..Default::default()
        },
        resolution: [16, 16],
        ..Default::default()
    }
}

/// A diffuse floor under a large square light close above it: every strategy matters here,
/// and every point of the floor sees the light over a good part of its hemisphere (so that
/// hemisphere sampling finds it often enough for per-pixel variance estimates to be reliable).
pub fn big_light() -> SceneDesc {
    let quad = |y: f32, s: f32, flip: bool| {
        let p = vec![
            Vec3::new(-s, y, -s),
            Vec3::new(s, y, -s),
            Vec3::new(s, y, s),
            Vec3::new(-s, y, s),
        ];
        let i = if flip {
            vec![0, 1, 2, 0, 2, 3]
        } else {
            vec![0, 2, 1, 0, 3, 2]
        };
        (p, i)
    };
    let (fp, fi) = quad(0.0, 1.0, false); // faces +y
    let (lp, li) = quad(0.5, 0.6, true); // faces -y
    SceneDesc {
        meshes: vec![
            MeshDesc {
                name: "floor".into(),
                positions: fp,
                indices: fi,
                ..Default::default()
            },
            MeshDesc {
                name: "light".into(),
                positions: lp,
                indices: li,
                emission: Some(Emission {
                    radiance: Vec3::new(4.0, 3.0, 2.0),
                    two_sided: false,
                }),
                ..Default::default()
            },
        ],
        point_lights: vec![PointLightDesc {
            position: Vec3::new(1.2, 0.8, 0.3),
            intensity: Vec3::splat(0.3),
            attenuation: INVERSE_SQUARE,
        }],
        materials: vec![diffuse(Vec3::new(0.7, 0.5, 0.3), false)],
        camera: CameraDesc {
            origin: Vec3::new(0.0, 2.5, 2.5),
            target: Vec3::ZERO,
            fov_degrees: 50.0,
            ..Default::default()
        },
        resolution: [24, 24],
        ..Default::default()
    }
}

/// An integrator that returns NaN or infinity for some samples.
pub struct Broken;

impl Integrator for Broken {
    fn li(&self, _: &Scene, ray: Ray, _: &mut AnySampler, _: &mut PathStats) -> Rgb {
        if ray.d.x > 0.05 {
            Rgb::new(f32::NAN, 0.0, 0.0)
        } else if ray.d.x < -0.05 {
            Rgb::splat(f32::INFINITY)
        } else {
            Rgb::ONE
        }
    }
}

/// `big_light` with more to trace: a back wall (two-sided, another reflectance) that makes
/// paths bounce, a mirror sphere (a material the packet path hands to the scalar code) and an
/// emitting sphere (a light it samples one lane at a time).
pub fn mixed_scene() -> SceneDesc {
    let mut desc = big_light();
    desc.materials.push(diffuse(Vec3::new(0.2, 0.8, 0.6), true));
    desc.materials.push(MaterialDesc::Mirror {
        reflectance: Vec3::splat(0.9),
    });
    desc.meshes.push(MeshDesc {
        name: "wall".into(),
        positions: vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 1.5, -1.2),
            Vec3::new(-1.0, 1.5, -1.2),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material: 1,
        ..Default::default()
    });
    desc.spheres.push(SphereDesc {
        center: Vec3::new(0.4, 0.25, 0.1),
        radius: 0.25,
        material: 2,
        emission: None,
        ..Default::default()
    });
    desc.spheres.push(SphereDesc {
        center: Vec3::new(-0.5, 0.15, 0.3),
        radius: 0.15,
        material: 0,
        emission: Some(Emission {
            radiance: Vec3::new(2.0, 2.0, 1.0),
            two_sided: false,
        }),
        ..Default::default()
    });
    desc
}

/// Every pixel's samples 0..spp, in order, each tagged with its position in the list.
pub fn every_sample(scene: &Scene, spp: u32) -> Vec<SampleRef> {
    let [w, h] = scene.camera().resolution();
    (0..w * h)
        .flat_map(|p| {
            (0..spp).map(move |index| SampleRef {
                pixel: [p % w, p / w],
                index,
                tag: p * spp + index,
            })
        })
        .collect()
}

pub fn packets_match_one_path_at_a_time(scene: &Scene, bvh: bool) {
    let samples = every_sample(scene, 6);
    let mut lit = 0;
    for kind in SamplerKind::ALL {
        for (max_depth, rr_depth) in [(u32::MAX, 5), (u32::MAX, 1), (3, 5), (0, 5)] {
            let integrator = PathIntegrator {
                max_depth,
                rr_depth,
                ..Default::default()
            };
            let mut sampler = kind.build(6, 9);
            let mut packed = vec![None; samples.len()];
            let mut packed_stats = PathStats::default();
            integrator.li_samples(
                scene,
                &mut sampler,
                &mut samples.iter().copied(),
                &mut |tag, l| packed[tag as usize] = Some(l),
                &mut packed_stats,
            );
            let mut stats = PathStats::default();
            for s in &samples {
                let (ray, weight) = camera_ray(scene, &mut sampler, *s);
                let l = integrator.li(scene, ray, &mut sampler, &mut stats) * weight;
                let p = packed[s.tag as usize].expect("every sample is estimated");
                assert_eq!(
                    p.to_array().map(f32::to_bits),
                    l.to_array().map(f32::to_bits),
                    "{kind:?}, depth {max_depth}, rr {rr_depth}, {s:?}: {p} vs {l}"
                );
                lit += usize::from(l.max_element() > 0.0);
            }
            assert_eq!(packed_stats.rays, stats.rays, "{kind:?}, depth {max_depth}");
            if bvh {
                assert_eq!(packed_stats, stats, "{kind:?}, depth {max_depth}");
            } else {
                assert_eq!(packed_stats.nodes_visited, 0);
            }
        }
    }
    // A guard that the comparison covers lit paths, not only black ones.
    let estimates = SamplerKind::ALL.len() * 4 * samples.len();
    assert!(lit * 10 > estimates, "{lit} of {estimates} found light");
}

/// Runs `go(cancel, after_pass)` with a pass callback that stops the render after `n` passes
/// and keeps the film as that pass left it.
pub fn film_after_passes(
    n: u32,
    go: impl FnOnce(&std::sync::atomic::AtomicBool, &mut dyn FnMut(&Film)),
) -> Film {
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut passes = 0;
    let mut kept = None;
    go(&stop, &mut |film| {
        passes += 1;
        if passes == n {
            kept = Some(film.clone());
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    });
    kept.expect("the render ran that many passes")
}
