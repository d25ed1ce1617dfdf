//! Mitsuba textures: `bitmap` (`filter_type`, `wrap_mode`, `raw`, `to_uv`), `checkerboard`,
//! `mesh_attribute`, and the constants `rawconstant`, `srgb`, `uniform`, `d65`, `blackbody`.
//!
//! Mitsuba's (u, v) has v growing downwards from the image's top row; pathlab's grows upwards
//! (OBJ). Mitsuba's OBJ and PLY loaders flip v, so a mesh's pathlab coordinates are Mitsuba's
//! with v flipped, F(u, v) = (u, 1 - v); a texture's `to_uv` is conjugated by F accordingly.

use super::{Ctx, Obj};
use crate::spectrum::{blackbody_to_rgb, SpectrumKind};
use crate::Error;
use glam::{Affine2, DMat4, Mat2, Vec2, Vec3};
use pathlab_render::desc::{TextureDesc, TextureFilter, WrapMode};

/// F: Mitsuba's (u, v) to pathlab's and back.
const FLIP_V: Affine2 = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);

/// A Mitsuba `to_uv` transform (a 4×4 matrix whose 2D part acts on (u, v)).
fn affine2(m: DMat4) -> Affine2 {
    let m = m.as_mat4();
    Affine2::from_mat2_translation(
        Mat2::from_cols(
            m.x_axis.truncate().truncate(),
            m.y_axis.truncate().truncate(),
        ),
        m.w_axis.truncate().truncate(),
    )
}

/// The value of a constant texture object, or `None` for a varying one.
pub(super) fn constant(ctx: &mut Ctx, t: Obj, kind: SpectrumKind) -> Result<Option<Vec3>, Error> {
    let c = match t.plugin {
        "srgb" | "d65" => Some(ctx.color(t, "color", Vec3::ONE, kind)?),
        "uniform" => Some(Vec3::splat(ctx.float(t, "value", 1.0)? as f32)),
        "rawconstant" => Some(match ctx.vector(t, "value")? {
            Some(v) => v.as_vec3(),
            None => Vec3::splat(ctx.float(t, "value", 1.0)? as f32),
        }),
        "blackbody" => {
            let kelvin = ctx.positive(t, "temperature", 6504.0)?;
            let scale = ctx.float(t, "scale", 1.0)?;
            Some((blackbody_to_rgb(kelvin) * scale).as_vec3())
        }
        _ => None,
    };
    if c.is_some() {
        ctx.accept(t, &["unbounded"]);
    }
    Ok(c)
}

/// A texture object as a [`TextureDesc`].
pub(super) fn texture(ctx: &mut Ctx, t: Obj, kind: SpectrumKind) -> Result<TextureDesc, Error> {
    if let Some(c) = constant(ctx, t, kind)? {
        return Ok(TextureDesc::Constant(c));
    }
    match t.plugin {
        "bitmap" => {
            let path = ctx.file(t, "filename")?;
            let raw = ctx.boolean(t, "raw", false)?;
            let filter = match ctx.choice(t, "filter_type", &["bilinear", "nearest"])? {
                "nearest" => TextureFilter::Nearest,
                _ => TextureFilter::Bilinear,
            };
            let wrap = match ctx.choice(t, "wrap_mode", &["repeat", "mirror", "clamp"])? {
                "mirror" => WrapMode::Mirror,
                "clamp" => WrapMode::Clamp,
                _ => WrapMode::Repeat,
            };
            let to_uv = affine2(ctx.transform(t, "to_uv")?);
            // The pixel layout of the evaluation (`format`) and the lookup structure
            // (`accel`) change nothing in an RGB render.
            ctx.accept(t, &["format", "accel"]);
            let image =
                crate::texture::load(&path, raw).map_err(|e| ctx.file_error(t, "filename", e))?;
            Ok(TextureDesc::Image {
                image,
                filter,
                wrap,
                to_uv: FLIP_V * to_uv * FLIP_V,
            })
        }
        "checkerboard" => {
            let color0 = ctx.color(t, "color0", Vec3::splat(0.4), kind)?;
            let color1 = ctx.color(t, "color1", Vec3::splat(0.2), kind)?;
            let to_uv = affine2(ctx.transform(t, "to_uv")?);
            Ok(TextureDesc::Checkerboard {
                color0,
                color1,
                to_uv: to_uv * FLIP_V,
            })
        }
        "mesh_attribute" => {
            let name = ctx.string(t, "name")?.ok_or_else(|| {
                ctx.error(
                    t.loc,
                    "<texture type=\"mesh_attribute\">: expected a 'name' string",
                )
            })?;
            if !(name.starts_with("vertex_") || name.starts_with("face_")) {
                return Err(ctx.error(
                    t.loc,
                    format!(
                        "<texture type=\"mesh_attribute\">: attribute '{name}' must start with vertex_ or face_"
                    ),
                ));
            }
            let scale = ctx.float(t, "scale", 1.0)?;
            if scale != 1.0 {
                ctx.warn(
                    t.loc,
                    "<texture type=\"mesh_attribute\">: 'scale' is not supported; using 1",
                );
            }
            Ok(TextureDesc::MeshAttribute { name })
        }
        other => {
            let what = format!("<{} type=\"{other}\">", t.class);
            ctx.warn(
                t.loc,
                format!("{what} is not supported by pathlab; using a constant 0.5"),
            );
            ctx.accept_all(t);
            Ok(TextureDesc::value(0.5))
        }
    }
}
