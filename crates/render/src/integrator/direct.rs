use super::{emitted, escaped, power_heuristic, sample_light, trace, Integrator, PathStats};
use crate::desc::Rgb;
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectIntegrator {
    /// The sampling strategy.
    pub strategy: DirectStrategy,
    /// Samples per camera ray (each of light and BSDF for MIS).
    pub samples: u32,
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
        let found = match trace(scene, &ray, false, stats) {
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
        let Some(si) = trace(scene, &ray, true, stats) else {
            return escaped(scene, &ray).map_or(Rgb::ZERO, |(le, _)| le);
        };
        let wo = -ray.d;
        let mut l = emitted(scene, ray.o, &ray, &si).map_or(Rgb::ZERO, |(le, _)| le);
        let bsdf = scene.bsdf(&si, wo);
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
                    let f_cos = bsdf.f(wo, wi) * wi.dot(si.ns).abs();
                    sum += Self::gather(scene, &si, wi, f_cos, pdf, stats).0;
                }
                DirectStrategy::Light => {
                    let u_select = sampler.next_1d();
                    let u_light = sampler.next_2d();
                    sum += sample_light(scene, &si, &bsdf, wo, u_select, u_light, n, 0, stats);
                }
                DirectStrategy::Mis => {
                    let u_select = sampler.next_1d();
                    let u_light = sampler.next_2d();
                    sum += sample_light(scene, &si, &bsdf, wo, u_select, u_light, n, n, stats);
                    if let Some(bs) = bsdf.sample_f(wo, sampler.next_1d(), sampler.next_2d()) {
                        let f_cos = bs.f * bs.wi.dot(si.ns).abs();
                        let (c, pdf_light) = Self::gather(scene, &si, bs.wi, f_cos, bs.pdf, stats);
                        if let Some(pdf_light) = pdf_light {
                            let w = if bs.delta {
                                1.0
                            } else {
                                power_heuristic(n, bs.pdf, n, pdf_light)
                            };
                            sum += c * w;
                        }
                    }
                }
            }
        }
        l += sum / n as f32;
        l
    }
}
