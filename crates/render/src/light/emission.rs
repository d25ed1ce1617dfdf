//! Rays of emitted light (pbrt-v4's `SampleLe` and `PDF_Le`): where light subpaths of the
//! bidirectional path tracer start.
//!
//! A light that emits rays is sampled in two steps: a point (uniform by area on an area light's
//! shape, density `pdf_pos` per unit area; the position itself for point and spot lights, a
//! delta with `pdf_pos` one) and a direction from it (cosine-weighted about an area light's
//! normal, on a side chosen with probability ½ when both sides emit; uniform over the sphere
//! for a point light and over the cone for a spot light), density `pdf_dir` per unit solid
//! angle. Lights at infinity and projectors do not emit rays here ([`Light::emits_rays`]): the
//! bidirectional integrator reaches them from the camera side only.

use super::{AreaShape, Light};
use crate::desc::Rgb;
use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{
    cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_cone, sample_uniform_sphere,
    uniform_cone_pdf, uniform_sphere_pdf, uniform_triangle,
};

/// A ray of emitted light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLeSample {
    /// Where it leaves the light.
    pub p: Vec3,
    /// The light's surface normal there (area lights; none for points).
    pub n: Option<Vec3>,
    /// Its texture coordinates there (area lights).
    pub uv: Vec2,
    /// Unit direction of travel.
    pub w: Vec3,
    /// Radiance along `w` (area lights), or radiant intensity (point and spot lights).
    pub le: Rgb,
    /// Density of the point per unit area (one for a light at a point).
    pub pdf_pos: f32,
    /// Density of the direction per unit solid angle.
    pub pdf_dir: f32,
}

/// Whether an attenuation is the physical inverse square law, the only one light leaving a
/// point can follow.
fn physical(attenuation: [f32; 3]) -> bool {
    attenuation == [0.0, 0.0, 1.0]
}

impl Light {
    /// Whether [`Light::sample_le`] can start rays of light from it: area lights, and point and
    /// spot lights that fall off with the inverse square of distance.
    pub fn emits_rays(&self) -> bool {
        match self {
            Light::Area { .. } => true,
            Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } => {
                physical(*attenuation)
            }
            _ => false,
        }
    }

    /// Whether the light sits at one point (no ray can hit it).
    pub fn is_delta_position(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Projector(_)
        )
    }

    /// A ray of emitted light: the point from `u_pos`, the direction from `u_dir`. `None` for
    /// a light that does not emit rays, or a sample that carries nothing.
    pub fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<LightLeSample> {
        if !self.emits_rays() {
            return None;
        }
        match *self {
            Light::Area {
                shape,
                ref texture,
                two_sided,
                ..
            } => {
                let (p, n, pdf_pos, b) = match shape {
                    AreaShape::Triangle(t) => {
                        let b = uniform_triangle(u_pos.x, u_pos.y);
                        let [v0, v1, v2] = t.triangle.p;
                        (b[0] * v0 + b[1] * v1 + b[2] * v2, t.normal, t.pdf_area, b)
                    }
                    AreaShape::Sphere(s) => {
                        let ss = s.sample(u_pos);
                        (ss.p, ss.n, ss.pdf_area, [0.0; 3])
                    }
                };
                // Both sides: the first half of u_dir.x picks the front, stretched back to [0, 1).
                let (side, ux) = if !two_sided {
                    (n, u_dir.x)
                } else if u_dir.x < 0.5 {
                    (n, u_dir.x * 2.0)
                } else {
                    (-n, (u_dir.x - 0.5) * 2.0)
                };
                let local =
                    sample_cosine_hemisphere(Vec2::new(ux.min(1.0 - f32::EPSILON), u_dir.y));
                let w = Frame::from_normal(side).to_world(local);
                let uv = texture
                    .as_deref()
                    .map_or(Vec2::ZERO, |t| t.uv(&shape, p, b));
                let le = self.le(n, w, uv);
                let pdf_dir = self.pdf_le_dir(Some(n), w);
                (pdf_dir > 0.0 && le.max_element() > 0.0).then_some(LightLeSample {
                    p,
                    n: Some(n),
                    uv,
                    w,
                    le,
                    pdf_pos,
                    pdf_dir,
                })
            }
            Light::Point {
                position,
                intensity,
                ..
            } => Some(LightLeSample {
                p: position,
                n: None,
                uv: Vec2::ZERO,
                w: sample_uniform_sphere(u_dir),
                le: intensity,
                pdf_pos: 1.0,
                pdf_dir: uniform_sphere_pdf(),
            }),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_cutoff,
                exponent,
                ..
            } => {
                let w =
                    Frame::from_normal(direction).to_world(sample_uniform_cone(u_dir, cos_cutoff));
                let cos = direction.dot(w).max(0.0);
                Some(LightLeSample {
                    p: position,
                    n: None,
                    uv: Vec2::ZERO,
                    w,
                    le: intensity * cos.powf(exponent),
                    pdf_pos: 1.0,
                    pdf_dir: uniform_cone_pdf(cos_cutoff),
                })
            }
            _ => None,
        }
    }

    /// Density per unit area with which [`Light::sample_le`] chooses a point of the light (one
    /// for a light at a point; zero for one that does not emit rays).
    pub fn pdf_le_pos(&self) -> f32 {
        if !self.emits_rays() {
            return 0.0;
        }
        match *self {
            Light::Area { shape, .. } => match shape {
                AreaShape::Triangle(t) => t.pdf_area,
                AreaShape::Sphere(s) => 1.0 / s.area(),
            },
            _ => 1.0,
        }
    }

    /// Density per unit solid angle with which [`Light::sample_le`] leaves a point of the light
    /// (normal `n`, for area lights) in direction `w`.
    pub fn pdf_le_dir(&self, n: Option<Vec3>, w: Vec3) -> f32 {
        if !self.emits_rays() {
            return 0.0;
        }
        match *self {
            Light::Area { two_sided, .. } => {
                let cos = n.map_or(0.0, |n| n.dot(w));
                if two_sided {
                    0.5 * cosine_hemisphere_pdf(cos.abs())
                } else {
                    cosine_hemisphere_pdf(cos.max(0.0))
                }
            }
            Light::Point { .. } => uniform_sphere_pdf(),
            Light::Spot {
                direction,
                cos_cutoff,
                ..
            } if direction.dot(w) >= cos_cutoff => uniform_cone_pdf(cos_cutoff),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::AreaTriangle;
    use crate::shape::Triangle;
    use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
    use pathlab_mc::stats::{chi2_test_2d_with_quadrature, cos_theta_phi};

    fn lights() -> Vec<Light> {
        let tri = AreaTriangle::new(Triangle {
            p: [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.5),
            ],
        });
        let area = |two_sided| Light::Area {
            shape: AreaShape::Triangle(tri),
            radiance: Rgb::new(1.0, 2.0, 3.0),
            two_sided,
            texture: None,
        };
        vec![
            area(false),
            area(true),
            Light::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                intensity: Rgb::ONE,
                attenuation: [0.0, 0.0, 1.0],
            },
            Light::Spot {
                position: Vec3::ZERO,
                direction: Vec3::new(0.0, 0.6, 0.8),
                intensity: Rgb::ONE,
                cos_cutoff: 0.7,
                exponent: 2.0,
                attenuation: [0.0, 0.0, 1.0],
            },
        ]
    }

    /// Directions of emitted rays in (cos θ, φ) against their own `pdf_le_dir`: a chi-square
    /// test of each sampling routine against its density (which must integrate to one).
    #[test]
    fn emitted_directions_follow_their_density() {
        let n = 200_000u32;
        for (k, light) in lights().iter().enumerate() {
            let mut sampler: AnySampler = SamplerKind::Independent.build(n, 11 + k as u64);
            let mut normal = None;
            let samples: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    sampler.start_pixel_sample([0, 0], i, 0);
                    let s = light
                        .sample_le(sampler.next_2d(), sampler.next_2d())
                        .expect("every light here emits everywhere");
                    normal = s.n;
                    assert!((s.pdf_dir - light.pdf_le_dir(s.n, s.w)).abs() <= 1e-4 * s.pdf_dir);
                    assert_eq!(s.pdf_pos, light.pdf_le_pos());
                    cos_theta_phi(s.w.as_dvec3().to_array())
                })
                .collect();
            let t = chi2_test_2d_with_quadrature(
                samples,
                |z, phi| {
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    light.pdf_le_dir(normal, w) as f64
                },
                [[-1.0, 1.0], [0.0, std::f64::consts::TAU]],
                [32, 32],
                8,
            );
            assert!(t.passes(1e-3), "light {k}: {t:?}");
        }
    }

    #[test]
    fn lights_without_rays_say_so() {
        let env = Light::Environment {
            radiance: Rgb::ONE,
            scene_radius: 1.0,
        };
        assert!(!env.emits_rays());
        assert_eq!(env.sample_le(Vec2::splat(0.5), Vec2::splat(0.5)), None);
        let falloff = Light::Point {
            position: Vec3::ZERO,
            intensity: Rgb::ONE,
            attenuation: [1.0, 0.0, 0.0],
        };
        assert!(!falloff.emits_rays());
        assert!(lights().iter().all(Light::emits_rays));
    }
}
