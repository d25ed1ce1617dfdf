//! Path tracing eight paths at a time: each lane follows one pixel sample, and a lane whose
//! path ends takes the next sample at once, so the lanes stay busy. Rays are traced one lane
//! after another through the BVH (its own SIMD traversal), or, in scenes of a few dozen
//! triangles, all eight against every triangle at once; the scattering at diffuse surfaces
//! lit by emitting triangles (light sampling with its MIS weight, the shadow ray's ends, the
//! cosine-weighted BSDF sample) is computed for all eight lanes together in SIMD registers;
//! any other material or light falls back to the scalar path code for that lane and bounce.
//!
//! Each lane computes exactly what [`PathIntegrator::li`] computes for its sample, to the bit
//! (tested): the same random numbers in the same order, the same operations in the same
//! order. Only the order in which the samples finish differs, and, where every triangle is
//! tested, which of several triangles at exactly the same distance a ray is taken to hit.

use super::path::{PathIntegrator, PathState};
use super::{camera_ray, sample_light, PathStats, SampleRef};
use crate::accel::RayLanes;
use crate::bsdf::Material;
use crate::desc::Rgb;
use crate::geometry::{Ray, RAY_EPSILON, SHADOW_RAY_END};
use crate::lanes::{F8, M8, V8, W};
use crate::light::{AreaShape, Light};
use crate::scene::{Scene, SurfaceInteraction};
use glam::Vec2;
use pathlab_mc::sampler::AnySampler;
use pathlab_mc::warp::sin_cos_quarter_turn;
use std::f32::consts::FRAC_1_PI;

/// What the lanes' scattering reads: the surface point, the directions, the material, the
/// light point's triangle and the random numbers (structure of arrays).
#[derive(Clone, Copy, Default)]
struct ScatterIn {
    p: V8,
    ng: V8,
    ns: V8,
    wo: V8,
    reflectance: V8,
    two_sided: M8,
    /// Lanes whose light sample is a point on an emitting triangle (the others have no light
    /// sample, or took theirs one lane at a time).
    light: M8,
    light_vertices: [V8; 3],
    light_normal: V8,
    light_pdf_area: F8,
    light_radiance: V8,
    light_two_sided: M8,
    /// Probability of choosing the lane's light.
    light_pmf: F8,
    u_light: [F8; 2],
    u_bsdf: [F8; 2],
}

/// What the lanes' scattering yields.
#[derive(Clone, Copy, Default)]
struct ScatterOut {
    /// Lanes that trace a shadow ray towards their light point.
    shadow: M8,
    shadow_o: V8,
    shadow_d: V8,
    /// The light sample's contribution f Li |cos θi| w / p, before visibility and throughput.
    ld: V8,
    /// Lanes whose BSDF sample is a direction (the others' paths end).
    sampled: M8,
    wi: V8,
    pdf: F8,
    /// f |cos θi| / p of the BSDF sample, the throughput's factor.
    weight: V8,
}

/// `offset_ray_origin` in lanes: `p` moved off the surface along `ng`, to the side of `w`.
#[inline(always)]
fn offset_ray_origin(p: V8, ng: V8, w: V8) -> V8 {
    let eps = F8::splat(RAY_EPSILON) * (F8::splat(1.0) + p.abs().max_element());
    let step = ng.scale(eps);
    // `w · ng >= 0`, false for NaN as there.
    F8::splat(0.0).le(w.dot(ng)).select3(p + step, p - step)
}

/// The lanes' scattering at diffuse surfaces: [`super::sample_light`] for a point on an
/// emitting triangle, up to the shadow ray, and [`crate::bsdf::Bsdf::sample_f`] for a
/// Lambertian BSDF, each expression as the scalar code writes it.
#[inline(always)]
fn scatter_lanes(a: &ScatterIn, out: &mut ScatterOut) {
    let zero = F8::splat(0.0);
    let one = F8::splat(1.0);
    let inv_pi = F8::splat(FRAC_1_PI);
    // The shading frame (`Bsdf::from_bxdf`, `coordinate_system`): a two-sided material turns
    // its normal towards wo.
    let flip = a.two_sided & a.wo.dot(a.ns).lt(zero);
    let n = flip.select3(-a.ns, a.ns);
    let sign = n.z.sign_one();
    let inv = F8::splat(-1.0) / (sign + n.z);
    let b = n.x * n.y * inv;
    let s = V8 {
        x: one + sign * n.x * n.x * inv,
        y: sign * b,
        z: -sign * n.x,
    };
    let t = V8 {
        x: b,
        y: sign + n.y * n.y * inv,
        z: -n.y,
    };
    let wo_z = a.wo.dot(n);
    let f_lambert = a.reflectance.scale(inv_pi);

    // Light sampling (`AreaTriangle::sample`, `Light::sample_li`, `sample_light`).
    let su0 = a.u_light[0].sqrt();
    let b0 = one - su0;
    let b1 = a.u_light[1] * su0;
    let b2 = (one - b0 - b1).max(zero);
    let [v0, v1, v2] = a.light_vertices;
    let p_light = v0.scale(b0) + v1.scale(b1) + v2.scale(b2);
    let to_light = p_light - a.p;
    let dist2 = to_light.dot(to_light);
    let wi = to_light.div_by(dist2.sqrt());
    let cos_light = a.light_normal.dot(-wi);
    let abs_cos_light = cos_light.abs();
    let emits = cos_light.gt(zero) | (a.light_two_sided & cos_light.lt(zero));
    let li = emits.select3(a.light_radiance, V8::default());
    let pdf_light = a.light_pdf_area * dist2 / abs_cos_light;
    let wi_z = wi.dot(n);
    let lambert = wo_z.gt(zero) & wi_z.gt(zero);
    let f = lambert
        .select3(f_lambert, V8::default())
        .scale(wi.dot(a.ns).abs());
    // `sample_light`'s early returns, kept as written (`!(x <= 0)` lets NaN through).
    let shadow = a.light
        & dist2.not_equal(zero)
        & abs_cos_light.not_equal(zero)
        & !pdf_light.le(zero)
        & !li.max_element().le(zero)
        & !f.max_element().le(zero);
    let o = offset_ray_origin(a.p, a.ng, to_light);
    let end = offset_ray_origin(p_light, a.light_normal, o - p_light);
    let pdf = a.light_pmf * pdf_light;
    // `power_heuristic(1, pdf, 1, bsdf.pdf(wo, wi))`.
    let pdf_bsdf = lambert.select(wi_z.max(zero) * inv_pi, zero);
    let (f2, g2) = (pdf * pdf, pdf_bsdf * pdf_bsdf);
    let mis = pdf
        .is_infinite()
        .select(one, (f2 + g2).equals(zero).select(zero, f2 / (f2 + g2)));
    out.shadow = shadow;
    out.shadow_o = o;
    out.shadow_d = end - o;
    out.ld = f.mul_axes(li).scale(mis / pdf);

    // BSDF sampling (`Diffuse::sample`: the concentric disk lifted to the hemisphere).
    let ux = F8::splat(2.0) * a.u_bsdf[0] - one;
    let uy = F8::splat(2.0) * a.u_bsdf[1] - one;
    let centre = ux.equals(zero) & uy.equals(zero);
    let x_wedge = ux.abs().gt(uy.abs());
    let r = x_wedge.select(ux, uy);
    let ratio = x_wedge.select(uy / ux, ux / uy);
    let mut sin = [0.0; W];
    let mut cos = [0.0; W];
    for i in 0..W {
        (sin[i], cos[i]) = sin_cos_quarter_turn(ratio.0[i]);
    }
    let (sin, cos) = (F8(sin), F8(cos));
    let dx = centre.select(zero, r * x_wedge.select(cos, sin));
    let dy = centre.select(zero, r * x_wedge.select(sin, cos));
    let z = (one - dx * dx - dy * dy).max(zero).sqrt();
    let pdf_sample = z.max(zero) * inv_pi;
    let finite = f_lambert.x.is_finite() & f_lambert.y.is_finite() & f_lambert.z.is_finite();
    // `Diffuse::sample` returns nothing where `wo.z <= 0` (so a NaN goes on).
    out.sampled = !wo_z.le(zero) & pdf_sample.gt(zero) & finite;
    let wi = s.scale(dx) + t.scale(dy) + n.scale(z);
    out.wi = wi;
    out.pdf = pdf_sample;
    out.weight = f_lambert.scale(wi.dot(a.ns).abs() / pdf_sample);
}

/// [`scatter_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn scatter_avx2(_: crate::simd::Avx2, a: &ScatterIn, out: &mut ScatterOut) {
    scatter_lanes(a, out)
}

/// [`scatter_lanes`] on the best vector unit this CPU has.
fn scatter(a: &ScatterIn, out: &mut ScatterOut) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `scatter_avx2` requires AVX2 and FMA, which `avx2` proves this CPU has. Its
        // body is safe code.
        return unsafe { scatter_avx2(avx2, a, out) };
    }
    scatter_lanes(a, out)
}

/// The reflectance and sidedness of a plain (untextured) Lambertian material.
#[inline]
fn lambertian(m: &Material) -> Option<(Rgb, bool)> {
    m.as_lambertian()
}

/// One lane's path: its sample's tag and where the path stands.
#[derive(Clone, Copy)]
struct Lane {
    tag: u32,
    st: PathState,
}

impl PathIntegrator {
    /// Whether [`PathIntegrator::li_packets`] computes what this integrator's settings ask
    /// for: MIS with one light sample and every bounce counted.
    pub(crate) fn packets_apply(&self) -> bool {
        self.only_bounce.is_none()
            && !self.hide_emitters
            && self.light_samples <= 1
            && self.lighting == super::PathLighting::Mis
    }

    /// [`super::Integrator::li_samples`] eight paths at a time.
    pub(crate) fn li_packets(
        &self,
        scene: &Scene,
        sampler: &AnySampler,
        samples: &mut dyn Iterator<Item = SampleRef>,
        out: &mut dyn FnMut(u32, Rgb),
        stats: &mut PathStats,
    ) {
        let mut samplers: [AnySampler; W] = std::array::from_fn(|_| sampler.clone());
        let mut lanes: [Option<Lane>; W] = [None; W];
        let mut hits: [Option<SurfaceInteraction>; W] = [None; W];
        let mut u = [[0.0f32; W]; 7];
        let mut a = ScatterIn::default();
        let mut b = ScatterOut::default();
        let mut more = true;
        let all_triangles = scene.tests_all_triangles();
        let mut rays = RayLanes::default();
        loop {
            // Idle lanes take the next samples.
            for (lane, smp) in lanes.iter_mut().zip(&mut samplers) {
                if lane.is_none() && more {
                    match samples.next() {
                        Some(s) => {
                            let ray = camera_ray(scene, smp, s);
                            *lane = Some(Lane {
                                tag: s.tag,
                                st: PathState::new(ray),
                            });
                        }
                        None => more = false,
                    }
                }
            }
            if lanes.iter().all(Option::is_none) {
                break;
            }
            // Small scenes: every lane's ray against every triangle at once.
            let nearest = all_triangles.then(|| {
                let mut t_max = F8::splat(f32::NEG_INFINITY);
                for (i, lane) in lanes.iter().enumerate() {
                    if let Some(lane) = lane {
                        let ray = &lane.st.ray;
                        rays.o.set(i, ray.o);
                        rays.d.set(i, ray.d);
                        rays.t_min.0[i] = ray.t_min;
                        t_max.0[i] = ray.t_max;
                    }
                }
                scene.nearest_of_rays(&rays, t_max)
            });
            // Trace every lane; scatter the ones at other materials now, and gather the
            // Lambertian ones' inputs.
            let mut lambert_lanes = 0u32;
            for i in 0..W {
                let Some(lane) = &mut lanes[i] else {
                    hits[i] = None;
                    continue;
                };
                let smp = &mut samplers[i];
                let st = &mut lane.st;
                // The surface interaction is made in place and read a field at a time.
                stats.rays += 1;
                match &nearest {
                    Some(nearest) => match nearest.lane(i) {
                        Some((slot, t, b1, b2)) => {
                            scene.interaction_into(&st.ray, slot, t, b1, b2, &mut hits[i])
                        }
                        None => hits[i] = None,
                    },
                    None => {
                        stats.nodes_visited +=
                            scene.intersect_into(&st.ray, st.depth == 0, &mut hits[i]) as u64
                    }
                }
                if !self.arrive(scene, st, hits[i].as_ref()) {
                    out(lane.tag, st.l);
                    lanes[i] = None;
                    hits[i] = None;
                    continue;
                }
                // `arrive` goes on only at a surface.
                let Some(si) = &hits[i] else { continue };
                let Some((reflectance, two_sided)) = lambertian(scene.material(si.material)) else {
                    if !self.scatter(scene, st, si, smp, stats) {
                        out(lane.tag, st.l);
                        lanes[i] = None;
                    }
                    hits[i] = None;
                    continue;
                };
                let wo = -st.ray.d;
                a.p.set(i, si.p);
                a.ng.set(i, si.ng);
                a.ns.set(i, si.ns);
                a.wo.set(i, wo);
                a.reflectance.set(i, reflectance);
                a.two_sided.set(i, two_sided);
                lambert_lanes |= 1 << i;
            }
            if lambert_lanes == 0 {
                continue;
            }
            // The scalar code's random numbers, in its order, for all Lambertian lanes at
            // once: light choice (1D), light point (2D), lobe choice (1D, unused: a Lambertian
            // BSDF has one), direction (2D), Russian roulette (1D).
            AnySampler::next_lanes(&mut samplers, lambert_lanes, &[1, 2, 1, 2, 1], &mut u);
            a.u_light = [F8(u[1]), F8(u[2])];
            a.u_bsdf = [F8(u[4]), F8(u[5])];
            // From here on, the lanes with a hit are the Lambertian ones (the others' hits
            // were cleared above).
            for i in 0..W {
                let (Some(lane), Some(si)) = (&mut lanes[i], &hits[i]) else {
                    continue;
                };
                let u_light = Vec2::new(u[1][i], u[2][i]);
                let triangle_light =
                    gather_light(scene, i, si, &mut lane.st, u[0][i], u_light, &mut a, stats);
                a.light.set(i, triangle_light);
            }
            scatter(&a, &mut b);
            for i in 0..W {
                let (Some(lane), Some(si)) = (&mut lanes[i], &hits[i]) else {
                    continue;
                };
                let goes_on = self.finish_bounce(scene, i, &mut lane.st, si, &b, u[6][i], stats);
                if !goes_on {
                    out(lane.tag, lane.st.l);
                    lanes[i] = None;
                }
            }
        }
    }

    /// The end of lane `i`'s bounce after the SIMD scattering: the shadow ray (adding the light
    /// sample's contribution where it is unblocked), the throughput times the BSDF sample's
    /// weight, Russian roulette with `u_rr`. Returns whether the path goes on.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn finish_bounce(
        &self,
        scene: &Scene,
        i: usize,
        st: &mut PathState,
        si: &SurfaceInteraction,
        b: &ScatterOut,
        u_rr: f32,
        stats: &mut PathStats,
    ) -> bool {
        if b.shadow.get(i) {
            stats.rays += 1;
            let shadow = Ray {
                o: b.shadow_o.get(i),
                d: b.shadow_d.get(i),
                t_min: 0.0,
                t_max: SHADOW_RAY_END,
            };
            if !scene.occluded(&shadow) {
                st.l += st.beta * b.ld.get(i);
            }
        }
        b.sampled.get(i) && {
            st.beta *= b.weight.get(i);
            st.beta.max_element() > 0.0
                && st.beta.is_finite()
                && self.survive(st, si, b.wi.get(i), b.pdf.0[i], u_rr)
        }
    }
}

/// Lane `i`'s light choice from `u_select`: an emitting triangle's data go to the lane of `a`
/// (returns true) for the SIMD light sample; any other light is sampled here with the scalar
/// code, its contribution added to `st.l`. No light: nothing (as the scalar code).
#[allow(clippy::too_many_arguments)]
#[inline]
fn gather_light(
    scene: &Scene,
    i: usize,
    si: &SurfaceInteraction,
    st: &mut PathState,
    u_select: f32,
    u_light: Vec2,
    a: &mut ScatterIn,
    stats: &mut PathStats,
) -> bool {
    let Some((index, pmf)) = scene.light_sampler().sample(u_select) else {
        return false;
    };
    match &scene.lights()[index] {
        Light::Area {
            shape: AreaShape::Triangle(t),
            radiance,
            two_sided,
            texture: None,
        } => {
            for (v, p) in a.light_vertices.iter_mut().zip(t.triangle.p) {
                v.set(i, p);
            }
            a.light_normal.set(i, t.normal);
            a.light_pdf_area.0[i] = t.pdf_area;
            a.light_radiance.set(i, *radiance);
            a.light_two_sided.set(i, *two_sided);
            a.light_pmf.0[i] = pmf;
            true
        }
        _ => {
            let wo = -st.ray.d;
            let bsdf = scene.bsdf(si, wo);
            let ld = sample_light(scene, si, &bsdf, wo, u_select, u_light, 1, 1, stats);
            // (The scalar code divides by the one light sample: exact.)
            st.l += st.beta * ld;
            false
        }
    }
}
