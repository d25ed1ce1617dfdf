//! Integrators on scenes with known answers: furnaces, bounce decomposition, strategy
//! agreement, determinism and the NaN guard. Tolerances are multiples of the standard errors
//! the renders estimate themselves.

use glam::{DVec3, Vec3};
use pathlab_mc::sampler::{AnySampler, SamplerKind};
use pathlab_mc::stats::z_test_two_sample;
use pathlab_render::desc::*;
use pathlab_render::film::Film;
use pathlab_render::geometry::Ray;
use pathlab_render::integrator::*;
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::{diffuse, Scene};

const MAX_Z: f64 = 4.0;

fn run(desc: &SceneDesc, integrator: IntegratorKind, spp: u32, seed: u64) -> Film {
    let scene = Scene::build(desc).unwrap();
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0
}

fn path(max_depth: u32) -> IntegratorKind {
    IntegratorKind::Path(PathIntegrator {
        max_depth,
        ..Default::default()
    })
}

/// Asserts that every channel of the image mean is within 4 standard errors of `truth`.
fn assert_mean(name: &str, film: &Film, truth: DVec3) {
    let (m, se) = (film.image_mean(), film.image_mean_std_error());
    eprintln!("{name}: mean {m:.5?} ± {se:.5?}, expected {truth:?}");
    for c in 0..3 {
        assert!(
            // The second term is the single-precision rounding of the radiance computation.
            (m[c] - truth[c]).abs() <= MAX_Z * se[c] + 1e-6 * truth[c].abs(),
            "{name}: channel {c}: {} vs {} (se {})",
            m[c],
            truth[c],
            se[c]
        );
    }
}

/// The camera at the centre of a closed sphere that emits 1 everywhere and reflects albedo a.
fn closed_furnace(albedo: f32) -> SceneDesc {
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

#[test]
fn closed_furnace_converges_to_geometric_series() {
    // L = Le + a L  =>  L = 1/(1 - a), reached only with unbounded depth (Russian roulette).
    for albedo in [0.5f32, 0.8] {
        let film = run(&closed_furnace(albedo), path(u32::MAX), 256, 3);
        let truth = 1.0 / (1.0 - albedo as f64);
        assert_mean(
            &format!("closed furnace, albedo {albedo}"),
            &film,
            DVec3::splat(truth),
        );
    }
}

#[test]
fn closed_furnace_depths_are_partial_sums() {
    // With max depth d, L = 1 + a + ... + a^d.
    let albedo = 0.6f64;
    for d in [0u32, 1, 3] {
        let film = run(&closed_furnace(albedo as f32), path(d), 64, 4 + d as u64);
        let truth: f64 = (0..=d).map(|k| albedo.powi(k as i32)).sum();
        assert_mean(
            &format!("closed furnace, -m {d}"),
            &film,
            DVec3::splat(truth),
        );
    }
}

/// An albedo-0.8 sphere filling the view under a uniform white sky.
fn sky_sphere() -> SceneDesc {
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

#[test]
fn white_sky_furnace_reflects_the_albedo() {
    // A convex surface sees the sky over its whole hemisphere: L = a at every depth >= 1.
    for integrator in [
        path(1),
        path(u32::MAX),
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Hemisphere,
            samples: 4,
            ..Default::default()
        }),
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Cosine,
            samples: 1,
            ..Default::default()
        }),
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Light,
            samples: 4,
            ..Default::default()
        }),
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Mis,
            samples: 1,
            ..Default::default()
        }),
    ] {
        let film = run(&sky_sphere(), integrator, 64, 5);
        assert_mean(
            &format!("sky furnace {integrator:?}"),
            &film,
            DVec3::splat(0.8),
        );
    }
    // Cosine sampling is exact here: f cos / p = a for every sample.
    let film = run(
        &sky_sphere(),
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Cosine,
            samples: 1,
            ..Default::default()
        }),
        16,
        6,
    );
    assert!(film.image_mean_std_error().max_element() < 1e-6);
}

/// A diffuse floor under a large square light close above it: every strategy matters here,
/// and every point of the floor sees the light over a good part of its hemisphere (so that
/// hemisphere sampling finds it often enough for per-pixel variance estimates to be reliable).
fn big_light() -> SceneDesc {
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

#[test]
fn direct_strategies_agree_and_match_the_path_tracer() {
    // The point light is found only by light sampling; the area light by all. Compare the
    // strategies that see both (light, MIS, path -m 1) pixel by pixel, and hemisphere/cosine on
    // a scene without the point light.
    let desc = big_light();
    let reference = run(&desc, path(1), 256, 10);
    for (i, strategy) in [DirectStrategy::Light, DirectStrategy::Mis]
        .into_iter()
        .enumerate()
    {
        let film = run(
            &desc,
            IntegratorKind::Direct(DirectIntegrator {
                strategy,
                samples: 1,
                ..Default::default()
            }),
            256,
            11 + i as u64,
        );
        assert_same_image(strategy.name(), &film, &reference);
    }
    let mut no_point = big_light();
    no_point.point_lights.clear();
    let reference = run(
        &no_point,
        IntegratorKind::Direct(DirectIntegrator {
            strategy: DirectStrategy::Mis,
            samples: 1,
            ..Default::default()
        }),
        256,
        20,
    );
    for (i, strategy) in DirectStrategy::ALL.into_iter().enumerate() {
        let film = run(
            &no_point,
            IntegratorKind::Direct(DirectIntegrator {
                strategy,
                samples: 4,
                ..Default::default()
            }),
            256,
            21 + i as u64,
        );
        assert_same_image(strategy.name(), &film, &reference);
    }
}

/// Per-pixel two-sample z-tests: at most 0.1% of pixel channels beyond 4σ (rounded up to 1),
/// and image means within 3 combined standard errors.
fn assert_same_image(name: &str, a: &Film, b: &Film) {
    let mut outliers = 0;
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let (va, vb) = (p.variance_of_mean(), q.variance_of_mean());
        for c in 0..3 {
            let z = z_test_two_sample(p.mean()[c], va[c].sqrt(), q.mean()[c], vb[c].sqrt());
            outliers += (!z.within(MAX_Z)) as usize;
        }
    }
    let allowed = (a.pixels().len() * 3) / 1000 + 1;
    assert!(
        outliers <= allowed,
        "{name}: {outliers} pixel channels beyond {MAX_Z} sigma"
    );
    let (ma, mb) = (a.image_mean(), b.image_mean());
    let (sa, sb) = (a.image_mean_std_error(), b.image_mean_std_error());
    for c in 0..3 {
        let z = z_test_two_sample(ma[c], sa[c], mb[c], sb[c]);
        assert!(
            z.within(3.0),
            "{name}: image mean channel {c}: {} vs {} (z {})",
            ma[c],
            mb[c],
            z.z
        );
    }
}

#[test]
fn bounces_add_up_to_the_full_image() {
    // The images of bounces 0..=3 alone sum to the -m 3 image.
    let mut desc = big_light();
    desc.resolution = [16, 16];
    let full = run(&desc, path(3), 128, 30);
    let parts: Vec<Film> = (0..=3)
        .map(|k| {
            let i = IntegratorKind::Path(PathIntegrator {
                max_depth: 3,
                only_bounce: Some(k),
                ..Default::default()
            });
            run(&desc, i, 128, 31 + k as u64)
        })
        .collect();
    let mut outliers = 0;
    for (idx, f) in full.pixels().iter().enumerate() {
        let sum: DVec3 = parts.iter().map(|p| p.pixels()[idx].mean()).sum();
        let var: DVec3 = parts
            .iter()
            .map(|p| p.pixels()[idx].variance_of_mean())
            .sum::<DVec3>()
            + f.variance_of_mean();
        for c in 0..3 {
            let d = (sum[c] - f.mean()[c]).abs();
            outliers += (d > MAX_Z * var[c].sqrt() + 1e-6 * f.mean()[c].abs()) as usize;
        }
    }
    assert!(
        outliers <= 1,
        "{outliers} pixel channels differ beyond 4 sigma"
    );
    // Bounce 0 alone is the emission seen directly, i.e. the -m 0 image: with the same seed the
    // camera rays are the same, so the two agree exactly.
    assert_eq!(
        parts[0].mean_image(),
        run(&desc, path(0), 128, 31).mean_image()
    );
}

#[test]
fn same_seed_same_image_for_any_thread_count() {
    let desc = big_light();
    let scene = Scene::build(&desc).unwrap();
    let settings = RenderSettings::new(8, 42, SamplerKind::Independent);
    let render_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            render(
                &scene,
                &path(u32::MAX),
                &settings,
                &|_| {},
                &Default::default(),
            )
            .0
        })
    };
    let one = render_with(1);
    assert_eq!(one, render_with(2));
    assert_eq!(one, render_with(3));
    let other = render(
        &scene,
        &path(u32::MAX),
        &RenderSettings::new(8, 43, SamplerKind::Independent),
        &|_| {},
        &Default::default(),
    )
    .0;
    assert_ne!(one, other);
}

/// An integrator that returns NaN or infinity for some samples.
struct Broken;

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

#[test]
fn nonfinite_samples_never_reach_the_film() {
    let scene = Scene::build(&big_light()).unwrap();
    let settings = RenderSettings::new(4, 1, SamplerKind::Independent);
    let (film, stats) = render(&scene, &Broken, &settings, &|_| {}, &Default::default());
    assert!(stats.nonfinite_samples > 0);
    assert_eq!(stats.samples + stats.nonfinite_samples, 24 * 24 * 4);
    assert!(film
        .pixels()
        .iter()
        .all(|p| p.mean().is_finite() && p.variance().is_finite()));
    assert!(film
        .pixels()
        .iter()
        .any(|p| p.count() == 4 && p.mean() == DVec3::ONE));
}

#[test]
fn cancelled_render_keeps_what_was_done() {
    let scene = Scene::build(&big_light()).unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(true);
    let (film, stats) = render(
        &scene,
        &path(1),
        &RenderSettings::new(4, 1, SamplerKind::Independent),
        &|_| {},
        &cancel,
    );
    assert!(stats.cancelled);
    assert_eq!(stats.samples, 0);
    assert!(film.pixels().iter().all(|p| p.count() == 0));
}

#[test]
fn bad_scenes_are_errors() {
    let mut desc = big_light();
    desc.meshes[0].material = 7;
    assert!(Scene::build(&desc)
        .unwrap_err()
        .to_string()
        .contains("material index 7"));
    let mut desc = big_light();
    desc.meshes[0].indices.push(99);
    assert!(Scene::build(&desc).is_err());
    let mut desc = big_light();
    desc.meshes[0].indices = vec![0, 1, 99];
    assert!(Scene::build(&desc)
        .unwrap_err()
        .to_string()
        .contains("out of range"));
    let mut desc = big_light();
    desc.resolution = [0, 10];
    assert!(Scene::build(&desc).is_err());
}

#[test]
fn glass_and_mirror_spheres_in_a_white_furnace() {
    // Under a uniform sky of radiance 1, a glass sphere without absorption passes or reflects
    // everything: L = 1 at every depth limit that lets paths escape (unbounded here). A mirror
    // of reflectance 0.7 shows 0.7 of the sky.
    for (material, truth) in [
        (
            MaterialDesc::Glass {
                reflectance: Vec3::ONE,
                transmittance: Vec3::ONE,
                roughness: 0.0,
                ior: 1.5,
                distribution: NormalDistribution::Ggx,
                fresnel: FresnelModel::Exact,
            },
            1.0,
        ),
        (
            // Schlick's reflectance splits energy as R and 1 - R too.
            MaterialDesc::Glass {
                reflectance: Vec3::ONE,
                transmittance: Vec3::ONE,
                roughness: 0.0,
                ior: 1.5,
                distribution: NormalDistribution::Ggx,
                fresnel: FresnelModel::Schlick,
            },
            1.0,
        ),
        (
            MaterialDesc::Mirror {
                reflectance: Vec3::splat(0.7),
            },
            0.7,
        ),
    ] {
        let mut desc = sky_sphere();
        desc.materials = vec![material.clone()];
        let film = run(&desc, path(u32::MAX), 256, 8);
        assert_mean(
            &format!("{material:?} in a white furnace"),
            &film,
            DVec3::splat(truth),
        );
        // Every pixel, not just the mean.
        for p in film.pixels() {
            let se = p.variance_of_mean().map(f64::sqrt);
            for c in 0..3 {
                assert!(
                    (p.mean()[c] - truth).abs() <= MAX_Z * se[c] + 1e-4,
                    "{material:?}: pixel {:?}",
                    p.mean()
                );
            }
        }
    }
}

#[test]
fn path_lighting_strategies_agree_under_an_environment_map() {
    // MIS, BSDF sampling alone and light sampling alone estimate the same image: a diffuse
    // and a rough gold sphere on a diffuse floor under a sky with a 2 x 2 texel sun.
    let (w, h) = (32usize, 16usize);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let sky = Vec3::new(0.3, 0.4, 0.6) * (1.0 - y as f32 / h as f32) + Vec3::splat(0.05);
            if (10..12).contains(&x) && (4..6).contains(&y) {
                sky + Vec3::splat(40.0)
            } else {
                sky
            }
        })
        .collect();
    let desc = SceneDesc {
        spheres: vec![
            SphereDesc {
                center: Vec3::new(-0.6, 0.0, 0.0),
                radius: 0.5,
                material: 0,
                emission: None,
                ..Default::default()
            },
            SphereDesc {
                center: Vec3::new(0.6, 0.0, 0.0),
                radius: 0.5,
                material: 1,
                emission: None,
                ..Default::default()
            },
        ],
        meshes: vec![MeshDesc {
            name: "floor".into(),
            positions: vec![
                Vec3::new(-3.0, -0.5, -3.0),
                Vec3::new(3.0, -0.5, -3.0),
                Vec3::new(3.0, -0.5, 3.0),
                Vec3::new(-3.0, -0.5, 3.0),
            ],
            indices: vec![0, 2, 1, 0, 3, 2],
            material: 0,
            ..Default::default()
        }],
        materials: vec![
            diffuse(Vec3::splat(0.7), false),
            MaterialDesc::Conductor {
                alpha: 0.3,
                eta: Vec3::new(0.143, 0.374, 1.442),
                k: Vec3::new(3.983, 2.385, 1.603),
                distribution: NormalDistribution::Ggx,
            },
        ],
        environment_map: Some(EnvironmentMapDesc {
            source: "synthetic sky".into(),
            width: w,
            height: h,
            texels: std::sync::Arc::new(texels),
            to_world: glam::Mat3::from_rotation_y(0.5),
            scale: 1.0,
        }),
        camera: CameraDesc {
            origin: Vec3::new(0.0, 0.8, 4.0),
            target: Vec3::ZERO,
            fov_degrees: 40.0,
            ..Default::default()
        },
        resolution: [24, 16],
        ..Default::default()
    };
    let film = |lighting, seed| {
        run(
            &desc,
            IntegratorKind::Path(PathIntegrator {
                max_depth: 3,
                lighting,
                ..Default::default()
            }),
            512,
            seed,
        )
    };
    let mis = film(PathLighting::Mis, 1);
    for (name, other) in [
        ("BSDF sampling", film(PathLighting::Bsdf, 2)),
        ("light sampling", film(PathLighting::Light, 3)),
    ] {
        let (a, sa) = (mis.image_mean(), mis.image_mean_std_error());
        let (b, sb) = (other.image_mean(), other.image_mean_std_error());
        eprintln!("MIS {a:.5?} ± {sa:.5?}; {name} {b:.5?} ± {sb:.5?}");
        for c in 0..3 {
            let z = z_test_two_sample(a[c], sa[c], b[c], sb[c]);
            assert!(z.within(MAX_Z), "{name}, channel {c}: z = {:.2}", z.z);
        }
        // MIS is never much worse than either strategy alone; here it beats both.
        assert!(
            sa.max_element() < sb.max_element(),
            "{name}: {sa:?} vs {sb:?}"
        );
    }
}

/// `big_light` with more to trace: a back wall (two-sided, another reflectance) that makes
/// paths bounce, a mirror sphere (a material the packet path hands to the scalar code) and an
/// emitting sphere (a light it samples one lane at a time).
fn mixed_scene() -> SceneDesc {
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

#[test]
fn packets_compute_what_one_path_at_a_time_computes() {
    // The path integrator follows eight paths at once, computing the scattering at
    // Lambertian surfaces lit by emitting triangles in SIMD lanes and everything else with
    // the scalar code: every sample's radiance must be the scalar `li`'s to the bit, and the
    // rays and nodes counted the same. In a scene of a few triangles the lanes' rays are
    // tested against every triangle at once instead of walking the BVH (the same distances;
    // of triangles at exactly the same distance, possibly another, which these rays do not
    // meet), and no nodes are counted.
    for (desc, bvh) in [(mixed_scene(), true), (big_light(), false)] {
        let scene = Scene::build(&desc).unwrap();
        packets_match_one_path_at_a_time(&scene, bvh);
    }
}

fn packets_match_one_path_at_a_time(scene: &Scene, bvh: bool) {
    let [w, h] = scene.camera().resolution();
    let samples: Vec<SampleRef> = (0..w * h)
        .flat_map(|p| {
            (0..6).map(move |index| SampleRef {
                pixel: [p % w, p / w],
                index,
                tag: p * 6 + index,
            })
        })
        .collect();
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
                let ray = camera_ray(scene, &mut sampler, *s);
                let l = integrator.li(scene, ray, &mut sampler, &mut stats);
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

#[test]
fn passes_resumes_and_sample_ranges_give_the_same_film_to_the_bit() {
    use pathlab_render::render::{pass_ends, render_from};
    // The schedule: 1, 1, 2, 4, ... samples per pixel, then steady passes.
    assert_eq!(pass_ends(0, 20, 4), vec![1, 2, 4, 8, 12, 16, 20]);
    assert_eq!(pass_ends(8, 11, 64), vec![9, 10, 11]);
    let desc = big_light();
    let scene = Scene::build(&desc).unwrap();
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let settings = RenderSettings::new(37, 5, sampler);
        let integrator = path(u32::MAX);
        let whole = render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0;
        // Stopped after some passes (by the pass callback), then resumed from that film.
        let stop = std::sync::atomic::AtomicBool::new(false);
        let mut passes = 0;
        let (part, stats) = render_from(
            &scene,
            &integrator,
            &settings,
            Film::new(24, 24),
            &|_| {},
            &stop,
            &mut |_, _| {
                passes += 1;
                if passes == 3 {
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            },
        );
        assert!(stats.cancelled);
        assert!(
            part.pixels().iter().all(|p| p.count() == 4),
            "three passes: 1 + 1 + 2"
        );
        let resumed = render_from(
            &scene,
            &integrator,
            &settings,
            part,
            &|_| {},
            &Default::default(),
            &mut |_, _| {},
        )
        .0;
        assert!(resumed == whole, "{sampler:?}: resumed film differs");
        // Shards: disjoint sample ranges added together.
        let mut merged = Film::new(24, 24);
        for range in [[0, 10], [10, 11], [11, 37]] {
            let s = RenderSettings {
                sample_range: Some(range),
                ..settings
            };
            let f = render(&scene, &integrator, &s, &|_| {}, &Default::default()).0;
            assert!(f
                .pixels()
                .iter()
                .all(|p| p.count() == (range[1] - range[0]) as u64));
            for (a, b) in merged.pixels_mut().iter_mut().zip(f.pixels()) {
                a.merge(b);
            }
        }
        assert!(merged == whole, "{sampler:?}: merged shards differ");
    }
}

/// Runs `go(cancel, after_pass)` with a pass callback that stops the render after `n` passes
/// and keeps the film as that pass left it.
fn film_after_passes(
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

#[test]
fn progressive_and_adaptive_renders_resume_to_the_same_film_to_the_bit() {
    use pathlab_render::progressive::{render_progressive, render_progressive_from, StopRule};
    use pathlab_render::render::{render_from, Adaptive};
    let desc = big_light();
    let scene = Scene::build(&desc).unwrap();
    let integrator = path(u32::MAX);
    let settings = RenderSettings::new(1, 9, SamplerKind::Independent);
    // --target-error: the allocation of each pass is a function of the film.
    let stop = StopRule {
        target_error: Some(0.06),
        time_limit: None,
        max_spp: 1 << 12,
    };
    let (whole, _, report) = render_progressive(
        &scene,
        &integrator,
        &settings,
        &stop,
        &|_, _| {},
        &Default::default(),
    );
    assert_eq!(report.stopped_by, "target", "{report:?}");
    assert!(report.passes >= 3, "{report:?}");
    let counts = |f: &Film| f.pixels().iter().map(|p| p.count()).collect::<Vec<_>>();
    assert!(
        counts(&whole).windows(2).any(|w| w[0] != w[1]),
        "the passes are spent unevenly"
    );
    let part = film_after_passes(2, |cancel, keep| {
        render_progressive_from(
            &scene,
            &integrator,
            &settings,
            &stop,
            Film::new(24, 24),
            &|_| {},
            cancel,
            &mut |f, _, _, _| keep(f),
        );
    });
    let (resumed, _, again) = render_progressive_from(
        &scene,
        &integrator,
        &settings,
        &stop,
        part,
        &|_| {},
        &Default::default(),
        &mut |_, _, _, _| {},
    );
    assert_eq!(again.passes + 2, report.passes);
    assert!(resumed == whole, "resumed progressive film differs");
    // Adaptive, two-stage rule: the plan is drawn again from its own stream.
    let settings = RenderSettings {
        adaptive: Some(Adaptive {
            batch: 4,
            ..Adaptive::DEFAULT
        }),
        ..RenderSettings::new(64, 9, SamplerKind::Sobol)
    };
    let (whole, _) = render(&scene, &integrator, &settings, &|_| {}, &Default::default());
    assert!(counts(&whole).windows(2).any(|w| w[0] != w[1]));
    let part = film_after_passes(2, |cancel, keep| {
        render_from(
            &scene,
            &integrator,
            &settings,
            Film::new(24, 24),
            &|_| {},
            cancel,
            &mut |f, _| keep(f),
        );
    });
    assert!(counts(&part) != counts(&whole));
    let resumed = render_from(
        &scene,
        &integrator,
        &settings,
        part,
        &|_| {},
        &Default::default(),
        &mut |_, _| {},
    )
    .0;
    assert!(resumed == whole, "resumed adaptive film differs");
}
