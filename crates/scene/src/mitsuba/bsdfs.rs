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

/// A dielectric's `specular_reflectance` and `specular_transmittance` scales (default 1).
fn specular_scales(ctx: &mut Ctx, b: Obj) -> Result<(Vec3, Vec3), Error> {
    let mut scale = |name: &str| ctx.color(b, name, Vec3::ONE, SpectrumKind::Reflectance);
    Ok((
        scale("specular_reflectance")?,
        scale("specular_transmittance")?,
    ))
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

/// The one nested BSDF of `b`.
fn one_nested<'t>(ctx: &Ctx<'t>, b: Obj) -> Result<Obj<'t>, Error> {
    let n = nested(ctx, b)?;
    match n.as_slice() {
        [one] => Ok(*one),
        _ => Err(ctx.error(
            b.loc,
            format!(
                "{} needs exactly one nested <bsdf>, found {}",
                ctx.what(b),
                n.len()
            ),
        )),
    }
}

/// The nested BSDFs of `b`.
fn nested<'t>(ctx: &Ctx<'t>, b: Obj) -> Result<Vec<Obj<'t>>, Error> {
    Ok(ctx
        .children(b, "bsdf")?
        .into_iter()
        .map(|(_, o)| o)
        .collect())
}

/// A rough model's α along u and v, each a number or a texture: `alpha`, or `alpha_u` and
/// `alpha_v` (Mitsuba's default 0.1 each).
fn alphas(ctx: &mut Ctx, b: Obj) -> Result<(TextureDesc, TextureDesc), Error> {
    let alpha = |ctx: &mut Ctx, name| {
        let t = ctx.texture(b, name, Vec3::splat(0.1), SpectrumKind::Unbounded)?;
        if let Some(a) = t.as_constant() {
            non_negative_alpha(ctx, b, name, a.x)?;
        }
        Ok(t)
    };
    if ctx.has(b, "alpha_u") || ctx.has(b, "alpha_v") {
        if ctx.has(b, "alpha") {
            return Err(ctx.error(
                b.loc,
                format!("{}: give either alpha or alpha_u and alpha_v", ctx.what(b)),
            ));
        }
        return Ok((alpha(ctx, "alpha_u")?, alpha(ctx, "alpha_v")?));
    }
    let a = alpha(ctx, "alpha")?;
    Ok((a.clone(), a))
}

/// An error at property `name` of `b` unless the roughness `a` (an α, or the principled
/// model's roughness) is a number ≥ 0 (Mitsuba gives no meaning to a negative one; it is not
/// taken as smooth).
fn non_negative_alpha(ctx: &Ctx, b: Obj, name: &str, a: f32) -> Result<(), Error> {
    if a >= 0.0 && a.is_finite() {
        return Ok(());
    }
    Err(ctx.error(
        ctx.loc_of(b, name),
        format!("{}: {name} must be a number >= 0, got {a}", ctx.what(b)),
    ))
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
        "twosided" => two_sided_bsdf(ctx, b)?,
        "mask" => {
            let inner = one_nested(ctx, b)?;
            MaterialDesc::Mask {
                opacity: ctx.texture(b, "opacity", Vec3::splat(0.5), SpectrumKind::Unbounded)?,
                inner: Box::new(ctx.material_desc(inner)?),
            }
        }
        "blendbsdf" => {
            let inner = nested(ctx, b)?;
            let [first, second] = inner.as_slice() else {
                return Err(ctx.error(
                    b.loc,
                    format!(
                        "<bsdf type=\"blendbsdf\"> needs two nested <bsdf>s, found {}",
                        inner.len()
                    ),
                ));
            };
            MaterialDesc::Blend {
                weight: ctx.texture(b, "weight", Vec3::splat(0.5), SpectrumKind::Unbounded)?,
                first: Box::new(ctx.material_desc(*first)?),
                second: Box::new(ctx.material_desc(*second)?),
            }
        }
        "normalmap" => {
            let inner = one_nested(ctx, b)?;
            let normals = ctx
                .opt_texture(b, "normalmap", SpectrumKind::Unbounded)?
                .ok_or_else(|| {
                    ctx.error(
                        b.loc,
                        "<bsdf type=\"normalmap\"> needs a 'normalmap' texture",
                    )
                })?;
            MaterialDesc::NormalMap {
                normals,
                inner: Box::new(ctx.material_desc(inner)?),
            }
        }
        "bumpmap" => bump_map(ctx, b)?,
        "conductor" | "roughconductor" => conductor(ctx, b)?,
        "principled" | "principledthin" => principled(ctx, b)?,
        "roughplastic" => rough_plastic(ctx, b)?,
        "thindielectric" => {
            let (reflectance, transmittance) = specular_scales(ctx, b)?;
            MaterialDesc::ThinGlass {
                reflectance,
                transmittance,
                ior: relative_ior(ctx, b, BK7)?,
            }
        }
        "dielectric" | "roughdielectric" => dielectric(ctx, b)?,
        "plastic" => MaterialDesc::Plastic {
            specular: ctx.color(
                b,
                "specular_reflectance",
                Vec3::ONE,
                SpectrumKind::Reflectance,
            )?,
            diffuse: ctx.color(
                b,
                "diffuse_reflectance",
                Vec3::splat(0.5),
                SpectrumKind::Reflectance,
            )?,
            ior: relative_ior(ctx, b, 1.49)?,
            nonlinear: ctx.boolean(b, "nonlinear", false)?,
        },
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

/// Mitsuba's `twosided`: one nested BSDF on both sides, or a front and a back one.
fn two_sided_bsdf(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let inner = nested(ctx, b)?;
    Ok(match inner.as_slice() {
        [one] => two_sided(ctx.material_desc(*one)?),
        [front, back] => MaterialDesc::TwoSided {
            front: Box::new(ctx.material_desc(*front)?),
            back: Box::new(ctx.material_desc(*back)?),
        },
        _ => {
            return Err(ctx.error(
                b.loc,
                format!(
                    "<bsdf type=\"twosided\"> needs one or two nested <bsdf>s, found {}",
                    inner.len()
                ),
            ))
        }
    })
}

/// Mitsuba's `bumpmap`: the nested BSDF under the normal that the nested height texture perturbs.
fn bump_map(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let inner = one_nested(ctx, b)?;
    // The height texture is the nested texture, whatever its name.
    let textures = ctx.children(b, "texture")?;
    let [(_, t)] = textures.as_slice() else {
        return Err(ctx.error(
            b.loc,
            format!(
                "<bsdf type=\"bumpmap\"> needs one nested <texture>, found {}",
                textures.len()
            ),
        ));
    };
    let height = super::textures::texture(ctx, *t, SpectrumKind::Unbounded)?;
    Ok(MaterialDesc::BumpMap {
        height,
        scale: ctx.float(b, "scale", 1.0)? as f32,
        inner: Box::new(ctx.material_desc(inner)?),
    })
}

/// Mitsuba's `conductor` and `roughconductor`: a named metal or `eta` and `k`, and the roughness of the rough one (isotropic or `alpha_u`/`alpha_v`).
fn conductor(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
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
    let specular = ctx.texture(
        b,
        "specular_reflectance",
        Vec3::ONE,
        SpectrumKind::Reflectance,
    )?;
    Ok(if b.plugin == "conductor" {
        MaterialDesc::RoughConductor {
            alpha_u: TextureDesc::value(0.0),
            alpha_v: TextureDesc::value(0.0),
            eta,
            k,
            specular,
            distribution: NormalDistribution::Beckmann,
        }
    } else {
        let distribution = distribution(ctx, b)?;
        let (alpha_u, alpha_v) = alphas(ctx, b)?;
        MaterialDesc::RoughConductor {
            alpha_u,
            alpha_v,
            eta,
            k,
            specular,
            distribution,
        }
    })
}

/// Mitsuba's `dielectric` and `roughdielectric`: glass of one roughness, or of roughness that
/// is textured or differs along u and v.
fn dielectric(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let ((alpha_u, alpha_v), distribution) = if b.plugin == "roughdielectric" {
        (alphas(ctx, b)?, distribution(ctx, b)?)
    } else {
        let smooth = TextureDesc::value(0.0);
        ((smooth.clone(), smooth), NormalDistribution::Beckmann)
    };
    let (reflectance, transmittance) = specular_scales(ctx, b)?;
    let ior = relative_ior(ctx, b, BK7)?;
    Ok(match (alpha_u.as_constant(), alpha_v.as_constant()) {
        (Some(u), Some(v)) if u == v => MaterialDesc::Glass {
            reflectance,
            transmittance,
            roughness: u.x,
            ior,
            distribution,
            fresnel: FresnelModel::Exact,
        },
        _ => MaterialDesc::RoughGlass {
            alpha_u,
            alpha_v,
            ior,
            distribution,
            reflectance,
            transmittance,
        },
    })
}

/// Mitsuba's `roughplastic` (its roughness a number: Mitsuba takes no texture there).
fn rough_plastic(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let alpha = ctx.texture(b, "alpha", Vec3::splat(0.1), SpectrumKind::Unbounded)?;
    let Some(alpha) = alpha.as_constant() else {
        return Err(ctx.error(
        ctx.loc_of(b, "alpha"),
        "<bsdf type=\"roughplastic\">: alpha must be a number (Mitsuba's roughplastic takes no roughness texture)",
    ));
    };
    non_negative_alpha(ctx, b, "alpha", alpha.x)?;
    Ok(MaterialDesc::RoughPlastic {
        diffuse: ctx.texture(
            b,
            "diffuse_reflectance",
            Vec3::splat(0.5),
            SpectrumKind::Reflectance,
        )?,
        specular: ctx.color(
            b,
            "specular_reflectance",
            Vec3::ONE,
            SpectrumKind::Reflectance,
        )?,
        alpha: alpha.x,
        ior: relative_ior(ctx, b, 1.49)?,
        nonlinear: ctx.boolean(b, "nonlinear", false)?,
        distribution: distribution(ctx, b)?,
    })
}

/// Mitsuba's `principled` and `principledthin`: optional parameters switch their lobes on
/// when given (and not the number 0).
fn principled(ctx: &mut Ctx, b: Obj) -> Result<MaterialDesc, Error> {
    let thin = b.plugin == "principledthin";
    let opt = |ctx: &mut Ctx, name: &str| -> Result<Option<TextureDesc>, Error> {
        if ctx.is_zero(b, name) {
            ctx.accept(b, &[name]);
            return Ok(None);
        }
        ctx.opt_texture(b, name, SpectrumKind::Unbounded)
    };
    let anisotropic = opt(ctx, "anisotropic")?;
    let spec_trans = opt(ctx, "spec_trans")?;
    let sheen = opt(ctx, "sheen")?;
    let sheen_tint = opt(ctx, "sheen_tint")?;
    let spec_tint = opt(ctx, "spec_tint")?;
    let flatness = opt(ctx, "flatness")?;
    let (metallic, clearcoat, diff_trans) = if thin {
        (None, None, opt(ctx, "diff_trans")?)
    } else {
        (opt(ctx, "metallic")?, opt(ctx, "clearcoat")?, None)
    };
    let rates: &[&str] = if thin {
        &[
            "specular_reflectance_sampling_rate",
            "specular_transmittance_sampling_rate",
            "diffuse_transmittance_sampling_rate",
            "diffuse_reflectance_sampling_rate",
        ]
    } else {
        &[
            "main_specular_sampling_rate",
            "clearcoat_sampling_rate",
            "diffuse_reflectance_sampling_rate",
        ]
    };
    for rate in rates {
        if ctx.float(b, rate, 1.0)? != 1.0 {
            ctx.warn(
                ctx.loc_of(b, rate),
                format!(
                    "{}: '{rate}' is not supported; pathlab samples at rate 1",
                    ctx.what(b)
                ),
            );
        }
    }
    let eta = if thin {
        ctx.texture(b, "eta", Vec3::splat(1.5), SpectrumKind::Unbounded)?
    } else if ctx.has(b, "eta") {
        if ctx.has(b, "specular") {
            return Err(ctx.error(
                b.loc,
                "<bsdf type=\"principled\">: give either eta or specular",
            ));
        }
        TextureDesc::value(ctx.positive(b, "eta", 1.5)? as f32)
    } else {
        let mut specular = ctx.float(b, "specular", 0.5)? as f32;
        if spec_trans.is_some() && specular == 0.0 {
            specular = 1e-3;
        }
        TextureDesc::value(2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0)
    };
    let roughness = ctx.texture(b, "roughness", Vec3::splat(0.5), SpectrumKind::Unbounded)?;
    if let Some(r) = roughness.as_constant() {
        non_negative_alpha(ctx, b, "roughness", r.x)?;
    }
    Ok(MaterialDesc::Principled(Box::new(PrincipledDesc {
        base_color: ctx.texture(b, "base_color", Vec3::splat(0.5), SpectrumKind::Reflectance)?,
        roughness,
        anisotropic,
        spec_trans,
        metallic,
        clearcoat,
        clearcoat_gloss: if thin {
            TextureDesc::value(0.0)
        } else {
            ctx.texture(b, "clearcoat_gloss", Vec3::ZERO, SpectrumKind::Unbounded)?
        },
        sheen,
        sheen_tint,
        spec_tint,
        flatness,
        diff_trans,
        eta,
        thin,
    })))
}

/// Mitsuba's `twosided` around one BSDF: a diffuse one reflects on both sides, any other
/// reflective one is the same material on its back as on its front.
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
        // Transmission has no back side to mirror (Mitsuba refuses it there).
        m @ (MaterialDesc::Glass { .. }
        | MaterialDesc::ThinGlass { .. }
        | MaterialDesc::RoughGlass { .. }
        | MaterialDesc::DiffuseTransmission { .. }) => m,
        // The same material seen from behind as from the front.
        other => MaterialDesc::on_both_sides(other),
    }
}

impl<'t> Ctx<'t> {
    /// The material a BSDF object describes, without adding it to the scene.
    pub(super) fn material_desc(&mut self, b: Obj) -> Result<MaterialDesc, Error> {
        bsdf(self, b)
    }

    /// Whether property `name` of `o` is the number 0 (which Mitsuba's principled BSDFs take
    /// as the parameter not being given).
    pub(super) fn is_zero(&self, o: Obj, name: &str) -> bool {
        self.tree.nodes[o.index].props.iter().any(|p| {
            p.name == name
                && matches!(p.value, Value::Float(v) if v == 0.0) | matches!(p.value, Value::Int(0))
        })
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
