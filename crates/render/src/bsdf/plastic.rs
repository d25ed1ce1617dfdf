//! A diffuse base under a smooth dielectric coat (Mitsuba's `plastic`).

use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
use super::mirror::specular_reflection;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use std::f32::consts::FRAC_1_PI;

/// Smooth plastic: specular reflection off the coat with probability-free weight F(θo), plus
/// light that enters the coat, scatters diffusely off the base and leaves:
///
/// f_diffuse = ρ' (1 - F(θi)) (1 - F(θo)) / (η² π), with ρ' = ρ / (1 - F_dr,int)
///
/// where F_dr,int is the coat's diffuse reflectance seen from inside. Its albedo is
/// F(θo) + (1 - F(θo)) ρ ≤ 1 (using 1 - F_dr,ext = η² (1 - F_dr,int)): ρ is the overall
/// diffuse albedo and a white base reflects everything. With `nonlinear`, ρ' = ρ / (1 - ρ
/// F_dr,int) accounts for the base's colour at each internal bounce (albedo
/// F + (1 - F) ρ (1 - F_dr,int) / (1 - ρ F_dr,int), still ≤ 1 and equal for ρ = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// Diffuse reflectance of the base.
    pub diffuse: Rgb,
    /// Scale of the coat's reflection (Mitsuba's `specular_reflectance`; 1 is physical).
    pub specular: Rgb,
    /// Index of the coat relative to outside.
    pub eta: f32,
    /// Whether internal reflections tint by the base colour.
    pub nonlinear: bool,
    /// Diffuse Fresnel reflectance of the coat from inside.
    fdr_int: f32,
}

impl Plastic {
    /// A plastic with diffuse base `diffuse` and coat index `eta`.
    pub fn new(diffuse: Rgb, eta: f32, nonlinear: bool) -> Self {
        Plastic {
            diffuse,
            specular: Rgb::ONE,
            eta,
            nonlinear,
            fdr_int: fresnel_diffuse_reflectance(1.0 / eta),
        }
    }

    /// The same plastic with its coat reflection scaled by `specular`.
    pub fn with_specular(self, specular: Rgb) -> Self {
        Plastic { specular, ..self }
    }

    fn base(&self) -> Rgb {
        if self.nonlinear {
            self.diffuse / (Rgb::ONE - self.diffuse * self.fdr_int)
        } else {
            self.diffuse / (1.0 - self.fdr_int)
        }
    }

    /// Probability of sampling the specular coat reflection: F s against (1 - F) d, with s
    /// and d the mean specular scale and diffuse reflectance (as Mitsuba weighs them).
    fn specular_probability(&self, f_o: f32) -> f32 {
        let mean = |c: Rgb| (c.x + c.y + c.z) / 3.0;
        let s = f_o * mean(self.specular.max(Rgb::ZERO));
        let d = (1.0 - f_o) * mean(self.diffuse);
        if s + d > 0.0 {
            s / (s + d)
        } else {
            1.0
        }
    }

    /// The non-delta (diffuse) part of f.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (f_o, f_i) = (
            fresnel_dielectric(wo.z, self.eta),
            fresnel_dielectric(wi.z, self.eta),
        );
        self.base() * ((1.0 - f_o) * (1.0 - f_i) * FRAC_1_PI / (self.eta * self.eta))
    }

    /// The coat's mirror reflection (a delta) or a cosine-weighted direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let p_spec = self.specular_probability(f_o);
        if uc < p_spec {
            return specular_reflection(wo, self.specular * f_o, p_spec);
        }
        let wi = sample_cosine_hemisphere(u);
        LocalSample::evaluated(wi, self.pdf(wo, wi), || self.f(wo, wi))
    }

    /// Density of the non-delta part of [`Plastic::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let p_spec = self.specular_probability(fresnel_dielectric(wo.z, self.eta));
        (1.0 - p_spec) * cosine_hemisphere_pdf(wi.z)
    }
}
