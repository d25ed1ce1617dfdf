//! BSDFs in the local shading frame (z = shading normal). `f(wo, wi)` excludes the cosine;
//! the integrator multiplies by |cos θi|. Both directions point away from the surface.

use crate::desc::{MaterialDesc, Rgb};
use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use std::f32::consts::FRAC_1_PI;

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// BSDF value f(wo, wi).
    pub f: Rgb,
    /// The sampled direction, in world space.
    pub wi: Vec3,
    /// Its density per unit solid angle, or for a delta lobe the probability of choosing it.
    pub pdf: f32,
    /// Whether the direction comes from a delta lobe (mirror reflection, refraction): no other
    /// strategy could have produced it, so MIS gives it weight one.
    pub delta: bool,
}

/// The reflectance model of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bxdf {
    /// Lambertian: f = reflectance / π on the upper hemisphere.
    Diffuse {
        /// Albedo.
        reflectance: Rgb,
    },
    /// Perfect specular reflection, wi = (-wo.x, -wo.y, wo.z), scaled by `reflectance`.
    Mirror {
        /// Reflectance.
        reflectance: Rgb,
    },
    /// A smooth dielectric interface (glass): exact Fresnel reflectance F chooses reflection
    /// with probability F and refraction (Snell's law) otherwise; total internal reflection
    /// beyond the critical angle. Radiance crossing the interface is scaled by 1/η² (η the
    /// relative index in the direction of travel), as radiance transport requires.
    Dielectric {
        /// Index of refraction inside (below the normal) relative to outside.
        eta: f32,
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the transmitted part.
        transmittance: Rgb,
    },
}

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

/// Refracts `wo` (local frame, z = normal) through an interface of relative index `eta`
/// (inside / outside); `None` under total internal reflection. Returns wi and the relative
/// index η' along the path (η for entering, 1/η for leaving).
pub fn refract(wo: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (cos_o, etap, sign) = if wo.z > 0.0 {
        (wo.z, eta, 1.0)
    } else {
        (-wo.z, 1.0 / eta, -1.0)
    };
    let sin2_t = (1.0 - cos_o * cos_o).max(0.0) / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wi = Vec3::new(-wo.x / etap, -wo.y / etap, -sign * cos_t);
    Some((wi.normalize(), etap))
}

/// A material: its BxDF and whether its back side reflects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Reflectance model.
    pub bxdf: Bxdf,
    /// Whether the back side of the surface reflects too.
    pub two_sided: bool,
}

impl From<&MaterialDesc> for Material {
    /// The material for a description. Materials whose BSDF is not implemented yet (rough
    /// glass, conductors other than a perfect mirror) are approximated by a two-sided diffuse
    /// surface of a similar overall colour; loaders warn when they produce one.
    fn from(d: &MaterialDesc) -> Self {
        let diffuse = |reflectance: Rgb, two_sided| Material {
            bxdf: Bxdf::Diffuse {
                reflectance: reflectance.clamp(Vec3::ZERO, Vec3::ONE),
            },
            two_sided,
        };
        match *d {
            MaterialDesc::Diffuse {
                reflectance,
                two_sided,
            } => diffuse(reflectance, two_sided),
            MaterialDesc::Mirror { reflectance } => Material {
                bxdf: Bxdf::Mirror { reflectance },
                two_sided: true,
            },
            MaterialDesc::Glass {
                reflectance,
                transmittance,
                roughness,
                ior,
            } if roughness == 0.0 && ior > 0.0 && ior.is_finite() => Material {
                bxdf: Bxdf::Dielectric {
                    eta: ior,
                    reflectance,
                    transmittance,
                },
                // The side matters: inside and outside differ.
                two_sided: false,
            },
            MaterialDesc::Glass { transmittance, .. } => diffuse(transmittance * 0.8, true),
            MaterialDesc::Conductor { alpha, eta, k }
                if alpha == 0.0 && is_perfect_mirror(eta, k) =>
            {
                Material {
                    bxdf: Bxdf::Mirror {
                        reflectance: Vec3::ONE,
                    },
                    two_sided: true,
                }
            }
            MaterialDesc::Conductor { eta, k, .. } => {
                // Normal-incidence Fresnel reflectance of the conductor.
                let f0 = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
                diffuse(f0, true)
            }
        }
    }
}

/// Whether a conductor's index (η, k) reflects everything at every angle (η = 0, k = 1: the
/// value Mitsuba's parameterless `conductor` stands for).
fn is_perfect_mirror(eta: Rgb, k: Rgb) -> bool {
    eta.max_element() == 0.0 && (k - Vec3::ONE).abs().max_element() == 0.0
}

/// Whether the renderer draws this material as described (false: a diffuse stand-in).
pub fn is_supported(d: &MaterialDesc) -> bool {
    match *d {
        MaterialDesc::Diffuse { .. } | MaterialDesc::Mirror { .. } => true,
        MaterialDesc::Glass { roughness, ior, .. } => {
            roughness == 0.0 && ior > 0.0 && ior.is_finite()
        }
        MaterialDesc::Conductor { alpha, eta, k } => alpha == 0.0 && is_perfect_mirror(eta, k),
    }
}

/// A material at a surface point: the BxDF and the shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    frame: Frame,
    bxdf: Bxdf,
}

impl Bsdf {
    /// The BSDF of `material` at a point with unit shading normal `n`, seen from direction
    /// `wo`. A two-sided material is evaluated on the side `wo` is on; a one-sided one keeps
    /// its normal, and reflects nothing when seen from behind.
    pub fn new(material: &Material, n: Vec3, wo: Vec3) -> Self {
        let n = if material.two_sided && wo.dot(n) < 0.0 {
            -n
        } else {
            n
        };
        Bsdf {
            frame: Frame::from_normal(n),
            bxdf: material.bxdf,
        }
    }

    /// The shading normal (flipped towards `wo` for two-sided materials).
    pub fn normal(&self) -> Vec3 {
        self.frame.n
    }

    /// The local shading frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// f(wo, wi), world-space directions.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let (wo, wi) = (self.frame.to_local(wo), self.frame.to_local(wi));
        match self.bxdf {
            Bxdf::Diffuse { reflectance } => {
                if wo.z > 0.0 && wi.z > 0.0 {
                    reflectance * FRAC_1_PI
                } else {
                    Rgb::ZERO
                }
            }
            // Delta lobes: zero for every pair of directions a non-delta strategy can produce.
            Bxdf::Mirror { .. } | Bxdf::Dielectric { .. } => Rgb::ZERO,
        }
    }

    /// Whether every lobe is a delta distribution (light sampling can never help).
    pub fn is_delta(&self) -> bool {
        matches!(self.bxdf, Bxdf::Mirror { .. } | Bxdf::Dielectric { .. })
    }

    /// Samples wi given wo (cosine-weighted for the diffuse model; the delta lobes for mirror
    /// and glass, choosing between reflection and refraction with `u.x`).
    pub fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let wo_local = self.frame.to_local(wo);
        match self.bxdf {
            Bxdf::Mirror { reflectance } => {
                if wo_local.z == 0.0 {
                    return None;
                }
                let wi = Vec3::new(-wo_local.x, -wo_local.y, wo_local.z);
                Some(BsdfSample {
                    f: reflectance / wi.z.abs(),
                    wi: self.frame.to_world(wi),
                    pdf: 1.0,
                    delta: true,
                })
            }
            Bxdf::Dielectric {
                eta,
                reflectance,
                transmittance,
            } => {
                if wo_local.z == 0.0 {
                    return None;
                }
                let f = fresnel_dielectric(wo_local.z, eta);
                if u.x < f {
                    let wi = Vec3::new(-wo_local.x, -wo_local.y, wo_local.z);
                    return Some(BsdfSample {
                        f: reflectance * (f / wi.z.abs()),
                        wi: self.frame.to_world(wi),
                        pdf: f,
                        delta: true,
                    });
                }
                let (wi, etap) = refract(wo_local, eta)?;
                let t = 1.0 - f;
                Some(BsdfSample {
                    f: transmittance * (t / (wi.z.abs() * etap * etap)),
                    wi: self.frame.to_world(wi),
                    pdf: t,
                    delta: true,
                })
            }
            Bxdf::Diffuse { reflectance } => {
                if wo_local.z <= 0.0 {
                    return None;
                }
                let wi = sample_cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(wi.z);
                (pdf > 0.0).then(|| BsdfSample {
                    f: reflectance * FRAC_1_PI,
                    wi: self.frame.to_world(wi),
                    pdf,
                    delta: false,
                })
            }
        }
    }

    /// Density of [`Bsdf::sample_f`] choosing `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (self.frame.to_local(wo), self.frame.to_local(wi));
        match self.bxdf {
            Bxdf::Diffuse { .. } => {
                if wo.z > 0.0 && wi.z > 0.0 {
                    cosine_hemisphere_pdf(wi.z)
                } else {
                    0.0
                }
            }
            Bxdf::Mirror { .. } | Bxdf::Dielectric { .. } => 0.0,
        }
    }
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
    fn refraction_obeys_snell() {
        for &(theta, eta) in &[(0.3f32, 1.5f32), (1.2, 1.33), (0.7, 1.0 / 1.5)] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            match refract(wo, eta) {
                Some((wi, etap)) => {
                    assert!(wi.z < 0.0);
                    let sin_t = (wi.x * wi.x + wi.y * wi.y).sqrt();
                    assert!((theta.sin() - etap * sin_t).abs() < 1e-5, "{theta} {eta}");
                    // Back through the interface returns the original direction.
                    let (back, _) = refract(wi, eta).unwrap();
                    assert!((back - wo).length() < 1e-4);
                }
                None => assert!(theta.sin() / eta > 1.0),
            }
        }
    }

    #[test]
    fn glass_sampling_conserves_energy() {
        // Without absorption, the expected throughput f |cos| / pdf of one sample is one on
        // both sides (radiance scaling aside): reflection F/F and transmission (1-F)/(1-F).
        let m = Material {
            bxdf: Bxdf::Dielectric {
                eta: 1.5,
                reflectance: Vec3::ONE,
                transmittance: Vec3::ONE,
            },
            two_sided: false,
        };
        let bsdf = Bsdf::new(&m, Vec3::Z, Vec3::Z);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let (mut reflected, n) = (0, 10_000);
        for i in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, 0.5);
            let s = bsdf.sample_f(wo, u).unwrap();
            let weight = s.f * s.wi.z.abs() / s.pdf;
            if s.wi.z > 0.0 {
                reflected += 1;
                assert!((weight - Vec3::ONE).abs().max_element() < 1e-5);
            } else {
                assert!((weight * 1.5 * 1.5 - Vec3::ONE).abs().max_element() < 1e-4);
            }
            assert!(s.delta);
        }
        // The fraction reflected is the Fresnel reflectance (stratified u: exact up to 1/n).
        let f = fresnel_dielectric(0.8, 1.5);
        assert!((reflected as f32 / n as f32 - f).abs() <= 1.0 / n as f32 + 1e-6);
        let mirror = Bsdf::new(
            &Material {
                bxdf: Bxdf::Mirror {
                    reflectance: Vec3::splat(0.7),
                },
                two_sided: true,
            },
            Vec3::Z,
            wo,
        );
        let s = mirror.sample_f(wo, Vec2::ZERO).unwrap();
        assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
        assert!(
            (s.f * s.wi.z / s.pdf - Vec3::splat(0.7))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(mirror.f(wo, s.wi), Vec3::ZERO);
        assert_eq!(mirror.pdf(wo, s.wi), 0.0);
    }
}
