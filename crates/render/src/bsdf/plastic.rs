//! A diffuse base under a smooth dielectric coat (Mitsuba's `plastic`), written once for one
//! direction and for eight lanes: the path tracer's lanes shade with these same functions.

use super::bxdf::DirectionSample;
use super::fresnel::{fresnel_dielectric_real, fresnel_diffuse_reflectance};
use super::mirror::specular_reflection_real;
use super::LocalSample;
use crate::desc::Rgb;
use glam::{Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8};
use pathlab_mc::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

/// Smooth plastic: specular reflection off the coat with probability-free weight F(θo), plus
/// light that enters the coat, scatters diffusely off the base and leaves:
///
/// f_diffuse = ρ' (1 - F(θi)) (1 - F(θo)) / (η² π), with ρ' = ρ / (1 - F_dr,int)
///
/// where F_dr,int is the coat's diffuse reflectance seen from inside. Its albedo is
/// F(θo) + (1 - F(θo)) ρ ≤ 1 (using 1 - F_dr,ext = η² (1 - F_dr,int)): ρ is the overall
/// diffuse albedo and a white base reflects everything. With `nonlinear`, ρ' = ρ / (1 - ρ
/// F_dr,int) accounts for the base's colour at each internal bounce (albedo
/// F + (1 - F) ρ (1 - F_dr,int) / (1 - ρ F_dr,int), still ≤ 1 and equal for ρ = 1).
///
/// `V`, `R` and `M` are the colour, number and truth types: [`Rgb`], `f32` and `bool` for one
/// material, [`V8`], [`F8`] and [`M8`] for eight lanes' materials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Plastic<V = Rgb, R = f32, M = bool> {
    /// Diffuse reflectance of the base.
    pub diffuse: V,
    /// Scale of the coat's reflection (Mitsuba's `specular_reflectance`; 1 is physical).
    pub specular: V,
    /// Index of the coat relative to outside.
    pub eta: R,
    /// Whether internal reflections tint by the base colour.
    pub nonlinear: M,
    /// Diffuse Fresnel reflectance of the coat from inside.
    fdr_int: R,
}

impl Plastic {
    /// A plastic with diffuse base `diffuse` and coat index `eta`.
    pub fn new(diffuse: Rgb, eta: f32, nonlinear: bool) -> Self {
        Plastic {
            diffuse,
            specular: Rgb::ONE,
            eta,
            nonlinear,
            fdr_int: fresnel_diffuse_reflectance(1.0 / eta),
        }
    }

    /// The same plastic with its coat reflection scaled by `specular`.
    pub fn with_specular(self, specular: Rgb) -> Self {
        Plastic { specular, ..self }
    }

    /// The non-delta (diffuse) part of f.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_and_pdf(wo, wi).0
    }

    /// The coat's mirror reflection (a delta) or a cosine-weighted direction.
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<LocalSample> {
        let (s, specular) = self.sample_real(wo, uc, u.x, u.y);
        if specular {
            s.delta()
        } else {
            s.local()
        }
    }

    /// Density of the non-delta part of [`Plastic::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_and_pdf(wo, wi).1
    }
}

/// The mean of a colour's three channels.
#[inline(always)]
pub(super) fn mean<V: Vector3>(c: V) -> V::R {
    (c.x() + c.y() + c.z()) / V::R::splat(3.0)
}

/// The base's albedo ρ' that a coat whose diffuse reflectance from inside is `internal`
/// scales up to account for the light it reflects back: ρ / (1 - `internal`), or, where
/// `nonlinear`, ρ / (1 - ρ `internal`) (the base's colour at each internal bounce).
#[inline(always)]
pub(super) fn coated_base<V: Vector3>(
    diffuse: V,
    internal: V::R,
    nonlinear: <V::R as Real>::Mask,
) -> V {
    let tinted = diffuse.div_axes(V::splat(Vec3::ONE) - diffuse.scale(internal));
    let plain = diffuse.div_by(V::R::splat(1.0) - internal);
    V::select(nonlinear, tinted, plain)
}

impl<V: Vector3> Plastic<V, V::R, <V::R as Real>::Mask> {
    /// Probability of sampling the specular coat reflection: F s against (1 - F) d, with s
    /// and d the mean specular scale and diffuse reflectance (as Mitsuba weighs them).
    #[inline(always)]
    fn specular_probability(&self, f_o: V::R) -> V::R {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let c = self.specular;
        let positive = V::new(c.x().max(zero), c.y().max(zero), c.z().max(zero));
        let s = f_o * mean(positive);
        let d = (one - f_o) * mean(self.diffuse);
        V::R::select((s + d).gt(zero), s / (s + d), one)
    }

    /// The non-delta part of f and its density as a sample from `wo` (zero where either
    /// direction is below the surface).
    #[inline(always)]
    pub fn f_and_pdf(&self, wo: V, wi: V) -> (V, V::R) {
        let (zero, one) = (V::R::splat(0.0), V::R::splat(1.0));
        let (f_o, f_i) = (
            fresnel_dielectric_real(wo.z(), self.eta),
            fresnel_dielectric_real(wi.z(), self.eta),
        );
        let base = coated_base(self.diffuse, self.fdr_int, self.nonlinear);
        let f =
            base.scale((one - f_o) * (one - f_i) * V::R::splat(FRAC_1_PI) / (self.eta * self.eta));
        let pdf = (one - self.specular_probability(f_o)) * cosine_hemisphere_pdf(wi.z());
        // `z <= 0`: a NaN goes on, as it did through the early return of the one-direction
        // code this was written from.
        let none = wo.z().le(zero) | wi.z().le(zero);
        (
            V::select(none, V::splat(Vec3::ZERO), f),
            V::R::select(none, zero, pdf),
        )
    }

    /// The coat's mirror reflection, with probability `specular_probability`, or a
    /// cosine-weighted direction from (`u0`, `u1`); `uc` chooses. Returns the sample (it
    /// exists where `wo` is above the surface and its density is positive) and where it is
    /// the mirror reflection (a delta lobe).
    #[inline(always)]
    pub fn sample_real(
        &self,
        wo: V,
        uc: V::R,
        u0: V::R,
        u1: V::R,
    ) -> (DirectionSample<V>, <V::R as Real>::Mask) {
        let zero = V::R::splat(0.0);
        let f_o = fresnel_dielectric_real(wo.z(), self.eta);
        let p_spec = self.specular_probability(f_o);
        let specular = uc.lt(p_spec);
        let wi: V = cosine_hemisphere(u0, u1);
        let (f, pdf) = self.f_and_pdf(wo, wi);
        let diffuse = DirectionSample {
            wi,
            pdf,
            f,
            valid: pdf.gt(zero),
        };
        let mirror = specular_reflection_real(wo, self.specular.scale(f_o), p_spec);
        let mut s = DirectionSample::select(specular, mirror, diffuse);
        s.valid = s.valid & !wo.z().le(zero);
        (s, specular)
    }
}

impl Plastic<V8, F8, M8> {
    /// Sets lane `i` to `p`. Every field is taken apart here: a field added to [`Plastic`]
    /// fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, p: Plastic) {
        let Plastic {
            diffuse,
            specular,
            eta,
            nonlinear,
            fdr_int,
        } = p;
        self.diffuse.set(i, diffuse);
        self.specular.set(i, specular);
        self.eta.0[i] = eta;
        self.nonlinear.set(i, nonlinear);
        self.fdr_int.0[i] = fdr_int;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use pathlab_mc::rng::Pcg32;

    /// A direction uniform on the sphere.
    pub(crate) fn direction(rng: &mut Pcg32) -> Vec3 {
        let z = 2.0 * rng.uniform_f32() - 1.0;
        let phi = std::f32::consts::TAU * rng.uniform_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// The bits of a colour or direction.
    pub(crate) fn bits(v: Vec3) -> [u32; 3] {
        v.to_array().map(f32::to_bits)
    }

    /// Eight lanes of inputs for a test of a model's lanes against one material: each
    /// lane's material, the directions wo and wi, and a sample's numbers uc and u.
    pub(crate) struct LaneInputs<T> {
        pub(crate) one: Vec<T>,
        pub(crate) wo: V8,
        pub(crate) wi: V8,
        pub(crate) uc: F8,
        pub(crate) u: [F8; 2],
    }

    impl<T> LaneInputs<T> {
        /// Each lane's material and directions (wo, wi) from `lane(rng, i)`, and then its
        /// sample's numbers uc, u0 and u1, all drawn from `rng` lane after lane.
        pub(crate) fn draw(
            rng: &mut Pcg32,
            mut lane: impl FnMut(&mut Pcg32, usize) -> (T, Vec3, Vec3),
        ) -> Self {
            let mut inputs = LaneInputs {
                one: Vec::with_capacity(8),
                wo: V8::default(),
                wi: V8::default(),
                uc: F8::default(),
                u: [F8::default(); 2],
            };
            for i in 0..8 {
                let (material, o, w) = lane(rng, i);
                inputs.one.push(material);
                inputs.wo.set(i, o);
                inputs.wi.set(i, w);
                let [u0, u1] = &mut inputs.u;
                (inputs.uc.0[i], u0.0[i], u1.0[i]) =
                    (rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
            }
            inputs
        }

        /// Lane `i`'s wo, wi, uc and u.
        pub(crate) fn lane(&self, i: usize) -> (Vec3, Vec3, f32, Vec2) {
            let u = Vec2::new(self.u[0].0[i], self.u[1].0[i]);
            (self.wo.get(i), self.wi.get(i), self.uc.0[i], u)
        }
    }

    /// Asserts that lane `i` of `f` and `pdf` are `one`'s (f, pdf), to the bit.
    pub(crate) fn assert_lane_f_pdf(f: V8, pdf: F8, i: usize, one: (Vec3, f32), what: &str) {
        assert_eq!(bits(f.get(i)), bits(one.0), "f, lane {i}: {what}");
        assert_eq!(pdf.0[i].to_bits(), one.1.to_bits(), "pdf, lane {i}: {what}");
    }

    /// Asserts that lane `i` of `s` is the one-direction sample `one`, to the bit: there
    /// where it is, of the same direction, value and density. Returns `one`.
    pub(crate) fn assert_lane_sample(
        s: &DirectionSample<V8>,
        i: usize,
        one: Option<LocalSample>,
        what: &str,
    ) -> Option<LocalSample> {
        assert_eq!(s.valid.get(i), one.is_some(), "sample, lane {i}: {what}");
        if let Some(one) = one {
            assert_eq!(bits(s.wi.get(i)), bits(one.wi), "wi, lane {i}: {what}");
            assert_eq!(bits(s.f.get(i)), bits(one.f), "f, lane {i}: {what}");
            assert_eq!(
                s.pdf.0[i].to_bits(),
                one.pdf.to_bits(),
                "pdf, lane {i}: {what}"
            );
        }
        one
    }

    /// Eight lanes of smooth plastic compute, lane by lane, what one plastic computes, to the
    /// bit: f, pdf and the sample (which lobe included), linear and not, for directions on
    /// both sides and on the horizon, of coats that reflect and of a black one.
    #[test]
    fn lanes_compute_what_one_plastic_computes() {
        let mut rng = Pcg32::new(3, 5);
        let (mut seen, mut specular, mut diffuse) = (0, 0, 0);
        for round in 0..400 {
            let case = LaneInputs::draw(&mut rng, |rng, i| {
                let rho = Vec3::new(rng.uniform_f32(), 0.5, rng.uniform_f32());
                let eta = [1.5, 1.33, 2.4, 1.05][(round + i) % 4];
                let s = [1.0, 0.0, 0.4][(round + i) % 3];
                let p = Plastic::new(rho, eta, i % 2 == 0).with_specular(Vec3::new(s, 1.0, s));
                let (o, mut w) = (direction(rng), direction(rng));
                if round % 5 == 2 {
                    w.z = 0.0;
                }
                (p, o, w)
            });
            let mut lanes = Plastic::<V8, F8, M8>::default();
            for (i, p) in case.one.iter().enumerate() {
                lanes.set_lane(i, *p);
            }
            let (f, pdf) = lanes.f_and_pdf(case.wo, case.wi);
            let (s, delta) = lanes.sample_real(case.wo, case.uc, case.u[0], case.u[1]);
            for (i, p) in case.one.iter().enumerate() {
                let (o, w, uc, u) = case.lane(i);
                let what = format!("{o} {w}");
                assert_lane_f_pdf(f, pdf, i, (p.f(o, w), p.pdf(o, w)), &what);
                if let Some(scalar) = assert_lane_sample(&s, i, p.sample(o, uc, u), &what) {
                    assert_eq!(delta.get(i), scalar.delta, "lane {i}");
                    if scalar.delta {
                        specular += 1;
                    } else {
                        diffuse += 1;
                    }
                }
                seen += 1;
            }
        }
        // A guard that both lobes' samples are compared, not only the empty ones.
        assert!(
            specular * 20 > seen && diffuse * 4 > seen,
            "{specular} specular and {diffuse} diffuse samples of {seen}"
        );
    }
}
