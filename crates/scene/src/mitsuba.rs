//! A practical subset of Mitsuba 3's XML scene format.
//!
//! Supported: `<scene>`, `<default>` and `$name` substitution, `<include>`, `<ref id>`,
//! `<transform>` (`matrix`, `translate`, `rotate`, `scale`, `lookat`; later operations apply
//! after earlier ones, as in Mitsuba); shapes `obj`, `ply`, `rectangle`, `cube`, `sphere`,
//! `disk`; BSDFs `diffuse` (one-sided, as Mitsuba's) and `twosided`, with `conductor`,
//! `roughconductor`, `dielectric`, `roughdielectric`, `plastic` read and drawn by stand-ins
//! until their BSDFs exist; emitters `area`, `point`, `spot`, `directional`, `constant`
//! (`envmap` is reported and skipped); sensors `perspective` and `thinlens` (`fov`,
//! `fov_axis`, `to_world`, film size, sampler `sample_count`); integrator `path` `max_depth`
//! (Mitsuba counts the camera ray as depth 1: ours = Mitsuba's - 1).

use crate::meshfile;
use crate::xml::{child, parse_document, read_text, XmlFile};
use crate::Error;
use glam::{Mat3, Mat4, Vec3};
use pathlab_render::desc::*;
use roxmltree::Node;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How deep `<include>` may nest (a loop of includes stops here).
const MAX_INCLUDE_DEPTH: usize = 16;

/// Loads a Mitsuba 3 XML scene.
pub fn load(path: &Path) -> Result<SceneDesc, Error> {
    let mut loader = Loader {
        defaults: HashMap::new(),
        bsdfs: HashMap::new(),
        desc: SceneDesc {
            resolution: [768, 576],
            ..Default::default()
        },
        include_depth: 0,
    };
    loader.file(path)?;
    if loader.desc.materials.is_empty() {
        loader.desc.materials.push(default_bsdf());
    }
    Ok(loader.desc)
}

fn default_bsdf() -> MaterialDesc {
    MaterialDesc::Diffuse {
        reflectance: Vec3::splat(0.5),
        two_sided: false,
    }
}

struct Loader {
    defaults: HashMap<String, String>,
    /// BSDFs by id: index into `desc.materials`.
    bsdfs: HashMap<String, usize>,
    desc: SceneDesc,
    include_depth: usize,
}

impl Loader {
    fn file(&mut self, path: &Path) -> Result<(), Error> {
        let text = read_text(path)?;
        let doc = parse_document(&text, path)?;
        let file = XmlFile { path, doc: &doc };
        let root = doc.root_element();
        if root.tag_name().name() != "scene" {
            return Err(file.error(root, "expected a <scene> document"));
        }
        for node in root.children().filter(|n| n.is_element()) {
            self.top_level(&file, node)?;
        }
        Ok(())
    }

    fn top_level(&mut self, f: &XmlFile, node: Node) -> Result<(), Error> {
        match node.tag_name().name() {
            "default" => {
                let name = self.attr(f, node, "name")?;
                let value = self.attr(f, node, "value")?;
                self.defaults.entry(name).or_insert(value);
            }
            "include" => {
                if self.include_depth >= MAX_INCLUDE_DEPTH {
                    return Err(f.error(node, "includes nest too deeply (a loop?)"));
                }
                let name = self.attr(f, node, "filename")?;
                let path = relative(f.path, &name);
                self.include_depth += 1;
                let result = self.file(&path);
                self.include_depth -= 1;
                result?;
            }
            "bsdf" => {
                let index = self.bsdf(f, node)?;
                if let Some(id) = node.attribute("id") {
                    self.bsdfs.insert(id.to_string(), index);
                }
            }
            "shape" => self.shape(f, node)?,
            "emitter" => self.emitter(f, node, None)?,
            "sensor" => self.sensor(f, node)?,
            "integrator" => {
                if let Some(d) = self.property(f, node, "max_depth")? {
                    let d: i64 = d
                        .parse()
                        .map_err(|_| f.error(node, format!("max_depth '{d}' is not an integer")))?;
                    // Mitsuba's depth counts the camera ray; -1 is unbounded.
                    self.desc.hints.max_depth = Some(if d < 0 {
                        u32::MAX
                    } else {
                        (d.max(1) - 1) as u32
                    });
                }
            }
            other => self.desc.warnings.push(format!(
                "{}: <{other}> is not supported; skipped",
                f.path.display()
            )),
        }
        Ok(())
    }

    /// An attribute with `$name` defaults substituted.
    fn attr(&self, f: &XmlFile, node: Node, name: &str) -> Result<String, Error> {
        let raw = node
            .attribute(name)
            .ok_or_else(|| f.error(node, format!("expected a '{name}' attribute")))?;
        self.substitute(f, node, raw)
    }

    fn substitute(&self, f: &XmlFile, node: Node, raw: &str) -> Result<String, Error> {
        if let Some(key) = raw.strip_prefix('$') {
            return self
                .defaults
                .get(key)
                .cloned()
                .ok_or_else(|| f.error(node, format!("parameter '${key}' has no <default>")));
        }
        Ok(raw.to_string())
    }

    /// The `value` of the child property element named `name` (any type).
    fn property(&self, f: &XmlFile, node: Node, name: &str) -> Result<Option<String>, Error> {
        match node.children().find(|c| {
            c.is_element() && c.attribute("name") == Some(name) && c.has_attribute("value")
        }) {
            Some(c) => Ok(Some(self.attr(f, c, "value")?)),
            None => Ok(None),
        }
    }

    fn float(&self, f: &XmlFile, node: Node, name: &str, default: f32) -> Result<f32, Error> {
        match self.property(f, node, name)? {
            Some(v) => parse_f32(f, node, &v),
            None => Ok(default),
        }
    }

    /// A colour property: `<rgb value="r, g, b">`, `<float value>` or `<spectrum value>` with one
    /// number.
    fn color(&self, f: &XmlFile, node: Node, name: &str, default: Vec3) -> Result<Vec3, Error> {
        let Some(c) = node
            .children()
            .find(|c| c.is_element() && c.attribute("name") == Some(name))
        else {
            return Ok(default);
        };
        if c.tag_name().name() == "texture" {
            return Ok(default);
        }
        let v = numbers(f, c, &self.attr(f, c, "value")?)?;
        match v.len() {
            1 => Ok(Vec3::splat(v[0])),
            3 => Ok(Vec3::new(v[0], v[1], v[2])),
            n => Err(f.error(c, format!("expected 1 or 3 numbers, found {n}"))),
        }
    }

    /// A `<texture type="bitmap" name="NAME">` child, loaded (8-bit images are decoded from
    /// sRGB unless `raw` is true); other texture types are warned about and skipped.
    fn bitmap(
        &mut self,
        f: &XmlFile,
        node: Node,
        name: &str,
    ) -> Result<Option<Arc<Texture>>, Error> {
        let Some(t) = node.children().find(|c| {
            c.is_element() && c.tag_name().name() == "texture" && c.attribute("name") == Some(name)
        }) else {
            return Ok(None);
        };
        let kind = self.attr(f, t, "type")?;
        if kind != "bitmap" {
            self.desc.warnings.push(format!(
                "{}: texture '{kind}' is not supported; using a constant colour",
                f.path.display()
            ));
            return Ok(None);
        }
        let file = self
            .property(f, t, "filename")?
            .ok_or_else(|| f.error(t, "bitmap needs a 'filename' string"))?;
        let raw = self.property(f, t, "raw")?.as_deref() == Some("true");
        let texture = crate::texture::load(&relative(f.path, &file), raw)?;
        Ok(Some(texture))
    }

    /// A `distribution` property: `beckmann` (Mitsuba's default) or `ggx`.
    fn distribution(&self, f: &XmlFile, node: Node) -> Result<NormalDistribution, Error> {
        match self.property(f, node, "distribution")?.as_deref() {
            None | Some("beckmann") => Ok(NormalDistribution::Beckmann),
            Some("ggx") => Ok(NormalDistribution::Ggx),
            Some(other) => Err(f.error(
                node,
                format!("unknown microfacet distribution '{other}' (expected beckmann or ggx)"),
            )),
        }
    }

    /// An index of refraction: a number or one of Mitsuba's named media.
    fn ior(&self, f: &XmlFile, node: Node, name: &str, default: f32) -> Result<f32, Error> {
        let Some(v) = self.property(f, node, name)? else {
            return Ok(default);
        };
        if let Some(&(_, n)) = NAMED_IORS.iter().find(|(k, _)| k.eq_ignore_ascii_case(&v)) {
            return Ok(n);
        }
        let n = parse_f32(f, node, &v)?;
        if n > 0.0 && n.is_finite() {
            Ok(n)
        } else {
            Err(f.error(node, format!("{name} must be positive, got {v}")))
        }
    }

    fn bsdf(&mut self, f: &XmlFile, node: Node) -> Result<usize, Error> {
        let material = self.bsdf_desc(f, node)?;
        self.desc.materials.push(material);
        Ok(self.desc.materials.len() - 1)
    }

    fn bsdf_desc(&mut self, f: &XmlFile, node: Node) -> Result<MaterialDesc, Error> {
        let kind = self.attr(f, node, "type")?;
        let desc = match kind.as_str() {
            "diffuse" => match self.bitmap(f, node, "reflectance")? {
                Some(texture) => MaterialDesc::TexturedDiffuse {
                    texture,
                    scale: Vec3::ONE,
                    two_sided: false,
                },
                None => MaterialDesc::Diffuse {
                    reflectance: self.color(f, node, "reflectance", Vec3::splat(0.5))?,
                    two_sided: false,
                },
            },
            "twosided" => {
                let inner = child(node, "bsdf")
                    .ok_or_else(|| f.error(node, "twosided needs a nested <bsdf>"))?;
                match self.bsdf_desc(f, inner)? {
                    MaterialDesc::Diffuse { reflectance, .. } => MaterialDesc::Diffuse {
                        reflectance,
                        two_sided: true,
                    },
                    MaterialDesc::TexturedDiffuse { texture, scale, .. } => {
                        MaterialDesc::TexturedDiffuse {
                            texture,
                            scale,
                            two_sided: true,
                        }
                    }
                    other => other,
                }
            }
            "conductor" | "roughconductor" => {
                let (eta, k) = match self.property(f, node, "material")? {
                    Some(name) => named_conductor(&name).ok_or_else(|| {
                        f.error(
                            node,
                            format!(
                                "unknown conductor material '{name}' (known: {}; or give eta and k)",
                                CONDUCTORS.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
                            ),
                        )
                    })?,
                    // Mitsuba's default: a perfect mirror.
                    None => (Vec3::ZERO, Vec3::ONE),
                };
                MaterialDesc::Conductor {
                    alpha: if kind == "conductor" {
                        0.0
                    } else {
                        self.float(f, node, "alpha", 0.1)?
                    },
                    eta: self.color(f, node, "eta", eta)?,
                    k: self.color(f, node, "k", k)?,
                    distribution: self.distribution(f, node)?,
                }
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                if kind == "thindielectric" {
                    self.desc.warnings.push(format!(
                        "{}: 'thindielectric' is drawn as a solid dielectric",
                        f.path.display()
                    ));
                }
                MaterialDesc::Glass {
                    reflectance: self.color(f, node, "specular_reflectance", Vec3::ONE)?,
                    transmittance: self.color(f, node, "specular_transmittance", Vec3::ONE)?,
                    roughness: if kind == "roughdielectric" {
                        self.float(f, node, "alpha", 0.1)?
                    } else {
                        0.0
                    },
                    ior: self.ior(f, node, "int_ior", 1.5046)?
                        / self.ior(f, node, "ext_ior", 1.000277)?,
                    distribution: self.distribution(f, node)?,
                    fresnel: FresnelModel::Exact,
                }
            }
            "plastic" => MaterialDesc::Plastic {
                diffuse: self.color(f, node, "diffuse_reflectance", Vec3::splat(0.5))?,
                ior: self.ior(f, node, "int_ior", 1.49)?
                    / self.ior(f, node, "ext_ior", 1.000277)?,
                nonlinear: self.property(f, node, "nonlinear")?.as_deref() == Some("true"),
            },
            "roughplastic" | "principled" => {
                self.desc.warnings.push(format!(
                    "{}: BSDF '{kind}' is drawn as a diffuse surface of its base colour",
                    f.path.display()
                ));
                MaterialDesc::Diffuse {
                    reflectance: self.color(f, node, "diffuse_reflectance", Vec3::splat(0.5))?,
                    two_sided: false,
                }
            }
            other => {
                self.desc.warnings.push(format!(
                    "{}: BSDF '{other}' is not supported; using grey diffuse",
                    f.path.display()
                ));
                default_bsdf()
            }
        };
        Ok(desc)
    }

    fn transform(&self, f: &XmlFile, node: Node) -> Result<Mat4, Error> {
        let Some(t) = node
            .children()
            .find(|c| c.is_element() && c.tag_name().name() == "transform")
        else {
            return Ok(Mat4::IDENTITY);
        };
        let mut m = Mat4::IDENTITY;
        for op in t.children().filter(|c| c.is_element()) {
            let xyz = |default: f32| -> Result<Vec3, Error> {
                if let Some(v) = op.attribute("value") {
                    let v = numbers(f, op, &self.substitute(f, op, v)?)?;
                    return match v.len() {
                        1 => Ok(Vec3::splat(v[0])),
                        3 => Ok(Vec3::new(v[0], v[1], v[2])),
                        n => Err(f.error(op, format!("expected 1 or 3 numbers, found {n}"))),
                    };
                }
                let get = |k: &str| -> Result<f32, Error> {
                    match op.attribute(k) {
                        Some(v) => parse_f32(f, op, &self.substitute(f, op, v)?),
                        None => Ok(default),
                    }
                };
                Ok(Vec3::new(get("x")?, get("y")?, get("z")?))
            };
            let step = match op.tag_name().name() {
                "translate" => Mat4::from_translation(xyz(0.0)?),
                "scale" => Mat4::from_scale(xyz(1.0)?),
                "rotate" => {
                    let axis = xyz(0.0)?.normalize_or_zero();
                    if axis == Vec3::ZERO {
                        return Err(f.error(op, "rotation axis is zero"));
                    }
                    let angle = parse_f32(f, op, &self.attr(f, op, "angle")?)?;
                    Mat4::from_axis_angle(axis, angle.to_radians())
                }
                "matrix" => {
                    let v = numbers(f, op, &self.attr(f, op, "value")?)?;
                    if v.len() != 16 {
                        return Err(f.error(op, format!("expected 16 numbers, found {}", v.len())));
                    }
                    Mat4::from_cols_slice(&v).transpose()
                }
                "lookat" => {
                    let point = |k: &str| -> Result<Vec3, Error> {
                        let v = numbers(f, op, &self.attr(f, op, k)?)?;
                        if v.len() != 3 {
                            return Err(f.error(op, format!("'{k}' needs 3 numbers")));
                        }
                        Ok(Vec3::new(v[0], v[1], v[2]))
                    };
                    let origin = point("origin")?;
                    let target = point("target")?;
                    let up = if op.has_attribute("up") {
                        point("up")?
                    } else {
                        Vec3::Y
                    };
                    let dir = (target - origin).normalize_or_zero();
                    let left = up.cross(dir).normalize_or_zero();
                    if dir == Vec3::ZERO || left == Vec3::ZERO {
                        return Err(f.error(op, "lookat: degenerate origin, target or up"));
                    }
                    let new_up = dir.cross(left);
                    Mat4::from_cols(
                        left.extend(0.0),
                        new_up.extend(0.0),
                        dir.extend(0.0),
                        origin.extend(1.0),
                    )
                }
                other => return Err(f.error(op, format!("unknown transform operation <{other}>"))),
            };
            m = step * m;
        }
        if !m.is_finite() {
            return Err(f.error(t, "transform is not finite"));
        }
        Ok(m)
    }

    fn shape(&mut self, f: &XmlFile, node: Node) -> Result<(), Error> {
        let kind = self.attr(f, node, "type")?;
        let m = self.transform(f, node)?;
        // Material: a nested <bsdf>, a <ref id>, or the default.
        let material = if let Some(b) = child(node, "bsdf") {
            self.bsdf(f, b)?
        } else if let Some(r) = child(node, "ref") {
            let id = self.attr(f, r, "id")?;
            *self
                .bsdfs
                .get(&id)
                .ok_or_else(|| f.error(r, format!("reference to undefined BSDF id '{id}'")))?
        } else {
            self.desc.materials.push(default_bsdf());
            self.desc.materials.len() - 1
        };
        let mut emission = None;
        if let Some(e) = child(node, "emitter") {
            if self.attr(f, e, "type")? == "area" {
                emission = Some(Emission {
                    radiance: self.color(f, e, "radiance", Vec3::ONE)?,
                    two_sided: false,
                });
            } else {
                self.emitter(f, e, Some(m))?;
            }
        }
        let name = node.attribute("id").unwrap_or(&kind).to_string();
        let (positions, indices): (Vec<Vec3>, Vec<u32>) = match kind.as_str() {
            "rectangle" => (
                vec![
                    Vec3::new(-1., -1., 0.),
                    Vec3::new(1., -1., 0.),
                    Vec3::new(1., 1., 0.),
                    Vec3::new(-1., 1., 0.),
                ],
                vec![0, 1, 2, 0, 2, 3],
            ),
            "cube" => cube(),
            "disk" => disk(64),
            "sphere" => {
                let center = match child(node, "point") {
                    Some(p) if p.attribute("name") == Some("center") => {
                        let g = |k: &str| -> Result<f32, Error> {
                            parse_f32(f, p, &self.substitute(f, p, p.attribute(k).unwrap_or("0"))?)
                        };
                        Vec3::new(g("x")?, g("y")?, g("z")?)
                    }
                    _ => Vec3::ZERO,
                };
                let radius = self.float(f, node, "radius", 1.0)?;
                let c = m.transform_point3(center);
                let r = radius * (m.transform_vector3(Vec3::X)).length();
                if !(r > 0.0 && r.is_finite()) {
                    return Err(f.error(node, format!("sphere radius must be positive, got {r}")));
                }
                self.desc.spheres.push(SphereDesc {
                    center: c,
                    radius: r,
                    material,
                    emission,
                });
                return Ok(());
            }
            "obj" | "ply" => {
                let file = self
                    .property(f, node, "filename")?
                    .ok_or_else(|| f.error(node, "expected a 'filename' property"))?;
                let path = relative(f.path, &file);
                let mesh = if kind == "obj" {
                    meshfile::load_obj(&path)?
                } else {
                    meshfile::load_ply(&path)?
                };
                for mut md in mesh.meshes {
                    md.positions = md
                        .positions
                        .iter()
                        .map(|&p| m.transform_point3(p))
                        .collect();
                    let nm = m.inverse().transpose();
                    md.normals = md
                        .normals
                        .iter()
                        .map(|&n| nm.transform_vector3(n).normalize_or_zero())
                        .collect();
                    if m.determinant() < 0.0 {
                        flip_winding(&mut md.indices);
                    }
                    md.material = material;
                    md.emission = emission;
                    self.desc.meshes.push(md);
                }
                return Ok(());
            }
            other => {
                self.desc
                    .warnings
                    .push(format!("shape '{other}' is not supported; skipped"));
                return Ok(());
            }
        };
        let mut indices = indices;
        if m.determinant() < 0.0 {
            flip_winding(&mut indices);
        }
        // Mitsuba's rectangle maps its corners (±1, ±1) to the unit square of (u, v).
        let uvs = if kind == "rectangle" {
            positions
                .iter()
                .map(|p| glam::Vec2::new(0.5 * (p.x + 1.0), 0.5 * (p.y + 1.0)))
                .collect()
        } else {
            Vec::new()
        };
        self.desc.meshes.push(MeshDesc {
            name,
            positions: positions.iter().map(|&p| m.transform_point3(p)).collect(),
            indices,
            material,
            emission,
            normals: Vec::new(),
            uvs,
            visibility: Visibility::ALL,
        });
        Ok(())
    }

    fn emitter(&mut self, f: &XmlFile, node: Node, parent: Option<Mat4>) -> Result<(), Error> {
        let kind = self.attr(f, node, "type")?;
        let m = parent.unwrap_or(Mat4::IDENTITY) * self.transform(f, node)?;
        let position =
            match child(node, "point").filter(|p| p.attribute("name") == Some("position")) {
                Some(p) => {
                    let g = |k: &str| -> Result<f32, Error> {
                        parse_f32(f, p, &self.substitute(f, p, p.attribute(k).unwrap_or("0"))?)
                    };
                    Vec3::new(g("x")?, g("y")?, g("z")?)
                }
                None => m.transform_point3(Vec3::ZERO),
            };
        let forward = m.transform_vector3(Vec3::Z).normalize_or(Vec3::NEG_Y);
        match kind.as_str() {
            "point" => self.desc.point_lights.push(PointLightDesc {
                position,
                intensity: self.color(f, node, "intensity", Vec3::ONE)?,
                attenuation: INVERSE_SQUARE,
            }),
            "spot" => self.desc.spot_lights.push(SpotLightDesc {
                position,
                direction: forward,
                intensity: self.color(f, node, "intensity", Vec3::ONE)?,
                cutoff_degrees: self.float(f, node, "cutoff_angle", 20.0)?,
                exponent: 0.0,
                attenuation: INVERSE_SQUARE,
            }),
            "directional" => {
                let direction = match child(node, "vector")
                    .filter(|v| v.attribute("name") == Some("direction"))
                {
                    Some(v) => {
                        let g = |k: &str| -> Result<f32, Error> {
                            parse_f32(f, v, &self.substitute(f, v, v.attribute(k).unwrap_or("0"))?)
                        };
                        Vec3::new(g("x")?, g("y")?, g("z")?)
                    }
                    None => forward,
                };
                self.desc.directional_lights.push(DirectionalLightDesc {
                    direction: direction.normalize_or(Vec3::NEG_Y),
                    irradiance: self.color(f, node, "irradiance", Vec3::ONE)?,
                });
            }
            "constant" => {
                let r = self.color(f, node, "radiance", Vec3::ONE)?;
                self.desc.environment = Some(self.desc.environment.unwrap_or(Vec3::ZERO) + r);
            }
            "envmap" => {
                let name = self
                    .property(f, node, "filename")?
                    .ok_or_else(|| f.error(node, "envmap needs a 'filename' string"))?;
                let rotation = Mat3::from_mat4(m);
                let map = crate::envmap::load(
                    &relative(f.path, &name),
                    rotation,
                    self.float(f, node, "scale", 1.0)?,
                )?;
                if self.desc.environment_map.is_some() {
                    self.desc.warnings.push(format!(
                        "{}: more than one envmap; using the last",
                        f.path.display()
                    ));
                }
                self.desc.environment_map = Some(map);
            }
            other => self.desc.warnings.push(format!(
                "{}: emitter '{other}' is not supported yet; skipped",
                f.path.display()
            )),
        }
        Ok(())
    }

    fn sensor(&mut self, f: &XmlFile, node: Node) -> Result<(), Error> {
        let kind = self.attr(f, node, "type")?;
        if kind != "perspective" && kind != "thinlens" {
            self.desc.warnings.push(format!(
                "sensor '{kind}' is not supported; using a perspective camera"
            ));
        }
        let m = self.transform(f, node)?;
        let origin = m.transform_point3(Vec3::ZERO);
        let forward = m.transform_vector3(Vec3::Z).normalize_or(Vec3::NEG_Z);
        let up = m.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
        let axis = match self.property(f, node, "fov_axis")?.as_deref() {
            None | Some("x") => FovAxis::X,
            Some("y") => FovAxis::Y,
            Some("smaller") => FovAxis::Smaller,
            Some("larger") => FovAxis::Larger,
            Some("diagonal") => FovAxis::Diagonal,
            Some(other) => return Err(f.error(node, format!("unknown fov_axis '{other}'"))),
        };
        let focus = self.float(f, node, "focus_distance", 1.0)?;
        self.desc.camera = CameraDesc {
            origin,
            target: origin + forward * focus.max(1e-3),
            up,
            fov_degrees: self.float(f, node, "fov", 39.3077)?,
            fov_axis: axis,
            lens_radius: if kind == "thinlens" {
                self.float(f, node, "aperture_radius", 0.0)?
            } else {
                0.0
            },
            focal_distance: focus,
            focal_pixels: None,
        };
        if let Some(film) = child(node, "film") {
            let w = self.float(f, film, "width", 768.0)?;
            let h = self.float(f, film, "height", 576.0)?;
            if !(1.0..=65536.0).contains(&w) || !(1.0..=65536.0).contains(&h) {
                return Err(f.error(film, format!("film size {w} x {h} is out of range")));
            }
            self.desc.resolution = [w as u32, h as u32];
            if let Some(rf) = child(film, "rfilter") {
                let t = self.attr(f, rf, "type")?;
                if t != "box" {
                    self.desc
                        .warnings
                        .push(format!("pixel filter '{t}' is rendered as a box filter"));
                }
            }
        }
        if let Some(sampler) = child(node, "sampler") {
            if let Some(n) = self.property(f, sampler, "sample_count")? {
                let n: u32 = n
                    .parse()
                    .map_err(|_| f.error(sampler, format!("sample_count '{n}' is not a count")))?;
                self.desc.hints.spp = Some(n.max(1));
            }
        }
        Ok(())
    }
}

fn parse_f32(f: &XmlFile, node: Node, text: &str) -> Result<f32, Error> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(f.error(
            node,
            format!(
                "expected a finite number, found '{}'",
                crate::xml::truncate(text)
            ),
        )),
    }
}

/// Numbers separated by commas and/or spaces.
fn numbers(f: &XmlFile, node: Node, text: &str) -> Result<Vec<f32>, Error> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| parse_f32(f, node, t))
        .collect()
}

fn relative(base: &Path, name: &str) -> PathBuf {
    base.parent().unwrap_or(Path::new(".")).join(name)
}

fn flip_winding(indices: &mut [u32]) {
    for t in indices.chunks_exact_mut(3) {
        t.swap(1, 2);
    }
}

/// Mitsuba's `cube`: [-1, 1]³ with outward-facing triangles.
fn cube() -> (Vec<Vec3>, Vec<u32>) {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            let (u, v) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
            let base = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push(n + a * u + b * v);
            }
            // u x v = n for sign +1; flip for the negative face so that the front faces out.
            if sign > 0.0 {
                indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            } else {
                indices.extend([base, base + 2, base + 1, base, base + 3, base + 2]);
            }
        }
    }
    (positions, indices)
}

/// Mitsuba's `disk`: the unit disk in the xy plane facing +z, as a fan of `n` triangles.
fn disk(n: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut positions = vec![Vec3::ZERO];
    for i in 0..n {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
    }
    let indices = (0..n).flat_map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    (positions, indices)
}

/// Named indices of refraction Mitsuba accepts for `int_ior` / `ext_ior`.
const NAMED_IORS: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// RGB complex indices (η, k) of common metals for `conductor`'s `material` (values at the
/// centres of the red, green and blue bands; `none` is the perfect mirror).
const CONDUCTORS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("none", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    ("Au", [0.143, 0.374, 1.442], [3.983, 2.385, 1.603]),
    ("Ag", [0.155, 0.117, 0.138], [4.828, 3.122, 2.147]),
    ("Cu", [0.200, 0.924, 1.102], [3.912, 2.452, 2.142]),
    ("Al", [1.657, 0.880, 0.521], [9.224, 6.270, 4.837]),
];

fn named_conductor(name: &str) -> Option<(Vec3, Vec3)> {
    CONDUCTORS
        .iter()
        .find(|c| c.0.eq_ignore_ascii_case(name))
        .map(|c| (Vec3::from_array(c.1), Vec3::from_array(c.2)))
}
