//! A smooth dielectric interface (glass).

use super::fresnel::{fresnel_dielectric, fresnel_schlick};
use super::mirror::specular_reflection;
use super::scattering::refract;
use super::{Lobes, LocalSample};
use crate::desc::Rgb;
use glam::Vec3;

/// Which Fresnel reflectance a dielectric uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FresnelModel {
    /// The exact dielectric Fresnel equations (unpolarised light).
    #[default]
    Exact,
    /// Schlick's approximation, as the course's renderer uses.
    Schlick,
}

impl FresnelModel {
    /// Reflectance at cos θi (positive: from outside) for relative index `eta`.
    #[inline]
    pub fn reflectance(self, cos_theta_i: f32, eta: f32) -> f32 {
        match self {
            FresnelModel::Exact => fresnel_dielectric(cos_theta_i, eta),
            FresnelModel::Schlick => fresnel_schlick(cos_theta_i, eta),
        }
    }
}

/// Glass: Fresnel reflectance F chooses reflection with probability F and refraction (Snell's
/// law) otherwise; total internal reflection beyond the critical angle. Radiance crossing the
/// interface is scaled by 1/η'² (η' the relative index along the path), as radiance transport
/// requires. Both lobes are deltas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// Index of refraction inside (below the normal) relative to outside.
    pub eta: f32,
    /// Scale of the reflected part.
    pub reflectance: Rgb,
    /// Scale of the transmitted part.
    pub transmittance: Rgb,
    /// Exact Fresnel or Schlick's approximation.
    pub fresnel: FresnelModel,
}

impl SmoothDielectric {
    /// Reflection with probability F, refraction otherwise (`uc` chooses).
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<LocalSample> {
        self.sample_lobes(wo, uc, Lobes::All)
    }

    /// [`SmoothDielectric::sample`] restricted to `lobes` (the other's probability given to
    /// the one left).
    pub fn sample_lobes(&self, wo: Vec3, uc: f32, lobes: Lobes) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let f = self.fresnel.reflectance(wo.z, self.eta);
        let (pr, pt) = lobes.choose(f, 1.0 - f)?;
        if uc < pr {
            return specular_reflection(wo, self.reflectance * f, pr);
        }
        let (wi, etap) = refract(wo, self.eta)?;
        let t = 1.0 - f;
        Some(LocalSample {
            f: self.transmittance * (t / (wi.z.abs() * etap * etap)),
            wi,
            pdf: pt,
            delta: true,
        })
    }
}
