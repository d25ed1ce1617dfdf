//! Conductors: smooth (a delta lobe) or rough (a microfacet model), with the Fresnel
//! reflectance of a complex index of refraction.

use super::fresnel::fresnel_conductor_rgb;
use super::microfacet::Microfacet;
use super::mirror::specular_reflection;
use super::scattering::reflect;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};

/// A conductor with complex index η + i k per channel. Smooth without a distribution;
/// otherwise f = D(wm) G(wo, wi, wm) F(wo·wm) / (4 cos θo cos θi) with wm the half vector
/// (Cook–Torrance / Walter et al. 2007), sampled through the distribution of normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the index, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption), per channel.
    pub k: Rgb,
    /// Scale of the reflection (Mitsuba's `specular_reflectance`; one for a plain metal).
    pub specular: Rgb,
    /// The microfacet distribution (`None`: a smooth surface).
    pub distribution: Option<Microfacet>,
}

impl Conductor {
    /// Fresnel reflectance per channel at cos θ.
    #[inline]
    fn fresnel(&self, cos: f32) -> Rgb {
        self.specular * fresnel_conductor_rgb(cos, self.eta, self.k)
    }

    /// f(wo, wi) (zero for a smooth conductor: a delta lobe).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(m) = self.distribution else {
            return Rgb::ZERO;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return Rgb::ZERO;
        }
        let wm = wm.normalize();
        let dg = m.d(wm) * m.g(wo, wi, wm);
        self.fresnel(wo.dot(wm)) * (dg / (4.0 * wo.z * wi.z))
    }

    /// A sample: the mirror direction when smooth, otherwise the reflection of `wo` about a
    /// sampled microfacet normal.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<LocalSample> {
        let Some(m) = self.distribution else {
            return specular_reflection(wo, self.fresnel(wo.z.abs()), 1.0);
        };
        if wo.z <= 0.0 {
            return None;
        }
        let wm = m.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        LocalSample::evaluated(wi, self.pdf(wo, wi), || self.f(wo, wi))
    }

    /// Density of [`Conductor::sample`]: pdf(wm) / (4 wo·wm).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(m) = self.distribution else {
            return 0.0;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        let cos_om = wo.dot(wm);
        if cos_om <= 0.0 {
            return 0.0;
        }
        m.pdf_wm(wo, wm) / (4.0 * cos_om)
    }
}
