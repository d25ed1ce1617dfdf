//! Path tracing eight paths at a time: each lane follows one pixel sample, and a lane whose
//! path ends takes the next sample at once, so the lanes stay busy. Rays are traced one lane
//! after another through the BVH (its own SIMD traversal), or, in scenes of a few dozen
//! triangles and a few spheres, all eight against every primitive at once (skipping the
//! blocks of triangles none of them meets where the rays go one way: camera rays and first
//! bounces, since the lanes take consecutive samples of a pixel); their shadow rays too, the
//! same way (one lane after another through the BVH, or all eight against every primitive,
//! skipping the blocks none meets: rays towards one light converge). The lanes that start
//! together make their camera rays together, and the sampler draws each bounce's random
//! numbers for all lanes at once.
//!
//! The physics is the one-path code's ([`super::path`]): `arrive`, `scatter` and `survive`
//! for every lane and bounce, except where a lane's material is one lobe of those the lanes
//! shade ([`Material::lane_bxdf`]: Lambertian, or a blend of two Lambertian materials, which
//! is one Lambertian lobe; a mirror; smooth conductors and glass; rough GGX or Beckmann
//! conductors and glass, of one roughness or anisotropic; thin sheets of glass; smooth and
//! rough plastic; diffuse reflection and transmission; the principled model, solid or thin;
//! any of those under a normal or bump map; of a two-sided pair of those, the one on wo's
//! side; a mask over one of those, its lobe weighted by the opacity, the rest passing
//! straight through). There the lanes are shaded together
//! in SIMD registers by the same functions the one-path code calls, instantiated on eight
//! lanes (the BSDFs: [`Diffuse`],
//! [`RoughConductor`], [`RoughDielectric`] (their distributions: [`MicrofacetLanes`], whose
//! anisotropic Beckmann lanes go one lane at a time), [`Mirror`], [`SmoothConductor`],
//! [`DielectricLanes`], [`ThinDielectric`], [`Plastic`], [`RoughPlastic`] (its coat's table
//! read lane by lane), [`DiffuseTransmission`], [`PrincipledLobes`]; [`TriangleEmitter::sample_li`],
//! [`EnvironmentMap::sample_direction_lanes`], the shading [`Frame`] (or, for an
//! anisotropic lobe or a mapped normal, the frame [`Material::lane_bxdf`] gives the lane),
//! a map's guard ([`guard_attenuation`]), [`offset_ray_origin`],
//! [`power_heuristic_weight`]; see `scatter_lanes`): this module holds only the scheduling
//! and the masks that stand for the one-path code's early returns. Emitting triangles and
//! environment maps are sampled in the lanes; any other light (points, spots, directional
//! lights, spheres, textured emitters, projectors, a constant environment) by its own
//! [`Light::sample_li`], one lane at a time, the BSDF's value and density towards the sample
//! and its MIS weight then computed in the lanes with the others. The rays that leave the
//! scene look the environment map up together too
//! ([`EnvironmentMap::eval_and_pdf_lanes`]), and `arrive` takes what they found.
//!
//! Each lane computes exactly what [`PathIntegrator::li`] computes for its sample, to the bit
//! (tested): the same random numbers in the same order, the same operations in the same
//! order. Only the order in which the samples finish differs, and, where every triangle is
//! tested, which of several triangles at exactly the same distance a ray is taken to hit.

use super::path::{PathIntegrator, PathState};
use super::{
    camera_sample, power_heuristic_weight, shadow_ray, CameraSample, PathStats, SampleRef,
};
use crate::accel::RayLanes;
use crate::bsdf::bxdf::DirectionSample;
use crate::bsdf::{
    guard_admits, guard_attenuation, CoatLanes, DielectricLanes, Diffuse, DiffuseTransmission,
    LaneBxdf, Lobes, Material, MicrofacetLanes, Mirror, Plastic, PrincipledLobes, RoughConductor,
    RoughDielectric, RoughPlastic, SmoothConductor, ThinDielectric,
};
use crate::desc::{RayKind, Rgb};
use crate::geometry::{offset_ray_origin, Frame, Ray, SHADOW_RAY_END};
use crate::light::envmap::{DirectionLanes, EnvironmentMap};
use crate::light::{AreaShape, Light, LightLiSample, TriangleEmitter};
use crate::scene::{Scene, SurfaceInteraction};
use crate::simd::lanes::{F8, M8, V8, W};
use glam::Vec2;
use pathlab_mc::sampler::AnySampler;

/// What the lanes' scattering reads: the surface point, the directions, the material, the
/// light's triangle and the random numbers (structure of arrays).
#[derive(Clone, Copy, Default)]
struct ScatterIn {
    p: V8,
    ng: V8,
    ns: V8,
    wo: V8,
    /// Which lanes have which lobe ([`LobeLanes`], and the rarer ones in `coated_lobes`):
    /// `metal`, a rough conductor; `rough_glass`; `mirror`; `smooth_metal`, a smooth
    /// conductor; `glass`; `thin_glass`; `plastic`; `rough_plastic`; `translucent`, diffuse
    /// reflection and transmission; `principled`; the others' is `diffuse`.
    lobes: LobeLanes,
    diffuse: Diffuse<V8>,
    metal: RoughConductor<V8, MicrofacetLanes>,
    rough_glass: RoughDielectric<F8, V8, MicrofacetLanes>,
    mirror: Mirror<V8>,
    smooth_metal: SmoothConductor<V8>,
    glass: DielectricLanes,
    thin_glass: ThinDielectric<V8, F8>,
    plastic: Plastic<V8, F8, M8>,
    rough_plastic: RoughPlastic<V8, F8, MicrofacetLanes, M8, CoatLanes>,
    translucent: DiffuseTransmission<V8>,
    principled: PrincipledLobes<V8, F8, M8, MicrofacetLanes>,
    two_sided: M8,
    /// Lanes whose lobe has a weight below one, the rest of the light passing straight
    /// through ([`crate::bsdf::LaneLobe::weight`]: a mask that lets some through), and that
    /// weight (cleared, and looked at, only where `mixed` has the lane).
    mixed: M8,
    lobe_weight: F8,
    /// Whether some lane has one of the lobes of `coated` (cleared, and looked at, only
    /// where one had).
    coated: bool,
    coated_lobes: CoatedLanes,
    /// Whether some lane has a frame along the surface's tangent or a guard (`tangent` and
    /// `guard` are cleared, and looked at, only where one had).
    mapped: bool,
    /// Lanes whose frame follows the surface's tangent (anisotropic roughness, a normal or
    /// bump map), given in `frame` (those [`Material::lane_bxdf`] gives; the others' frame
    /// is made in the lanes, around the shading normal).
    tangent: M8,
    frame: Frame<V8>,
    /// Lanes under a normal or bump map, and their guards (the surface's own shading normal
    /// and the shadowing α², [`crate::bsdf::Guard`]).
    guard: M8,
    guard_n: V8,
    guard_alpha2: F8,
    /// Lanes whose light sample is a point on an emitting triangle.
    light: M8,
    emitter: TriangleEmitter<V8>,
    /// Lanes whose light sample is a direction of an environment map, and its direction and
    /// density per solid angle (the lanes in neither mask have no light sample, or took theirs
    /// one lane at a time).
    environment: M8,
    environment_wi: V8,
    environment_pdf: F8,
    /// Lanes whose light sample was taken one lane at a time by the light's own
    /// [`Light::sample_li`] (points, spots, directional lights, spheres, textured triangles,
    /// projectors, a constant environment), and that sample.
    drawn: DrawnLights,
    /// Probability of choosing the lane's light.
    light_pmf: F8,
    u_light: [F8; 2],
    /// The lobe choice's number (glass's choice between reflection and refraction).
    u_lobe: F8,
    u_bsdf: [F8; 2],
}

/// Light samples taken one lane at a time ([`gather_light`]), whose BSDF values, MIS weights
/// and contributions the lanes compute together: each lane's direction, radiance, density per
/// solid angle, whether the light is a delta distribution, and its shadow ray
/// ([`super::shadow_ray`]).
#[derive(Clone, Copy, Default)]
struct DrawnLights {
    lanes: M8,
    wi: V8,
    li: V8,
    pdf: F8,
    delta: M8,
    shadow_o: V8,
    shadow_d: V8,
    shadow_t_max: F8,
}

impl DrawnLights {
    /// Lane `i`'s sample `ls` and its shadow ray.
    #[inline(always)]
    fn set(&mut self, i: usize, ls: &LightLiSample, shadow: &Ray) {
        self.lanes.set(i, true);
        self.wi.set(i, ls.wi);
        self.li.set(i, ls.li);
        self.pdf.0[i] = ls.pdf;
        self.delta.set(i, ls.is_delta);
        self.shadow_o.set(i, shadow.o);
        self.shadow_d.set(i, shadow.d);
        self.shadow_t_max.0[i] = shadow.t_max;
    }
}

/// Which lanes have which lobe (the rest: Lambertian, or one of [`CoatedLanes`]).
#[derive(Clone, Copy, Default)]
struct LobeLanes {
    conductor: M8,
    rough_glass: M8,
    smooth_metal: M8,
    glass: M8,
    /// The delta lobes (mirrors, smooth conductors, glass and thin sheets of it): no light
    /// sample. Those in none of `smooth_metal`, `glass` and [`CoatedLanes::thin_glass`] are
    /// mirrors.
    delta: M8,
}

/// Which lanes have the rarer lobes (cleared, and looked at, only where some lane had one:
/// [`ScatterIn::coated`]): thin sheets of glass (in [`LobeLanes::delta`] too), smooth
/// plastic (a delta lobe, the coat's reflection, and a diffuse one), rough plastic, diffuse
/// reflection and transmission, the principled model.
#[derive(Clone, Copy, Default)]
struct CoatedLanes {
    thin_glass: M8,
    plastic: M8,
    rough_plastic: M8,
    translucent: M8,
    principled: M8,
}

/// What the lanes' scattering yields.
#[derive(Clone, Copy, Default)]
struct ScatterOut {
    /// Lanes that trace a shadow ray towards their light point (or, for an environment map,
    /// towards infinity along `shadow_d`).
    shadow: M8,
    shadow_o: V8,
    shadow_d: V8,
    shadow_t_max: F8,
    /// The light sample's contribution f Li |cos θi| w / p, before visibility and throughput
    /// (for an emitting triangle).
    ld: V8,
    /// An environment map's sample's f |cos θi| and w / p, whose product with its radiance,
    /// read once the shadow ray is known to be unblocked, is its contribution.
    f: V8,
    weight_over_pdf: F8,
    /// Lanes whose BSDF sample is a direction (the others' paths end).
    sampled: M8,
    wi: V8,
    pdf: F8,
    /// Whether it comes from a delta lobe, and the relative index η' it crossed (one where it
    /// did not refract).
    delta: M8,
    eta: F8,
    /// f |cos θi| / p of the BSDF sample, the throughput's factor.
    weight: V8,
}

/// The lanes' scattering at the lobes [`Material::lane_bxdf`] gives, composed of the functions the
/// one-path code calls, on lanes: the shading frame ([`Frame::from_normal`], turned towards wo for
/// a two-sided material as [`crate::bsdf::Bsdf::from_bxdf`] does), [`super::sample_light`] for a
/// point on an emitting triangle, an environment map's direction (drawn before, by
/// [`EnvironmentMap::sample_direction_lanes`]) or a sample of another light (drawn before, one lane
/// at a time, into [`ScatterIn::drawn`]) up to the shadow ray ([`TriangleEmitter::sample_li`],
/// [`Diffuse::f_z`], [`RoughConductor::f_and_pdf`], [`RoughDielectric::f_and_pdf`],
/// [`Plastic::f_and_pdf`], [`RoughPlastic::f_and_pdf`] or [`DiffuseTransmission::f_and_pdf`] or
/// [`PrincipledLobes::f_and_pdf`], [`offset_ray_origin`], [`power_heuristic_weight`] against the
/// lobe's density, weight one for a delta light; the map's radiance is read after the shadow ray,
/// as there), and [`crate::bsdf::Bsdf::sample_f`] for a BSDF of that one lobe
/// ([`Diffuse::sample_z`], [`RoughConductor::sample`], [`RoughDielectric::sample_real`],
/// [`Mirror::sample_real`], [`SmoothConductor::sample`], [`DielectricLanes::sample`],
/// [`ThinDielectric::sample_real`], [`Plastic::sample_real`] (whose coat's reflection is a delta
/// sample), [`RoughPlastic::sample_real`], [`DiffuseTransmission::sample_real`],
/// [`PrincipledLobes::sample_real`]; smooth lobes have no light sample); where some light passes
/// straight through (a mask), the choice [`crate::bsdf::Bsdf::sample_f`] makes between the lobe and
/// passing through, the lobe's value and density weighted, and, for a sample that is not a delta
/// one, both evaluated again towards the direction taken (the lobes' functions above). Only the
/// control flow is the lanes' own: masks where the one-path code returns early, and each lobe's
/// functions skipped where no lane has it (all but the Lambertian ones and the triangles' and maps'
/// light samples without `OTHER_LOBES`: a separate, smaller instance for passes of Lambertian lanes
/// alone; the plastics, thin glass, diffuse transmission and the principled model only with
/// `COATED`: the instance for the other lobes stays as small as it was without them; passing
/// through only with `MIXED`).
#[inline(always)]
fn scatter_lanes<const OTHER_LOBES: bool, const COATED: bool, const MIXED: bool>(
    a: &ScatterIn,
    out: &mut ScatterOut,
) {
    let zero = F8::splat(0.0);
    let flip = a.two_sided & a.wo.dot(a.ns).lt(zero);
    let mut frame = Frame::from_normal(flip.select3(-a.ns, a.ns));
    let tangent = a.tangent;
    if OTHER_LOBES && a.mapped {
        frame = Frame {
            s: tangent.select3(a.frame.s, frame.s),
            t: tangent.select3(a.frame.t, frame.t),
            n: tangent.select3(a.frame.n, frame.n),
        };
    }
    let wo_z = a.wo.dot(frame.n);
    // The other lobes' functions take whole local directions (unused, and not computed, in
    // the Lambertian instance).
    let wo_local = frame.to_local(a.wo);
    let metal = a.lobes.conductor;
    let any_metal = OTHER_LOBES && metal.any();
    let rough_glass = a.lobes.rough_glass;
    let any_rough_glass = OTHER_LOBES && rough_glass.any();
    let plastic = a.coated_lobes.plastic;
    let any_plastic = COATED && plastic.any();
    let rough_plastic = a.coated_lobes.rough_plastic;
    let any_rough_plastic = COATED && rough_plastic.any();
    let translucent = a.coated_lobes.translucent;
    let any_translucent = COATED && translucent.any();
    let principled = a.coated_lobes.principled;
    let any_principled = COATED && principled.any();

    // Light sampling: a point on a triangle, an environment map's direction, or a sample
    // drawn one lane at a time.
    let env = a.environment;
    let drawn = &a.drawn;
    let any_drawn = OTHER_LOBES && drawn.lanes.any();
    let ls = a.emitter.sample_li(a.p, a.u_light[0], a.u_light[1]);
    let mut wi = env.select3(a.environment_wi, ls.wi);
    if any_drawn {
        wi = drawn.lanes.select3(drawn.wi, wi);
    }
    let (f, mut bsdf_pdf) = lobes_f_and_pdf::<OTHER_LOBES, COATED>(a, &frame, wo_z, wo_local, wi);
    let cos_i = wi.dot(frame.n).abs();
    // `Bsdf::f_cos` and `Bsdf::pdf` of a lobe with passing through: f (weight · cos), and
    // the weight times the lobe's density.
    let mixed = a.mixed;
    let any_mixed = OTHER_LOBES && MIXED && mixed.any();
    // The lobe's weight: the mask's opacity where light passes through, one elsewhere (one
    // times a value is that value, to the bit).
    let w = a.lobe_weight;
    let mut lobe_w = F8::splat(1.0);
    let mut f_scale = cos_i;
    if any_mixed {
        lobe_w = mixed.select(w, lobe_w);
        f_scale = lobe_w * cos_i;
        bsdf_pdf = lobe_w * bsdf_pdf;
    }
    let guard = a.guard;
    let guarded = OTHER_LOBES && a.mapped && guard.any();
    let f = if guarded {
        // `Bsdf::f_cos` of a guarded lobe: f (weight · attenuation · cos), its weight one,
        // or the mask's opacity where light passes through. Where the guard does not admit
        // wi this is zero, and the sample ends here (its density, which `Bsdf::pdf` would
        // make zero too, is not asked for).
        let attenuation = guard_attenuation(a.guard_n, a.guard_alpha2, frame.n, wi);
        let guarded = lobe_w * attenuation * cos_i;
        guard.select3(f.scale(guarded), f.scale(f_scale))
    } else {
        f.scale(f_scale)
    };
    // `visible_light_sample`'s early returns (`!(x <= 0)` lets NaN through, as there).
    let triangle = a.light
        & ls.dist2.not_equal(zero)
        & ls.abs_cos_light.not_equal(zero)
        & !ls.pdf.le(zero)
        & !ls.li.max_element().le(zero);
    let environment = env & !a.environment_pdf.le(zero);
    // (A drawn sample's checks of its density and radiance were made where it was drawn.)
    out.shadow = (triangle | environment | drawn.lanes) & !f.max_element().le(zero);
    // Towards the triangle's point (`spawn_ray_to`), or along the direction (`spawn_ray`).
    let o = offset_ray_origin(a.p, a.ng, env.select3(wi, ls.p_light - a.p));
    let end = offset_ray_origin(ls.p_light, a.emitter.normal, o - ls.p_light);
    out.shadow_o = o;
    out.shadow_d = env.select3(wi, end - o);
    out.shadow_t_max = env.select(F8::splat(f32::INFINITY), F8::splat(SHADOW_RAY_END));
    let mut light_pdf = env.select(a.environment_pdf, ls.pdf);
    let mut li = ls.li;
    if any_drawn {
        let on = drawn.lanes;
        out.shadow_o = on.select3(drawn.shadow_o, out.shadow_o);
        out.shadow_d = on.select3(drawn.shadow_d, out.shadow_d);
        out.shadow_t_max = on.select(drawn.shadow_t_max, out.shadow_t_max);
        light_pdf = on.select(drawn.pdf, light_pdf);
        li = on.select3(drawn.li, li);
    }
    let pdf = a.light_pmf * light_pdf;
    let mut mis = power_heuristic_weight(pdf, bsdf_pdf);
    if any_drawn {
        // A delta light's sample has weight one (no BSDF sample finds it).
        mis = (drawn.lanes & drawn.delta).select(F8::splat(1.0), mis);
    }
    out.ld = f.mul_axes(li).scale(mis / pdf);
    out.f = f;
    out.weight_over_pdf = mis / pdf;

    // BSDF sampling (and `Bsdf::sample_f`'s checks of a positive density and a finite value).
    let [u0, u1] = a.u_bsdf;
    // Where light may pass through, `Bsdf::sample_f` chooses the lobe with probability its
    // weight, and reuses the rest of the number within it.
    let mut u_lobe = a.u_lobe;
    let mut passing = M8::default();
    if any_mixed {
        passing = mixed & !(w.gt(zero) & u_lobe.lt(w));
        let within = (u_lobe / w).max(zero).min(F8::splat(1.0 - f32::EPSILON));
        u_lobe = mixed.select(within, u_lobe);
    }
    let mut bs = a.diffuse.sample_z(wo_z, u0, u1);
    if any_metal {
        bs = DirectionSample::select(metal, a.metal.sample(wo_local, u0, u1), bs);
    }
    let mut eta = F8::splat(1.0);
    if any_rough_glass {
        let g = a
            .rough_glass
            .sample_real(wo_local, u_lobe, u0, u1, Lobes::All);
        eta = rough_glass.select(a.rough_glass.relative_ior(wo_local, g.wi), eta);
        bs = DirectionSample::select(rough_glass, g, bs);
    }
    let lobes = &a.lobes;
    let mut delta = lobes.delta;
    if any_plastic {
        let (p, specular) = a.plastic.sample_real(wo_local, u_lobe, u0, u1);
        bs = DirectionSample::select(plastic, p, bs);
        delta = delta | (plastic & specular);
    }
    if any_rough_plastic {
        let p = a.rough_plastic.sample_real(wo_local, u_lobe, u0, u1);
        bs = DirectionSample::select(rough_plastic, p, bs);
    }
    if any_translucent {
        let t = a.translucent.sample_real(wo_local, u_lobe, u0, u1);
        bs = DirectionSample::select(translucent, t, bs);
    }
    if any_principled {
        let p = a.principled.sample_real(wo_local, u_lobe, u0, u1);
        eta = principled.select(a.principled.relative_ior(wo_local, p.wi), eta);
        bs = DirectionSample::select(principled, p, bs);
    }
    if OTHER_LOBES && lobes.delta.any() {
        let wo = wo_local;
        let mut d = a.mirror.sample_real(wo);
        if lobes.smooth_metal.any() {
            d = DirectionSample::select(lobes.smooth_metal, a.smooth_metal.sample(wo), d);
        }
        if lobes.glass.any() {
            let (g, g_eta) = a.glass.sample(wo, u_lobe);
            d = DirectionSample::select(lobes.glass, g, d);
            eta = lobes.glass.select(g_eta, eta);
        }
        let thin_glass = a.coated_lobes.thin_glass;
        if COATED && thin_glass.any() {
            let g = a.thin_glass.sample_real(wo, u_lobe);
            d = DirectionSample::select(thin_glass, g, d);
        }
        bs = DirectionSample::select(lobes.delta, d, bs);
    }
    out.delta = delta;
    out.eta = eta;
    let wi = frame.to_world(bs.wi);
    let (mut f, mut valid) = (bs.f, bs.valid);
    // The guard's attenuation towards wi (one where there is no guard).
    let mut attenuation = F8::splat(1.0);
    if guarded {
        // `Bsdf::sample_f` of a guarded lobe: none where the guard does not admit wi, the
        // value attenuated where it does.
        let towards_wi = guard_attenuation(a.guard_n, a.guard_alpha2, frame.n, wi);
        attenuation = guard.select(towards_wi, attenuation);
        f = guard.select3(f.scale(attenuation), f);
        valid = valid & (guard_admits(a.guard_n, frame.n, wi) | !guard);
    }
    let finite = |f: V8| f.x.is_finite() & f.y.is_finite() & f.z.is_finite();
    let mut sampled = valid & bs.pdf.gt(zero) & finite(f);
    let (mut wi, mut pdf, mut cos) = (wi, bs.pdf, wi.dot(frame.n).abs());
    if any_mixed {
        // The lobe's delta sample: f times its weight and attenuation, the density times its
        // weight.
        let chosen = mixed & !passing;
        let scaled = chosen & delta;
        f = scaled.select3(bs.f.scale(w * attenuation), f);
        pdf = scaled.select(pdf * w, pdf);
        // Its other samples: the mixture's value and density towards the direction taken
        // (`Bsdf::f_cos` / cos and `Bsdf::pdf`), where the density is positive.
        let smooth = chosen & !delta & sampled;
        if smooth.any() {
            let (f_mixed, pdf_mixed) =
                lobes_f_and_pdf::<OTHER_LOBES, COATED>(a, &frame, wo_z, wo_local, wi);
            let pdf_mixed = w * pdf_mixed;
            let f_mixed = f_mixed.scale(w * attenuation * cos).div_by(cos);
            let ok = pdf_mixed.gt(zero) & cos.gt(zero) & finite(f_mixed);
            sampled = sampled & (ok | !smooth);
            (f, pdf) = where_lobe(smooth, (f_mixed, pdf_mixed), (f, pdf));
        }
        // Straight through: f cos / pdf = null / null (one), a delta sample of no refraction.
        let null = F8::splat(1.0) - w;
        let c = a.wo.dot(frame.n).abs().max(F8::splat(1e-6));
        f = passing.select3(V8::splat(glam::Vec3::ONE).scale(null / c), f);
        wi = passing.select3(-a.wo, wi);
        pdf = passing.select(null, pdf);
        cos = passing.select(c, cos);
        sampled = (passing & null.gt(zero)) | (sampled & !passing);
        out.delta = out.delta | passing;
        out.eta = passing.select(F8::splat(1.0), out.eta);
    }
    out.sampled = sampled;
    out.wi = wi;
    out.pdf = pdf;
    out.weight = f.scale(cos / pdf);
}

/// The value and density of each lane's lobe ([`scatter_lanes`]' lobes, `Bxdf::f` and
/// `Bxdf::pdf`) towards `wi`, from wo (`wo_z` its cosine and `wo_local` it in `frame`).
#[inline(always)]
fn lobes_f_and_pdf<const OTHER_LOBES: bool, const COATED: bool>(
    a: &ScatterIn,
    frame: &Frame<V8>,
    wo_z: F8,
    wo_local: V8,
    wi: V8,
) -> (V8, F8) {
    let metal = a.lobes.conductor;
    let rough_glass = a.lobes.rough_glass;
    let plastic = a.coated_lobes.plastic;
    let rough_plastic = a.coated_lobes.rough_plastic;
    let translucent = a.coated_lobes.translucent;
    let principled = a.coated_lobes.principled;
    let any_metal = OTHER_LOBES && metal.any();
    let any_rough_glass = OTHER_LOBES && rough_glass.any();
    let any_plastic = COATED && plastic.any();
    let any_rough_plastic = COATED && rough_plastic.any();
    let any_translucent = COATED && translucent.any();
    let any_principled = COATED && principled.any();
    let wi_z = wi.dot(frame.n);
    let wi_local = frame.to_local(wi);
    let mut f_pdf = (a.diffuse.f_z(wo_z, wi_z), a.diffuse.pdf_z(wo_z, wi_z));
    if any_metal {
        f_pdf = where_lobe(metal, a.metal.f_and_pdf(wo_local, wi_local), f_pdf);
    }
    if any_rough_glass {
        let glass = a.rough_glass.f_and_pdf(wo_local, wi_local, Lobes::All);
        f_pdf = where_lobe(rough_glass, glass, f_pdf);
    }
    if any_plastic {
        f_pdf = where_lobe(plastic, a.plastic.f_and_pdf(wo_local, wi_local), f_pdf);
    }
    if any_rough_plastic {
        let rough = a.rough_plastic.f_and_pdf(wo_local, wi_local);
        f_pdf = where_lobe(rough_plastic, rough, f_pdf);
    }
    if any_translucent {
        let t = a.translucent.f_and_pdf(wo_local, wi_local);
        f_pdf = where_lobe(translucent, t, f_pdf);
    }
    if any_principled {
        let p = a.principled.f_and_pdf(wo_local, wi_local);
        f_pdf = where_lobe(principled, p, f_pdf);
    }
    f_pdf
}

/// A lobe's value and density where `lanes` have it, `others` elsewhere (a function, not a
/// closure: `#[inline(always)]` keeps it in the vector-unit instances that call it).
#[inline(always)]
fn where_lobe(lanes: M8, (f, pdf): (V8, F8), others: (V8, F8)) -> (V8, F8) {
    (lanes.select3(f, others.0), lanes.select(pdf, others.1))
}

/// [`scatter_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn scatter_avx2<const OTHER_LOBES: bool, const COATED: bool, const MIXED: bool>(
    _: crate::simd::Avx2,
    a: &ScatterIn,
    out: &mut ScatterOut,
) {
    scatter_lanes::<OTHER_LOBES, COATED, MIXED>(a, out)
}

/// [`scatter_lanes`] on the best vector unit this CPU has, its Lambertian instance where no
/// lane has another lobe or a light sample drawn one lane at a time.
#[inline]
fn scatter(a: &mut ScatterIn, out: &mut ScatterOut) {
    let lobes = &a.lobes;
    let other = (lobes.conductor | lobes.rough_glass | lobes.delta | a.drawn.lanes | a.mixed).any()
        || a.mapped
        || a.coated;
    if other {
        return scatter_other_lobes(a, out);
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `scatter_avx2` requires AVX2 and FMA, which `avx2` proves this CPU has. Its
        // body is safe code.
        return unsafe { scatter_avx2::<false, false, false>(avx2, a, out) };
    }
    scatter_lanes::<false, false, false>(a, out)
}

/// [`scatter`]'s instance for every lobe and light, out of line so that the Lambertian one
/// stays small enough to be inlined into the path loop.
#[inline(never)]
fn scatter_other_lobes(a: &mut ScatterIn, out: &mut ScatterOut) {
    // The distributions' functions computed lane by lane (Beckmann's, anisotropic ones) only
    // where a lane has the lobe now (a lane keeps its lobe's fields from an earlier bounce;
    // where no lane has a lobe, its functions are not computed at all).
    if a.lobes.conductor.any() {
        a.metal.distribution.only_in(a.lobes.conductor);
    }
    if a.lobes.rough_glass.any() {
        a.rough_glass.distribution.only_in(a.lobes.rough_glass);
    }
    let rough_plastic = a.coated_lobes.rough_plastic;
    if a.coated && rough_plastic.any() {
        a.rough_plastic.distribution.only_in(rough_plastic);
    }
    let principled = a.coated_lobes.principled;
    if a.coated && principled.any() {
        a.principled.only_in(principled);
    }
    let a = &*a;
    if a.mixed.any() {
        return scatter_mixed(a, out);
    }
    if a.coated {
        return scatter_coated(a, out);
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: as in `scatter`.
        return unsafe { scatter_avx2::<true, false, false>(avx2, a, out) };
    }
    scatter_lanes::<true, false, false>(a, out)
}

/// [`scatter_other_lobes`]' instance where some lane has a plastic, a thin sheet of glass or
/// diffuse transmission.
#[inline(never)]
fn scatter_coated(a: &ScatterIn, out: &mut ScatterOut) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: as in `scatter`.
        return unsafe { scatter_avx2::<true, true, false>(avx2, a, out) };
    }
    scatter_lanes::<true, true, false>(a, out)
}

/// [`scatter_other_lobes`]' instances where some lane's lobe lets light pass through (a
/// mask's): the choice between them and the lobe evaluated again take code (and time) the
/// other instances are without.
#[inline(never)]
fn scatter_mixed(a: &ScatterIn, out: &mut ScatterOut) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: as in `scatter`.
        return unsafe {
            match a.coated {
                true => scatter_avx2::<true, true, true>(avx2, a, out),
                false => scatter_avx2::<true, false, true>(avx2, a, out),
            }
        };
    }
    match a.coated {
        true => scatter_lanes::<true, true, true>(a, out),
        false => scatter_lanes::<true, false, true>(a, out),
    }
}

/// One lane's path: its sample's tag and where the path stands.
#[derive(Clone, Copy)]
struct Lane {
    tag: u32,
    st: PathState,
    /// The weight of the sample's radiance (the pixel filter's; one for most filters).
    weight: f32,
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
        let every_primitive = scene.tests_every_primitive();
        let mut rays = RayLanes::default();
        loop {
            if more {
                more = start_paths(scene, &mut lanes, &mut samplers, samples);
            }
            if lanes.iter().all(Option::is_none) {
                break;
            }
            // Small scenes: every lane's ray against every primitive at once.
            let nearest = every_primitive.then(|| nearest_of_lanes(scene, &lanes, &mut rays));
            // Trace every lane.
            for i in 0..W {
                let Some(lane) = &lanes[i] else {
                    hits[i] = None;
                    continue;
                };
                let st = &lane.st;
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
                            scene.intersect_into(&st.ray, RayKind::at_depth(st.depth), &mut hits[i])
                                as u64
                    }
                }
            }
            let escapes = look_up_escapes(scene, &lanes, &hits);
            // Arrive; scatter the lanes at materials the lanes do not shade together now, and
            // gather the others' inputs.
            let mut shaded = 0u32;
            a.lobes = LobeLanes::default();
            a.mixed = M8::default();
            if a.coated {
                (a.coated, a.coated_lobes) = (false, CoatedLanes::default());
            }
            if a.mapped {
                (a.mapped, a.tangent, a.guard) = (false, M8::default(), M8::default());
            }
            for i in 0..W {
                let Some(lane) = &mut lanes[i] else { continue };
                let smp = &mut samplers[i];
                let st = &mut lane.st;
                let looked_up = escapes
                    .as_ref()
                    .filter(|e| e.active & (1 << i) != 0)
                    .map(|e| (e.le.get(i), e.pdf.0[i]));
                if !self.arrive_looked_up(scene, st, hits[i].as_ref(), looked_up) {
                    out(lane.tag, st.l * lane.weight);
                    lanes[i] = None;
                    hits[i] = None;
                    continue;
                }
                // `arrive` goes on only at a surface.
                let Some(si) = &hits[i] else { continue };
                let material = scene.material(si.material);
                // A plain Lambertian material first, the common case; then the other lobes the
                // lanes shade; the rest scatters here, one lane at a time.
                let two_sided = match material.as_lambertian() {
                    Some((diffuse, two_sided)) => {
                        stats.random_vertices += u64::from(diffuse.reflectance.max_element() > 0.0);
                        a.diffuse.set_lane(i, diffuse);
                        two_sided
                    }
                    None => match gather_lobe(scene, si, -st.ray.d, material, i, &mut a, stats) {
                        Some(two_sided) => two_sided,
                        None => {
                            if !self.scatter(scene, st, si, smp, stats) {
                                out(lane.tag, st.l * lane.weight);
                                lanes[i] = None;
                            }
                            hits[i] = None;
                            continue;
                        }
                    },
                };
                let wo = -st.ray.d;
                a.p.set(i, si.p);
                a.ng.set(i, si.ng);
                a.ns.set(i, si.ns);
                a.wo.set(i, wo);
                a.two_sided.set(i, two_sided);
                shaded |= 1 << i;
            }
            if shaded == 0 {
                continue;
            }
            // The scalar code's random numbers, in its order, for all these lanes at once:
            // light choice (1D), light point (2D), lobe choice (1D, unused: their BSDFs have
            // one lobe), direction (2D), Russian roulette (1D).
            AnySampler::next_lanes(&mut samplers, shaded, &[1, 2, 1, 2, 1], &mut u);
            a.u_light = [F8(u[1]), F8(u[2])];
            a.u_lobe = F8(u[3]);
            a.u_bsdf = [F8(u[4]), F8(u[5])];
            // The environment map's table, asked for now and read after the light choices
            // below (a cache miss more often than not, where the lanes waited on it).
            if let Some(map) = environment_map(scene) {
                map.prefetch_directions(a.u_light, shaded);
            }
            // From here on, the lanes with a hit are the ones shaded together (the others'
            // hits were cleared above).
            let mut environment = None;
            let mut environment_lanes = 0u32;
            a.drawn.lanes = M8::default();
            for i in 0..W {
                let (Some(_), Some(si)) = (&lanes[i], &hits[i]) else {
                    continue;
                };
                // Smooth lobes take no light sample (their numbers are drawn all the same).
                if a.lobes.delta.get(i) {
                    a.light.set(i, false);
                    continue;
                }
                let u_light = Vec2::new(u[1][i], u[2][i]);
                let light = gather_light(scene, i, si, u[0][i], u_light, &mut a);
                a.light.set(i, matches!(light, LaneLight::Triangle));
                if let LaneLight::Environment(map) = light {
                    environment = Some(map);
                    environment_lanes |= 1 << i;
                }
            }
            // The environment map's directions for every lane that chose it, together.
            let directions = environment.map(|map| {
                let d = sample_direction_lanes(map, [F8(u[1]), F8(u[2])], environment_lanes);
                (map, d)
            });
            a.environment = M8::default();
            if let Some((_, d)) = &directions {
                (a.environment, a.environment_wi, a.environment_pdf) = (d.found, d.wi, d.pdf);
            }
            scatter(&mut a, &mut b);
            // Small scenes: every lane's shadow ray against every primitive at once.
            let blocked = every_primitive.then(|| blocked_lanes(scene, &b, &mut rays));
            for i in 0..W {
                let (Some(lane), Some(si)) = (&mut lanes[i], &hits[i]) else {
                    continue;
                };
                let goes_on = self.finish_bounce(
                    scene,
                    i,
                    &mut lane.st,
                    si,
                    &b,
                    blocked.map(|m| m & (1 << i) != 0),
                    directions.as_ref(),
                    u[6][i],
                    stats,
                );
                if !goes_on {
                    out(lane.tag, lane.st.l * lane.weight);
                    lanes[i] = None;
                }
            }
        }
    }

    /// The end of lane `i`'s bounce after the SIMD scattering: the shadow ray (traced here
    /// unless `blocked` says whether it is; adding the light sample's contribution where it is
    /// unblocked; an environment map's radiance, from `directions`, is read then), the
    /// throughput times the BSDF sample's weight (and the radiance scale by the relative index
    /// it crossed), Russian roulette with `u_rr`. Returns whether the path goes on.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn finish_bounce(
        &self,
        scene: &Scene,
        i: usize,
        st: &mut PathState,
        si: &SurfaceInteraction,
        b: &ScatterOut,
        blocked: Option<bool>,
        directions: Option<&(&EnvironmentMap, DirectionLanes)>,
        u_rr: f32,
        stats: &mut PathStats,
    ) -> bool {
        if b.shadow.get(i) {
            stats.rays += 1;
            let environment = directions.filter(|(_, d)| d.found.get(i));
            let occluded = blocked.unwrap_or_else(|| {
                scene.occluded(&Ray {
                    o: b.shadow_o.get(i),
                    d: b.shadow_d.get(i),
                    t_min: 0.0,
                    t_max: b.shadow_t_max.0[i],
                })
            });
            if !occluded {
                match environment {
                    Some((map, d)) => {
                        // As `visible_light_sample` and `sample_light` finish.
                        let li = map.radiance_at(Vec2::new(d.uv[0].0[i], d.uv[1].0[i]));
                        if li.max_element() > 0.0 {
                            st.l += st.beta * (b.f.get(i) * li * b.weight_over_pdf.0[i]);
                        }
                    }
                    None => st.l += st.beta * b.ld.get(i),
                }
            }
        }
        b.sampled.get(i) && {
            st.beta *= b.weight.get(i);
            let eta = b.eta.0[i];
            st.eta_scale *= eta * eta;
            st.beta.max_element() > 0.0
                && st.beta.is_finite()
                && self.survive(scene, st, si, b.wi.get(i), b.pdf.0[i], b.delta.get(i), u_rr)
        }
    }
}

/// Idle lanes take the next samples' camera rays, made together where several lanes start and
/// the camera allows ([`crate::camera::Camera::generate_rays`]); returns whether samples
/// remain. (Out of line, as [`look_up_escapes`]: inlined, the Cornell box ran 2–4% slower.)
#[inline(never)]
fn start_paths(
    scene: &Scene,
    lanes: &mut [Option<Lane>; W],
    samplers: &mut [AnySampler; W],
    samples: &mut dyn Iterator<Item = SampleRef>,
) -> bool {
    let mut cam = [CameraSample::default(); W];
    let mut started = 0u32;
    let mut more = true;
    for (i, (lane, smp)) in lanes.iter_mut().zip(samplers.iter_mut()).enumerate() {
        if lane.is_none() {
            let Some(s) = samples.next() else {
                more = false;
                break;
            };
            cam[i] = camera_sample(scene, smp, s);
            *lane = Some(Lane {
                tag: s.tag,
                st: PathState::new(Ray::new(glam::Vec3::ZERO, glam::Vec3::ZERO)),
                weight: cam[i].weight,
            });
            started |= 1 << i;
        }
    }
    if started == 0 {
        return more;
    }
    // Together where several lanes start (one lane alone is made faster by itself).
    let camera = scene.camera();
    let rays = if started.count_ones() > 1 {
        camera.generate_rays(cam.map(|c| c.film))
    } else {
        None
    };
    for (i, lane) in lanes.iter_mut().enumerate() {
        if let (true, Some(lane)) = (started & (1 << i) != 0, lane) {
            lane.st.ray = match &rays {
                Some(rays) => rays[i],
                None => camera.generate_ray(cam[i].film, cam[i].u_lens),
            };
        }
    }
    more
}

/// Every busy lane's ray against every primitive at once (the small scenes' trace); idle lanes
/// get an empty interval. Blocks of triangles that no ray meets are skipped where every ray
/// is a camera ray or a first bounce (the lanes take consecutive samples of a pixel, so
/// those rays go the same way; deeper ones leave scattered points and meet nearly every
/// block).
fn nearest_of_lanes(
    scene: &Scene,
    lanes: &[Option<Lane>; W],
    rays: &mut RayLanes,
) -> crate::accel::Nearest {
    let mut t_max = F8::splat(f32::NEG_INFINITY);
    let mut coherent = true;
    for (i, lane) in lanes.iter().enumerate() {
        if let Some(lane) = lane {
            coherent &= lane.st.depth <= 1;
            rays.set(i, &lane.st.ray);
            t_max.0[i] = lane.st.ray.t_max;
        }
    }
    scene.nearest_of_rays(rays, t_max, coherent)
}

/// The lanes whose shadow ray ([`ScatterOut::shadow`]) something blocks, as bits, found by
/// testing every primitive against all eight at once ([`Scene::nearest_of_rays`]; only where
/// [`Scene::tests_every_primitive`]): a ray is blocked where it has a nearest hit within its
/// extent, which is where [`Scene::occluded`] finds one (the same triangle and sphere tests).
/// Lanes without a shadow ray get an empty extent. The blocks of triangles that no shadow ray
/// meets the box of are skipped: shadow rays towards a small light converge on it, and in the
/// Cornell box this is what makes the lanes' test faster than the BVH's early exit (without
/// it, 7% slower; with it, 1% faster).
fn blocked_lanes(scene: &Scene, b: &ScatterOut, rays: &mut RayLanes) -> u32 {
    if !b.shadow.any() {
        return 0;
    }
    (rays.o, rays.d, rays.t_min) = (b.shadow_o, b.shadow_d, F8::splat(0.0));
    let t_max = b
        .shadow
        .select(b.shadow_t_max, F8::splat(f32::NEG_INFINITY));
    let nearest = scene.nearest_of_rays(rays, t_max, true);
    (0..W)
        .filter(|&i| nearest.lane(i).is_some())
        .fold(0, |m, i| m | 1 << i)
}

/// An environment map's radiance and density towards the rays of the lanes `active`, which
/// left the scene.
struct Escapes {
    active: u32,
    le: V8,
    pdf: F8,
}

/// The environment map's radiance and density towards every lane's ray that left the scene,
/// looked up together ([`EnvironmentMap::eval_and_pdf_lanes`]) where two or more did and the
/// scene's environment is a map. Kept out of line: inlined in the path loop, it made the loop
/// slower (3% on sky-spheres).
#[inline(never)]
fn look_up_escapes(
    scene: &Scene,
    lanes: &[Option<Lane>; W],
    hits: &[Option<SurfaceInteraction>; W],
) -> Option<Escapes> {
    let map = environment_map(scene)?;
    let mut w = V8::default();
    let mut active = 0u32;
    for (i, (lane, hit)) in lanes.iter().zip(hits).enumerate() {
        if let (Some(lane), None) = (lane, hit) {
            w.set(i, lane.st.ray.d);
            active |= 1 << i;
        }
    }
    if active.count_ones() < 2 {
        return None;
    }
    let (le, pdf) = eval_and_pdf_lanes(map, w, active);
    Some(Escapes { active, le, pdf })
}

/// The scene's environment map, if its environment is one.
fn environment_map(scene: &Scene) -> Option<&EnvironmentMap> {
    let index = scene.environment()?;
    match &scene.lights()[index as usize] {
        Light::EnvironmentMap { map, .. } => Some(map),
        _ => None,
    }
}

/// [`EnvironmentMap::sample_direction_lanes`] on the best vector unit this CPU has.
fn sample_direction_lanes(map: &EnvironmentMap, u: [F8; 2], active: u32) -> DirectionLanes {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `sample_direction_lanes_avx2` requires AVX2 and FMA, which `avx2` proves
        // this CPU has. Its body is safe code.
        return unsafe { sample_direction_lanes_avx2(avx2, map, u, active) };
    }
    map.sample_direction_lanes(u, active)
}

/// [`EnvironmentMap::sample_direction_lanes`] compiled for AVX2 (the same bits, as
/// [`eval_and_pdf_lanes_avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn sample_direction_lanes_avx2(
    _: crate::simd::Avx2,
    map: &EnvironmentMap,
    u: [F8; 2],
    active: u32,
) -> DirectionLanes {
    map.sample_direction_lanes(u, active)
}

/// [`EnvironmentMap::eval_and_pdf_lanes`] on the best vector unit this CPU has.
fn eval_and_pdf_lanes(map: &EnvironmentMap, w: V8, active: u32) -> (V8, F8) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `eval_and_pdf_lanes_avx2` requires AVX2 and FMA, which `avx2` proves this
        // CPU has. Its body is safe code.
        return unsafe { eval_and_pdf_lanes_avx2(avx2, map, w, active) };
    }
    map.eval_and_pdf_lanes(w, active)
}

/// [`EnvironmentMap::eval_and_pdf_lanes`] compiled for AVX2 (the same bits: Rust does not fuse
/// a product and a sum into one FMA).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn eval_and_pdf_lanes_avx2(
    _: crate::simd::Avx2,
    map: &EnvironmentMap,
    w: V8,
    active: u32,
) -> (V8, F8) {
    map.eval_and_pdf_lanes(w, active)
}

/// Lane `i`'s lobe at `si` seen from `wo` into `a`, where `material` is one the lanes shade
/// together other than a plain Lambertian one ([`Material::lane_bxdf`]): returns its
/// sidedness, or `None` for a material the lanes leave to the one-path code. A lobe whose
/// frame follows the surface's tangent (or a normal or bump map's) gets it here, with a map's
/// guard, as [`Scene::bsdf`] makes them.
#[inline(always)]
fn gather_lobe(
    scene: &Scene,
    si: &SurfaceInteraction,
    wo: glam::Vec3,
    material: &Material,
    i: usize,
    a: &mut ScatterIn,
    stats: &mut PathStats,
) -> Option<bool> {
    let lane = material.lane_bxdf(|| scene.tex_point(si), wo, si.ns)?;
    let (lobe, two_sided) = (lane.bxdf, lane.two_sided);
    if lane.mapped {
        gather_frame(scene, si, wo, material, i, a);
    }
    let lobes = &mut a.lobes;
    let mixed = lane.weight < 1.0;
    if mixed {
        a.mixed.set(i, true);
        a.lobe_weight.0[i] = lane.weight;
        // All passing through: a delta BSDF (`Bsdf::is_delta`), without a light sample.
        if lane.weight <= 0.0 {
            lobes.delta.set(i, true);
        }
    }
    // As `scatter` counts a vertex whose BSDF is not black: every lobe but a black diffuse
    // one, and any through which light passes.
    let black = matches!(lobe, LaneBxdf::Diffuse(d) if d.reflectance.max_element() <= 0.0);
    stats.random_vertices += u64::from(!black || mixed);
    let coated = &mut a.coated_lobes;
    match lobe {
        LaneBxdf::Diffuse(diffuse) => a.diffuse.set_lane(i, diffuse),
        LaneBxdf::Conductor(metal) => {
            a.metal.set_lane(i, metal);
            lobes.conductor.set(i, true);
        }
        LaneBxdf::RoughDielectric(glass) => {
            a.rough_glass.set_lane(i, glass);
            lobes.rough_glass.set(i, true);
        }
        LaneBxdf::Mirror(mirror) => {
            a.mirror.set_lane(i, mirror);
            lobes.delta.set(i, true);
        }
        LaneBxdf::SmoothConductor(metal) => {
            a.smooth_metal.set_lane(i, metal);
            lobes.smooth_metal.set(i, true);
            lobes.delta.set(i, true);
        }
        LaneBxdf::Dielectric(glass) => {
            a.glass.set_lane(i, glass);
            lobes.glass.set(i, true);
            lobes.delta.set(i, true);
        }
        LaneBxdf::ThinDielectric(glass) => {
            a.thin_glass.set_lane(i, glass);
            coated.thin_glass.set(i, true);
            lobes.delta.set(i, true);
            a.coated = true;
        }
        LaneBxdf::DiffuseTransmission(d) => {
            a.translucent.set_lane(i, d);
            coated.translucent.set(i, true);
            a.coated = true;
        }
        LaneBxdf::Plastic(plastic) => {
            a.plastic.set_lane(i, plastic);
            coated.plastic.set(i, true);
            a.coated = true;
        }
        LaneBxdf::RoughPlastic(plastic) => {
            a.rough_plastic.set_lane(i, plastic);
            coated.rough_plastic.set(i, true);
            a.coated = true;
        }
        LaneBxdf::Principled(p) => {
            a.principled.set_lane(i, p.lobes());
            coated.principled.set(i, true);
            a.coated = true;
        }
    }
    Some(two_sided)
}

/// Lane `i`'s frame and guard, for a lobe [`Material::lane_bxdf`] gives as mapped
/// ([`Material::lane_frame`]), into `a`: out of line, the rarer case.
#[inline(never)]
fn gather_frame(
    scene: &Scene,
    si: &SurfaceInteraction,
    wo: glam::Vec3,
    material: &Material,
    i: usize,
    a: &mut ScatterIn,
) {
    let (frame, guard) = material.lane_frame(&scene.shading_point(si), wo);
    a.frame.s.set(i, frame.s);
    a.frame.t.set(i, frame.t);
    a.frame.n.set(i, frame.n);
    a.tangent.set(i, true);
    if let Some(guard) = guard {
        a.guard_n.set(i, guard.n);
        a.guard_alpha2.0[i] = guard.alpha2;
        a.guard.set(i, true);
    }
    a.mapped = true;
}

/// How a lane's light sample is taken.
enum LaneLight<'a> {
    /// A point on an emitting triangle, in the SIMD lanes.
    Triangle,
    /// A direction of this environment map, in the SIMD lanes.
    Environment(&'a EnvironmentMap),
    /// Any other: drawn one lane at a time into [`ScatterIn::drawn`] (whose mask says whether
    /// there is a sample), or no light at all.
    Other,
}

/// Lane `i`'s light choice from `u_select`: an emitting triangle's data go to the lane of `a`
/// for the SIMD light sample, as does the light's probability for an environment map; any
/// other light is sampled here by its own [`Light::sample_li`] with `u_light`, its sample and
/// shadow ray going to `a.drawn` (where it has a density and radiance: otherwise, as for no
/// light at all, nothing, as [`super::visible_light_sample`] returns early).
#[inline]
fn gather_light<'a>(
    scene: &'a Scene,
    i: usize,
    si: &SurfaceInteraction,
    u_select: f32,
    u_light: Vec2,
    a: &mut ScatterIn,
) -> LaneLight<'a> {
    let Some((index, pmf)) = scene.light_sampler().sample(u_select) else {
        return LaneLight::Other;
    };
    match &scene.lights()[index] {
        Light::Area {
            shape: AreaShape::Triangle(t),
            radiance,
            two_sided,
            texture: None,
        } => {
            a.emitter.set_lane(i, t.emitter(*radiance, *two_sided));
            a.light_pmf.0[i] = pmf;
            LaneLight::Triangle
        }
        Light::EnvironmentMap { map, .. } => {
            a.light_pmf.0[i] = pmf;
            LaneLight::Environment(map)
        }
        light => {
            draw_light_sample(light, pmf, i, si, u_light, a);
            LaneLight::Other
        }
    }
}

/// [`gather_light`]'s sample of a light the lanes do not sample together, drawn by the light's
/// own [`Light::sample_li`] into lane `i` of `a.drawn` where it may carry light (the lane
/// stays off otherwise). Out of line: the path loop stays as small as it is for the common
/// lights.
#[inline(never)]
fn draw_light_sample(
    light: &Light,
    pmf: f32,
    i: usize,
    si: &SurfaceInteraction,
    u_light: Vec2,
    a: &mut ScatterIn,
) {
    if let Some(ls) = light.sample_li(si.p, u_light) {
        if ls.may_carry_light(true) {
            a.drawn.set(i, &ls, &shadow_ray(light, si, &ls));
            a.light_pmf.0[i] = pmf;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::diffuse::TEST_SCALE;
    use crate::desc::{CameraDesc, Emission, MeshDesc, SceneDesc};
    use crate::integrator::Integrator;
    use glam::Vec3;

    /// A floor and a back wall lit by an emitting quad above, seen from the front.
    fn room() -> Scene {
        Scene::build(&room_desc()).unwrap()
    }

    /// [`room`]'s description.
    fn room_desc() -> SceneDesc {
        let quad = |c: [Vec3; 4], material, emission| MeshDesc {
            name: "quad".into(),
            positions: c.to_vec(),
            indices: vec![0, 1, 2, 0, 2, 3],
            material,
            emission,
            ..Default::default()
        };
        SceneDesc {
            meshes: vec![
                quad(
                    [
                        Vec3::new(-1.0, 0.0, -1.0),
                        Vec3::new(-1.0, 0.0, 1.0),
                        Vec3::new(1.0, 0.0, 1.0),
                        Vec3::new(1.0, 0.0, -1.0),
                    ],
                    0,
                    None,
                ),
                quad(
                    [
                        Vec3::new(-1.0, 0.0, -1.0),
                        Vec3::new(1.0, 0.0, -1.0),
                        Vec3::new(1.0, 2.0, -1.0),
                        Vec3::new(-1.0, 2.0, -1.0),
                    ],
                    0,
                    None,
                ),
                quad(
                    [
                        Vec3::new(-0.3, 1.5, -0.3),
                        Vec3::new(0.3, 1.5, -0.3),
                        Vec3::new(0.3, 1.5, 0.3),
                        Vec3::new(-0.3, 1.5, 0.3),
                    ],
                    0,
                    Some(Emission {
                        radiance: Vec3::splat(10.0),
                        two_sided: false,
                    }),
                ),
            ],
            materials: vec![crate::scene::diffuse(Vec3::splat(0.6), false)],
            camera: CameraDesc {
                origin: Vec3::new(0.0, 1.0, 3.0),
                target: Vec3::new(0.0, 0.5, 0.0),
                up: Vec3::Y,
                fov_degrees: 50.0,
                ..Default::default()
            },
            resolution: [8, 8],
            ..Default::default()
        }
    }

    /// The default path tracer's estimates of every pixel's samples, on this thread.
    fn render_here(scene: &Scene) -> Vec<Rgb> {
        let integrator = PathIntegrator::default();
        assert!(
            integrator.packets_apply(),
            "the default settings take the lanes"
        );
        let mut sampler = pathlab_mc::sampler::SamplerKind::Independent.build(4, 1);
        let samples: Vec<SampleRef> = (0..64u32)
            .flat_map(|p| {
                (0..4).map(move |index| SampleRef {
                    pixel: [p % 8, p / 8],
                    index,
                    tag: p * 4 + index,
                })
            })
            .collect();
        let mut out = vec![Rgb::ZERO; samples.len()];
        integrator.li_samples(
            scene,
            &mut sampler,
            &mut samples.iter().copied(),
            &mut |tag, l| out[tag as usize] = l,
            &mut PathStats::default(),
        );
        out
    }

    #[test]
    fn the_lanes_shadow_rays_are_blocked_where_the_bvh_finds_a_blocker() {
        // The room with two spheres: small enough for the lanes' shadow rays to be tested
        // against every primitive at once. Each lane's answer must be `Scene::occluded`'s, for
        // rays of every length (to infinity, as towards an environment map, and short), in
        // rounds where some lanes have no shadow ray.
        let mut desc = room_desc();
        desc.spheres = [
            (Vec3::new(0.3, 0.4, 0.0), 0.3),
            (Vec3::new(-0.5, 1.0, -0.5), 0.2),
        ]
        .map(|(center, radius)| crate::desc::SphereDesc {
            center,
            radius,
            ..Default::default()
        })
        .to_vec();
        let scene = Scene::build(&desc).unwrap();
        assert!(scene.tests_every_primitive());
        let mut rng = pathlab_mc::rng::Pcg32::new(3, 7);
        let mut rays = RayLanes::default();
        let (mut blocked, mut clear) = (0, 0);
        for _ in 0..2000 {
            let mut b = ScatterOut::default();
            let mut shadows = [None; W];
            for (i, shadow) in shadows.iter_mut().enumerate() {
                if rng.uniform_f32() < 0.2 {
                    continue;
                }
                let mut u = || rng.uniform_f32();
                let mut point = || Vec3::new(2.0 * u() - 1.0, 1.8 * u() + 0.05, 2.0 * u() - 1.0);
                let (o, target) = (point(), point());
                let unit = pathlab_mc::warp::sample_uniform_sphere(glam::Vec2::new(u(), u()));
                // Towards infinity, a short way, and to a point (as to a point light).
                let (d, t_max) = match i % 3 {
                    0 => (unit, f32::INFINITY),
                    1 => (unit, 2.0 * u()),
                    _ => (target - o, SHADOW_RAY_END),
                };
                b.shadow.set(i, true);
                b.shadow_o.set(i, o);
                b.shadow_d.set(i, d);
                b.shadow_t_max.0[i] = t_max;
                *shadow = Some(Ray {
                    o,
                    d,
                    t_min: 0.0,
                    t_max,
                });
            }
            let lanes = blocked_lanes(&scene, &b, &mut rays);
            for (i, shadow) in shadows.iter().enumerate() {
                let want = shadow.is_some_and(|ray| scene.occluded(&ray));
                assert_eq!(lanes & (1 << i) != 0, want, "lane {i}: {shadow:?}");
                match (shadow, want) {
                    (Some(_), true) => blocked += 1,
                    (Some(_), false) => clear += 1,
                    _ => {}
                }
            }
        }
        assert!(
            blocked > 1000 && clear > 1000,
            "{blocked} blocked, {clear} clear"
        );
    }

    #[test]
    fn the_lanes_shade_with_the_diffuse_bsdfs_own_code() {
        // Halving what `Diffuse` computes must dim every lit sample of the default render,
        // which runs in lanes: there is no second copy of the BSDF for them.
        let scene = room();
        let full = render_here(&scene);
        TEST_SCALE.with(|s| s.set(0.5));
        let half = render_here(&scene);
        TEST_SCALE.with(|s| s.set(1.0));
        let lit = full.iter().filter(|l| l.max_element() > 0.0).count();
        assert!(lit > 100, "only {lit} lit samples");
        let (sum_full, sum_half): (f32, f32) = (
            full.iter().map(|l| l.y).sum(),
            half.iter().map(|l| l.y).sum(),
        );
        assert!(
            sum_half < 0.75 * sum_full,
            "halving the BSDF: {sum_half} vs {sum_full}"
        );
    }
}
