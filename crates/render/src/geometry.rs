//! Rays, bounding boxes, shading frames and the offsetting that keeps rays from hitting the
//! surface they leave.

use glam::Vec3;
use pathlab_mc::simd::lanes::{Real, Vector3};

/// A ray `o + t d` for `t` in `(t_min, t_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction (unit length where the code says so; intersection works with any length).
    pub d: Vec3,
    /// The near end of the ray's extent (0 for rays the renderer makes: it offsets origins).
    pub t_min: f32,
    /// The far end of the ray's extent.
    pub t_max: f32,
}

impl Ray {
    /// A ray of unbounded extent.
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray {
            o,
            d,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + t * self.d
    }
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The empty box (union identity).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box of one point.
    pub fn point(p: Vec3) -> Self {
        Aabb { min: p, max: p }
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The box both hold (empty if they do not meet).
    #[inline]
    pub fn intersection(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.max(o.min),
            max: self.max.min(o.max),
        }
    }

    /// The smallest box holding this one and `p`.
    #[inline]
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Whether the box holds nothing.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Centre of the box.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Edge lengths (zero for an empty box).
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Surface area (zero for an empty box).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The axis of largest extent (0, 1 or 2).
    pub fn largest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Slab test: the entry distance if the ray meets the box within `(0, t_max)`.
    /// `inv_d` is `1 / ray.d` per component.
    #[inline]
    pub fn hit(&self, o: Vec3, inv_d: Vec3, t_max: f32) -> Option<f32> {
        let t0 = (self.min - o) * inv_d;
        let t1 = (self.max - o) * inv_d;
        let tmin = t0.min(t1).max_element().max(0.0);
        let tmax = t0.max(t1).min_element().min(t_max);
        // NaN from 0 * inf (origin on a slab plane, direction parallel) compares false: miss
        // is avoided by max/min ignoring NaN in glam's element-wise operations.
        (tmin <= tmax).then_some(tmin)
    }
}

/// An orthonormal frame: local z is the normal. `V` is glam's `Vec3`, or [`V8`] for the
/// frames of eight lanes.
///
/// [`V8`]: crate::simd::lanes::V8
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frame<V = Vec3> {
    /// Local x.
    pub s: V,
    /// Local y.
    pub t: V,
    /// Local z, the normal.
    pub n: V,
}

impl<V: Vector3> Frame<V> {
    /// A frame around the unit normal `n`.
    #[inline(always)]
    pub fn from_normal(n: V) -> Self {
        let (s, t) = pathlab_mc::warp::coordinate_system(n);
        Frame { s, t, n }
    }

    /// World → local.
    #[inline(always)]
    pub fn to_local(&self, v: V) -> V {
        V::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local → world.
    #[inline(always)]
    pub fn to_world(&self, v: V) -> V {
        self.s.scale(v.x()) + self.t.scale(v.y()) + self.n.scale(v.z())
    }
}

/// Relative size of the offset that moves a ray origin off the surface it leaves.
pub const RAY_EPSILON: f32 = 1e-4;

/// A point moved off a surface along its geometric normal `ng`, to the side of `w`, by
/// `RAY_EPSILON` times the point's magnitude (at least `RAY_EPSILON`): enough to clear the
/// rounding error of single-precision intersection at that magnitude, small against scene
/// features. For one point or for lanes.
#[inline(always)]
pub fn offset_ray_origin<V: Vector3>(p: V, ng: V, w: V) -> V {
    let one = V::R::splat(1.0);
    let eps = V::R::splat(RAY_EPSILON) * (one + p.abs().max_element());
    let step = ng.scale(eps);
    // `w · ng >= 0`, false for NaN.
    V::select(V::R::splat(0.0).le(w.dot(ng)), p + step, p - step)
}

/// A ray leaving surface point `p` (geometric normal `ng`) in direction `w`.
#[inline]
pub fn spawn_ray(p: Vec3, ng: Vec3, w: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, ng, w), w)
}

/// The far end of a shadow ray from [`spawn_ray_to`], whose direction spans the segment to its
/// target: just short of it.
pub const SHADOW_RAY_END: f32 = 1.0 - 1e-4;

/// A shadow ray from surface point `p` towards point `target` (which lies on a surface with
/// normal `ng_target`, or anywhere when `None`), stopping just short of it.
#[inline]
pub fn spawn_ray_to(p: Vec3, ng: Vec3, target: Vec3, ng_target: Option<Vec3>) -> Ray {
    let o = offset_ray_origin(p, ng, target - p);
    let end = match ng_target {
        Some(n) => offset_ray_origin(target, n, o - target),
        None => target,
    };
    let d = end - o;
    Ray {
        o,
        d,
        t_min: 0.0,
        t_max: SHADOW_RAY_END,
    }
}
