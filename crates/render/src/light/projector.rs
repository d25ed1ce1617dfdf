//! Projectors: Mitsuba's textured spot light and projector, a texture seen through a pinhole.

use crate::color::luminance;
use crate::desc::{ProjectorKind, Rgb, SpotFalloff};
use crate::texture::{Tex, TexPoint};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;

/// A point light shining through an image plane: Mitsuba's `spot` and `projector`.
#[derive(Clone, Debug, PartialEq)]
pub struct Projector {
    /// Position.
    pub position: Vec3,
    /// Rotation from world to the light's frame (rows: its x, y, z axes).
    pub to_local: Mat3,
    /// The image.
    pub texture: Tex,
    /// The profile.
    pub kind: ProjectorKind,
}

impl Projector {
    /// Radiant intensity towards local direction `d` (unit).
    pub fn intensity(&self, d: Vec3) -> Rgb {
        if d.z <= 0.0 {
            return Rgb::ZERO;
        }
        match self.kind {
            ProjectorKind::Spot {
                intensity,
                cutoff,
                beam_width,
                falloff,
            } => {
                let cos = d.z;
                let cos_cutoff = cutoff.cos();
                if cos <= cos_cutoff {
                    return Rgb::ZERO;
                }
                let cos_beam = beam_width.cos();
                let falloff = if cos >= cos_beam {
                    1.0
                } else {
                    match falloff {
                        SpotFalloff::LinearInAngle => {
                            (cutoff - cos.clamp(-1.0, 1.0).acos()) / (cutoff - beam_width)
                        }
                        SpotFalloff::SmoothStepInCosine => {
                            let t = ((cos - cos_cutoff) / (cos_beam - cos_cutoff)).clamp(0.0, 1.0);
                            t * t * (3.0 - 2.0 * t)
                        }
                    }
                };
                let k = 0.5 / (d.z * cutoff.tan());
                let uv = Vec2::new(0.5 + d.x * k, 0.5 - d.y * k);
                intensity * self.texture.eval(&TexPoint::uv(uv)) * falloff
            }
            ProjectorKind::Projector {
                scale,
                tan_half_fov_x,
                aspect,
            } => {
                let x = d.x / (d.z * tan_half_fov_x);
                let y = aspect * d.y / (d.z * tan_half_fov_x);
                let uv = Vec2::new(0.5 - 0.5 * x, 0.5 + 0.5 * y);
                if !(0.0..=1.0).contains(&uv.x) || !(0.0..=1.0).contains(&uv.y) {
                    return Rgb::ZERO;
                }
                let cos3 = d.z * d.z * d.z;
                self.texture.eval(&TexPoint::uv(uv)) * (PI * scale / cos3)
            }
        }
    }

    /// The power it emits (luminance), for choosing lights: ∫ I dω over the image's cone,
    /// estimated on a grid of directions.
    pub(super) fn phi(&self) -> f32 {
        let n = 32;
        let mut sum = 0.0f64;
        // Directions over the hemisphere z > 0, equal-area in (cos θ, φ).
        for i in 0..n {
            for j in 0..n {
                let z = (i as f32 + 0.5) / n as f32;
                let phi = (j as f32 + 0.5) / n as f32 * std::f32::consts::TAU;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                sum += luminance(self.intensity(d)) as f64;
            }
        }
        (sum * std::f64::consts::TAU / (n * n) as f64) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(falloff: SpotFalloff) -> Projector {
        Projector {
            position: Vec3::ZERO,
            to_local: Mat3::IDENTITY,
            texture: Tex::Constant(Rgb::ONE),
            kind: ProjectorKind::Spot {
                intensity: Rgb::splat(2.0),
                cutoff: 30f32.to_radians(),
                beam_width: 20f32.to_radians(),
                falloff,
            },
        }
    }

    fn at_angle(deg: f32) -> Vec3 {
        let t = deg.to_radians();
        Vec3::new(t.sin(), 0.0, t.cos())
    }

    #[test]
    fn spot_falloffs_follow_their_definitions() {
        let (cos_cut, cos_beam) = (30f32.to_radians().cos(), 20f32.to_radians().cos());
        for deg in [
            0.0f32, 10.0, 20.0, 22.0, 25.0, 28.0, 29.9, 30.0, 45.0, 100.0,
        ] {
            let linear = spot(SpotFalloff::LinearInAngle).intensity(at_angle(deg)).x;
            let smooth = spot(SpotFalloff::SmoothStepInCosine)
                .intensity(at_angle(deg))
                .x;
            let t = ((at_angle(deg).z - cos_cut) / (cos_beam - cos_cut)).clamp(0.0, 1.0);
            let expected_smooth = if deg >= 30.0 {
                0.0
            } else {
                2.0 * t * t * (3.0 - 2.0 * t)
            };
            let expected_linear = 2.0 * ((30.0 - deg) / 10.0).clamp(0.0, 1.0);
            assert!((smooth - expected_smooth).abs() < 1e-5, "{deg}°: {smooth}");
            assert!((linear - expected_linear).abs() < 1e-4, "{deg}°: {linear}");
        }
        // pbrt-v4's power normalisation: ∫ I dω = 2π I ((1 - cos beam) + (cos beam - cos cutoff) / 2),
        // the smoothstep averaging ½ over the falloff band in cos θ.
        let exact = std::f32::consts::TAU * 2.0 * ((1.0 - cos_beam) + 0.5 * (cos_beam - cos_cut));
        let n = 200_000;
        let sum: f64 = (0..n)
            .map(|i| {
                let z = 1.0 - (1.0 - cos_cut) * (i as f32 + 0.5) / n as f32;
                let d = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
                spot(SpotFalloff::SmoothStepInCosine).intensity(d).x as f64
            })
            .sum();
        let integral = sum * std::f64::consts::TAU * (1.0 - cos_cut as f64) / n as f64;
        assert!(
            (integral - exact as f64).abs() < 1e-4 * exact as f64,
            "{integral} vs {exact}"
        );
    }
}
