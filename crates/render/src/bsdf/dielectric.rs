//! A smooth dielectric interface (glass).

use super::bxdf::DirectionSample;
use super::fresnel::{
    fresnel_dielectric, fresnel_dielectric_real, fresnel_schlick, fresnel_schlick_real,
};
use super::mirror::specular_reflection_real;
use super::scattering::{refract_real, relative_eta};
use super::{Lobes, LocalSample};
use crate::desc::Rgb;
use glam::Vec3;
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8};

/// Which Fresnel reflectance a dielectric uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FresnelModel {
    /// The exact dielectric Fresnel equations (unpolarised light).
    #[default]
    Exact,
    /// Schlick's approximation, as the course's renderer uses.
    Schlick,
}

impl FresnelModel {
    /// Reflectance at cos θi (positive: from outside) for relative index `eta`.
    #[inline]
    pub fn reflectance(self, cos_theta_i: f32, eta: f32) -> f32 {
        match self {
            FresnelModel::Exact => fresnel_dielectric(cos_theta_i, eta),
            FresnelModel::Schlick => fresnel_schlick(cos_theta_i, eta),
        }
    }
}

/// Glass: Fresnel reflectance F chooses reflection with probability F and refraction (Snell's
/// law) otherwise; total internal reflection beyond the critical angle. Radiance crossing the
/// interface is scaled by 1/η'² (η' the relative index along the path), as radiance transport
/// requires. Both lobes are deltas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// Index of refraction inside (below the normal) relative to outside.
    pub eta: f32,
    /// Scale of the reflected part.
    pub reflectance: Rgb,
    /// Scale of the transmitted part.
    pub transmittance: Rgb,
    /// Exact Fresnel or Schlick's approximation.
    pub fresnel: FresnelModel,
}

impl SmoothDielectric {
    /// Reflection with probability F, refraction otherwise (`uc` chooses).
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<LocalSample> {
        self.sample_lobes(wo, uc, Lobes::All)
    }

    /// [`SmoothDielectric::sample`] restricted to `lobes` (the other's probability given to
    /// the one left).
    pub fn sample_lobes(&self, wo: Vec3, uc: f32, lobes: Lobes) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let f = self.fresnel.reflectance(wo.z, self.eta);
        let (pr, pt) = lobes.choose(f, 1.0 - f)?;
        let lobe = (self.reflectance, self.transmittance, self.eta);
        sample_interface(lobe, wo, uc, f, (pr, pt)).delta()
    }
}

/// A smooth dielectric's sample, for one direction or lanes, once its Fresnel reflectance
/// `f` and the probabilities (`pr`, `pt`) of reflecting and refracting are known: reflection
/// where `uc < pr`, refraction otherwise; `lobe` is (reflectance, transmittance, η).
#[inline(always)]
fn sample_interface<V: Vector3>(
    (reflectance, transmittance, eta): (V, V, V::R),
    wo: V,
    uc: V::R,
    f: V::R,
    (pr, pt): (V::R, V::R),
) -> DirectionSample<V> {
    let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
    let r = specular_reflection_real(wo, reflectance.scale(f), pr);
    let (wi, etap, refracts) = refract_real(wo, eta);
    let t = one - f;
    let reflects = uc.lt(pr);
    DirectionSample {
        wi: V::select(reflects, r.wi, wi),
        pdf: V::R::select(reflects, r.pdf, pt),
        f: V::select(
            reflects,
            r.f,
            transmittance.scale(t / (wi.z().abs() * etap * etap)),
        ),
        valid: !wo.z().equals(zero) & ((reflects & r.valid) | (!reflects & refracts)),
    }
}

/// Eight lanes' smooth dielectrics (the path tracer's lanes).
#[derive(Clone, Copy, Debug, Default)]
pub struct DielectricLanes {
    /// Relative index η.
    pub eta: F8,
    /// Scale of the reflected part.
    pub reflectance: V8,
    /// Scale of the transmitted part.
    pub transmittance: V8,
    /// Lanes whose Fresnel reflectance is Schlick's approximation (the others': exact).
    pub schlick: M8,
}

impl DielectricLanes {
    /// Sets lane `i` to `d`. Every field is taken apart here: a field added to
    /// [`SmoothDielectric`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, d: SmoothDielectric) {
        let SmoothDielectric {
            eta,
            reflectance,
            transmittance,
            fresnel,
        } = d;
        self.eta.0[i] = eta;
        self.reflectance.set(i, reflectance);
        self.transmittance.set(i, transmittance);
        self.schlick.set(
            i,
            match fresnel {
                FresnelModel::Exact => false,
                FresnelModel::Schlick => true,
            },
        );
    }

    /// [`SmoothDielectric::sample`] in every lane (both lobes), and the relative index η' of
    /// each sample. Schlick's reflectance is computed only where some lane takes it.
    #[inline(always)]
    pub fn sample(&self, wo: V8, uc: F8) -> (DirectionSample<V8>, F8) {
        let mut f = fresnel_dielectric_real(wo.z, self.eta);
        if self.schlick.any() {
            f = self.schlick.select(fresnel_schlick_real(wo.z, self.eta), f);
        }
        let lobe = (self.reflectance, self.transmittance, self.eta);
        // `Lobes::All`'s probabilities: (F, 1 - F).
        let s = sample_interface(lobe, wo, uc, f, (f, F8::splat(1.0) - f));
        let eta = relative_eta(wo, s.wi, self.eta);
        (s, eta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bxdf;
    use pathlab_mc::rng::Pcg32;

    /// Eight lanes of glass sample, lane by lane, what the one-direction [`SmoothDielectric`]
    /// samples, to the bit, with the relative index [`Bxdf::relative_ior`] gives: from both
    /// sides, at grazing angles, beyond the critical angle and on the surface; of exact
    /// Fresnel reflectance and of Schlick's, in lanes of either alone and side by side.
    #[test]
    fn lanes_sample_what_one_direction_samples() {
        let mut rng = Pcg32::new(5, 3);
        let (mut reflected, mut refracted) = (0, 0);
        for round in 0..500 {
            let mut lanes = DielectricLanes::default();
            let (mut wo, mut uc) = (V8::default(), F8::default());
            let mut one = Vec::new();
            for i in 0..8 {
                let d = SmoothDielectric {
                    eta: [1.5, 1.0 / 1.33, 2.4, 1.0001][(round + i) % 4],
                    reflectance: Vec3::new(1.0, rng.uniform_f32(), 0.5),
                    transmittance: Vec3::new(rng.uniform_f32(), 1.0, 0.9),
                    // Both models side by side, and lanes of one model alone.
                    fresnel: match (round / 4 % 3, i % 2) {
                        (0, 1) | (1, _) => FresnelModel::Schlick,
                        _ => FresnelModel::Exact,
                    },
                };
                lanes.set_lane(i, d);
                let z = match round % 7 {
                    0 => 0.0,
                    1 => 1e-4 * (rng.uniform_f32() - 0.5),
                    _ => 2.0 * rng.uniform_f32() - 1.0,
                };
                let phi = std::f32::consts::TAU * rng.uniform_f32();
                let r = (1.0 - z * z).max(0.0).sqrt();
                wo.set(i, Vec3::new(r * phi.cos(), r * phi.sin(), z));
                uc.0[i] = rng.uniform_f32();
                one.push(d);
            }
            let (s, eta) = lanes.sample(wo, uc);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, d) in one.iter().enumerate() {
                let o = wo.get(i);
                let scalar = d.sample(o, uc.0[i]);
                assert_eq!(s.valid.get(i), scalar.is_some(), "lane {i}: {o}");
                let Some(scalar) = scalar else { continue };
                assert_eq!(bits(s.wi.get(i)), bits(scalar.wi), "lane {i}: {o}");
                assert_eq!(bits(s.f.get(i)), bits(scalar.f));
                assert_eq!(s.pdf.0[i].to_bits(), scalar.pdf.to_bits());
                let relative = Bxdf::Dielectric(*d).relative_ior(o, scalar.wi);
                assert_eq!(eta.0[i].to_bits(), relative.to_bits());
                if scalar.wi.z * o.z > 0.0 {
                    reflected += 1;
                } else {
                    refracted += 1;
                }
            }
        }
        // A guard that both lobes are compared.
        assert!(
            reflected > 200 && refracted > 1000,
            "{reflected} {refracted}"
        );
    }
}
