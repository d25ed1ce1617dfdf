//! glTF 2.0 (`.gltf` with its buffers, or `.glb`), via the `gltf` crate: triangle meshes with
//! their node transforms, the first perspective camera, metallic-roughness materials mapped to
//! the closest BSDF (base colour → diffuse; metallic → conductor with that normal-incidence
//! reflectance), emissive materials as area lights, and `KHR_lights_punctual` point, spot and
//! directional lights. Without a camera or lights, the defaults of standalone meshes apply.

use crate::meshfile::{add_default_lights, framing_camera, DEFAULT_RESOLUTION};
use crate::Error;
use glam::{Mat4, Vec2, Vec3};
use gltf::khr_lights_punctual::Kind;
use pathlab_render::desc::*;
use std::path::Path;
use std::sync::Arc;

/// The JSON of a `.gltf` file, or of a `.glb` file's first chunk.
fn gltf_json(bytes: &[u8]) -> Option<&[u8]> {
    if !bytes.starts_with(b"glTF") {
        return Some(bytes);
    }
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (length, kind) = (word(12)?, word(16)?);
    (kind == 0x4E4F_534A).then(|| bytes.get(20..20 + length))?
}

/// What the `gltf` crate's import is not asked to judge, checked on the JSON first (anything
/// else is left to the crate): that every mesh primitive's `POSITION` names an existing
/// accessor, and that the files the buffers and images name can be read.
fn check_before_import(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let Some(json) = gltf_json(bytes) else {
        return Ok(());
    };
    let Ok(root) = serde_json::from_slice::<serde_json::Value>(json) else {
        return Ok(());
    };
    check_position_accessors(&root)?;
    check_referenced_files(path, &root)
}

/// That every mesh primitive's `POSITION` names an existing accessor: the `gltf` crate's
/// validation reads that accessor before checking the index (and panics on a bad one).
fn check_position_accessors(root: &serde_json::Value) -> Result<(), String> {
    let accessors = root["accessors"].as_array().map_or(0, Vec::len);
    for (m, mesh) in root["meshes"].as_array().into_iter().flatten().enumerate() {
        for (p, prim) in mesh["primitives"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            if let Some(i) = prim["attributes"]["POSITION"].as_u64() {
                if i as usize >= accessors {
                    return Err(format!(
                        "not a valid glTF file: meshes[{m}].primitives[{p}] takes its positions from accessor {i}, but there are {accessors} accessors"
                    ));
                }
            }
        }
    }
    Ok(())
}

/// That the files the buffers and images name (relative URIs, beside the glTF file; not
/// `data:` URIs) can be read: the crate's import reports a missing one as an I/O error
/// without its name.
fn check_referenced_files(path: &Path, root: &serde_json::Value) -> Result<(), String> {
    let dir = path.parent().unwrap_or(Path::new(""));
    for kind in ["buffers", "images"] {
        for (i, item) in root[kind].as_array().into_iter().flatten().enumerate() {
            let Some(uri) = item["uri"].as_str() else {
                continue;
            };
            if uri.starts_with("data:") {
                continue;
            }
            // Decoded as the crate's import decodes it (which panics where this errs).
            let Ok(name) = urlencoding::decode(uri) else {
                return Err(format!(
                    "{kind}[{i}] names '{uri}', whose escapes decode to no UTF-8 text"
                ));
            };
            let file = dir.join(&*name);
            if let Err(e) = std::fs::metadata(&file) {
                return Err(format!(
                    "{kind}[{i}] names '{uri}', which cannot be read ({}: {e})",
                    file.display()
                ));
            }
        }
    }
    Ok(())
}

/// Loads a glTF 2.0 file.
pub fn load(path: &Path) -> Result<SceneDesc, Error> {
    let err = |message: String| parse_error(path, message);
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    check_before_import(path, &bytes).map_err(err)?;
    let (doc, buffers, images) = gltf::import(path).map_err(|e| match e {
        gltf::Error::Io(io) => Error::io(path, io),
        other => err(format!("not a valid glTF file: {other}")),
    })?;
    let mut desc = SceneDesc {
        resolution: DEFAULT_RESOLUTION,
        ..Default::default()
    };
    let mut camera = None;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| err("the file has no scene".into()))?;
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut visited = 0usize;
    let file = File {
        path,
        buffers: &buffers,
        images: &images,
    };
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1_000_000 {
            return Err(err("node hierarchy is too large or cyclic".into()));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(err(format!(
                "node {} has a non-finite transform",
                node.index()
            )));
        }
        if let Some(mesh) = node.mesh() {
            for (k, prim) in mesh.primitives().enumerate() {
                file.add_primitive(&mut desc, &mesh, k, &prim, world)?;
            }
        }
        if camera.is_none() {
            camera = node.camera().and_then(|c| perspective_camera(&c, world));
        }
        if let Some(light) = node.light() {
            add_light(&mut desc, &light, world).map_err(|message| parse_error(path, message))?;
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    match camera {
        Some((c, aspect)) => {
            desc.camera = c;
            if let Some(a) = aspect.filter(|a| *a > 0.0 && a.is_finite()) {
                desc.resolution = [
                    (DEFAULT_RESOLUTION[1] as f32 * a).round().max(1.0) as u32,
                    DEFAULT_RESOLUTION[1],
                ];
            }
        }
        None => desc.camera = framing_camera(path, &desc)?,
    }
    let lit = !desc.point_lights.is_empty()
        || !desc.spot_lights.is_empty()
        || !desc.directional_lights.is_empty()
        || desc.meshes.iter().any(|m| m.emission.is_some());
    if !lit {
        add_default_lights(&mut desc);
        desc.warnings
            .push("the scene has no lights: lit by a default sky and key light".into());
    }
    Ok(desc)
}

/// An error in the glTF file at `path` (which has no lines to point at).
fn parse_error(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.display().to_string(),
        line: 0,
        column: 0,
        message,
    }
}

/// What a glTF file's meshes read from: its path (for messages), buffers and images.
struct File<'a> {
    path: &'a Path,
    buffers: &'a [gltf::buffer::Data],
    images: &'a [gltf::image::Data],
}

impl File<'_> {
    /// Adds primitive `k` of `mesh`, placed by `world`, as a mesh and its material (a warning
    /// for primitives other than triangles, which are skipped).
    fn add_primitive(
        &self,
        desc: &mut SceneDesc,
        mesh: &gltf::Mesh,
        k: usize,
        prim: &gltf::Primitive,
        world: Mat4,
    ) -> Result<(), Error> {
        let err = |message: String| parse_error(self.path, message);
        if prim.mode() != gltf::mesh::Mode::Triangles {
            desc.warnings.push(format!(
                "mesh {}: primitive {k} is not triangles; skipped",
                mesh.index()
            ));
            return Ok(());
        }
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| {
                err(format!(
                    "mesh {}: primitive {k} has no positions",
                    mesh.index()
                ))
            })?
            .map(|p| world.transform_point3(Vec3::from_array(p)))
            .collect();
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(err(format!(
                "mesh {}: a position is not finite: {p}",
                mesh.index()
            )));
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(err(format!(
                "mesh {}: index {bad} out of range ({} vertices)",
                mesh.index(),
                positions.len()
            )));
        }
        let normal_matrix = world.inverse().transpose();
        let normals = reader
            .read_normals()
            .map(|n| {
                n.map(|n| {
                    normal_matrix
                        .transform_vector3(Vec3::from_array(n))
                        .normalize_or_zero()
                })
                .collect()
            })
            .unwrap_or_default();
        let uvs = reader
            .read_tex_coords(0)
            // glTF's v grows downwards; pathlab's upwards.
            .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect())
            .unwrap_or_default();
        let m = prim.material();
        let material = self.material(&m, &mut desc.warnings);
        let emission = Vec3::from_array(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        desc.materials.push(material);
        desc.meshes.push(MeshDesc {
            name: mesh.name().unwrap_or("mesh").to_string(),
            positions,
            indices,
            material: desc.materials.len() - 1,
            emission: (emission.max_element() > 0.0).then_some(Emission {
                radiance: emission,
                two_sided: false,
            }),
            normals,
            uvs,
            visibility: Visibility::ALL,
            ..Default::default()
        });
        Ok(())
    }

    /// The closest BSDF to a metallic-roughness material: a conductor whose normal-incidence
    /// reflectance is the base colour where it is metallic, else diffuse (textured by its
    /// base-colour image where it has one).
    fn material(&self, m: &gltf::Material, warnings: &mut Vec<String>) -> MaterialDesc {
        let pbr = m.pbr_metallic_roughness();
        let base = Vec3::from_slice(&pbr.base_color_factor()[..3]);
        let texture = pbr.base_color_texture().and_then(|info| {
            let index = info.texture().source().index();
            let texture = self.images.get(index).and_then(|img| {
                base_color_texture(img, format!("{} image {index}", self.path.display()))
            });
            if texture.is_none() {
                warnings.push(format!(
                    "material {}: base-colour image {index} has an unsupported pixel format; using the base colour factor",
                    m.index().map_or("default".into(), |i| i.to_string())
                ));
            }
            texture
        });
        if pbr.metallic_factor() > 0.5 {
            let s = base.clamp(Vec3::ZERO, Vec3::splat(0.999)).map(f32::sqrt);
            MaterialDesc::Conductor {
                alpha: pbr.roughness_factor() * pbr.roughness_factor(),
                eta: (Vec3::ONE + s) / (Vec3::ONE - s),
                k: Vec3::ZERO,
                distribution: NormalDistribution::Ggx,
            }
        } else if let Some(texture) = texture {
            MaterialDesc::TexturedDiffuse {
                texture: TextureDesc::image(texture),
                scale: base.clamp(Vec3::ZERO, Vec3::ONE),
                two_sided: m.double_sided(),
            }
        } else {
            MaterialDesc::Diffuse {
                reflectance: base.clamp(Vec3::ZERO, Vec3::ONE),
                two_sided: m.double_sided(),
            }
        }
    }
}

/// A perspective camera placed by `world`, and its aspect ratio if the file gives one.
fn perspective_camera(cam: &gltf::Camera, world: Mat4) -> Option<(CameraDesc, Option<f32>)> {
    let gltf::camera::Projection::Perspective(p) = cam.projection() else {
        return None;
    };
    let origin = world.transform_point3(Vec3::ZERO);
    let forward = world
        .transform_vector3(Vec3::NEG_Z)
        .normalize_or(Vec3::NEG_Z);
    Some((
        CameraDesc {
            origin,
            target: origin + forward,
            up: world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y),
            fov_degrees: p.yfov().to_degrees(),
            fov_axis: FovAxis::Y,
            lens_radius: 0.0,
            focal_distance: 1.0,
            focal_pixels: None,
            ..Default::default()
        },
        p.aspect_ratio(),
    ))
}

/// Adds a `KHR_lights_punctual` light placed by `world`; what is wrong with it otherwise.
fn add_light(
    desc: &mut SceneDesc,
    light: &gltf::khr_lights_punctual::Light,
    world: Mat4,
) -> Result<(), String> {
    let color = Vec3::from_array(light.color()) * light.intensity();
    if !crate::spectrum::is_emission(color) {
        return Err(format!(
            "light {} ('{}'): color times intensity must be >= 0 in every channel, got {color}",
            light.index(),
            light.name().unwrap_or("")
        ));
    }
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world
        .transform_vector3(Vec3::NEG_Z)
        .normalize_or(Vec3::NEG_Z);
    match light.kind() {
        Kind::Point => desc.point_lights.push(PointLightDesc {
            position,
            intensity: color,
            attenuation: INVERSE_SQUARE,
        }),
        Kind::Directional => desc.directional_lights.push(DirectionalLightDesc {
            direction,
            irradiance: color,
        }),
        Kind::Spot {
            outer_cone_angle, ..
        } => desc.spot_lights.push(SpotLightDesc {
            position,
            direction,
            intensity: color,
            cutoff_degrees: outer_cone_angle.to_degrees(),
            exponent: 0.0,
            attenuation: INVERSE_SQUARE,
        }),
    }
    Ok(())
}

/// A glTF base-colour image as a linear texture (8-bit channels are sRGB-encoded).
fn base_color_texture(img: &gltf::image::Data, source: String) -> Option<Arc<Texture>> {
    use gltf::image::Format;
    let channels = match img.format {
        Format::R8 => 1,
        Format::R8G8 => 2,
        Format::R8G8B8 => 3,
        Format::R8G8B8A8 => 4,
        _ => return None,
    };
    let decode = pathlab_render::image_io::srgb_decode;
    let texels = img
        .pixels
        .chunks_exact(channels)
        .map(|p| {
            let c = |i: usize| decode(p[i.min(channels - 1)] as f32 / 255.0);
            if channels < 3 {
                Vec3::splat(c(0))
            } else {
                Vec3::new(c(0), c(1), c(2))
            }
        })
        .collect();
    Texture::new(source, img.width as usize, img.height as usize, texels).map(Arc::new)
}
