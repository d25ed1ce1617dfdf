//! BSDFs in the local shading frame (z = shading normal). `f(wo, wi)` excludes the cosine;
//! the integrator multiplies by |cos θi|. Both directions point away from the surface.
//!
//! One file per model, each with `f`, `sample` and `pdf` in the local frame: [`diffuse`],
//! [`mirror`], [`dielectric`] (smooth glass), [`conductor`] (smooth or microfacet),
//! [`rough_dielectric`], [`plastic`]; [`microfacet`] holds the distributions and
//! [`fresnel`] the reflectance formulas.

pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod microfacet;
pub mod mirror;
pub mod plastic;
pub mod rough_dielectric;

pub use conductor::Conductor;
pub use dielectric::{refract, FresnelModel, SmoothDielectric};
pub use diffuse::Diffuse;
pub use fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
pub use microfacet::{Microfacet, NormalDistribution};
pub use mirror::Mirror;
pub use plastic::Plastic;
pub use rough_dielectric::RoughDielectric;

use crate::desc::{MaterialDesc, Rgb};
use crate::geometry::Frame;
use crate::texture::{Tex, TexPoint};
use glam::{Vec2, Vec3};

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// BSDF value f(wo, wi).
    pub f: Rgb,
    /// The sampled direction, in world space.
    pub wi: Vec3,
    /// Its density per unit solid angle, or for a delta lobe the probability of choosing it.
    pub pdf: f32,
    /// Whether the direction comes from a delta lobe (mirror reflection, refraction): no other
    /// strategy could have produced it, so MIS gives it weight one.
    pub delta: bool,
}

/// A sampled direction in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSample {
    /// f(wo, wi).
    pub f: Rgb,
    /// The direction, local frame.
    pub wi: Vec3,
    /// Density per solid angle, or the probability of a delta lobe.
    pub pdf: f32,
    /// Whether it comes from a delta lobe.
    pub delta: bool,
}

impl LocalSample {
    /// A non-delta sample of direction `wi` with density `pdf`, whose f is evaluated only when
    /// the density is positive (`None` otherwise: a direction the strategy cannot produce).
    #[inline]
    pub(crate) fn evaluated(wi: Vec3, pdf: f32, f: impl FnOnce() -> Rgb) -> Option<LocalSample> {
        (pdf > 0.0).then(|| LocalSample {
            f: f(),
            wi,
            pdf,
            delta: false,
        })
    }
}

/// The reflectance model of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bxdf {
    /// Lambertian.
    Diffuse(Diffuse),
    /// Perfect specular reflection.
    Mirror(Mirror),
    /// Smooth glass.
    Dielectric(SmoothDielectric),
    /// A smooth or rough conductor.
    Conductor(Conductor),
    /// Rough glass.
    RoughDielectric(RoughDielectric),
    /// Diffuse under a smooth coat.
    Plastic(Plastic),
}

impl Bxdf {
    /// f(wo, wi) in the local frame (zero for delta lobes).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            Bxdf::Diffuse(b) => b.f(wo, wi),
            Bxdf::Conductor(b) => b.f(wo, wi),
            Bxdf::RoughDielectric(b) => b.f(wo, wi),
            Bxdf::Plastic(b) => b.f(wo, wi),
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) => Rgb::ZERO,
        }
    }

    /// Samples wi given wo in the local frame: `uc` chooses a lobe, `u` the direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        match self {
            Bxdf::Diffuse(b) => b.sample(wo, u),
            Bxdf::Mirror(b) => b.sample(wo),
            Bxdf::Dielectric(b) => b.sample(wo, uc),
            Bxdf::Conductor(b) => b.sample(wo, u),
            Bxdf::RoughDielectric(b) => b.sample(wo, uc, u),
            Bxdf::Plastic(b) => b.sample(wo, uc, u),
        }
    }

    /// Density of [`Bxdf::sample`] choosing `wi` (its non-delta part).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bxdf::Diffuse(b) => b.pdf(wo, wi),
            Bxdf::Conductor(b) => b.pdf(wo, wi),
            Bxdf::RoughDielectric(b) => b.pdf(wo, wi),
            Bxdf::Plastic(b) => b.pdf(wo, wi),
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) => 0.0,
        }
    }

    /// Whether every lobe is a delta distribution (light sampling can never help).
    pub fn is_delta(&self) -> bool {
        match self {
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) => true,
            Bxdf::Conductor(c) => c.distribution.is_none(),
            Bxdf::Diffuse(_) | Bxdf::RoughDielectric(_) | Bxdf::Plastic(_) => false,
        }
    }
}

/// A material: its BxDF, whether its back side reflects, and a texture that varies the
/// diffuse albedo over the surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Reflectance model.
    pub bxdf: Bxdf,
    /// Whether the back side of the surface reflects too.
    pub two_sided: bool,
    /// Albedo texture of a diffuse BxDF (its reflectance then scales the texture).
    pub texture: Option<Tex>,
}

impl Material {
    /// A material without texture.
    pub fn new(bxdf: Bxdf, two_sided: bool) -> Self {
        Material {
            bxdf,
            two_sided,
            texture: None,
        }
    }

    /// The BSDF at a point with shading normal `n` and texture point `p`, seen from `wo`.
    #[inline]
    pub fn bsdf(&self, n: Vec3, wo: Vec3, p: &TexPoint) -> Bsdf {
        let bxdf = match (&self.texture, self.bxdf) {
            (Some(t), Bxdf::Diffuse(d)) => Bxdf::Diffuse(Diffuse {
                reflectance: (d.reflectance * t.eval(p)).clamp(Vec3::ZERO, Vec3::ONE),
            }),
            _ => self.bxdf,
        };
        Bsdf::from_bxdf(bxdf, self.two_sided, n, wo)
    }

    /// The material of a description; `attribute` gives the scene's table index of a named
    /// mesh attribute its textures read.
    pub fn from_desc(d: &MaterialDesc, attribute: &mut dyn FnMut(&str) -> u32) -> Self {
        match d {
            MaterialDesc::TexturedDiffuse {
                texture,
                scale,
                two_sided,
            } => Material {
                bxdf: Bxdf::Diffuse(Diffuse {
                    reflectance: scale.max(Vec3::ZERO),
                }),
                two_sided: *two_sided,
                texture: Some(Tex::new(texture, attribute)),
            },
            other => Material::from(other),
        }
    }
}

/// A description's index of refraction, or glass's 1.5 where it is not a positive number.
fn usable_ior(ior: f32) -> f32 {
    if ior > 0.0 && ior.is_finite() {
        ior
    } else {
        1.5
    }
}

/// Roughness below which a microfacet model is drawn as its smooth (delta) limit.
const SMOOTH_ALPHA: f32 = 1e-4;

impl From<&MaterialDesc> for Material {
    /// The material for a description.
    fn from(d: &MaterialDesc) -> Self {
        match *d {
            MaterialDesc::Diffuse {
                reflectance,
                two_sided,
            } => Material::new(
                Bxdf::Diffuse(Diffuse {
                    reflectance: reflectance.clamp(Vec3::ZERO, Vec3::ONE),
                }),
                two_sided,
            ),
            MaterialDesc::TexturedDiffuse {
                ref texture,
                scale,
                two_sided,
            } => Material {
                bxdf: Bxdf::Diffuse(Diffuse {
                    reflectance: scale.max(Vec3::ZERO),
                }),
                two_sided,
                texture: Some(Tex::from_desc(texture)),
            },
            MaterialDesc::Mirror { reflectance } => {
                Material::new(Bxdf::Mirror(Mirror { reflectance }), true)
            }
            MaterialDesc::Glass {
                reflectance,
                transmittance,
                roughness,
                ior,
                distribution,
                fresnel,
            } => {
                let eta = usable_ior(ior);
                let bxdf = if roughness > SMOOTH_ALPHA {
                    Bxdf::RoughDielectric(RoughDielectric {
                        eta,
                        distribution: Microfacet::new(distribution, roughness),
                        reflectance,
                        transmittance,
                    })
                } else {
                    Bxdf::Dielectric(SmoothDielectric {
                        eta,
                        reflectance,
                        transmittance,
                        fresnel,
                    })
                };
                // The side matters: inside and outside differ.
                Material::new(bxdf, false)
            }
            MaterialDesc::Conductor {
                alpha,
                eta,
                k,
                distribution,
            } => Material::new(
                Bxdf::Conductor(Conductor {
                    eta,
                    k,
                    distribution: (alpha > SMOOTH_ALPHA)
                        .then(|| Microfacet::new(distribution, alpha)),
                }),
                true,
            ),
            MaterialDesc::Plastic {
                diffuse,
                ior,
                nonlinear,
            } => Material::new(
                Bxdf::Plastic(Plastic::new(
                    diffuse.clamp(Vec3::ZERO, Vec3::ONE),
                    usable_ior(ior),
                    nonlinear,
                )),
                false,
            ),
        }
    }
}

/// A material at a surface point: the BxDF and the shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    frame: Frame,
    bxdf: Bxdf,
}

impl Bsdf {
    /// The BSDF of `material` at a point with unit shading normal `n`, seen from direction
    /// `wo`. A two-sided material is evaluated on the side `wo` is on; a one-sided one keeps
    /// its normal, and reflects nothing when seen from behind.
    pub fn new(material: &Material, n: Vec3, wo: Vec3) -> Self {
        Self::from_bxdf(material.bxdf, material.two_sided, n, wo)
    }

    /// The BSDF of `bxdf` at a point with unit shading normal `n` seen from `wo`.
    pub fn from_bxdf(bxdf: Bxdf, two_sided: bool, n: Vec3, wo: Vec3) -> Self {
        let n = if two_sided && wo.dot(n) < 0.0 { -n } else { n };
        Bsdf {
            frame: Frame::from_normal(n),
            bxdf,
        }
    }

    /// The shading normal (flipped towards `wo` for two-sided materials).
    pub fn normal(&self) -> Vec3 {
        self.frame.n
    }

    /// The local shading frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// The reflectance model.
    pub fn bxdf(&self) -> &Bxdf {
        &self.bxdf
    }

    /// f(wo, wi), world-space directions.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.bxdf
            .f(self.frame.to_local(wo), self.frame.to_local(wi))
    }

    /// Whether every lobe is a delta distribution (light sampling can never help).
    pub fn is_delta(&self) -> bool {
        self.bxdf.is_delta()
    }

    /// Samples wi given wo (world space): `uc` chooses a lobe, `u` the direction in it.
    pub fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        let s = self.bxdf.sample(self.frame.to_local(wo), uc, u)?;
        (s.pdf > 0.0 && s.f.is_finite()).then(|| BsdfSample {
            f: s.f,
            wi: self.frame.to_world(s.wi),
            pdf: s.pdf,
            delta: s.delta,
        })
    }

    /// Density of [`Bsdf::sample_f`] choosing `wi` (world space).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.bxdf
            .pdf(self.frame.to_local(wo), self.frame.to_local(wi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_obeys_snell() {
        for &(theta, eta) in &[(0.3f32, 1.5f32), (1.2, 1.33), (0.7, 1.0 / 1.5)] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            match refract(wo, eta) {
                Some((wi, etap)) => {
                    assert!(wi.z < 0.0);
                    let sin_t = (wi.x * wi.x + wi.y * wi.y).sqrt();
                    assert!((theta.sin() - etap * sin_t).abs() < 1e-5, "{theta} {eta}");
                    // Back through the interface returns the original direction.
                    let (back, _) = refract(wi, eta).unwrap();
                    assert!((back - wo).length() < 1e-4);
                }
                None => assert!(theta.sin() / eta > 1.0),
            }
        }
    }

    #[test]
    fn glass_sampling_conserves_energy() {
        // Without absorption, the expected throughput f |cos| / pdf of one sample is one on
        // both sides (radiance scaling aside): reflection F/F and transmission (1-F)/(1-F).
        let m = Material::new(
            Bxdf::Dielectric(SmoothDielectric {
                eta: 1.5,
                reflectance: Vec3::ONE,
                transmittance: Vec3::ONE,
                fresnel: FresnelModel::Exact,
            }),
            false,
        );
        let bsdf = Bsdf::new(&m, Vec3::Z, Vec3::Z);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let (mut reflected, n) = (0, 10_000);
        for i in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, 0.5);
            let s = bsdf.sample_f(wo, u.x, u).unwrap();
            let weight = s.f * s.wi.z.abs() / s.pdf;
            if s.wi.z > 0.0 {
                reflected += 1;
                assert!((weight - Vec3::ONE).abs().max_element() < 1e-5);
            } else {
                assert!((weight * 1.5 * 1.5 - Vec3::ONE).abs().max_element() < 1e-4);
            }
            assert!(s.delta);
        }
        // The fraction reflected is the Fresnel reflectance (stratified u: exact up to 1/n).
        let f = fresnel_dielectric(0.8, 1.5);
        assert!((reflected as f32 / n as f32 - f).abs() <= 1.0 / n as f32 + 1e-6);
        let mirror = Bsdf::new(
            &Material::new(
                Bxdf::Mirror(Mirror {
                    reflectance: Vec3::splat(0.7),
                }),
                true,
            ),
            Vec3::Z,
            wo,
        );
        let s = mirror.sample_f(wo, 0.0, Vec2::ZERO).unwrap();
        assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
        assert!(
            (s.f * s.wi.z / s.pdf - Vec3::splat(0.7))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(mirror.f(wo, s.wi), Vec3::ZERO);
        assert_eq!(mirror.pdf(wo, s.wi), 0.0);
    }
}
