//! Lambertian reflection and Lambertian transmission together: pbrt-v4's
//! `diffusetransmission` (leaves, paper, a lamp shade). f = R/π for directions on the side of
//! `wo`, T/π on the other; both sides alike.
//!
//! Sampling picks reflection with probability p_r = max(R) / (max(R) + max(T)) (pbrt-v4's
//! choice), then a cosine-weighted direction on the chosen side: pdf = p_r cos θ / π on `wo`'s
//! side, (1 - p_r) |cos θ| / π on the other.

use super::bxdf::DirectionSample;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, V8};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

/// Diffuse reflection `reflectance` and diffuse transmission `transmittance`, written once
/// for one material (`V = Rgb`) and for eight lanes' materials ([`V8`]): the path tracer's
/// lanes shade with these same functions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiffuseTransmission<V = Rgb> {
    /// Albedo of the reflection, per channel.
    pub reflectance: V,
    /// Albedo of the transmission, per channel.
    pub transmittance: V,
}

impl DiffuseTransmission {
    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_and_pdf(wo, wi).0
    }

    /// A cosine-weighted direction on the side `uc` chooses (reflection below p_r).
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        self.sample_real(wo, uc, u.x, u.y).local()
    }

    /// Density of [`DiffuseTransmission::sample`] choosing `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_and_pdf(wo, wi).1
    }
}

impl<V: Vector3> DiffuseTransmission<V> {
    /// Probability that sampling chooses reflection (½ when both are black).
    #[inline(always)]
    fn reflect_probability(&self) -> V::R {
        let (r, t) = (
            self.reflectance.max_element(),
            self.transmittance.max_element(),
        );
        V::R::select((r + t).gt(V::R::splat(0.0)), r / (r + t), V::R::splat(0.5))
    }

    /// f(wo, wi) and its density as a sample from `wo`: reflection where the two are on one
    /// side, transmission where they are on opposite sides, nothing on the surface.
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V) -> (V, V::R) {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let side = wo.z() * wi.z();
        let (reflected, transmitted) = (side.gt(zero), side.lt(zero));
        let inv_pi = V::R::splat(FRAC_1_PI);
        let f = V::select(
            reflected,
            self.reflectance.scale(inv_pi),
            V::select(
                transmitted,
                self.transmittance.scale(inv_pi),
                V::splat(Vec3::ZERO),
            ),
        );
        let p_r = self.reflect_probability();
        let choice = V::R::select(reflected, p_r, one - p_r);
        let pdf = V::R::select(
            reflected | transmitted,
            choice * cosine_hemisphere_pdf(wi.z().abs()),
            zero,
        );
        (f, pdf)
    }

    /// A cosine-weighted direction from (`u0`, `u1`) on the side `uc` chooses: `wo`'s side
    /// (reflection) below p_r, the other above. It exists where `wo` is off the surface (and
    /// not NaN) and its density is positive.
    #[inline(always)]
    pub fn sample_real(&self, wo: V, uc: V::R, u0: V::R, u1: V::R) -> DirectionSample<V> {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let p_r = self.reflect_probability();
        let reflect = uc.lt(p_r);
        let up: V = cosine_hemisphere(u0, u1);
        // Reflection leaves on wo's side, transmission on the other.
        let above = wo.z().gt(zero);
        let flip = (reflect & !above) | (!reflect & above);
        let wi = V::new(up.x(), up.y(), V::R::select(flip, -up.z(), up.z()));
        let choice = V::R::select(reflect, p_r, one - p_r);
        let pdf = choice * cosine_hemisphere_pdf(wi.z().abs());
        DirectionSample {
            wi,
            pdf,
            f: self.f_and_pdf(wo, wi).0,
            valid: !wo.z().equals(zero) & wo.z().equals(wo.z()) & pdf.gt(zero),
        }
    }
}

impl DiffuseTransmission<V8> {
    /// Sets lane `i` to `d`. Every field is taken apart here: a field added to
    /// [`DiffuseTransmission`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, d: DiffuseTransmission) {
        let DiffuseTransmission {
            reflectance,
            transmittance,
        } = d;
        self.reflectance.set(i, reflectance);
        self.transmittance.set(i, transmittance);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::plastic::tests::{
        assert_lane_f_pdf, assert_lane_sample, direction, LaneInputs,
    };
    use pathlab_mc::rng::Pcg32;

    /// Eight lanes compute, lane by lane, what one material computes, to the bit: f, pdf and
    /// the sample, both lobes, from both sides and on the surface, black lobes included.
    #[test]
    fn lanes_compute_what_one_material_computes() {
        let mut rng = Pcg32::new(17, 4);
        let (mut reflected, mut transmitted, mut seen) = (0, 0, 0);
        for round in 0..300 {
            let case = LaneInputs::draw(&mut rng, |rng, i| {
                let black = [1.0, 1.0, 1.0, 0.0][(round + i) % 4];
                let d = DiffuseTransmission {
                    reflectance: Vec3::new(rng.uniform_f32(), 0.4, 0.1) * black,
                    transmittance: Vec3::new(0.3, rng.uniform_f32(), 0.6) * [1.0, 0.0][i % 2],
                };
                let (mut o, mut w) = (direction(rng), direction(rng));
                match round % 7 {
                    2 => w.z = 0.0,
                    5 => o.z = 0.0,
                    _ => {}
                }
                (d, o, w)
            });
            let mut lanes = DiffuseTransmission::<V8>::default();
            for (i, d) in case.one.iter().enumerate() {
                lanes.set_lane(i, *d);
            }
            let (f, pdf) = lanes.f_and_pdf(case.wo, case.wi);
            let s = lanes.sample_real(case.wo, case.uc, case.u[0], case.u[1]);
            for (i, d) in case.one.iter().enumerate() {
                let (o, w, uc, u) = case.lane(i);
                let what = format!("{o} {w}");
                assert_lane_f_pdf(f, pdf, i, (d.f(o, w), d.pdf(o, w)), &what);
                if let Some(scalar) = assert_lane_sample(&s, i, d.sample(o, uc, u), &what) {
                    if scalar.wi.z * o.z > 0.0 {
                        reflected += 1;
                    } else {
                        transmitted += 1;
                    }
                }
                seen += 1;
            }
        }
        assert!(
            reflected * 5 > seen && transmitted * 5 > seen,
            "{reflected} reflected, {transmitted} transmitted of {seen}"
        );
    }
}
