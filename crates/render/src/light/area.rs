//! Area lights: the shapes they emit from (triangles and spheres), the triangle emitter the
//! one-path and the eight-lane integrators share, and emission textures.

use crate::desc::Rgb;
use crate::shape::{Sphere, Triangle};
use crate::texture::Tex;
use glam::{Mat3, Vec2, Vec3};
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8};
use pathlab_mc::warp::{uniform_triangle, uniform_triangle_pdf};
use std::f32::consts::PI;

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
    pub(super) area: f32,
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
/// lanes' points ([`Vector3`] is `Vec3` or [`crate::simd::lanes::V8`]): the one implementation of a
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
    pub(super) fn uv(&self, shape: &AreaShape, p: Vec3, b: [f32; 3]) -> Vec2 {
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
