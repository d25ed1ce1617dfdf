//! Lights: area lights (emissive triangles and spheres, optionally textured), point, spot and
//! directional lights, projectors (Mitsuba's textured spot and projector), a uniform
//! environment and environment maps; and the choice of a light in proportion to its power.

use crate::desc::{ProjectorKind, Rgb};
use crate::envmap::EnvironmentMap;
use crate::geometry::Aabb;
use crate::shape::{Sphere, Triangle};
use crate::texture::{Tex, TexPoint};
use glam::{Mat3, Vec2, Vec3};
use pathlab_mc::distribution::AliasTable;
use pathlab_mc::lanes::{Real, Vector3, F8, M8, V8};
use pathlab_mc::warp::{
    sample_uniform_sphere, uniform_sphere_pdf, uniform_triangle, uniform_triangle_pdf,
};
use std::f32::consts::PI;
use std::sync::Arc;

/// The shape an area light emits from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AreaShape {
    /// A triangle.
    Triangle(AreaTriangle),
    /// A sphere.
    Sphere(Sphere),
}

/// An emitting triangle with its unit normal and area computed once (every light sample and
/// density would compute them again: two cross products, two square roots and a division).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaTriangle {
    /// The triangle.
    pub triangle: Triangle,
    /// Unit normal (the winding's side).
    pub(crate) normal: Vec3,
    area: f32,
    /// `1 / area`, the density per unit area of a uniform point.
    pub(crate) pdf_area: f32,
}

impl AreaTriangle {
    /// `triangle` with its normal and area.
    pub fn new(triangle: Triangle) -> AreaTriangle {
        let area = triangle.area();
        AreaTriangle {
            triangle,
            normal: triangle.normal(),
            area,
            pdf_area: uniform_triangle_pdf(area),
        }
    }

    /// The triangle as a [`TriangleEmitter`] of `radiance`.
    #[inline]
    pub fn emitter(&self, radiance: Rgb, two_sided: bool) -> TriangleEmitter<Vec3> {
        TriangleEmitter {
            vertices: self.triangle.p,
            normal: self.normal,
            pdf_area: self.pdf_area,
            radiance,
            two_sided,
        }
    }
}

/// An emitting triangle of uniform radiance, for light sampling at one point or at eight
/// lanes' points ([`Vector3`] is `Vec3` or [`crate::lanes::V8`]): the one implementation of a
/// triangle's light sample.
#[derive(Clone, Copy, Debug)]
pub struct TriangleEmitter<V: Vector3> {
    /// The corners.
    pub vertices: [V; 3],
    /// The unit normal (the winding's side).
    pub normal: V,
    /// Density per unit area of a uniform point (1 / area).
    pub pdf_area: V::R,
    /// Emitted radiance.
    pub radiance: V,
    /// Whether it emits from both sides.
    pub two_sided: <V::R as Real>::Mask,
}

/// A light sample of a [`TriangleEmitter`] from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct TriangleLiSample<V: Vector3> {
    /// The point on the triangle.
    pub p_light: V,
    /// Its barycentrics.
    pub b: [V::R; 3],
    /// Squared distance to it (a sample at distance zero does not exist).
    pub dist2: V::R,
    /// Unit direction towards it.
    pub wi: V,
    /// |cos| at the light (a sample seen edge-on does not exist).
    pub abs_cos_light: V::R,
    /// Whether the triangle emits towards the reference point.
    pub emits: <V::R as Real>::Mask,
    /// Radiance arriving along `wi` (zero where it does not emit).
    pub li: V,
    /// Density per unit solid angle.
    pub pdf: V::R,
}

impl Default for TriangleEmitter<V8> {
    fn default() -> Self {
        TriangleEmitter {
            vertices: [V8::default(); 3],
            normal: V8::default(),
            pdf_area: F8::default(),
            radiance: V8::default(),
            two_sided: M8::default(),
        }
    }
}

impl TriangleEmitter<V8> {
    /// Sets lane `i` to `e`. Every field is taken apart here: a field added to
    /// [`TriangleEmitter`] fails to compile until its lanes are set too.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, e: TriangleEmitter<Vec3>) {
        let TriangleEmitter {
            vertices,
            normal,
            pdf_area,
            radiance,
            two_sided,
        } = e;
        for (lanes, v) in self.vertices.iter_mut().zip(vertices) {
            lanes.set(i, v);
        }
        self.normal.set(i, normal);
        self.pdf_area.0[i] = pdf_area;
        self.radiance.set(i, radiance);
        self.two_sided.set(i, two_sided);
    }
}

impl<V: Vector3> TriangleEmitter<V> {
    /// A point uniform over the triangle from `u`, as seen from `p`.
    #[inline(always)]
    pub fn sample_li(&self, p: V, u0: V::R, u1: V::R) -> TriangleLiSample<V> {
        let zero = V::R::splat(0.0);
        let b = uniform_triangle(u0, u1);
        let [v0, v1, v2] = self.vertices;
        let p_light = v0.scale(b[0]) + v1.scale(b[1]) + v2.scale(b[2]);
        let to_light = p_light - p;
        let dist2 = to_light.dot(to_light);
        let wi = to_light.div_by(dist2.sqrt());
        let cos_light = self.normal.dot(-wi);
        let emits = cos_light.gt(zero) | (self.two_sided & cos_light.lt(zero));
        let abs_cos_light = cos_light.abs();
        TriangleLiSample {
            p_light,
            b,
            dist2,
            wi,
            abs_cos_light,
            emits,
            li: V::select(emits, self.radiance, V::splat(Vec3::ZERO)),
            pdf: self.pdf_area * dist2 / abs_cos_light,
        }
    }
}

/// A texture over an area light's surface.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaTexture {
    /// The texture, at the surface's (u, v).
    pub tex: Tex,
    /// A triangle's corner (u, v).
    pub corner_uvs: [Vec2; 3],
    /// A sphere's rotation from world to its own frame (its (u, v) are spherical angles).
    pub to_object: Mat3,
}

impl AreaTexture {
    /// (u, v) of the point `p` with barycentrics `b` on `shape`.
    fn uv(&self, shape: &AreaShape, p: Vec3, b: [f32; 3]) -> Vec2 {
        match shape {
            AreaShape::Triangle(_) => {
                let c = &self.corner_uvs;
                b[0] * c[0] + b[1] * c[1] + b[2] * c[2]
            }
            AreaShape::Sphere(s) => sphere_uv(self.to_object * ((p - s.center) / s.radius)),
        }
    }
}

/// Texture coordinates of a point on a sphere, given its unit direction `d` from the centre
/// in the sphere's own frame: u = φ / 2π, v = 1 - θ / π (Mitsuba's v = θ / π, flipped to
/// pathlab's convention).
#[inline]
pub fn sphere_uv(d: Vec3) -> Vec2 {
    let phi = d.y.atan2(d.x);
    let u = phi / std::f32::consts::TAU + if phi < 0.0 { 1.0 } else { 0.0 };
    Vec2::new(u, 1.0 - d.z.clamp(-1.0, 1.0).acos() / PI)
}

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
    fn phi(&self) -> f32 {
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

/// The weights of relative luminance Y for linear sRGB / Rec. 709 primaries.
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Relative luminance of linear sRGB / Rec. 709 primaries.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    let [r, g, b] = LUMINANCE_WEIGHTS;
    r as f32 * c.x + g as f32 * c.y + b as f32 * c.z
}

/// [`luminance`] in double precision (of image means and other sums).
#[inline]
pub fn luminance_f64(c: glam::DVec3) -> f64 {
    let [r, g, b] = LUMINANCE_WEIGHTS;
    r * c.x + g * c.y + b * c.z
}

impl Light {
    /// Whether the light is at infinity (shadow rays towards it have no end).
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Environment { .. } | Light::EnvironmentMap { .. } | Light::Directional { .. }
        )
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

    /// Samples incident radiance at `p`.
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightLiSample> {
        match *self {
            Light::Area {
                shape,
                ref texture,
                radiance,
                two_sided,
            } => {
                let (s, b) = match shape {
                    AreaShape::Triangle(t) => {
                        let s = t.emitter(radiance, two_sided).sample_li(p, u.x, u.y);
                        if s.dist2 == 0.0 || s.abs_cos_light == 0.0 {
                            return None;
                        }
                        let li = match texture {
                            None => s.li,
                            Some(tex) if s.emits => {
                                radiance
                                    * tex.tex.eval(&TexPoint::uv(tex.uv(&shape, s.p_light, s.b)))
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
                    AreaShape::Sphere(sph) => (sph.sample(u), [0.0; 3]),
                };
                let to_light = s.p - p;
                let dist2 = to_light.length_squared();
                if dist2 == 0.0 {
                    return None;
                }
                let wi = to_light / dist2.sqrt();
                let cos_l = s.n.dot(-wi).abs();
                if cos_l == 0.0 {
                    return None;
                }
                let li = match texture {
                    None => self.le(s.n, -wi, Vec2::ZERO),
                    Some(t) => {
                        let c = s.n.dot(-wi);
                        if c > 0.0 || (two_sided && c < 0.0) {
                            radiance * t.tex.eval(&TexPoint::uv(t.uv(&shape, s.p, b)))
                        } else {
                            Rgb::ZERO
                        }
                    }
                };
                Some(LightLiSample {
                    li,
                    wi,
                    pdf: s.pdf_area * dist2 / cos_l,
                    p_light: s.p,
                    n_light: Some(s.n),
                    is_delta: false,
                })
            }
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
            Light::EnvironmentMap {
                ref map,
                scene_radius,
            } => {
                let (wi, pdf, li) = map.sample(u)?;
                Some(LightLiSample {
                    li,
                    wi,
                    pdf,
                    p_light: p + wi * (4.0 * scene_radius.max(1.0)),
                    n_light: None,
                    is_delta: false,
                })
            }
        }
    }

    /// Density per unit solid angle with which [`Light::sample_li`] from `p` produces the point
    /// `p_light` (normal `n_light`) on an area light, or the direction `wi` for the environment.
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
        match *self {
            Light::Area { shape, .. } => {
                let area = match shape {
                    AreaShape::Triangle(t) => t.area,
                    AreaShape::Sphere(s) => s.area(),
                };
                let dist2 = (p_light - p).length_squared();
                let cos_l = n_light.dot(-wi).abs();
                if cos_l == 0.0 {
                    0.0
                } else {
                    dist2 / (cos_l * area)
                }
            }
            Light::Environment { .. } => uniform_sphere_pdf(),
            Light::EnvironmentMap { ref map, .. } => map.pdf(wi),
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Projector(_) => 0.0,
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

/// Chooses lights (alias method): every emitter equally likely, and among the lights of one
/// emitter (the triangles of an emitting mesh) in proportion to their power, as Mitsuba
/// chooses them (uniformly among emitters, a mesh's points by area). Lights that may be
/// sampled but have zero power get a tiny share of their emitter's so that every one stays
/// reachable; lights that must not be sampled (seen by camera rays only) get none.
#[derive(Clone, Debug)]
pub struct LightSampler {
    table: Option<AliasTable>,
}

impl LightSampler {
    /// The sampler for `lights`, light `i` belonging to emitter `groups[i]`; those with
    /// `sampleable[i] == false` are never chosen.
    pub fn new(lights: &[Light], sampleable: &[bool], groups: &[u32]) -> Self {
        let phi = |i: usize| (lights[i].phi() as f64).max(0.0);
        let mut totals: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        for i in (0..lights.len()).filter(|&i| sampleable[i]) {
            *totals.entry(groups[i]).or_insert(0.0) += phi(i);
        }
        let emitters = totals.len().max(1) as f64;
        let mut counts: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for i in (0..lights.len()).filter(|&i| sampleable[i]) {
            *counts.entry(groups[i]).or_insert(0) += 1;
        }
        let weights: Vec<f64> = (0..lights.len())
            .map(|i| {
                if !sampleable[i] {
                    return 0.0;
                }
                let total = totals[&groups[i]];
                let share = if total > 0.0 {
                    phi(i).max(total * 1e-6) / total
                } else {
                    1.0 / counts[&groups[i]] as f64
                };
                share / emitters
            })
            .collect();
        LightSampler {
            table: AliasTable::new(&weights).ok(),
        }
    }

    /// A light index and its probability, or `None` when there are no lights.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        self.table.as_ref().map(|t| {
            let (index, pmf) = t.choose(u);
            (index, pmf as f32)
        })
    }

    /// The probability of choosing light `index`.
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        self.table.as_ref().map_or(0.0, |t| t.pmf(index) as f32)
    }
}

/// Radius of the sphere around a box.
pub fn bounding_radius(b: &Aabb) -> f32 {
    0.5 * b.extent().length()
}

#[cfg(test)]
mod tests {
    use super::*;
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
            let pdf = light.pdf_li(p, s.wi, s.p_light, area.normal);
            assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{} vs {pdf}", s.pdf);
            let ls = light.sample_li(p, u).unwrap();
            assert_eq!((ls.pdf, ls.wi, ls.p_light), (s.pdf, s.wi, s.p_light));
        }
    }
}
