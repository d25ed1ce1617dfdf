//! The bidirectional path tracer on scenes with known answers (furnaces) and against the path
//! tracer pixel by pixel on scenes where every strategy has work: area, sphere and point
//! lights, glass (importance through refraction), a glossy conductor and a mirror. Tolerances
//! are multiples of the standard errors the renders estimate themselves.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use pathlab_mc::stats::z_test_two_sample;
use pathlab_render::bsdf::{FresnelModel, NormalDistribution};
use pathlab_render::desc::*;
use pathlab_render::film::Film;
use pathlab_render::integrator::*;
use pathlab_testkit::reference::replicated_estimates;

fn bdpt(max_depth: u32) -> IntegratorKind {
    IntegratorKind::Bdpt(BdptIntegrator {
        max_depth,
        ..Default::default()
    })
}

#[test]
fn closed_furnace_converges_to_geometric_series() {
    // Inside a sphere that emits 1 everywhere and reflects a: L = 1 + a + ... + a^d at depth d.
    // Every join strategy finds light here, and their weights must sum to one.
    let albedo = 0.6f64;
    for (d, spp) in [(0u32, 16), (1, 64), (3, 64), (u32::MAX, 128)] {
        let film = run(
            &closed_furnace(albedo as f32),
            bdpt(d),
            spp,
            40 + d as u64 % 7,
        );
        let truth: f64 = if d == u32::MAX {
            1.0 / (1.0 - albedo)
        } else {
            (0..=d).map(|k| albedo.powi(k as i32)).sum()
        };
        assert_mean(
            &format!("bdpt closed furnace, -m {d}"),
            &film,
            DVec3::splat(truth),
        );
    }
}

#[test]
fn lights_at_infinity_are_found_from_the_camera() {
    // The sky starts no light subpaths: light sampling and BSDF sampling find it.
    let film = run(&sky_sphere(), bdpt(u32::MAX), 64, 5);
    assert_mean("bdpt sky furnace", &film, DVec3::splat(0.8));
    let mut desc = sky_sphere();
    desc.materials = vec![glass()];
    let film = run(&desc, bdpt(u32::MAX), 256, 6);
    assert_mean("bdpt glass in a white furnace", &film, DVec3::ONE);
}

fn glass() -> MaterialDesc {
    MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::ONE,
        roughness: 0.0,
        ior: 1.5,
        distribution: NormalDistribution::Ggx,
        fresnel: FresnelModel::Exact,
    }
}

/// `mixed_scene` (area, sphere and point lights, a mirror, a two-sided wall) with a glass
/// sphere and a rough glass sphere on the floor and a glossy conductor plate.
fn every_strategy_scene() -> SceneDesc {
    let mut desc = mixed_scene();
    let glass_index = desc.materials.len();
    desc.materials.push(glass());
    desc.materials.push(MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::ONE,
        roughness: 0.3,
        ior: 1.33,
        distribution: NormalDistribution::Ggx,
        fresnel: FresnelModel::Exact,
    });
    desc.materials.push(MaterialDesc::RoughConductor {
        alpha_u: TextureDesc::value(0.2),
        alpha_v: TextureDesc::value(0.2),
        eta: Vec3::new(0.2, 0.9, 1.1),
        k: Vec3::new(3.9, 2.4, 2.2),
        specular: TextureDesc::value(1.0),
        distribution: NormalDistribution::Ggx,
    });
    for (center, radius, material) in [
        (Vec3::new(0.1, 0.2, 0.5), 0.2, glass_index),
        (Vec3::new(-0.2, 0.15, -0.4), 0.15, glass_index + 1),
    ] {
        desc.spheres.push(SphereDesc {
            center,
            radius,
            material,
            emission: None,
            ..Default::default()
        });
    }
    desc.meshes.push(MeshDesc {
        name: "plate".into(),
        positions: vec![
            Vec3::new(0.6, 0.0, -0.9),
            Vec3::new(1.0, 0.0, -0.9),
            Vec3::new(1.0, 0.6, -0.6),
            Vec3::new(0.6, 0.6, -0.6),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material: glass_index + 2,
        ..Default::default()
    });
    desc
}

/// Pixel values and the variance of each value, from `renders` independent renders (light
/// traced to the lens lands on pixels other than the sample's, so a pixel's own samples do not
/// give its variance).
fn replicated(
    desc: &SceneDesc,
    integrator: IntegratorKind,
    spp: u32,
    renders: u64,
) -> Vec<(DVec3, DVec3)> {
    let films: Vec<Film> = (0..renders)
        .map(|k| run(desc, integrator, spp, 100 + k))
        .collect();
    replicated_estimates(&films)
        .into_iter()
        .map(|e| e.expect("every pixel is rendered"))
        .collect()
}

#[test]
fn bdpt_matches_the_path_tracer_where_every_strategy_works() {
    let desc = every_strategy_scene();
    for d in [2u32, u32::MAX] {
        let pt = run(&desc, path(d), 1024, 71);
        let bd = replicated(&desc, bdpt(d), 32, 8);
        let name = format!("bdpt vs path, -m {d}");
        let (mut outliers, mut n) = (0, 0);
        let (mut sum_bd, mut sum_pt, mut var_bd) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for ((m, v), p) in bd.iter().zip(pt.pixels()) {
            sum_bd += *m;
            sum_pt += p.mean();
            var_bd += *v;
            for c in 0..3 {
                let z = z_test_two_sample(
                    m[c],
                    v[c].sqrt(),
                    p.mean()[c],
                    p.variance_of_mean()[c].sqrt(),
                )
                .z;
                n += 1;
                if (z.is_nan() || z.abs() >= MAX_Z) && (m[c] - p.mean()[c]).abs() > 1e-4 {
                    outliers += 1;
                }
            }
        }
        let k = bd.len() as f64;
        for c in 0..3 {
            let z = z_test_two_sample(
                sum_bd[c] / k,
                var_bd[c].sqrt() / k,
                sum_pt[c] / k,
                pt.image_mean_std_error()[c],
            )
            .z;
            eprintln!(
                "{name}: image mean channel {c}: {:.5} vs {:.5}, z {z:.2}",
                sum_bd[c] / k,
                sum_pt[c] / k
            );
            assert!(z.abs() < MAX_Z, "{name}: image mean channel {c}: z {z}");
        }
        eprintln!("{name}: {outliers} of {n} pixel channels beyond |z| {MAX_Z}");
        assert!(
            outliers as f64 <= 0.01 * n as f64 + 1.0,
            "{name}: {outliers} of {n}"
        );
    }
}

#[test]
fn bdpt_is_deterministic_for_a_seed() {
    let desc = every_strategy_scene();
    let a = run(&desc, bdpt(u32::MAX), 8, 3);
    let b = run(&desc, bdpt(u32::MAX), 8, 3);
    assert_same_image("bdpt twice", &a, &b);
}

#[test]
fn light_traced_to_the_lens_survives_shards_and_film_files_to_the_bit() {
    // Two shards of the sample range, each written to a film file and read back, merge into
    // the film of one render: pixel sums, splat sums and light paths alike.
    use pathlab_mc::sampler::SamplerKind;
    use pathlab_render::film_file::{self, FilmHeader};
    use pathlab_render::render::{render, RenderSettings};
    use pathlab_render::scene::Scene;
    let scene = Scene::build(&every_strategy_scene()).expect("the scene builds");
    let integrator = bdpt(u32::MAX);
    let settings = |range: Option<[u32; 2]>| RenderSettings {
        sample_range: range,
        ..RenderSettings::new(8, 9, SamplerKind::Independent)
    };
    let whole = render(
        &scene,
        &integrator,
        &settings(None),
        &|_| {},
        &Default::default(),
    )
    .0;
    assert!(whole.light_paths() > 0 && !whole.splat_sums().is_empty());
    let dir = std::env::temp_dir().join(format!("pathlab-bdpt-shards-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let parts: Vec<(String, FilmHeader, Film)> = [[0u32, 3], [3, 8]]
        .into_iter()
        .map(|range| {
            let film = render(
                &scene,
                &integrator,
                &settings(Some(range)),
                &|_| {},
                &Default::default(),
            )
            .0;
            let header = FilmHeader {
                resolution: [film.width(), film.height()],
                key: "k".into(),
                description: "bdpt".into(),
                seed: 9,
                spp: 8,
                range,
                writer: "test".into(),
            };
            let path = dir.join(format!("part{}.plf", range[0]));
            film_file::write(&path, &header, &film).unwrap();
            let (header, read) = film_file::read(&path).unwrap();
            assert_eq!(read, film, "a film file keeps the splats");
            (path.display().to_string(), header, read)
        })
        .collect();
    let (_, merged) = film_file::merge(parts).unwrap();
    assert_eq!(merged, whole);
    std::fs::remove_dir_all(&dir).ok();
}
