//! A rough dielectric interface: microfacet reflection and transmission (Walter et al. 2007).

use super::fresnel::fresnel_dielectric;
use super::microfacet::Microfacet;
use super::scattering::{reflect, refract_about};
use super::{Lobes, LocalSample};
use crate::desc::Rgb;
use glam::{Vec2, Vec3};

/// Rough glass. For wo and wi on the same side, f = D G F / (4 |cos θo cos θi|) with the
/// half vector wm ∝ wo + wi; across the interface (relative index η' along the path),
/// wm ∝ wo + η' wi and
/// f = D G (1 - F) |wi·wm| |wo·wm| / (|cos θi cos θo| (wi·wm + wo·wm / η')² η'²),
/// the last η'² being the radiance scaling of refraction. Sampling draws wm, then reflection
/// with probability F(wo·wm) and refraction otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// Index of refraction inside relative to outside.
    pub eta: f32,
    /// The microfacet distribution.
    pub distribution: Microfacet,
    /// Scale of the reflected part.
    pub reflectance: Rgb,
    /// Scale of the transmitted part.
    pub transmittance: Rgb,
}

/// The generalised half vector of a pair of directions, on the upper side, with η' and
/// whether the pair is a reflection; `None` for degenerate or back-facing configurations.
fn half_vector(wo: Vec3, wi: Vec3, eta: f32) -> Option<(Vec3, f32, bool)> {
    let (cos_o, cos_i) = (wo.z, wi.z);
    if cos_o == 0.0 || cos_i == 0.0 {
        return None;
    }
    let reflection = cos_o * cos_i > 0.0;
    let etap = if reflection {
        1.0
    } else if cos_o > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    if wm.length_squared() == 0.0 {
        return None;
    }
    let mut wm = wm.normalize();
    if wm.z < 0.0 {
        wm = -wm;
    }
    // Facets seen from behind by either direction contribute nothing.
    if wm.dot(wi) * cos_i <= 0.0 || wm.dot(wo) * cos_o <= 0.0 {
        return None;
    }
    Some((wm, etap, reflection))
}

impl RoughDielectric {
    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some((wm, etap, reflection)) = half_vector(wo, wi, self.eta) else {
            return Rgb::ZERO;
        };
        let m = &self.distribution;
        let f = fresnel_dielectric(wo.dot(wm), self.eta);
        let dg = m.d(wm) * m.g(wo, wi, wm);
        if reflection {
            return self.reflectance * (dg * f / (4.0 * (wo.z * wi.z).abs()));
        }
        let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * wi.z * wo.z;
        let ft = dg * (1.0 - f) * (wi.dot(wm) * wo.dot(wm) / denom).abs() / (etap * etap);
        self.transmittance * ft
    }

    /// A sampled microfacet normal, then reflection (probability F) or refraction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        self.sample_lobes(wo, uc, u, Lobes::All)
    }

    /// [`RoughDielectric::sample`] restricted to `lobes` (at the sampled facet, the other
    /// lobe's probability given to the one left).
    pub fn sample_lobes(&self, wo: Vec3, uc: f32, u: Vec2, lobes: Lobes) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.distribution.sample_wm(wo, u);
        // A facet facing away from wo (possible when sampling D cos θm rather than visible
        // normals) is invisible from wo.
        if wo.dot(wm) * wo.z <= 0.0 {
            return None;
        }
        let f = fresnel_dielectric(wo.dot(wm), self.eta);
        let (pr, _) = lobes.choose(f, 1.0 - f)?;
        let (wi, reflection) = if uc < pr {
            (reflect(wo, wm), true)
        } else {
            (refract_about(wo, wm, self.eta)?.0, false)
        };
        // A facet can send a reflection across the macro surface or a refraction back: such
        // paths are not part of the model (f is evaluated through another facet there).
        if (wi.z * wo.z > 0.0) != reflection || wi.z == 0.0 {
            return None;
        }
        LocalSample::evaluated(wi, self.pdf_lobes(wo, wi, lobes), || self.f(wo, wi))
    }

    /// Density of [`RoughDielectric::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.pdf_lobes(wo, wi, Lobes::All)
    }

    /// Density of [`RoughDielectric::sample_lobes`].
    pub fn pdf_lobes(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        let Some((wm, etap, reflection)) = half_vector(wo, wi, self.eta) else {
            return 0.0;
        };
        let f = fresnel_dielectric(wo.dot(wm), self.eta);
        let Some((pr, pt)) = lobes.choose(f, 1.0 - f) else {
            return 0.0;
        };
        let pdf_wm = self.distribution.pdf_wm(wo, wm);
        if reflection {
            pdf_wm / (4.0 * wo.dot(wm).abs()) * pr
        } else {
            let dwm_dwi = wi.dot(wm).abs() / (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            pdf_wm * dwm_dwi * pt
        }
    }
}
