//! The reflectance models a material is made of, dispatched by [`Bxdf`]: each in its own
//! shading frame (z = shading normal), with `f`, `sample` and `pdf`.

use super::*;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3};

/// A lobe's sample in the local frame, for one direction (`V = Vec3`) or for eight lanes
/// ([`crate::simd::lanes::V8`]): it exists where `valid`. Whether the lobe is a delta is the
/// caller's to say ([`DirectionSample::local`], [`DirectionSample::delta`]).
#[derive(Clone, Copy, Debug)]
pub struct DirectionSample<V: Vector3> {
    /// The sampled direction, local.
    pub wi: V,
    /// Its density per unit solid angle.
    pub pdf: V::R,
    /// f there.
    pub f: V,
    /// Where the sample exists.
    pub valid: <V::R as Real>::Mask,
}

impl DirectionSample<Vec3> {
    /// The sample of a non-delta lobe where it exists.
    #[inline]
    pub fn local(self) -> Option<LocalSample> {
        self.with_delta(false)
    }

    /// The sample of a delta lobe where it exists.
    #[inline]
    pub fn delta(self) -> Option<LocalSample> {
        self.with_delta(true)
    }

    #[inline]
    fn with_delta(self, delta: bool) -> Option<LocalSample> {
        self.valid.then_some(LocalSample {
            f: self.f,
            wi: self.wi,
            pdf: self.pdf,
            delta,
        })
    }
}

impl<V: Vector3> DirectionSample<V> {
    /// `a` in the lanes `m`, `b` in the others (for one direction: `a` where `m`).
    #[inline(always)]
    pub fn select(m: <V::R as Real>::Mask, a: Self, b: Self) -> Self {
        DirectionSample {
            wi: V::select(m, a.wi, b.wi),
            pdf: V::R::select(m, a.pdf, b.pdf),
            f: V::select(m, a.f, b.f),
            valid: (m & a.valid) | (!m & b.valid),
        }
    }
}

/// A sampled direction in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSample {
    /// f(wo, wi).
    pub f: Rgb,
    /// The direction, local frame.
    pub wi: Vec3,
    /// Density per solid angle, or the probability of a delta lobe.
    pub pdf: f32,
    /// Whether it comes from a delta lobe.
    pub delta: bool,
}

/// Which of a BSDF's lobes a sample may come from (pbrt-v4's `BxDFReflTransFlags`): layered
/// models walk inside their layers by sampling reflection or transmission alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobes {
    /// Reflection and transmission, each with its own probability.
    All,
    /// Reflection only.
    Reflection,
    /// Transmission only.
    Transmission,
}

impl Lobes {
    /// The probabilities of choosing reflection and transmission whose unrestricted values are
    /// `r` and `t = 1 - r`: the restricted lobe's share set to zero, the rest renormalised
    /// (exactly `(r, t)` for [`Lobes::All`]). `None` when nothing is left.
    pub(crate) fn choose(self, r: f32, t: f32) -> Option<(f32, f32)> {
        let (r, t, left) = self.choose_real(r, t);
        left.then_some((r, t))
    }

    /// [`Lobes::choose`] for one value or lanes: the probabilities, and where anything is
    /// left.
    #[inline(always)]
    pub(crate) fn choose_real<R: Real>(self, r: R, t: R) -> (R, R, R::Mask) {
        let zero = R::splat(0.0);
        let (r, t) = match self {
            Lobes::All => return (r, t, R::every_lane()),
            Lobes::Reflection => (r, zero),
            Lobes::Transmission => (zero, t),
        };
        (r / (r + t), t / (r + t), (r + t).gt(zero))
    }
}

/// The reflectance model of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bxdf {
    /// Lambertian.
    Diffuse(Diffuse),
    /// Lambertian reflection and transmission.
    DiffuseTransmission(DiffuseTransmission),
    /// A dielectric coat over a diffuse or conductor base (pbrt-v4's layered BSDFs).
    Layered(Layered),
    /// Perfect specular reflection.
    Mirror(Mirror),
    /// Smooth glass.
    Dielectric(SmoothDielectric),
    /// A thin sheet of glass.
    ThinDielectric(ThinDielectric),
    /// A smooth or rough conductor.
    Conductor(Conductor),
    /// Rough glass.
    RoughDielectric(RoughDielectric),
    /// Diffuse under a smooth coat.
    Plastic(Plastic),
    /// Diffuse under a rough coat.
    RoughPlastic(RoughPlastic),
    /// Disney's principled BSDF (Mitsuba's `principled` and `principledthin`).
    Principled(Principled),
}

impl Bxdf {
    /// f(wo, wi) in the local frame (zero for delta lobes).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            Bxdf::Diffuse(b) => b.f(wo, wi),
            Bxdf::DiffuseTransmission(b) => b.f(wo, wi),
            Bxdf::Layered(b) => b.f(wo, wi),
            Bxdf::Conductor(b) => b.f(wo, wi),
            Bxdf::RoughDielectric(b) => b.f(wo, wi),
            Bxdf::Plastic(b) => b.f(wo, wi),
            Bxdf::RoughPlastic(b) => b.f(wo, wi),
            Bxdf::Principled(b) => b.f(wo, wi),
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_) => Rgb::ZERO,
        }
    }

    /// Samples wi given wo in the local frame: `uc` chooses a lobe, `u` the direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        match self {
            Bxdf::Diffuse(b) => b.sample(wo, u),
            Bxdf::DiffuseTransmission(b) => b.sample(wo, uc, u),
            Bxdf::Layered(b) => b.sample(wo, uc, u),
            Bxdf::Mirror(b) => b.sample(wo),
            Bxdf::Dielectric(b) => b.sample(wo, uc),
            Bxdf::ThinDielectric(b) => b.sample(wo, uc),
            Bxdf::Conductor(b) => b.sample(wo, u),
            Bxdf::RoughDielectric(b) => b.sample(wo, uc, u),
            Bxdf::Plastic(b) => b.sample(wo, uc, u),
            Bxdf::RoughPlastic(b) => b.sample(wo, uc, u),
            Bxdf::Principled(b) => b.sample(wo, uc, u),
        }
    }

    /// Density of [`Bxdf::sample`] choosing `wi` (its non-delta part).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bxdf::Diffuse(b) => b.pdf(wo, wi),
            Bxdf::DiffuseTransmission(b) => b.pdf(wo, wi),
            Bxdf::Layered(b) => b.pdf(wo, wi),
            Bxdf::Conductor(b) => b.pdf(wo, wi),
            Bxdf::RoughDielectric(b) => b.pdf(wo, wi),
            Bxdf::Plastic(b) => b.pdf(wo, wi),
            Bxdf::RoughPlastic(b) => b.pdf(wo, wi),
            Bxdf::Principled(b) => b.pdf(wo, wi),
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_) => 0.0,
        }
    }

    /// The relative index of refraction η' of a sample from `wo` to `wi` (local frame) that
    /// refracts through an interface between two media (smooth or rough glass, the
    /// transmission of a solid principled material): η entering, 1/η leaving; the radiance it
    /// carries across is scaled by 1/η'² (pbrt-v4's `BSDFSample::eta`). One for everything
    /// else: reflection, thin sheets, diffuse and layered transmission.
    pub fn relative_ior(&self, wo: Vec3, wi: Vec3) -> f32 {
        let eta = match self {
            Bxdf::Dielectric(b) => b.eta,
            Bxdf::RoughDielectric(b) => b.eta,
            Bxdf::Principled(b) if !b.thin => b.eta,
            _ => return 1.0,
        };
        scattering::relative_eta(wo, wi, eta)
    }

    /// Whether `sample` returns an estimate (f / pdf unbiased, pdf for MIS only) rather than
    /// exact values: the layered models.
    pub fn is_stochastic(&self) -> bool {
        matches!(self, Bxdf::Layered(_))
    }

    /// Whether every lobe is a delta distribution (light sampling can never help).
    pub fn is_delta(&self) -> bool {
        match self {
            Bxdf::Mirror(_) | Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_) => true,
            Bxdf::Conductor(c) => c.distribution.is_none(),
            Bxdf::Diffuse(_)
            | Bxdf::DiffuseTransmission(_)
            | Bxdf::Layered(_)
            | Bxdf::RoughDielectric(_)
            | Bxdf::Plastic(_)
            | Bxdf::RoughPlastic(_)
            | Bxdf::Principled(_) => false,
        }
    }
}

/// A description's index of refraction, or glass's 1.5 where it is not a positive number.
pub(crate) fn usable_ior(ior: f32) -> f32 {
    if ior > 0.0 && ior.is_finite() {
        ior
    } else {
        1.5
    }
}

/// Roughness below which a microfacet model is drawn as its smooth (delta) limit.
pub(crate) const SMOOTH_ALPHA: f32 = 1e-4;

#[cfg(test)]
mod tests {
    #[test]
    fn a_bxdf_stays_as_small_as_its_largest_fixed_model() {
        // Every shading point copies one or more; the layered model keeps its stack behind a
        // reference so that it adds nothing.
        assert!(std::mem::size_of::<super::Bxdf>() <= std::mem::size_of::<super::Principled>());
    }
}
