//! A rough dielectric interface: microfacet reflection and transmission (Walter et al. 2007),
//! written once for one direction and for eight lanes.

use super::bxdf::DirectionSample;
use super::fresnel::fresnel_dielectric_real;
use super::microfacet::{Distribution, Microfacet, MicrofacetLanes};
use super::scattering::{reflect, refract_about_real, relative_eta};
use super::{Lobes, LocalSample};
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, V8};

/// Rough glass. For wo and wi on the same side, f = D G F / (4 |cos θo cos θi|) with the
/// half vector wm ∝ wo + wi; across the interface (relative index η' along the path),
/// wm ∝ wo + η' wi and
/// f = D G (1 - F) |wi·wm| |wo·wm| / (|cos θi cos θo| (wi·wm + wo·wm / η')² η'²),
/// the last η'² being the radiance scaling of refraction. Sampling draws wm, then reflection
/// with probability F(wo·wm) and refraction otherwise.
///
/// `R`, `V` and `M` are the number, colour and distribution types: `f32`, [`Rgb`] and
/// [`Microfacet`] for one direction, or [`F8`], [`V8`] and [`MicrofacetLanes`] for eight
/// lanes (the path tracer's).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoughDielectric<R = f32, V = Rgb, M = Microfacet> {
    /// Index of refraction inside relative to outside.
    pub eta: R,
    /// The microfacet distribution.
    pub distribution: M,
    /// Scale of the reflected part.
    pub reflectance: V,
    /// Scale of the transmitted part.
    pub transmittance: V,
}

/// Per-lane truth values of a vector type's numbers.
type MaskOf<V> = <<V as Vector3>::R as Real>::Mask;

/// The generalised half vector of a pair of directions, on the upper side, with η', whether
/// the pair is a reflection, and where it exists (not for degenerate or back-facing
/// configurations). For one pair or lanes.
#[inline(always)]
fn half_vector<V: Vector3>(wo: V, wi: V, eta: V::R) -> (V, V::R, MaskOf<V>, MaskOf<V>) {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let (cos_o, cos_i) = (wo.z(), wi.z());
    let reflection = (cos_o * cos_i).gt(zero);
    let etap = V::R::select(
        reflection,
        one,
        V::R::select(cos_o.gt(zero), eta, one / eta),
    );
    let sum = wi.scale(etap) + wo;
    let wm = sum.normalize();
    let wm = V::select(wm.z().lt(zero), -wm, wm);
    // Facets seen from behind by either direction contribute nothing.
    let exists = !cos_o.equals(zero)
        & !cos_i.equals(zero)
        & !sum.dot(sum).equals(zero)
        & !(wm.dot(wi) * cos_i).le(zero)
        & !(wm.dot(wo) * cos_o).le(zero);
    (wm, etap, reflection, exists)
}

impl RoughDielectric {
    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_and_pdf(wo, wi, Lobes::All).0
    }

    /// A sampled microfacet normal, then reflection (probability F) or refraction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        self.sample_lobes(wo, uc, u, Lobes::All)
    }

    /// [`RoughDielectric::sample`] restricted to `lobes` (at the sampled facet, the other
    /// lobe's probability given to the one left).
    pub fn sample_lobes(&self, wo: Vec3, uc: f32, u: Vec2, lobes: Lobes) -> Option<LocalSample> {
        self.sample_real(wo, uc, u.x, u.y, lobes).local()
    }

    /// Density of [`RoughDielectric::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.pdf_lobes(wo, wi, Lobes::All)
    }

    /// Density of [`RoughDielectric::sample_lobes`].
    pub fn pdf_lobes(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        self.f_and_pdf(wo, wi, lobes).1
    }
}

impl<V, M> RoughDielectric<V::R, V, M>
where
    V: Vector3,
    M: Distribution<V::R>,
{
    /// f(wo, wi) and the density of [`RoughDielectric::sample_real`] restricted to `lobes`
    /// choosing `wi`, from one half vector (zero where there is none).
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V, lobes: Lobes) -> (V, V::R) {
        let (zero, one, four) = (V::R::splat(0.0), V::R::splat(1.0), V::R::splat(4.0));
        let (wm, etap, reflection, exists) = half_vector(wo, wi, self.eta);
        let m = &self.distribution;
        let (cos_om, cos_im) = (wo.dot(wm), wi.dot(wm));
        let fresnel = fresnel_dielectric_real(cos_om, self.eta);
        let dg = m.d(wm) * m.g(wo, wi, wm);
        // Across: the Jacobian's denominator (wi·wm + wo·wm / η')².
        let across = cos_im + cos_om / etap;
        let across2 = across * across;
        let f_reflect = self
            .reflectance
            .scale(dg * fresnel / (four * (wo.z() * wi.z()).abs()));
        let denom = across2 * wi.z() * wo.z();
        let t = dg * (one - fresnel) * (cos_im * cos_om / denom).abs() / (etap * etap);
        let f = V::select(reflection, f_reflect, self.transmittance.scale(t));
        let (pr, pt, chosen) = lobes.choose_real(fresnel, one - fresnel);
        let pdf_wm = m.pdf_wm(wo, wm);
        let pdf = V::R::select(
            reflection,
            pdf_wm / (four * cos_om.abs()) * pr,
            pdf_wm * (cos_im.abs() / across2) * pt,
        );
        (
            V::select(exists, f, V::splat(Vec3::ZERO)),
            V::R::select(exists & chosen, pdf, zero),
        )
    }

    /// A microfacet normal from (`u0`, `u1`), then reflection where `uc` < the reflection's
    /// probability (restricted to `lobes`), refraction elsewhere. It exists where `wo` is off
    /// the surface and sees the facet, the lobe is left, the refraction is not total internal
    /// reflection, the direction lies on the side its lobe sends it to (a facet can send a
    /// reflection across the macro surface or a refraction back: such paths are not part of
    /// the model) and its density is positive.
    #[inline(always)]
    pub fn sample_real(
        &self,
        wo: V,
        uc: V::R,
        u0: V::R,
        u1: V::R,
        lobes: Lobes,
    ) -> DirectionSample<V> {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let wm = self.distribution.sample_wm(wo, u0, u1);
        let fresnel = fresnel_dielectric_real(wo.dot(wm), self.eta);
        let (pr, _, chosen) = lobes.choose_real(fresnel, one - fresnel);
        let reflects = uc.lt(pr);
        let (wt, _, refracts) = refract_about_real(wo, wm, self.eta);
        let wi = V::select(reflects, reflect(wo, wm), wt);
        let same_side = (wi.z() * wo.z()).gt(zero);
        let (f, pdf) = self.f_and_pdf(wo, wi, lobes);
        DirectionSample {
            wi,
            pdf,
            f,
            valid: !wo.z().equals(zero)
                & !(wo.dot(wm) * wo.z()).le(zero)
                & chosen
                & (reflects | refracts)
                & ((same_side & reflects) | (!same_side & !reflects))
                & !wi.z().equals(zero)
                & pdf.gt(zero),
        }
    }

    /// The relative index η' of a sample from `wo` to `wi`.
    #[inline(always)]
    pub fn relative_ior(&self, wo: V, wi: V) -> V::R {
        relative_eta(wo, wi, self.eta)
    }
}

impl RoughDielectric<F8, V8, MicrofacetLanes> {
    /// Sets lane `i` to `d`. Every field is taken apart here: a field added to
    /// [`RoughDielectric`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, d: RoughDielectric) {
        let RoughDielectric {
            eta,
            distribution,
            reflectance,
            transmittance,
        } = d;
        self.eta.0[i] = eta;
        self.distribution.set_lane(i, distribution);
        self.reflectance.set(i, reflectance);
        self.transmittance.set(i, transmittance);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlab_mc::rng::Pcg32;

    /// Eight lanes of rough glass compute, lane by lane, what the one-direction model computes
    /// (through [`Microfacet`]), to the bit: f, the density and the sample for each choice of
    /// lobes, from both sides, for reflected, refracted and opposite pairs, with distributions
    /// of one roughness and anisotropic ones.
    #[test]
    fn lanes_compute_what_one_direction_computes() {
        let mut rng = Pcg32::new(4, 8);
        let direction = |rng: &mut Pcg32| {
            let z = 2.0 * rng.uniform_f32() - 1.0;
            let phi = std::f32::consts::TAU * rng.uniform_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let mut valid = [0; 3];
        for round in 0..600 {
            let lobes = [Lobes::All, Lobes::Reflection, Lobes::Transmission][round % 3];
            let mut lanes = RoughDielectric::<F8, V8, MicrofacetLanes>::default();
            let (mut wo, mut wi) = (V8::default(), V8::default());
            let (mut uc, mut u0, mut u1) = (F8::default(), F8::default(), F8::default());
            let mut one = Vec::new();
            for i in 0..8 {
                let (kind, alpha) = (
                    crate::bsdf::conductor::tests::lane_kind(round / 3, i),
                    [0.01, 0.1, 0.3, 0.8, 1.5][(round + i) % 5],
                );
                let d = RoughDielectric {
                    eta: [1.5, 1.0 / 1.33, 2.4, 1.0001][(round / 3 + i) % 4],
                    // Every fourth round, every third lane anisotropic.
                    distribution: if round % 4 == 3 && i % 3 == 0 {
                        Microfacet::anisotropic(kind, alpha, 0.3 * alpha + 0.05)
                    } else {
                        Microfacet::new(kind, alpha)
                    },
                    reflectance: Vec3::new(1.0, rng.uniform_f32(), 0.5),
                    transmittance: Vec3::new(rng.uniform_f32(), 1.0, 0.9),
                };
                lanes.set_lane(i, d);
                let (o, mut w) = (direction(&mut rng), direction(&mut rng));
                match round % 7 {
                    0 => w = -o,
                    1 => w = Vec3::new(-o.x, -o.y, o.z),
                    _ => {}
                }
                wo.set(i, o);
                wi.set(i, w);
                (uc.0[i], u0.0[i], u1.0[i]) =
                    (rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                one.push(d);
            }
            let (f, pdf) = lanes.f_and_pdf(wo, wi, lobes);
            let s = lanes.sample_real(wo, uc, u0, u1, lobes);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, d) in one.iter().enumerate() {
                let (o, w) = (wo.get(i), wi.get(i));
                assert_eq!(bits(f.get(i)), bits(d.f(o, w)), "f, lane {i}: {o} {w}");
                let p = d.pdf_lobes(o, w, lobes);
                assert_eq!(pdf.0[i].to_bits(), p.to_bits(), "pdf, lane {i}: {o} {w}");
                let u = Vec2::new(u0.0[i], u1.0[i]);
                let scalar = d.sample_lobes(o, uc.0[i], u, lobes);
                assert_eq!(s.valid.get(i), scalar.is_some(), "lane {i}: {o} {lobes:?}");
                if let Some(scalar) = scalar {
                    assert_eq!(bits(s.wi.get(i)), bits(scalar.wi));
                    assert_eq!(bits(s.f.get(i)), bits(scalar.f));
                    assert_eq!(s.pdf.0[i].to_bits(), scalar.pdf.to_bits());
                    let eta = crate::bsdf::Bxdf::RoughDielectric(*d).relative_ior(o, scalar.wi);
                    let lanes_eta = lanes.relative_ior(wo, s.wi).0[i];
                    assert_eq!(lanes_eta.to_bits(), eta.to_bits());
                    valid[round % 3] += 1;
                }
            }
        }
        // A guard that samples of every choice are compared.
        assert!(valid.iter().all(|&n| n > 300), "{valid:?}");
    }
}
