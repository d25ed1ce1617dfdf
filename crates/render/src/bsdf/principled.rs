//! Disney's principled BSDF as Mitsuba 3 defines it (`principled`: a solid object, and
//! `principledthin`: a thin sheet), with Mitsuba's lobes, weights and approximations, so that
//! scenes written for it render the same.
//!
//! Directions follow pathlab's convention: `wo` towards the viewer, `wi` towards the light,
//! both in the local frame. Mitsuba's formulas give f · |cos θi|; these return f.
//!
//! The model is written once ([`PrincipledLobes`]) for one material and for eight lanes'
//! materials: [`Principled`] evaluates through it, and the path tracer's lanes shade with the
//! same functions.

use super::bxdf::DirectionSample;
use super::fresnel::fresnel_dielectric_real;
use super::microfacet::{Distribution, Microfacet, MicrofacetLanes, NormalDistribution};
use super::scattering::{reflect, refract_about_real, relative_eta};
use super::LocalSample;
use crate::color::mitsuba_luminance_real as luminance;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Which optional lobes and parameters a principled material has (Mitsuba switches lobes on
/// by the parameter being given, and some formulas change with it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PrincipledFlags {
    /// `anisotropic` given (and not the number 0).
    pub anisotropic: bool,
    /// `spec_trans` given.
    pub spec_trans: bool,
    /// `metallic` given.
    pub metallic: bool,
    /// `clearcoat` given.
    pub clearcoat: bool,
    /// `sheen` given.
    pub sheen: bool,
    /// `sheen_tint` given.
    pub sheen_tint: bool,
    /// `spec_tint` given.
    pub spec_tint: bool,
    /// `flatness` given.
    pub flatness: bool,
    /// `diff_trans` given (thin only).
    pub diff_trans: bool,
}

/// The parameters of a principled material at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// Base colour.
    pub base_color: Rgb,
    /// Roughness in [0, 1].
    pub roughness: f32,
    /// Anisotropy in [0, 1].
    pub anisotropic: f32,
    /// Share of specular transmission.
    pub spec_trans: f32,
    /// Metalness.
    pub metallic: f32,
    /// Clear coat weight.
    pub clearcoat: f32,
    /// Clear coat glossiness.
    pub clearcoat_gloss: f32,
    /// Sheen weight.
    pub sheen: f32,
    /// Sheen tint towards the base colour.
    pub sheen_tint: f32,
    /// Specular tint towards the base colour.
    pub spec_tint: f32,
    /// Flatness (fake subsurface).
    pub flatness: f32,
    /// Diffuse transmission in [0, 2] (thin only).
    pub diff_trans: f32,
    /// Relative index of refraction.
    pub eta: f32,
    /// Which lobes are on.
    pub flags: PrincipledFlags,
    /// A thin sheet (`principledthin`) rather than the surface of a solid.
    pub thin: bool,
}

/// The mask type of a colour type's numbers.
type Mask<V> = <<V as Vector3>::R as Real>::Mask;

/// `s` in every channel.
#[inline(always)]
fn grey<V: Vector3>(s: V::R) -> V {
    V::new(s, s, s)
}

/// `value + term()` where `m`, `value` elsewhere; `term` is computed only where some lane
/// has `m` (for one material: only where `m` holds).
#[inline(always)]
fn add_where<V: Vector3>(value: V, m: Mask<V>, term: impl FnOnce() -> V) -> V {
    if V::R::any(m) {
        V::select(m, value + term(), value)
    } else {
        value
    }
}

/// [`add_where`] for a number.
#[inline(always)]
fn add_real_where<R: Real>(value: R, m: R::Mask, term: impl FnOnce() -> R) -> R {
    if R::any(m) {
        R::select(m, value + term(), value)
    } else {
        value
    }
}

/// glam's `try_normalize`: the vector times the reciprocal of its length, and where that
/// reciprocal is finite and positive (elsewhere the vector is meaningless).
#[inline(always)]
fn try_normalize<V: Vector3>(v: V) -> (V, Mask<V>) {
    let rcp = V::R::splat(1.0) / v.dot(v).sqrt();
    (v.scale(rcp), rcp.is_finite() & rcp.gt(V::R::splat(0.0)))
}

/// (1 - c)⁵ clamped: Schlick's weight.
#[inline(always)]
fn schlick_weight<R: Real>(c: R) -> R {
    let m = (R::splat(1.0) - c).max(R::splat(0.0)).min(R::splat(1.0));
    let m2 = m * m;
    m2 * m2 * m
}

/// ((η - 1) / (η + 1))².
#[inline(always)]
fn schlick_r0<R: Real>(eta: R) -> R {
    let r = (eta - R::splat(1.0)) / (eta + R::splat(1.0));
    r * r
}

/// Schlick's Fresnel with normal-incidence reflectance `r0` (the transmitted angle's cosine
/// inside the denser medium), Mitsuba's `calc_schlick`.
#[inline(always)]
fn calc_schlick<V: Vector3>(r0: V, cos_i: V::R, eta: V::R) -> V {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let eta_it = V::R::select(zero.le(cos_i), eta, one / eta);
    let eta_ti = one / eta_it;
    let cos_t2 = one - (one - cos_i * cos_i) * eta_ti * eta_ti;
    let cos_t = cos_t2.max(zero).sqrt();
    let w = V::R::select(
        eta_it.gt(one),
        schlick_weight(cos_i.abs()),
        schlick_weight(cos_t),
    );
    r0 + (grey::<V>(one) - r0).scale(w)
}

/// The base colour normalised by its luminance (white for black).
#[inline(always)]
fn tint<V: Vector3>(base: V) -> V {
    let lum = luminance(base);
    V::select(
        lum.gt(V::R::splat(0.0)),
        base.div_by(lum),
        grey(V::R::splat(1.0)),
    )
}

/// Whether a facet `m` faces `v` and `w` from the sides macro surface reflection (or
/// transmission) needs, for light arriving from the side of `cos`'s sign.
#[inline(always)]
fn compatible<V: Vector3>(m: V, v: V, w: V, cos: V::R, reflection: bool) -> Mask<V> {
    let zero = V::R::splat(0.0);
    let m = V::select(cos.lt(zero), -m, m);
    let faces_v = v.dot(m).gt(zero);
    if reflection {
        faces_v & w.dot(m).gt(zero)
    } else {
        faces_v & w.dot(-m).gt(zero)
    }
}

/// Smith's GGX masking for the clear coat (isotropic, separable; α = 0.25).
#[inline(always)]
fn smith_ggx1<V: Vector3>(v: V, wh: V) -> V::R {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let alpha = V::R::splat(0.25);
    let cos2 = v.z() * v.z();
    let tan2 = (one - cos2) / cos2;
    let g = V::R::splat(2.0) / (one + (one + alpha * alpha * tan2).sqrt());
    let g = V::R::select(v.z().equals(one), one, g);
    V::R::select((v.dot(wh) * v.z()).le(zero), zero, g)
}

/// ln α² of the clear coat's GTR1 distribution of roughness α, taken once per material
/// ([`Principled::lobes`]) rather than in each evaluation.
#[inline(always)]
fn gtr1_ln_a2(alpha: f32) -> f32 {
    (alpha * alpha).ln()
}

/// The GTR1 distribution of the clear coat, of roughness `alpha` (and `ln_a2`, its
/// [`gtr1_ln_a2`]), at the normal `m`.
#[inline(always)]
fn gtr1_eval<V: Vector3>(alpha: V::R, ln_a2: V::R, m: V) -> V::R {
    let one = V::R::splat(1.0);
    let a2 = alpha * alpha;
    let r = (a2 - one) / (V::R::splat(PI) * ln_a2 * (one + (a2 - one) * m.z() * m.z()));
    V::R::select((r * m.z()).gt(V::R::splat(1e-20)), r, V::R::splat(0.0))
}

/// The density of [`gtr1_sample`]'s normals.
#[inline(always)]
fn gtr1_pdf<V: Vector3>(alpha: V::R, ln_a2: V::R, m: V) -> V::R {
    let zero = V::R::splat(0.0);
    V::R::select(m.z().lt(zero), zero, m.z() * gtr1_eval(alpha, ln_a2, m))
}

/// A normal from GTR1 of roughness `alpha` (computed in the lanes `lanes`).
#[inline(always)]
fn gtr1_sample<V: Vector3>(alpha: V::R, u0: V::R, u1: V::R, lanes: Mask<V>) -> V {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let phi = V::R::splat(TAU) * u0;
    let (sin_phi, cos_phi) = (
        phi.map_where(lanes, f32::sin),
        phi.map_where(lanes, f32::cos),
    );
    let a2 = alpha * alpha;
    let cos2 = (one - a2.map2_where(one - u1, lanes, f32::powf)) / (one - a2);
    let sin = (one - cos2).max(zero).sqrt();
    let cos = cos2.max(zero).sqrt();
    V::new(cos_phi * sin, sin_phi * sin, cos)
}

/// Mitsuba's `calc_dist_params`: (αx, αy) from roughness and anisotropy.
fn dist(roughness: f32, anisotropic: f32, has_anisotropic: bool) -> Microfacet {
    let r2 = roughness * roughness;
    if !has_anisotropic {
        let a = r2.max(0.001);
        return Microfacet::new(NormalDistribution::Ggx, a);
    }
    let aspect = (1.0 - 0.9 * anisotropic).sqrt();
    Microfacet::anisotropic(
        NormalDistribution::Ggx,
        (r2 / aspect).max(0.001),
        (r2 * aspect).max(0.001),
    )
}

/// A principled material at a point, ready to evaluate: [`Principled`]'s parameters, its
/// flags as truth values and its two microfacet distributions (the specular lobes', and a
/// thin sheet's transmission's). Written once for one material (`V`, `R`, `M`, `D` =
/// [`Rgb`], `f32`, `bool`, [`Microfacet`]: what [`Principled::lobes`] gives) and for eight
/// lanes' materials ([`V8`], [`F8`], [`M8`], [`MicrofacetLanes`]: set lane by lane by
/// [`PrincipledLobes::set_lane`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PrincipledLobes<V = Rgb, R = f32, M = bool, D = Microfacet> {
    base_color: V,
    roughness: R,
    spec_trans: R,
    metallic: R,
    clearcoat: R,
    /// The clear coat's GTR1 roughness (from its glossiness).
    clearcoat_alpha: R,
    /// Its [`gtr1_ln_a2`], where the material has a clear coat (zero elsewhere).
    clearcoat_ln_a2: R,
    sheen: R,
    sheen_tint: R,
    spec_tint: R,
    flatness: R,
    diff_trans: R,
    eta: R,
    has_spec_trans: M,
    has_metallic: M,
    has_clearcoat: M,
    has_sheen: M,
    has_sheen_tint: M,
    has_spec_tint: M,
    has_flatness: M,
    has_diff_trans: M,
    thin: M,
    /// The specular lobes' distribution.
    specular: D,
    /// A thin sheet's transmission's (Burley 2015's scaled roughness).
    thin_transmission: D,
}

impl Principled {
    /// The material ready to evaluate (the distributions made from roughness and anisotropy).
    #[inline]
    pub fn lobes(&self) -> PrincipledLobes {
        // Every field taken apart: a field added to `Principled` fails to compile until it
        // is passed on here.
        let Principled {
            base_color,
            roughness,
            anisotropic,
            spec_trans,
            metallic,
            clearcoat,
            clearcoat_gloss,
            sheen,
            sheen_tint,
            spec_tint,
            flatness,
            diff_trans,
            eta,
            flags,
            thin,
        } = *self;
        let PrincipledFlags {
            anisotropic: has_anisotropic,
            spec_trans: has_spec_trans,
            metallic: has_metallic,
            clearcoat: has_clearcoat,
            sheen: has_sheen,
            sheen_tint: has_sheen_tint,
            spec_tint: has_spec_tint,
            flatness: has_flatness,
            diff_trans: has_diff_trans,
        } = flags;
        let clearcoat_alpha = 0.1 + clearcoat_gloss * (0.001 - 0.1);
        PrincipledLobes {
            base_color,
            roughness,
            spec_trans,
            metallic,
            clearcoat,
            clearcoat_alpha,
            clearcoat_ln_a2: if has_clearcoat {
                gtr1_ln_a2(clearcoat_alpha)
            } else {
                0.0
            },
            sheen,
            sheen_tint,
            spec_tint,
            flatness,
            diff_trans,
            eta,
            has_spec_trans,
            has_metallic,
            has_clearcoat,
            has_sheen,
            has_sheen_tint,
            has_spec_tint,
            has_flatness,
            has_diff_trans,
            thin,
            specular: dist(roughness, anisotropic, has_anisotropic),
            thin_transmission: dist(
                (0.65 * eta - 0.35) * roughness,
                anisotropic,
                has_anisotropic,
            ),
        }
    }

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.lobes().f(wo, wi)
    }

    /// A sample of wi from `wo`: a lobe chosen as Mitsuba weighs them, then its direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        self.lobes().sample_real(wo, uc, u.x, u.y).local()
    }

    /// Density of [`Principled::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.lobes().pdf(wo, wi)
    }
}

impl PrincipledLobes<V8, F8, M8, MicrofacetLanes> {
    /// Sets lane `i` to `p`. Every field is taken apart here: a field added to
    /// [`PrincipledLobes`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, p: PrincipledLobes) {
        let PrincipledLobes {
            base_color,
            roughness,
            spec_trans,
            metallic,
            clearcoat,
            clearcoat_alpha,
            clearcoat_ln_a2,
            sheen,
            sheen_tint,
            spec_tint,
            flatness,
            diff_trans,
            eta,
            has_spec_trans,
            has_metallic,
            has_clearcoat,
            has_sheen,
            has_sheen_tint,
            has_spec_tint,
            has_flatness,
            has_diff_trans,
            thin,
            specular,
            thin_transmission,
        } = p;
        self.base_color.set(i, base_color);
        for (lanes, x) in [
            (&mut self.roughness, roughness),
            (&mut self.spec_trans, spec_trans),
            (&mut self.metallic, metallic),
            (&mut self.clearcoat, clearcoat),
            (&mut self.clearcoat_alpha, clearcoat_alpha),
            (&mut self.clearcoat_ln_a2, clearcoat_ln_a2),
            (&mut self.sheen, sheen),
            (&mut self.sheen_tint, sheen_tint),
            (&mut self.spec_tint, spec_tint),
            (&mut self.flatness, flatness),
            (&mut self.diff_trans, diff_trans),
            (&mut self.eta, eta),
        ] {
            lanes.0[i] = x;
        }
        for (lanes, on) in [
            (&mut self.has_spec_trans, has_spec_trans),
            (&mut self.has_metallic, has_metallic),
            (&mut self.has_clearcoat, has_clearcoat),
            (&mut self.has_sheen, has_sheen),
            (&mut self.has_sheen_tint, has_sheen_tint),
            (&mut self.has_spec_tint, has_spec_tint),
            (&mut self.has_flatness, has_flatness),
            (&mut self.has_diff_trans, has_diff_trans),
            (&mut self.thin, thin),
        ] {
            lanes.set(i, on);
        }
        self.specular.set_lane(i, specular);
        self.thin_transmission.set_lane(i, thin_transmission);
    }

    /// Computes the distributions' functions that go one lane at a time only in the lanes
    /// `lanes` ([`MicrofacetLanes::only_in`]).
    #[inline(always)]
    pub fn only_in(&mut self, lanes: M8) {
        self.specular.only_in(lanes);
        self.thin_transmission.only_in(lanes);
    }
}

impl<V: Vector3, D: Distribution<V::R>> PrincipledLobes<V, V::R, Mask<V>, D> {
    /// f(wo, wi).
    #[inline(always)]
    pub fn f(&self, wo: V, wi: V) -> V {
        self.value(wo, wi, &self.halves(wo, wi))
    }

    /// f(wo, wi) and [`PrincipledLobes::pdf`], which share their half vectors.
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V) -> (V, V::R) {
        let h = self.halves(wo, wi);
        (self.value(wo, wi, &h), self.density(wo, wi, &h))
    }

    /// The half vectors between `wo` and `wi` that a solid's and a thin sheet's value and
    /// density both start from, each found where some lane is of that kind.
    #[inline(always)]
    fn halves(&self, wo: V, wi: V) -> Halves<V> {
        Halves {
            solid: V::R::any(!self.thin).then(|| self.solid_half(wo, wi)),
            thin: V::R::any(self.thin).then(|| ThinHalf::new(wo, wi)),
        }
    }

    /// f(wo, wi) from its half vectors.
    #[inline(always)]
    fn value(&self, wo: V, wi: V, h: &Halves<V>) -> V {
        let zero = V::R::splat(0.0);
        let mut value = grey(zero);
        if let Some(h) = &h.solid {
            value = self.solid_value(wo, wi, h);
        }
        if let Some(h) = &h.thin {
            value = V::select(self.thin, self.thin_value(h), value);
        }
        let none = wo.z().equals(zero) | wi.z().equals(zero);
        V::select(none, grey(zero), value.div_by(wi.z().abs()))
    }

    /// The relative index η' of a sample from `wo` to `wi` (a solid's refraction: see
    /// [`super::Bxdf::relative_ior`]; one for a thin sheet).
    #[inline(always)]
    pub fn relative_ior(&self, wo: V, wi: V) -> V::R {
        V::R::select(self.thin, V::R::splat(1.0), relative_eta(wo, wi, self.eta))
    }

    /// What a solid's value and density at (`v`, `l`) share: the side `v` is on, whether
    /// `l` is a reflection, the half vector of the reflection or refraction and its dielectric
    /// Fresnel term, and which facets may serve it.
    #[inline(always)]
    fn solid_half(&self, v: V, l: V) -> SolidHalf<V> {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let front = v.z().gt(zero);
        let reflect = (v.z() * l.z()).gt(zero);
        let eta_path = V::R::select(front, self.eta, one / self.eta);
        let (wh, found) = try_normalize(v + l.scale(V::R::select(reflect, one, eta_path)));
        let wh = V::select(wh.z().lt(zero), -wh, wh);
        SolidHalf {
            front,
            reflect,
            eta_path,
            wh,
            found,
            f_diel: fresnel_dielectric_real(v.dot(wh), self.eta),
            refl_ok: compatible(wh, v, l, v.z(), true),
            refr_ok: compatible(wh, v, l, v.z(), false),
        }
    }

    /// Mitsuba's `principled` eval: f · |cos θi|.
    #[inline(always)]
    fn solid_value(&self, v: V, l: V, h: &SolidHalf<V>) -> V {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let (cos_i, cos_o) = (v.z(), l.z());
        let brdf = (one - self.metallic) * (one - self.spec_trans);
        let bsdf = (one - self.metallic) * self.spec_trans;
        let refract = (cos_i * cos_o).lt(zero);
        let SolidHalf {
            front,
            reflect,
            eta_path,
            wh,
            found,
            f_diel,
            refl_ok,
            refr_ok,
        } = *h;
        let inv_eta_path = one / eta_path;
        let spec = &self.specular;
        let d = spec.d(wh);
        let g = spec.g(v, l, wh);
        let mut value = grey(zero);
        value = add_where(value, reflect & refl_ok & f_diel.gt(zero), || {
            let spec_tint = V::R::select(self.has_spec_tint, self.spec_tint, zero);
            let cos_h = v.dot(wh);
            let eta_it = V::R::select(zero.le(cos_h), self.eta, one / self.eta);
            let mut schlick = grey(zero);
            schlick = add_where(schlick, self.has_metallic, || {
                calc_schlick(self.base_color, cos_h, self.eta).scale(self.metallic)
            });
            schlick = add_where(schlick, self.has_spec_tint, || {
                let f0 = tint(self.base_color).scale(schlick_r0(eta_it));
                calc_schlick(f0, cos_h, self.eta).scale((one - self.metallic) * spec_tint)
            });
            let fresnel = V::select(
                front,
                grey::<V>((one - self.metallic) * (one - spec_tint) * f_diel) + schlick,
                grey(bsdf * f_diel),
            );
            fresnel.scale(d * g / (V::R::splat(4.0) * cos_i.abs()))
        });
        let transmits = self.has_spec_trans & bsdf.gt(zero) & refract & refr_ok & f_diel.lt(one);
        value = add_where(value, transmits, || {
            let scale = inv_eta_path * inv_eta_path;
            let (vh, lh) = (v.dot(wh), l.dot(wh));
            let denom = vh + eta_path * lh;
            let t = (scale * (one - f_diel) * d * g * eta_path * eta_path * vh * lh
                / (cos_i * denom * denom))
                .abs();
            self.transmission_color(transmits).scale(bsdf * t)
        });
        let coated = self.has_clearcoat & self.clearcoat.gt(zero) & reflect & refl_ok & front;
        value = add_where(value, coated, || {
            let fcc = calc_schlick(grey::<V>(V::R::splat(0.04)), v.dot(wh), self.eta).x();
            let dcc = gtr1_eval(self.clearcoat_alpha, self.clearcoat_ln_a2, wh);
            let gcc = smith_ggx1(v, wh) * smith_ggx1(l, wh);
            grey(self.clearcoat * V::R::splat(0.25) * fcc * dcc * gcc * cos_o.abs())
        });
        let diffuse = brdf.gt(zero) & reflect & front;
        value = add_where(value, diffuse, || self.diffuse_value(v, l, wh, brdf, one));
        let sheen = diffuse & self.has_sheen & self.sheen.gt(zero) & (one - self.metallic).gt(zero);
        value = add_where(value, sheen, || {
            self.sheen_value(l, wh, one - self.metallic)
        });
        V::select(found, value, grey(zero))
    }

    /// The colour of a solid's specular transmission, √(base colour) (its square roots taken
    /// in the lanes `lanes`).
    #[inline(always)]
    fn transmission_color(&self, lanes: Mask<V>) -> V {
        let zero = V::R::splat(0.0);
        let c = self.base_color;
        let root = |x: V::R| x.max(zero).map_where(lanes, |x| x.powf(0.5));
        V::new(root(c.x()), root(c.y()), root(c.z()))
    }

    /// The diffuse, retro-reflection and fake-subsurface part, scaled by `weight` and by
    /// `keep` (the thin sheet's share not transmitted diffusely).
    #[inline(always)]
    fn diffuse_value(&self, v: V, l: V, wh: V, weight: V::R, keep: V::R) -> V {
        let (one, half) = (V::R::splat(1.0), V::R::splat(0.5));
        let (ci, co) = (v.z().abs(), l.z().abs());
        let (fo, fi) = (schlick_weight(co), schlick_weight(ci));
        let f_diff = (one - half * fi) * (one - half * fo);
        let cos_d = wh.dot(l);
        let rr = V::R::splat(2.0) * self.roughness * cos_d * cos_d;
        let f_retro = rr * (fo + fi + fo * fi * (rr - one));
        let mut lobe = f_diff + f_retro;
        if V::R::any(self.has_flatness) {
            let fss90 = rr / V::R::splat(2.0);
            let fss = (one + fo * (fss90 - one)) * (one + fi * (fss90 - one));
            let f_ss = V::R::splat(1.25) * (fss * (one / (co + ci) - half) + half);
            let a = f_diff + f_retro;
            lobe = V::R::select(self.has_flatness, a + self.flatness * (f_ss - a), lobe);
        }
        self.base_color
            .scale(weight * co * V::R::splat(FRAC_1_PI) * keep * lobe)
    }

    /// The sheen, scaled by `weight`.
    #[inline(always)]
    fn sheen_value(&self, l: V, wh: V, weight: V::R) -> V {
        let one = V::R::splat(1.0);
        let fd = schlick_weight(wh.dot(l).abs());
        let white = grey::<V>(one);
        let mut c = white;
        if V::R::any(self.has_sheen_tint) {
            let tinted = white + (tint(self.base_color) - white).scale(self.sheen_tint);
            c = V::select(self.has_sheen_tint, tinted, c);
        }
        c.scale(self.sheen * weight * fd * l.z().abs())
    }

    /// The share of a thin sheet's specular transmission and of its diffuse transmission
    /// (zero where the parameter is not given).
    #[inline(always)]
    fn thin_shares(&self) -> (V::R, V::R) {
        let zero = V::R::splat(0.0);
        (
            V::R::select(self.has_spec_trans, self.spec_trans, zero),
            V::R::select(
                self.has_diff_trans,
                self.diff_trans / V::R::splat(2.0),
                zero,
            ),
        )
    }

    /// Mitsuba's `principledthin` eval: f · |cos θi|.
    #[inline(always)]
    fn thin_value(&self, h: &ThinHalf<V>) -> V {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let (spec_trans, diff_trans) = self.thin_shares();
        let ThinHalf {
            v,
            lt,
            reflect,
            wh,
            found,
            refl_ok,
            refr_ok,
            ..
        } = *h;
        let cos_i = v.z();
        let cos_o = lt.z();
        let refract = cos_o.lt(zero);
        let mut value = grey(zero);
        let specular = self.has_spec_trans & spec_trans.gt(zero);
        let spec_r = specular & reflect & refl_ok;
        let spec_t = specular & refract & refr_ok;
        if V::R::any(spec_r | spec_t) {
            let f_diel = fresnel_dielectric_real(v.dot(wh), self.eta);
            value = add_where(value, spec_r, || {
                // Mitsuba's thin_fresnel: the dielectric term blended towards a tinted
                // Schlick term (zero without spec_tint) by spec_tint.
                let spec_tint = V::R::select(self.has_spec_tint, self.spec_tint, zero);
                let mut schlick = grey(zero);
                if V::R::any(self.has_spec_tint) {
                    let f0 = tint(self.base_color).scale(schlick_r0(self.eta));
                    let s = calc_schlick(f0, v.dot(wh), self.eta);
                    schlick = V::select(self.has_spec_tint, s, schlick);
                }
                let f = grey::<V>(f_diel) + (schlick - grey(f_diel)).scale(spec_tint);
                let spec = &self.specular;
                let (d, g) = (spec.d(wh), spec.g(v, lt, wh));
                f.scale(spec_trans * d * g / (V::R::splat(4.0) * cos_i))
            });
            value = add_where(value, spec_t, || {
                let spec = &self.thin_transmission;
                let (d, g) = (spec.d(wh), spec.g(v, lt, wh));
                self.base_color
                    .scale(spec_trans * (one - f_diel) * d * g / (V::R::splat(4.0) * cos_i))
            });
        }
        let diffuse = reflect & spec_trans.lt(one) & diff_trans.lt(one);
        value = add_where(value, diffuse, || {
            self.diffuse_value(v, lt, wh, one - spec_trans, one - diff_trans)
        });
        let sheen = diffuse & self.has_sheen & self.sheen.gt(zero);
        value = add_where(value, sheen, || {
            self.sheen_value(lt, wh, (one - spec_trans) * (one - diff_trans))
        });
        let transmits = self.has_diff_trans & refract & spec_trans.lt(one) & diff_trans.gt(zero);
        value = add_where(value, transmits, || {
            self.base_color
                .scale((one - spec_trans) * diff_trans * V::R::splat(FRAC_1_PI) * cos_o.abs())
        });
        V::select(found, value, grey(zero))
    }

    /// The probabilities of Mitsuba's lobes for a solid (diffuse, clear coat, transmission,
    /// reflection) seen from the front (`front`) or from inside, given the dielectric Fresnel
    /// term `f` of the sampled (or half-vector) facet.
    #[inline(always)]
    fn solid_probabilities(&self, front: Mask<V>, f: V::R) -> [V::R; 4] {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let brdf = (one - self.metallic) * (one - self.spec_trans);
        let bsdf = V::R::select(
            self.has_spec_trans,
            (one - self.metallic) * self.spec_trans,
            zero,
        );
        let reflect = V::R::select(front, one - bsdf * (one - f), f);
        let trans = V::R::select(
            self.has_spec_trans,
            V::R::select(front, bsdf * (one - f), one - f),
            zero,
        );
        let coat = V::R::select(
            self.has_clearcoat & front,
            V::R::splat(0.25) * self.clearcoat,
            zero,
        );
        let diffuse = V::R::select(front, brdf, zero);
        let total = reflect + trans + coat + diffuse;
        let some = total.gt(zero);
        let share = |p: V::R, otherwise: f32| V::R::select(some, p / total, V::R::splat(otherwise));
        [
            share(diffuse, 0.0),
            share(coat, 0.0),
            share(trans, 0.0),
            share(reflect, 1.0),
        ]
    }

    /// The thin sheet's lobe probabilities: specular reflection, specular transmission,
    /// diffuse reflection, diffuse transmission.
    #[inline(always)]
    fn thin_probabilities(&self) -> [V::R; 4] {
        let (zero, one, two) = (V::R::splat(0.0), V::R::splat(1.0), V::R::splat(2.0));
        let (st, dt) = self.thin_shares();
        let p = [
            st / two,
            st / two,
            (one - st) * (one - dt),
            V::R::select(self.has_diff_trans, (one - st) * dt, zero),
        ];
        let total = p[0] + p[1] + p[2] + p[3];
        let some = total.gt(zero);
        let diffuse = [zero, zero, one, zero];
        std::array::from_fn(|i| V::R::select(some, p[i] / total, diffuse[i]))
    }

    /// A sample of wi from `wo` (`uc` choosing the lobe as Mitsuba weighs them, (`u0`, `u1`)
    /// its direction), with f and the density there: it exists where the direction does and
    /// its density is positive.
    #[inline(always)]
    pub fn sample_real(&self, wo: V, uc: V::R, u0: V::R, u1: V::R) -> DirectionSample<V> {
        let zero = V::R::splat(0.0);
        let solid = !self.thin;
        let (mut wi, mut found) = (wo, V::R::no_lane());
        if V::R::any(solid) {
            (wi, found) = self.sample_solid(wo, uc, u0, u1);
        }
        if V::R::any(self.thin) {
            let (t, t_found) = self.sample_thin(wo, uc, u0, u1);
            wi = V::select(self.thin, t, wi);
            found = (self.thin & t_found) | (solid & found);
        }
        let finite = wi.x().is_finite() & wi.y().is_finite() & wi.z().is_finite();
        let found = found & !wo.z().equals(zero) & !wi.z().equals(zero) & finite;
        let (f, pdf) = self.f_and_pdf(wo, wi);
        DirectionSample {
            wi,
            pdf,
            f,
            valid: found & pdf.gt(zero),
        }
    }

    /// Whether a solid scatters light seen from the front (`front`) or from inside: from
    /// inside only when it transmits.
    #[inline(always)]
    fn seen_from(&self, front: Mask<V>) -> Mask<V> {
        let one = V::R::splat(1.0);
        let transmits = ((one - self.metallic) * self.spec_trans).gt(V::R::splat(0.0));
        front | (self.has_spec_trans & transmits)
    }

    /// A solid's sampled direction and where it exists. As Mitsuba samples it: the facet
    /// first (its Fresnel term weighs the lobes), then the chosen lobe's direction from the
    /// same two numbers. A lobe's direction on the side (or facet) the lobe does not serve
    /// has no density in `pdf`: it is a failed sample, not one for the other lobes.
    #[inline(always)]
    fn sample_solid(&self, wo: V, uc: V::R, u0: V::R, u1: V::R) -> (V, Mask<V>) {
        let zero = V::R::splat(0.0);
        let front = wo.z().gt(zero);
        let up = V::select(front, wo, -wo);
        let m = self.specular.sample_wm(up, u0, u1);
        let f = fresnel_dielectric_real(wo.dot(m), self.eta);
        let [p_diff, p_coat, p_trans, _] = self.solid_probabilities(front, f);
        let diffuse = uc.lt(p_diff);
        let coat = !diffuse & uc.lt(p_diff + p_coat);
        let trans = !diffuse & !coat & uc.lt(p_diff + p_coat + p_trans);
        // The specular reflection, where none of the others was chosen.
        let mut wi = reflect(wo, m);
        let mut found = (wi.z() * wo.z()).gt(zero);
        if V::R::any(trans) {
            let (t, _, refracts) = refract_about_real(wo, m, self.eta);
            wi = V::select(trans, t, wi);
            let ok = refracts & (t.z() * wo.z()).lt(zero);
            found = (trans & ok) | (!trans & found);
        }
        if V::R::any(coat) {
            let m = gtr1_sample(self.clearcoat_alpha, u0, u1, coat);
            let r = reflect(wo, m);
            wi = V::select(coat, r, wi);
            let ok = r.z().gt(zero) & wo.dot(m).gt(zero);
            found = (coat & ok) | (!coat & found);
        }
        if V::R::any(diffuse) {
            let w: V = cosine_hemisphere(u0, u1);
            wi = V::select(diffuse, V::select(front, w, -w), wi);
            found = diffuse | found;
        }
        (wi, found & self.seen_from(front))
    }

    /// A thin sheet's sampled direction and where it exists. A specular direction below the
    /// sheet (before the transmission's mirroring), or one whose facet `f` and `pdf` refuse,
    /// is a failed sample: `pdf` gives it no density.
    #[inline(always)]
    fn sample_thin(&self, wo: V, uc: V::R, u0: V::R, u1: V::R) -> (V, Mask<V>) {
        let zero = V::R::splat(0.0);
        let sign = wo.z().sign_one();
        let v = wo.scale(sign);
        let [p_sr, p_st, p_dr, _] = self.thin_probabilities();
        let spec_r = uc.lt(p_sr);
        let spec_t = !spec_r & uc.lt(p_sr + p_st);
        let diff_r = !spec_r & !spec_t & uc.lt(p_sr + p_st + p_dr);
        let diffuse = !spec_r & !spec_t;
        let mut found = V::R::every_lane();
        let mut w = v;
        if V::R::any(diffuse) {
            let c: V = cosine_hemisphere(u0, u1);
            w = V::select(diff_r, c, -c);
        }
        if V::R::any(spec_t) {
            let m = self.thin_transmission.sample_wm(v, u0, u1);
            let r = reflect(v, m);
            let t = V::new(r.x(), r.y(), -r.z());
            w = V::select(spec_t, t, w);
            let ok = r.z().gt(zero) & compatible(m, v, t, v.z(), false);
            found = (spec_t & ok) | (!spec_t & found);
        }
        if V::R::any(spec_r) {
            let r = reflect(v, self.specular.sample_wm(v, u0, u1));
            w = V::select(spec_r, r, w);
            found = (spec_r & r.z().gt(zero)) | (!spec_r & found);
        }
        (w.scale(sign), found)
    }

    /// Density of [`PrincipledLobes::sample_real`] choosing `wi`.
    #[inline(always)]
    pub fn pdf(&self, wo: V, wi: V) -> V::R {
        self.density(wo, wi, &self.halves(wo, wi))
    }

    /// [`PrincipledLobes::pdf`] from its half vectors.
    #[inline(always)]
    fn density(&self, wo: V, wi: V, h: &Halves<V>) -> V::R {
        let zero = V::R::splat(0.0);
        let mut pdf = zero;
        if let Some(h) = &h.solid {
            pdf = self.pdf_solid(wo, wi, h);
        }
        if let Some(h) = &h.thin {
            pdf = V::R::select(self.thin, self.pdf_thin(h), pdf);
        }
        let none = wo.z().equals(zero) | wi.z().equals(zero);
        V::R::select(none, zero, pdf)
    }

    #[inline(always)]
    fn pdf_solid(&self, v: V, l: V, h: &SolidHalf<V>) -> V::R {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let SolidHalf {
            front,
            reflect,
            eta_path,
            wh,
            found,
            f_diel: f,
            refl_ok,
            refr_ok,
        } = *h;
        let [p_diff, p_coat, p_trans, p_refl] = self.solid_probabilities(front, f);
        let up = V::select(front, v, -v);
        let spec = &self.specular;
        let visible = spec.pdf_wm(up, wh);
        // Reflection: the specular lobe's and the clear coat's facets, and the diffuse lobe.
        let jacobian = one / (V::R::splat(4.0) * l.dot(wh)).abs();
        let mut reflected = add_real_where(zero, refl_ok, || p_refl * visible * jacobian);
        let coated = refl_ok & self.has_clearcoat;
        reflected = add_real_where(reflected, coated, || {
            p_coat * gtr1_pdf(self.clearcoat_alpha, self.clearcoat_ln_a2, wh) * jacobian
        });
        reflected = reflected + p_diff * cosine_hemisphere_pdf(l.z().abs());
        // Transmission.
        let transmits = self.has_spec_trans & refr_ok;
        let transmitted = add_real_where(zero, transmits, || {
            let (vh, lh) = (v.dot(wh), l.dot(wh));
            let denom = vh + eta_path * lh;
            let jacobian = (eta_path * eta_path * lh / (denom * denom)).abs();
            p_trans * visible * jacobian
        });
        let pdf = V::R::select(reflect, reflected, transmitted);
        V::R::select(found & self.seen_from(front), pdf, zero)
    }

    #[inline(always)]
    fn pdf_thin(&self, h: &ThinHalf<V>) -> V::R {
        let zero = V::R::splat(0.0);
        let ThinHalf {
            v,
            lt,
            lr,
            reflect,
            wh,
            found,
            refl_ok,
            refr_ok,
        } = *h;
        let [p_sr, p_st, p_dr, p_dt] = self.thin_probabilities();
        let jacobian = V::R::splat(1.0) / (V::R::splat(4.0) * lr.dot(wh)).abs();
        let spec_r = found & reflect & refl_ok;
        let spec_t = found & !reflect & refr_ok;
        let mut pdf = add_real_where(zero, spec_r, || {
            p_sr * self.specular.pdf_wm(v, wh) * jacobian
        });
        pdf = add_real_where(pdf, spec_t, || {
            p_st * self.thin_transmission.pdf_wm(v, wh) * jacobian
        });
        let diffuse = V::R::select(
            reflect,
            p_dr * cosine_hemisphere_pdf(lt.z()),
            p_dt * cosine_hemisphere_pdf(-lt.z()),
        );
        pdf + diffuse
    }
}

/// The half vectors a principled value and density share ([`PrincipledLobes::f_and_pdf`]):
/// a solid's where some lane is a solid, a thin sheet's where some lane is thin.
struct Halves<V: Vector3> {
    solid: Option<SolidHalf<V>>,
    thin: Option<ThinHalf<V>>,
}

/// A solid's half vector at (v, l) and what goes with it ([`PrincipledLobes::solid_half`]).
#[derive(Clone, Copy)]
struct SolidHalf<V: Vector3> {
    /// v on the outside.
    front: Mask<V>,
    /// v and l on the same side.
    reflect: Mask<V>,
    /// The relative index along the path, η from the front, 1/η from inside.
    eta_path: V::R,
    /// The half vector of the reflection, or of the refraction, turned up.
    wh: V,
    /// Where `wh` exists.
    found: Mask<V>,
    /// The dielectric Fresnel term of v at `wh`.
    f_diel: V::R,
    /// Where `wh` may serve a reflection, and a refraction.
    refl_ok: Mask<V>,
    refr_ok: Mask<V>,
}

/// A thin sheet's half vector at (v, l), both mirrored to v's side of the sheet.
#[derive(Clone, Copy)]
struct ThinHalf<V: Vector3> {
    /// v and l, mirrored so that v is above the sheet.
    v: V,
    lt: V,
    /// `lt` reflected to v's side.
    lr: V,
    /// `lt` above the sheet.
    reflect: Mask<V>,
    /// The half vector of v and `lr`, and where it exists.
    wh: V,
    found: Mask<V>,
    /// Where `wh` may serve a reflection, and a transmission.
    refl_ok: Mask<V>,
    refr_ok: Mask<V>,
}

impl<V: Vector3> ThinHalf<V> {
    /// The half vector of `wo` and `wi` at a thin sheet.
    #[inline(always)]
    fn new(wo: V, wi: V) -> Self {
        let sign = wo.z().sign_one();
        let (v, lt) = (wo.scale(sign), wi.scale(sign));
        let lr = V::new(lt.x(), lt.y(), lt.z().abs());
        let (wh, found) = try_normalize(v + lr);
        ThinHalf {
            v,
            lt,
            lr,
            reflect: lt.z().gt(V::R::splat(0.0)),
            wh,
            found,
            refl_ok: compatible(wh, v, lt, v.z(), true),
            refr_ok: compatible(wh, v, lt, v.z(), false),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::plastic::tests::{
        assert_lane_f_pdf, assert_lane_sample, direction, LaneInputs,
    };
    use pathlab_mc::rng::Pcg32;

    /// A principled material of random parameters, each optional one given or not by `bits`,
    /// solid or thin.
    fn random_material(rng: &mut Pcg32, bits: u32, thin: bool) -> Principled {
        let mut u = || rng.uniform_f32();
        let flags = PrincipledFlags {
            anisotropic: bits & 1 != 0,
            spec_trans: bits & 2 != 0,
            metallic: bits & 4 != 0,
            clearcoat: bits & 8 != 0,
            sheen: bits & 16 != 0,
            sheen_tint: bits & 32 != 0,
            spec_tint: bits & 64 != 0,
            flatness: bits & 128 != 0,
            diff_trans: bits & 256 != 0,
        };
        // A parameter not given is zero, as the material reads it.
        let given = |on: bool, x: f32| if on { x } else { 0.0 };
        Principled {
            base_color: Vec3::new(u(), u(), u()),
            roughness: u(),
            anisotropic: given(flags.anisotropic, u()),
            spec_trans: given(flags.spec_trans, u()),
            metallic: given(flags.metallic, u()),
            clearcoat: given(flags.clearcoat, u()),
            clearcoat_gloss: u(),
            sheen: given(flags.sheen, u()),
            sheen_tint: given(flags.sheen_tint, u()),
            spec_tint: given(flags.spec_tint, u()),
            flatness: given(flags.flatness, u()),
            diff_trans: given(flags.diff_trans, 2.0 * u()),
            eta: 1.001 + u(),
            flags,
            thin,
        }
    }

    /// Eight lanes of principled materials compute, lane by lane, what one material computes,
    /// to the bit: f, pdf, the sample and the relative index it crossed, for solids and thin
    /// sheets mixed in the lanes, every optional lobe on or off, directions on both sides, on
    /// the horizon and mirrored.
    #[test]
    fn lanes_compute_what_one_principled_material_computes() {
        let mut rng = Pcg32::new(11, 13);
        let (mut seen, mut sampled, mut refracted) = (0, 0, 0);
        for round in 0..600 {
            let case = LaneInputs::draw(&mut rng, |rng, i| {
                let bits = rng.next_u32() & 511;
                let thin = match round % 3 {
                    0 => false,
                    1 => true,
                    _ => i % 2 == 0,
                };
                let p = random_material(rng, bits, thin);
                let o = direction(rng);
                let w = match (round + i) % 5 {
                    0 => Vec3::new(o.x, o.y, 0.0),
                    1 => Vec3::new(-o.x, -o.y, o.z),
                    _ => direction(rng),
                };
                (p, o, w)
            });
            let mut lanes = PrincipledLobes::<V8, F8, M8, MicrofacetLanes>::default();
            for (i, p) in case.one.iter().enumerate() {
                lanes.set_lane(i, p.lobes());
            }
            let (f, pdf) = lanes.f_and_pdf(case.wo, case.wi);
            let s = lanes.sample_real(case.wo, case.uc, case.u[0], case.u[1]);
            let eta = lanes.relative_ior(case.wo, s.wi);
            for (i, p) in case.one.iter().enumerate() {
                let (o, w, uc, u) = case.lane(i);
                let what = format!("{p:?} {o} {w}");
                assert_lane_f_pdf(f, pdf, i, (p.f(o, w), p.pdf(o, w)), &what);
                if let Some(scalar) = assert_lane_sample(&s, i, p.sample(o, uc, u), &what) {
                    let bxdf = super::super::Bxdf::Principled(*p);
                    let expected = bxdf.relative_ior(o, scalar.wi);
                    assert_eq!(eta.0[i].to_bits(), expected.to_bits(), "η', lane {i}");
                    sampled += 1;
                    refracted += usize::from(expected != 1.0);
                }
                seen += 1;
            }
        }
        // A guard that samples, refracted ones among them, are compared.
        assert!(
            sampled * 2 > seen && refracted * 50 > seen,
            "{sampled} samples ({refracted} refracted) of {seen}"
        );
    }
}
