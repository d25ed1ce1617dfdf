//! A thin dielectric sheet (a window pane, a soap film): Mitsuba's `thindielectric`.
//!
//! Light meets two parallel interfaces close together. Summing the internal reflections, a
//! sheet with single-interface reflectance R = F(cos θ) reflects R' = R + T²R / (1 - R²) =
//! 2R / (1 + R) and transmits T' = 1 - R' without changing direction: the two refractions
//! cancel and the displacement is neglected. Both lobes are deltas, both sides alike.

use super::bxdf::DirectionSample;
use super::fresnel::fresnel_dielectric_real;
use super::mirror::specular_reflection_real;
use super::LocalSample;
use crate::desc::Rgb;
use glam::Vec3;
use pathlab_mc::simd::lanes::{Real, Vector3, F8, V8};

/// A thin sheet of a dielectric, written once for one sheet (`V = Rgb`, `R = f32`) and for
/// eight lanes' sheets ([`V8`], [`F8`]): the path tracer's lanes sample with these same
/// functions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ThinDielectric<V = Rgb, R = f32> {
    /// Index of refraction of the sheet relative to the medium around it.
    pub eta: R,
    /// Scale of the reflected part.
    pub reflectance: V,
    /// Scale of the transmitted part.
    pub transmittance: V,
}

impl ThinDielectric {
    /// The sheet's reflectance R' = 2R / (1 + R) at |cos θ| = `cos`.
    pub fn reflectance(&self, cos: f32) -> f32 {
        self.reflectance_real(cos)
    }

    /// Reflection with probability R', straight transmission otherwise (`uc` chooses).
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<LocalSample> {
        self.sample_real(wo, uc).delta()
    }
}

impl<V: Vector3> ThinDielectric<V, V::R> {
    /// [`ThinDielectric::reflectance`] for one sheet or lanes.
    #[inline(always)]
    fn reflectance_real(&self, cos: V::R) -> V::R {
        let r = fresnel_dielectric_real(cos.abs(), self.eta);
        V::R::splat(2.0) * r / (V::R::splat(1.0) + r)
    }

    /// [`ThinDielectric::sample`] for one sheet or lanes: both lobes are deltas; the sample
    /// exists where `wo` is off the surface (and, reflected, where R' > 0).
    #[inline(always)]
    pub fn sample_real(&self, wo: V, uc: V::R) -> DirectionSample<V> {
        let zero = V::R::splat(0.0);
        let r = self.reflectance_real(wo.z());
        let reflected = specular_reflection_real(wo, self.reflectance.scale(r), r);
        let t = V::R::splat(1.0) - r;
        let wi = -wo;
        let transmitted = DirectionSample {
            f: self.transmittance.scale(t / wi.z().abs()),
            wi,
            pdf: t,
            valid: !wo.z().equals(zero),
        };
        DirectionSample::select(uc.lt(r), reflected, transmitted)
    }
}

impl ThinDielectric<V8, F8> {
    /// Sets lane `i` to `d`. Every field is taken apart here: a field added to
    /// [`ThinDielectric`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, d: ThinDielectric) {
        let ThinDielectric {
            eta,
            reflectance,
            transmittance,
        } = d;
        self.eta.0[i] = eta;
        self.reflectance.set(i, reflectance);
        self.transmittance.set(i, transmittance);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::plastic::tests::{assert_lane_sample, direction};
    use pathlab_mc::rng::Pcg32;

    /// Eight lanes of thin sheets sample, lane by lane, what one sheet samples, to the bit,
    /// from both sides and on the surface, both lobes.
    #[test]
    fn lanes_sample_what_one_sheet_samples() {
        let mut rng = Pcg32::new(21, 8);
        let (mut reflected, mut transmitted) = (0, 0);
        for round in 0..300 {
            let mut lanes = ThinDielectric::<V8, F8>::default();
            let (mut wo, mut uc) = (V8::default(), F8::default());
            let mut one = Vec::new();
            for i in 0..8 {
                let d = ThinDielectric {
                    eta: [1.5, 1.33, 2.4, 1.0][(round + i) % 4],
                    reflectance: Vec3::new(1.0, rng.uniform_f32(), 0.5),
                    transmittance: Vec3::new(rng.uniform_f32(), 1.0, 0.8),
                };
                lanes.set_lane(i, d);
                let mut o = direction(&mut rng);
                if round % 7 == 3 {
                    o.z = 0.0;
                }
                wo.set(i, o);
                // Small numbers too, to choose the reflection often.
                uc.0[i] = rng.uniform_f32() * [1.0, 0.1][round % 2];
                one.push(d);
            }
            let s = lanes.sample_real(wo, uc);
            for (i, d) in one.iter().enumerate() {
                let o = wo.get(i);
                let scalar = d.sample(o, uc.0[i]);
                if let Some(scalar) = assert_lane_sample(&s, i, scalar, &format!("{o}")) {
                    assert!(scalar.delta);
                    if scalar.wi.z * o.z > 0.0 {
                        reflected += 1;
                    } else {
                        transmitted += 1;
                    }
                }
            }
        }
        assert!(
            reflected > 200 && transmitted > 200,
            "{reflected} {transmitted}"
        );
    }
}
