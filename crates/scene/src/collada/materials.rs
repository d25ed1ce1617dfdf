//! COLLADA materials: a material's effect (the `phong`/`lambert`/`blinn` diffuse colour and
//! the course's CGL extras) and its textures.

use super::{Effect, Loader};
use crate::xml::{child, path as xpath};
use crate::Error;
use glam::Vec3;
use pathlab_render::desc::*;
use roxmltree::Node;
use std::path::Path;
use std::sync::Arc;

impl<'a, 'input> Loader<'_, 'a, 'input> {
    pub(super) fn effect(&mut self, material: Node<'a, 'input>) -> Result<Effect, Error> {
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
    pub(super) fn texture(&mut self, effect: Node, texture: Node) -> Option<Arc<Texture>> {
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
}
