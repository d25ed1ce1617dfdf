//! The CS184 course's COLLADA 1.4.1 scenes (`.dae`), read the way the course's renderer reads
//! them (see `CS184-CONVENTIONS` in the project's documentation):
//!
//! - `<up_axis>` Z_UP maps (x, y, z) to (-x, z, y) (X_UP swaps x and y and negates z); node
//!   transforms (`<matrix>` row-major, `<translate>`, `<rotate>`, `<scale>`) compose parent
//!   first;
//! - meshes from `<polylist>`, `<triangles>` and `<polygons>` with any input offsets, positions,
//!   normals and texture coordinates; spheres from `<extra><technique profile="CGL"><sphere>`;
//! - materials: the `phong`/`lambert`/`blinn` diffuse colour, and the CGL `emission`, `mirror`,
//!   `glass`/`refraction` and `microfacet` extras;
//! - lights: the CGL technique wins over `technique_common` (area, point, directional, spot,
//!   ambient). When a file has CGL lights, camera rays see its emissive meshes and every other
//!   ray sees the CGL area lights instead, as the course's renderer does;
//! - the camera is placed as the course's viewer does: on a sphere of radius 1.5 × the scene's
//!   bounding-box diagonal around the box centre, in the direction of the camera node's
//!   transform of (0, 0, -1), looking at the centre, with the image-plane distance fixed for an
//!   800 x 600 image (other resolutions show more or less at the same scale).

use crate::xml::{child, children, parse_document, path as xpath, read_text, XmlFile};
use crate::Error;
use glam::{Mat4, Vec2, Vec3};
use pathlab_render::desc::*;
use roxmltree::Node;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Default image size of the course's renderer.
pub const DEFAULT_RESOLUTION: [u32; 2] = [800, 600];

/// Loads a `.dae` file.
pub fn load(path: &Path) -> Result<SceneDesc, Error> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Parses COLLADA text; `path` names it in errors and locates textures.
pub fn parse(text: &str, path: &Path) -> Result<SceneDesc, Error> {
    let doc = parse_document(text, path)?;
    let file = XmlFile { path, doc: &doc };
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err(file.error(root, "expected a <COLLADA> document"));
    }
    let mut loader = Loader {
        file: &file,
        ids: HashMap::new(),
        desc: SceneDesc {
            resolution: DEFAULT_RESOLUTION,
            ..Default::default()
        },
        material_index: HashMap::new(),
        emissive_meshes: Vec::new(),
        cgl_area_lights: Vec::new(),
        has_cgl_lights: false,
        camera: None,
        bounds: (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
    };
    for n in root.descendants().filter(|n| n.is_element()) {
        if let Some(id) = n.attribute("id") {
            loader.ids.insert(id, n);
        }
    }
    let up = xpath(root, &["asset", "up_axis"])
        .and_then(|n| n.text())
        .map(str::trim)
        .unwrap_or("Y_UP");
    let entry = match up {
        "Z_UP" => Mat4::from_cols_array(&[
            -1., 0., 0., 0., 0., 0., 1., 0., 0., 1., 0., 0., 0., 0., 0., 1.,
        ]),
        "X_UP" => Mat4::from_cols_array(&[
            0., 1., 0., 0., 1., 0., 0., 0., 0., 0., -1., 0., 0., 0., 0., 1.,
        ]),
        _ => Mat4::IDENTITY,
    };
    let scene = loader.visual_scene(root)?;
    for node in children(scene, "node") {
        loader.node(node, entry)?;
    }
    loader.finish()
}

/// A CGL area light: a parallelogram emitting `radiance` towards `direction`.
struct AreaLight {
    center: Vec3,
    dim_x: Vec3,
    dim_y: Vec3,
    direction: Vec3,
    radiance: Vec3,
}

struct Loader<'f, 'a, 'input> {
    file: &'f XmlFile<'a, 'input>,
    ids: HashMap<&'a str, Node<'a, 'input>>,
    desc: SceneDesc,
    material_index: HashMap<String, usize>,
    /// Indices into `desc.meshes` of meshes with a CGL emission material.
    emissive_meshes: Vec<usize>,
    cgl_area_lights: Vec<AreaLight>,
    has_cgl_lights: bool,
    /// The camera node's world transform and the camera element.
    camera: Option<(Mat4, Node<'a, 'input>)>,
    bounds: (Vec3, Vec3),
}

/// A material as the file describes it.
struct Effect {
    material: MaterialDesc,
    emission: Option<Vec3>,
}

impl<'f, 'a, 'input> Loader<'f, 'a, 'input> {
    fn lookup(&self, from: Node, url: &str) -> Result<Node<'a, 'input>, Error> {
        let id = url.strip_prefix('#').unwrap_or(url);
        self.ids.get(id).copied().ok_or_else(|| {
            self.file
                .error(from, format!("reference to undefined id '{url}'"))
        })
    }

    fn visual_scene(&self, root: Node<'a, 'input>) -> Result<Node<'a, 'input>, Error> {
        if let Some(inst) = xpath(root, &["scene", "instance_visual_scene"]) {
            let url = inst.attribute("url").unwrap_or("");
            return self.lookup(inst, url);
        }
        xpath(root, &["library_visual_scenes", "visual_scene"])
            .ok_or_else(|| self.file.error(root, "no <visual_scene> to render"))
    }

    /// A `<matrix>`'s 16 numbers, row-major. The course's reader fills the numbers a short
    /// matrix lacks with zeros; so does this, with a warning naming the element's line.
    fn matrix(&mut self, c: Node) -> Result<Mat4, Error> {
        let mut v = self.file.floats(c)?;
        if v.len() < 16 {
            let at = self.file.error(c, "");
            let line = match &at {
                Error::Parse { path, line, .. } => format!("{path}:{line}"),
                _ => String::new(),
            };
            self.desc.warnings.push(format!(
                "{line}: <matrix> has {} of its 16 numbers; the rest are taken as 0, as the course's renderer does",
                v.len()
            ));
            v.resize(16, 0.0);
        }
        Ok(Mat4::from_cols_slice(&v[..16]).transpose())
    }

    fn transform(&mut self, node: Node) -> Result<Mat4, Error> {
        let mut m = Mat4::IDENTITY;
        for c in node.children().filter(|c| c.is_element()) {
            let t = match c.tag_name().name() {
                "matrix" => self.matrix(c)?,
                "translate" => Mat4::from_translation(Vec3::from_slice(&self.file.floats_n(c, 3)?)),
                "scale" => Mat4::from_scale(Vec3::from_slice(&self.file.floats_n(c, 3)?)),
                "rotate" => {
                    let v = self.file.floats_n(c, 4)?;
                    let axis = Vec3::new(v[0], v[1], v[2]).normalize_or_zero();
                    if axis == Vec3::ZERO {
                        return Err(self.file.error(c, "rotation axis is zero"));
                    }
                    Mat4::from_axis_angle(axis, v[3].to_radians())
                }
                _ => continue,
            };
            m *= t;
        }
        if !m.is_finite() {
            return Err(self.file.error(node, "transform is not finite"));
        }
        Ok(m)
    }

    fn node(&mut self, node: Node<'a, 'input>, parent: Mat4) -> Result<(), Error> {
        let world = parent * self.transform(node)?;
        for c in node.children().filter(|c| c.is_element()) {
            match c.tag_name().name() {
                "instance_geometry" => self.instance_geometry(c, world)?,
                "instance_light" => {
                    let light = self.lookup(c, c.attribute("url").unwrap_or(""))?;
                    self.light(light, world)?;
                }
                "instance_camera" => {
                    let cam = self.lookup(c, c.attribute("url").unwrap_or(""))?;
                    if self.camera.is_none() {
                        self.camera = Some((world, cam));
                    }
                }
                "instance_node" => {
                    let n = self.lookup(c, c.attribute("url").unwrap_or(""))?;
                    self.node(n, world)?;
                }
                "node" => self.node(c, world)?,
                _ => {}
            }
        }
        Ok(())
    }

    fn grow(&mut self, p: Vec3) {
        self.bounds.0 = self.bounds.0.min(p);
        self.bounds.1 = self.bounds.1.max(p);
    }

    /// The material a primitive's symbol is bound to in an instance.
    fn bound_material(
        &mut self,
        instance: Node,
        symbol: Option<&str>,
    ) -> Result<(usize, Option<Vec3>), Error> {
        let mut target = symbol.map(|s| s.to_string());
        if let Some(tc) = xpath(instance, &["bind_material", "technique_common"]) {
            for im in children(tc, "instance_material") {
                if symbol.is_none() || im.attribute("symbol") == symbol {
                    target = im.attribute("target").map(|t| t.to_string());
                    break;
                }
            }
        }
        let Some(target) = target else {
            return Ok((self.default_material(), None));
        };
        let id = target.strip_prefix('#').unwrap_or(&target).to_string();
        let Some(&material) = self.ids.get(id.as_str()) else {
            self.desc.warnings.push(format!(
                "material '{id}' is not defined; using grey diffuse"
            ));
            return Ok((self.default_material(), None));
        };
        let effect = self.effect(material)?;
        let index = match self.material_index.get(&id) {
            Some(&i) => i,
            None => {
                self.desc.materials.push(effect.material);
                self.material_index
                    .insert(id, self.desc.materials.len() - 1);
                self.desc.materials.len() - 1
            }
        };
        Ok((index, effect.emission))
    }

    fn default_material(&mut self) -> usize {
        *self
            .material_index
            .entry("<default>".to_string())
            .or_insert_with(|| {
                self.desc.materials.push(MaterialDesc::Diffuse {
                    reflectance: Vec3::splat(0.5),
                    two_sided: true,
                });
                self.desc.materials.len() - 1
            })
    }

    fn effect(&mut self, material: Node<'a, 'input>) -> Result<Effect, Error> {
        let inst = child(material, "instance_effect")
            .ok_or_else(|| self.file.error(material, "expected an <instance_effect>"))?;
        let effect = self.lookup(inst, inst.attribute("url").unwrap_or(""))?;
        let mut diffuse = Vec3::splat(0.5);
        let mut texture = None;
        if let Some(shading) = xpath(effect, &["profile_COMMON", "technique"]).and_then(|t| {
            ["phong", "lambert", "blinn", "constant"]
                .iter()
                .find_map(|name| child(t, name))
        }) {
            if let Some(d) = child(shading, "diffuse") {
                if let Some(c) = child(d, "color") {
                    diffuse = Vec3::from_slice(&self.file.floats_n(c, 3)?);
                } else if let Some(t) = child(d, "texture") {
                    texture = self.texture(effect, t);
                    diffuse = Vec3::ONE;
                }
            }
        }
        let cgl = effect.descendants().find(|n| {
            n.is_element()
                && n.tag_name().name() == "technique"
                && n.attribute("profile") == Some("CGL")
        });
        let mut out = Effect {
            material: match texture {
                Some(texture) => MaterialDesc::TexturedDiffuse {
                    texture: TextureDesc::image(texture),
                    scale: Vec3::ONE,
                    two_sided: true,
                },
                None => MaterialDesc::Diffuse {
                    reflectance: diffuse.clamp(Vec3::ZERO, Vec3::ONE),
                    two_sided: true,
                },
            },
            emission: None,
        };
        let Some(cgl) = cgl else {
            return Ok(out);
        };
        let rgb = |n: Node, name: &str, default: Vec3| -> Result<Vec3, Error> {
            match child(n, name) {
                Some(c) => Ok(Vec3::from_slice(&self.file.floats_n(c, 3)?)),
                None => Ok(default),
            }
        };
        let scalar = |n: Node, name: &str, default: f32| -> Result<f32, Error> {
            match child(n, name) {
                Some(c) => Ok(self.file.floats_n(c, 1)?[0]),
                None => Ok(default),
            }
        };
        for m in cgl.children().filter(|c| c.is_element()) {
            match m.tag_name().name() {
                "emission" => {
                    out.emission = Some(rgb(m, "radiance", Vec3::ONE)?);
                    // An emitter reflects nothing.
                    out.material = MaterialDesc::Diffuse {
                        reflectance: Vec3::ZERO,
                        two_sided: true,
                    };
                }
                "mirror" => {
                    out.material = MaterialDesc::Mirror {
                        reflectance: rgb(m, "reflectance", Vec3::ONE)?,
                    }
                }
                "glass" | "refraction" => {
                    out.material = MaterialDesc::Glass {
                        reflectance: rgb(m, "reflectance", Vec3::ONE)?,
                        transmittance: rgb(m, "transmittance", Vec3::ONE)?,
                        roughness: scalar(m, "roughness", 0.0)?,
                        ior: scalar(m, "ior", 1.5)?,
                        distribution: NormalDistribution::Beckmann,
                        fresnel: FresnelModel::Exact,
                    }
                }
                "microfacet" => {
                    out.material = MaterialDesc::Conductor {
                        alpha: scalar(m, "alpha", 0.5)?,
                        eta: rgb(m, "eta", Vec3::ONE)?,
                        k: rgb(m, "k", Vec3::ZERO)?,
                        // The course's microfacet model.
                        distribution: NormalDistribution::Beckmann,
                    }
                }
                _ => {}
            }
        }
        Ok(out)
    }

    /// The image a `<texture texture="...">` names, loaded; `None` (with a warning) when it
    /// cannot be found or read. The name is a sampler's sid in the effect, whose surface names
    /// the `<image>`; a direct image id works too.
    fn texture(&mut self, effect: Node, texture: Node) -> Option<Arc<Texture>> {
        let name = texture.attribute("texture").unwrap_or("?");
        let param = |sid: &str| {
            effect
                .descendants()
                .find(|n| n.tag_name().name() == "newparam" && n.attribute("sid") == Some(sid))
        };
        let text_of = |n: Option<Node>, path: &[&str]| {
            n.and_then(|n| xpath(n, path))
                .and_then(|n| n.text())
                .map(|t| t.trim().to_string())
        };
        let surface = text_of(param(name), &["sampler2D", "source"]);
        let image_id = text_of(
            surface.as_deref().and_then(param),
            &["surface", "init_from"],
        )
        .unwrap_or_else(|| name.to_string());
        let image = self
            .ids
            .get(image_id.as_str())
            .copied()
            .filter(|n| n.tag_name().name() == "image");
        let Some(file) = text_of(image, &["init_from"]) else {
            self.desc.warnings.push(format!(
                "texture '{name}' names no <image>; using a white diffuse surface"
            ));
            return None;
        };
        let file = file.strip_prefix("file://").unwrap_or(&file).to_string();
        let full = self
            .file
            .path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&file);
        match crate::texture::load(&full, false) {
            Ok(t) => Some(t),
            Err(e) => {
                self.desc.warnings.push(format!(
                    "texture '{file}': {e}; using a white diffuse surface"
                ));
                None
            }
        }
    }

    fn instance_geometry(&mut self, inst: Node<'a, 'input>, world: Mat4) -> Result<(), Error> {
        let geom = self.lookup(inst, inst.attribute("url").unwrap_or(""))?;
        if let Some(sphere) = geom
            .descendants()
            .find(|n| n.is_element() && n.tag_name().name() == "sphere")
        {
            let radius = child(sphere, "radius")
                .map(|r| self.file.floats_n(r, 1))
                .transpose()?
                .map_or(1.0, |v| v[0]);
            let center = world.transform_point3(Vec3::ZERO);
            let scale = (world.transform_point3(Vec3::X) - center).length();
            let radius = radius * scale;
            if !(radius > 0.0 && radius.is_finite()) {
                return Err(self.file.error(
                    sphere,
                    format!("sphere radius must be positive, got {radius}"),
                ));
            }
            let (material, emission) = self.bound_material(inst, None)?;
            self.grow(center - Vec3::splat(radius));
            self.grow(center + Vec3::splat(radius));
            self.desc.spheres.push(SphereDesc {
                center,
                radius,
                material,
                emission: emission.map(|radiance| Emission {
                    radiance,
                    two_sided: false,
                }),
                ..Default::default()
            });
            return Ok(());
        }
        let Some(mesh) = child(geom, "mesh") else {
            self.desc.warnings.push(format!(
                "geometry '{}' has no <mesh> or CGL sphere; skipped",
                geom.attribute("id").unwrap_or("?")
            ));
            return Ok(());
        };
        let normal_matrix = world.inverse().transpose();
        for prim in mesh.children().filter(|c| c.is_element()) {
            let kind = prim.tag_name().name();
            if !matches!(kind, "polylist" | "triangles" | "polygons") {
                continue;
            }
            let (material, emission) = self.bound_material(inst, prim.attribute("material"))?;
            let tri = self.primitive(prim)?;
            let positions: Vec<Vec3> = tri
                .positions
                .iter()
                .map(|&p| world.transform_point3(p))
                .collect();
            for &p in &positions {
                self.grow(p);
            }
            let normals = tri
                .normals
                .iter()
                .map(|&n| normal_matrix.transform_vector3(n).normalize_or_zero())
                .collect();
            let name = format!("{}/{kind}", geom.attribute("id").unwrap_or("mesh"));
            if emission.is_some() {
                self.emissive_meshes.push(self.desc.meshes.len());
            }
            let count = positions.len() as u32;
            self.desc.meshes.push(MeshDesc {
                name,
                positions,
                indices: (0..count).collect(),
                material,
                emission: emission.map(|radiance| Emission {
                    radiance,
                    two_sided: false,
                }),
                normals,
                uvs: tri.uvs,
                visibility: Visibility::ALL,
                ..Default::default()
            });
        }
        Ok(())
    }

    /// Reads a `<source>`'s values (float_array via its accessor) as `stride`-tuples.
    fn source(&self, source: Node<'a, 'input>, want: usize) -> Result<Vec<f32>, Error> {
        let array = child(source, "float_array")
            .ok_or_else(|| self.file.error(source, "expected a <float_array>"))?;
        let values = self.file.floats(array)?;
        if let Some(count) = array.attribute("count") {
            let count: usize = count.parse().map_err(|_| {
                self.file
                    .error(array, format!("count '{count}' is not a number"))
            })?;
            if count != values.len() {
                return Err(self.file.error(
                    array,
                    format!("count says {count} values but {} are given", values.len()),
                ));
            }
        }
        let accessor = xpath(source, &["technique_common", "accessor"]);
        let stride = match accessor.and_then(|a| a.attribute("stride")) {
            Some(s) => s
                .parse::<usize>()
                .ok()
                .filter(|&s| s >= want)
                .ok_or_else(|| {
                    self.file.error(
                        source,
                        format!("accessor stride '{s}' must be at least {want}"),
                    )
                })?,
            None => want,
        };
        Ok(values
            .chunks_exact(stride)
            .flat_map(|c| c[..want].to_vec())
            .collect())
    }

    fn primitive(&self, prim: Node<'a, 'input>) -> Result<Triangles, Error> {
        // Inputs: semantic, source, offset.
        let mut stride = 0usize;
        let mut pos: Option<(Vec<Vec3>, usize)> = None;
        let mut nor: Option<(Vec<Vec3>, usize)> = None;
        let mut tex: Option<(Vec<Vec2>, usize)> = None;
        for input in children(prim, "input") {
            let offset: usize = input
                .attribute("offset")
                .unwrap_or("0")
                .parse()
                .map_err(|_| self.file.error(input, "offset is not a number"))?;
            if offset > 64 {
                return Err(self
                    .file
                    .error(input, format!("offset {offset} is implausibly large")));
            }
            stride = stride.max(offset + 1);
            let semantic = input.attribute("semantic").unwrap_or("");
            let src = self.lookup(input, input.attribute("source").unwrap_or(""))?;
            let vec3s = |v: Vec<f32>| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
            match semantic {
                "VERTEX" => {
                    let p = children(src, "input")
                        .find(|i| i.attribute("semantic") == Some("POSITION"))
                        .ok_or_else(|| self.file.error(src, "expected a POSITION input"))?;
                    let psrc = self.lookup(p, p.attribute("source").unwrap_or(""))?;
                    pos = Some((vec3s(self.source(psrc, 3)?), offset));
                    if let Some(n) =
                        children(src, "input").find(|i| i.attribute("semantic") == Some("NORMAL"))
                    {
                        let nsrc = self.lookup(n, n.attribute("source").unwrap_or(""))?;
                        nor = Some((vec3s(self.source(nsrc, 3)?), offset));
                    }
                }
                "POSITION" => pos = Some((vec3s(self.source(src, 3)?), offset)),
                "NORMAL" => nor = Some((vec3s(self.source(src, 3)?), offset)),
                "TEXCOORD" if tex.is_none() => {
                    let v = self.source(src, 2)?;
                    tex = Some((v.chunks_exact(2).map(Vec2::from_slice).collect(), offset));
                }
                _ => {}
            }
        }
        let (positions, pos_offset) =
            pos.ok_or_else(|| self.file.error(prim, "expected a VERTEX input"))?;
        let stride = stride.max(1);
        // Polygons: vertex counts and index lists.
        let polygons: Vec<Vec<u32>> = match prim.tag_name().name() {
            "polygons" => children(prim, "p")
                .map(|p| self.file.indices(p))
                .collect::<Result<_, _>>()?,
            kind => {
                let p = child(prim, "p")
                    .map(|p| self.file.indices(p))
                    .transpose()?
                    .unwrap_or_default();
                let counts: Vec<u32> = if kind == "polylist" {
                    child(prim, "vcount")
                        .map(|v| self.file.indices(v))
                        .transpose()?
                        .unwrap_or_default()
                } else {
                    vec![3; p.len() / (3 * stride)]
                };
                let mut out = Vec::with_capacity(counts.len().min(p.len()));
                let mut at = 0usize;
                for &c in &counts {
                    let len = c as usize * stride;
                    let Some(slice) = p.get(at..at + len) else {
                        return Err(self.file.error(
                            prim,
                            format!(
                                "<p> has {} indices but the polygon counts need more",
                                p.len()
                            ),
                        ));
                    };
                    out.push(slice.to_vec());
                    at += len;
                }
                out
            }
        };
        if let Some(count) = prim
            .attribute("count")
            .and_then(|c| c.parse::<usize>().ok())
        {
            if count != polygons.len() {
                return Err(self.file.error(
                    prim,
                    format!(
                        "count says {count} polygons but {} are given",
                        polygons.len()
                    ),
                ));
            }
        }
        let mut out = Triangles::default();
        let fetch =
            |list: &[u32], corner: usize, offset: usize| list[corner * stride + offset] as usize;
        for poly in &polygons {
            if poly.len() % stride != 0 {
                return Err(self.file.error(
                    prim,
                    "a polygon's index count is not a multiple of the input count",
                ));
            }
            let corners = poly.len() / stride;
            for k in 1..corners.saturating_sub(1) {
                for corner in [0, k, k + 1] {
                    let pi = fetch(poly, corner, pos_offset);
                    let p = *positions.get(pi).ok_or_else(|| {
                        self.file.error(
                            prim,
                            format!(
                                "position index {pi} out of range ({} positions)",
                                positions.len()
                            ),
                        )
                    })?;
                    out.positions.push(p);
                    if let Some((normals, off)) = &nor {
                        let ni = fetch(poly, corner, *off);
                        out.normals.push(*normals.get(ni).ok_or_else(|| {
                            self.file.error(
                                prim,
                                format!(
                                    "normal index {ni} out of range ({} normals)",
                                    normals.len()
                                ),
                            )
                        })?);
                    }
                    if let Some((uvs, off)) = &tex {
                        let ti = fetch(poly, corner, *off);
                        out.uvs.push(*uvs.get(ti).ok_or_else(|| {
                            self.file.error(
                                prim,
                                format!(
                                    "texture coordinate index {ti} out of range ({})",
                                    uvs.len()
                                ),
                            )
                        })?);
                    }
                }
            }
        }
        Ok(out)
    }

    fn light(&mut self, light: Node<'a, 'input>, world: Mat4) -> Result<(), Error> {
        let cgl = light.descendants().find(|n| {
            n.is_element()
                && n.tag_name().name() == "technique"
                && n.attribute("profile") == Some("CGL")
        });
        let common = child(light, "technique_common");
        let (technique, is_cgl) = match (cgl, common) {
            (Some(c), _) => (c, true),
            (None, Some(c)) => (c, false),
            (None, None) => {
                self.desc.warnings.push(format!(
                    "light '{}' has no technique pathlab reads; skipped",
                    light.attribute("id").unwrap_or("?")
                ));
                return Ok(());
            }
        };
        let Some(kind) = technique.children().find(|c| c.is_element()) else {
            return Ok(());
        };
        self.has_cgl_lights |= is_cgl;
        let color = match child(kind, "color") {
            Some(c) => Vec3::from_slice(&self.file.floats_n(c, 3)?),
            None => Vec3::ONE,
        };
        let scalar = |name: &str, default: f32| -> Result<f32, Error> {
            match child(kind, name) {
                Some(c) => Ok(self.file.floats_n(c, 1)?[0]),
                None => Ok(default),
            }
        };
        let attenuation = if [
            "constant_attenuation",
            "linear_attenuation",
            "quadratic_attenuation",
        ]
        .iter()
        .any(|n| child(kind, n).is_some())
        {
            [
                scalar("constant_attenuation", 1.0)?,
                scalar("linear_attenuation", 0.0)?,
                scalar("quadratic_attenuation", 0.0)?,
            ]
        } else {
            INVERSE_SQUARE
        };
        let position = world.transform_point3(Vec3::ZERO);
        let direction = (world.transform_point3(Vec3::NEG_Z) - position).normalize_or(Vec3::NEG_Y);
        match kind.tag_name().name() {
            "area" => {
                let dim_x = world.transform_point3(Vec3::Y.cross(Vec3::NEG_Z)) - position;
                let dim_y = world.transform_point3(Vec3::Y) - position;
                self.cgl_area_lights.push(AreaLight {
                    center: position,
                    dim_x,
                    dim_y,
                    direction,
                    radiance: color,
                });
            }
            "point" => self.desc.point_lights.push(PointLightDesc {
                position,
                intensity: color,
                attenuation,
            }),
            "spot" => self.desc.spot_lights.push(SpotLightDesc {
                position,
                direction,
                intensity: color,
                cutoff_degrees: scalar("falloff_angle", 45.0)?,
                exponent: scalar("falloff_exponent", 0.0)?,
                attenuation,
            }),
            "directional" => self.desc.directional_lights.push(DirectionalLightDesc {
                direction,
                irradiance: color,
            }),
            "ambient" => {
                self.desc.environment = Some(self.desc.environment.unwrap_or(Vec3::ZERO) + color)
            }
            other => self
                .desc
                .warnings
                .push(format!("light type '{other}' is not supported; skipped")),
        }
        Ok(())
    }

    fn finish(mut self) -> Result<SceneDesc, Error> {
        // CGL lights: emissive meshes are seen by camera rays only, and the area lights light
        // the scene as one-sided parallelograms hidden from the camera.
        if self.has_cgl_lights {
            for &i in &self.emissive_meshes {
                self.desc.meshes[i].visibility = Visibility::CAMERA_ONLY;
            }
        }
        let black = self.desc.materials.len();
        if !self.cgl_area_lights.is_empty() {
            self.desc.materials.push(MaterialDesc::Diffuse {
                reflectance: Vec3::ZERO,
                two_sided: false,
            });
        }
        for (k, a) in self.cgl_area_lights.iter().enumerate() {
            let (hx, hy) = (0.5 * a.dim_x, 0.5 * a.dim_y);
            let mut positions = vec![
                a.center - hx - hy,
                a.center + hx - hy,
                a.center + hx + hy,
                a.center - hx + hy,
            ];
            // Wind the parallelogram so that its front (counter-clockwise) side faces `direction`.
            let n = (positions[1] - positions[0]).cross(positions[2] - positions[0]);
            if n.dot(a.direction) < 0.0 {
                positions.swap(1, 3);
            }
            self.desc.meshes.push(MeshDesc {
                name: format!("area light {k}"),
                positions,
                indices: vec![0, 1, 2, 0, 2, 3],
                material: black,
                emission: Some(Emission {
                    radiance: a.radiance,
                    two_sided: false,
                }),
                normals: Vec::new(),
                uvs: Vec::new(),
                visibility: Visibility::INDIRECT_ONLY,
                ..Default::default()
            });
        }
        let bright = |c: Vec3| c.max_element() > 0.0;
        let d = &self.desc;
        let has_light = d.point_lights.iter().any(|l| bright(l.intensity))
            || d.spot_lights.iter().any(|l| bright(l.intensity))
            || d.directional_lights.iter().any(|l| bright(l.irradiance))
            || d.environment.is_some_and(bright)
            || d.meshes
                .iter()
                .any(|m| m.emission.is_some_and(|e| bright(e.radiance)))
            || d.spheres
                .iter()
                .any(|s| s.emission.is_some_and(|e| bright(e.radiance)));
        if !has_light {
            self.desc.environment = Some(Vec3::ONE);
            self.desc
                .warnings
                .push("the scene has no lights: lit by a uniform white environment".into());
        }
        self.desc.camera = self.course_camera()?;
        Ok(self.desc)
    }

    /// The camera as the course's viewer places it (see the module documentation).
    fn course_camera(&mut self) -> Result<CameraDesc, Error> {
        let (min, max) = self.bounds;
        let (center, extent) = if min.x <= max.x {
            (0.5 * (min + max), (max - min).length())
        } else {
            (Vec3::ZERO, 1.0)
        };
        let (dir, xfov, yfov, aspect) = match self.camera {
            Some((world, cam)) => {
                let persp = cam
                    .descendants()
                    .find(|n| n.is_element() && n.tag_name().name() == "perspective");
                let get = |name: &str| -> Result<Option<f32>, Error> {
                    persp
                        .and_then(|p| child(p, name))
                        .map(|n| self.file.floats_n(n, 1).map(|v| v[0]))
                        .transpose()
                };
                (
                    world
                        .transform_point3(Vec3::NEG_Z)
                        .normalize_or(Vec3::NEG_Z),
                    get("xfov")?,
                    get("yfov")?,
                    get("aspect_ratio")?,
                )
            }
            None => {
                self.desc.warnings.push("no camera: looking down -z".into());
                (Vec3::NEG_Z, None, None, None)
            }
        };
        let half_tan = |deg: f32| (deg.to_radians() * 0.5).tan();
        let aspect = aspect
            .filter(|a| *a > 0.0 && a.is_finite())
            .unwrap_or(4.0 / 3.0);
        let (tx, mut ty) = match (xfov, yfov) {
            (Some(x), Some(y)) => (half_tan(x), half_tan(y)),
            (Some(x), None) => (half_tan(x), half_tan(x) / aspect),
            (None, Some(y)) => (half_tan(y) * aspect, half_tan(y)),
            (None, None) => (half_tan(50.0), half_tan(50.0) * 0.75),
        };
        // Configure for 800 x 600: widen whichever field of view is too small for 4:3. Only the
        // vertical one matters from here on (it fixes the image-plane distance), and it changes
        // only when the horizontal one is the wider.
        if tx / ty >= 4.0 / 3.0 {
            ty = tx * 0.75;
        }
        let d = 600.0 / (2.0 * ty);
        let phi = dir.y.clamp(-1.0, 1.0).acos();
        let theta = dir.x.atan2(dir.z);
        let r = 1.5 * extent;
        let offset = r * Vec3::new(phi.sin() * theta.sin(), phi.cos(), phi.sin() * theta.cos());
        let up = if phi.sin() < 0.0 {
            Vec3::NEG_Y
        } else {
            Vec3::Y
        };
        Ok(CameraDesc {
            origin: center + offset,
            target: center,
            up,
            fov_degrees: 2.0 * ty.atan().to_degrees(),
            fov_axis: FovAxis::Y,
            lens_radius: 0.0,
            focal_distance: r,
            focal_pixels: Some(d),
            ..Default::default()
        })
    }
}

/// Triangles expanded per corner.
#[derive(Default)]
struct Triangles {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
}
