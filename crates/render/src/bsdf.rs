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
    /// Its density per unit solid angle.
    pub pdf: f32,
}

/// The reflectance model of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bxdf {
    /// Lambertian: f = reflectance / π on the upper hemisphere.
    Diffuse {
        /// Albedo.
        reflectance: Rgb,
    },
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
    /// The material for a description. Materials whose BSDF is not implemented yet (mirror,
    /// glass, conductor) are approximated by a two-sided diffuse surface of a similar overall
    /// colour; loaders warn when they produce one.
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
            MaterialDesc::Mirror { reflectance } => diffuse(reflectance * 0.8, true),
            MaterialDesc::Glass { transmittance, .. } => diffuse(transmittance * 0.8, true),
            MaterialDesc::Conductor { eta, k, .. } => {
                // Normal-incidence Fresnel reflectance of the conductor.
                let f0 = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
                diffuse(f0, true)
            }
        }
    }
}

/// Whether the renderer draws this material as described (false: a diffuse stand-in).
pub fn is_supported(d: &MaterialDesc) -> bool {
    matches!(d, MaterialDesc::Diffuse { .. })
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
        }
    }

    /// Samples wi given wo (cosine-weighted for the diffuse model).
    pub fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let wo_local = self.frame.to_local(wo);
        match self.bxdf {
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
        }
    }
}
