//! The BSDFs the statistical tests run, at the roughnesses and angles they take.

use glam::Vec3;
use pathlab_render::bsdf::*;
use pathlab_render::desc::Rgb;

pub fn gold() -> (Rgb, Rgb) {
    (
        Vec3::new(0.143, 0.374, 1.442),
        Vec3::new(3.983, 2.385, 1.603),
    )
}

pub fn conductor(kind: NormalDistribution, alpha: f32) -> Bxdf {
    let (eta, k) = gold();
    Bxdf::Conductor(Conductor {
        specular: glam::Vec3::ONE,
        eta,
        k,
        distribution: Some(Microfacet::new(kind, alpha)),
    })
}

pub fn anisotropic_conductor(kind: NormalDistribution, ax: f32, ay: f32) -> Bxdf {
    let (eta, k) = gold();
    Bxdf::Conductor(Conductor {
        specular: glam::Vec3::ONE,
        eta,
        k,
        distribution: Some(Microfacet::anisotropic(kind, ax, ay)),
    })
}

pub fn rough_plastic(kind: NormalDistribution, alpha: f32) -> Bxdf {
    Bxdf::RoughPlastic(RoughPlastic::new(
        Vec3::new(0.2, 0.5, 0.3),
        Vec3::ONE,
        1.5,
        Microfacet::new(kind, alpha),
        false,
    ))
}

/// Mitsuba's principled material: a solid with every lobe on (`thin` false) or a thin sheet
/// with specular and diffuse transmission.
pub fn principled(thin: bool, roughness: f32) -> Bxdf {
    let flags = PrincipledFlags {
        anisotropic: true,
        spec_trans: true,
        metallic: true,
        clearcoat: !thin,
        sheen: true,
        sheen_tint: true,
        spec_tint: true,
        flatness: thin,
        diff_trans: thin,
    };
    Bxdf::Principled(Principled {
        base_color: Vec3::new(0.6, 0.3, 0.2),
        roughness,
        anisotropic: 0.4,
        spec_trans: 0.4,
        metallic: if thin { 0.0 } else { 0.3 },
        clearcoat: 0.7,
        clearcoat_gloss: 0.5,
        sheen: 0.3,
        sheen_tint: 0.5,
        spec_tint: 0.3,
        flatness: 0.4,
        diff_trans: 0.6,
        eta: 1.5,
        flags,
        thin,
    })
}

/// A direction at polar angle `theta_deg` and azimuth `phi_deg`, above.
pub fn wo_at_azimuth(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

pub fn rough_glass(kind: NormalDistribution, alpha: f32) -> Bxdf {
    Bxdf::RoughDielectric(RoughDielectric {
        eta: 1.5,
        distribution: Microfacet::new(kind, alpha),
        reflectance: Vec3::ONE,
        transmittance: Vec3::ONE,
    })
}

pub fn anisotropic_rough_glass(kind: NormalDistribution, ax: f32, ay: f32) -> Bxdf {
    Bxdf::RoughDielectric(RoughDielectric {
        distribution: Microfacet::anisotropic(kind, ax, ay),
        ..match rough_glass(kind, ax) {
            Bxdf::RoughDielectric(g) => g,
            _ => unreachable!(),
        }
    })
}

pub fn plastic(diffuse: f32, nonlinear: bool) -> Bxdf {
    Bxdf::Plastic(Plastic::new(Vec3::splat(diffuse), 1.5, nonlinear))
}

pub fn diffuse() -> Bxdf {
    Bxdf::Diffuse(Diffuse {
        reflectance: Vec3::splat(0.7),
    })
}

/// Diffuse reflection and transmission of different colours (reflection chosen with
/// probability 0.6 / (0.6 + 0.5)).
pub fn diffuse_transmission() -> Bxdf {
    Bxdf::DiffuseTransmission(DiffuseTransmission {
        reflectance: Vec3::new(0.6, 0.3, 0.1),
        transmittance: Vec3::new(0.2, 0.5, 0.4),
    })
}

/// A direction at polar angle `theta_deg` in the xz-plane (φ = 0), above or below.
pub fn wo_at(theta_deg: f32, below: bool) -> Vec3 {
    let t = theta_deg.to_radians();
    let z = if below { -t.cos() } else { t.cos() };
    Vec3::new(t.sin(), 0.0, z)
}
