//! pbrt-v4's `Texture` directive: `constant`, `imagemap` (with its encoding, filter, wrap, uv
//! mapping, scale and invert), `scale`, `mix`, `bilerp` and 2D `checkerboard` textures, each
//! kept by name for the materials that use it.

use super::params::ParamList;
use super::spectra::Use;
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
            "constant" => TextureDesc::Constant(self.value_of_type(&params, "value", ty, 1.0)?),
            "imagemap" => self.image_texture(&name, ty, &params)?,
            "scale" => {
                let tex = self.texture_or_value(&params, "tex", ty, 1.0)?;
                // pbrt-v4: the scale is a float texture for either type.
                let scale = self.texture_or_value(&params, "scale", "float", 1.0)?;
                tex.product(scale)
            }
            "mix" => {
                let first = self.texture_or_value(&params, "tex1", ty, 0.0)?;
                let second = self.texture_or_value(&params, "tex2", ty, 1.0)?;
                let amount = self.texture_or_value(&params, "amount", "float", 0.5)?;
                TextureDesc::mix(amount, first, second)
            }
            "checkerboard" => self.checkerboard(&name, ty, &params)?,
            "bilerp" => {
                // pbrt-v4's defaults: 0 along t = 0 and 1 along t = 1.
                let mut corner =
                    |key: &str, default: f32| self.value_of_type(&params, key, ty, default);
                let corners = [
                    corner("v00", 0.0)?,
                    corner("v10", 0.0)?,
                    corner("v01", 1.0)?,
                    corner("v11", 1.0)?,
                ];
                let to_uv = self.uv_mapping(&name, &params)?;
                TextureDesc::Bilerp { corners, to_uv }
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
            Some("black") => WrapMode::Black,
            _ => WrapMode::Repeat,
        };
        let to_uv = self.uv_mapping(name, params)?;
        Ok(match crate::texture::load(&path, raw) {
            Ok(image) => {
                // pbrt-v4: the texel times scale, then inverted.
                let t = TextureDesc::Image {
                    image,
                    filter,
                    wrap,
                    to_uv,
                }
                .scaled(scale);
                if invert {
                    t.inverted()
                } else {
                    t
                }
            }
            Err(e) => {
                self.warn(format!("Texture \"{name}\": {e}; a constant 0.5 is used"));
                TextureDesc::value(0.5)
            }
        })
    }

    /// A texture parameter or a value of the texture's type (`default` where absent).
    pub(super) fn texture_or_value(
        &mut self,
        params: &ParamList,
        name: &str,
        ty: &str,
        default: f32,
    ) -> Result<TextureDesc, Error> {
        if params
            .params
            .iter()
            .any(|p| p.name == name && p.ty == "texture")
        {
            return self.color_texture(params, name, Rgb::splat(default));
        }
        Ok(TextureDesc::Constant(
            self.value_of_type(params, name, ty, default)?,
        ))
    }

    /// Parameter `name` as a value of the texture's type: a number (grey) for a `float`
    /// texture, a spectrum otherwise; `default` where absent.
    fn value_of_type(
        &mut self,
        params: &ParamList,
        name: &str,
        ty: &str,
        default: f32,
    ) -> Result<Rgb, Error> {
        Ok(if ty == "float" {
            Rgb::splat(self.float(params, name, default as f64)? as f32)
        } else {
            self.spectrum(params, name, Use::Albedo)?
                .unwrap_or(Rgb::splat(default))
        })
    }

    /// pbrt-v4's 2D `checkerboard`: `tex1` (default 1) where ⌊s⌋ + ⌊t⌋ is even, `tex2` (default
    /// 0) elsewhere, (s, t) being the uv mapping's coordinates.
    fn checkerboard(
        &mut self,
        name: &str,
        ty: &str,
        params: &ParamList,
    ) -> Result<TextureDesc, Error> {
        let dimension = self.float(params, "dimension", 2.0)?;
        if dimension != 2.0 {
            self.warn(format!("Texture \"{name}\": a {dimension}D checkerboard is not supported; the 2D one is used"));
        }
        let first = self.texture_or_value(params, "tex1", ty, 1.0)?;
        let second = self.texture_or_value(params, "tex2", ty, 0.0)?;
        let to_st = self.uv_mapping(name, params)?;
        // The checkerboard's colour0 lies where the fractional parts of both coordinates are
        // on the same side of ½: at half the (s, t) scale, where ⌊s⌋ + ⌊t⌋ is even.
        let to_uv = glam::Affine2::from_scale(glam::Vec2::splat(0.5)) * to_st;
        Ok(match (first.as_constant(), second.as_constant()) {
            (Some(color0), Some(color1)) => TextureDesc::Checkerboard {
                color0,
                color1,
                to_uv,
            },
            _ => TextureDesc::mix(
                TextureDesc::Checkerboard {
                    color0: Rgb::ZERO,
                    color1: Rgb::ONE,
                    to_uv,
                },
                first,
                second,
            ),
        })
    }

    /// pbrt-v4's `uv` texture mapping: (s, t) = (uscale u + udelta, vscale v + vdelta); other
    /// mappings are warned about and read as it.
    fn uv_mapping(&mut self, name: &str, params: &ParamList) -> Result<glam::Affine2, Error> {
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
        Ok(glam::Affine2::from_scale_angle_translation(
            glam::Vec2::new(su, sv),
            0.0,
            glam::Vec2::new(du, dv),
        ))
    }
}
