//! Projectors: Mitsuba's textured spot light and projector, a texture seen through a pinhole.

use crate::color::luminance;
use crate::desc::{ProjectorKind, Rgb};
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
            } => {
                let cos = d.z;
                if cos <= cutoff.cos() {
                    return Rgb::ZERO;
                }
                let falloff = if cos >= beam_width.cos() {
                    1.0
                } else {
                    (cutoff - cos.clamp(-1.0, 1.0).acos()) / (cutoff - beam_width)
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
