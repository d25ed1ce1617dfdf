//! Direct lighting only ([`DirectIntegrator`]): one bounce, its directions drawn by uniform
//! hemisphere, cosine, BSDF or light sampling, or both combined by MIS ([`DirectStrategy`]),
//! the course's first estimators. With MIS of one light and one BSDF sample (Mitsuba's
//! `direct` as its scenes use it) the estimator is the path tracer's at depth one, and renders
//! run through the path tracer's eight lanes ([`DirectIntegrator::as_path`]).

use super::{
    emitted, escaped, power_heuristic, sample_light, trace, Integrator, PathIntegrator, PathStats,
};
use crate::desc::{RayKind, Rgb};
use crate::geometry::Frame;
use crate::geometry::{spawn_ray, Ray};
use crate::scene::{Scene, SurfaceInteraction};
use glam::{Vec2, Vec3};
use pathlab_mc::named::by_name;
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
        let what = "direct-lighting strategy";
        by_name(s, &DirectStrategy::ALL, DirectStrategy::name, what)
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
    ) -> Gathered {
        if f_cos.max_element() <= 0.0 || pdf <= 0.0 {
            return Gathered::default();
        }
        let ray = spawn_ray(si.p, si.ng, wi);
        let hit = trace(scene, &ray, RayKind::Indirect, stats);
        let found = match &hit {
            Some(hit) => emitted(scene, si.p, &ray, hit),
            None => escaped(scene, &ray, true),
        };
        let end = hit.map(|h| h.p);
        match found {
            Some((le, pdf_light)) => Gathered {
                l: f_cos * le / pdf,
                pdf_light: Some(pdf_light),
                end,
            },
            None => Gathered {
                end,
                ..Gathered::default()
            },
        }
    }

    /// A direction of the uniform (`Hemisphere`) or cosine-weighted (`Cosine`) hemisphere
    /// about `frame`'s normal from `u`, and its density.
    fn hemisphere_direction(cosine: bool, frame: &Frame, u: Vec2) -> (Vec3, f32) {
        let (w, pdf) = if cosine {
            let w = sample_cosine_hemisphere(u);
            (w, cosine_hemisphere_pdf(w.z))
        } else {
            (sample_uniform_hemisphere(u), uniform_hemisphere_pdf())
        };
        (frame.to_world(w), pdf)
    }
}

/// What a direction drawn at a surface point found: `f |cos| Le / pdf` (zero where no light
/// was found), the density with which light sampling would have chosen that light, and where
/// the ray ended (none when it left the scene).
#[derive(Clone, Copy, Debug, Default)]
struct Gathered {
    l: Rgb,
    pdf_light: Option<f32>,
    end: Option<Vec3>,
}

impl Integrator for DirectIntegrator {
    /// The samples' estimates; by the path tracer's eight-lane scheduling where it computes
    /// the same estimator ([`DirectIntegrator::as_path`]).
    fn li_samples(
        &self,
        scene: &Scene,
        sampler: &mut AnySampler,
        samples: &mut dyn Iterator<Item = super::SampleRef>,
        out: &mut dyn FnMut(u32, Rgb),
        stats: &mut PathStats,
    ) {
        match self.as_path() {
            Some(path) => path.li_samples(scene, sampler, samples, out, stats),
            None => super::li_one_at_a_time(self, scene, sampler, samples, out, stats),
        }
    }

    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        let seen = |found: Option<(Rgb, f32)>| match found {
            Some((le, _)) if !self.hide_emitters => le,
            _ => Rgb::ZERO,
        };
        let Some(si) = trace(scene, &ray, RayKind::Camera, stats) else {
            return seen(escaped(scene, &ray, false));
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
                    let cosine = self.strategy == DirectStrategy::Cosine;
                    let (wi, pdf) = Self::hemisphere_direction(cosine, &frame, sampler.next_2d());
                    let f_cos = bsdf.f_cos(wo, wi);
                    sum += Self::gather(scene, &si, wi, f_cos, pdf, stats).l;
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
    /// The path tracer whose estimate this integrator's is, where there is one: MIS of one
    /// light sample and one BSDF sample is the path tracer's estimate at depth one (the
    /// emission the camera sees, the light sample at the first surface and the emission the
    /// BSDF sample finds, weighted by the same power heuristic, from the same random numbers
    /// in the same order); Russian roulette starts later.
    pub fn as_path(&self) -> Option<PathIntegrator> {
        let one_each = self.samples == 1 && self.bsdf_samples.unwrap_or(self.samples) == 1;
        (self.strategy == DirectStrategy::Mis && one_each).then(|| PathIntegrator {
            max_depth: 1,
            hide_emitters: self.hide_emitters,
            ..PathIntegrator::default()
        })
    }

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
                    let found = Self::gather(scene, si, bs.wi, f_cos, bs.pdf, stats);
                    let c = found.l;
                    if let Some(pdf_light) = found.pdf_light {
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

/// How [`direct_samples`] draws directions at a surface point: the course's four ways.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleStrategy {
    /// Uniformly over the hemisphere about the shading normal.
    Hemisphere,
    /// Cosine-weighted over that hemisphere.
    Cosine,
    /// From the BSDF.
    Bsdf,
    /// A point on a light (chosen by power), with a shadow ray.
    Light,
}

impl SampleStrategy {
    /// Every strategy, in the course's order.
    pub const ALL: [SampleStrategy; 4] = [
        SampleStrategy::Hemisphere,
        SampleStrategy::Cosine,
        SampleStrategy::Bsdf,
        SampleStrategy::Light,
    ];

    /// The strategy's name in settings and messages.
    pub fn name(self) -> &'static str {
        match self {
            SampleStrategy::Hemisphere => "hemisphere",
            SampleStrategy::Cosine => "cosine",
            SampleStrategy::Bsdf => "bsdf",
            SampleStrategy::Light => "light",
        }
    }
}

impl std::str::FromStr for SampleStrategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let what = "sampling strategy";
        by_name(s, &SampleStrategy::ALL, SampleStrategy::name, what)
    }
}

/// One direct-lighting sample at a surface point, as the course's slides draw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectSample {
    /// The direction drawn (world space, away from the point).
    pub wi: Vec3,
    /// Where it ends: the surface the ray hits, or the point on the light (light sampling);
    /// none where the ray leaves the scene.
    pub end: Option<Vec3>,
    /// f |cos θ| / pdf: what the light arriving along `wi` is multiplied by (for light
    /// sampling, pdf includes the probability of choosing the light).
    pub weight: Rgb,
    /// The sample's estimate of the reflected direct light: the weight times the light
    /// that arrives (zero where none does or the shadow ray is blocked).
    pub contribution: Rgb,
}

/// `n` direct-lighting samples at `si` (seen from direction `wo`) drawn by `strategy` from
/// the random numbers of `seed`: each an unbiased estimate of the light the point reflects
/// towards `wo` directly (their mean is the strategy's `n`-sample estimate). The same
/// pieces as [`DirectIntegrator`]'s and the path tracer's: the hemisphere warps, the BSDF's
/// `sample_f`, the light sample of next-event estimation.
pub fn direct_samples(
    scene: &Scene,
    si: &SurfaceInteraction,
    wo: Vec3,
    strategy: SampleStrategy,
    n: u32,
    seed: u64,
) -> Vec<DirectSample> {
    let bsdf = scene.bsdf(si, wo);
    let frame = *bsdf.frame();
    let mut rng = pathlab_mc::rng::Pcg32::new(seed, 0x5eed);
    let mut u2 = || Vec2::new(rng.uniform_f32(), rng.uniform_f32());
    let stats = &mut PathStats::default();
    (0..n)
        .map(|_| match strategy {
            SampleStrategy::Hemisphere | SampleStrategy::Cosine => {
                let cosine = strategy == SampleStrategy::Cosine;
                let (wi, pdf) = DirectIntegrator::hemisphere_direction(cosine, &frame, u2());
                let f_cos = bsdf.f_cos(wo, wi);
                let found = DirectIntegrator::gather(scene, si, wi, f_cos, pdf, stats);
                DirectSample {
                    wi,
                    end: found.end,
                    weight: f_cos / pdf,
                    contribution: found.l,
                }
            }
            SampleStrategy::Bsdf => {
                let u = u2();
                match bsdf.sample_f(wo, u.x, u2()) {
                    Some(bs) => {
                        let f_cos = bs.f * bs.cos;
                        let found =
                            DirectIntegrator::gather(scene, si, bs.wi, f_cos, bs.pdf, stats);
                        DirectSample {
                            wi: bs.wi,
                            end: found.end,
                            weight: f_cos / bs.pdf,
                            contribution: found.l,
                        }
                    }
                    None => DirectSample {
                        wi: Vec3::ZERO,
                        end: None,
                        weight: Rgb::ZERO,
                        contribution: Rgb::ZERO,
                    },
                }
            }
            SampleStrategy::Light => {
                let (u_select, u_light) = (u2().x, u2());
                // The estimate is next-event estimation's own; the point and the weight are
                // read from the same light sample it draws.
                let contribution =
                    sample_light(scene, si, &bsdf, wo, u_select, u_light, 1, 0, stats);
                let sample = scene.light_sampler().sample(u_select).and_then(|(i, pmf)| {
                    let ls = scene.lights()[i].sample_li(si.p, u_light)?;
                    Some((ls.wi, ls.p_light, bsdf.f_cos(wo, ls.wi) / (pmf * ls.pdf)))
                });
                let (wi, end, weight) = match sample {
                    Some((wi, p, w)) if w.is_finite() => (wi, Some(p), w),
                    Some((wi, p, _)) => (wi, Some(p), Rgb::ZERO),
                    None => (Vec3::ZERO, None, Rgb::ZERO),
                };
                DirectSample {
                    wi,
                    end,
                    weight,
                    contribution,
                }
            }
        })
        .collect()
}
