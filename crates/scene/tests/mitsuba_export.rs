//! Scenes written as Mitsuba XML (`mitsuba::export`) and read back by the Mitsuba loader: the
//! same geometry to the bit, the same materials, lights, camera, film and settings.

use glam::{Vec2, Vec3};
use pathlab_render::bsdf::NormalDistribution;
use pathlab_render::desc::{
    CameraDesc, DirectionalLightDesc, Emission, EnvironmentMapDesc, IntegratorHint, MaterialDesc,
    MeshDesc, PixelFilter, PointLightDesc, SceneDesc, SphereDesc, TextureDesc, INVERSE_SQUARE,
};
use pathlab_render::mc::sampler::SamplerKind;
use pathlab_scene::mitsuba::export::{to_mitsuba, write_mitsuba, ExportError};
use std::path::PathBuf;

/// An empty folder of this test's own under the system's temporary directory.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pathlab-export-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    dir
}

/// `m` in the form the Mitsuba loader gives it: conductors (and mirrors) as rough conductors
/// with constant textures, smooth glass with the loader's (unused) distribution.
fn normalized(m: &MaterialDesc) -> MaterialDesc {
    match m {
        MaterialDesc::Conductor {
            alpha,
            eta,
            k,
            distribution,
        } => MaterialDesc::RoughConductor {
            alpha_u: TextureDesc::value(*alpha),
            alpha_v: TextureDesc::value(*alpha),
            eta: *eta,
            k: *k,
            specular: TextureDesc::Constant(Vec3::ONE),
            distribution: if *alpha > 0.0 {
                *distribution
            } else {
                NormalDistribution::Beckmann
            },
        },
        MaterialDesc::Mirror { reflectance } => MaterialDesc::RoughConductor {
            alpha_u: TextureDesc::value(0.0),
            alpha_v: TextureDesc::value(0.0),
            eta: Vec3::ZERO,
            k: Vec3::ONE,
            specular: TextureDesc::Constant(*reflectance),
            distribution: NormalDistribution::Beckmann,
        },
        // Smooth glass has no microfacet distribution.
        MaterialDesc::Glass {
            roughness,
            distribution: _,
            ..
        } if *roughness == 0.0 => {
            let mut g = m.clone();
            if let MaterialDesc::Glass { distribution, .. } = &mut g {
                *distribution = NormalDistribution::Beckmann;
            }
            g
        }
        MaterialDesc::TwoSided { front, back } => MaterialDesc::TwoSided {
            front: Box::new(normalized(front)),
            back: Box::new(normalized(back)),
        },
        other => other.clone(),
    }
}

/// Writes `desc`, reads it back, and checks that nothing changed.
fn round_trip(name: &str, desc: &SceneDesc) -> SceneDesc {
    let dir = scratch(name);
    let xml = dir.join("scene.xml");
    let warnings = write_mitsuba(desc, &xml).unwrap_or_else(|e| panic!("{name}: {e}"));
    let back = pathlab_scene::load(xml.to_str().expect("a UTF-8 path"))
        .unwrap_or_else(|e| panic!("{name}: reading back: {e}"));
    assert!(back.warnings.is_empty(), "{name}: {:?}", back.warnings);

    assert_eq!(back.resolution, desc.resolution, "{name}");
    assert_eq!(back.filter, desc.filter, "{name}");
    let (h, hb) = (&desc.hints, &back.hints);
    assert_eq!(hb.spp, Some(h.spp_or_default()), "{name}");
    assert_eq!(hb.max_depth, h.max_depth, "{name}");
    assert_eq!(hb.rr_depth, h.rr_depth, "{name}");
    assert_eq!(hb.hide_emitters, h.hide_emitters, "{name}");
    assert_eq!(hb.crop, h.crop, "{name}");
    assert_eq!(
        hb.sampler,
        Some(h.sampler.unwrap_or(SamplerKind::Independent)),
        "{name}"
    );
    let integrator = match h.integrator {
        Some(IntegratorHint::Bdpt) => {
            assert!(
                warnings.iter().any(|w| w.contains("bidirectional")),
                "{warnings:?}"
            );
            Some(IntegratorHint::Path)
        }
        None => Some(IntegratorHint::Path),
        other => other,
    };
    assert_eq!(hb.integrator, integrator, "{name}");

    let (c, cb) = (&desc.camera, &back.camera);
    let close = |a: Vec3, b: Vec3| (a - b).length() <= 1e-5 * a.length().max(1.0);
    assert!(close(cb.origin, c.origin), "{name}: {cb:?} vs {c:?}");
    let view = |c: &CameraDesc| (c.target - c.origin).normalize();
    assert!(close(view(cb), view(c)), "{name}: {cb:?} vs {c:?}");
    assert!(close(cb.up.normalize(), c.up.normalize()), "{name}");
    // The loader gives the field of view along x.
    let (fx, fxb) = (
        horizontal_fov(c, desc.resolution),
        horizontal_fov(cb, back.resolution),
    );
    assert!((fx - fxb).abs() < 1e-3, "{name}: {fx} vs {fxb}");
    assert_eq!(cb.lens_radius, c.lens_radius, "{name}");
    if c.lens_radius > 0.0 {
        assert_eq!(cb.focal_distance, c.focal_distance, "{name}");
    }
    assert_eq!(
        cb.principal_point_offset, c.principal_point_offset,
        "{name}"
    );

    assert_eq!(back.meshes.len(), desc.meshes.len(), "{name}");
    for (m, mb) in desc.meshes.iter().zip(&back.meshes) {
        assert!(mb.positions == m.positions, "{name}: {}", m.name);
        assert!(mb.indices == m.indices, "{name}: {}", m.name);
        // (The PLY reader makes normals unit length.)
        assert_eq!(mb.normals.len(), m.normals.len(), "{name}: {}", m.name);
        for (a, b) in m.normals.iter().zip(&mb.normals) {
            assert!(close(a.normalize(), *b), "{name}: {a} vs {b}");
        }
        assert_eq!(mb.uvs.len(), m.uvs.len(), "{name}: {}", m.name);
        for (a, b) in m.uvs.iter().zip(&mb.uvs) {
            assert!((*a - *b).abs().max_element() <= 1e-6, "{name}: {a} vs {b}");
        }
        assert_eq!(mb.emission, m.emission, "{name}: {}", m.name);
        assert_eq!(
            normalized(&back.materials[mb.material]),
            normalized(&desc.materials[m.material]),
            "{name}: {}",
            m.name
        );
    }
    assert_eq!(back.spheres.len(), desc.spheres.len(), "{name}");
    for (s, sb) in desc.spheres.iter().zip(&back.spheres) {
        assert_eq!((sb.center, sb.radius), (s.center, s.radius), "{name}");
        assert_eq!(sb.emission, s.emission, "{name}");
        assert_eq!(
            normalized(&back.materials[sb.material]),
            normalized(&desc.materials[s.material]),
            "{name}"
        );
    }
    assert_eq!(back.point_lights, desc.point_lights, "{name}");
    assert_eq!(back.directional_lights, desc.directional_lights, "{name}");
    assert_eq!(back.environment, desc.environment, "{name}");
    let _ = std::fs::remove_dir_all(&dir);
    back
}

/// The horizontal field of view in degrees of camera `c` on an image of `[w, h]` pixels.
fn horizontal_fov(c: &CameraDesc, [w, h]: [u32; 2]) -> f64 {
    use pathlab_render::desc::FovAxis;
    let (w, h) = (w as f64, h as f64);
    let t = (c.fov_degrees as f64 * 0.5).to_radians().tan();
    let scale = match c.fov_axis {
        FovAxis::X => 1.0,
        FovAxis::Y => w / h,
        FovAxis::Smaller if w <= h => 1.0,
        FovAxis::Smaller => w / h,
        FovAxis::Larger if w >= h => 1.0,
        FovAxis::Larger => w / h,
        FovAxis::Diagonal => w / (w * w + h * h).sqrt(),
    };
    2.0 * (t * scale).atan().to_degrees()
}

fn data(path: &str) -> String {
    format!("{}/../../tests/data/{path}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn bitterlis_pbrt_scenes_read_back_as_they_were_written() {
    for scene in ["cornell-box", "veach-mis", "veach-bidir"] {
        let desc = pathlab_scene::load(&data(&format!("bitterli/{scene}/scene-v4.pbrt")))
            .unwrap_or_else(|e| panic!("{e}"));
        round_trip(scene, &desc);
    }
}

#[test]
fn the_builtin_box_reads_back_as_it_was_written() {
    let desc = pathlab_scene::builtin::load("cornell-box").expect("the built-in box");
    round_trip("builtin", &desc);
    // The course's camera: its image plane a number of pixels away, written as the field of
    // view it gives.
    let mut desc = desc;
    desc.camera.focal_pixels = Some(300.0);
    let back = round_trip_geometry("focal-pixels", &desc);
    let [w, _] = desc.resolution;
    let fov = 2.0 * (w as f64 * 0.5 / 300.0).atan().to_degrees();
    assert!((horizontal_fov(&back.camera, back.resolution) - fov).abs() < 1e-3);
}

/// [`round_trip`] for a scene whose camera the file gives another way (written as a field of
/// view): the camera as the file reads back, the rest checked.
fn round_trip_geometry(name: &str, desc: &SceneDesc) -> SceneDesc {
    let mut same_view = desc.clone();
    let dir = scratch(&format!("{name}-view"));
    let xml = dir.join("scene.xml");
    write_mitsuba(desc, &xml).unwrap_or_else(|e| panic!("{name}: {e}"));
    let back = pathlab_scene::load(xml.to_str().expect("a UTF-8 path"))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    same_view.camera = back.camera;
    let _ = std::fs::remove_dir_all(&dir);
    round_trip(name, &same_view)
}

/// A scene of every material, light and camera setting the writer knows.
fn everything() -> SceneDesc {
    let quad = |material, emission| MeshDesc {
        name: format!("quad{material}"),
        positions: vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.1, 1.0),
        ],
        indices: vec![0, 2, 1, 0, 3, 2],
        material,
        emission,
        normals: if material % 2 == 0 {
            vec![Vec3::Y; 4]
        } else {
            Vec::new()
        },
        uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::new(0.25, 0.75)],
        ..Default::default()
    };
    let metal = |alpha| MaterialDesc::Conductor {
        alpha,
        eta: Vec3::new(0.2, 0.9, 1.1),
        k: Vec3::new(3.9, 2.4, 2.1),
        distribution: NormalDistribution::Ggx,
    };
    let materials = vec![
        MaterialDesc::Diffuse {
            reflectance: Vec3::new(0.1, 0.2, 0.3),
            two_sided: false,
        },
        MaterialDesc::Diffuse {
            reflectance: Vec3::new(0.7, 0.6, 0.5),
            two_sided: true,
        },
        metal(0.0),
        metal(0.2),
        MaterialDesc::Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7),
        },
        MaterialDesc::Glass {
            reflectance: Vec3::ONE,
            transmittance: Vec3::new(0.9, 1.0, 0.9),
            roughness: 0.0,
            ior: 1.5,
            distribution: NormalDistribution::Beckmann,
            fresnel: Default::default(),
        },
        MaterialDesc::Glass {
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
            roughness: 0.3,
            ior: 1.33,
            distribution: NormalDistribution::Ggx,
            fresnel: Default::default(),
        },
        MaterialDesc::ThinGlass {
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
            ior: 1.5,
        },
        MaterialDesc::Plastic {
            diffuse: Vec3::new(0.5, 0.2, 0.1),
            specular: Vec3::ONE,
            ior: 1.49,
            nonlinear: true,
        },
        MaterialDesc::RoughPlastic {
            diffuse: TextureDesc::Constant(Vec3::new(0.1, 0.5, 0.2)),
            specular: Vec3::ONE,
            alpha: 0.15,
            ior: 1.6,
            nonlinear: false,
            distribution: NormalDistribution::Beckmann,
        },
        MaterialDesc::TwoSided {
            front: Box::new(metal(0.1)),
            back: Box::new(MaterialDesc::Diffuse {
                reflectance: Vec3::splat(0.4),
                two_sided: false,
            }),
        },
    ];
    let mut meshes: Vec<MeshDesc> = (0..materials.len()).map(|m| quad(m, None)).collect();
    meshes.push(quad(
        0,
        Some(Emission {
            radiance: Vec3::new(10.0, 8.0, 6.0),
            two_sided: false,
        }),
    ));
    let mut desc = SceneDesc {
        meshes,
        materials,
        spheres: vec![SphereDesc {
            center: Vec3::new(0.5, 1.0, -0.25),
            radius: 0.3,
            material: 1,
            emission: Some(Emission {
                radiance: Vec3::splat(3.0),
                two_sided: false,
            }),
            ..Default::default()
        }],
        point_lights: vec![PointLightDesc {
            position: Vec3::new(0.0, 3.0, 1.0),
            intensity: Vec3::new(5.0, 5.0, 4.0),
            attenuation: INVERSE_SQUARE,
        }],
        directional_lights: vec![DirectionalLightDesc {
            direction: Vec3::new(0.0, -0.6, -0.8),
            irradiance: Vec3::splat(2.0),
        }],
        environment: Some(Vec3::new(0.1, 0.2, 0.3)),
        resolution: [64, 48],
        filter: PixelFilter::gaussian(0.5),
        ..Default::default()
    };
    desc.camera.lens_radius = 0.05;
    desc.camera.focal_distance = 4.5;
    desc.camera.principal_point_offset = Vec2::new(0.1, -0.05);
    desc.hints.spp = Some(16);
    desc.hints.max_depth = Some(6);
    desc.hints.rr_depth = Some(3);
    desc.hints.sampler = Some(SamplerKind::Sobol);
    desc.hints.hide_emitters = true;
    desc
}

#[test]
fn every_material_light_and_camera_setting_the_writer_knows_reads_back() {
    round_trip("everything", &everything());
    let mut desc = everything();
    desc.hints.max_depth = Some(u32::MAX);
    desc.hints.sampler = Some(SamplerKind::Stratified);
    desc.filter = PixelFilter::Tent { radius: 1.5 };
    desc.hints.integrator = Some(IntegratorHint::Direct {
        emitter_samples: 2,
        bsdf_samples: 3,
    });
    desc.hints.max_depth = None;
    desc.hints.rr_depth = None;
    round_trip("everything-2", &desc);
}

/// An edit of a scene.
type Change = Box<dyn Fn(&mut SceneDesc)>;

#[test]
fn what_mitsuba_cannot_express_is_an_error_naming_it() {
    let cases: Vec<(&str, Change)> = vec![
        (
            "material 0: a textured diffuse",
            Box::new(|d| {
                d.materials[0] = MaterialDesc::TexturedDiffuse {
                    texture: TextureDesc::Checkerboard {
                        color0: Vec3::ZERO,
                        color1: Vec3::ONE,
                        to_uv: glam::Affine2::IDENTITY,
                    },
                    scale: Vec3::ONE,
                    two_sided: false,
                }
            }),
        ),
        (
            "both sides",
            Box::new(|d| {
                if let Some(e) = &mut d.spheres[0].emission {
                    e.two_sided = true;
                }
            }),
        ),
        (
            "environment map",
            Box::new(|d| {
                d.environment_map = Some(EnvironmentMapDesc {
                    source: "sky.exr".into(),
                    width: 2,
                    height: 3,
                    texels: std::sync::Arc::new(vec![Vec3::ONE; 6]),
                    to_world: glam::Mat3::IDENTITY,
                    scale: 1.0,
                })
            }),
        ),
        (
            "rays do not see",
            Box::new(|d| d.meshes[0].visibility.camera = false),
        ),
        (
            "inverse square",
            Box::new(|d| d.point_lights[0].attenuation = [1.0, 0.0, 0.0]),
        ),
    ];
    for (needle, change) in cases {
        let mut desc = everything();
        change(&mut desc);
        match to_mitsuba(&desc, "meshes") {
            Err(ExportError::Unsupported(what)) => {
                assert!(what.contains(needle), "{what:?} should name {needle:?}")
            }
            other => panic!(
                "{needle}: expected an error, got {:?}",
                other.map(|s| s.xml)
            ),
        }
    }
}

#[test]
fn a_mesh_shaded_by_its_faces_stays_so() {
    // Normals that are not one per vertex: the renderer shades with face normals, and so
    // does the written mesh (where Mitsuba would otherwise make smooth ones).
    let mut desc = everything();
    desc.meshes[0].normals = vec![Vec3::Y; 3];
    let scene = to_mitsuba(&desc, "meshes").expect("written");
    let first_shape = scene.xml.split("<shape").nth(1).expect("a shape");
    assert!(first_shape.contains("face_normals"), "{first_shape}");
    let dir = scratch("face-normals");
    let xml = dir.join("scene.xml");
    write_mitsuba(&desc, &xml).expect("written");
    let back = pathlab_scene::load(xml.to_str().expect("a UTF-8 path")).expect("read back");
    assert!(back.meshes[0].normals.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn approximations_are_warned_of() {
    let mut desc = everything();
    desc.filter = PixelFilter::Gaussian {
        stddev: 0.5,
        radius: 1.5,
    };
    desc.hints.integrator = Some(IntegratorHint::Bdpt);
    let scene = to_mitsuba(&desc, "meshes").expect("written");
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    assert!(scene.warnings[0].contains("bidirectional"));
    assert!(scene.warnings[1].contains("4 standard deviations"));
}
