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

/// Two independent renders agree in their image mean and in every pixel (a z-test of the
/// difference, with a few outliers allowed for pixels whose variance estimate is poor).
fn assert_agree(name: &str, a: &Film, b: &Film) {
    let (ma, mb) = (a.image_mean(), b.image_mean());
    let (sa, sb) = (a.image_mean_std_error(), b.image_mean_std_error());
    for c in 0..3 {
        let z = z_test_two_sample(ma[c], sa[c], mb[c], sb[c]).z;
        eprintln!(
            "{name}: channel {c}: {:.5} vs {:.5}, z {z:.2}",
            ma[c], mb[c]
        );
        assert!(z.abs() < MAX_Z, "{name}: image mean channel {c}: z {z}");
    }
    let mut outliers = 0;
    let mut n = 0;
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let (va, vb) = (p.variance_of_mean(), q.variance_of_mean());
        for c in 0..3 {
            let z = z_test_two_sample(p.mean()[c], va[c].sqrt(), q.mean()[c], vb[c].sqrt()).z;
            n += 1;
            if !(z.abs() < MAX_Z) && (p.mean()[c] - q.mean()[c]).abs() > 1e-4 {
                outliers += 1;
            }
        }
    }
    eprintln!("{name}: {outliers} of {n} pixel channels beyond |z| {MAX_Z}");
    assert!(
        outliers as f64 <= 0.01 * n as f64 + 1.0,
        "{name}: {outliers} of {n}"
    );
}

#[test]
fn bdpt_matches_the_path_tracer_where_every_strategy_works() {
    let desc = every_strategy_scene();
    for d in [2u32, u32::MAX] {
        let pt = run(&desc, path(d), 1024, 71);
        let bd = run(&desc, bdpt(d), 256, 72);
        assert_agree(&format!("bdpt vs path, -m {d}"), &bd, &pt);
    }
}

#[test]
fn bdpt_is_deterministic_for_a_seed() {
    let desc = every_strategy_scene();
    let a = run(&desc, bdpt(u32::MAX), 8, 3);
    let b = run(&desc, bdpt(u32::MAX), 8, 3);
    assert_same_image("bdpt twice", &a, &b);
}
