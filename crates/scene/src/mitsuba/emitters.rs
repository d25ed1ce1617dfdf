//! Mitsuba emitter plugins: `area` (on shapes), `point`, `spot`, `projector`, `directional`,
//! `constant`, `envmap`.

use super::{mat4, sensors, Ctx, Obj};
use crate::spectrum::SpectrumKind;
use crate::Error;
use glam::{DVec3, Mat3, Vec3};
use pathlab_render::desc::*;

/// An area emitter's radiance: a constant, or a texture over the shape's (u, v).
pub(super) fn area_radiance(ctx: &mut Ctx, e: Obj) -> Result<(Vec3, Option<TextureDesc>), Error> {
    let t = ctx.texture(e, "radiance", Vec3::ONE, SpectrumKind::Emission)?;
    Ok(match t {
        TextureDesc::Constant(c) => (c, None),
        texture => (Vec3::ONE, Some(texture)),
    })
}

/// The position and orthonormal frame (columns: local x, y, z in world space) of an emitter's
/// `to_world`.
fn placement(ctx: &Ctx, e: Obj) -> Result<(Vec3, Mat3), Error> {
    let m = ctx.transform(e, "to_world")?;
    let origin = m.transform_point3(DVec3::ZERO);
    let z = m.transform_vector3(DVec3::Z).normalize_or(DVec3::Z);
    let y0 = m.transform_vector3(DVec3::Y);
    let x = y0.cross(z).normalize_or(z.any_orthonormal_vector());
    let y = z.cross(x);
    let _ = mat4;
    Ok((
        origin.as_vec3(),
        Mat3::from_cols(x.as_vec3(), y.as_vec3(), z.as_vec3()),
    ))
}

/// The emitter `e` (not on a shape), added to the scene.
pub(super) fn emitter(ctx: &mut Ctx, e: Obj) -> Result<(), Error> {
    match e.plugin {
        "point" => {
            let (origin, _) = placement(ctx, e)?;
            let position = match ctx.vector(e, "position")? {
                Some(p) => p.as_vec3(),
                None => origin,
            };
            let intensity = ctx.color(e, "intensity", Vec3::ONE, SpectrumKind::Emission)?;
            ctx.desc.point_lights.push(PointLightDesc {
                position,
                intensity,
                attenuation: INVERSE_SQUARE,
            });
        }
        "spot" => {
            let (position, frame) = placement(ctx, e)?;
            let intensity = ctx.color(e, "intensity", Vec3::ONE, SpectrumKind::Emission)?;
            let texture = ctx
                .opt_texture(e, "texture", SpectrumKind::Emission)?
                .unwrap_or(TextureDesc::Constant(Vec3::ONE));
            let cutoff = ctx.positive(e, "cutoff_angle", 20.0)?;
            let beam = ctx.float(e, "beam_width", cutoff * 0.75)?;
            if !(beam > 0.0 && beam <= cutoff && cutoff < 90.0) {
                return Err(ctx.error(
                    e.loc,
                    format!("<emitter type=\"spot\">: need 0 < beam_width ({beam}) <= cutoff_angle ({cutoff}) < 90"),
                ));
            }
            ctx.desc.projectors.push(ProjectorDesc {
                position,
                frame,
                texture,
                kind: ProjectorKind::Spot {
                    intensity,
                    cutoff: (cutoff as f32).to_radians(),
                    beam_width: (beam as f32).to_radians(),
                    falloff: SpotFalloff::LinearInAngle,
                },
            });
        }
        "projector" => {
            let (position, frame) = placement(ctx, e)?;
            let texture = ctx.texture(e, "irradiance", Vec3::ONE, SpectrumKind::Emission)?;
            let (w, h) = match &texture {
                TextureDesc::Image { image, .. } => {
                    let (w, h) = image.size();
                    (w as f64, h as f64)
                }
                _ => (1.0, 1.0),
            };
            let aspect = w / h;
            let fov_x = sensors::fov_x(ctx, e, aspect)?;
            let scale = ctx.non_negative(e, "scale", 1.0)? as f32;
            ctx.desc.projectors.push(ProjectorDesc {
                position,
                frame,
                texture,
                kind: ProjectorKind::Projector {
                    scale,
                    tan_half_fov_x: (0.5 * fov_x.to_radians()).tan() as f32,
                    aspect: aspect as f32,
                },
            });
        }
        "directional" => {
            let (_, frame) = placement(ctx, e)?;
            let direction = match ctx.vector(e, "direction")? {
                Some(d) => d.as_vec3(),
                None => frame.z_axis,
            };
            let Some(direction) = direction.try_normalize() else {
                return Err(ctx.error(
                    e.loc,
                    "<emitter type=\"directional\">: the direction is zero",
                ));
            };
            let irradiance = ctx.color(e, "irradiance", Vec3::ONE, SpectrumKind::Emission)?;
            ctx.desc.directional_lights.push(DirectionalLightDesc {
                direction,
                irradiance,
            });
        }
        "constant" => {
            let r = ctx.color(e, "radiance", Vec3::ONE, SpectrumKind::Emission)?;
            ctx.desc.environment = Some(ctx.desc.environment.unwrap_or(Vec3::ZERO) + r);
        }
        "envmap" => {
            let path = ctx.file(e, "filename")?;
            let m = ctx.transform(e, "to_world")?;
            let scale = ctx.float(e, "scale", 1.0)? as f32;
            ctx.accept(e, &["filter_type", "mis_compensation"]);
            let map = crate::envmap::load(&path, Mat3::from_mat4(m.as_mat4()), scale)
                .map_err(|err| ctx.file_error(e, "filename", err))?;
            if ctx.desc.environment_map.is_some() {
                ctx.warn(e.loc, "more than one envmap: pathlab uses the last");
            }
            ctx.desc.environment_map = Some(map);
        }
        "area" => {
            return Err(ctx.error(e.loc, "<emitter type=\"area\"> must be nested in a <shape>"));
        }
        other => {
            let what = ctx.what(e);
            ctx.warn(
                e.loc,
                format!("{what} is not supported by pathlab; skipped"),
            );
            ctx.accept_all(e);
            let _ = other;
        }
    }
    Ok(())
}
