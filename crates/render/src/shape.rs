//! Shapes: triangles and spheres, their intersection with rays and their uniform area sampling.

use crate::geometry::{Aabb, Ray};
use crate::simd::lanes::{F8, V8, W};
use glam::{Vec2, Vec3};
use pathlab_mc::warp::sample_uniform_sphere;
use std::f32::consts::PI;

/// Relative margin of squared distance within which a point counts as on a sphere (and is
/// sampled by area rather than by cone: [`Sphere::sample_cone`]).
const ON_SPHERE: f32 = 1e-3;

/// A triangle's vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertex positions.
    pub p: [Vec3; 3],
}

/// Where a ray meets a triangle: distance and barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric coordinate of vertex 1.
    pub b1: f32,
    /// Barycentric coordinate of vertex 2.
    pub b2: f32,
}

/// A point sampled on a shape's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    /// The point.
    pub p: Vec3,
    /// Unit geometric normal there (the shape's outward / winding side).
    pub n: Vec3,
    /// Density per unit area.
    pub pdf_area: f32,
}

impl Triangle {
    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::point(self.p[0]).grow(self.p[1]).grow(self.p[2])
    }

    /// The boxes of this triangle's parts inside `bounds` below and above the plane at `pos`
    /// on `axis` (a spatial split's pieces: [`crate::accel::SplitPrim`]). Each box holds its
    /// part: where an edge crosses the plane, the rounded crossing point is widened by its
    /// possible error on the other axes.
    pub fn split_bounds(&self, bounds: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
        let (mut below, mut above) = (Aabb::EMPTY, Aabb::EMPTY);
        for i in 0..3 {
            let (a, b) = (self.p[i], self.p[(i + 1) % 3]);
            let (ca, cb) = (a[axis], b[axis]);
            if ca <= pos {
                below = below.grow(a);
            }
            if ca >= pos {
                above = above.grow(a);
            }
            if (ca < pos && pos < cb) || (cb < pos && pos < ca) {
                let x = a + (b - a) * ((pos - ca) / (cb - ca));
                // A handful of roundings, each at most ε of the larger endpoint.
                let pad = a.abs().max(b.abs()) * (16.0 * f32::EPSILON);
                let (mut lo, mut hi) = (x - pad, x + pad);
                lo[axis] = pos;
                hi[axis] = pos;
                below = below.grow(lo).grow(hi);
                above = above.grow(lo).grow(hi);
            }
        }
        (below.intersection(*bounds), above.intersection(*bounds))
    }

    /// Area.
    pub fn area(&self) -> f32 {
        0.5 * (self.p[1] - self.p[0])
            .cross(self.p[2] - self.p[0])
            .length()
    }

    /// Unit normal of the counter-clockwise winding (zero for a degenerate triangle).
    pub fn normal(&self) -> Vec3 {
        (self.p[1] - self.p[0])
            .cross(self.p[2] - self.p[0])
            .normalize_or_zero()
    }

    /// Möller–Trumbore intersection ("Fast, Minimum Storage Ray/Triangle Intersection",
    /// 1997), both sides, within `(ray.t_min, ray.t_max)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<TriangleHit> {
        let e1 = self.p[1] - self.p[0];
        let e2 = self.p[2] - self.p[0];
        let pvec = ray.d.cross(e2);
        let det = e1.dot(pvec);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv_det = 1.0 / det;
        let tvec = ray.o - self.p[0];
        let b1 = tvec.dot(pvec) * inv_det;
        if !(0.0..=1.0).contains(&b1) {
            return None;
        }
        let qvec = tvec.cross(e1);
        let b2 = ray.d.dot(qvec) * inv_det;
        if b2 < 0.0 || b1 + b2 > 1.0 {
            return None;
        }
        let t = e2.dot(qvec) * inv_det;
        (t > ray.t_min && t < ray.t_max).then_some(TriangleHit { t, b1, b2 })
    }
}

/// A ray's quadratic a t² + 2b t + c = 0 against a sphere, and its discriminant written as
/// a (r² - |o - (b/a) d|²) (see [`Sphere::intersect`]).
#[derive(Clone, Copy, Default)]
struct SphereQuadratic {
    a: f64,
    b: f64,
    c: f64,
    disc: f64,
}

impl SphereQuadratic {
    /// Whether there is a direction and real roots (a NaN discriminant passes: its roots are
    /// NaN, found nowhere).
    #[inline(always)]
    fn has_roots(&self) -> bool {
        !(self.a == 0.0 || self.disc < 0.0)
    }

    /// The root nearest the ray's origin within `(t_min, t_max)`, or NaN: every case a select
    /// rather than a branch. Meaningful where [`SphereQuadratic::has_roots`].
    #[inline(always)]
    fn nearest_root(&self, t_min: f32, t_max: f32) -> f32 {
        let SphereQuadratic { a, b, c, disc } = *self;
        let q = -(b + disc.sqrt().copysign(b));
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
        let (t0, t1) = (t0.min(t1), t0.max(t1));
        let (t_min, t_max) = (t_min as f64, t_max as f64);
        let t = if t0 > t_min && t0 < t_max {
            t0
        } else if t1 > t_min && t1 < t_max {
            t1
        } else {
            f64::NAN
        };
        t as f32
    }
}

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
}

impl Sphere {
    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.center - Vec3::splat(self.radius),
            max: self.center + Vec3::splat(self.radius),
        }
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// The nearest intersection distance within `(ray.t_min, ray.t_max)`, from either side.
    ///
    /// Solves a t² + 2b t + c = 0 in `f64` relative to the centre, with the discriminant
    /// written as a (r² - |o - (b/a) d|²) to avoid cancellation for distant origins, and the
    /// roots as q/a and c/q to avoid it for near-tangent ones.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let q = self.quadratic(ray.o, ray.d);
        // Most rays that reach a sphere's test miss it: they end here.
        if !q.has_roots() {
            return None;
        }
        let t = q.nearest_root(ray.t_min, ray.t_max);
        (!t.is_nan()).then_some(t)
    }

    /// [`Sphere::intersect`] of eight rays (origins `o`, directions `d`, extents from `t_min`
    /// to `t_max`): each lane's distance, NaN where there is none. The same functions as the
    /// one-ray test for every lane (so the same bits); without branches, so that a caller
    /// compiled for wide registers computes the eight lanes together.
    #[inline(always)]
    pub fn intersect_lanes(&self, o: &V8, d: &V8, t_min: &F8, t_max: &F8) -> [f32; W] {
        // Loops over the lanes rather than `array::from_fn`, whose closure the compiler
        // keeps out of line, one lane at a time.
        let mut q = [SphereQuadratic::default(); W];
        let mut any_roots = false;
        for (i, q) in q.iter_mut().enumerate() {
            *q = self.quadratic(o.get(i), d.get(i));
            any_roots |= q.has_roots();
        }
        // Most groups of rays miss a sphere altogether: they end here, before the roots'
        // square root and divisions, as one ray does.
        let mut t = [f32::NAN; W];
        if !any_roots {
            return t;
        }
        for (i, t) in t.iter_mut().enumerate() {
            let root = q[i].nearest_root(t_min.0[i], t_max.0[i]);
            *t = if q[i].has_roots() { root } else { f32::NAN };
        }
        t
    }

    /// The quadratic of a ray from `o` along `d`, relative to the centre in `f64`.
    #[inline(always)]
    fn quadratic(&self, o: Vec3, d: Vec3) -> SphereQuadratic {
        let o = (o - self.center).as_dvec3();
        let d = d.as_dvec3();
        let r = self.radius as f64;
        let a = d.length_squared();
        let b = o.dot(d);
        let c = o.length_squared() - r * r;
        let l = o - (b / a) * d;
        let disc = a * (r * r - l.length_squared());
        SphereQuadratic { a, b, c, disc }
    }

    /// The cone of directions in which the sphere is seen from `p`, outside it: its axis
    /// (towards the centre, unit), sin² of its half-angle and 1 - cos of it (computed as
    /// sin² / (1 + cos), accurate for small spheres far away, where 1 - cos would cancel).
    /// `None` from inside or on the sphere, where it fills a hemisphere or more.
    #[inline]
    fn cone_from(&self, p: Vec3) -> Option<(Vec3, f32, f32)> {
        let to_center = self.center - p;
        let dist2 = to_center.length_squared();
        let r2 = self.radius * self.radius;
        // Points on the sphere (within rounding, with a wide margin) count as inside: there
        // the cone is a hemisphere whose apex the sphere itself bends away from.
        if dist2 <= r2 * (1.0 + ON_SPHERE) || !dist2.is_finite() {
            return None;
        }
        let sin2_max = r2 / dist2;
        let cos_max = (1.0 - sin2_max).sqrt();
        Some((
            to_center / dist2.sqrt(),
            sin2_max,
            sin2_max / (1.0 + cos_max),
        ))
    }

    /// A point of the part of the sphere seen from `p`, whose direction from `p` is uniform
    /// in the cone the sphere subtends there (pbrt-v4's and Mitsuba 3's sphere sampling): the
    /// point and its outward normal, and the density per unit solid angle,
    /// 1 / (2π (1 - cos θmax)). `None` from inside or on the sphere (sample the surface by area
    /// there: [`Sphere::sample`]).
    ///
    /// cos θ is uniform in [cos θmax, 1] and φ in [0, 2π); the ray from `p` at angle θ from the
    /// axis meets the sphere first at the point whose angle α from the axis, seen from the
    /// centre towards `p`, has cos α = sin²θ / sin θmax + cos θ √(1 - sin²θ / sin²θmax). Every
    /// quantity is written so as not to cancel when the cone is narrow (1 - cos θ as a
    /// product, sin²θ as (1 - cos θ)(1 + cos θ)).
    #[inline]
    pub fn sample_cone(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let (axis, sin2_max, one_minus_cos_max) = self.cone_from(p)?;
        let one_minus_cos = u.x * one_minus_cos_max;
        let cos_theta = 1.0 - one_minus_cos;
        let sin2_theta = one_minus_cos * (2.0 - one_minus_cos);
        let cos_alpha = sin2_theta / sin2_max.sqrt()
            + cos_theta * (1.0 - sin2_theta / sin2_max).max(0.0).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (std::f32::consts::TAU * u.y).sin_cos();
        let (t, b) = pathlab_mc::warp::coordinate_system(axis);
        // The normal points back along the axis, tilted by α.
        let n = (-cos_alpha * axis + sin_alpha * (cos_phi * t + sin_phi * b)).normalize();
        Some((
            self.center + self.radius * n,
            n,
            1.0 / (std::f32::consts::TAU * one_minus_cos_max),
        ))
    }

    /// The density per unit solid angle of [`Sphere::sample_cone`] from `p` (the same for
    /// every direction of the cone), or `None` from inside or on the sphere.
    #[inline]
    pub fn cone_pdf(&self, p: Vec3) -> Option<f32> {
        let (_, _, one_minus_cos_max) = self.cone_from(p)?;
        Some(1.0 / (std::f32::consts::TAU * one_minus_cos_max))
    }

    /// A point uniform over the surface.
    pub fn sample(&self, u: Vec2) -> ShapeSample {
        let n = sample_uniform_sphere(u);
        ShapeSample {
            p: self.center + self.radius * n,
            n,
            pdf_area: 1.0 / self.area(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Angle between unit-ish vectors `a` and `b`, accurate for small angles (`f64`).
    fn angle(a: Vec3, b: Vec3) -> f64 {
        let (a, b) = (a.as_dvec3().normalize(), b.as_dvec3().normalize());
        a.cross(b).length().atan2(a.dot(b))
    }

    /// Directions of [`Sphere::sample_cone`] against its density: uniform in the cone, i.e.
    /// (1 - cos θ) / (1 - cos θmax) and φ / 2π uniform on the unit square (a chi-square test),
    /// for a large sphere close by and a small one far away (where 1 - cos θmax is 1e-5).
    /// Every point lies on the sphere, faces the reference point, and is what a ray from the
    /// reference point towards it meets first.
    #[test]
    fn cone_samples_are_uniform_in_the_solid_angle_the_sphere_subtends() {
        use pathlab_mc::rng::Pcg32;
        use pathlab_mc::stats::chi2_test_2d;
        let mut rng = Pcg32::new(8, 3);
        for (center, radius) in [
            (Vec3::new(0.3, -0.2, 1.5), 1.2f32),
            (Vec3::new(7.0, 6.0, -2.0), 0.05),
        ] {
            let sphere = Sphere { center, radius };
            let p = Vec3::new(0.1, 0.2, -0.3);
            let axis = center - p;
            let sin_max = radius as f64 / axis.as_dvec3().length();
            let one_minus_cos_max = 1.0 - (1.0 - sin_max * sin_max).sqrt();
            let pdf = sphere.cone_pdf(p).expect("outside");
            let expected = 1.0 / (std::f64::consts::TAU * one_minus_cos_max);
            assert!((pdf as f64 - expected).abs() <= 1e-5 * expected);
            let (t, _) = pathlab_mc::warp::coordinate_system(axis.normalize());
            let n = 100_000;
            let mut points = Vec::with_capacity(n);
            for _ in 0..n {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let (point, normal, cone_pdf) = sphere.sample_cone(p, u).expect("outside");
                assert_eq!(cone_pdf, pdf);
                let s = ShapeSample {
                    p: point,
                    n: normal,
                    pdf_area: 0.0,
                };
                assert!(((s.p - center).length() - radius).abs() <= 1e-5 * radius.max(1.0));
                let to_p = p - s.p;
                assert!(s.n.dot(to_p) >= -1e-4 * to_p.length(), "{s:?}");
                let d = (s.p - p).normalize();
                let hit = sphere.intersect(&Ray::new(p, d)).expect("the ray meets it");
                assert!(
                    (p + d * hit - s.p).length() <= 1e-4 * (1.0 + radius),
                    "{s:?}"
                );
                let theta = angle(d, axis);
                let one_minus_cos = 2.0 * (theta * 0.5).sin().powi(2);
                // φ about the axis, from the frame's first tangent.
                let perp = d.as_dvec3()
                    - d.as_dvec3().dot(axis.as_dvec3().normalize()) * axis.as_dvec3().normalize();
                let phi =
                    angle(t, perp.as_vec3()).copysign(t.cross(perp.as_vec3()).dot(axis) as f64);
                let phi = phi.rem_euclid(std::f64::consts::TAU);
                points.push([
                    one_minus_cos / one_minus_cos_max,
                    phi / std::f64::consts::TAU,
                ]);
            }
            let test = chi2_test_2d(points, |_, _| 1.0, [[0.0, 1.0], [0.0, 1.0]], [16, 16]);
            assert!(test.passes(1e-3), "radius {radius}: {test:?}");
        }
        // Inside or on it: no cone.
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        assert!(sphere
            .sample_cone(Vec3::new(0.5, 0.0, 0.0), Vec2::splat(0.5))
            .is_none());
        assert!(sphere.cone_pdf(Vec3::X).is_none());
        assert!(sphere.cone_pdf(Vec3::X * 1.0001).is_none());
        assert!(sphere.cone_pdf(Vec3::X * 1.01).is_some());
    }

    #[test]
    fn triangle_hits_inside_and_misses_outside() {
        let tri = Triangle {
            p: [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
        };
        let hit = tri
            .intersect(&Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z))
            .unwrap();
        assert!(
            (hit.t - 1.0).abs() < 1e-6
                && (hit.b1 - 0.25).abs() < 1e-6
                && (hit.b2 - 0.25).abs() < 1e-6
        );
        // From behind too.
        assert!(tri
            .intersect(&Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z))
            .is_some());
        assert!(tri
            .intersect(&Ray::new(Vec3::new(0.75, 0.75, 1.0), Vec3::NEG_Z))
            .is_none());
        let mut short = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z);
        short.t_max = 0.5;
        assert!(tri.intersect(&short).is_none());
        assert_eq!(tri.normal(), Vec3::Z);
        assert!((tri.area() - 0.5).abs() < 1e-7);
    }

    #[test]
    fn split_bounds_hold_every_point_of_their_parts() {
        let mut rng = pathlab_mc::rng::Pcg32::new(31, 2);
        let mut point = |scale: f32| {
            Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * scale - 0.3 * scale
        };
        let mut split_pieces = 0;
        for k in 0..300 {
            // Large and far triangles too, where the crossing's rounding matters.
            let scale = [1.0, 1e3, 1e-3][k % 3];
            let tri = Triangle {
                p: [point(scale), point(scale), point(scale)],
            };
            // The whole triangle, or the part of it in a smaller box (an earlier split's).
            let whole = tri.bounds();
            let bounds = if k % 2 == 0 {
                whole
            } else {
                Aabb {
                    min: whole.min + 0.2 * whole.extent(),
                    max: whole.max,
                }
            };
            let axis = k % 3;
            let pos = whole.min[axis] + point(1.0).x.abs().min(1.0) * whole.extent()[axis];
            let (below, above) = tri.split_bounds(&bounds, axis, pos);
            let inside = |b: &Aabb, p: Vec3| b.min.cmple(p).all() && b.max.cmpge(p).all();
            for j in 0..400 {
                let (u, v) = ((j % 20) as f32 / 19.0, (j / 20) as f32 / 19.0);
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let p = tri.p[0] + u * (tri.p[1] - tri.p[0]) + v * (tri.p[2] - tri.p[0]);
                if !inside(&bounds, p) {
                    continue;
                }
                if p[axis] <= pos {
                    assert!(inside(&below, p), "{p} below {pos} outside {below:?}");
                }
                if p[axis] >= pos {
                    assert!(inside(&above, p), "{p} above {pos} outside {above:?}");
                }
            }
            split_pieces += usize::from(!below.is_empty() && !above.is_empty());
            // Each piece keeps to its side of the plane.
            assert!(below.is_empty() || below.max[axis] <= pos);
            assert!(above.is_empty() || above.min[axis] >= pos);
        }
        assert!(split_pieces > 100);
    }

    #[test]
    fn sphere_from_outside_inside_and_on_surface() {
        let s = Sphere {
            center: Vec3::new(0.0, 0.0, -5.0),
            radius: 1.0,
        };
        let t = s.intersect(&Ray::new(Vec3::ZERO, Vec3::NEG_Z)).unwrap();
        assert!((t - 4.0).abs() < 1e-5);
        let t = s
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::X))
            .unwrap();
        assert!((t - 1.0).abs() < 1e-6);
        // Leaving the surface outwards misses; inwards hits the far side.
        let p = Vec3::new(0.0, 0.0, -4.0);
        assert!(s.intersect(&Ray::new(p, Vec3::Z)).is_none());
        let t = s.intersect(&Ray::new(p, Vec3::NEG_Z)).unwrap();
        assert!((t - 2.0).abs() < 1e-5);
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
    }
}
