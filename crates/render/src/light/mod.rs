//! Lights: area lights (emissive triangles and spheres, optionally textured), point, spot and
//! directional lights, projectors (Mitsuba's textured spot and projector), a uniform
//! environment and environment maps; and the choice of a light in proportion to its power.
//!
//! The light type and what every light answers (`mod.rs`); area lights' shapes, textures and the
//! triangle emitter shared with the packet path (`area`); projectors (`projector`); environment
//! maps (`envmap`); choosing a light (`sampler`); rays of emitted light, where the bidirectional
//! path tracer's light subpaths start (`emission`).

mod area;
mod emission;
pub mod envmap;
mod projector;
mod sampler;

pub use area::{
    sphere_uv, AreaShape, AreaTexture, AreaTriangle, TriangleEmitter, TriangleLiSample,
};
pub use emission::LightLeSample;
pub use projector::Projector;
pub use sampler::LightSampler;

use crate::color::luminance;
use crate::desc::Rgb;
use crate::geometry::Aabb;
use crate::texture::{Tex, TexPoint};
use envmap::EnvironmentMap;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::{sample_uniform_sphere, uniform_sphere_pdf};
use std::f32::consts::PI;
use std::sync::Arc;

/// A light source.
#[derive(Clone, Debug)]
pub enum Light {
    /// Uniform radiance from a surface (times a texture, when it has one).
    Area {
        /// The emitting surface.
        shape: AreaShape,
        /// Radiance of the front side.
        radiance: Rgb,
        /// Whether the back side emits too.
        two_sided: bool,
        /// A texture multiplying the radiance.
        texture: Option<Arc<AreaTexture>>,
    },
    /// Radiant intensity from a point (a delta light), divided by c + l d + q d².
    Point {
        /// Position.
        position: Vec3,
        /// Intensity.
        intensity: Rgb,
        /// Constant, linear and quadratic attenuation.
        attenuation: [f32; 3],
    },
    /// A point light limited to a cone, with a cos^exponent falloff.
    Spot {
        /// Position.
        position: Vec3,
        /// Cone axis (unit).
        direction: Vec3,
        /// Intensity on the axis.
        intensity: Rgb,
        /// Cosine of the cone's half-angle.
        cos_cutoff: f32,
        /// Exponent of the falloff.
        exponent: f32,
        /// Constant, linear and quadratic attenuation.
        attenuation: [f32; 3],
    },
    /// Light arriving along one direction from infinitely far (a delta light).
    Directional {
        /// Direction of travel (unit).
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Rgb,
        /// Radius of a sphere bounding the scene (for the power estimate).
        scene_radius: f32,
    },
    /// Uniform radiance from every direction at infinity.
    Environment {
        /// Radiance.
        radiance: Rgb,
        /// Radius of a sphere bounding the scene (for the power estimate).
        scene_radius: f32,
    },
    /// A point light shining through an image plane (see [`crate::desc::ProjectorDesc`]).
    Projector(Arc<Projector>),
    /// Radiance at infinity from an image (sampled by luminance).
    EnvironmentMap {
        /// The map.
        map: Arc<EnvironmentMap>,
        /// Radius of a sphere bounding the scene (for the power estimate).
        scene_radius: f32,
    },
}

/// Incident radiance sampled from a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLiSample {
    /// Radiance arriving at the reference point along `wi` (before visibility).
    pub li: Rgb,
    /// Unit direction from the reference point towards the light.
    pub wi: Vec3,
    /// Density per unit solid angle (1 for delta lights).
    pub pdf: f32,
    /// The point on the light (for a shadow ray).
    pub p_light: Vec3,
    /// The light's surface normal there (none for points and the environment).
    pub n_light: Option<Vec3>,
    /// Whether the light is a delta distribution (no BSDF sample can hit it).
    pub is_delta: bool,
}

/// A light sample whose radiance may not have been read yet ([`Light::sample_li_deferred`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeferredLiSample {
    /// The sample; its `li` is zero while `at` holds where to read it.
    pub ls: LightLiSample,
    /// An environment map's (u, v) whose radiance [`Light::deferred_li`] reads.
    at: Option<Vec2>,
}

impl LightLiSample {
    /// Whether the sample may carry light: a density not at or below zero and, where its
    /// radiance is known already (`li_known`), a radiance not at or below zero (a NaN is
    /// neither, and passes). The light sample's early return, for one lane and for the lanes
    /// alike.
    #[inline]
    pub fn may_carry_light(&self, li_known: bool) -> bool {
        !(self.pdf <= 0.0 || (li_known && self.li.max_element() <= 0.0))
    }
}

impl DeferredLiSample {
    /// Whether `ls.li` is the radiance already (otherwise [`Light::deferred_li`] reads it).
    pub fn has_li(&self) -> bool {
        self.at.is_none()
    }
}

/// 1 / (c + l d + q d²), or 0 where that is not positive.
#[inline]
fn attenuate(attenuation: [f32; 3], dist2: f32) -> f32 {
    let [c, l, q] = attenuation;
    let denom = c + l * dist2.sqrt() + q * dist2;
    if denom > 0.0 {
        1.0 / denom
    } else {
        0.0
    }
}

impl Light {
    /// Whether the light is at infinity (shadow rays towards it have no end).
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Environment { .. } | Light::EnvironmentMap { .. } | Light::Directional { .. }
        )
    }

    /// The box around an emitting surface (none for other lights). Every shape of an area
    /// light is matched by name, so that a new one cannot be left without a box (which would
    /// let a path's last ray skip it: [`crate::scene::Scene::may_find_emission`]).
    pub fn surface_bounds(&self) -> Option<Aabb> {
        match self {
            Light::Area { shape, .. } => Some(match shape {
                AreaShape::Triangle(t) => t.triangle.bounds(),
                AreaShape::Sphere(s) => s.bounds(),
            }),
            _ => None,
        }
    }

    /// Radiance from an environment light arriving along world direction `-w` (`w` points
    /// from the scene into the environment); zero for other lights.
    #[inline]
    pub fn le_environment(&self, w: Vec3) -> Rgb {
        match self {
            Light::Environment { radiance, .. } => *radiance,
            Light::EnvironmentMap { map, .. } => map.eval(w),
            _ => Rgb::ZERO,
        }
    }

    /// Whether the light's emission reads a texture at its surface's (u, v).
    pub fn reads_texture(&self) -> bool {
        matches!(
            self,
            Light::Area {
                texture: Some(_),
                ..
            }
        )
    }

    /// Radiance leaving an area light at a point with normal `n` and texture coordinates `uv`
    /// in direction `w` (away from the light).
    #[inline]
    pub fn le(&self, n: Vec3, w: Vec3, uv: Vec2) -> Rgb {
        match self {
            Light::Area {
                radiance,
                two_sided,
                texture,
                ..
            } => {
                let c = n.dot(w);
                if c > 0.0 || (*two_sided && c < 0.0) {
                    match texture {
                        None => *radiance,
                        Some(t) => *radiance * t.tex.eval(&TexPoint::uv(uv)),
                    }
                } else {
                    Rgb::ZERO
                }
            }
            Light::Environment { .. } | Light::EnvironmentMap { .. } => self.le_environment(w),
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Projector(_) => Rgb::ZERO,
        }
    }

    /// [`Light::sample_li`] of an area light: a point on its triangle or sphere, its radiance
    /// read from the texture where there is one.
    fn sample_area_li(
        &self,
        shape: AreaShape,
        texture: Option<&AreaTexture>,
        radiance: Rgb,
        two_sided: bool,
        p: Vec3,
        u: Vec2,
    ) -> Option<LightLiSample> {
        let sph = match shape {
            AreaShape::Triangle(t) => {
                let s = t.emitter(radiance, two_sided).sample_li(p, u.x, u.y);
                if s.dist2 == 0.0 || s.abs_cos_light == 0.0 {
                    return None;
                }
                let li = match texture {
                    None => s.li,
                    Some(tex) if s.emits => {
                        radiance * tex.tex.eval(&TexPoint::uv(tex.uv(&shape, s.p_light, s.b)))
                    }
                    Some(_) => Rgb::ZERO,
                };
                return Some(LightLiSample {
                    li,
                    wi: s.wi,
                    pdf: s.pdf,
                    p_light: s.p_light,
                    n_light: Some(t.normal),
                    is_delta: false,
                });
            }
            AreaShape::Sphere(sph) => sph,
        };
        // From outside, uniform in the cone the sphere subtends (its density per unit solid
        // angle comes with it); from inside, uniform over its area.
        let (p_light, n, cone_pdf) = match sph.sample_cone(p, u) {
            Some((p_light, n, pdf)) => (p_light, n, Some(pdf)),
            None => {
                let s = sph.sample(u);
                (s.p, s.n, None)
            }
        };
        let to_light = p_light - p;
        let dist2 = to_light.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let wi = to_light / dist2.sqrt();
        let cos_l = n.dot(-wi).abs();
        if cos_l == 0.0 {
            return None;
        }
        // (By area: the uniform density 1 / area per unit area, as `Sphere::sample` gives it.)
        let pdf = cone_pdf.unwrap_or_else(|| 1.0 / sph.area() * dist2 / cos_l);
        let li = match texture {
            None => self.le(n, -wi, Vec2::ZERO),
            Some(t) => {
                let c = n.dot(-wi);
                if c > 0.0 || (two_sided && c < 0.0) {
                    radiance * t.tex.eval(&TexPoint::uv(t.uv(&shape, p_light, [0.0; 3])))
                } else {
                    Rgb::ZERO
                }
            }
        };
        Some(LightLiSample {
            li,
            wi,
            pdf,
            p_light,
            n_light: Some(n),
            is_delta: false,
        })
    }

    /// Samples incident radiance at `p`.
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightLiSample> {
        match *self {
            Light::Area {
                shape,
                ref texture,
                radiance,
                two_sided,
            } => self.sample_area_li(shape, texture.as_deref(), radiance, two_sided, p, u),
            Light::Point {
                position,
                intensity,
                attenuation,
            } => {
                let to_light = position - p;
                let dist2 = to_light.length_squared();
                (dist2 > 0.0).then(|| LightLiSample {
                    li: intensity * attenuate(attenuation, dist2),
                    wi: to_light / dist2.sqrt(),
                    pdf: 1.0,
                    p_light: position,
                    n_light: None,
                    is_delta: true,
                })
            }
            Light::Spot {
                position,
                direction,
                intensity,
                cos_cutoff,
                exponent,
                attenuation,
            } => {
                let to_light = position - p;
                let dist2 = to_light.length_squared();
                if dist2 == 0.0 {
                    return None;
                }
                let wi = to_light / dist2.sqrt();
                let cos = direction.dot(-wi);
                if cos < cos_cutoff {
                    return None;
                }
                Some(LightLiSample {
                    li: intensity * (cos.max(0.0).powf(exponent) * attenuate(attenuation, dist2)),
                    wi,
                    pdf: 1.0,
                    p_light: position,
                    n_light: None,
                    is_delta: true,
                })
            }
            Light::Projector(ref pr) => {
                let to_light = pr.position - p;
                let dist2 = to_light.length_squared();
                if dist2 == 0.0 {
                    return None;
                }
                let wi = to_light / dist2.sqrt();
                let li = pr.intensity(pr.to_local * -wi) / dist2;
                Some(LightLiSample {
                    li,
                    wi,
                    pdf: 1.0,
                    p_light: pr.position,
                    n_light: None,
                    is_delta: true,
                })
            }
            Light::Directional {
                direction,
                irradiance,
                scene_radius,
            } => Some(LightLiSample {
                li: irradiance,
                wi: -direction,
                pdf: 1.0,
                p_light: p - direction * (4.0 * scene_radius.max(1.0)),
                n_light: None,
                is_delta: true,
            }),
            Light::Environment {
                radiance,
                scene_radius,
            } => {
                let wi = sample_uniform_sphere(u);
                Some(LightLiSample {
                    li: radiance,
                    wi,
                    pdf: uniform_sphere_pdf(),
                    p_light: p + wi * (4.0 * scene_radius.max(1.0)),
                    n_light: None,
                    is_delta: false,
                })
            }
            Light::EnvironmentMap { .. } => {
                let deferred = self.sample_li_deferred(p, u)?;
                Some(LightLiSample {
                    li: self.deferred_li(&deferred),
                    ..deferred.ls
                })
            }
        }
    }

    /// [`Light::sample_li`], except that an environment map's radiance is left to
    /// [`Light::deferred_li`]: its texel lookup, often a cache miss, is then skipped for the
    /// samples a caller rejects first (a zero BSDF value, a blocked shadow ray). The same
    /// sample and the same radiance as [`Light::sample_li`].
    pub fn sample_li_deferred(&self, p: Vec3, u: Vec2) -> Option<DeferredLiSample> {
        let Light::EnvironmentMap {
            ref map,
            scene_radius,
        } = *self
        else {
            return self
                .sample_li(p, u)
                .map(|ls| DeferredLiSample { ls, at: None });
        };
        let (wi, pdf, uv) = map.sample_direction(u)?;
        Some(DeferredLiSample {
            ls: LightLiSample {
                li: Rgb::ZERO,
                wi,
                pdf,
                p_light: p + wi * (4.0 * scene_radius.max(1.0)),
                n_light: None,
                is_delta: false,
            },
            at: Some(uv),
        })
    }

    /// The radiance of a sample [`Light::sample_li_deferred`] of this light gave.
    pub fn deferred_li(&self, s: &DeferredLiSample) -> Rgb {
        match (self, s.at) {
            (Light::EnvironmentMap { map, .. }, Some(uv)) => map.radiance_at(uv),
            _ => s.ls.li,
        }
    }

    /// Density per unit solid angle with which [`Light::sample_li`] from `p` produces the point
    /// `p_light` (normal `n_light`) of an area light, in direction `wi`; zero for every other
    /// light (those at infinity: [`Light::pdf_li_towards`]).
    pub fn pdf_li_at(&self, p: Vec3, wi: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
        let Light::Area { shape, .. } = *self else {
            return 0.0;
        };
        let area = match shape {
            AreaShape::Triangle(t) => t.area,
            AreaShape::Sphere(s) => match s.cone_pdf(p) {
                Some(pdf) => return pdf,
                None => s.area(),
            },
        };
        let dist2 = (p_light - p).length_squared();
        let cos_l = n_light.dot(-wi).abs();
        if cos_l == 0.0 {
            0.0
        } else {
            dist2 / (cos_l * area)
        }
    }

    /// Density per unit solid angle with which [`Light::sample_li`] produces direction `wi` of
    /// the environment (from any point); zero for every other light.
    pub fn pdf_li_towards(&self, wi: Vec3) -> f32 {
        match *self {
            Light::Environment { .. } => uniform_sphere_pdf(),
            Light::EnvironmentMap { ref map, .. } => map.pdf(wi),
            _ => 0.0,
        }
    }

    /// [`Light::le_environment`] and [`Light::pdf_li_towards`] of one direction (an
    /// environment map finds the direction's place in its image once).
    #[inline]
    pub fn le_and_pdf_towards(&self, wi: Vec3) -> (Rgb, f32) {
        match *self {
            Light::EnvironmentMap { ref map, .. } => map.eval_and_pdf(wi),
            _ => (self.le_environment(wi), self.pdf_li_towards(wi)),
        }
    }

    /// Total emitted power (luminance), for choosing lights.
    pub fn phi(&self) -> f32 {
        match *self {
            Light::Area {
                shape,
                radiance,
                two_sided,
                ref texture,
            } => {
                let area = match shape {
                    AreaShape::Triangle(t) => t.area,
                    AreaShape::Sphere(s) => s.area(),
                };
                let sides = if two_sided { 2.0 } else { 1.0 };
                let mean = texture.as_ref().map_or(Rgb::ONE, |t| match &t.tex {
                    Tex::Image { image, .. } => image.mean(),
                    other => other.eval(&TexPoint::uv(Vec2::splat(0.5))),
                });
                PI * area * sides * luminance(radiance * mean)
            }
            Light::Projector(ref pr) => pr.phi(),
            Light::Point { intensity, .. } => 4.0 * PI * luminance(intensity),
            Light::Spot {
                intensity,
                cos_cutoff,
                ..
            } => 2.0 * PI * (1.0 - cos_cutoff) * luminance(intensity),
            Light::Directional {
                irradiance,
                scene_radius,
                ..
            } => PI * scene_radius * scene_radius * luminance(irradiance),
            Light::Environment {
                radiance,
                scene_radius,
            } => 4.0 * PI * PI * scene_radius * scene_radius * luminance(radiance),
            // Power through a disk of the scene's radius: π R² ∫ L dω.
            Light::EnvironmentMap {
                ref map,
                scene_radius,
            } => PI * scene_radius * scene_radius * map.luminance_integral(),
        }
    }
}

/// Radius of the sphere around a box.
pub fn bounding_radius(b: &Aabb) -> f32 {
    0.5 * b.extent().length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Triangle;
    use pathlab_mc::rng::Pcg32;

    #[test]
    fn triangle_light_samples_lie_on_the_triangle_with_the_density_pdf_li_gives() {
        let mut rng = Pcg32::new(4, 4);
        let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
        for _ in 0..1000 {
            let triangle = Triangle {
                p: [point(), point() * 3.0, point() - 2.0],
            };
            let area = AreaTriangle::new(triangle);
            assert_eq!(area.area, triangle.area());
            let light = Light::Area {
                shape: AreaShape::Triangle(area),
                radiance: Vec3::ONE,
                two_sided: true,
                texture: None,
            };
            let (p, u) = (point() * 4.0 + Vec3::splat(3.0), point().truncate());
            let s = area.emitter(Vec3::ONE, true).sample_li(p, u.x, u.y);
            let [a, b, c] = triangle.p;
            let expected = s.b[0] * a + s.b[1] * b + s.b[2] * c;
            assert!((s.p_light - expected).length() < 1e-5);
            assert!((s.b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
            assert!(s.b.iter().all(|&x| x >= 0.0));
            let pdf = light.pdf_li_at(p, s.wi, s.p_light, area.normal);
            assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{} vs {pdf}", s.pdf);
            let ls = light.sample_li(p, u).unwrap();
            assert_eq!((ls.pdf, ls.wi, ls.p_light), (s.pdf, s.wi, s.p_light));
        }
    }

    /// A sphere of radiance L seen from a point facing its centre gives irradiance
    /// E = π L sin²θmax: the light samples' f-free estimate Σ L cos θ / p / N agrees within its
    /// standard error, for a sphere close by and one far away; each sample's density is the one
    /// `pdf_li_at` gives its direction.
    #[test]
    fn sphere_light_samples_estimate_the_irradiance_the_sphere_gives() {
        use pathlab_mc::stats::z_test;
        let mut rng = Pcg32::new(12, 5);
        for (center, radius) in [
            (Vec3::new(0.0, 0.0, 2.0), 1.5f32),
            (Vec3::new(0.0, 0.0, 9.0), 0.1),
        ] {
            let light = Light::Area {
                shape: AreaShape::Sphere(crate::shape::Sphere { center, radius }),
                radiance: Vec3::splat(2.0),
                two_sided: false,
                texture: None,
            };
            let p = Vec3::ZERO;
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let ls = light.sample_li(p, u).expect("a sample");
                let n_light = ls.n_light.expect("a surface point");
                let pdf = light.pdf_li_at(p, ls.wi, ls.p_light, n_light);
                assert!((ls.pdf - pdf).abs() <= 1e-5 * pdf, "{} vs {pdf}", ls.pdf);
                let x = (ls.li.x * ls.wi.z / ls.pdf) as f64;
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            let sin2 = (radius as f64 / center.length() as f64).powi(2);
            let truth = std::f64::consts::PI * 2.0 * sin2;
            let t = z_test(mean, se.max(1e-12 * truth), truth);
            assert!(
                t.p_value > 1e-4,
                "radius {radius}: {mean} ± {se} vs {truth}"
            );
        }
    }

    #[test]
    fn deferred_samples_are_the_samples_and_radiance_sample_li_gives() {
        let (w, h) = (16, 9);
        let texels: Vec<Rgb> = (0..w * h)
            .map(|i| Vec3::new(1.0 + (i % 5) as f32, (i % 3) as f32, 0.5))
            .collect();
        let map = EnvironmentMap::new(texels, w, h, glam::Mat3::from_rotation_y(0.4), 1.5)
            .expect("a map");
        let lights = [
            Light::EnvironmentMap {
                map: Arc::new(map),
                scene_radius: 3.0,
            },
            Light::Environment {
                radiance: Vec3::ONE,
                scene_radius: 3.0,
            },
            Light::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: Vec3::splat(4.0),
                attenuation: [0.0, 0.0, 1.0],
            },
        ];
        let mut rng = Pcg32::new(7, 1);
        let p = Vec3::new(0.1, -0.2, 0.3);
        for (k, light) in lights.iter().enumerate() {
            let mut read = 0;
            for _ in 0..2000 {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let whole = light.sample_li(p, u);
                let deferred = light.sample_li_deferred(p, u);
                assert_eq!(whole.is_some(), deferred.is_some());
                let (Some(whole), Some(d)) = (whole, deferred) else {
                    continue;
                };
                // Only the environment map leaves its radiance to be read.
                assert_eq!(d.has_li(), k != 0);
                read += usize::from(!d.has_li());
                let li = light.deferred_li(&d);
                assert_eq!(whole, LightLiSample { li, ..d.ls });
                assert!(li.max_element() > 0.0);
            }
            assert!(k != 0 || read > 1900, "{read} deferred samples");
        }
    }
}
