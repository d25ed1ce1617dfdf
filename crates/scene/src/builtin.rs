//! Scenes compiled into the binary.

use crate::Error;
use glam::Vec3;
use pathlab_render::desc::{CameraDesc, Emission, FovAxis, MaterialDesc, MeshDesc, SceneDesc};

/// Names of the built-in scenes.
pub const NAMES: [&str; 1] = ["cornell-box"];

/// The built-in scene called `name`.
pub fn load(name: &str) -> Result<SceneDesc, Error> {
    match name {
        "cornell-box" => cornell_box(),
        _ => Err(Error::UnknownBuiltin {
            name: name.to_string(),
            known: NAMES.join(", "),
        }),
    }
}

const CORNELL_OBJ: &str = include_str!("../data/cornell-box.obj");

/// Mitsuba 3's `cornell_box()`: 36 triangles in three diffuse colours, a one-sided rectangular
/// area light of radiance (18.387, 13.9873, 6.75357) facing down, a pinhole camera at
/// (0, 0, 3.9) looking at the origin with +y up and a 39.3077° field of view on the smaller
/// image axis, 256 x 256 pixels. Surfaces are one-sided, as Mitsuba's `diffuse`.
pub fn cornell_box() -> Result<SceneDesc, Error> {
    let white = Vec3::new(0.885809, 0.698859, 0.666422);
    let green = Vec3::new(0.105421, 0.37798, 0.076425);
    let red = Vec3::new(0.570068, 0.0430135, 0.0443706);
    let materials = [white, green, red]
        .into_iter()
        .map(|reflectance| MaterialDesc::Diffuse {
            reflectance,
            two_sided: false,
        })
        .collect();
    let (models, _) = tobj::load_obj_buf(
        &mut CORNELL_OBJ.as_bytes(),
        &tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        },
        |_| Ok(Default::default()),
    )
    .map_err(|e| Error::Parse {
        path: "built-in cornell-box.obj".into(),
        line: 0,
        column: 0,
        message: e.to_string(),
    })?;
    let meshes = models
        .into_iter()
        .map(|m| {
            let positions = m
                .mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect();
            let (material, emission) = match m.name.as_str() {
                "green-wall" => (1, None),
                "red-wall" => (2, None),
                "light" => (
                    0,
                    Some(Emission {
                        radiance: Vec3::new(18.387, 13.9873, 6.75357),
                        two_sided: false,
                    }),
                ),
                _ => (0, None),
            };
            MeshDesc {
                name: m.name,
                positions,
                indices: m.mesh.indices,
                material,
                emission,
                ..Default::default()
            }
        })
        .collect();
    Ok(SceneDesc {
        meshes,
        materials,
        camera: CameraDesc {
            origin: Vec3::new(0.0, 0.0, 3.9),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 39.3077,
            fov_axis: FovAxis::Smaller,
            lens_radius: 0.0,
            focal_distance: 3.9,
            focal_pixels: None,
            ..Default::default()
        },
        resolution: [256, 256],
        ..Default::default()
    })
}
