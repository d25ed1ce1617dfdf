//! Bidirectional path tracing ([`BdptIntegrator`], Veach 1997, ch. 10; pbrt-v4's
//! `BDPTIntegrator`).
//!
//! Each pixel sample traces a camera subpath x₀ x₁ … (x₀ on the lens) and a light subpath
//! y₀ y₁ … (y₀ on a light, chosen by the scene's light sampler, its ray by
//! [`crate::light::Light::sample_le`]), then joins every prefix of one with every prefix of the
//! other: strategy (s, t) takes s light vertices and t camera vertices, so that the same path
//! of length s + t − 1 segments can come from several strategies. s = 0 is the camera path
//! finding emission itself, s = 1 light sampling at its last vertex, s ≥ 2 a shadow ray
//! between xₜ₋₁ and yₛ₋₁, and t = 1 light tracing: yₛ₋₁ joined to a point on the lens
//! ([`crate::camera::Camera::sample_wi`]), its contribution splatted on the film position it
//! reaches, which may be another pixel's ([`Integrator::li_splat`]). Each contribution is
//! weighted by the power heuristic over the densities with which every other strategy would
//! have produced the same path (computed from the per-vertex densities `pdf_fwd` and
//! `pdf_rev`, both per unit area, recomputed from the vertices' positions), so that the
//! weights of one path sum to one and the estimate stays unbiased.
//!
//! Light tracing is taken when the render loop collects splats and the camera can receive
//! light (a perspective camera without clipping planes); otherwise (adaptive sampling, one
//! pixel's samples, an orthographic camera) the other strategies share its paths, caustics
//! seen directly then being found by s = 0 alone, as the path tracer finds them. Lights that
//! do not emit rays (at infinity, projectors) are reached by s = 0 and s = 1 only.
//!
//! Light subpaths carry importance: at their vertices the BSDF is the adjoint one
//! ([`crate::bsdf::Bsdf::f_cos_importance`]; a delta refraction's weight without the 1/η'²
//! that scales radiance, [`crate::bsdf::BsdfSample::eta`]).

#[cfg(test)]
mod tests;
mod vertex;

use super::{trace, visible_light_sample, Integrator, PathStats, VisibleLightSample};
use crate::desc::{RayKind, Rgb};
use crate::geometry::{offset_ray_origin, spawn_ray, spawn_ray_to, Ray};
use crate::scene::Scene;
use glam::Vec2;
use pathlab_mc::sampler::{AnySampler, Sampler};
use vertex::{Kind, Vertex};

/// Bidirectional path tracing with the power heuristic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BdptIntegrator {
    /// Largest bounce counted, s + t − 2 (`u32::MAX`: unbounded).
    pub max_depth: u32,
    /// First bounce of either subpath at which Russian roulette may end it.
    pub rr_depth: u32,
    /// Camera rays see no emitters.
    pub hide_emitters: bool,
}

impl Default for BdptIntegrator {
    fn default() -> Self {
        BdptIntegrator {
            max_depth: u32::MAX,
            rr_depth: 5,
            hide_emitters: false,
        }
    }
}

/// The vertices of one sample's two subpaths.
struct Subpaths {
    camera: Vec<Vertex>,
    light: Vec<Vertex>,
    /// Whether this sample takes the light-tracing strategies (t = 1): when its light can be
    /// splatted on the film, and the camera can receive it.
    light_tracing: bool,
}

impl BdptIntegrator {
    /// Follows `ray` from the subpath's last vertex, appending at most `max_vertices` surface
    /// (or, for the camera, escaped) vertices. `importance`: a light subpath, whose BSDFs are
    /// the adjoint ones.
    #[allow(clippy::too_many_arguments)]
    fn random_walk(
        &self,
        scene: &Scene,
        path: &mut Vec<Vertex>,
        mut ray: Ray,
        mut beta: Rgb,
        max_vertices: u32,
        importance: bool,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) {
        // The product of the BSDF weights alone, for Russian roulette (a light subpath's
        // throughput starts at the light's radiance over its density).
        let mut walk = Rgb::ONE;
        // The product of η'² over a camera subpath's refractions: Russian roulette weighs its
        // walk without refraction's radiance scaling, as the path tracer does.
        let mut eta_scale = 1.0f32;
        let mut bounces = 0u32;
        while bounces < max_vertices {
            let kind = if importance {
                RayKind::Indirect
            } else {
                RayKind::at_depth(bounces)
            };
            let Some(si) = trace(scene, &ray, kind, stats) else {
                if let (false, Some(env)) = (importance, scene.environment()) {
                    let mut v = Vertex::endpoint(Kind::Infinite, ray.d, None, Some(env), beta);
                    v.wo = -ray.d;
                    Self::append(scene, path, v);
                }
                return;
            };
            let wo = -ray.d;
            let bsdf = scene.bsdf(&si, wo);
            let mut v = Vertex::endpoint(Kind::Surface, si.p, Some(si.ng), si.light, beta);
            v.wo = wo;
            v.surface = Some((si, bsdf));
            Self::append(scene, path, v);
            bounces += 1;
            if !importance {
                stats.random_vertices += u64::from(!bsdf.is_black());
            }
            if bounces >= max_vertices {
                return;
            }
            let Some(bs) = bsdf.sample_f(wo, sampler.next_1d(), sampler.next_2d()) else {
                return;
            };
            let weight = match (importance, bs.delta) {
                (false, _) => bs.f * (bs.cos / bs.pdf),
                (true, false) => bsdf.f_cos_importance(wo, bs.wi) / bs.pdf,
                (true, true) => bs.f * (bs.cos / bs.pdf * (bs.eta * bs.eta)),
            };
            beta *= weight;
            walk *= weight;
            if !importance {
                eta_scale *= bs.eta * bs.eta;
            }
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                return;
            }
            if let Some(last) = path.last_mut() {
                last.delta = bs.delta;
            }
            if bounces >= self.rr_depth {
                let q = (walk * eta_scale).max_element().min(0.95);
                if sampler.next_1d() >= q {
                    return;
                }
                beta /= q;
                walk /= q;
            }
            ray = spawn_ray(si.p, si.ng, bs.wi);
        }
    }

    /// Appends `v` to `path`, with the density per unit area with which the vertex before
    /// produced it, and sets the reverse density of the one before that. Both come from the
    /// vertices' positions by [`BdptIntegrator::pdf`], as every density the MIS weights
    /// recompute does (not from the sample's own density and direction, which the ray's
    /// offset origin and rounding make differ slightly, by a few percent for short grazing
    /// segments): the weights of one path must sum to one. Zero after a delta lobe.
    fn append(scene: &Scene, path: &mut Vec<Vertex>, mut v: Vertex) {
        let k = path.len();
        let prev = &path[k - 1];
        if !prev.delta {
            v.pdf_fwd = Self::pdf(scene, prev, k.checked_sub(2).map(|i| &path[i]), &v);
            if k >= 2 {
                path[k - 2].pdf_rev = Self::pdf(scene, &path[k - 1], Some(&v), &path[k - 2]);
            }
        }
        path.push(v);
    }

    /// The camera subpath of camera ray `ray` and a light subpath.
    fn subpaths(
        &self,
        scene: &Scene,
        ray: Ray,
        light_tracing: bool,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Subpaths {
        let mut camera = Vec::with_capacity(8);
        camera.push(Vertex::endpoint(Kind::Camera, ray.o, None, None, Rgb::ONE));
        let max_camera = self.max_depth.saturating_add(1);
        self.random_walk(
            scene,
            &mut camera,
            ray,
            Rgb::ONE,
            max_camera,
            false,
            sampler,
            stats,
        );
        let light = self.light_subpath(scene, sampler, stats);
        Subpaths {
            camera,
            light,
            light_tracing,
        }
    }

    /// A light subpath: a light chosen by the light sampler, a ray of its light
    /// ([`crate::light::Light::sample_le`]), and the walk from it. Empty when the light
    /// chosen emits no rays (it lies at infinity).
    fn light_subpath(
        &self,
        scene: &Scene,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Vec<Vertex> {
        let mut light = Vec::with_capacity(8);
        let u_select = sampler.next_1d();
        let (u_pos, u_dir) = (sampler.next_2d(), sampler.next_2d());
        let Some((index, pmf)) = scene.light_sampler().sample(u_select) else {
            return light;
        };
        let Some(le) = scene.lights()[index].sample_le(u_pos, u_dir) else {
            return light;
        };
        let pdf_pos = pmf * le.pdf_pos;
        let cos = le.n.map_or(1.0, |n| n.dot(le.w).abs());
        let mut y0 = Vertex::endpoint(Kind::Light, le.p, le.n, Some(index as u32), le.le);
        y0.pdf_fwd = pdf_pos;
        light.push(y0);
        let beta = le.le * (cos / (pdf_pos * le.pdf_dir));
        let o = match le.n {
            Some(n) => offset_ray_origin(le.p, n, le.w),
            None => le.p,
        };
        let ray = Ray::new(o, le.w);
        self.random_walk(
            scene,
            &mut light,
            ray,
            beta,
            self.max_depth,
            true,
            sampler,
            stats,
        );
        light
    }

    /// Density per unit area at `next` with which the light `v` lies on emits towards it.
    fn pdf_light(scene: &Scene, v: &Vertex, next: &Vertex) -> f32 {
        let Some(light) = v.light.map(|i| &scene.lights()[i as usize]) else {
            return 0.0;
        };
        if v.kind == Kind::Infinite {
            // Lights at infinity start no subpaths: no strategy needs this.
            return 0.0;
        }
        let w = next.p - v.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let pdf_dir = light.pdf_le_dir(v.n, w / d2.sqrt());
        v.convert_density(pdf_dir, next)
    }

    /// Density with which a light subpath (or light sampling) starts at endpoint `v`: per unit
    /// area on a surface, per unit solid angle at infinity.
    fn pdf_light_origin(scene: &Scene, v: &Vertex) -> f32 {
        let Some(index) = v.light else { return 0.0 };
        let light = &scene.lights()[index as usize];
        let pmf = scene.light_sampler().pmf(index as usize);
        if v.kind == Kind::Infinite {
            pmf * light.pdf_li_towards(v.p)
        } else {
            pmf * light.pdf_le_pos()
        }
    }

    /// Density per unit area at `next` with which vertex `v`, reached from `prev`, produces it.
    fn pdf(scene: &Scene, v: &Vertex, prev: Option<&Vertex>, next: &Vertex) -> f32 {
        match v.kind {
            Kind::Light | Kind::Infinite => Self::pdf_light(scene, v, next),
            Kind::Camera => {
                let w = v.towards(next);
                v.convert_density(scene.camera().pdf_we_dir(v.p, w), next)
            }
            Kind::Surface => {
                let (Some((_, bsdf)), Some(prev)) = (&v.surface, prev) else {
                    return 0.0;
                };
                let pdf = bsdf.pdf(v.towards(prev), v.towards(next));
                v.convert_density(pdf, next)
            }
        }
    }

    /// The power-heuristic weight of strategy (s, t), `sampled` being the vertex this strategy
    /// chose itself: the light point of light sampling (s = 1), or the lens point of light
    /// tracing (t = 1). `emits`: whether the path's light starts subpaths; `delta_light`:
    /// whether no ray can hit it. Light tracing counts among the strategies when the sample
    /// takes it ([`Subpaths::light_tracing`]).
    #[allow(clippy::too_many_arguments)]
    fn mis_weight(
        scene: &Scene,
        paths: &Subpaths,
        sampled: Option<&Vertex>,
        s: usize,
        t: usize,
        emits: bool,
        delta_light: bool,
    ) -> f32 {
        if s + t == 2 {
            return 1.0;
        }
        let qs = match s {
            0 => None,
            1 => sampled,
            _ => Some(&paths.light[s - 1]),
        };
        let (pt, pt_minus) = match t {
            1 => match sampled {
                Some(lens) => (lens, None),
                None => return 0.0,
            },
            _ => (&paths.camera[t - 1], Some(&paths.camera[t - 2])),
        };
        let qs_minus = (s > 1).then(|| &paths.light[s - 2]);
        // The reverse densities the join changes (of x_{t-1}, x_{t-2}, y_{s-1}, y_{s-2}).
        let (pt_rev, pt_minus_rev, qs_rev, qs_minus_rev) = match (qs, pt_minus) {
            (Some(qs), _) => (
                Self::pdf(scene, qs, qs_minus, pt),
                pt_minus.map_or(0.0, |pm| Self::pdf(scene, pt, Some(qs), pm)),
                Self::pdf(scene, pt, pt_minus, qs),
                qs_minus.map_or(0.0, |qm| Self::pdf(scene, qs, Some(pt), qm)),
            ),
            (None, Some(pt_minus)) => (
                Self::pdf_light_origin(scene, pt),
                Self::pdf_light(scene, pt, pt_minus),
                0.0,
                0.0,
            ),
            (None, None) => return 0.0,
        };
        // (pdf_fwd, pdf_rev, delta) of the vertices of this strategy's path; the vertices
        // joined are not degenerate, whatever their subpaths left them by.
        let camera = |i: usize| {
            let v = &paths.camera[i];
            match t - 1 - i {
                0 => (v.pdf_fwd, pt_rev, false),
                1 => (v.pdf_fwd, pt_minus_rev, v.delta),
                _ => (v.pdf_fwd, v.pdf_rev, v.delta),
            }
        };
        let light = |i: usize| {
            let v = match (s, qs) {
                (1, Some(sampled)) => sampled,
                _ => &paths.light[i],
            };
            match s - 1 - i {
                0 => (v.pdf_fwd, qs_rev, false),
                1 => (v.pdf_fwd, qs_minus_rev, v.delta),
                _ => (v.pdf_fwd, v.pdf_rev, v.delta),
            }
        };
        let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
        let mut sum = 0.0f32;
        // Strategies with fewer camera vertices, down to t = 1 when light tracing is taken,
        // else t = 2.
        let lowest = if paths.light_tracing { 1 } else { 2 };
        let mut ri = 1.0f32;
        for i in (lowest..t).rev() {
            let (fwd, rev, delta) = camera(i);
            ri *= remap(rev) / remap(fwd);
            let s_other = s + t - i;
            if !delta && !camera(i - 1).2 && (emits || s_other < 2) {
                sum += ri * ri;
            }
        }
        // Strategies with fewer light vertices, down to s = 0.
        ri = 1.0;
        for i in (0..s).rev() {
            let (fwd, rev, delta) = light(i);
            ri *= remap(rev) / remap(fwd);
            let delta_before = if i > 0 { light(i - 1).2 } else { delta_light };
            if !delta && !delta_before {
                sum += ri * ri;
            }
        }
        let w = 1.0 / (1.0 + sum);
        if w.is_finite() {
            w
        } else {
            0.0
        }
    }

    /// Strategy s = 0: the camera subpath's vertex t − 1 is on a light.
    fn emission(&self, scene: &Scene, paths: &Subpaths, t: usize) -> Rgb {
        let pt = &paths.camera[t - 1];
        if t == 2 && self.hide_emitters {
            return Rgb::ZERO;
        }
        let Some(index) = pt.light else {
            return Rgb::ZERO;
        };
        let light = &scene.lights()[index as usize];
        let le = match (&pt.surface, pt.kind) {
            (Some((si, _)), _) => light.le(si.ng, pt.wo, si.uv),
            (None, Kind::Infinite) => light.le_environment(pt.p),
            _ => Rgb::ZERO,
        };
        let l = pt.beta * le;
        if l.max_element() <= 0.0 {
            return Rgb::ZERO;
        }
        if Self::pdf_light_origin(scene, pt) == 0.0 {
            // On a light no other strategy samples.
            return l;
        }
        l * Self::mis_weight(scene, paths, None, 0, t, light.emits_rays(), false)
    }

    /// Strategy s = 1: light sampling at the camera subpath's vertex t − 1.
    fn light_sample(
        &self,
        scene: &Scene,
        paths: &Subpaths,
        t: usize,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Rgb {
        let pt = &paths.camera[t - 1];
        let Some((si, bsdf)) = pt.connectible() else {
            return Rgb::ZERO;
        };
        let u = (sampler.next_1d(), sampler.next_2d());
        let Some(VisibleLightSample { index, pmf, ls, f }) =
            visible_light_sample(scene, si, bsdf, pt.wo, u, stats)
        else {
            return Rgb::ZERO;
        };
        let light = &scene.lights()[index];
        let (kind, p) = if light.is_infinite() {
            (Kind::Infinite, ls.wi)
        } else {
            (Kind::Light, ls.p_light)
        };
        let mut sampled = Vertex::endpoint(kind, p, ls.n_light, Some(index as u32), Rgb::ZERO);
        sampled.pdf_fwd = Self::pdf_light_origin(scene, &sampled);
        let l = pt.beta * f * ls.li / (pmf * ls.pdf);
        let w = Self::mis_weight(
            scene,
            paths,
            Some(&sampled),
            1,
            t,
            light.emits_rays(),
            ls.is_delta,
        );
        l * w
    }

    /// Strategy s ≥ 2, t ≥ 2: a shadow ray between the light subpath's vertex s − 1 and the
    /// camera subpath's vertex t − 1.
    fn join(
        &self,
        scene: &Scene,
        paths: &Subpaths,
        s: usize,
        t: usize,
        stats: &mut PathStats,
    ) -> Rgb {
        let (qs, pt) = (&paths.light[s - 1], &paths.camera[t - 1]);
        let (Some((sq, bq)), Some((sp, bp))) = (qs.connectible(), pt.connectible()) else {
            return Rgb::ZERO;
        };
        let d = qs.p - pt.p;
        let d2 = d.length_squared();
        if d2 == 0.0 {
            return Rgb::ZERO;
        }
        let w = d / d2.sqrt();
        let l = qs.beta * bq.f_cos_importance(qs.wo, -w) * bp.f_cos(pt.wo, w) * pt.beta / d2;
        if l.max_element() <= 0.0 || !l.is_finite() {
            return Rgb::ZERO;
        }
        stats.rays += 1;
        if scene.occluded(&spawn_ray_to(sp.p, sp.ng, sq.p, Some(sq.ng))) {
            return Rgb::ZERO;
        }
        let delta_light = paths.light[0]
            .light
            .is_some_and(|i| scene.lights()[i as usize].is_delta_position());
        l * Self::mis_weight(scene, paths, None, s, t, true, delta_light)
    }
}

impl BdptIntegrator {
    /// The estimate of one camera ray: every strategy's weighted contribution, those of light
    /// tracing handed to `splat` when there is one.
    fn estimate(
        &self,
        scene: &Scene,
        ray: Ray,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
        mut splat: Option<&mut dyn FnMut(Vec2, Rgb)>,
    ) -> Rgb {
        let light_tracing = splat.is_some() && self.splats(scene);
        let paths = self.subpaths(scene, ray, light_tracing, sampler, stats);
        let mut l = Rgb::ZERO;
        let within = |s: usize, t: usize| (s + t - 2) as u64 <= self.max_depth as u64;
        if let Some(splat) = splat.as_mut().filter(|_| light_tracing) {
            for s in (2..=paths.light.len()).take_while(|&s| within(s, 1)) {
                if let Some((film, v)) = self.light_trace(scene, &paths, s, sampler, stats) {
                    splat(film, v);
                }
            }
        }
        for t in 2..=paths.camera.len() {
            // s = 1 samples its own light point, so it needs no light subpath.
            for s in (0..=paths.light.len().max(1)).take_while(|&s| within(s, t)) {
                l += match s {
                    0 => self.emission(scene, &paths, t),
                    1 => self.light_sample(scene, &paths, t, sampler, stats),
                    _ => self.join(scene, &paths, s, t, stats),
                };
            }
        }
        l
    }

    /// Strategy t = 1: the light subpath's vertex s − 1 joined to a point on the lens; the
    /// film position it reaches and its weighted contribution there.
    fn light_trace(
        &self,
        scene: &Scene,
        paths: &Subpaths,
        s: usize,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> Option<(Vec2, Rgb)> {
        let qs = &paths.light[s - 1];
        let u = sampler.next_2d();
        let (sq, bq) = qs.connectible()?;
        let cs = scene.camera().sample_wi(sq.p, u)?;
        let l = qs.beta * bq.f_cos_importance(qs.wo, cs.wi) * (cs.we / cs.pdf);
        if l.max_element() <= 0.0 || !l.is_finite() {
            return None;
        }
        stats.rays += 1;
        if scene.occluded(&spawn_ray_to(sq.p, sq.ng, cs.p_lens, None)) {
            return None;
        }
        let lens = Vertex::endpoint(Kind::Camera, cs.p_lens, None, None, Rgb::ZERO);
        let delta_light = paths.light[0]
            .light
            .is_some_and(|i| scene.lights()[i as usize].is_delta_position());
        let w = Self::mis_weight(scene, paths, Some(&lens), s, 1, true, delta_light);
        Some((cs.film, l * w))
    }
}

impl Integrator for BdptIntegrator {
    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        self.estimate(scene, ray, sampler, stats, None)
    }

    fn splats(&self, scene: &Scene) -> bool {
        scene.camera().supports_light_tracing()
    }

    fn li_splat(
        &self,
        scene: &Scene,
        ray: Ray,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
        splat: &mut dyn FnMut(Vec2, Rgb),
    ) -> Rgb {
        self.estimate(scene, ray, sampler, stats, Some(splat))
    }
}
