//! The BSDF at a surface point: a weighted mixture of lobes, each a [`Bxdf`] in its own
//! shading frame, plus a pass-through weight; sampled by choosing a lobe, evaluated as the
//! weighted sum.

use super::*;
use crate::desc::Rgb;
use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3};

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// BSDF value f(wo, wi) (for a delta lobe, the value whose product with `cos` over `pdf`
    /// is the lobe's weight).
    pub f: Rgb,
    /// The sampled direction, in world space.
    pub wi: Vec3,
    /// Its density per unit solid angle, or for a delta lobe the probability of choosing it.
    pub pdf: f32,
    /// Whether the direction comes from a delta lobe (mirror reflection, refraction, passing
    /// through): no other strategy could have produced it, so MIS gives it weight one.
    pub delta: bool,
    /// The foreshortening |cos θi| that goes with `f`: the throughput of the sample is
    /// f · cos / pdf. (The cosine to the lobe's own shading normal, which a normal map may
    /// have moved away from the surface's.)
    pub cos: f32,
    /// The relative index of refraction η' the sample crossed ([`Bxdf::relative_ior`]): one
    /// unless it refracts into or out of a medium, its radiance then scaled by 1/η'² in `f`.
    pub eta: f32,
}

/// Most lobes a [`Bsdf`] holds (a mask or blend of blends deeper than this keeps the first).
pub const MAX_LOBES: usize = 4;

/// One lobe of a [`Bsdf`]: a BxDF in its shading frame, with its mixture weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe {
    /// Mixture weight (its share of f, and the probability of sampling it).
    pub weight: f32,
    /// The shading frame.
    pub frame: Frame,
    /// The model.
    pub bxdf: Bxdf,
    /// For a lobe whose normal a normal or bump map moved, what the surface's own shading
    /// normal says about light arriving along wi.
    pub guard: Option<Guard>,
}

/// The rules of a perturbed normal (Mitsuba's `normalmap` and `bumpmap`): light arriving on
/// the other side of the surface's own shading normal than of the lobe's counts nothing, and
/// what arrives is attenuated by the microfacet shadowing term of Estevez et al. 2019 ("A
/// Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem"),
/// 2 / (1 + √(1 + α² tan²θ)), θ measured from the surface's own normal and
/// α² = min(tan²θp / 8, 1) from the perturbed normal's tilt θp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guard {
    /// The surface's own shading normal.
    pub n: Vec3,
    /// α² of the shadowing term (zero: no attenuation).
    pub alpha2: f32,
}

/// Whether a guard of the surface's own shading normal `n` admits light arriving along `wi`
/// at a lobe of normal `lobe_n`: whether `wi` is on the same side of both. For one direction
/// or lanes.
#[inline(always)]
pub fn guard_admits<V: Vector3>(n: V, lobe_n: V, wi: V) -> <V::R as Real>::Mask {
    (wi.dot(n) * wi.dot(lobe_n)).gt(V::R::splat(0.0))
}

/// The factor a guard of the surface's own shading normal `n` and shadowing α² `alpha2`
/// applies to light arriving along `wi` at a lobe of normal `lobe_n`: zero where it does not
/// admit it ([`guard_admits`]), else the shadowing term (one where α² is zero). For one
/// direction or lanes.
#[inline(always)]
pub fn guard_attenuation<V: Vector3>(n: V, alpha2: V::R, lobe_n: V, wi: V) -> V::R {
    let (zero, one, two) = (V::R::splat(0.0), V::R::splat(1.0), V::R::splat(2.0));
    let cos = wi.dot(n);
    let tan2 = (one - cos * cos).max(zero) / (cos * cos);
    let shadowing = V::R::select(
        alpha2.equals(zero),
        one,
        two / (one + (one + alpha2 * tan2).sqrt()),
    );
    V::R::select(guard_admits(n, lobe_n, wi), shadowing, zero)
}

impl Lobe {
    /// Whether `wi` passes the lobe's guard.
    #[inline]
    fn admits(&self, wi: Vec3) -> bool {
        self.guard
            .is_none_or(|g| guard_admits(g.n, self.frame.n, wi))
    }

    /// The factor the guard applies to light arriving along `wi` (one without a guard; zero
    /// where it does not admit it).
    #[inline]
    fn attenuation(&self, wi: Vec3) -> f32 {
        match self.guard {
            None => 1.0,
            Some(g) => guard_attenuation(g.n, g.alpha2, self.frame.n, wi),
        }
    }
}

/// A material at a surface point: a weighted mixture of lobes and a pass-through weight (a
/// mask's transparency: light continues along its direction). The weights and the
/// pass-through sum to one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    first: Lobe,
    rest: [Option<Lobe>; MAX_LOBES - 1],
    /// Weight of passing straight through.
    null: f32,
}

impl Bsdf {
    /// The BSDF of `material` at a point with unit shading normal `n`, seen from direction
    /// `wo` (no texture coordinates: textures read at (0, 0)). A two-sided material is
    /// evaluated on the side `wo` is on; a one-sided one keeps its normal, and reflects
    /// nothing when seen from behind.
    pub fn new(material: &Material, n: Vec3, wo: Vec3) -> Self {
        material.bsdf(&ShadingPoint::at(n), wo)
    }

    /// The BSDF of `bxdf` at a point with unit shading normal `n` seen from `wo`.
    pub fn from_bxdf(bxdf: Bxdf, two_sided: bool, n: Vec3, wo: Vec3) -> Self {
        let n = if two_sided && wo.dot(n) < 0.0 { -n } else { n };
        Bsdf::single(Frame::from_normal(n), bxdf)
    }

    /// One lobe of weight one.
    pub(crate) fn single(frame: Frame, bxdf: Bxdf) -> Self {
        Bsdf {
            first: Lobe {
                weight: 1.0,
                frame,
                bxdf,
                guard: None,
            },
            rest: [None; MAX_LOBES - 1],
            null: 0.0,
        }
    }

    /// A mixture of lobe `first`, the lobes `rest` holds, and pass-through weight `null`.
    pub(crate) fn mixture(first: Lobe, rest: [Option<Lobe>; MAX_LOBES - 1], null: f32) -> Self {
        Bsdf { first, rest, null }
    }

    /// Every lobe.
    #[inline]
    pub fn lobes(&self) -> impl Iterator<Item = &Lobe> {
        std::iter::once(&self.first).chain(self.rest.iter().flatten())
    }

    /// Whether the BSDF is a single lobe of weight one (the common case).
    #[inline]
    fn is_single(&self) -> bool {
        self.rest[0].is_none() && self.null == 0.0
    }

    /// Whether the BSDF reflects and transmits nothing whatever the directions (black
    /// Lambertian lobes only, nothing passing through): radiance leaving such a point is its
    /// emission alone, which no random number can change.
    pub fn is_black(&self) -> bool {
        self.null == 0.0
            && self.lobes().all(|l| match &l.bxdf {
                Bxdf::Diffuse(d) => l.weight == 0.0 || d.reflectance.max_element() <= 0.0,
                _ => l.weight == 0.0,
            })
    }

    /// The weight of passing straight through.
    pub fn pass_through(&self) -> f32 {
        self.null
    }

    /// The first lobe's shading normal (flipped towards `wo` for two-sided materials).
    pub fn normal(&self) -> Vec3 {
        self.first.frame.n
    }

    /// The first lobe's local shading frame.
    pub fn frame(&self) -> &Frame {
        &self.first.frame
    }

    /// The first lobe's reflectance model.
    pub fn bxdf(&self) -> &Bxdf {
        &self.first.bxdf
    }

    /// f(wo, wi), world-space directions (the mixture; without foreshortening, which each
    /// lobe measures against its own normal: see [`Bsdf::f_cos`]).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if self.is_single() && self.first.guard.is_none() {
            let l = &self.first;
            return l.bxdf.f(l.frame.to_local(wo), l.frame.to_local(wi));
        }
        self.lobes()
            .map(|l| {
                l.bxdf.f(l.frame.to_local(wo), l.frame.to_local(wi))
                    * (l.weight * l.attenuation(wi))
            })
            .sum()
    }

    /// f(wo, wi) |cos θi|, each lobe's cosine to its own shading normal: what light arriving
    /// along `wi` contributes towards `wo`.
    #[inline]
    pub fn f_cos(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if self.is_single() && self.first.guard.is_none() {
            let l = &self.first;
            return l.bxdf.f(l.frame.to_local(wo), l.frame.to_local(wi)) * wi.dot(l.frame.n).abs();
        }
        self.lobes()
            .map(|l| {
                l.bxdf.f(l.frame.to_local(wo), l.frame.to_local(wi))
                    * (l.weight * l.attenuation(wi) * wi.dot(l.frame.n).abs())
            })
            .sum()
    }

    /// f(wi, wo) |cos θi|: the adjoint of [`Bsdf::f_cos`], for importance carried from the
    /// lights (pbrt-v4's `TransportMode::Importance`): light that arrived along `wo` leaving
    /// along `wi`, foreshortened on the side it leaves. The radiance BSDF with its directions
    /// exchanged is its adjoint, so that refraction's 1/η² scaling of radiance, which
    /// importance does not undergo, comes out right without a mode in every model.
    pub fn f_cos_importance(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.lobes()
            .map(|l| {
                l.bxdf.f(l.frame.to_local(wi), l.frame.to_local(wo))
                    * (l.weight * l.attenuation(wo) * wi.dot(l.frame.n).abs())
            })
            .sum()
    }

    /// Whether every lobe is a delta distribution (light sampling can never help).
    pub fn is_delta(&self) -> bool {
        self.lobes().all(|l| l.bxdf.is_delta() || l.weight <= 0.0)
    }

    /// Samples wi given wo (world space): `uc` chooses a lobe (or passing through), `u` the
    /// direction in it.
    pub fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if self.is_single() {
            let l = &self.first;
            let wo_local = l.frame.to_local(wo);
            let s = l.bxdf.sample(wo_local, uc, u)?;
            let wi = l.frame.to_world(s.wi);
            if !l.admits(wi) {
                return None;
            }
            let f = match l.guard {
                None => s.f,
                Some(_) => s.f * l.attenuation(wi),
            };
            return (s.pdf > 0.0 && f.is_finite()).then(|| BsdfSample {
                f,
                wi,
                pdf: s.pdf,
                delta: s.delta,
                cos: wi.dot(l.frame.n).abs(),
                eta: l.bxdf.relative_ior(wo_local, s.wi),
            });
        }
        // Choose a lobe by weight, and reuse the rest of `uc` within it.
        let mut acc = 0.0;
        let mut chosen = None;
        for l in self.lobes() {
            if l.weight > 0.0 && uc < acc + l.weight {
                chosen = Some((l, ((uc - acc) / l.weight).clamp(0.0, 1.0 - f32::EPSILON)));
                break;
            }
            acc += l.weight;
        }
        let Some((l, uc)) = chosen else {
            // Straight through: f cos / pdf = null / null = 1.
            if self.null <= 0.0 {
                return None;
            }
            let c = wo.dot(self.first.frame.n).abs().max(1e-6);
            return Some(BsdfSample {
                f: Rgb::splat(self.null / c),
                wi: -wo,
                pdf: self.null,
                delta: true,
                cos: c,
                eta: 1.0,
            });
        };
        let wo_local = l.frame.to_local(wo);
        let s = l.bxdf.sample(wo_local, uc, u)?;
        let wi = l.frame.to_world(s.wi);
        if !l.admits(wi)
            || s.pdf.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            || !s.f.is_finite()
        {
            return None;
        }
        let cos = wi.dot(l.frame.n).abs();
        let eta = l.bxdf.relative_ior(wo_local, s.wi);
        if s.delta {
            return Some(BsdfSample {
                f: s.f * (l.weight * l.attenuation(wi)),
                wi,
                pdf: s.pdf * l.weight,
                delta: true,
                cos,
                eta,
            });
        }
        let pdf = self.pdf(wo, wi);
        if pdf.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || cos <= 0.0 {
            return None;
        }
        if l.bxdf.is_stochastic() {
            // The lobe's f / pdf is an estimate of its own value over its own density, not of
            // f over `pdf`: the sample weighs the chosen lobe alone (chosen with probability
            // its weight, which cancels), and carries the mixture's pdf for MIS.
            let f = s.f * (l.attenuation(wi) * pdf / s.pdf);
            return f.is_finite().then_some(BsdfSample {
                f,
                wi,
                pdf,
                delta: false,
                cos,
                eta,
            });
        }
        let f = self.f_cos(wo, wi) / cos;
        f.is_finite().then_some(BsdfSample {
            f,
            wi,
            pdf,
            delta: false,
            cos,
            eta,
        })
    }

    /// Density of [`Bsdf::sample_f`] choosing `wi` (world space; its non-delta part).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_single() && self.first.guard.is_none() {
            let l = &self.first;
            return l.bxdf.pdf(l.frame.to_local(wo), l.frame.to_local(wi));
        }
        self.lobes()
            .filter(|l| l.admits(wi))
            .map(|l| l.weight * l.bxdf.pdf(l.frame.to_local(wo), l.frame.to_local(wi)))
            .sum()
    }
}
