//! Fresnel reflectance: exact for dielectrics and for conductors (complex index of
//! refraction), Schlick's approximation as the course's option, and the hemispherical
//! average of the dielectric reflectance that coated materials need.

use crate::simd::lanes::{Real, Vector3, F8, V8};
use glam::Vec3;

/// Fresnel reflectance of a smooth dielectric for light arriving at cos θi (positive: from the
/// outside, the side the normal points to) with relative index `eta` = n_inside / n_outside.
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    fresnel_dielectric_real(cos_theta_i, eta)
}

/// [`fresnel_dielectric`] written once for one value and for lanes.
#[inline(always)]
pub fn fresnel_dielectric_real<R: Real>(cos_theta_i: R, eta: R) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    // From inside: the angle's cosine on the inside and the index seen from there.
    let inside = cos_theta_i.lt(zero);
    let cos_i = R::select(inside, -cos_theta_i, cos_theta_i).min(one);
    let eta = R::select(inside, one / eta, eta);
    let sin2_t = (one - cos_i * cos_i) / (eta * eta);
    let cos_t = (one - sin2_t).max(zero).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    // Total internal reflection where sin²θt >= 1.
    R::select(
        one.le(sin2_t),
        one,
        R::splat(0.5) * (r_parl * r_parl + r_perp * r_perp),
    )
}

/// Schlick's approximation R0 + (1 - R0)(1 - cos θ)^5 of [`fresnel_dielectric`], with
/// R0 = ((η - 1)/(η + 1))², on the side with the smaller index (inside a denser medium it
/// uses the transmitted angle and is 1 past the critical angle).
pub fn fresnel_schlick(cos_theta_i: f32, eta: f32) -> f32 {
    fresnel_schlick_real(cos_theta_i, eta)
}

/// [`fresnel_schlick`] written once for one value and for lanes. The fifth power is
/// x · (x² · x²), the products `powi(5)` is expanded into.
#[inline(always)]
pub fn fresnel_schlick_real<R: Real>(cos_theta_i: R, eta: R) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let r = (eta - one) / (eta + one);
    let r0 = r * r;
    // From inside: the angle's cosine on the inside and the index seen from there.
    let inside = cos_theta_i.lt(zero);
    let cos_i = R::select(inside, -cos_theta_i, cos_theta_i);
    let eta_rel = R::select(inside, one / eta, eta);
    // Schlick's formula holds for the angle in the less dense medium: where light arrives
    // from the denser side, the transmitted angle's cosine (its square root is not taken
    // past the critical angle, where the reflectance is 1).
    let denser = eta_rel.lt(one);
    let sin2_t = (one - cos_i * cos_i) / (eta_rel * eta_rel);
    let total = denser & one.le(sin2_t);
    let cos = R::select(denser, (one - sin2_t).sqrt(), cos_i.min(one));
    let m = one - cos;
    let m2 = m * m;
    let f = r0 + (one - r0) * ((m2 * m2) * m);
    R::select(total, one, f)
}

/// A complex number over a [`Real`] (one value or lanes), only as much as the conductor
/// Fresnel equations need. Its arithmetic is inlined always: in the lanes' large scattering
/// function the compiler would otherwise call it, each operand passed through memory.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex<R> {
    re: R,
    im: R,
}

impl<R: Real> Complex<R> {
    #[inline(always)]
    fn new(re: R, im: R) -> Self {
        Complex { re, im }
    }
    #[inline(always)]
    fn real(re: R) -> Self {
        Complex::new(re, R::splat(0.0))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    #[inline(always)]
    fn scale(self, s: R) -> Self {
        Complex::new(self.re * s, self.im * s)
    }
    #[inline(always)]
    fn norm2(self) -> R {
        self.re * self.re + self.im * self.im
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let d = o.norm2();
        Complex::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// The principal square root (non-negative real part; zero at zero).
    #[inline(always)]
    fn sqrt(self) -> Self {
        let zero = R::splat(0.0);
        let r = self.norm2().sqrt();
        let re = (R::splat(0.5) * (r + self.re)).max(zero).sqrt();
        let im = (R::splat(0.5) * (r - self.re)).max(zero).sqrt();
        let at_zero = r.equals(zero);
        Complex::new(
            R::select(at_zero, zero, re),
            R::select(at_zero, zero, R::select(self.im.lt(zero), -im, im)),
        )
    }
}

/// Fresnel reflectance (unpolarised) of a conductor with complex relative index η + i k, for
/// light arriving at cos θi ∈ [0, 1] from the outside.
pub fn fresnel_conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    fresnel_conductor_real(cos_theta_i, eta, k)
}

/// [`fresnel_conductor`] of the three channels' indices at once, in the lanes of one [`F8`]:
/// each channel to the bit as [`fresnel_conductor`] gives it.
pub fn fresnel_conductor_rgb(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    // The five spare lanes repeat the first channel (any finite index would do).
    let lanes = |v: Vec3| F8([v.x, v.y, v.z, v.x, v.x, v.x, v.x, v.x]);
    let f = fresnel_conductor_real(F8::splat(cos_theta_i), lanes(eta), lanes(k));
    Vec3::new(f.0[0], f.0[1], f.0[2])
}

/// [`fresnel_conductor`] of each channel of a colour: one colour (`Vec3`, by
/// [`fresnel_conductor_rgb`]) or eight lanes' ([`V8`], a channel at a time), to the bit the
/// same.
pub trait ConductorFresnel: Vector3 {
    /// The reflectance per channel at cos θi with index `eta` + i `k` per channel.
    fn fresnel_conductor(cos_theta_i: Self::R, eta: Self, k: Self) -> Self;
}

impl ConductorFresnel for Vec3 {
    #[inline(always)]
    fn fresnel_conductor(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
        fresnel_conductor_rgb(cos_theta_i, eta, k)
    }
}

impl ConductorFresnel for V8 {
    #[inline(always)]
    fn fresnel_conductor(cos_theta_i: F8, eta: V8, k: V8) -> V8 {
        V8 {
            x: fresnel_conductor_real(cos_theta_i, eta.x, k.x),
            y: fresnel_conductor_real(cos_theta_i, eta.y, k.y),
            z: fresnel_conductor_real(cos_theta_i, eta.z, k.z),
        }
    }
}

/// [`fresnel_conductor`] written once for one value and for lanes.
#[inline(always)]
fn fresnel_conductor_real<R: Real>(cos_theta_i: R, eta: R, k: R) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    // `clamp(0, 1)` (NaN stays NaN).
    let cos_i = R::select(cos_theta_i.lt(zero), zero, cos_theta_i);
    let cos_i = R::select(cos_i.gt(one), one, cos_i);
    let sin2_i = one - cos_i * cos_i;
    let n = Complex::new(eta, k);
    let sin2_t = Complex::real(sin2_i).div(n.mul(n));
    let cos_t = Complex::real(one).sub(sin2_t).sqrt();
    let n_cos_i = n.scale(cos_i);
    let r_parl = n_cos_i.sub(cos_t).div(n_cos_i.add(cos_t));
    let ci = Complex::real(cos_i);
    let n_cos_t = n.mul(cos_t);
    let r_perp = ci.sub(n_cos_t).div(ci.add(n_cos_t));
    R::splat(0.5) * (r_parl.norm2() + r_perp.norm2())
}

/// Hemispherical average 2 ∫ F(μ) μ dμ of the dielectric Fresnel reflectance for light
/// arriving from the side with index 1 (`eta` > 0 is the other side's relative index; pass
/// 1/η for light arriving from inside). Midpoint rule on 4096 intervals.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    const N: usize = 4096;
    let sum: f64 = (0..N)
        .map(|i| {
            let mu = (i as f64 + 0.5) / N as f64;
            fresnel_dielectric(mu as f32, eta) as f64 * mu
        })
        .sum();
    (2.0 * sum / N as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_dielectric_values() {
        // Normal incidence: ((η - 1)/(η + 1))².
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Grazing incidence reflects everything; beyond the critical angle inside, too.
        assert!(fresnel_dielectric(1e-6, 1.5) > 0.999);
        let critical = (1.0f32 / 1.5).asin();
        assert_eq!(fresnel_dielectric(-(critical + 0.01).cos(), 1.5), 1.0);
        assert!(fresnel_dielectric(-(critical - 0.05).cos(), 1.5) < 1.0);
        // Brewster's angle: the parallel component vanishes, F = r_perp² / 2.
        let brewster = 1.5f32.atan();
        let f = fresnel_dielectric(brewster.cos(), 1.5);
        assert!(f > 0.0 && f < 0.1);
    }

    #[test]
    fn three_channels_at_once_are_each_channel_alone() {
        // Every channel of the lanes' Fresnel is the one-value Fresnel's, to the bit, over
        // angles from grazing to normal (and outside [0, 1], and NaN) and indices of metals,
        // a dielectric (k = 0) and an index of one.
        let mut rng = pathlab_mc::rng::Pcg32::new(11, 3);
        let mut cosines = vec![0.0f32, 1.0, -0.5, 1.5, 1e-7, f32::NAN];
        cosines.extend((0..200).map(|_| rng.uniform_f32()));
        let indices = [
            (
                Vec3::new(0.143, 0.374, 1.442),
                Vec3::new(3.983, 2.385, 1.603),
            ),
            (Vec3::new(1.5, 1.0, 0.2), Vec3::new(0.0, 0.0, 3.9)),
            (Vec3::new(2.8, 0.05, 1.0), Vec3::new(1e-3, 5.0, 0.0)),
        ];
        for (eta, k) in indices {
            for &c in &cosines {
                let f = fresnel_conductor_rgb(c, eta, k);
                for (got, (e, kk)) in f
                    .to_array()
                    .into_iter()
                    .zip(eta.to_array().into_iter().zip(k.to_array()))
                {
                    let want = fresnel_conductor(c, e, kk);
                    assert!(
                        got.to_bits() == want.to_bits(),
                        "cos {c}, eta {e}, k {kk}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn conductor_fresnel_matches_known_values() {
        // k = 0 is a dielectric.
        for &c in &[1.0f32, 0.7, 0.3, 0.05] {
            let (a, b) = (fresnel_conductor(c, 1.5, 0.0), fresnel_dielectric(c, 1.5));
            assert!((a - b).abs() < 1e-5, "cos {c}: {a} vs {b}");
        }
        // Normal incidence: ((η-1)² + k²) / ((η+1)² + k²); gold's red channel.
        let (eta, k) = (0.143f32, 3.983f32);
        let r0 = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        assert!((fresnel_conductor(1.0, eta, k) - r0).abs() < 1e-5);
        // Grazing incidence reflects everything.
        assert!(fresnel_conductor(1e-4, eta, k) > 0.999);
        // A perfect conductor (η = 0, k = 1) reflects everything at every angle.
        for &c in &[1.0f32, 0.5, 0.1] {
            assert!((fresnel_conductor(c, 0.0, 1.0) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn schlick_is_close_to_exact_and_exact_at_the_ends() {
        assert!((fresnel_schlick(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_schlick(0.0, 1.5) - 1.0).abs() < 1e-6);
        // Schlick's error for glass peaks at 0.0357 (cos θ ≈ 0.09), about 0.02 mid-range.
        for i in 1..100 {
            let c = i as f32 / 100.0;
            let err = (fresnel_schlick(c, 1.5) - fresnel_dielectric(c, 1.5)).abs();
            assert!(err < 0.036, "cos {c}: {err}");
        }
        let critical = (1.0f32 / 1.5).asin();
        assert_eq!(fresnel_schlick(-(critical + 0.01).cos(), 1.5), 1.0);
    }

    #[test]
    fn diffuse_reflectances_obey_the_reciprocity_relation() {
        // Energy balance across an interface: 1 - F_ext = η² (1 - F_int).
        for &eta in &[1.33f32, 1.5, 2.0] {
            let ext = fresnel_diffuse_reflectance(eta);
            let int = fresnel_diffuse_reflectance(1.0 / eta);
            assert!(
                ((1.0 - ext) - eta * eta * (1.0 - int)).abs() < 1e-4,
                "η {eta}: {ext} {int}"
            );
        }
        // Known value for η = 1.5: F_dr ≈ 0.0918 from outside.
        assert!((fresnel_diffuse_reflectance(1.5) - 0.0918).abs() < 1e-3);
    }
}
