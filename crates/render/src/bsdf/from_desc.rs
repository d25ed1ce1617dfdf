//! What a scene's [`MaterialDesc`] becomes: a [`Material`] tree whose leaves are fixed BxDFs
//! where nothing is textured, and textured models otherwise.

use super::material::PrincipledModel;
use super::rough_plastic::CoatTable;
use super::*;
use crate::desc::{CoatedBase, CoatedDesc, MaterialDesc, PrincipledDesc, Rgb, TextureDesc};
use crate::texture::Tex;
use glam::Vec3;

impl Material {
    /// The material of a description; `attribute` gives the scene's table index of a named
    /// mesh attribute its textures read.
    pub fn from_desc(d: &MaterialDesc, attribute: &mut dyn FnMut(&str) -> u32) -> Self {
        let mut tex = |t: &TextureDesc| Tex::new(t, attribute);
        match d {
            MaterialDesc::Diffuse {
                reflectance,
                two_sided,
            } => Material::new(
                Bxdf::Diffuse(Diffuse {
                    reflectance: reflectance.clamp(Vec3::ZERO, Vec3::ONE),
                }),
                *two_sided,
            ),
            MaterialDesc::TexturedDiffuse {
                texture,
                scale,
                two_sided,
            } => Material::Leaf(Leaf {
                model: Model::Diffuse {
                    texture: tex(texture),
                    scale: scale.max(Vec3::ZERO),
                },
                two_sided: *two_sided,
            }),
            MaterialDesc::Mirror { reflectance } => Material::new(
                Bxdf::Mirror(Mirror {
                    reflectance: *reflectance,
                }),
                true,
            ),
            MaterialDesc::DiffuseTransmission {
                reflectance,
                transmittance,
            } => match (reflectance.as_constant(), transmittance.as_constant()) {
                (Some(r), Some(t)) => Material::new(
                    Bxdf::DiffuseTransmission(DiffuseTransmission {
                        reflectance: r.clamp(Vec3::ZERO, Vec3::ONE),
                        transmittance: t.clamp(Vec3::ZERO, Vec3::ONE),
                    }),
                    false,
                ),
                _ => Material::Leaf(Leaf {
                    model: Model::DiffuseTransmission {
                        reflectance: tex(reflectance),
                        transmittance: tex(transmittance),
                    },
                    two_sided: false,
                }),
            },
            MaterialDesc::Coated(c) => coated(c, &mut tex),
            MaterialDesc::Glass { .. } | MaterialDesc::ThinGlass { .. } => glass(d),
            &MaterialDesc::Conductor {
                alpha,
                eta,
                k,
                distribution,
            } => conductor(eta, k, Rgb::ONE, distribution, alpha),
            MaterialDesc::RoughConductor { .. } => rough_conductor(d, &mut tex),
            MaterialDesc::RoughGlass { .. } => rough_glass(d, &mut tex),
            &MaterialDesc::Plastic {
                diffuse,
                specular,
                ior,
                nonlinear,
            } => Material::new(
                Bxdf::Plastic(
                    Plastic::new(
                        diffuse.clamp(Vec3::ZERO, Vec3::ONE),
                        usable_ior(ior),
                        nonlinear,
                    )
                    .with_specular(specular.max(Vec3::ZERO)),
                ),
                false,
            ),
            MaterialDesc::RoughPlastic { .. } => rough_plastic(d, &mut tex),
            MaterialDesc::Principled(d) => principled(d, &mut tex),
            MaterialDesc::Mask { opacity, inner } => {
                let o = tex(opacity);
                Material::Mask(o, Box::new(Material::from_desc(inner, attribute)))
            }
            MaterialDesc::Blend {
                weight,
                first,
                second,
            } => {
                let w = tex(weight);
                let a = Material::from_desc(first, attribute);
                let b = Material::from_desc(second, attribute);
                Material::Blend(w, Box::new((a, b)))
            }
            MaterialDesc::TwoSided { front, back } => {
                let a = Material::from_desc(front, attribute);
                let b = Material::from_desc(back, attribute);
                Material::TwoSided(Box::new((a, b)))
            }
            MaterialDesc::NormalMap { normals, inner } => {
                let n = tex(normals);
                Material::NormalMap(n, Box::new(Material::from_desc(inner, attribute)))
            }
            MaterialDesc::BumpMap {
                height,
                scale,
                inner,
            } => {
                let h = tex(height);
                Material::BumpMap(h, *scale, Box::new(Material::from_desc(inner, attribute)))
            }
        }
    }
}

/// A roughness α along u and v given as two textures: `Err` with the numbers where both are
/// numbers (a fixed microfacet distribution), `Ok` with the textures to read at each point.
fn numbers_or_textures(
    alpha: &[TextureDesc; 2],
    tex: &mut impl FnMut(&TextureDesc) -> Tex,
) -> Result<[Tex; 2], [f32; 2]> {
    match alpha.clone().map(|t| t.as_constant().map(|a| a.x)) {
        [Some(au), Some(av)] => Err([au, av]),
        _ => Ok(alpha.clone().map(|t| tex(&t))),
    }
}

/// A coated material: a fixed layered model where nothing is textured or anisotropic; else a
/// model whose textured parameters (base albedo, roughnesses, the medium) are read at each
/// point.
fn coated(c: &CoatedDesc, tex: &mut impl FnMut(&TextureDesc) -> Tex) -> Material {
    let roughness = |alpha: &Result<[Tex; 2], [f32; 2]>| match alpha {
        Err([au, av]) => Microfacet::unless_smooth(NormalDistribution::Ggx, *au, *av),
        Ok(_) => None,
    };
    let (base, reflectance, base_texture, base_alpha, base_anisotropic) = match &c.base {
        CoatedBase::Diffuse(t) => {
            let reflectance = t
                .as_constant()
                .unwrap_or(Rgb::ZERO)
                .clamp(Vec3::ZERO, Vec3::ONE);
            let texture = t.as_constant().is_none().then(|| tex(t));
            (Base::Diffuse, reflectance, texture, None, false)
        }
        CoatedBase::Conductor { eta, k, alpha } => {
            let textures = numbers_or_textures(alpha, tex);
            let base = Base::Conductor(Conductor {
                eta: *eta,
                k: *k,
                specular: Rgb::ONE,
                distribution: roughness(&textures),
            });
            (base, Rgb::ZERO, None, textures.ok(), alpha[0] != alpha[1])
        }
    };
    let coat_alpha = numbers_or_textures(&c.coat_alpha, tex);
    // The medium: fixed where its three parameters are numbers, else read at each point.
    let (medium, medium_textures) = match (
        c.thickness.as_constant(),
        c.albedo.as_constant(),
        c.g.as_constant(),
    ) {
        (Some(thickness), Some(albedo), Some(g)) => {
            (LayerMedium::new(thickness.x, albedo, g.x), None)
        }
        _ => (
            LayerMedium::new(1.0, Rgb::ZERO, 0.0),
            Some(Box::new([&c.thickness, &c.albedo, &c.g].map(&mut *tex))),
        ),
    };
    let stack = LayerStack {
        coat: Coat {
            eta: usable_ior(c.coat_eta),
            roughness: roughness(&coat_alpha),
        },
        base,
        medium,
        max_depth: c.max_depth.min(u16::MAX as u32) as u16,
        samples: c.samples.clamp(1, u16::MAX as u32) as u16,
    };
    let layered = Layered::new(stack, reflectance);
    let anisotropic = base_anisotropic || c.coat_alpha[0] != c.coat_alpha[1];
    let coat_alpha = coat_alpha.ok();
    if base_texture.is_none()
        && coat_alpha.is_none()
        && base_alpha.is_none()
        && medium_textures.is_none()
        && !anisotropic
    {
        return Material::new(Bxdf::Layered(layered), false);
    }
    Material::Leaf(Leaf {
        model: Model::Coated {
            layered,
            base_texture,
            coat_alpha: coat_alpha.map(Box::new),
            base_alpha: base_alpha.map(Box::new),
            medium: medium_textures,
            anisotropic,
        },
        two_sided: false,
    })
}

/// Smooth, rough or thin glass. The side matters: inside and outside differ.
fn glass(d: &MaterialDesc) -> Material {
    let bxdf = match *d {
        MaterialDesc::Glass {
            reflectance,
            transmittance,
            roughness,
            ior,
            distribution,
            fresnel: _,
        } if roughness > SMOOTH_ALPHA => Bxdf::RoughDielectric(RoughDielectric {
            eta: usable_ior(ior),
            distribution: Microfacet::new(distribution, roughness),
            reflectance,
            transmittance,
        }),
        MaterialDesc::Glass {
            reflectance,
            transmittance,
            ior,
            fresnel,
            ..
        } => Bxdf::Dielectric(SmoothDielectric {
            eta: usable_ior(ior),
            reflectance,
            transmittance,
            fresnel,
        }),
        MaterialDesc::ThinGlass {
            reflectance,
            transmittance,
            ior,
        } => Bxdf::ThinDielectric(ThinDielectric {
            eta: usable_ior(ior),
            reflectance,
            transmittance,
        }),
        _ => unreachable!("glass() is called with glass descriptions"),
    };
    Material::new(bxdf, false)
}

/// An isotropic conductor, smooth where `alpha` is below [`SMOOTH_ALPHA`].
fn conductor(eta: Rgb, k: Rgb, specular: Rgb, kind: NormalDistribution, alpha: f32) -> Material {
    Material::new(
        Bxdf::Conductor(Conductor {
            eta,
            k,
            specular,
            distribution: (alpha > SMOOTH_ALPHA).then(|| Microfacet::new(kind, alpha)),
        }),
        true,
    )
}

/// A rough conductor: a fixed BxDF when its roughness is one constant and its specular
/// reflectance constant, else a textured (possibly anisotropic) model.
fn rough_conductor(d: &MaterialDesc, tex: &mut dyn FnMut(&TextureDesc) -> Tex) -> Material {
    let MaterialDesc::RoughConductor {
        alpha_u,
        alpha_v,
        eta,
        k,
        specular,
        distribution,
    } = d
    else {
        unreachable!("rough_conductor() is called with rough conductors")
    };
    match (alpha_u.as_constant(), specular.as_constant()) {
        (Some(alpha), Some(specular)) if alpha_v.as_constant() == Some(alpha) => {
            conductor(*eta, *k, specular, *distribution, alpha.x)
        }
        _ => Material::Leaf(Leaf {
            model: Model::Conductor {
                alpha_u: tex(alpha_u),
                alpha_v: tex(alpha_v),
                eta: *eta,
                k: *k,
                specular: tex(specular),
                kind: *distribution,
            },
            two_sided: true,
        }),
    }
}

/// Glass of textured or anisotropic roughness: the fixed glass of its roughness when that is
/// one constant, else a textured model. The side matters, as for all glass.
fn rough_glass(d: &MaterialDesc, tex: &mut dyn FnMut(&TextureDesc) -> Tex) -> Material {
    let &MaterialDesc::RoughGlass {
        ref alpha_u,
        ref alpha_v,
        ior,
        distribution,
        reflectance,
        transmittance,
    } = d
    else {
        unreachable!("rough_glass() is called with rough glass")
    };
    match (alpha_u.as_constant(), alpha_v.as_constant()) {
        (Some(a), Some(b)) if a == b => glass(&MaterialDesc::Glass {
            reflectance,
            transmittance,
            roughness: a.x,
            ior,
            distribution,
            fresnel: crate::desc::FresnelModel::Exact,
        }),
        _ => Material::Leaf(Leaf {
            model: Model::Dielectric {
                alpha_u: tex(alpha_u),
                alpha_v: tex(alpha_v),
                eta: usable_ior(ior),
                kind: distribution,
                reflectance,
                transmittance,
            },
            two_sided: false,
        }),
    }
}

/// Diffuse under a rough coat: a fixed BxDF when the diffuse reflectance is constant, else a
/// textured model with its coat's table.
fn rough_plastic(d: &MaterialDesc, tex: &mut dyn FnMut(&TextureDesc) -> Tex) -> Material {
    let &MaterialDesc::RoughPlastic {
        ref diffuse,
        specular,
        alpha,
        ior,
        nonlinear,
        distribution,
    } = d
    else {
        unreachable!("rough_plastic() is called with rough plastics")
    };
    let eta = usable_ior(ior);
    let m = Microfacet::new(distribution, alpha);
    if let Some(d) = diffuse.as_constant() {
        let bxdf = RoughPlastic::new(d.clamp(Vec3::ZERO, Vec3::ONE), specular, eta, m, nonlinear);
        return Material::new(Bxdf::RoughPlastic(bxdf), false);
    }
    Material::Leaf(Leaf {
        model: Model::RoughPlastic {
            diffuse: tex(diffuse),
            specular,
            eta,
            distribution: m,
            nonlinear,
            table: CoatTable::get(m, eta),
        },
        two_sided: false,
    })
}

/// Disney's principled BSDF, its parameters textured.
fn principled(d: &PrincipledDesc, tex: &mut dyn FnMut(&TextureDesc) -> Tex) -> Material {
    let mut opt = |t: &Option<TextureDesc>| t.as_ref().map(&mut *tex);
    let model = PrincipledModel {
        anisotropic: opt(&d.anisotropic),
        spec_trans: opt(&d.spec_trans),
        metallic: opt(&d.metallic),
        clearcoat: opt(&d.clearcoat),
        sheen: opt(&d.sheen),
        sheen_tint: opt(&d.sheen_tint),
        spec_tint: opt(&d.spec_tint),
        flatness: opt(&d.flatness),
        diff_trans: opt(&d.diff_trans),
        base_color: tex(&d.base_color),
        roughness: tex(&d.roughness),
        clearcoat_gloss: tex(&d.clearcoat_gloss),
        eta: tex(&d.eta),
        thin: d.thin,
    };
    Material::Leaf(Leaf {
        model: Model::Principled(Box::new(model)),
        two_sided: false,
    })
}
