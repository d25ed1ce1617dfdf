use super::{emitted, escaped, power_heuristic, sample_light, trace, Integrator, PathStats};
use crate::desc::Rgb;
use crate::geometry::{spawn_ray, Ray};
use crate::scene::Scene;
use pathlab_mc::sampler::{AnySampler, Sampler};

/// Unidirectional path tracing with next-event estimation and MIS.
///
/// At every surface the path meets it adds light sampling (next-event estimation) and then
/// continues in a direction sampled from the BSDF; emission found by the continued ray is
/// weighted against light sampling by the power heuristic, so each light path is counted once
/// overall. Bounces are counted as the course does: the radiance a camera ray sees directly
/// has bounce 0, direct lighting bounce 1, and so on; `max_depth` caps them.
///
/// `lighting` picks how light is found at each vertex: both strategies combined by MIS (the
/// default), BSDF sampling alone (emission counts only when a sampled direction hits it), or
/// light sampling alone (emission found by BSDF sampling counts only after a delta bounce,
/// which light sampling cannot produce). All three are unbiased; they differ in variance.
///
/// Russian roulette from `rr_depth` on: the path continues with probability
/// q = min(max component of the throughput, 0.95) and its throughput is divided by q, which
/// keeps the estimator unbiased.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathIntegrator {
    /// Largest bounce counted (`u32::MAX`: unbounded).
    pub max_depth: u32,
    /// First bounce at which Russian roulette may end the path.
    pub rr_depth: u32,
    /// Only the radiance of this bounce, when set.
    pub only_bounce: Option<u32>,
    /// Light samples per surface point.
    pub light_samples: u32,
    /// How light is found at each vertex.
    pub lighting: PathLighting,
}

/// The strategies a path tracer uses to find light at each vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PathLighting {
    /// Light sampling and BSDF sampling, weighted by the power heuristic.
    #[default]
    Mis,
    /// BSDF sampling only.
    Bsdf,
    /// Light sampling only (BSDF sampling still continues the path and finds emission after
    /// delta bounces).
    Light,
}

impl Default for PathIntegrator {
    fn default() -> Self {
        PathIntegrator {
            max_depth: u32::MAX,
            rr_depth: 5,
            only_bounce: None,
            light_samples: 1,
            lighting: PathLighting::Mis,
        }
    }
}

impl Integrator for PathIntegrator {
    fn li(
        &self,
        scene: &Scene,
        mut ray: Ray,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Rgb {
        let mut l = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        let n_light = self.light_samples.max(1);
        // MIS weight of emission found by a BSDF-sampled direction of density `pdf_bsdf`
        // (infinite after a delta bounce) that light sampling would find with `pdf_light`.
        let bsdf_weight = |pdf_bsdf: f32, pdf_light: f32| match self.lighting {
            PathLighting::Mis => power_heuristic(1, pdf_bsdf, n_light, pdf_light),
            PathLighting::Bsdf => 1.0,
            PathLighting::Light => {
                if pdf_bsdf.is_infinite() {
                    1.0
                } else {
                    0.0
                }
            }
        };
        let bsdf_samples = u32::from(self.lighting == PathLighting::Mis);
        let wants = |bounce: u32| self.only_bounce.is_none_or(|k| k == bounce);
        // The previous vertex and the BSDF density of the direction that left it (infinite
        // for a delta lobe, which gives emission found through it MIS weight one).
        let mut prev: Option<(glam::Vec3, f32)> = None;
        let mut depth = 0u32;
        loop {
            let Some(si) = trace(scene, &ray, depth == 0, stats) else {
                if let Some((le, pdf_light)) = escaped(scene, &ray) {
                    let w = prev.map_or(1.0, |(_, pdf_bsdf)| bsdf_weight(pdf_bsdf, pdf_light));
                    if wants(depth) {
                        l += beta * w * le;
                    }
                }
                break;
            };
            let wo = -ray.d;
            let p_prev = prev.map_or(ray.o, |(p, _)| p);
            if let Some((le, pdf_light)) = emitted(scene, p_prev, &ray, &si) {
                let w = prev.map_or(1.0, |(_, pdf_bsdf)| bsdf_weight(pdf_bsdf, pdf_light));
                if wants(depth) {
                    l += beta * w * le;
                }
            }
            if depth >= self.max_depth {
                break;
            }
            let bsdf = scene.bsdf(&si, wo);
            if wants(depth + 1) && !bsdf.is_delta() && self.lighting != PathLighting::Bsdf {
                let mut ld = Rgb::ZERO;
                for _ in 0..n_light {
                    let u_select = sampler.next_1d();
                    let u_light = sampler.next_2d();
                    ld += sample_light(
                        scene,
                        &si,
                        &bsdf,
                        wo,
                        u_select,
                        u_light,
                        n_light,
                        bsdf_samples,
                        stats,
                    );
                }
                l += beta * ld / n_light as f32;
            } else {
                for _ in 0..n_light {
                    sampler.next_1d();
                    sampler.next_2d();
                }
            }
            let Some(bs) = bsdf.sample_f(wo, sampler.next_1d(), sampler.next_2d()) else {
                break;
            };
            beta *= bs.f * (bs.wi.dot(si.ns).abs() / bs.pdf);
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            prev = Some((si.p, if bs.delta { f32::INFINITY } else { bs.pdf }));
            depth += 1;
            let u_rr = sampler.next_1d();
            if depth >= self.rr_depth {
                let q = beta.max_element().min(0.95);
                if u_rr >= q {
                    break;
                }
                beta /= q;
            }
            if self.only_bounce.is_some_and(|k| depth > k) {
                break;
            }
            ray = spawn_ray(si.p, si.ng, bs.wi);
        }
        l
    }
}
