//! Fresnel reflectance: exact for dielectrics and for conductors (complex index of
//! refraction), Schlick's approximation as the course's option, and the hemispherical
//! average of the dielectric reflectance that coated materials need.

/// Fresnel reflectance of a smooth dielectric for light arriving at cos θi (positive: from the
/// outside, the side the normal points to) with relative index `eta` = n_inside / n_outside.
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_theta_i < 0.0 {
        (-cos_theta_i, 1.0 / eta)
    } else {
        (cos_theta_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Schlick's approximation R0 + (1 - R0)(1 - cos θ)^5 of [`fresnel_dielectric`], with
/// R0 = ((η - 1)/(η + 1))², on the side with the smaller index (inside a denser medium it
/// uses the transmitted angle and is 1 past the critical angle).
pub fn fresnel_schlick(cos_theta_i: f32, eta: f32) -> f32 {
    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    // Schlick's formula holds for the angle in the less dense medium.
    let (cos_i, eta_rel) = if cos_theta_i < 0.0 {
        (-cos_theta_i, 1.0 / eta)
    } else {
        (cos_theta_i, eta)
    };
    let cos = if eta_rel < 1.0 {
        let sin2_t = (1.0 - cos_i * cos_i) / (eta_rel * eta_rel);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    } else {
        cos_i.min(1.0)
    };
    r0 + (1.0 - r0) * (1.0 - cos).powi(5)
}

/// A complex number, only as much as the conductor Fresnel equations need.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex {
    re: f32,
    im: f32,
}

impl Complex {
    const fn new(re: f32, im: f32) -> Self {
        Complex { re, im }
    }
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, s: f32) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }
    fn norm2(self) -> f32 {
        self.re * self.re + self.im * self.im
    }
    fn div(self, o: Complex) -> Complex {
        let d = o.norm2();
        Complex::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// The principal square root (non-negative real part).
    fn sqrt(self) -> Complex {
        let r = self.norm2().sqrt();
        if r == 0.0 {
            return Complex::new(0.0, 0.0);
        }
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt();
        Complex::new(re, if self.im < 0.0 { -im } else { im })
    }
}

/// Fresnel reflectance (unpolarised) of a conductor with complex relative index η + i k, for
/// light arriving at cos θi ∈ [0, 1] from the outside.
pub fn fresnel_conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_theta_i.clamp(0.0, 1.0);
    let sin2_i = 1.0 - cos_i * cos_i;
    let n = Complex::new(eta, k);
    let sin2_t = Complex::new(sin2_i, 0.0).div(n.mul(n));
    let cos_t = Complex::new(1.0, 0.0).sub(sin2_t).sqrt();
    let n_cos_i = n.scale(cos_i);
    let r_parl = n_cos_i.sub(cos_t).div(n_cos_i.add(cos_t));
    let ci = Complex::new(cos_i, 0.0);
    let n_cos_t = n.mul(cos_t);
    let r_perp = ci.sub(n_cos_t).div(ci.add(n_cos_t));
    0.5 * (r_parl.norm2() + r_perp.norm2())
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
