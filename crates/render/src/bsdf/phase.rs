//! The Henyey–Greenstein phase function, for scattering inside the layers of a
//! [`super::layered::Layered`] BSDF: p(wo, wi) = (1 - g²) / (4π (1 + g² + 2g cos θ)^{3/2}),
//! θ the angle between `wo` and `wi`, both pointing away from the scattering point (so g > 0
//! scatters forwards, towards wi = -wo), as pbrt-v4 defines it.

use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// The Henyey–Greenstein phase function of asymmetry `g` in (-1, 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    /// Mean cosine of the scattering angle.
    pub g: f32,
}

/// A direction sampled from a phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseSample {
    /// The direction.
    pub wi: Vec3,
    /// The phase function's value there, which is also its density.
    pub p: f32,
}

impl HenyeyGreenstein {
    /// The value for cos θ = `cos` (wo · wi).
    fn value(&self, cos: f32) -> f32 {
        let g = self.g;
        let denom = 1.0 + g * g + 2.0 * g * cos;
        (1.0 - g * g) / (4.0 * PI * denom * denom.max(0.0).sqrt())
    }

    /// p(wo, wi), which is also the density of [`HenyeyGreenstein::sample`].
    pub fn p(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.value(wo.dot(wi))
    }

    /// A direction with density p(wo, ·), by inverting the distribution of cos θ.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let g = self.g;
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
            -(1.0 + g * g - s * s) / (2.0 * g)
        }
        .clamp(-1.0, 1.0);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = TAU * u.y;
        let local = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
        PhaseSample {
            wi: Frame::from_normal(wo).to_world(local),
            p: self.value(cos),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlab_mc::rng::Pcg32;
    use pathlab_mc::stats::{bonferroni, chi2_test_2d, cos_theta_phi};

    #[test]
    fn samples_fit_the_phase_function_which_integrates_to_one() {
        let gs = [-0.7f32, -0.2, 0.0, 0.0005, 0.3, 0.85];
        let alpha = bonferroni(0.01, gs.len());
        let wo = Vec3::new(0.3, -0.5, 0.81).normalize();
        for g in gs {
            let hg = HenyeyGreenstein { g };
            let mut rng = Pcg32::new(3, 9);
            let samples: Vec<[f64; 2]> = (0..400_000)
                .map(|_| {
                    let s = hg.sample(wo, Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
                    assert!((s.wi.length() - 1.0).abs() < 1e-4);
                    assert!((s.p - hg.p(wo, s.wi)).abs() <= 1e-3 * s.p);
                    cos_theta_phi(s.wi.as_dvec3().to_array())
                })
                .collect();
            let t = chi2_test_2d(
                samples,
                |z, phi| {
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    hg.p(wo, d) as f64
                },
                [[-1.0, 1.0], [0.0, std::f64::consts::TAU]],
                [40, 40],
            );
            assert!(t.passes(alpha), "g {g}: p = {:.2e}", t.p_value);
            // ∫ p dω = 1, by the midpoint rule in (cos θ, φ) about wo.
            let n = 2000;
            let integral: f64 = (0..n)
                .map(|i| hg.value(-1.0 + 2.0 * (i as f32 + 0.5) / n as f32) as f64)
                .sum::<f64>()
                * 2.0
                / n as f64
                * std::f64::consts::TAU;
            assert!((integral - 1.0).abs() < 2e-3, "g {g}: ∫ p = {integral}");
        }
    }
}
