//! Direct lighting only ([`DirectIntegrator`]): one bounce, its directions drawn by uniform
//! hemisphere, cosine, BSDF or light sampling, or both combined by MIS ([`DirectStrategy`]),
//! the course's first estimators.

use super::{emitted, escaped, power_heuristic, sample_light, trace, Integrator, PathStats};
use crate::desc::{RayKind, Rgb};
use crate::geometry::{spawn_ray, Ray};
use crate::scene::{Scene, SurfaceInteraction};
use glam::Vec3;
use pathlab_mc::sampler::{AnySampler, Sampler};
use pathlab_mc::warp::{
    cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_hemisphere,
    uniform_hemisphere_pdf,
};

/// How direct lighting picks its directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectStrategy {
    /// Directions uniform over the hemisphere: p = 1/(2π).
    Hemisphere,
    /// Cosine-weighted directions: p = cos θ/π.
    Cosine,
    /// Points on the lights (chosen by power), converted to solid angle: p = d²/(A |cos θl|).
    Light,
    /// Light and BSDF samples combined by the power heuristic.
    Mis,
}

impl DirectStrategy {
    /// All strategies, in the order of the course's comparison.
    pub const ALL: [DirectStrategy; 4] = [
        DirectStrategy::Hemisphere,
        DirectStrategy::Cosine,
        DirectStrategy::Light,
        DirectStrategy::Mis,
    ];

    /// The name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            DirectStrategy::Hemisphere => "hemisphere",
            DirectStrategy::Cosine => "cosine",
            DirectStrategy::Light => "light",
            DirectStrategy::Mis => "mis",
        }
    }
}

impl std::str::FromStr for DirectStrategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        DirectStrategy::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown direct-lighting strategy '{s}' (expected hemisphere, cosine, light or mis)"))
    }
}

/// Direct lighting: the emission the camera sees plus light that reaches the first surface in
/// one bounce, estimated with `samples` directions (or light points) per camera ray.
///
/// With MIS, `samples` light samples and `bsdf_samples` BSDF samples (default: as many) are
/// combined by the power heuristic with their counts, m p_l and k p_b (Mitsuba's `direct`
/// with `emitter_samples` and `bsdf_samples`); a count of zero drops that strategy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectIntegrator {
    /// The sampling strategy.
    pub strategy: DirectStrategy,
    /// Samples per camera ray (light samples for MIS).
    pub samples: u32,
    /// BSDF samples per camera ray for MIS (`None`: as many as `samples`).
    pub bsdf_samples: Option<u32>,
    /// Camera rays see no emitters.
    pub hide_emitters: bool,
}

impl Default for DirectIntegrator {
    fn default() -> Self {
        DirectIntegrator {
            strategy: DirectStrategy::Mis,
            samples: 1,
            bsdf_samples: None,
            hide_emitters: false,
        }
    }
}

impl DirectIntegrator {
    /// Emission found along a sampled direction `wi`, weighted by `f_cos / pdf` (f_cos being
    /// f(wo, wi) |cos θi|, or the sampled value of a delta lobe); also returns the density with
    /// which light sampling would have found it.
    fn gather(
        scene: &Scene,
        si: &SurfaceInteraction,
        wi: Vec3,
        f_cos: Rgb,
        pdf: f32,
        stats: &mut PathStats,
    ) -> (Rgb, Option<f32>) {
        if f_cos.max_element() <= 0.0 || pdf <= 0.0 {
            return (Rgb::ZERO, None);
        }
        let ray = spawn_ray(si.p, si.ng, wi);
        let found = match trace(scene, &ray, RayKind::Indirect, stats) {
            Some(hit) => emitted(scene, si.p, &ray, &hit),
            None => escaped(scene, &ray),
        };
        match found {
            Some((le, pdf_light)) => (f_cos * le / pdf, Some(pdf_light)),
            None => (Rgb::ZERO, None),
        }
    }
}

impl Integrator for DirectIntegrator {
    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        let seen = |found: Option<(Rgb, f32)>| match found {
            Some((le, _)) if !self.hide_emitters => le,
            _ => Rgb::ZERO,
        };
        let Some(si) = trace(scene, &ray, RayKind::Camera, stats) else {
            return seen(escaped(scene, &ray));
        };
        let wo = -ray.d;
        let mut l = seen(emitted(scene, ray.o, &ray, &si));
        let bsdf = scene.bsdf(&si, wo);
        stats.random_vertices += u64::from(!bsdf.is_black());
        if self.strategy == DirectStrategy::Mis {
            return l + self.mis(scene, &si, &bsdf, wo, sampler, stats);
        }
        let n = self.samples.max(1);
        let frame = *bsdf.frame();
        let mut sum = Rgb::ZERO;
        for _ in 0..n {
            match self.strategy {
                DirectStrategy::Hemisphere | DirectStrategy::Cosine => {
                    let u = sampler.next_2d();
                    let (w, pdf) = if self.strategy == DirectStrategy::Hemisphere {
                        (sample_uniform_hemisphere(u), uniform_hemisphere_pdf())
                    } else {
                        let w = sample_cosine_hemisphere(u);
                        (w, cosine_hemisphere_pdf(w.z))
                    };
                    let wi = frame.to_world(w);
                    let f_cos = bsdf.f_cos(wo, wi);
                    sum += Self::gather(scene, &si, wi, f_cos, pdf, stats).0;
                }
                DirectStrategy::Light | DirectStrategy::Mis => {
                    let u_select = sampler.next_1d();
                    let u_light = sampler.next_2d();
                    sum += sample_light(scene, &si, &bsdf, wo, u_select, u_light, n, 0, stats);
                }
            }
        }
        l += sum / n as f32;
        l
    }
}

impl DirectIntegrator {
    /// Light and BSDF samples combined by the power heuristic with their counts. With equal
    /// counts the samples come in pairs (light, then BSDF), as the course's comparison draws
    /// them.
    fn mis(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        bsdf: &crate::bsdf::Bsdf,
        wo: Vec3,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Rgb {
        let m = self.samples;
        let k = self.bsdf_samples.unwrap_or(m);
        let mut light = Rgb::ZERO;
        let mut from_bsdf = Rgb::ZERO;
        for i in 0..m.max(k) {
            if i < m && !bsdf.is_delta() {
                let u_select = sampler.next_1d();
                let u_light = sampler.next_2d();
                light += sample_light(scene, si, bsdf, wo, u_select, u_light, m, k, stats);
            } else if i < m {
                sampler.next_1d();
                sampler.next_2d();
            }
            if i < k {
                if let Some(bs) = bsdf.sample_f(wo, sampler.next_1d(), sampler.next_2d()) {
                    let f_cos = bs.f * bs.cos;
                    let (c, pdf_light) = Self::gather(scene, si, bs.wi, f_cos, bs.pdf, stats);
                    if let Some(pdf_light) = pdf_light {
                        let w = if bs.delta || m == 0 {
                            1.0
                        } else {
                            power_heuristic(k, bs.pdf, m, pdf_light)
                        };
                        from_bsdf += c * w;
                    }
                }
            }
        }
        let mut l = Rgb::ZERO;
        if m > 0 {
            l += light / m as f32;
        }
        if k > 0 {
            l += from_bsdf / k as f32;
        }
        l
    }
}
