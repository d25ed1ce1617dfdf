//! Integrators: estimators of the radiance arriving along a camera ray.
//!
//! - [`PathIntegrator`]: unidirectional path tracing with next-event estimation, multiple
//!   importance sampling of light and BSDF samples (power heuristic), Russian roulette and
//!   per-bounce output;
//! - [`BdptIntegrator`]: bidirectional path tracing, camera and light subpaths joined by every
//!   strategy and weighted by MIS;
//! - [`DirectIntegrator`]: direct lighting only, by one of four strategies (uniform hemisphere,
//!   cosine-weighted hemisphere, light sampling, MIS), the course's comparison;
//! - debug views: shading normals, distance, BVH nodes visited.

mod bdpt;
mod choice;
mod debug;
mod direct;
mod packet;
mod path;

pub use bdpt::BdptIntegrator;
pub use choice::{IntegratorChoice, IntegratorName};
pub use debug::DebugView;
pub use direct::{direct_samples, DirectIntegrator, DirectSample, DirectStrategy, SampleStrategy};
pub use path::{PathIntegrator, PathLighting};

use crate::bsdf::Bsdf;
use crate::desc::{RayKind, Rgb};
use crate::geometry::{offset_ray_origin, spawn_ray_to, Ray};
use crate::light::{Light, LightLiSample};
use crate::scene::{Scene, SurfaceInteraction};
use glam::{Vec2, Vec3};
use pathlab_mc::sampler::{AnySampler, Sampler};
use pathlab_mc::simd::lanes::Real;

/// Counters an integrator keeps while it works.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathStats {
    /// Rays traced (closest-hit and shadow).
    pub rays: u64,
    /// BVH nodes visited by closest-hit rays.
    pub nodes_visited: u64,
    /// Surface points at which a path drew random numbers that could change its radiance
    /// (a BSDF that is not black). A pixel whose samples added none has radiance that only
    /// its camera rays decide (they escaped, or met black emitters): see
    /// [`crate::render::Adaptive`].
    pub random_vertices: u64,
}

impl PathStats {
    /// Adds another's counts.
    pub fn merge(&mut self, o: &PathStats) {
        self.rays += o.rays;
        self.nodes_visited += o.nodes_visited;
        self.random_vertices += o.random_vertices;
    }
}

/// One pixel sample to estimate: its pixel, its index among the pixel's samples, and a tag
/// by which the caller files the result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleRef {
    /// The pixel.
    pub pixel: [u32; 2],
    /// The sample's index in the pixel (what positions the sampler).
    pub index: u32,
    /// The caller's tag for the result.
    pub tag: u32,
}

/// Computes the radiance along camera rays.
pub trait Integrator: Sync {
    /// An estimate of the radiance arriving at the camera along `ray`, from the sampler's
    /// next dimensions.
    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb;

    /// Whether [`Integrator::li_splat`] traces light to the lens in `scene`, adding radiance
    /// to film positions other than the sample's (which the render loop then collects).
    fn splats(&self, _scene: &Scene) -> bool {
        false
    }

    /// [`Integrator::li`], also handing the radiance that light traced to the lens brings to
    /// film position `film` (pixels) to `splat`, for a film whose splats are divided by the
    /// light paths traced (one per call) and multiplied by the pixel count
    /// ([`crate::film::Film`]). By default [`Integrator::li`], which splats nothing.
    fn li_splat(
        &self,
        scene: &Scene,
        ray: Ray,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
        _splat: &mut dyn FnMut(Vec2, Rgb),
    ) -> Rgb {
        self.li(scene, ray, sampler, stats)
    }

    /// Estimates each of `samples`: positions `sampler` at the sample, makes its camera ray
    /// ([`camera_ray`]) and hands `(tag, radiance)` to `out`. By default one sample after
    /// another with [`Integrator::li`]; an integrator that follows several paths together may
    /// finish them in another order, always the same one for the same samples.
    fn li_samples(
        &self,
        scene: &Scene,
        sampler: &mut AnySampler,
        samples: &mut dyn Iterator<Item = SampleRef>,
        out: &mut dyn FnMut(u32, Rgb),
        stats: &mut PathStats,
    ) {
        li_one_at_a_time(self, scene, sampler, samples, out, stats);
    }
}

/// [`Integrator::li_samples`] one sample after another with [`Integrator::li`] (the default).
pub fn li_one_at_a_time<I: Integrator + ?Sized>(
    integrator: &I,
    scene: &Scene,
    sampler: &mut AnySampler,
    samples: &mut dyn Iterator<Item = SampleRef>,
    out: &mut dyn FnMut(u32, Rgb),
    stats: &mut PathStats,
) {
    for s in samples {
        let (ray, weight) = camera_ray(scene, sampler, s);
        out(s.tag, integrator.li(scene, ray, sampler, stats) * weight);
    }
}

/// Positions `sampler` at pixel sample `s` and makes its camera ray from the first
/// dimensions: the position in the pixel, then the point on the lens; with the weight the
/// sample's radiance takes (one, except under a pixel filter with negative lobes).
#[inline]
pub fn camera_ray(scene: &Scene, sampler: &mut AnySampler, s: SampleRef) -> (Ray, f32) {
    let c = camera_sample(scene, sampler, s);
    (scene.camera().generate_ray(c.film, c.u_lens), c.weight)
}

/// What a camera ray is made from: the film position, the weight of the sample's radiance
/// and the lens sample.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CameraSample {
    pub film: glam::Vec2,
    pub weight: f32,
    pub u_lens: glam::Vec2,
}

/// [`camera_ray`]'s use of the sampler: positions it at pixel sample `s` and draws the
/// position in the pixel, then the point on the lens. Inlined always: called, it returns the
/// sample through memory, written field by field, and the caller's copy of it as one block
/// then waits for those writes to finish (a failed store-to-load forward; half of the
/// eight-lane path's `start_paths` in the profile of a cheap scene).
#[inline(always)]
pub(crate) fn camera_sample(scene: &Scene, sampler: &mut AnySampler, s: SampleRef) -> CameraSample {
    sampler.start_pixel_sample(s.pixel, s.index, 0);
    let (film, weight) = scene.camera().film_sample(s.pixel, sampler.next_pixel_2d());
    let u_lens = sampler.next_2d();
    CameraSample {
        film,
        weight,
        u_lens,
    }
}

/// Which integrator, with its settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegratorKind {
    /// Path tracing.
    Path(PathIntegrator),
    /// Bidirectional path tracing.
    Bdpt(BdptIntegrator),
    /// Direct lighting.
    Direct(DirectIntegrator),
    /// A debug view.
    Debug(DebugView),
}

impl IntegratorKind {
    /// The integrator a scene file asks for ([`crate::desc::RenderHints`]): its path tracer
    /// (or bidirectional path tracer) with the file's depth, roulette and emitter visibility,
    /// or direct lighting with its
    /// numbers of light and BSDF samples combined by MIS; the path tracer without a hint.
    pub fn from_hints(hints: &crate::desc::RenderHints) -> IntegratorKind {
        match hints.integrator {
            Some(crate::desc::IntegratorHint::Direct {
                emitter_samples,
                bsdf_samples,
            }) => IntegratorKind::Direct(DirectIntegrator {
                strategy: DirectStrategy::Mis,
                samples: emitter_samples,
                bsdf_samples: Some(bsdf_samples),
                hide_emitters: hints.hide_emitters,
            }),
            Some(crate::desc::IntegratorHint::Bdpt) => IntegratorKind::Bdpt(BdptIntegrator {
                max_depth: hints.max_depth.unwrap_or(u32::MAX),
                rr_depth: hints.rr_depth.unwrap_or(5),
                hide_emitters: hints.hide_emitters,
            }),
            Some(crate::desc::IntegratorHint::Path) | None => {
                let default = PathIntegrator::default();
                IntegratorKind::Path(PathIntegrator {
                    max_depth: hints.max_depth.unwrap_or(default.max_depth),
                    rr_depth: hints.rr_depth.unwrap_or(default.rr_depth),
                    hide_emitters: hints.hide_emitters,
                    ..default
                })
            }
        }
    }
}

impl Integrator for IntegratorKind {
    fn splats(&self, scene: &Scene) -> bool {
        match self {
            IntegratorKind::Bdpt(i) => i.splats(scene),
            _ => false,
        }
    }

    fn li_splat(
        &self,
        scene: &Scene,
        ray: Ray,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
        splat: &mut dyn FnMut(Vec2, Rgb),
    ) -> Rgb {
        match self {
            IntegratorKind::Bdpt(i) => i.li_splat(scene, ray, sampler, stats, splat),
            _ => self.li(scene, ray, sampler, stats),
        }
    }

    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        match self {
            IntegratorKind::Path(i) => i.li(scene, ray, sampler, stats),
            IntegratorKind::Bdpt(i) => i.li(scene, ray, sampler, stats),
            IntegratorKind::Direct(i) => i.li(scene, ray, sampler, stats),
            IntegratorKind::Debug(i) => i.li(scene, ray, sampler, stats),
        }
    }

    fn li_samples(
        &self,
        scene: &Scene,
        sampler: &mut AnySampler,
        samples: &mut dyn Iterator<Item = SampleRef>,
        out: &mut dyn FnMut(u32, Rgb),
        stats: &mut PathStats,
    ) {
        match self {
            IntegratorKind::Path(i) => i.li_samples(scene, sampler, samples, out, stats),
            IntegratorKind::Bdpt(i) => i.li_samples(scene, sampler, samples, out, stats),
            IntegratorKind::Direct(i) => i.li_samples(scene, sampler, samples, out, stats),
            IntegratorKind::Debug(i) => i.li_samples(scene, sampler, samples, out, stats),
        }
    }
}

/// Closest hit of a ray of `kind`, counting the ray.
#[inline]
pub(crate) fn trace(
    scene: &Scene,
    ray: &Ray,
    kind: RayKind,
    stats: &mut PathStats,
) -> Option<SurfaceInteraction> {
    let (hit, visited) = match kind {
        RayKind::Camera => scene.intersect_camera(ray),
        RayKind::Indirect => scene.intersect(ray),
    };
    stats.rays += 1;
    stats.nodes_visited += visited as u64;
    hit
}

/// The power heuristic with exponent 2 (Veach 1997) for `nf` samples of density `f_pdf`
/// against `ng` samples of density `g_pdf`.
#[inline]
pub fn power_heuristic(nf: u32, f_pdf: f32, ng: u32, g_pdf: f32) -> f32 {
    power_heuristic_weight(nf as f32 * f_pdf, ng as f32 * g_pdf)
}

/// The power heuristic's weight f² / (f² + g²) of a strategy with (sample count times)
/// density `f` against one with `g`: one where `f` overflowed to infinity (light sampling's
/// density at a grazing angle), zero where both vanish. For one value or for lanes. (Delta
/// lobes and delta lights are flagged, not given infinite densities: their callers give
/// them weight one without asking.)
#[inline(always)]
pub fn power_heuristic_weight<T: Real>(f: T, g: T) -> T {
    let (zero, one) = (T::splat(0.0), T::splat(1.0));
    let (f2, g2) = (f * f, g * g);
    T::select(
        f.is_infinite(),
        one,
        T::select((f2 + g2).equals(zero), zero, f2 / (f2 + g2)),
    )
}

/// A light sample that reaches a surface point: the light chosen and the probability of
/// choosing it, the sample, and f |cos θi| towards it (all positive).
pub(crate) struct VisibleLightSample {
    /// The light's index.
    pub(crate) index: usize,
    /// The probability of choosing it.
    pub(crate) pmf: f32,
    /// The sample.
    pub(crate) ls: LightLiSample,
    /// f(wo, wi) |cos θi| along it.
    pub(crate) f: Rgb,
}

/// Light sampling at surface point `si` seen from `wo`: a light chosen by `u_select`, a point
/// or direction on it by `u_light`, kept when it carries light, the BSDF passes it and a
/// shadow ray finds nothing in between (the ray is counted). The one light sample of the path
/// tracer, the direct integrator and the bidirectional path tracer's s = 1 strategy.
pub(crate) fn visible_light_sample(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    (u_select, u_light): (f32, Vec2),
    stats: &mut PathStats,
) -> Option<VisibleLightSample> {
    let (index, pmf) = scene.light_sampler().sample(u_select)?;
    let light = &scene.lights()[index];
    // An environment map's radiance is read last, once the sample is known to count.
    let deferred = light.sample_li_deferred(si.p, u_light)?;
    let ls = deferred.ls;
    if !ls.may_carry_light(deferred.has_li()) {
        return None;
    }
    let f = bsdf.f_cos(wo, ls.wi);
    if f.max_element() <= 0.0 {
        return None;
    }
    stats.rays += 1;
    if scene.occluded(&shadow_ray(light, si, &ls)) {
        return None;
    }
    let li = light.deferred_li(&deferred);
    if li.max_element() <= 0.0 {
        return None;
    }
    Some(VisibleLightSample {
        index,
        pmf,
        ls: LightLiSample { li, ..ls },
        f,
    })
}

/// The shadow ray from surface point `si` towards `light`'s sample `ls`: along its direction
/// without end for a light at infinity, otherwise to just short of its point.
#[inline]
pub(crate) fn shadow_ray(light: &Light, si: &SurfaceInteraction, ls: &LightLiSample) -> Ray {
    if light.is_infinite() {
        Ray::new(offset_ray_origin(si.p, si.ng, ls.wi), ls.wi)
    } else {
        spawn_ray_to(si.p, si.ng, ls.p_light, ls.n_light)
    }
}

/// A light sample's contribution f · Li · |cos θi| / p at a surface point, weighted by MIS
/// against `bsdf_samples` BSDF samples when that is nonzero (delta lights always get weight 1).
/// `light_samples` is how many such light samples the caller averages.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sample_light(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    u_select: f32,
    u_light: Vec2,
    light_samples: u32,
    bsdf_samples: u32,
    stats: &mut PathStats,
) -> Rgb {
    let Some(VisibleLightSample { pmf, ls, f, .. }) =
        visible_light_sample(scene, si, bsdf, wo, (u_select, u_light), stats)
    else {
        return Rgb::ZERO;
    };
    let pdf = pmf * ls.pdf;
    let weight = if ls.is_delta || bsdf_samples == 0 {
        1.0
    } else {
        power_heuristic(light_samples, pdf, bsdf_samples, bsdf.pdf(wo, ls.wi))
    };
    f * ls.li * (weight / pdf)
}

/// Radiance emitted towards the previous vertex by the surface a ray from `p_prev` hit, and the
/// density with which light sampling at `p_prev` would have chosen that point (for MIS).
/// Inlined always: at every hit of every path, where the compiler's choice to call it or not
/// moved with unrelated changes (a call measured about 2% slower on the Cornell box).
#[inline(always)]
pub(crate) fn emitted(
    scene: &Scene,
    p_prev: Vec3,
    ray: &Ray,
    si: &SurfaceInteraction,
) -> Option<(Rgb, f32)> {
    let index = si.light?;
    let light = &scene.lights()[index as usize];
    let le = light.le(si.ng, -ray.d, si.uv);
    if le.max_element() <= 0.0 {
        return None;
    }
    let pdf =
        scene.light_sampler().pmf(index as usize) * light.pdf_li_at(p_prev, ray.d, si.p, si.ng);
    Some((le, pdf))
}

/// Environment radiance along a ray that left the scene, and the density with which light
/// sampling would have chosen its direction: computed where `pdf_needed` (for an MIS weight),
/// 0 otherwise (a camera ray, a delta lobe's ray).
#[inline]
pub(crate) fn escaped(scene: &Scene, ray: &Ray, pdf_needed: bool) -> Option<(Rgb, f32)> {
    escaped_looked_up(scene, ray, pdf_needed, None)
}

/// [`escaped`], where `looked_up` may hold the environment's radiance towards the ray and
/// its density ([`Light::le_and_pdf_towards`]), found beforehand (by the eight-lane path, for
/// several rays at once).
#[inline]
pub(crate) fn escaped_looked_up(
    scene: &Scene,
    ray: &Ray,
    pdf_needed: bool,
    looked_up: Option<(Rgb, f32)>,
) -> Option<(Rgb, f32)> {
    let index = scene.environment()?;
    let light = &scene.lights()[index as usize];
    if !pdf_needed {
        // (`le_and_pdf_towards` gives `le_environment`'s radiance, to the bit.)
        let le = looked_up.map_or_else(|| light.le_environment(ray.d), |(le, _)| le);
        return Some((le, 0.0));
    }
    let (le, pdf) = looked_up.unwrap_or_else(|| light.le_and_pdf_towards(ray.d));
    Some((le, scene.light_sampler().pmf(index as usize) * pdf))
}
