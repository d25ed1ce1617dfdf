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
//!
//! Geometry (sources, primitives) is read in `geometry`, materials (effects, textures) in
//! `materials`.

use crate::xml::{child, children, parse_document, path as xpath, read_text, XmlFile};
use crate::Error;
use glam::{Mat4, Vec3};
use pathlab_render::desc::*;
use roxmltree::Node;
use std::collections::HashMap;
use std::path::Path;

mod geometry;
mod materials;

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
            Some(c) => {
                let color = Vec3::from_slice(&self.file.floats_n(c, 3)?);
                if !crate::spectrum::is_emission(color) {
                    return Err(self.file.error(
                        c,
                        format!("a light's colour must be >= 0 in every channel, got {color}"),
                    ));
                }
                color
            }
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
