//! Standalone meshes: Wavefront OBJ (with MTL materials, via `tobj`) and PLY (ASCII and binary,
//! via `ply-rs-bw`). They carry no camera or lights, so the scene gets a default camera that
//! frames the mesh's bounding box from the front and a default light (a uniform sky plus a key
//! light from the upper left) unless the mesh emits light itself.

use crate::Error;
use glam::{Vec2, Vec3};
use pathlab_render::desc::*;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::path::Path;

/// Default image size of standalone meshes.
pub const DEFAULT_RESOLUTION: [u32; 2] = [640, 480];

/// The materials of an OBJ file's MTL files, or why they could not be read.
type MtlResult = Result<Vec<tobj::Material>, tobj::LoadError>;

/// An OBJ file's models, triangulated with one index per vertex, and its materials.
fn read_obj(path: &Path) -> Result<(Vec<tobj::Model>, MtlResult), Error> {
    tobj::load_obj(
        path,
        &tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        },
    )
    .map_err(|e| obj_error(path, e))
}

/// The MTL files an OBJ file's `mtllib` lines name that do not exist beside it (for the
/// warning when its materials cannot be read: `tobj`'s error does not name the file).
fn missing_mtl_files(path: &Path) -> Vec<String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("mtllib"))
        .filter(|rest| rest.starts_with([' ', '\t']))
        .flat_map(str::split_whitespace)
        .filter(|name| !dir.join(name).exists())
        .map(str::to_string)
        .collect()
}

/// Loads a Wavefront OBJ file and the MTL files it names.
pub fn load_obj(path: &Path) -> Result<SceneDesc, Error> {
    let (models, materials) = read_obj(path)?;
    let mut desc = SceneDesc::default();
    let mtl = match materials {
        Ok(m) => m,
        Err(e) => {
            let missing = missing_mtl_files(path);
            let why = if missing.is_empty() {
                e.to_string()
            } else {
                format!("{} not found beside the OBJ file ({e})", missing.join(", "))
            };
            desc.warnings
                .push(format!("materials: {why}; using grey diffuse"));
            Vec::new()
        }
    };
    // One material per MTL entry, plus a grey default at the end.
    let mut emissions = Vec::new();
    for m in &mtl {
        let kd = m.diffuse.map_or(Vec3::splat(0.8), Vec3::from_array);
        let texture = m.diffuse_texture.as_ref().and_then(|name| {
            let file = path.parent().unwrap_or(Path::new(".")).join(name);
            crate::texture::load(&file, false)
                .map_err(|e| {
                    desc.warnings.push(format!(
                        "material '{}': map_Kd {e}; using Kd instead",
                        m.name
                    ))
                })
                .ok()
        });
        desc.materials.push(match texture {
            // The map replaces Kd, as most OBJ readers do.
            Some(texture) => MaterialDesc::TexturedDiffuse {
                texture: TextureDesc::image(texture),
                scale: Vec3::ONE,
                two_sided: true,
            },
            None => MaterialDesc::Diffuse {
                reflectance: kd.clamp(Vec3::ZERO, Vec3::ONE),
                two_sided: true,
            },
        });
        let ke = m.emissive.map(Vec3::from_array);
        if let Some(ke) = ke.filter(|&e| !crate::spectrum::is_emission(e)) {
            return Err(Error::Parse {
                path: path.display().to_string(),
                line: 0,
                column: 0,
                message: format!(
                    "material '{}' (in the MTL file): Ke is an emission and must be >= 0 in every channel, got {ke}",
                    m.name
                ),
            });
        }
        let ke = ke.filter(|e| e.max_element() > 0.0);
        emissions.push(ke);
        if m.shininess.is_some_and(|ns| ns > 100.0) {
            desc.warnings.push(format!(
                "material '{}': Ns {} asks for a glossy surface; rendered as diffuse",
                m.name,
                m.shininess.unwrap_or(0.0)
            ));
        }
    }
    let default = desc.materials.len();
    desc.materials.push(MaterialDesc::Diffuse {
        reflectance: Vec3::splat(0.8),
        two_sided: true,
    });
    for model in models {
        let material = model
            .mesh
            .material_id
            .filter(|&i| i < mtl.len())
            .unwrap_or(default);
        let emission = emissions
            .get(material)
            .copied()
            .flatten()
            .map(|radiance| Emission {
                radiance,
                two_sided: false,
            });
        let mut mesh = model_mesh(path, model)?;
        mesh.material = material;
        mesh.emission = emission;
        desc.meshes.push(mesh);
    }
    standalone(path, desc)
}

/// The geometry of one OBJ model: positions, indices, and normals and texture coordinates
/// where every vertex has them.
fn model_mesh(path: &Path, model: tobj::Model) -> Result<MeshDesc, Error> {
    let m = &model.mesh;
    let positions = vec3s(path, &m.positions, "vertex")?;
    check_indices(path, &model.name, &m.indices, positions.len())?;
    let normals = if m.normals.len() == m.positions.len() {
        vec3s(path, &m.normals, "normal")?
    } else {
        Vec::new()
    };
    let uvs = if m.texcoords.len() / 2 == positions.len() {
        m.texcoords.chunks_exact(2).map(Vec2::from_slice).collect()
    } else {
        Vec::new()
    };
    Ok(MeshDesc {
        name: model.name,
        positions,
        indices: model.mesh.indices,
        normals,
        uvs,
        ..Default::default()
    })
}

/// The meshes of an OBJ file, without its materials (for scene formats that bring their own).
pub fn obj_meshes(path: &Path) -> Result<Vec<MeshDesc>, Error> {
    let (models, _) = read_obj(path)?;
    models.into_iter().map(|m| model_mesh(path, m)).collect()
}

fn obj_error(path: &Path, e: tobj::LoadError) -> Error {
    match e {
        tobj::LoadError::OpenFileFailed | tobj::LoadError::ReadError => Error::Io {
            path: path.display().to_string(),
            message: format!("cannot read the file ({e})"),
        },
        other => Error::Parse {
            path: path.display().to_string(),
            line: obj_bad_line(path).unwrap_or(0),
            column: 0,
            message: format!("not a valid OBJ file: {other}"),
        },
    }
}

/// The first line of an OBJ file that the reader refuses (tobj names the fault but not the
/// line): a vertex, normal or texture coordinate that is not numbers, or a face whose index
/// refers to an element that does not exist (1-based, or negative from the end).
fn obj_bad_line(path: &Path) -> Option<usize> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut counts = [0i64; 3]; // v, vt, vn
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let kind = words.next();
        let slot = match kind {
            Some("v") => Some(0),
            Some("vt") => Some(1),
            Some("vn") => Some(2),
            _ => None,
        };
        if let Some(k) = slot {
            let numbers: Vec<&str> = words.collect();
            let needed = if k == 1 { 1 } else { 3 };
            if numbers.len() < needed || numbers.iter().any(|w| w.parse::<f32>().is_err()) {
                return Some(i + 1);
            }
            counts[k] += 1;
        } else if kind == Some("f") {
            for corner in words {
                for (k, index) in corner.split('/').enumerate().take(3) {
                    if index.is_empty() {
                        continue;
                    }
                    let slot = [0, 1, 2][k];
                    let ok = match index.parse::<i64>() {
                        Ok(n) if n > 0 => n <= counts[slot],
                        Ok(n) if n < 0 => -n <= counts[slot],
                        _ => false,
                    };
                    if !ok {
                        return Some(i + 1);
                    }
                }
            }
        }
    }
    None
}

fn vec3s(path: &Path, values: &[f32], what: &str) -> Result<Vec<Vec3>, Error> {
    values
        .chunks_exact(3)
        .enumerate()
        .map(|(i, c)| {
            let v = Vec3::from_slice(c);
            if v.is_finite() {
                Ok(v)
            } else {
                Err(Error::Parse {
                    path: path.display().to_string(),
                    line: 0,
                    column: 0,
                    message: format!(
                        "{what} {i} has a coordinate that is not a finite number: {v}"
                    ),
                })
            }
        })
        .collect()
}

fn check_indices(path: &Path, mesh: &str, indices: &[u32], vertices: usize) -> Result<(), Error> {
    match indices.iter().find(|&&i| i as usize >= vertices) {
        Some(i) => Err(Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: format!("mesh '{mesh}': vertex index {i} out of range ({vertices} vertices)"),
        }),
        None => Ok(()),
    }
}

/// Loads a PLY file (ASCII, binary little or big endian): vertex positions (and normals and
/// texture coordinates when present) and faces (polygons are fanned into triangles).
pub fn load_ply(path: &Path) -> Result<SceneDesc, Error> {
    let mut mesh = ply_mesh(path)?;
    mesh.attributes.clear();
    let desc = SceneDesc {
        meshes: vec![mesh],
        materials: vec![MaterialDesc::Diffuse {
            reflectance: Vec3::splat(0.8),
            two_sided: true,
        }],
        ..Default::default()
    };
    standalone(path, desc)
}

/// The names PLY files give texture coordinates, in order of preference.
pub(crate) const PLY_UV_NAMES: [(&str, &str); 4] = [
    ("u", "v"),
    ("s", "t"),
    ("texture_u", "texture_v"),
    ("texture_s", "texture_t"),
];

/// Vertex properties that are geometry, not attributes.
pub(crate) const PLY_GEOMETRY: &[&str] = &[
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "u",
    "v",
    "s",
    "t",
    "texture_u",
    "texture_v",
    "texture_s",
    "texture_t",
    "vertex_indices",
    "vertex_index",
];

/// Groups a PLY element's extra scalar properties into named attributes as Mitsuba does:
/// `name_0`, `name_1`, `name_2` (or `r`, `g`, `b` / `red`, `green`, `blue`, which make
/// `color`) become one attribute `prefix` + name of up to three channels; any other property
/// is an attribute of one channel.
fn ply_attributes(
    keys: &[String],
    rows: &[DefaultElement],
    prefix: &str,
    scalar: &dyn Fn(&DefaultElement, &str) -> Option<f32>,
) -> Vec<MeshAttribute> {
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for k in keys {
        if PLY_GEOMETRY.contains(&k.as_str()) {
            continue;
        }
        let base = match k.as_str() {
            "r" | "g" | "b" | "red" | "green" | "blue" => "color".to_string(),
            _ => match k.rsplit_once('_') {
                Some((b, d))
                    if !b.is_empty() && d.len() == 1 && d.as_bytes()[0].is_ascii_digit() =>
                {
                    b.to_string()
                }
                _ => k.clone(),
            },
        };
        match groups.iter_mut().find(|g| g.0 == base) {
            Some(g) => g.1.push(k.clone()),
            None => groups.push((base, vec![k.clone()])),
        }
    }
    let scale = |k: &str| {
        if matches!(k, "r" | "g" | "b" | "red" | "green" | "blue") {
            1.0 / 255.0
        } else {
            1.0
        }
    };
    groups
        .into_iter()
        .filter(|(_, ks)| ks.len() <= 3)
        .map(|(base, ks)| {
            let values = rows
                .iter()
                .map(|row| {
                    let c: Vec<f32> = ks
                        .iter()
                        .map(|k| scalar(row, k).unwrap_or(0.0) * scale(k))
                        .collect();
                    match c.as_slice() {
                        [a] => Vec3::splat(*a),
                        [a, b] => Vec3::new(*a, *b, 0.0),
                        [a, b, cc] => Vec3::new(*a, *b, *cc),
                        _ => Vec3::ZERO,
                    }
                })
                .collect();
            MeshAttribute {
                name: format!("{prefix}{base}"),
                per_face: prefix == "face_",
                values,
            }
        })
        .collect()
}

/// A PLY reader's error as one plain sentence: its "Line N:" as the location, and of its
/// nested restatements ("... String: 'x' Error: ...") only what it could not read.
fn ply_error(path: &Path, text: &str) -> Error {
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let (line, rest) = match text.strip_prefix("Line ").and_then(|r| r.split_once(':')) {
        Some((n, rest)) if n.parse::<usize>().is_ok() => (n.parse().unwrap_or(0), rest.trim()),
        _ => (0, text.as_str()),
    };
    let message = match rest.split_once(" String: ") {
        Some((what, found)) => {
            let found = found.split(" Error:").next().unwrap_or("").trim();
            format!("{} (found {found})", what.trim_end_matches('.'))
        }
        None => rest.to_string(),
    };
    Error::Parse {
        path: path.display().to_string(),
        line,
        column: 0,
        message: format!("not a valid PLY file: {message}"),
    }
}

/// The mesh of a PLY file: positions, normals and texture coordinates where present, faces
/// fanned into triangles, and the extra vertex and face properties as named attributes
/// (`vertex_color`, `face_weight`, ...; a polygon's face attribute goes to each of its
/// triangles).
pub fn ply_mesh(path: &Path) -> Result<MeshDesc, Error> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    ply_mesh_from(&mut std::io::BufReader::new(file), path)
}

/// [`ply_mesh`] from a reader of the file's bytes (`path` names it in messages).
pub fn ply_mesh_from(reader: &mut impl std::io::BufRead, path: &Path) -> Result<MeshDesc, Error> {
    let mut bytes = Vec::new();
    reader
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("ply")
        .to_string();
    match crate::ply_binary::read(&bytes) {
        Some(Ok(m)) => {
            return Ok(MeshDesc {
                name,
                positions: m.positions,
                indices: m.indices,
                normals: m.normals,
                uvs: m.uvs,
                ..Default::default()
            })
        }
        Some(Err(message)) => return Err(ply_error(path, &message)),
        None => {}
    }
    let reader = &mut std::io::Cursor::new(bytes);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(reader)
        .map_err(|e| ply_error(path, &e.to_string()))?;
    let err = |message: String| Error::Parse {
        path: path.display().to_string(),
        line: 0,
        column: 0,
        message,
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| err("no 'vertex' element".into()))?;
    let PlyVertices {
        positions,
        normals,
        uvs,
    } = ply_vertices(vertices).map_err(err)?;
    let keys = |element: &str| -> Vec<String> {
        ply.header
            .elements
            .get(element)
            .map(|e| e.properties.keys().cloned().collect())
            .unwrap_or_default()
    };
    let mut attributes = ply_attributes(&keys("vertex"), vertices, "vertex_", &ply_scalar);
    let mut indices = Vec::new();
    if let Some(faces) = ply.payload.get("face") {
        let face_attributes = ply_attributes(&keys("face"), faces, "face_", &ply_scalar);
        let face_attributes =
            ply_faces(faces, positions.len(), face_attributes, &mut indices).map_err(err)?;
        attributes.extend(face_attributes);
    }
    Ok(MeshDesc {
        name,
        positions,
        indices,
        normals,
        uvs,
        attributes,
        ..Default::default()
    })
}

/// A numeric property of a PLY element as `f32`.
fn ply_scalar(e: &DefaultElement, key: &str) -> Option<f32> {
    match e.get(key)? {
        Property::Float(v) => Some(*v),
        Property::Double(v) => Some(*v as f32),
        Property::Char(v) => Some(*v as f32),
        Property::UChar(v) => Some(*v as f32),
        Property::Short(v) => Some(*v as f32),
        Property::UShort(v) => Some(*v as f32),
        Property::Int(v) => Some(*v as f32),
        Property::UInt(v) => Some(*v as f32),
        _ => None,
    }
}

/// A PLY file's vertex data.
struct PlyVertices {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
}

/// The positions of a PLY file's vertices, and their normals and texture coordinates where
/// every vertex has them (else empty).
fn ply_vertices(vertices: &[DefaultElement]) -> Result<PlyVertices, String> {
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let scalar = ply_scalar;
    for (i, v) in vertices.iter().enumerate() {
        let p = match (scalar(v, "x"), scalar(v, "y"), scalar(v, "z")) {
            (Some(x), Some(y), Some(z)) => Vec3::new(x, y, z),
            _ => return Err(format!("vertex {i} lacks a numeric x, y or z")),
        };
        if !p.is_finite() {
            return Err(format!(
                "vertex {i} has a coordinate that is not a finite number: {p}"
            ));
        }
        positions.push(p);
        if let (Some(x), Some(y), Some(z)) = (scalar(v, "nx"), scalar(v, "ny"), scalar(v, "nz")) {
            normals.push(Vec3::new(x, y, z));
        }
        let uv = PLY_UV_NAMES
            .iter()
            .find_map(|(a, b)| Some(Vec2::new(scalar(v, a)?, scalar(v, b)?)));
        if let Some(uv) = uv {
            uvs.push(uv);
        }
    }
    if normals.len() != positions.len() {
        normals.clear();
    }
    if uvs.len() != positions.len() {
        uvs.clear();
    }
    Ok(PlyVertices {
        positions,
        normals,
        uvs,
    })
}

/// Fans a PLY file's faces (polygons over `vertex_count` vertices) into triangles, appended to
/// `indices`; returns the face attributes with one value per triangle.
fn ply_faces(
    faces: &[DefaultElement],
    vertex_count: usize,
    mut face_attributes: Vec<MeshAttribute>,
    indices: &mut Vec<u32>,
) -> Result<Vec<MeshAttribute>, String> {
    let mut triangle_values: Vec<Vec<Vec3>> = vec![Vec::new(); face_attributes.len()];
    for (f, face) in faces.iter().enumerate() {
        let list: Vec<i64> = match face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
        {
            Some(Property::ListInt(v)) => v.iter().map(|&x| x as i64).collect(),
            Some(Property::ListUInt(v)) => v.iter().map(|&x| x as i64).collect(),
            Some(Property::ListShort(v)) => v.iter().map(|&x| x as i64).collect(),
            Some(Property::ListUShort(v)) => v.iter().map(|&x| x as i64).collect(),
            Some(Property::ListChar(v)) => v.iter().map(|&x| x as i64).collect(),
            Some(Property::ListUChar(v)) => v.iter().map(|&x| x as i64).collect(),
            _ => return Err(format!("face {f} has no integer vertex_indices list")),
        };
        if let Some(&bad) = list.iter().find(|&&i| i < 0 || i as usize >= vertex_count) {
            return Err(format!(
                "face {f}: vertex index {bad} out of range ({vertex_count} vertices)"
            ));
        }
        for k in 1..list.len().saturating_sub(1) {
            indices.extend([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
            for (a, values) in face_attributes.iter().zip(&mut triangle_values) {
                values.push(a.values[f]);
            }
        }
    }
    for (a, values) in face_attributes.iter_mut().zip(triangle_values) {
        a.values = values;
    }
    Ok(face_attributes)
}

/// Adds the default camera, resolution and (when nothing emits) lights of a standalone mesh.
fn standalone(path: &Path, mut desc: SceneDesc) -> Result<SceneDesc, Error> {
    desc.camera = framing_camera(path, &desc)?;
    desc.resolution = DEFAULT_RESOLUTION;
    if !desc.meshes.iter().any(|m| m.emission.is_some()) {
        add_default_lights(&mut desc);
    }
    Ok(desc)
}

/// A uniform sky and a key light from the upper left, for scenes that bring no light.
pub(crate) fn add_default_lights(desc: &mut SceneDesc) {
    desc.environment = Some(Vec3::splat(0.5));
    desc.directional_lights.push(DirectionalLightDesc {
        direction: Vec3::new(0.5, -1.0, -0.6).normalize(),
        irradiance: Vec3::splat(2.0),
    });
}

/// A camera that frames the bounding box of all shapes from the front, slightly above and to
/// the right, with a 40° vertical field of view.
pub(crate) fn framing_camera(path: &Path, desc: &SceneDesc) -> Result<CameraDesc, Error> {
    let Some((lo, hi)) = desc.bounds() else {
        return Err(Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: "the file holds no geometry".into(),
        });
    };
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let fov: f32 = 40.0;
    // Far enough that the bounding sphere fits the vertical field of view, with a margin.
    let distance = 1.1 * radius / (0.5 * fov).to_radians().sin();
    let dir = Vec3::new(0.35, 0.3, 1.0).normalize();
    Ok(CameraDesc {
        origin: center + dir * distance,
        target: center,
        up: Vec3::Y,
        fov_degrees: fov,
        fov_axis: FovAxis::Y,
        lens_radius: 0.0,
        focal_distance: distance,
        ..Default::default()
    })
}
