//! Lambertian reflection and Lambertian transmission together: pbrt-v4's
//! `diffusetransmission` (leaves, paper, a lamp shade). f = R/π for directions on the side of
//! `wo`, T/π on the other; both sides alike.
//!
//! Sampling picks reflection with probability p_r = max(R) / (max(R) + max(T)) (pbrt-v4's
//! choice), then a cosine-weighted direction on the chosen side: pdf = p_r cos θ / π on `wo`'s
//! side, (1 - p_r) |cos θ| / π on the other.

use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

/// Diffuse reflection `reflectance` and diffuse transmission `transmittance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseTransmission {
    /// Albedo of the reflection, per channel.
    pub reflectance: Rgb,
    /// Albedo of the transmission, per channel.
    pub transmittance: Rgb,
}

impl DiffuseTransmission {
    /// Probability that sampling chooses reflection (½ when both are black).
    fn reflect_probability(&self) -> f32 {
        let (r, t) = (
            self.reflectance.max_element(),
            self.transmittance.max_element(),
        );
        if r + t > 0.0 {
            r / (r + t)
        } else {
            0.5
        }
    }

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let side = wo.z * wi.z;
        if side > 0.0 {
            self.reflectance * FRAC_1_PI
        } else if side < 0.0 {
            self.transmittance * FRAC_1_PI
        } else {
            Rgb::ZERO
        }
    }

    /// A cosine-weighted direction on the side `uc` chooses (reflection below p_r).
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 || wo.z.is_nan() {
            return None;
        }
        let p_r = self.reflect_probability();
        let reflect = uc < p_r;
        let mut wi: Vec3 = cosine_hemisphere(u.x, u.y);
        // Reflection leaves on wo's side, transmission on the other.
        if reflect != (wo.z > 0.0) {
            wi.z = -wi.z;
        }
        let choice = if reflect { p_r } else { 1.0 - p_r };
        let pdf = choice * cosine_hemisphere_pdf(wi.z.abs());
        LocalSample::evaluated(wi, pdf, || self.f(wo, wi))
    }

    /// Density of [`DiffuseTransmission::sample`] choosing `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let side = wo.z * wi.z;
        if side == 0.0 || side.is_nan() {
            return 0.0;
        }
        let p_r = self.reflect_probability();
        let choice = if side > 0.0 { p_r } else { 1.0 - p_r };
        choice * cosine_hemisphere_pdf(wi.z.abs())
    }
}
