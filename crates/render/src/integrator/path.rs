//! The path tracer ([`PathIntegrator`]): at each vertex, emission where no other strategy
//! could have found it, light sampling and BSDF sampling combined by multiple importance
//! sampling ([`PathLighting`]), then Russian roulette.

use super::{
    emitted, escaped_looked_up, li_one_at_a_time, power_heuristic, sample_light, trace, Integrator,
    PathStats, SampleRef,
};
use crate::desc::{RayKind, Rgb};
use crate::geometry::{spawn_ray, Ray};
use crate::scene::{Scene, SurfaceInteraction};
use glam::Vec3;
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
/// q = min(max component of β η², 0.95) and its throughput β is divided by q, which keeps the
/// estimator unbiased for any such q. η² is the product of the squared relative indices of
/// the refractions so far (pbrt-v4's `etaScale`, Mitsuba's `eta²`): refraction scales
/// radiance by 1/η'², which inside glass would otherwise end paths for a factor that leaving
/// the glass undoes, and so add variance.
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
    /// Camera rays see no emitters (lights still light the scene).
    pub hide_emitters: bool,
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

impl PathLighting {
    /// Every way, MIS first.
    pub const ALL: [PathLighting; 3] = [PathLighting::Mis, PathLighting::Bsdf, PathLighting::Light];

    /// The name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            PathLighting::Mis => "mis",
            PathLighting::Bsdf => "bsdf",
            PathLighting::Light => "light",
        }
    }
}

impl std::str::FromStr for PathLighting {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let what = "lighting";
        pathlab_mc::named::by_name(s, &PathLighting::ALL, PathLighting::name, what)
    }
}

impl Default for PathIntegrator {
    fn default() -> Self {
        PathIntegrator {
            max_depth: u32::MAX,
            rr_depth: 5,
            only_bounce: None,
            light_samples: 1,
            lighting: PathLighting::Mis,
            hide_emitters: false,
        }
    }
}

/// Where a path stands between bounces: the radiance gathered so far, the throughput, the
/// ray it follows next and what MIS needs of the vertex it left.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    /// Radiance gathered so far.
    pub(crate) l: Rgb,
    /// Throughput: the product of f |cos θ| / p (and the Russian-roulette divisions) so far.
    pub(crate) beta: Rgb,
    /// The product of η'² over the refractions so far ([`crate::bsdf::BsdfSample::eta`]):
    /// β η_scale is the throughput without refraction's radiance scaling, which Russian
    /// roulette weighs.
    pub(crate) eta_scale: f32,
    /// The ray the path follows next.
    pub(crate) ray: Ray,
    /// The vertex the path left last, and how it left it; none for the camera.
    pub(crate) prev: Option<PrevVertex>,
    /// Bounces so far (0: the camera ray).
    pub(crate) depth: u32,
}

/// The vertex a path left, with what MIS needs of the BSDF sample that left it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrevVertex {
    /// Its position.
    pub(crate) p: Vec3,
    /// The density per solid angle of the direction the path left along.
    pub(crate) pdf: f32,
    /// Whether that direction came from a delta lobe: no other strategy could have found what
    /// it reaches, so MIS gives that weight one.
    pub(crate) delta: bool,
}

impl PathState {
    /// A path starting with camera ray `ray`.
    pub(crate) fn new(ray: Ray) -> Self {
        PathState {
            l: Rgb::ZERO,
            beta: Rgb::ONE,
            eta_scale: 1.0,
            ray,
            prev: None,
            depth: 0,
        }
    }
}

impl PathIntegrator {
    /// Number of light samples per vertex.
    fn n_light(&self) -> u32 {
        self.light_samples.max(1)
    }

    /// Whether the radiance of bounce `bounce` counts.
    fn wants(&self, bounce: u32) -> bool {
        self.only_bounce.is_none_or(|k| k == bounce)
    }

    /// Whether [`PathIntegrator::bsdf_weight`] reads the light-sampling density of what the
    /// BSDF sample that left `prev` finds (MIS, from a vertex, not along a delta lobe), so that
    /// it need not be looked up otherwise.
    fn weighs_by_light_pdf(&self, prev: Option<&PrevVertex>) -> bool {
        self.lighting == PathLighting::Mis && prev.is_some_and(|v| !v.delta)
    }

    /// MIS weight of emission found by the BSDF sample that left `prev`, which light
    /// sampling would find with density `pdf_light`.
    fn bsdf_weight(&self, prev: &PrevVertex, pdf_light: f32) -> f32 {
        if prev.delta {
            return 1.0;
        }
        match self.lighting {
            PathLighting::Mis => power_heuristic(1, prev.pdf, self.n_light(), pdf_light),
            PathLighting::Bsdf => 1.0,
            PathLighting::Light => 0.0,
        }
    }

    /// What the path's ray found, `hit`: adds the environment's radiance (a miss) or the
    /// surface's emission, weighted by MIS. Returns whether the path goes on to scatter at the
    /// surface.
    #[inline]
    pub(crate) fn arrive(
        &self,
        scene: &Scene,
        st: &mut PathState,
        hit: Option<&SurfaceInteraction>,
    ) -> bool {
        self.arrive_looked_up(scene, st, hit, None)
    }

    /// [`PathIntegrator::arrive`], where `looked_up` may hold the environment's radiance and
    /// density towards a ray that left the scene, found beforehand (see
    /// [`super::escaped_looked_up`]).
    #[inline]
    pub(crate) fn arrive_looked_up(
        &self,
        scene: &Scene,
        st: &mut PathState,
        hit: Option<&SurfaceInteraction>,
        looked_up: Option<(Rgb, f32)>,
    ) -> bool {
        let Some(si) = hit else {
            let pdf_needed = self.weighs_by_light_pdf(st.prev.as_ref());
            if let Some(found) = escaped_looked_up(scene, &st.ray, pdf_needed, looked_up) {
                self.add_found_light(st, found);
            }
            return false;
        };
        let p_prev = st.prev.map_or(st.ray.o, |v| v.p);
        if let Some(found) = emitted(scene, p_prev, &st.ray, si) {
            self.add_found_light(st, found);
        }
        st.depth < self.max_depth
    }

    /// Adds radiance `le` that the path's BSDF-sampled ray found, which light sampling would
    /// have found with density `pdf_light`, weighted by MIS against it.
    #[inline]
    fn add_found_light(&self, st: &mut PathState, (le, pdf_light): (Rgb, f32)) {
        if self.hide_emitters && st.depth == 0 {
            return;
        }
        let w = st
            .prev
            .map_or(1.0, |prev| self.bsdf_weight(&prev, pdf_light));
        if self.wants(st.depth) {
            st.l += st.beta * w * le;
        }
    }

    /// Scattering at `si`: light sampling, then a BSDF-sampled direction and Russian roulette.
    /// Returns whether the path goes on (along `st.ray`, one bounce deeper).
    #[inline]
    pub(crate) fn scatter(
        &self,
        scene: &Scene,
        st: &mut PathState,
        si: &SurfaceInteraction,
        sampler: &mut AnySampler,
        stats: &mut PathStats,
    ) -> bool {
        let n_light = self.n_light();
        let bsdf_samples = u32::from(self.lighting == PathLighting::Mis);
        let wo = -st.ray.d;
        let bsdf = scene.bsdf(si, wo);
        stats.random_vertices += u64::from(!bsdf.is_black());
        if self.wants(st.depth + 1) && !bsdf.is_delta() && self.lighting != PathLighting::Bsdf {
            let mut ld = Rgb::ZERO;
            for _ in 0..n_light {
                let u_select = sampler.next_1d();
                let u_light = sampler.next_2d();
                ld += sample_light(
                    scene,
                    si,
                    &bsdf,
                    wo,
                    u_select,
                    u_light,
                    n_light,
                    bsdf_samples,
                    stats,
                );
            }
            st.l += st.beta * ld / n_light as f32;
        } else {
            for _ in 0..n_light {
                sampler.next_1d();
                sampler.next_2d();
            }
        }
        let Some(bs) = bsdf.sample_f(wo, sampler.next_1d(), sampler.next_2d()) else {
            return false;
        };
        st.beta *= bs.f * (bs.cos / bs.pdf);
        st.eta_scale *= bs.eta * bs.eta;
        if st.beta.max_element() <= 0.0 || !st.beta.is_finite() {
            return false;
        }
        self.survive(scene, st, si, bs.wi, bs.pdf, bs.delta, sampler.next_1d())
    }

    /// The end of a bounce whose BSDF sample `wi` (of density `pdf`, or from a delta lobe)
    /// left a finite, positive throughput: Russian roulette with `u_rr`, then the ray along
    /// `wi`. Returns whether the path goes on.
    ///
    /// A ray whose arrival would be the path's last (bounce `max_depth`) is traced only for
    /// the emission it may find; where it cannot find any ([`Scene::may_find_emission`]: no
    /// environment, and it misses the box around the emitting surfaces, or there are none)
    /// the path ends here instead, with the same radiance. Inlined always (as it was, by
    /// itself, before it took the scene): called, it cost the eight-lane path 2–4%.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn survive(
        &self,
        scene: &Scene,
        st: &mut PathState,
        si: &SurfaceInteraction,
        wi: Vec3,
        pdf: f32,
        delta: bool,
        u_rr: f32,
    ) -> bool {
        st.prev = Some(PrevVertex {
            p: si.p,
            pdf,
            delta,
        });
        st.depth += 1;
        if st.depth >= self.rr_depth {
            let q = (st.beta * st.eta_scale).max_element().min(0.95);
            if u_rr >= q {
                return false;
            }
            st.beta /= q;
        }
        if self.only_bounce.is_some_and(|k| st.depth > k) {
            return false;
        }
        let ray = spawn_ray(si.p, si.ng, wi);
        st.ray = ray;
        st.depth < self.max_depth || scene.may_find_emission(ray.o, ray.d)
    }
}

impl Integrator for PathIntegrator {
    fn li(&self, scene: &Scene, ray: Ray, sampler: &mut AnySampler, stats: &mut PathStats) -> Rgb {
        let mut st = PathState::new(ray);
        loop {
            let hit = trace(scene, &st.ray, RayKind::at_depth(st.depth), stats);
            if !self.arrive(scene, &mut st, hit.as_ref()) {
                break;
            }
            let Some(si) = &hit else { break };
            if !self.scatter(scene, &mut st, si, sampler, stats) {
                break;
            }
        }
        st.l
    }

    fn li_samples(
        &self,
        scene: &Scene,
        sampler: &mut AnySampler,
        samples: &mut dyn Iterator<Item = SampleRef>,
        out: &mut dyn FnMut(u32, Rgb),
        stats: &mut PathStats,
    ) {
        if self.packets_apply() {
            self.li_packets(scene, sampler, samples, out, stats);
        } else {
            li_one_at_a_time(self, scene, sampler, samples, out, stats);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::{CameraDesc, MeshDesc, PointLightDesc, SceneDesc, INVERSE_SQUARE};
    use glam::Vec2;
    use pathlab_mc::sampler::SamplerKind;

    /// A diffuse floor seen from above, lit by a point light, by a uniform environment of
    /// radiance `environment` where one is given, and by a small emitting square above it
    /// where `lamp`.
    fn floor_lit_by(environment: Option<Rgb>, lamp: bool) -> Scene {
        let quad = |y: f32, r: f32, emission: Option<crate::desc::Emission>| MeshDesc {
            name: "quad".into(),
            positions: vec![
                Vec3::new(-r, y, -r),
                Vec3::new(-r, y, r),
                Vec3::new(r, y, r),
                Vec3::new(r, y, -r),
            ],
            indices: if emission.is_some() {
                vec![0, 2, 1, 0, 3, 2]
            } else {
                vec![0, 1, 2, 0, 2, 3]
            },
            material: 0,
            emission,
            ..Default::default()
        };
        let mut meshes = vec![quad(0.0, 4.0, None)];
        if lamp {
            meshes.push(quad(
                1.5,
                0.2,
                Some(crate::desc::Emission {
                    radiance: Vec3::splat(20.0),
                    two_sided: false,
                }),
            ));
        }
        let desc = SceneDesc {
            meshes,
            materials: vec![crate::scene::diffuse(Vec3::splat(0.5), false)],
            point_lights: vec![PointLightDesc {
                position: Vec3::new(0.3, 1.0, 0.2),
                intensity: Vec3::splat(2.0),
                attenuation: INVERSE_SQUARE,
            }],
            environment,
            camera: CameraDesc {
                origin: Vec3::new(0.0, 2.0, 0.5),
                target: Vec3::ZERO,
                up: Vec3::Y,
                fov_degrees: 60.0,
                ..Default::default()
            },
            resolution: [8, 8],
            ..Default::default()
        };
        Scene::build(&desc).unwrap()
    }

    /// Every pixel's first sample by the one-path code, and the rays traced.
    fn radiance_and_rays(pt: &PathIntegrator, scene: &Scene) -> (Vec<Rgb>, u64) {
        radiance_and_rays_spp(pt, scene, 1)
    }

    /// Every pixel's first `spp` samples by the one-path code, and the rays traced.
    fn radiance_and_rays_spp(pt: &PathIntegrator, scene: &Scene, spp: u32) -> (Vec<Rgb>, u64) {
        let mut sampler = SamplerKind::Independent.build(spp, 3);
        let mut stats = PathStats::default();
        let mut out = Vec::new();
        for y in 0..8 {
            for x in 0..8 {
                for index in 0..spp {
                    let s = SampleRef {
                        pixel: [x, y],
                        index,
                        tag: 0,
                    };
                    let (ray, weight) = super::super::camera_ray(scene, &mut sampler, s);
                    out.push(pt.li(scene, ray, &mut sampler, &mut stats) * weight);
                }
            }
        }
        (out, stats.rays)
    }

    #[test]
    fn the_last_ray_is_traced_only_where_it_can_find_emission() {
        // Direct lighting, against a path one bounce longer that counts only the first
        // bounce's light: that one traces every ray that ends at bounce one, and stops there.
        let direct = PathIntegrator {
            max_depth: 1,
            ..Default::default()
        };
        let longer = PathIntegrator {
            max_depth: 2,
            only_bounce: Some(1),
            ..Default::default()
        };
        let up = Ray::new(Vec3::new(0.0, 0.1, 0.0), Vec3::Y);
        let aside = Ray::new(
            Vec3::new(0.0, 0.1, 0.0),
            Vec3::new(1.0, 1.0, 0.0).normalize(),
        );
        // Lit by the point alone, no ray can find emission: direct lighting traces a camera
        // ray and a shadow ray per sample (every camera ray meets the floor, every point
        // sees the light), and gives the same radiance to the bit.
        let point = floor_lit_by(None, false);
        assert!(!point.may_find_emission(up.o, up.d));
        let (l, rays) = radiance_and_rays(&direct, &point);
        let (l_longer, rays_longer) = radiance_and_rays(&longer, &point);
        assert_eq!(rays, 2 * 64);
        assert_eq!(rays_longer, 3 * 64);
        assert_eq!(l.iter().filter(|l| l.max_element() > 0.0).count(), 64);
        assert_eq!(l, l_longer);
        // Under a sky every BSDF-sampled ray may find it, and is traced.
        let sky = floor_lit_by(Some(Vec3::splat(0.25)), false);
        assert!(sky.may_find_emission(aside.o, aside.d));
        let (l, rays) = radiance_and_rays(&direct, &sky);
        let (l_longer, rays_longer) = radiance_and_rays(&longer, &sky);
        assert_eq!(rays, rays_longer);
        assert_eq!(l, l_longer);
        // With a small lamp, only the rays towards its box are.
        let lamp = floor_lit_by(None, true);
        assert!(lamp.may_find_emission(up.o, up.d));
        assert!(!lamp.may_find_emission(aside.o, aside.d));
        let (l, rays) = radiance_and_rays(&direct, &lamp);
        let (l_longer, rays_longer) = radiance_and_rays(&longer, &lamp);
        assert!(rays < rays_longer - 32, "{rays} rays, {rays_longer} traced");
        assert_eq!(l, l_longer);
        // Lit by BSDF sampling alone, the lamp's light is what the traced rays found.
        let (direct, longer) = (
            PathIntegrator {
                lighting: PathLighting::Bsdf,
                ..direct
            },
            PathIntegrator {
                lighting: PathLighting::Bsdf,
                ..longer
            },
        );
        let (l, rays) = radiance_and_rays_spp(&direct, &lamp, 16);
        let (l_longer, rays_longer) = radiance_and_rays_spp(&longer, &lamp, 16);
        let found = l.iter().filter(|l| l.max_element() > 0.0).count();
        assert!(found > 10, "{found} samples found the lamp");
        let camera_rays = 64 * 16;
        let (last, last_longer) = (rays - camera_rays, rays_longer - camera_rays);
        assert!(
            last < last_longer / 4,
            "{last} last rays, {last_longer} traced"
        );
        assert_eq!(l, l_longer);
    }

    #[test]
    fn russian_roulette_weighs_the_throughput_without_refractions_radiance_scaling() {
        let si = SurfaceInteraction {
            p: Vec3::ZERO,
            t: 1.0,
            ng: Vec3::Z,
            ns: Vec3::Z,
            material: 0,
            light: None,
            uv: Vec2::ZERO,
            prim: u32::MAX,
            b: Vec2::ZERO,
        };
        let pt = PathIntegrator::default();
        let scene = floor_lit_by(Some(Vec3::ONE), false);
        // Inside glass of index 1.5 after a refraction that kept 90% of the light: β is
        // 0.9 / 1.5² = 0.4, η_scale 1.5². Roulette continues with q = 0.9 (not 0.4), so
        // u = 0.8 goes on and β becomes 0.4 / 0.9.
        let mut st = PathState::new(Ray::new(Vec3::ZERO, Vec3::Z));
        st.depth = pt.rr_depth;
        st.beta = Rgb::splat(0.9 / 2.25);
        st.eta_scale = 2.25;
        assert!(pt.survive(&scene, &mut st, &si, Vec3::Z, 1.0, true, 0.8));
        assert_eq!(st.beta, Rgb::splat(0.9 / 2.25 / 0.9));
        // u = 0.9 ends it.
        st.beta = Rgb::splat(0.9 / 2.25);
        assert!(!pt.survive(&scene, &mut st, &si, Vec3::Z, 1.0, true, 0.9));
        // Without refractions η_scale is one and q is β itself (at most 0.95).
        let mut st = PathState::new(Ray::new(Vec3::ZERO, Vec3::Z));
        st.depth = pt.rr_depth;
        st.beta = Rgb::new(0.2, 0.4, 0.1);
        assert!(!pt.survive(&scene, &mut st, &si, Vec3::Z, 1.0, false, 0.4));
        st.beta = Rgb::new(0.2, 0.4, 0.1);
        assert!(pt.survive(&scene, &mut st, &si, Vec3::Z, 1.0, false, 0.399));
        assert_eq!(st.beta, Rgb::new(0.2, 0.4, 0.1) / 0.4);
    }
}
