//! A thin dielectric sheet (a window pane, a soap film): Mitsuba's `thindielectric`.
//!
//! Light meets two parallel interfaces close together. Summing the internal reflections, a
//! sheet with single-interface reflectance R = F(cos θ) reflects R' = R + T²R / (1 - R²) =
//! 2R / (1 + R) and transmits T' = 1 - R' without changing direction: the two refractions
//! cancel and the displacement is neglected. Both lobes are deltas, both sides alike.

use super::fresnel::fresnel_dielectric;
use super::mirror::specular_reflection;
use super::LocalSample;
use crate::desc::Rgb;
use glam::Vec3;

/// A thin sheet of a dielectric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// Index of refraction of the sheet relative to the medium around it.
    pub eta: f32,
    /// Scale of the reflected part.
    pub reflectance: Rgb,
    /// Scale of the transmitted part.
    pub transmittance: Rgb,
}

impl ThinDielectric {
    /// The sheet's reflectance R' = 2R / (1 + R) at |cos θ| = `cos`.
    pub fn reflectance(&self, cos: f32) -> f32 {
        let r = fresnel_dielectric(cos.abs(), self.eta);
        2.0 * r / (1.0 + r)
    }

    /// Reflection with probability R', straight transmission otherwise (`uc` chooses).
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = self.reflectance(wo.z);
        if uc < r {
            return specular_reflection(wo, self.reflectance * r, r);
        }
        let t = 1.0 - r;
        let wi = -wo;
        Some(LocalSample {
            f: self.transmittance * (t / wi.z.abs()),
            wi,
            pdf: t,
            delta: true,
        })
    }
}
