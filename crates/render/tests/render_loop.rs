//! The render loop's guarantees: the same image for any thread count, in one pass or many,
//! resumed or in sample ranges, eight paths at a time or one; non-finite samples kept off the
//! film; cancelled renders keep their work; bad scenes are errors.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::desc::{
    EnvironmentMapDesc, FresnelModel, MaterialDesc, MeshDesc, NormalDistribution, PrincipledDesc,
    SceneDesc, SphereDesc, TextureDesc,
};
use pathlab_render::film::Film;
use pathlab_render::integrator::{BdptIntegrator, IntegratorKind};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::{diffuse, Scene};

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

/// `desc` with a hundred small triangles far to the side: too many primitives to test every
/// one, so that rays walk the BVH.
fn crowded(mut desc: SceneDesc) -> SceneDesc {
    let positions: Vec<Vec3> = (0..100)
        .flat_map(|i| {
            let o = Vec3::new(40.0 + i as f32, 0.0, 0.0);
            [o, o + Vec3::X * 0.5, o + Vec3::Y * 0.5]
        })
        .collect();
    desc.meshes.push(MeshDesc {
        name: "crowd".into(),
        indices: (0..positions.len() as u32).collect(),
        positions,
        ..Default::default()
    });
    desc
}

/// `desc` with no emitting surface, lit by the other lights `with_more_lights` adds (points,
/// spots, a directional light, projectors) and by a constant environment where `sky`: with
/// no sky, a path's last ray, which could find no emission, is not traced at all.
fn without_emitting_surfaces(desc: SceneDesc, sky: bool) -> SceneDesc {
    let mut desc = with_more_lights(desc);
    for m in &mut desc.meshes {
        m.emission = None;
    }
    for s in &mut desc.spheres {
        s.emission = None;
    }
    if !sky {
        desc.environment = None;
    }
    desc
}

/// `desc` under an environment map with a bright spot (the lanes look up the rays that leave
/// the scene together).
fn under_a_sky(mut desc: SceneDesc) -> SceneDesc {
    let (width, height) = (16, 9);
    let texels = (0..width * height)
        .map(|k| {
            let spot = if k == 2 * width + 5 { 40.0 } else { 0.0 };
            Vec3::new(0.2 + (k % 3) as f32 * 0.1, 0.3, 0.4 + spot)
        })
        .collect();
    desc.environment_map = Some(EnvironmentMapDesc {
        source: "test sky".into(),
        width,
        height,
        texels: std::sync::Arc::new(texels),
        to_world: glam::Mat3::from_rotation_y(0.3),
        scale: 1.0,
    });
    desc
}

/// Spheres resting on the floor at (x, z) of radius r, of the materials `first`, `first + 1`…
/// in turn.
fn push_spheres(desc: &mut SceneDesc, first: usize, spheres: &[(f32, f32, f32)]) {
    for (k, &(x, z, r)) in spheres.iter().enumerate() {
        desc.spheres.push(SphereDesc {
            center: Vec3::new(x, r, z),
            radius: r,
            material: first + k,
            ..Default::default()
        });
    }
}

/// An anisotropic rough GGX conductor of roughness `alpha_u` along the tangent and `alpha_v`
/// across it (its frame follows the tangent).
fn anisotropic_conductor(alpha_u: f32, alpha_v: f32) -> MaterialDesc {
    MaterialDesc::RoughConductor {
        alpha_u: TextureDesc::Constant(Vec3::splat(alpha_u)),
        alpha_v: TextureDesc::Constant(Vec3::splat(alpha_v)),
        eta: Vec3::new(0.2, 0.9, 1.1),
        k: Vec3::new(3.9, 2.4, 2.2),
        specular: TextureDesc::Constant(Vec3::ONE),
        distribution: NormalDistribution::Ggx,
    }
}

/// Four spheres on the floor, (x, z, r) for [`push_spheres`], large enough to be entered.
const FOUR_SPHERES: [(f32, f32, f32); 4] = [
    (-0.5, 0.4, 0.2),
    (0.45, -0.3, 0.2),
    (0.1, 0.5, 0.22),
    (-0.2, -0.3, 0.2),
];

/// `desc` with rough conductors: GGX of one roughness on the wall and the mirror sphere, a
/// Beckmann sphere and an anisotropic GGX one (its frame along the sphere's tangent), all
/// shaded in the lanes; and rough glass spheres, GGX and Beckmann.
fn with_metals(mut desc: SceneDesc) -> SceneDesc {
    let gold = |alpha: f32, distribution| MaterialDesc::Conductor {
        alpha,
        eta: Vec3::new(0.143, 0.374, 1.442),
        k: Vec3::new(3.983, 2.385, 1.603),
        distribution,
    };
    desc.materials[1] = gold(0.08, NormalDistribution::Ggx);
    desc.materials[2] = gold(0.3, NormalDistribution::Ggx);
    desc.materials.push(gold(0.2, NormalDistribution::Beckmann));
    desc.materials.push(anisotropic_conductor(0.1, 0.4));
    let rough_glass = |distribution| MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::new(0.95, 1.0, 0.9),
        roughness: 0.2,
        ior: 1.5,
        distribution,
        fresnel: FresnelModel::Exact,
    };
    desc.materials.push(rough_glass(NormalDistribution::Ggx));
    desc.materials
        .push(rough_glass(NormalDistribution::Beckmann));
    push_spheres(
        &mut desc,
        3,
        &[
            (-0.1, 0.5, 0.12),
            (0.7, 0.5, 0.12),
            (-0.6, 0.0, 0.2),
            (0.1, -0.5, 0.15),
        ],
    );
    desc
}

/// `desc` with textured materials: a diffuse checkerboard, a rough GGX conductor whose
/// roughness is a checkerboard, an anisotropic one (a checkerboard along u, 0.2 along v)
/// and anisotropic Beckmann glass, on the floor and three spheres; all shaded in the lanes.
fn with_textures(mut desc: SceneDesc) -> SceneDesc {
    let checks = |a: Vec3, b: Vec3| TextureDesc::Checkerboard {
        color0: a,
        color1: b,
        to_uv: glam::Affine2::from_scale(glam::Vec2::splat(6.0)),
    };
    let metal = |alpha_v| MaterialDesc::RoughConductor {
        alpha_u: checks(Vec3::splat(0.05), Vec3::splat(0.4)),
        alpha_v,
        eta: Vec3::new(0.2, 0.9, 1.1),
        k: Vec3::new(3.9, 2.4, 2.2),
        specular: TextureDesc::Constant(Vec3::ONE),
        distribution: NormalDistribution::Ggx,
    };
    desc.materials[0] = MaterialDesc::TexturedDiffuse {
        texture: checks(Vec3::new(0.8, 0.2, 0.1), Vec3::new(0.1, 0.6, 0.7)),
        scale: Vec3::ONE,
        two_sided: false,
    };
    let first = desc.materials.len();
    desc.materials
        .push(metal(checks(Vec3::splat(0.05), Vec3::splat(0.4))));
    desc.materials
        .push(metal(TextureDesc::Constant(Vec3::splat(0.2))));
    desc.materials.push(MaterialDesc::RoughGlass {
        alpha_u: checks(Vec3::splat(0.05), Vec3::splat(0.3)),
        alpha_v: TextureDesc::Constant(Vec3::splat(0.15)),
        ior: 1.5,
        distribution: NormalDistribution::Beckmann,
        reflectance: Vec3::ONE,
        transmittance: Vec3::new(0.9, 1.0, 0.95),
    });
    push_spheres(
        &mut desc,
        first,
        &[(-0.4, 0.4, 0.2), (0.4, -0.3, 0.2), (0.0, 0.0, 0.2)],
    );
    desc
}

/// `desc` with smooth lobes: a mirror, a smooth conductor, glass (of exact Fresnel
/// reflectance and of Schlick's), a thin sheet of glass, each shaded in the lanes, each on a
/// sphere, the glass ones large enough to be entered and left.
fn with_smooth_lobes(mut desc: SceneDesc) -> SceneDesc {
    let glass = |fresnel| MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::new(0.9, 1.0, 0.95),
        roughness: 0.0,
        ior: 1.5,
        distribution: NormalDistribution::Ggx,
        fresnel,
    };
    let first = desc.materials.len();
    desc.materials.extend([
        MaterialDesc::Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7),
        },
        MaterialDesc::Conductor {
            alpha: 0.0,
            eta: Vec3::new(0.2, 0.9, 1.1),
            k: Vec3::new(3.9, 2.4, 2.2),
            distribution: NormalDistribution::Beckmann,
        },
        glass(FresnelModel::Exact),
        glass(FresnelModel::Schlick),
        MaterialDesc::ThinGlass {
            reflectance: Vec3::new(1.0, 0.9, 0.9),
            transmittance: Vec3::new(0.8, 1.0, 0.9),
            ior: 1.5,
        },
    ]);
    push_spheres(
        &mut desc,
        first,
        &[
            (-0.6, -0.4, 0.1),
            (0.6, -0.5, 0.12),
            (-0.2, 0.3, 0.25),
            (0.3, 0.6, 0.2),
            (-0.1, -0.2, 0.22),
        ],
    );
    desc
}

/// `desc` with the lights whose samples the lanes draw one lane at a time (besides the point
/// light and the emitting sphere every `mixed_scene` has): a spot light, a directional light, a
/// constant environment and a projector of a checkerboard, whose samples' BSDF values and MIS
/// weights the lanes compute together.
fn with_more_lights(mut desc: SceneDesc) -> SceneDesc {
    use pathlab_render::desc::{
        DirectionalLightDesc, ProjectorDesc, ProjectorKind, SpotFalloff, SpotLightDesc,
        INVERSE_SQUARE,
    };
    desc.spot_lights.push(SpotLightDesc {
        position: Vec3::new(-0.6, 1.4, 0.8),
        direction: Vec3::new(0.4, -1.0, -0.5).normalize(),
        intensity: Vec3::new(2.0, 1.5, 1.0),
        cutoff_degrees: 35.0,
        exponent: 2.0,
        attenuation: INVERSE_SQUARE,
    });
    desc.directional_lights.push(DirectionalLightDesc {
        direction: Vec3::new(0.3, -1.0, -0.2).normalize(),
        irradiance: Vec3::new(0.6, 0.7, 0.9),
    });
    desc.environment = Some(Vec3::new(0.1, 0.12, 0.15));
    desc.projectors.push(ProjectorDesc {
        position: Vec3::new(0.8, 1.2, 0.9),
        frame: glam::Mat3::from_rotation_x(1.9),
        texture: TextureDesc::Checkerboard {
            color0: Vec3::new(1.0, 0.2, 0.1),
            color1: Vec3::new(0.1, 0.3, 1.0),
            to_uv: glam::Affine2::from_scale(glam::Vec2::splat(4.0)),
        },
        kind: ProjectorKind::Spot {
            intensity: Vec3::splat(3.0),
            cutoff: 0.6,
            beam_width: 0.4,
            falloff: SpotFalloff::LinearInAngle,
        },
    });
    desc
}

/// `desc` with blends: of two Lambertian materials by a checkerboard weight (one Lambertian
/// lobe, shaded in the lanes), of a Lambertian one and a rough conductor (one lane at a time),
/// and of two Lambertian ones of different sidedness (one lane at a time); on the floor and on
/// spheres.
fn with_blends(mut desc: SceneDesc) -> SceneDesc {
    let diffuse = |r: Vec3, two_sided| MaterialDesc::Diffuse {
        reflectance: r,
        two_sided,
    };
    let blend = |first, second| MaterialDesc::Blend {
        weight: TextureDesc::Checkerboard {
            color0: Vec3::splat(0.25),
            color1: Vec3::splat(0.9),
            to_uv: glam::Affine2::from_scale(glam::Vec2::splat(5.0)),
        },
        first: Box::new(first),
        second: Box::new(second),
    };
    desc.materials[0] = blend(
        diffuse(Vec3::new(0.0, 0.5, 0.5), false),
        diffuse(Vec3::new(1.0, 1.0, 0.0), false),
    );
    let first = desc.materials.len();
    desc.materials.extend([
        blend(
            diffuse(Vec3::new(0.7, 0.2, 0.2), true),
            diffuse(Vec3::new(0.1, 0.2, 0.9), true),
        ),
        blend(
            diffuse(Vec3::new(0.7, 0.6, 0.2), false),
            MaterialDesc::Conductor {
                alpha: 0.2,
                eta: Vec3::new(0.2, 0.9, 1.1),
                k: Vec3::new(3.9, 2.4, 2.2),
                distribution: NormalDistribution::Ggx,
            },
        ),
        blend(
            diffuse(Vec3::new(0.3, 0.8, 0.2), false),
            diffuse(Vec3::new(0.9, 0.9, 0.9), true),
        ),
    ]);
    push_spheres(
        &mut desc,
        first,
        &[(-0.5, 0.4, 0.18), (0.45, -0.3, 0.18), (0.1, 0.5, 0.18)],
    );
    desc
}

/// `desc` with normal and bump maps: a normal map over the floor's diffuse material; over an
/// anisotropic rough conductor, a mirror and a two-sided diffuse material (on spheres), all
/// shaded in the lanes; a bump map over a diffuse sphere (in the lanes); and a normal map over
/// a blend of diffuse and conductor (one lane at a time).
fn with_maps(mut desc: SceneDesc) -> SceneDesc {
    let normals = |scale: f32| TextureDesc::Bilerp {
        corners: [
            Vec3::new(0.7, 0.5, 0.9),
            Vec3::new(0.3, 0.6, 0.8),
            Vec3::new(0.5, 0.2, 0.7),
            Vec3::new(0.5, 0.5, 1.0),
        ],
        to_uv: glam::Affine2::from_scale(glam::Vec2::splat(scale)),
    };
    let normal_map = |inner, scale| MaterialDesc::NormalMap {
        normals: normals(scale),
        inner: Box::new(inner),
    };
    let diffuse = |r: Vec3, two_sided| MaterialDesc::Diffuse {
        reflectance: r,
        two_sided,
    };
    let metal = anisotropic_conductor(0.25, 0.05);
    desc.materials[0] = normal_map(diffuse(Vec3::new(0.6, 0.5, 0.4), false), 1.0);
    let first = desc.materials.len();
    desc.materials.extend([
        normal_map(metal.clone(), 3.0),
        normal_map(
            MaterialDesc::Mirror {
                reflectance: Vec3::new(0.9, 0.8, 0.7),
            },
            2.0,
        ),
        normal_map(diffuse(Vec3::new(0.2, 0.7, 0.3), true), 4.0),
        MaterialDesc::BumpMap {
            height: normals(5.0),
            scale: 0.05,
            inner: Box::new(diffuse(Vec3::new(0.8, 0.8, 0.2), false)),
        },
        normal_map(
            MaterialDesc::Blend {
                weight: TextureDesc::Constant(Vec3::splat(0.5)),
                first: Box::new(diffuse(Vec3::new(0.5, 0.5, 0.9), false)),
                second: Box::new(metal),
            },
            2.0,
        ),
    ]);
    push_spheres(
        &mut desc,
        first,
        &[
            (-0.5, 0.4, 0.16),
            (0.45, -0.3, 0.16),
            (0.1, 0.5, 0.16),
            (-0.3, -0.4, 0.16),
            (0.6, 0.4, 0.16),
        ],
    );
    desc
}

/// `desc` with plastics and diffuse transmission, all shaded in the lanes: smooth plastic
/// (linear, on the floor, and nonlinear, its coat's reflection tinted), rough plastic (GGX
/// and Beckmann, one of them of a checkerboard base), on the floor and spheres; diffuse
/// reflection and transmission on the wall (lit through from behind too) and, textured, on a
/// sphere.
fn with_plastics(mut desc: SceneDesc) -> SceneDesc {
    let rough = |diffuse, distribution, alpha, nonlinear| MaterialDesc::RoughPlastic {
        diffuse,
        specular: Vec3::new(1.0, 0.9, 0.8),
        alpha,
        ior: 1.5,
        nonlinear,
        distribution,
    };
    desc.materials[0] = MaterialDesc::Plastic {
        diffuse: Vec3::new(0.6, 0.5, 0.4),
        specular: Vec3::ONE,
        ior: 1.5,
        nonlinear: false,
    };
    let first = desc.materials.len();
    desc.materials.extend([
        MaterialDesc::Plastic {
            diffuse: Vec3::new(0.1, 0.3, 0.8),
            specular: Vec3::new(0.8, 1.0, 0.6),
            ior: 1.7,
            nonlinear: true,
        },
        rough(
            TextureDesc::Constant(Vec3::new(0.7, 0.2, 0.2)),
            NormalDistribution::Ggx,
            0.2,
            false,
        ),
        rough(
            TextureDesc::Checkerboard {
                color0: Vec3::new(0.8, 0.8, 0.1),
                color1: Vec3::new(0.1, 0.2, 0.6),
                to_uv: glam::Affine2::from_scale(glam::Vec2::splat(6.0)),
            },
            NormalDistribution::Beckmann,
            0.4,
            true,
        ),
        MaterialDesc::DiffuseTransmission {
            reflectance: TextureDesc::Checkerboard {
                color0: Vec3::new(0.2, 0.6, 0.2),
                color1: Vec3::new(0.7, 0.1, 0.1),
                to_uv: glam::Affine2::from_scale(glam::Vec2::splat(5.0)),
            },
            transmittance: TextureDesc::Constant(Vec3::new(0.5, 0.4, 0.2)),
        },
    ]);
    desc.materials[1] = MaterialDesc::DiffuseTransmission {
        reflectance: TextureDesc::Constant(Vec3::new(0.3, 0.5, 0.4)),
        transmittance: TextureDesc::Constant(Vec3::new(0.4, 0.3, 0.5)),
    };
    push_spheres(
        &mut desc,
        first,
        &[
            (-0.5, 0.4, 0.18),
            (0.45, -0.3, 0.18),
            (0.1, 0.5, 0.18),
            (-0.1, -0.3, 0.18),
        ],
    );
    desc
}

/// `desc` with principled materials, all shaded in the lanes: a solid on the floor with
/// every lobe (metallic and clear coat of checkerboards, anisotropic, so that its frame follows
/// the tangent), a solid sphere that refracts (textured transmission, flatness), a thin sheet
/// on the wall (diffuse transmission, lit through from behind) and a thin sphere (specular
/// transmission); one of the solids with the lobes its parameters leave off.
fn with_principled(mut desc: SceneDesc) -> SceneDesc {
    let checker = |a: f32, b: f32, scale: f32| TextureDesc::Checkerboard {
        color0: Vec3::splat(a),
        color1: Vec3::splat(b),
        to_uv: glam::Affine2::from_scale(glam::Vec2::splat(scale)),
    };
    let constant = |x: f32| TextureDesc::Constant(Vec3::splat(x));
    let principled = |base: Vec3, thin: bool| PrincipledDesc {
        base_color: TextureDesc::Constant(base),
        roughness: constant(0.3),
        anisotropic: None,
        spec_trans: None,
        metallic: None,
        clearcoat: None,
        clearcoat_gloss: constant(0.5),
        sheen: None,
        sheen_tint: None,
        spec_tint: None,
        flatness: None,
        diff_trans: None,
        eta: constant(1.5),
        thin,
    };
    desc.materials[0] = MaterialDesc::Principled(Box::new(PrincipledDesc {
        anisotropic: Some(checker(0.1, 0.7, 5.0)),
        metallic: Some(checker(0.8, 0.1, 5.0)),
        clearcoat: Some(checker(0.9, 0.2, 3.0)),
        sheen: Some(constant(0.5)),
        sheen_tint: Some(constant(0.4)),
        spec_tint: Some(constant(0.6)),
        ..principled(Vec3::new(0.6, 0.5, 0.3), false)
    }));
    desc.materials[1] = MaterialDesc::Principled(Box::new(PrincipledDesc {
        diff_trans: Some(constant(1.2)),
        sheen: Some(constant(0.3)),
        ..principled(Vec3::new(0.3, 0.6, 0.4), true)
    }));
    let first = desc.materials.len();
    desc.materials.extend([
        MaterialDesc::Principled(Box::new(PrincipledDesc {
            spec_trans: Some(checker(0.8, 0.3, 6.0)),
            flatness: Some(constant(0.5)),
            roughness: constant(0.15),
            ..principled(Vec3::new(0.8, 0.7, 0.9), false)
        })),
        MaterialDesc::Principled(Box::new(PrincipledDesc {
            spec_trans: Some(constant(0.7)),
            anisotropic: Some(constant(0.5)),
            spec_tint: Some(constant(0.3)),
            ..principled(Vec3::new(0.7, 0.2, 0.2), true)
        })),
        MaterialDesc::Principled(Box::new(principled(Vec3::new(0.2, 0.3, 0.8), false))),
    ]);
    push_spheres(
        &mut desc,
        first,
        &[(-0.5, 0.4, 0.18), (0.45, -0.3, 0.18), (0.1, 0.5, 0.18)],
    );
    desc
}

/// `desc` with two-sided pairs of different materials, each side shaded in the lanes: on the
/// wall (Lambertian in front, an anisotropic rough conductor behind, its frame along the
/// tangent around the reversed normal) and on spheres that let light in, whose insides are
/// their back sides: diffuse transmission outside and a one-sided Lambertian material inside
/// (whose normal `collect` reverses), rough glass outside and the anisotropic conductor
/// inside, smooth glass outside and glass of Schlick's reflectance inside, a thin sheet outside
/// and a two-sided Lambertian material inside.
fn with_two_sided_pairs(mut desc: SceneDesc) -> SceneDesc {
    let pair = |front, back| MaterialDesc::TwoSided {
        front: Box::new(front),
        back: Box::new(back),
    };
    let anisotropic = || anisotropic_conductor(0.1, 0.4);
    let glass = |roughness, fresnel| MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::new(0.95, 1.0, 0.9),
        roughness,
        ior: 1.5,
        distribution: NormalDistribution::Ggx,
        fresnel,
    };
    desc.materials[1] = pair(diffuse(Vec3::new(0.6, 0.6, 0.3), false), anisotropic());
    let first = desc.materials.len();
    desc.materials.extend([
        pair(
            MaterialDesc::DiffuseTransmission {
                reflectance: TextureDesc::Constant(Vec3::new(0.3, 0.5, 0.4)),
                transmittance: TextureDesc::Constant(Vec3::new(0.5, 0.4, 0.3)),
            },
            diffuse(Vec3::new(0.9, 0.3, 0.2), false),
        ),
        pair(glass(0.2, FresnelModel::Exact), anisotropic()),
        pair(
            glass(0.0, FresnelModel::Exact),
            glass(0.0, FresnelModel::Schlick),
        ),
        pair(
            MaterialDesc::ThinGlass {
                reflectance: Vec3::ONE,
                transmittance: Vec3::new(0.8, 1.0, 0.9),
                ior: 1.5,
            },
            diffuse(Vec3::new(0.2, 0.4, 0.9), true),
        ),
    ]);
    push_spheres(&mut desc, first, &FOUR_SPHERES);
    desc
}

/// `desc` with masks whose opacity is a checkerboard of one and less: their opaque points
/// shaded in the lanes, the others (passing light through) one lane at a time. On the floor
/// over a Lambertian material (half see-through), and on spheres: over a two-sided pair,
/// over an anisotropic conductor under a normal map (the frame the mask's inner material
/// gives), over glass of Schlick's reflectance (opaque everywhere), and a mask over a mask.
fn with_masks(mut desc: SceneDesc) -> SceneDesc {
    let mask = |opaque_elsewhere: f32, inner| MaterialDesc::Mask {
        opacity: TextureDesc::Checkerboard {
            color0: Vec3::ONE,
            color1: Vec3::splat(opaque_elsewhere),
            to_uv: glam::Affine2::from_scale(glam::Vec2::splat(6.0)),
        },
        inner: Box::new(inner),
    };
    let anisotropic = anisotropic_conductor(0.3, 0.05);
    desc.materials[0] = mask(0.5, diffuse(Vec3::new(0.6, 0.5, 0.4), false));
    let first = desc.materials.len();
    desc.materials.extend([
        mask(
            0.0,
            MaterialDesc::TwoSided {
                front: Box::new(diffuse(Vec3::new(0.8, 0.3, 0.2), false)),
                back: Box::new(diffuse(Vec3::new(0.2, 0.3, 0.8), false)),
            },
        ),
        mask(
            0.3,
            MaterialDesc::NormalMap {
                normals: TextureDesc::Bilerp {
                    corners: [
                        Vec3::new(0.7, 0.5, 0.9),
                        Vec3::new(0.3, 0.6, 0.8),
                        Vec3::new(0.5, 0.2, 0.7),
                        Vec3::new(0.5, 0.5, 1.0),
                    ],
                    to_uv: glam::Affine2::from_scale(glam::Vec2::splat(3.0)),
                },
                inner: Box::new(anisotropic),
            },
        ),
        mask(
            1.0,
            MaterialDesc::Glass {
                reflectance: Vec3::ONE,
                transmittance: Vec3::new(0.95, 1.0, 0.9),
                roughness: 0.0,
                ior: 1.5,
                distribution: NormalDistribution::Ggx,
                fresnel: FresnelModel::Schlick,
            },
        ),
        mask(0.6, mask(1.0, diffuse(Vec3::new(0.3, 0.8, 0.3), true))),
    ]);
    push_spheres(&mut desc, first, &FOUR_SPHERES);
    desc
}

/// `desc` with masks that let some light through, shaded in the lanes as their lobe and
/// passing through (`LaneLobe::weight`): checkerboards of two opacities below one, or of
/// none, over smooth plastic on the floor (a delta lobe and a diffuse one), a rough conductor
/// on the wall, and spheres of smooth glass, rough glass, a two-sided pair (rough plastic in
/// front, a mirror behind) and diffuse transmission.
fn with_see_through_masks(mut desc: SceneDesc) -> SceneDesc {
    let mask = see_through_mask;
    let glass = |roughness| MaterialDesc::Glass {
        reflectance: Vec3::ONE,
        transmittance: Vec3::new(0.9, 1.0, 0.95),
        roughness,
        ior: 1.5,
        distribution: NormalDistribution::Ggx,
        fresnel: FresnelModel::Exact,
    };
    desc.materials[0] = mask(
        [0.75, 0.25],
        MaterialDesc::Plastic {
            diffuse: Vec3::new(0.6, 0.5, 0.4),
            specular: Vec3::ONE,
            ior: 1.5,
            nonlinear: false,
        },
    );
    desc.materials[1] = mask(
        [0.5, 0.0],
        MaterialDesc::Conductor {
            alpha: 0.2,
            eta: Vec3::new(0.143, 0.374, 1.442),
            k: Vec3::new(3.983, 2.385, 1.603),
            distribution: NormalDistribution::Ggx,
        },
    );
    let first = desc.materials.len();
    desc.materials.extend([
        mask([0.4, 0.8], glass(0.0)),
        mask([0.6, 0.0], glass(0.3)),
        mask(
            [0.5, 0.25],
            MaterialDesc::TwoSided {
                front: Box::new(MaterialDesc::RoughPlastic {
                    diffuse: TextureDesc::Constant(Vec3::new(0.7, 0.2, 0.2)),
                    specular: Vec3::ONE,
                    alpha: 0.2,
                    ior: 1.5,
                    nonlinear: false,
                    distribution: NormalDistribution::Ggx,
                }),
                back: Box::new(MaterialDesc::Mirror {
                    reflectance: Vec3::new(0.9, 0.8, 0.7),
                }),
            },
        ),
        mask(
            [0.7, 0.3],
            MaterialDesc::DiffuseTransmission {
                reflectance: TextureDesc::Constant(Vec3::new(0.3, 0.5, 0.4)),
                transmittance: TextureDesc::Constant(Vec3::new(0.4, 0.3, 0.5)),
            },
        ),
    ]);
    push_spheres(&mut desc, first, &FOUR_SPHERES);
    desc
}

/// `inner` under a mask of a checkerboard of `opacities`.
fn see_through_mask(opacities: [f32; 2], inner: MaterialDesc) -> MaterialDesc {
    MaterialDesc::Mask {
        opacity: TextureDesc::Checkerboard {
            color0: Vec3::splat(opacities[0]),
            color1: Vec3::splat(opacities[1]),
            to_uv: glam::Affine2::from_scale(glam::Vec2::splat(5.0)),
        },
        inner: Box::new(inner),
    }
}

/// `desc` with every material under a mask that lets some light through everywhere: over
/// `with_maps`' materials, lobes in frames of their own (normal and bump maps, anisotropic
/// roughness) under their maps' guards.
fn under_see_through_masks(mut desc: SceneDesc) -> SceneDesc {
    for m in &mut desc.materials {
        *m = see_through_mask([0.7, 0.35], m.clone());
    }
    desc
}

#[test]
fn packets_compute_what_one_path_at_a_time_computes() {
    // The path integrator follows eight paths at once, computing the scattering at
    // Lambertian surfaces in SIMD lanes (and the environment map's radiance towards the rays
    // that leave the scene), lit by emitting triangles or an environment map sampled in the
    // lanes or by any other light sampled one lane at a time (`with_more_lights`), and
    // everything else with the scalar code (rough conductors, anisotropic ones included, and
    // glass of one roughness, mirrors, smooth conductors and glass go through the lanes too,
    // textured or not, in the scenes `with_metals`, `with_smooth_lobes` and `with_textures`;
    // blends of two diffuse materials in `with_blends`; those lobes under normal and bump
    // maps in `with_maps`; smooth and rough plastics in `with_plastics`; the principled model
    // in `with_principled`; two-sided pairs in `with_two_sided_pairs`; masks in `with_masks`,
    // `with_see_through_masks` and, over maps, `under_see_through_masks`): every sample's radiance must be the scalar `li`'s to the
    // bit, and the rays and nodes counted the same. In a scene of a few triangles and spheres
    // the lanes' rays are tested against every primitive at once instead of walking the BVH
    // (the same distances; of primitives at exactly the same distance, possibly another,
    // which these rays do not meet), and no nodes are counted; with a hundred triangles more,
    // the lanes walk the BVH.
    for (desc, bvh) in [
        (mixed_scene(), false),
        (crowded(mixed_scene()), true),
        (big_light(), false),
        (under_a_sky(mixed_scene()), false),
        (crowded(under_a_sky(mixed_scene())), true),
        (with_metals(mixed_scene()), false),
        (crowded(under_a_sky(with_metals(mixed_scene()))), true),
        (with_smooth_lobes(mixed_scene()), false),
        (
            under_a_sky(with_smooth_lobes(with_metals(mixed_scene()))),
            false,
        ),
        (with_textures(mixed_scene()), false),
        (under_a_sky(with_textures(mixed_scene())), false),
        (with_more_lights(with_metals(mixed_scene())), false),
        (
            crowded(with_more_lights(with_smooth_lobes(mixed_scene()))),
            true,
        ),
        (with_blends(mixed_scene()), false),
        (under_a_sky(with_blends(mixed_scene())), false),
        (with_maps(mixed_scene()), false),
        (under_a_sky(with_maps(mixed_scene())), false),
        (with_plastics(mixed_scene()), false),
        (crowded(under_a_sky(with_plastics(mixed_scene()))), true),
        (with_more_lights(with_plastics(mixed_scene())), false),
        (with_principled(mixed_scene()), false),
        (crowded(under_a_sky(with_principled(mixed_scene()))), true),
        (with_more_lights(with_principled(mixed_scene())), false),
        (with_more_lights(with_maps(mixed_scene())), false),
        (with_two_sided_pairs(mixed_scene()), false),
        (
            crowded(under_a_sky(with_two_sided_pairs(mixed_scene()))),
            true,
        ),
        (with_masks(mixed_scene()), false),
        (with_see_through_masks(mixed_scene()), false),
        (
            crowded(with_more_lights(under_a_sky(with_see_through_masks(
                mixed_scene(),
            )))),
            true,
        ),
        (
            with_more_lights(under_a_sky(with_masks(mixed_scene()))),
            false,
        ),
        (under_see_through_masks(with_maps(mixed_scene())), false),
        (
            with_more_lights(under_a_sky(under_see_through_masks(with_maps(
                mixed_scene(),
            )))),
            false,
        ),
        (without_emitting_surfaces(mixed_scene(), false), false),
        (without_emitting_surfaces(mixed_scene(), true), false),
        (
            crowded(without_emitting_surfaces(with_metals(mixed_scene()), true)),
            true,
        ),
        (
            under_a_sky(without_emitting_surfaces(
                with_smooth_lobes(mixed_scene()),
                true,
            )),
            false,
        ),
    ] {
        let scene = Scene::build(&desc).unwrap();
        packets_match_one_path_at_a_time(&scene, bvh);
    }
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

#[test]
fn one_pixels_sample_values_are_the_samples_its_film_pixel_sums() {
    // A pixel's samples one by one (the viewer's histogram) sum to what the render put in
    // the pixel, exactly, for the default path tracer (eight paths at a time) and with the
    // Sobol sampler, starting at any sample index.
    let scene = Scene::build(&big_light()).unwrap();
    let settings = RenderSettings::new(32, 7, SamplerKind::Sobol);
    let (film, _) = render(
        &scene,
        &path(u32::MAX),
        &settings,
        &|_| {},
        &Default::default(),
    );
    for pixel in [[0, 0], [3, 5], [7, 7]] {
        let values = pathlab_render::render::pixel_sample_values(
            &scene,
            &path(u32::MAX),
            (SamplerKind::Sobol, 32, 7),
            pixel,
            0..32,
        );
        let mut stats = pathlab_render::film::PixelStats::default();
        values.iter().for_each(|&l| stats.add(l));
        assert_eq!(&stats, film.pixel(pixel[0], pixel[1]), "pixel {pixel:?}");
        let later = pathlab_render::render::pixel_sample_values(
            &scene,
            &path(u32::MAX),
            (SamplerKind::Sobol, 32, 7),
            pixel,
            20..32,
        );
        assert_eq!(later, values[20..]);
    }
}

#[test]
fn adaptive_and_light_tracing_renders_are_the_same_for_any_thread_count() {
    // Tiles add their samples to the film as each finishes, in whatever order the threads
    // finish them, and the adaptive rules read the film between rounds: the film's exact sums
    // keep the image the same. Light traced to the lens (bidirectional) lands on any tile.
    use pathlab_render::render::{Adaptive, AdaptiveRule};
    let scene = Scene::build(&big_light()).unwrap();
    let mut cases: Vec<(String, IntegratorKind, RenderSettings)> = [
        AdaptiveRule::TwoStage,
        AdaptiveRule::Course,
        AdaptiveRule::Neyman {
            image_luminance: 0.5,
        },
    ]
    .into_iter()
    .map(|rule| {
        let adaptive = Adaptive {
            batch: 4,
            min_samples: 8,
            rule,
            ..Adaptive::DEFAULT
        };
        let settings = RenderSettings {
            adaptive: Some(adaptive),
            ..RenderSettings::new(32, 5, SamplerKind::Independent)
        };
        (format!("adaptive {rule:?}"), path(u32::MAX), settings)
    })
    .collect();
    let bdpt = IntegratorKind::Bdpt(BdptIntegrator::default());
    let settings = RenderSettings::new(4, 5, SamplerKind::Independent);
    cases.push(("bidirectional".to_string(), bdpt, settings));
    for (name, integrator, settings) in &cases {
        let with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&scene, integrator, settings, &|_| {}, &Default::default()).0)
        };
        let one = with(1);
        assert!(
            one == with(2) && one == with(3),
            "{name}: the image depends on the thread count"
        );
        if matches!(integrator, IntegratorKind::Bdpt(_)) {
            assert!(one.light_paths() > 0, "no light reached the lens");
        }
    }
}

#[test]
fn a_film_too_large_to_allocate_is_an_error_that_says_its_size() {
    assert!(Film::try_new(24, 16).unwrap() == Film::new(24, 16));
    // 2^40 pixels: more memory than any machine has.
    let e = Film::try_new(1 << 20, 1 << 20).err().unwrap();
    assert!(e.contains("1048576x1048576") && e.contains("GiB"), "{e}");
}
