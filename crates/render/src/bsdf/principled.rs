//! Disney's principled BSDF as Mitsuba 3 defines it (`principled`: a solid object, and
//! `principledthin`: a thin sheet), with Mitsuba's lobes, weights and approximations, so that
//! scenes written for it render the same.
//!
//! Directions follow pathlab's convention: `wo` towards the viewer, `wi` towards the light,
//! both in the local frame. Mitsuba's formulas give f · |cos θi|; these return f.

use super::fresnel::fresnel_dielectric;
use super::microfacet::{Microfacet, NormalDistribution};
use super::scattering::{reflect, refract_about};
use super::LocalSample;
use crate::color::mitsuba_luminance as luminance;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
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

/// (1 - c)⁵ clamped: Schlick's weight.
#[inline]
fn schlick_weight(c: f32) -> f32 {
    let m = (1.0 - c).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// ((η - 1) / (η + 1))².
#[inline]
fn schlick_r0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Schlick's Fresnel with normal-incidence reflectance `r0` (the transmitted angle's cosine
/// inside the denser medium), Mitsuba's `calc_schlick`.
fn calc_schlick(r0: Rgb, cos_i: f32, eta: f32) -> Rgb {
    let eta_it = if cos_i >= 0.0 { eta } else { 1.0 / eta };
    let eta_ti = 1.0 / eta_it;
    let cos_t2 = 1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti;
    let cos_t = cos_t2.max(0.0).sqrt();
    let w = if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        schlick_weight(cos_t)
    };
    r0 + (Rgb::ONE - r0) * w
}

/// The base colour normalised by its luminance (white for black).
#[inline]
fn tint(base: Rgb) -> Rgb {
    let lum = luminance(base);
    if lum > 0.0 {
        base / lum
    } else {
        Rgb::ONE
    }
}

/// Whether a facet `m` faces `v` and `w` from the sides macro surface reflection (or
/// transmission) needs, for light arriving from the side of `cos`'s sign.
#[inline]
fn compatible(m: Vec3, v: Vec3, w: Vec3, cos: f32, reflection: bool) -> bool {
    let m = if cos < 0.0 { -m } else { m };
    v.dot(m) > 0.0
        && if reflection {
            w.dot(m) > 0.0
        } else {
            w.dot(-m) > 0.0
        }
}

/// Smith's GGX masking for the clear coat (isotropic, separable).
fn smith_ggx1(v: Vec3, wh: Vec3, alpha: f32) -> f32 {
    if v.dot(wh) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let cos2 = v.z * v.z;
    let tan2 = (1.0 - cos2) / cos2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// The GTR1 distribution of the clear coat.
#[derive(Clone, Copy)]
struct Gtr1 {
    alpha: f32,
}

impl Gtr1 {
    fn eval(&self, m: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let r = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z));
        if r * m.z > 1e-20 {
            r
        } else {
            0.0
        }
    }
    fn pdf(&self, m: Vec3) -> f32 {
        if m.z < 0.0 {
            0.0
        } else {
            m.z * self.eval(m)
        }
    }
    fn sample(&self, u: Vec2) -> Vec3 {
        let (sin_phi, cos_phi) = (TAU * u.x).sin_cos();
        let a2 = self.alpha * self.alpha;
        let cos2 = (1.0 - a2.powf(1.0 - u.y)) / (1.0 - a2);
        let sin = (1.0 - cos2).max(0.0).sqrt();
        let cos = cos2.max(0.0).sqrt();
        Vec3::new(cos_phi * sin, sin_phi * sin, cos)
    }
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

impl Principled {
    fn specular(&self) -> Microfacet {
        dist(self.roughness, self.anisotropic, self.flags.anisotropic)
    }

    fn clearcoat_distribution(&self) -> Gtr1 {
        Gtr1 {
            alpha: 0.1 + self.clearcoat_gloss * (0.001 - 0.1),
        }
    }

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z == 0.0 || wi.z == 0.0 {
            return Rgb::ZERO;
        }
        let value = if self.thin {
            self.thin_value(wo, wi)
        } else {
            self.solid_value(wo, wi)
        };
        value / wi.z.abs()
    }

    /// Mitsuba's `principled` eval: f · |cos θi|.
    fn solid_value(&self, v: Vec3, l: Vec3) -> Rgb {
        let (cos_i, cos_o) = (v.z, l.z);
        let brdf = (1.0 - self.metallic) * (1.0 - self.spec_trans);
        let bsdf = (1.0 - self.metallic) * self.spec_trans;
        let reflect = cos_i * cos_o > 0.0;
        let refract = cos_i * cos_o < 0.0;
        let front = cos_i > 0.0;
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let inv_eta_path = 1.0 / eta_path;
        let spec = self.specular();
        let Some(mut wh) = (v + l * if reflect { 1.0 } else { eta_path }).try_normalize() else {
            return Rgb::ZERO;
        };
        if wh.z < 0.0 {
            wh = -wh;
        }
        let f_diel = fresnel_dielectric(v.dot(wh), self.eta);
        let refl_ok = compatible(wh, v, l, cos_i, true);
        let refr_ok = compatible(wh, v, l, cos_i, false);
        let d = spec.d(wh);
        let g = spec.g1(v, wh) * spec.g1(l, wh);
        let mut value = Rgb::ZERO;
        if reflect && refl_ok && f_diel > 0.0 {
            let spec_tint = if self.flags.spec_tint {
                self.spec_tint
            } else {
                0.0
            };
            let cos_h = v.dot(wh);
            let eta_it = if cos_h >= 0.0 {
                self.eta
            } else {
                1.0 / self.eta
            };
            let mut schlick = Rgb::ZERO;
            if self.flags.metallic {
                schlick += self.metallic * calc_schlick(self.base_color, cos_h, self.eta);
            }
            if self.flags.spec_tint {
                let f0 = tint(self.base_color) * schlick_r0(eta_it);
                schlick += (1.0 - self.metallic) * spec_tint * calc_schlick(f0, cos_h, self.eta);
            }
            let fresnel = if front {
                Rgb::splat((1.0 - self.metallic) * (1.0 - spec_tint) * f_diel) + schlick
            } else {
                Rgb::splat(bsdf * f_diel)
            };
            value += fresnel * (d * g / (4.0 * cos_i.abs()));
        }
        if self.flags.spec_trans && bsdf > 0.0 && refract && refr_ok && f_diel < 1.0 {
            let scale = inv_eta_path * inv_eta_path;
            let (vh, lh) = (v.dot(wh), l.dot(wh));
            let denom = vh + eta_path * lh;
            let t = (scale * (1.0 - f_diel) * d * g * eta_path * eta_path * vh * lh
                / (cos_i * denom * denom))
                .abs();
            value += self.base_color.max(Rgb::ZERO).powf(0.5) * (bsdf * t);
        }
        if self.flags.clearcoat && self.clearcoat > 0.0 && reflect && refl_ok && front {
            let fcc = calc_schlick(Rgb::splat(0.04), v.dot(wh), self.eta).x;
            let dcc = self.clearcoat_distribution().eval(wh);
            let gcc = smith_ggx1(v, wh, 0.25) * smith_ggx1(l, wh, 0.25);
            value += Rgb::splat(self.clearcoat * 0.25 * fcc * dcc * gcc * cos_o.abs());
        }
        if brdf > 0.0 && reflect && front {
            value += self.diffuse_value(v, l, wh, brdf, 1.0);
            if self.flags.sheen && self.sheen > 0.0 && 1.0 - self.metallic > 0.0 {
                value += self.sheen_value(l, wh, 1.0 - self.metallic);
            }
        }
        value
    }

    /// The diffuse, retro-reflection and fake-subsurface part, scaled by `weight` and by
    /// `keep` (the thin sheet's share not transmitted diffusely).
    fn diffuse_value(&self, v: Vec3, l: Vec3, wh: Vec3, weight: f32, keep: f32) -> Rgb {
        let (ci, co) = (v.z.abs(), l.z.abs());
        let (fo, fi) = (schlick_weight(co), schlick_weight(ci));
        let f_diff = (1.0 - 0.5 * fi) * (1.0 - 0.5 * fo);
        let cos_d = wh.dot(l);
        let rr = 2.0 * self.roughness * cos_d * cos_d;
        let f_retro = rr * (fo + fi + fo * fi * (rr - 1.0));
        let lobe = if self.flags.flatness {
            let fss90 = rr / 2.0;
            let fss = (1.0 + fo * (fss90 - 1.0)) * (1.0 + fi * (fss90 - 1.0));
            let f_ss = 1.25 * (fss * (1.0 / (co + ci) - 0.5) + 0.5);
            let a = f_diff + f_retro;
            a + self.flatness * (f_ss - a)
        } else {
            f_diff + f_retro
        };
        self.base_color * (weight * co * FRAC_1_PI * keep * lobe)
    }

    /// The sheen, scaled by `weight`.
    fn sheen_value(&self, l: Vec3, wh: Vec3, weight: f32) -> Rgb {
        let fd = schlick_weight(wh.dot(l).abs());
        let c = if self.flags.sheen_tint {
            Rgb::ONE + self.sheen_tint * (tint(self.base_color) - Rgb::ONE)
        } else {
            Rgb::ONE
        };
        c * (self.sheen * weight * fd * l.z.abs())
    }

    /// The thin sheet's scaled roughness for transmission (Burley 2015).
    fn thin_transmission(&self) -> Microfacet {
        dist(
            (0.65 * self.eta - 0.35) * self.roughness,
            self.anisotropic,
            self.flags.anisotropic,
        )
    }

    /// Mitsuba's `principledthin` eval: f · |cos θi|.
    fn thin_value(&self, v: Vec3, l: Vec3) -> Rgb {
        let spec_trans = if self.flags.spec_trans {
            self.spec_trans
        } else {
            0.0
        };
        let diff_trans = if self.flags.diff_trans {
            self.diff_trans / 2.0
        } else {
            0.0
        };
        let sign = v.z.signum();
        let (v, lt) = (v * sign, l * sign);
        let cos_i = v.z;
        let cos_o = lt.z;
        let reflect = cos_o > 0.0;
        let refract = cos_o < 0.0;
        let lr = Vec3::new(lt.x, lt.y, lt.z.abs());
        let Some(wh) = (v + lr).try_normalize() else {
            return Rgb::ZERO;
        };
        let mut value = Rgb::ZERO;
        if self.flags.spec_trans {
            let f_diel = fresnel_dielectric(v.dot(wh), self.eta);
            if spec_trans > 0.0 && reflect && compatible(wh, v, lt, v.z, true) {
                let spec = self.specular();
                // Mitsuba's thin_fresnel: the dielectric term blended towards a tinted
                // Schlick term (zero without spec_tint) by spec_tint.
                let (spec_tint, schlick) = if self.flags.spec_tint {
                    let f0 = tint(self.base_color) * schlick_r0(self.eta);
                    (self.spec_tint, calc_schlick(f0, v.dot(wh), self.eta))
                } else {
                    (0.0, Rgb::ZERO)
                };
                let f = Rgb::splat(f_diel) + spec_tint * (schlick - Rgb::splat(f_diel));
                let d = spec.d(wh);
                let g = spec.g1(v, wh) * spec.g1(lt, wh);
                value += f * (spec_trans * d * g / (4.0 * cos_i));
            }
            if refract && spec_trans > 0.0 && compatible(wh, v, lt, v.z, false) {
                let spec = self.thin_transmission();
                let d = spec.d(wh);
                let g = spec.g1(v, wh) * spec.g1(lt, wh);
                value += self.base_color * (spec_trans * (1.0 - f_diel) * d * g / (4.0 * cos_i));
            }
        }
        if reflect && spec_trans < 1.0 && diff_trans < 1.0 {
            value += self.diffuse_value(v, lt, wh, 1.0 - spec_trans, 1.0 - diff_trans);
            if self.flags.sheen && self.sheen > 0.0 {
                value += self.sheen_value(lt, wh, (1.0 - spec_trans) * (1.0 - diff_trans));
            }
        }
        if self.flags.diff_trans && refract && spec_trans < 1.0 && diff_trans > 0.0 {
            value += self.base_color * ((1.0 - spec_trans) * diff_trans * FRAC_1_PI * cos_o.abs());
        }
        value
    }

    /// The probabilities of Mitsuba's lobes for a solid (diffuse, clear coat, transmission,
    /// reflection) seen from `wo`, given the dielectric Fresnel term `f` of the sampled (or
    /// half-vector) facet.
    fn solid_probabilities(&self, front: bool, f: f32) -> [f32; 4] {
        let brdf = (1.0 - self.metallic) * (1.0 - self.spec_trans);
        let bsdf = if self.flags.spec_trans {
            (1.0 - self.metallic) * self.spec_trans
        } else {
            0.0
        };
        let reflect = if front { 1.0 - bsdf * (1.0 - f) } else { f };
        let trans = if self.flags.spec_trans {
            if front {
                bsdf * (1.0 - f)
            } else {
                1.0 - f
            }
        } else {
            0.0
        };
        let coat = if self.flags.clearcoat && front {
            0.25 * self.clearcoat
        } else {
            0.0
        };
        let diffuse = if front { brdf } else { 0.0 };
        let total = reflect + trans + coat + diffuse;
        if total > 0.0 {
            [
                diffuse / total,
                coat / total,
                trans / total,
                reflect / total,
            ]
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    }

    /// The thin sheet's lobe probabilities: specular reflection, specular transmission,
    /// diffuse reflection, diffuse transmission.
    fn thin_probabilities(&self) -> [f32; 4] {
        let st = if self.flags.spec_trans {
            self.spec_trans
        } else {
            0.0
        };
        let dt = if self.flags.diff_trans {
            self.diff_trans / 2.0
        } else {
            0.0
        };
        let p = [
            st / 2.0,
            st / 2.0,
            (1.0 - st) * (1.0 - dt),
            if self.flags.diff_trans {
                (1.0 - st) * dt
            } else {
                0.0
            },
        ];
        let total: f32 = p.iter().sum();
        if total > 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0, 0.0, 1.0, 0.0]
        }
    }

    /// A sample of wi from `wo`: a lobe chosen as Mitsuba weighs them, then its direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wi = if self.thin {
            self.sample_thin(wo, uc, u)?
        } else {
            self.sample_solid(wo, uc, u)?
        };
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        LocalSample::evaluated(wi, self.pdf(wo, wi), || self.f(wo, wi))
    }

    /// Whether a solid scatters light seen from the front (`front`) or from inside: from
    /// inside only when it transmits.
    fn seen_from(&self, front: bool) -> bool {
        front || (self.flags.spec_trans && (1.0 - self.metallic) * self.spec_trans > 0.0)
    }

    fn sample_solid(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<Vec3> {
        let front = wo.z > 0.0;
        if !self.seen_from(front) {
            return None;
        }
        let spec = self.specular();
        // As Mitsuba samples it: the facet first (its Fresnel term weighs the lobes), then the
        // chosen lobe's direction from the same two numbers.
        let up = if front { wo } else { -wo };
        let m = spec.sample_wm(up, u);
        let f = fresnel_dielectric(wo.dot(m), self.eta);
        let [p_diff, p_coat, p_trans, _] = self.solid_probabilities(front, f);
        if uc < p_diff {
            let w = sample_cosine_hemisphere(u);
            return Some(if front { w } else { -w });
        }
        // A lobe's direction on the side (or facet) the lobe does not serve has no density
        // in `pdf`: it is a failed sample, not one for the other lobes.
        if uc < p_diff + p_coat {
            let m = self.clearcoat_distribution().sample(u);
            let wi = reflect(wo, m);
            return (wi.z > 0.0 && wo.dot(m) > 0.0).then_some(wi);
        }
        if uc < p_diff + p_coat + p_trans {
            let (wi, _) = refract_about(wo, m, self.eta)?;
            return (wi.z * wo.z < 0.0).then_some(wi);
        }
        let wi = reflect(wo, m);
        (wi.z * wo.z > 0.0).then_some(wi)
    }

    fn sample_thin(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<Vec3> {
        let sign = wo.z.signum();
        let v = wo * sign;
        let [p_sr, p_st, p_dr, _] = self.thin_probabilities();
        // A specular direction below the sheet (before the transmission's mirroring), or one
        // whose facet `f` and `pdf` refuse, is a failed sample: `pdf` gives it no density.
        let w = if uc < p_sr {
            let r = reflect(v, self.specular().sample_wm(v, u));
            (r.z > 0.0).then_some(r)?
        } else if uc < p_sr + p_st {
            let m = self.thin_transmission().sample_wm(v, u);
            let r = reflect(v, m);
            let t = Vec3::new(r.x, r.y, -r.z);
            (r.z > 0.0 && compatible(m, v, t, v.z, false)).then_some(t)?
        } else if uc < p_sr + p_st + p_dr {
            sample_cosine_hemisphere(u)
        } else {
            -sample_cosine_hemisphere(u)
        };
        Some(w * sign)
    }

    /// Density of [`Principled::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        if self.thin {
            self.pdf_thin(wo, wi)
        } else {
            self.pdf_solid(wo, wi)
        }
    }

    fn pdf_solid(&self, v: Vec3, l: Vec3) -> f32 {
        let front = v.z > 0.0;
        if !self.seen_from(front) {
            return 0.0;
        }
        let reflect = v.z * l.z > 0.0;
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let Some(mut wh) = (v + l * if reflect { 1.0 } else { eta_path }).try_normalize() else {
            return 0.0;
        };
        if wh.z < 0.0 {
            wh = -wh;
        }
        let f = fresnel_dielectric(v.dot(wh), self.eta);
        let [p_diff, p_coat, p_trans, p_refl] = self.solid_probabilities(front, f);
        let up = if front { v } else { -v };
        let spec = self.specular();
        let mut pdf = 0.0;
        if reflect {
            let jacobian = 1.0 / (4.0 * l.dot(wh)).abs();
            if compatible(wh, v, l, v.z, true) {
                pdf += p_refl * spec.pdf_wm(up, wh) * jacobian;
                if self.flags.clearcoat {
                    pdf += p_coat * self.clearcoat_distribution().pdf(wh) * jacobian;
                }
            }
            pdf += p_diff * cosine_hemisphere_pdf(l.z.abs());
        } else if self.flags.spec_trans && compatible(wh, v, l, v.z, false) {
            let (vh, lh) = (v.dot(wh), l.dot(wh));
            let denom = vh + eta_path * lh;
            let jacobian = (eta_path * eta_path * lh / (denom * denom)).abs();
            pdf += p_trans * spec.pdf_wm(up, wh) * jacobian;
        }
        pdf
    }

    fn pdf_thin(&self, wo: Vec3, wi: Vec3) -> f32 {
        let sign = wo.z.signum();
        let (v, lt) = (wo * sign, wi * sign);
        let [p_sr, p_st, p_dr, p_dt] = self.thin_probabilities();
        let reflect = lt.z > 0.0;
        let lr = Vec3::new(lt.x, lt.y, lt.z.abs());
        let mut pdf = 0.0;
        if let Some(wh) = (v + lr).try_normalize() {
            let jacobian = 1.0 / (4.0 * lr.dot(wh)).abs();
            if reflect && compatible(wh, v, lt, v.z, true) {
                pdf += p_sr * self.specular().pdf_wm(v, wh) * jacobian;
            }
            if !reflect && compatible(wh, v, lt, v.z, false) {
                pdf += p_st * self.thin_transmission().pdf_wm(v, wh) * jacobian;
            }
        }
        if reflect {
            pdf += p_dr * cosine_hemisphere_pdf(lt.z);
        } else {
            pdf += p_dt * cosine_hemisphere_pdf(-lt.z);
        }
        pdf
    }
}
