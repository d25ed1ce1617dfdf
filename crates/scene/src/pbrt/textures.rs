//! pbrt-v4's `Texture` directive: `constant`, `imagemap` (with its encoding, filter, wrap and
//! uv mapping), `scale` and `mix` textures, each kept by name for the materials that use it.

use super::materials::Use;
use super::params::ParamList;
use super::Builder;
use crate::Error;
use pathlab_render::desc::{Rgb, TextureDesc, TextureFilter, WrapMode};

impl Builder {
    /// `Texture "name" "spectrum"|"float" "class" ...`.
    pub(crate) fn texture(
        &mut self,
        name: String,
        ty: &str,
        class: &str,
        params: ParamList,
    ) -> Result<(), Error> {
        if ty != "spectrum" && ty != "float" && ty != "color" {
            return Err(self.error(format!(
                "Texture \"{name}\": type \"{ty}\" (expected spectrum or float)"
            )));
        }
        let tex = match class {
            "constant" => TextureDesc::Constant(if ty == "float" {
                Rgb::splat(self.float(&params, "value", 1.0)? as f32)
            } else {
                self.spectrum(&params, "value", Use::Albedo)?
                    .unwrap_or(Rgb::ONE)
            }),
            "imagemap" => self.image_texture(&name, ty, &params)?,
            "scale" => {
                let tex = self.texture_or_value(&params, "tex", ty)?;
                let scale = self.texture_or_value(&params, "scale", ty)?;
                match (tex.as_constant(), scale.as_constant()) {
                    (Some(a), Some(b)) => TextureDesc::Constant(a * b),
                    (None, Some(b)) if b == Rgb::ONE => tex,
                    (Some(a), None) if a == Rgb::ONE => scale,
                    _ => {
                        self.warn(format!("Texture \"{name}\": a scaled image is not supported; the image alone is used"));
                        if tex.as_constant().is_none() {
                            tex
                        } else {
                            scale
                        }
                    }
                }
            }
            "mix" => {
                let a = self.texture_or_value(&params, "tex1", ty)?;
                let b = self.texture_or_value(&params, "tex2", ty)?;
                let amount = self.float(&params, "amount", 0.5)? as f32;
                if a.as_constant().is_none()
                    || b.as_constant().is_none()
                    || params.has("amount")
                        && params
                            .params
                            .iter()
                            .any(|p| p.name == "amount" && p.ty == "texture")
                {
                    self.warn(format!("Texture \"{name}\": a mix of textures is not supported; their mean is used"));
                }
                TextureDesc::Constant(a.mean() * (1.0 - amount) + b.mean() * amount)
            }
            other => {
                self.warn(format!(
                    "Texture \"{name}\": \"{other}\" textures are not supported; a constant 0.5 is used"
                ));
                for p in &params.params {
                    p.used.set(true);
                }
                TextureDesc::value(0.5)
            }
        };
        self.warn_unused(&format!("Texture \"{name}\""), &params);
        self.textures.insert(name, tex);
        Ok(())
    }

    /// pbrt-v4's `imagemap` texture `name` of type `ty`: its image file (a constant 0.5, with a warning, where it cannot be read), encoding, filter, wrap and uv mapping.
    fn image_texture(
        &mut self,
        name: &str,
        ty: &str,
        params: &ParamList,
    ) -> Result<TextureDesc, Error> {
        let file = self.string(params, "filename")?.ok_or_else(|| {
            self.error(format!(
                "Texture \"{name}\": imagemap needs \"string filename\""
            ))
        })?;
        let path = self.resolve(&file);
        let encoding = self
            .string(params, "encoding")?
            .unwrap_or_else(|| "sRGB".into());
        let raw = encoding == "linear" || ty == "float" && encoding != "sRGB";
        if encoding.starts_with("gamma") {
            self.warn(format!(
                "Texture \"{name}\": encoding \"{encoding}\" read as sRGB"
            ));
        }
        let scale = self.float(params, "scale", 1.0)? as f32;
        let invert = self.bool(params, "invert", false)?;
        let filter = match self.string(params, "filter")?.as_deref() {
            Some("point") => TextureFilter::Nearest,
            _ => TextureFilter::Bilinear,
        };
        let wrap = match self.string(params, "wrap")?.as_deref() {
            Some("clamp") => WrapMode::Clamp,
            Some("black") => {
                self.warn(format!("Texture \"{name}\": wrap \"black\" read as clamp"));
                WrapMode::Clamp
            }
            _ => WrapMode::Repeat,
        };
        let su = self.float(params, "uscale", 1.0)? as f32;
        let sv = self.float(params, "vscale", 1.0)? as f32;
        let du = self.float(params, "udelta", 0.0)? as f32;
        let dv = self.float(params, "vdelta", 0.0)? as f32;
        if let Some(m) = self.string(params, "mapping")? {
            if m != "uv" {
                self.warn(format!(
                    "Texture \"{name}\": mapping \"{m}\" is not supported; uv is used"
                ));
            }
        }
        Ok(match crate::texture::load(&path, raw) {
            Ok(image) => {
                if invert || scale != 1.0 {
                    self.warn(format!("Texture \"{name}\": scale and invert of image textures are not supported; ignored"));
                }
                TextureDesc::Image {
                    image,
                    filter,
                    wrap,
                    to_uv: glam::Affine2::from_scale_angle_translation(
                        glam::Vec2::new(su, sv),
                        0.0,
                        glam::Vec2::new(du, dv),
                    ),
                }
            }
            Err(e) => {
                self.warn(format!("Texture \"{name}\": {e}; a constant 0.5 is used"));
                TextureDesc::value(0.5)
            }
        })
    }

    /// A texture parameter or a value of the texture's type (default 1).
    fn texture_or_value(
        &mut self,
        params: &ParamList,
        name: &str,
        ty: &str,
    ) -> Result<TextureDesc, Error> {
        if params
            .params
            .iter()
            .any(|p| p.name == name && p.ty == "texture")
        {
            return self.color_texture(params, name, Rgb::ONE);
        }
        Ok(TextureDesc::Constant(if ty == "float" {
            Rgb::splat(self.float(params, name, 1.0)? as f32)
        } else {
            self.spectrum(params, name, Use::Albedo)?
                .unwrap_or(Rgb::ONE)
        }))
    }
}
