//! Lambertian reflection, written once for one direction and for eight lanes (see
//! [`pathlab_mc::simd::lanes`]): the path tracer's lanes shade with these same functions.

use super::bxdf::DirectionSample;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, V8};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

/// Lambertian: f = reflectance / π on the upper hemisphere; sampled cosine-weighted. `V` is the
/// colour type: [`Rgb`], or [`crate::simd::lanes::V8`] for eight lanes' materials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Diffuse<V = Rgb> {
    /// Albedo.
    pub reflectance: V,
}

#[cfg(test)]
thread_local! {
    /// A factor on every Lambertian value computed on this thread, for the test that shows
    /// the lanes shade with this code (unit tests only).
    pub(crate) static TEST_SCALE: std::cell::Cell<f32> = const { std::cell::Cell::new(1.0) };
}

impl<V: Vector3> Diffuse<V> {
    /// ρ / π.
    #[inline(always)]
    fn value(&self) -> V {
        let f = self.reflectance.scale(V::R::splat(FRAC_1_PI));
        #[cfg(test)]
        let f = f.scale(V::R::splat(TEST_SCALE.with(std::cell::Cell::get)));
        f
    }

    /// f for directions whose local z are `wo_z` and `wi_z`.
    #[inline(always)]
    pub fn f_z(&self, wo_z: V::R, wi_z: V::R) -> V {
        let zero = V::R::splat(0.0);
        V::select(
            wo_z.gt(zero) & wi_z.gt(zero),
            self.value(),
            V::splat(Vec3::ZERO),
        )
    }

    /// Density of [`Diffuse::sample_z`] choosing a direction of local z `wi_z`.
    #[inline(always)]
    pub fn pdf_z(&self, wo_z: V::R, wi_z: V::R) -> V::R {
        let zero = V::R::splat(0.0);
        V::R::select(
            wo_z.gt(zero) & wi_z.gt(zero),
            cosine_hemisphere_pdf(wi_z),
            zero,
        )
    }

    /// A cosine-weighted direction from `u`, seen from a direction of local z `wo_z`.
    #[inline(always)]
    pub fn sample_z(&self, wo_z: V::R, u0: V::R, u1: V::R) -> DirectionSample<V> {
        let zero = V::R::splat(0.0);
        let wi: V = cosine_hemisphere(u0, u1);
        let pdf = cosine_hemisphere_pdf(wi.z());
        DirectionSample {
            wi,
            pdf,
            f: self.value(),
            // Nothing where wo is below (a NaN goes on, as `!(x <= 0)`).
            valid: !wo_z.le(zero) & pdf.gt(zero),
        }
    }
}

impl Diffuse {
    /// f(wo, wi).
    #[inline]
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_z(wo.z, wi.z)
    }

    /// A cosine-weighted direction.
    #[inline]
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<LocalSample> {
        self.sample_z(wo.z, u.x, u.y).local()
    }

    /// Density of [`Diffuse::sample`].
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.pdf_z(wo.z, wi.z)
    }
}

impl Diffuse<V8> {
    /// Sets lane `i` to `d`. Every field is taken apart here: a field added to [`Diffuse`]
    /// fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, d: Diffuse) {
        let Diffuse { reflectance } = d;
        self.reflectance.set(i, reflectance);
    }
}
