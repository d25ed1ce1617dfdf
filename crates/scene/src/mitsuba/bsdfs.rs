//! Mitsuba BSDF plugins as pathlab materials.

use super::ior::{conductor_names, named_conductor, named_ior};
use super::parse::Value;
use super::{Ctx, Obj};
use crate::spectrum::SpectrumKind;
use crate::Error;
use glam::Vec3;
use pathlab_render::desc::*;

/// Mitsuba's default relative index of `dielectric`: bk7 in air.
const BK7: f32 = 1.5046;
const AIR: f32 = 1.000277;

/// An index of refraction property: a number or one of Mitsuba's names.
pub(super) fn ior(ctx: &Ctx, b: Obj, name: &str, default: f32) -> Result<f32, Error> {
    if let Some(s) = ctx.string_or_none(b, name)? {
        return named_ior(&s).ok_or_else(|| {
            ctx.error(
                ctx.loc_of(b, name),
                format!(
                    "{}: unknown index of refraction '{s}' (known: {})",
                    ctx.what(b),
                    super::ior::NAMED_IORS
                        .iter()
                        .map(|n| n.0)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        });
    }
    let v = ctx.float(b, name, default as f64)? as f32;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(ctx.error(
            ctx.loc_of(b, name),
            format!("{}: {name} must be positive, got {v}", ctx.what(b)),
        ))
    }
}

/// `int_ior / ext_ior`.
fn relative_ior(ctx: &Ctx, b: Obj, int_default: f32) -> Result<f32, Error> {
    Ok(ior(ctx, b, "int_ior", int_default)? / ior(ctx, b, "ext_ior", AIR)?)
}

fn distribution(ctx: &Ctx, b: Obj) -> Result<NormalDistribution, Error> {
    // Visible-normal sampling changes the noise, not the image.
    ctx.accept(b, &["sample_visible"]);
    Ok(match ctx.choice(b, "distribution", &["beckmann", "ggx"])? {
        "ggx" => NormalDistribution::Ggx,
        _ => NormalDistribution::Beckmann,
    })
}

/// The nested BSDFs of `b`.
fn nested<'t>(ctx: &Ctx<'t>, b: Obj) -> Result<Vec<Obj<'t>>, Error> {
    Ok(ctx
        .children(b, "bsdf")?
        .into_iter()
        .map(|(_, o)| o)
        .collect())
}

/// Roughness α (isotropic) of a rough model.
fn alpha(ctx: &mut Ctx, b: Obj) -> Result<f32, Error> {
    if ctx.has(b, "alpha_u") || ctx.has(b, "alpha_v") {
        ctx.warn(
            b.loc,
            format!(
                "{}: anisotropic roughness is drawn with alpha_u only",
                ctx.what(b)
            ),
        );
        let a = ctx.float(b, "alpha_u", 0.1)? as f32;
        ctx.accept(b, &["alpha_v"]);
        return Ok(a);
    }
    Ok(ctx.float(b, "alpha", 0.1)? as f32)
}

/// The material for BSDF object `b`.
pub(super) fn bsdf(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let m = match b.plugin {
        "diffuse" => {
            let t = ctx.texture(
                b,
                "reflectance",
                Vec3::splat(0.5),
                SpectrumKind::Reflectance,
            )?;
            match t {
                TextureDesc::Constant(c) => MaterialDesc::Diffuse {
                    reflectance: c,
                    two_sided: false,
                },
                texture => MaterialDesc::TexturedDiffuse {
                    texture,
                    scale: Vec3::ONE,
                    two_sided: false,
                },
            }
        }
        "twosided" => {
            let inner = nested(ctx, b)?;
            match inner.as_slice() {
                [one] => two_sided(ctx.material_desc(*one)?),
                [front, _back] => {
                    ctx.warn(
                        b.loc,
                        "<bsdf type=\"twosided\"> with two BSDFs: the back side is drawn with the front's",
                    );
                    two_sided(ctx.material_desc(*front)?)
                }
                _ => {
                    return Err(ctx.error(
                        b.loc,
                        format!(
                            "<bsdf type=\"twosided\"> needs one or two nested <bsdf>s, found {}",
                            inner.len()
                        ),
                    ))
                }
            }
        }
        "conductor" | "roughconductor" => {
            let (mut eta, mut k) = (Vec3::ZERO, Vec3::ONE);
            if let Some(name) = ctx.string(b, "material")? {
                let (e, kk) = named_conductor(&name).ok_or_else(|| {
                    ctx.error(
                        ctx.loc_of(b, "material"),
                        format!(
                            "{}: unknown conductor material '{name}' (known: {}; or give eta and k)",
                            ctx.what(b),
                            conductor_names()
                        ),
                    )
                })?;
                (eta, k) = (Vec3::from_array(e), Vec3::from_array(kk));
            }
            let eta = ctx.color(b, "eta", eta, SpectrumKind::Unbounded)?;
            let k = ctx.color(b, "k", k, SpectrumKind::Unbounded)?;
            let specular = ctx.color(
                b,
                "specular_reflectance",
                Vec3::ONE,
                SpectrumKind::Reflectance,
            )?;
            if specular != Vec3::ONE {
                ctx.warn(
                    b.loc,
                    format!(
                        "{}: specular_reflectance is not supported yet; using 1",
                        ctx.what(b)
                    ),
                );
            }
            let (alpha, distribution) = if b.plugin == "conductor" {
                (0.0, NormalDistribution::Beckmann)
            } else {
                (alpha(ctx, b)?, distribution(ctx, b)?)
            };
            MaterialDesc::Conductor {
                alpha,
                eta,
                k,
                distribution,
            }
        }
        "dielectric" | "roughdielectric" | "thindielectric" => {
            if b.plugin == "thindielectric" {
                ctx.warn(
                    b.loc,
                    "<bsdf type=\"thindielectric\"> is drawn as a solid dielectric",
                );
            }
            let (roughness, distribution) = if b.plugin == "roughdielectric" {
                (alpha(ctx, b)?, distribution(ctx, b)?)
            } else {
                (0.0, NormalDistribution::Beckmann)
            };
            MaterialDesc::Glass {
                reflectance: ctx.color(
                    b,
                    "specular_reflectance",
                    Vec3::ONE,
                    SpectrumKind::Reflectance,
                )?,
                transmittance: ctx.color(
                    b,
                    "specular_transmittance",
                    Vec3::ONE,
                    SpectrumKind::Reflectance,
                )?,
                roughness,
                ior: relative_ior(ctx, b, BK7)?,
                distribution,
                fresnel: FresnelModel::Exact,
            }
        }
        "plastic" => {
            let specular = ctx.color(
                b,
                "specular_reflectance",
                Vec3::ONE,
                SpectrumKind::Reflectance,
            )?;
            if specular != Vec3::ONE {
                ctx.warn(
                    b.loc,
                    "<bsdf type=\"plastic\">: specular_reflectance is not supported yet; using 1",
                );
            }
            MaterialDesc::Plastic {
                diffuse: ctx.color(
                    b,
                    "diffuse_reflectance",
                    Vec3::splat(0.5),
                    SpectrumKind::Reflectance,
                )?,
                ior: relative_ior(ctx, b, 1.49)?,
                nonlinear: ctx.boolean(b, "nonlinear", false)?,
            }
        }
        other => {
            let what = ctx.what(b);
            ctx.warn(
                b.loc,
                format!("{what} is not supported by pathlab yet; drawn as grey diffuse"),
            );
            ctx.accept_all(b);
            let _ = other;
            super::default_bsdf()
        }
    };
    Ok(m)
}

fn two_sided(m: MaterialDesc) -> MaterialDesc {
    match m {
        MaterialDesc::Diffuse { reflectance, .. } => MaterialDesc::Diffuse {
            reflectance,
            two_sided: true,
        },
        MaterialDesc::TexturedDiffuse { texture, scale, .. } => MaterialDesc::TexturedDiffuse {
            texture,
            scale,
            two_sided: true,
        },
        other => other,
    }
}

impl<'t> Ctx<'t> {
    /// The material a BSDF object describes, without adding it to the scene.
    pub(super) fn material_desc(&mut self, b: Obj) -> Result<MaterialDesc, Error> {
        bsdf(self, b)
    }

    /// A string property, or `None` when absent or of another type (left unused then).
    pub(super) fn string_or_none(&self, o: Obj, name: &str) -> Result<Option<String>, Error> {
        let is_string = self.tree.nodes[o.index]
            .props
            .iter()
            .any(|p| p.name == name && matches!(p.value, Value::Str(_)));
        if is_string {
            self.string(o, name)
        } else {
            Ok(None)
        }
    }

    /// Where property `name` of `o` is written (the object's location when absent).
    pub(super) fn loc_of(&self, o: Obj, name: &str) -> super::Loc {
        self.tree.nodes[o.index]
            .props
            .iter()
            .find(|p| p.name == name)
            .map_or(o.loc, |p| p.loc)
    }
}
