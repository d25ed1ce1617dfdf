//! Integrators on scenes with known answers: furnaces, bounce decomposition, strategy
//! agreement, determinism and the NaN guard. Tolerances are multiples of the standard errors
//! the renders estimate themselves.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use pathlab_mc::stats::z_test_two_sample;
use pathlab_render::desc::*;
use pathlab_render::film::Film;
use pathlab_render::integrator::*;
use pathlab_render::scene::diffuse;

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

#[test]
fn the_course_strategies_samples_estimate_the_same_direct_light() {
    // A floor point under an emitting quad: uniform hemisphere, cosine, BSDF and light
    // sampling, 20 000 samples each, estimate the same reflected light (within 4 standard
    // errors of light sampling's), and show where their directions end.
    use pathlab_render::geometry::Ray;
    use pathlab_render::scene::Scene;
    let mut desc = big_light();
    desc.point_lights.clear();
    let scene = Scene::build(&desc).unwrap();
    // (Seen from the side, past the light's edge.)
    let eye = Vec3::new(1.5, 1.0, 1.5);
    let ray = Ray::new(eye, Vec3::new(0.5, 0.0, 0.4) - eye);
    let (si, _) = scene.intersect(&ray);
    let si = si.expect("the floor");
    let n = 20_000;
    let estimate = |strategy| {
        let samples = direct_samples(&scene, &si, -ray.d, strategy, n, 9);
        assert_eq!(samples.len(), n as usize);
        let mut y = pathlab_mc::estimator::RunningStats::new();
        samples.iter().for_each(|s| y.push(s.contribution.y as f64));
        let hits = samples
            .iter()
            .filter(|s| s.contribution.y > 0.0)
            .map(|s| s.end.expect("a lit sample ends somewhere"))
            .filter(|e| (e.y - 0.5).abs() < 1e-3)
            .count();
        (y.mean(), y.std_error(), hits)
    };
    let (light, light_se, light_hits) = estimate(SampleStrategy::Light);
    assert!(light > 0.1, "{light}");
    // Every light sample ends on the light, and (nothing blocks it) is lit.
    assert_eq!(light_hits, n as usize);
    for strategy in [
        SampleStrategy::Hemisphere,
        SampleStrategy::Cosine,
        SampleStrategy::Bsdf,
    ] {
        let (mean, se, hits) = estimate(strategy);
        let z = (mean - light) / (se * se + light_se * light_se).sqrt();
        assert!(
            z.abs() < 4.0,
            "{strategy:?}: {mean} ± {se} against {light} ± {light_se}"
        );
        // Only the directions that reach the light (y = 0.5) carry light, and they are fewer.
        assert!(hits > 0 && hits < n as usize / 2, "{strategy:?}: {hits}");
        assert!(se > light_se, "{strategy:?} noisier than light sampling");
    }
}

#[test]
fn direct_lighting_by_the_path_tracers_lanes_is_its_own_estimate() {
    // MIS of one light sample and one BSDF sample renders as the path tracer at depth one
    // (eight paths at a time). The integrator's own one-sample code draws the same random
    // numbers in the same order, so every sample's estimate is the same but for rounding
    // (the sums are formed in another order) in a scene of diffuse and mirror surfaces,
    // area, sphere and point lights.
    let direct = DirectIntegrator::default();
    assert!(direct.as_path().is_some());
    let scene = pathlab_render::scene::Scene::build(&mixed_scene()).unwrap();
    let samples = every_sample(&scene, 16);
    let mut sampler = pathlab_mc::sampler::SamplerKind::Independent.build(16, 3);
    let mut lanes = vec![None; samples.len()];
    direct.li_samples(
        &scene,
        &mut sampler,
        &mut samples.iter().copied(),
        &mut |tag, l| lanes[tag as usize] = Some(l),
        &mut PathStats::default(),
    );
    let mut lit = 0;
    for s in &samples {
        let (ray, weight) = camera_ray(&scene, &mut sampler, *s);
        let own = direct.li(&scene, ray, &mut sampler, &mut PathStats::default()) * weight;
        let l = lanes[s.tag as usize].expect("every sample is estimated");
        assert!(
            (l - own).abs().max_element() <= 1e-5 * (1.0 + own.abs().max_element()),
            "{s:?}: {l} by the lanes, {own} by the direct integrator"
        );
        lit += usize::from(own.max_element() > 0.0);
    }
    assert!(lit * 10 > samples.len(), "{lit} of {} lit", samples.len());
    // Other settings keep the direct integrator's own code.
    for other in [
        DirectIntegrator {
            samples: 2,
            ..direct
        },
        DirectIntegrator {
            bsdf_samples: Some(0),
            ..direct
        },
        DirectIntegrator {
            strategy: DirectStrategy::Light,
            ..direct
        },
    ] {
        assert!(other.as_path().is_none(), "{other:?}");
    }
}
