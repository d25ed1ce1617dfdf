//! Conductors: smooth (a delta lobe) or rough (a microfacet model), with the Fresnel
//! reflectance of a complex index of refraction.

use super::bxdf::DirectionSample;
use super::fresnel::ConductorFresnel;
use super::microfacet::{Distribution, Microfacet, MicrofacetLanes};
use super::mirror::specular_reflection_real;
use super::scattering::reflect;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, V8};

/// A conductor with complex index η + i k per channel. Smooth without a distribution;
/// otherwise f = D(wm) G(wo, wi, wm) F(wo·wm) / (4 cos θo cos θi) with wm the half vector
/// (Cook–Torrance / Walter et al. 2007), sampled through the distribution of normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the index, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption), per channel.
    pub k: Rgb,
    /// Scale of the reflection (Mitsuba's `specular_reflectance`; one for a plain metal).
    pub specular: Rgb,
    /// The microfacet distribution (`None`: a smooth surface).
    pub distribution: Option<Microfacet>,
}

impl Conductor {
    /// The smooth lobe (`None` when rough): the model the path tracer's lanes shade together
    /// with the same function.
    #[inline]
    pub fn as_smooth(&self) -> Option<SmoothConductor<Rgb>> {
        self.distribution.is_none().then_some(SmoothConductor {
            eta: self.eta,
            k: self.k,
            specular: self.specular,
        })
    }

    /// The rough lobe (`None` when smooth): the model the path tracer's lanes shade together,
    /// with the same functions.
    #[inline]
    pub fn rough(&self) -> Option<RoughConductor<Rgb, Microfacet>> {
        self.distribution.map(|distribution| RoughConductor {
            eta: self.eta,
            k: self.k,
            specular: self.specular,
            distribution,
        })
    }

    /// f(wo, wi) (zero for a smooth conductor: a delta lobe).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.rough().map_or(Rgb::ZERO, |r| r.f(wo, wi))
    }

    /// A sample: the mirror direction when smooth, otherwise the reflection of `wo` about a
    /// sampled microfacet normal.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<LocalSample> {
        if let Some(smooth) = self.as_smooth() {
            return smooth.sample(wo).delta();
        }
        self.rough()?.sample(wo, u.x, u.y).local()
    }

    /// Density of [`Conductor::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.rough().map_or(0.0, |r| r.pdf(wo, wi))
    }
}

/// A smooth conductor's lobe, written once for one direction (`V = Rgb`) and for eight lanes
/// (`V = V8`): the mirror direction, weighted by the Fresnel reflectance at |cos θo| (a delta
/// lobe).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SmoothConductor<V> {
    /// Real part of the index, per channel.
    pub eta: V,
    /// Imaginary part, per channel.
    pub k: V,
    /// Scale of the reflection.
    pub specular: V,
}

impl<V: ConductorFresnel> SmoothConductor<V> {
    /// The mirror direction of `wo` (where `wo` is off the surface).
    #[inline(always)]
    pub fn sample(&self, wo: V) -> DirectionSample<V> {
        let fresnel = V::fresnel_conductor(wo.z().abs(), self.eta, self.k);
        specular_reflection_real(wo, self.specular.mul_axes(fresnel), V::R::splat(1.0))
    }
}

impl SmoothConductor<V8> {
    /// Sets lane `i` to `c`. Every field is taken apart here: a field added to
    /// [`SmoothConductor`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, c: SmoothConductor<Rgb>) {
        let SmoothConductor { eta, k, specular } = c;
        self.eta.set(i, eta);
        self.k.set(i, k);
        self.specular.set(i, specular);
    }
}

/// A rough conductor's lobe, written once for one direction (`V = Rgb`, with `Microfacet`
/// or [`super::IsotropicMicrofacet`]) and for eight lanes (`V = V8`, with
/// [`MicrofacetLanes`]): f = D(wm) G(wo, wi, wm) F(wo·wm) / (4 cos θo cos θi) with wm
/// the half vector, sampled by reflecting `wo` about a normal from the distribution, of
/// density pdf(wm) / (4 wo·wm).
///
/// [`V8`]: crate::simd::lanes::V8
/// [`F8`]: crate::simd::lanes::F8
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoughConductor<V, M> {
    /// Real part of the index, per channel.
    pub eta: V,
    /// Imaginary part, per channel.
    pub k: V,
    /// Scale of the reflection.
    pub specular: V,
    /// The microfacet distribution.
    pub distribution: M,
}

impl<V: ConductorFresnel, M: Distribution<V::R>> RoughConductor<V, M> {
    /// f(wo, wi) and its density as a sample from `wo`, from one half vector (zero where
    /// either direction is below the surface or they are opposite).
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V) -> (V, V::R) {
        let (zero, four) = (V::R::splat(0.0), V::R::splat(4.0));
        let sum = wo + wi;
        let wm = sum.normalize();
        let m = &self.distribution;
        let dg = m.d(wm) * m.g(wo, wi, wm);
        let cos_om = wo.dot(wm);
        let fresnel = self
            .specular
            .mul_axes(V::fresnel_conductor(cos_om, self.eta, self.k));
        let f = fresnel.scale(dg / (four * wo.z() * wi.z()));
        let pdf = m.pdf_wm(wo, wm) / (four * cos_om);
        // Either below or the two opposite: nothing (`z <= 0` is false for NaN, as in the
        // one-direction code's early returns before it was written over `Real`).
        let none = wo.z().le(zero) | wi.z().le(zero) | sum.dot(sum).equals(zero);
        (
            V::select(none, V::splat(Vec3::ZERO), f),
            V::R::select(none | cos_om.le(zero), zero, pdf),
        )
    }

    /// f(wo, wi).
    #[inline(always)]
    pub fn f(&self, wo: V, wi: V) -> V {
        self.f_and_pdf(wo, wi).0
    }

    /// Density of [`RoughConductor::sample`] choosing `wi`.
    #[inline(always)]
    pub fn pdf(&self, wo: V, wi: V) -> V::R {
        self.f_and_pdf(wo, wi).1
    }

    /// The reflection of `wo` about a normal drawn from (`u0`, `u1`): it exists where `wo`
    /// and it are above the surface and its density is positive.
    #[inline(always)]
    pub fn sample(&self, wo: V, u0: V::R, u1: V::R) -> DirectionSample<V> {
        let zero = V::R::splat(0.0);
        let wm = self.distribution.sample_wm(wo, u0, u1);
        let wi = reflect(wo, wm);
        let (f, pdf) = self.f_and_pdf(wo, wi);
        DirectionSample {
            wi,
            pdf,
            f,
            valid: !wo.z().le(zero) & !wi.z().le(zero) & pdf.gt(zero),
        }
    }
}

impl RoughConductor<V8, MicrofacetLanes> {
    /// Sets lane `i` to `c`. Every field is taken apart here: a field added to
    /// [`RoughConductor`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, c: RoughConductor<Rgb, Microfacet>) {
        let RoughConductor {
            eta,
            k,
            specular,
            distribution,
        } = c;
        self.eta.set(i, eta);
        self.k.set(i, k);
        self.specular.set(i, specular);
        self.distribution.set_lane(i, distribution);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::bsdf::{Mirror, NormalDistribution};
    use pathlab_mc::rng::Pcg32;
    use pathlab_mc::simd::lanes::F8;

    /// Round `round`'s distribution in lane `i`: all lanes GGX, all Beckmann, or the two
    /// mixed.
    pub(crate) fn lane_kind(round: usize, i: usize) -> NormalDistribution {
        match (round % 3, i % 2) {
            (0, _) | (2, 0) => NormalDistribution::Ggx,
            _ => NormalDistribution::Beckmann,
        }
    }

    /// Eight lanes of the rough conductor compute, lane by lane, what the one-direction
    /// [`Conductor`] computes (through [`Microfacet`]), to the bit: f, pdf and the sample,
    /// for directions above, below and on the horizon, opposite pairs and equal ones, with
    /// GGX and Beckmann lanes, of one roughness or anisotropic.
    #[test]
    fn lanes_compute_what_the_one_direction_conductor_computes() {
        let mut rng = Pcg32::new(7, 11);
        let direction = |rng: &mut Pcg32| {
            let z = 2.0 * rng.uniform_f32() - 1.0;
            let phi = std::f32::consts::TAU * rng.uniform_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let (mut valid, mut lanes_seen) = (0, 0);
        for round in 0..400 {
            let mut lanes = RoughConductor::<V8, MicrofacetLanes>::default();
            let (mut wo, mut wi) = (V8::default(), V8::default());
            let (mut u0, mut u1) = (F8::default(), F8::default());
            let mut scalar = Vec::new();
            for i in 0..8 {
                let alpha = [1e-4, 0.01, 0.1, 0.3, 0.7, 1.0, 2.0, 0.05][(round + i) % 8];
                let c = Conductor {
                    eta: Vec3::new(0.2, 0.9, 1.4) + rng.uniform_f32(),
                    k: Vec3::new(3.9, 2.4, 1.6) * rng.uniform_f32(),
                    specular: Vec3::new(1.0, 0.8, rng.uniform_f32()),
                    // Every fourth round, every third lane anisotropic.
                    distribution: Some(if round % 4 == 3 && i % 3 == 0 {
                        Microfacet::anisotropic(lane_kind(round, i), alpha, 0.4 * alpha + 0.05)
                    } else {
                        Microfacet::new(lane_kind(round, i), alpha)
                    }),
                };
                lanes.set_lane(i, c.rough().expect("rough"));
                let (o, mut w) = (direction(&mut rng), direction(&mut rng));
                match round % 5 {
                    0 => w = -o,
                    1 => w = o,
                    2 => w.z = 0.0,
                    _ => {}
                }
                wo.set(i, o);
                wi.set(i, w);
                (u0.0[i], u1.0[i]) = (rng.uniform_f32(), rng.uniform_f32());
                scalar.push(c);
            }
            let (f, pdf) = lanes.f_and_pdf(wo, wi);
            let s = lanes.sample(wo, u0, u1);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, c) in scalar.iter().enumerate() {
                let (o, w) = (wo.get(i), wi.get(i));
                assert_eq!(bits(f.get(i)), bits(c.f(o, w)), "f, lane {i}: {o} {w}");
                assert_eq!(pdf.0[i].to_bits(), c.pdf(o, w).to_bits(), "pdf, lane {i}");
                let one = c.sample(o, Vec2::new(u0.0[i], u1.0[i]));
                assert_eq!(s.valid.get(i), one.is_some(), "sample, lane {i}: {o}");
                if let Some(one) = one {
                    assert_eq!(bits(s.wi.get(i)), bits(one.wi));
                    assert_eq!(bits(s.f.get(i)), bits(one.f));
                    assert_eq!(s.pdf.0[i].to_bits(), one.pdf.to_bits());
                    valid += 1;
                }
                lanes_seen += 1;
            }
        }
        // A guard that most samples are compared, not only the empty ones.
        assert!(
            valid * 3 > lanes_seen,
            "{valid} of {lanes_seen} samples valid"
        );
    }

    /// Eight lanes of the smooth conductor and of the mirror sample, lane by lane, what the
    /// one-direction models sample, to the bit (from both sides and on the surface).
    #[test]
    fn smooth_lanes_sample_what_one_direction_samples() {
        let mut rng = Pcg32::new(9, 2);
        for round in 0..200 {
            let mut metal = SmoothConductor::<V8>::default();
            let mut mirror = Mirror::<V8>::default();
            let mut wo = V8::default();
            let mut one = Vec::new();
            for i in 0..8 {
                let c = Conductor {
                    eta: Vec3::new(0.2, 0.9, 1.4) * rng.uniform_f32(),
                    k: Vec3::new(3.9, 2.4, 1.6) + rng.uniform_f32(),
                    specular: Vec3::new(1.0, 0.8, rng.uniform_f32()),
                    distribution: None,
                };
                let m = Mirror {
                    reflectance: Vec3::new(rng.uniform_f32(), 0.5, 1.0),
                };
                metal.set_lane(i, c.as_smooth().expect("smooth"));
                mirror.set_lane(i, m);
                let z = if round % 5 == 0 {
                    0.0
                } else {
                    2.0 * rng.uniform_f32() - 1.0
                };
                let r = (1.0 - z * z).max(0.0).sqrt();
                wo.set(i, Vec3::new(r * 0.6, r * 0.8, z));
                one.push((c, m));
            }
            let (s_metal, s_mirror) = (metal.sample(wo), mirror.sample_real(wo));
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, (c, m)) in one.iter().enumerate() {
                let o = wo.get(i);
                for (s, scalar) in [(s_metal, c.sample(o, Vec2::ZERO)), (s_mirror, m.sample(o))] {
                    assert_eq!(s.valid.get(i), scalar.is_some(), "lane {i}: {o}");
                    if let Some(scalar) = scalar {
                        assert!(scalar.delta);
                        assert_eq!(bits(s.wi.get(i)), bits(scalar.wi));
                        assert_eq!(bits(s.f.get(i)), bits(scalar.f));
                        assert_eq!(s.pdf.0[i].to_bits(), scalar.pdf.to_bits());
                    }
                }
            }
        }
    }
}
