//! BSDFs in the local shading frame (z = shading normal). `f(wo, wi)` excludes the cosine;
//! the integrator multiplies by |cos θi|. Both directions point away from the surface.
//!
//! One file per model, each with `f`, `sample` and `pdf` in the local frame: [`diffuse`],
//! [`diffuse_transmission`], [`layered`] (pbrt-v4's coated materials), [`mirror`], [`dielectric`] (smooth glass), [`conductor`] (smooth or microfacet),
//! [`rough_dielectric`], [`plastic`], [`rough_plastic`]; [`microfacet`] holds the
//! distributions, [`fresnel`] the reflectance formulas and [`scattering`] the reflected and
//! refracted directions; [`bxdf`] dispatches among the models.
//!
//! [`from_desc`] turns a scene's material description into a [`Material`]; [`material`]
//! evaluates it (textured parameters, masks, blends, two-sided pairs, normal and bump maps)
//! into the [`Bsdf`] at a surface point ([`mixture`]): a weighted mixture of lobes, each a
//! [`Bxdf`] in its own shading frame, plus an optional pass-through.

pub mod bxdf;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod diffuse_transmission;
pub mod fresnel;
pub mod from_desc;
pub mod layered;
pub mod material;
pub mod microfacet;
pub mod mirror;
pub mod mixture;
pub mod phase;
pub mod plastic;
pub mod principled;
pub mod rough_dielectric;
pub mod rough_plastic;
pub mod scattering;
pub mod thin_dielectric;

pub use bxdf::{Bxdf, Lobes, LocalSample};
pub use conductor::{Conductor, RoughConductor, SmoothConductor};
pub use dielectric::{DielectricLanes, FresnelModel, SmoothDielectric};
pub use diffuse::Diffuse;
pub use diffuse_transmission::DiffuseTransmission;
pub use fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
pub use layered::{Base, Coat, LayerMedium, LayerStack, Layered};
pub use material::{LaneBxdf, LaneLobe, Leaf, Material, Model, ShadingPoint};
pub use microfacet::{
    Distribution, IsotropicMicrofacet, Microfacet, MicrofacetLanes, NormalDistribution,
};
pub use mirror::Mirror;
pub use mixture::{guard_admits, guard_attenuation, Bsdf, BsdfSample, Guard, Lobe, MAX_LOBES};
pub use plastic::Plastic;
pub use principled::{Principled, PrincipledFlags, PrincipledLobes};
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::{CoatLanes, RoughPlastic};
pub use scattering::{reflect, refract, refract_about};
pub use thin_dielectric::ThinDielectric;

use bxdf::{usable_ior, SMOOTH_ALPHA};

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

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
                assert_eq!(s.eta, 1.0);
            } else {
                assert!((weight * 1.5 * 1.5 - Vec3::ONE).abs().max_element() < 1e-4);
                assert_eq!(s.eta, 1.5, "the relative index the sample crossed");
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
