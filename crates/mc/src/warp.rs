//! Warps: maps from the unit square [0, 1)² to other domains, each with its density.
//!
//! They come in threes, as in pbrt-v4: `sample_x(u)` maps a uniform point to the domain,
//! `x_pdf(..)` is the density of the result (solid-angle measure for directions, area measure
//! for disks and triangles), and `invert_x_sample(value)` maps a point of the domain back to
//! the `u` that produces it. The inverse makes round-trip tests possible and keeps
//! stratification visible: a stratified `u` gives stratified directions.
//!
//! Directions are in a local frame whose z axis is the pole (the shading normal for
//! hemispheres, the cone axis for cones); θ is measured from +z and φ around it from +x.
//!
//! The warps a renderer's inner loop draws from (the concentric disk, the cosine-weighted
//! hemisphere, the triangle, the orthonormal basis) are written once over
//! [`crate::simd::lanes::Real`]: `sample_x(u)` is their one-value form, and code that samples eight
//! directions at once calls the same function on lanes, to the same bits.
//!
//! ```
//! use glam::Vec2;
//! use pathlab_mc::warp::{sample_cosine_hemisphere, cosine_hemisphere_pdf};
//! let w = sample_cosine_hemisphere(Vec2::new(0.3, 0.8));
//! assert!(w.z > 0.0 && (w.length() - 1.0).abs() < 1e-6);
//! // pdf(ω) = cos θ / π
//! assert!((cosine_hemisphere_pdf(w.z) - w.z / std::f32::consts::PI).abs() < 1e-7);
//! ```

use crate::simd::lanes::{Real, Vector3};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

const INV_TAU: f32 = 1.0 / TAU;
const INV_4PI: f32 = 1.0 / (4.0 * PI);

#[inline]
fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// φ = atan2(y, x) mapped to [0, 1) as a fraction of a turn.
#[inline]
fn phi_fraction(y: f32, x: f32) -> f32 {
    let mut phi = y.atan2(x);
    if phi < 0.0 {
        phi += TAU;
    }
    (phi * INV_TAU).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
}

// ---------------------------------------------------------------------------------------------
// Disk

/// Shirley and Chiu's concentric map from the square to the unit disk: area preserving, and
/// concentric squares go to concentric circles, so strata stay compact.
#[inline]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = uniform_disk_concentric(u.x, u.y);
    Vec2::new(x, y)
}

/// [`sample_uniform_disk_concentric`] for one value or for lanes: the point (x, y) of the disk
/// for (u₀, u₁).
#[inline(always)]
pub fn uniform_disk_concentric<T: Real>(u0: T, u1: T) -> (T, T) {
    let (zero, one, two) = (T::splat(0.0), T::splat(1.0), T::splat(2.0));
    let ux = two * u0 - one;
    let uy = two * u1 - one;
    let centre = ux.equals(zero) & uy.equals(zero);
    // θ = π/4 (y/x) in the wedges where |x| > |y|, θ = π/2 - π/4 (x/y) in the others, whose
    // cosine and sine are the sine and cosine of π/4 (x/y).
    let x_wedge = ux.abs().gt(uy.abs());
    let r = T::select(x_wedge, ux, uy);
    let ratio = T::select(x_wedge, uy / ux, ux / uy);
    let (sin, cos) = sin_cos_quarter_turn(ratio);
    let x = T::select(centre, zero, r * T::select(x_wedge, cos, sin));
    let y = T::select(centre, zero, r * T::select(x_wedge, sin, cos));
    (x, y)
}

pub use crate::simd::trig::sin_cos_quarter_turn;

/// Density of a uniform point on the unit disk, per unit area: 1/π inside, 0 outside.
#[inline]
pub fn uniform_disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// The `u` that [`sample_uniform_disk_concentric`] maps to `p`.
pub fn invert_uniform_disk_concentric_sample(p: Vec2) -> Vec2 {
    let theta = p.y.atan2(p.x); // in (-π, π]
    let len = p.length();
    let (ox, oy);
    if theta.abs() < FRAC_PI_4 || theta.abs() > 3.0 * FRAC_PI_4 {
        // |x| >= |y| wedges: r = x, angle = (π/4) (y/x) measured from the x axis.
        let r = len.copysign(p.x);
        let angle = if p.x >= 0.0 {
            theta
        } else if theta > 0.0 {
            theta - PI
        } else {
            theta + PI
        };
        ox = r;
        oy = angle * r / FRAC_PI_4;
    } else {
        // |y| > |x| wedges: r = y, angle = π/2 - (π/4) (x/y).
        let r = len.copysign(p.y);
        let angle = if p.y >= 0.0 { theta } else { theta + PI };
        oy = r;
        ox = (FRAC_PI_2 - angle) * r / FRAC_PI_4;
    }
    ((Vec2::new(ox, oy) + Vec2::ONE) * 0.5).clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON / 2.0))
}

// ---------------------------------------------------------------------------------------------
// Hemisphere and sphere

/// A direction uniform over the hemisphere z ≥ 0: cos θ = u₀, φ = 2π u₁.
#[inline]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_hemisphere`] per unit solid angle: 1/(2π).
#[inline]
pub fn uniform_hemisphere_pdf() -> f32 {
    INV_TAU
}

/// The `u` that [`sample_uniform_hemisphere`] maps to `w`.
#[inline]
pub fn invert_uniform_hemisphere_sample(w: Vec3) -> Vec2 {
    Vec2::new(w.z, phi_fraction(w.y, w.x))
}

/// A direction over the hemisphere z ≥ 0 with density cos θ / π (Malley's method: a uniform
/// point of the disk, lifted to the hemisphere).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    cosine_hemisphere(u.x, u.y)
}

/// [`sample_cosine_hemisphere`] for one value or for lanes.
#[inline(always)]
pub fn cosine_hemisphere<T: Real>(u0: T, u1: T) -> T::V3 {
    let (x, y) = uniform_disk_concentric(u0, u1);
    let z = (T::splat(1.0) - x * x - y * y).max(T::splat(0.0)).sqrt();
    T::V3::new(x, y, z)
}

/// Density of [`sample_cosine_hemisphere`] per unit solid angle: cos θ / π (0 below the horizon).
#[inline(always)]
pub fn cosine_hemisphere_pdf<T: Real>(cos_theta: T) -> T {
    cos_theta.max(T::splat(0.0)) * T::splat(FRAC_1_PI)
}

/// The `u` that [`sample_cosine_hemisphere`] maps to `w`.
#[inline]
pub fn invert_cosine_hemisphere_sample(w: Vec3) -> Vec2 {
    invert_uniform_disk_concentric_sample(Vec2::new(w.x, w.y))
}

/// A direction uniform over the whole sphere: z = 1 - 2u₀, φ = 2π u₁.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`] per unit solid angle: 1/(4π).
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    INV_4PI
}

/// The `u` that [`sample_uniform_sphere`] maps to `w`.
#[inline]
pub fn invert_uniform_sphere_sample(w: Vec3) -> Vec2 {
    Vec2::new(((1.0 - w.z) * 0.5).clamp(0.0, 1.0), phi_fraction(w.y, w.x))
}

// ---------------------------------------------------------------------------------------------
// Cone

/// A direction uniform inside the cone of half-angle θmax around +z:
/// cos θ = (1 - u₀) + u₀ cos θmax, φ = 2π u₁. Used to sample the solid angle a sphere
/// subtends.
#[inline]
pub fn sample_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_theta_max;
    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
    let phi = TAU * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Density of [`sample_uniform_cone`] per unit solid angle: 1 / (2π (1 - cos θmax)).
#[inline]
pub fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    1.0 / (TAU * (1.0 - cos_theta_max))
}

/// The `u` that [`sample_uniform_cone`] maps to `w`.
#[inline]
pub fn invert_uniform_cone_sample(w: Vec3, cos_theta_max: f32) -> Vec2 {
    let u0 = (1.0 - w.z) / (1.0 - cos_theta_max);
    Vec2::new(u0.clamp(0.0, 1.0), phi_fraction(w.y, w.x))
}

// ---------------------------------------------------------------------------------------------
// Triangle

/// Barycentric coordinates `(b₀, b₁, b₂)` of a point uniform over a triangle:
/// b₀ = 1 - √u₀, b₁ = u₁ √u₀ (the square-root parameterisation; the point is
/// `b₀ p₀ + b₁ p₁ + b₂ p₂`).
#[inline]
pub fn sample_uniform_triangle(u: Vec2) -> [f32; 3] {
    uniform_triangle(u.x, u.y)
}

/// [`sample_uniform_triangle`] for one value or for lanes.
#[inline(always)]
pub fn uniform_triangle<T: Real>(u0: T, u1: T) -> [T; 3] {
    let one = T::splat(1.0);
    let su0 = u0.sqrt();
    let b0 = one - su0;
    let b1 = u1 * su0;
    [b0, b1, (one - b0 - b1).max(T::splat(0.0))]
}

/// Density of [`sample_uniform_triangle`] per unit area of a triangle of `area`: 1/area.
/// (Over the barycentric coordinates (b₀, b₁), whose triangle has area 1/2, it is 2.)
#[inline]
pub fn uniform_triangle_pdf(area: f32) -> f32 {
    1.0 / area
}

/// The `u` that [`sample_uniform_triangle`] maps to barycentrics `b`.
#[inline]
pub fn invert_uniform_triangle_sample(b: [f32; 3]) -> Vec2 {
    let su0 = 1.0 - b[0];
    let u1 = if su0 > 0.0 { b[1] / su0 } else { 0.0 };
    Vec2::new((su0 * su0).clamp(0.0, 1.0), u1.clamp(0.0, 1.0))
}

// ---------------------------------------------------------------------------------------------
// Frames

/// Two unit vectors completing `n` (unit) to a right-handed orthonormal basis (Duff et al.,
/// "Building an Orthonormal Basis, Revisited", JCGT 2017); for one vector or for lanes.
#[inline(always)]
pub fn coordinate_system<V: Vector3>(n: V) -> (V, V) {
    let (x, y, z) = (n.x(), n.y(), n.z());
    let one = V::R::splat(1.0);
    let sign = z.sign_one();
    let a = V::R::splat(-1.0) / (sign + z);
    let b = x * y * a;
    (
        V::new(one + sign * x * x * a, sign * b, -sign * x),
        V::new(b, sign + y * y * a, -y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    /// Distance from `x` to `exact` in units of the spacing of f32 values at `exact`.
    fn ulps(x: f32, exact: f64) -> f64 {
        let e = exact.abs() as f32;
        let spacing = (e.next_up() - e).max(f32::MIN_POSITIVE) as f64;
        (x as f64 - exact).abs() / spacing
    }

    #[test]
    fn quarter_turn_sin_cos_is_within_two_ulps() {
        let n = 1 << 20;
        let mut worst = (0.0f64, 0.0f64);
        for i in 0..=n {
            let t = -1.0 + 2.0 * i as f32 / n as f32;
            let (sin, cos) = sin_cos_quarter_turn(t);
            let a = std::f64::consts::FRAC_PI_4 * t as f64;
            worst.0 = worst.0.max(ulps(sin, a.sin()));
            worst.1 = worst.1.max(ulps(cos, a.cos()));
            // Never outside [-1, 1], so r (cos, sin) stays within the disk.
            assert!(cos <= 1.0 && sin.abs() <= 1.0, "t = {t}");
        }
        assert!(
            worst.0 <= 2.0 && worst.1 <= 2.0,
            "worst ulps (sin, cos): {worst:?}"
        );
        assert_eq!(sin_cos_quarter_turn(0.0), (0.0, 1.0));
    }

    fn uniform_points(n: usize) -> Vec<Vec2> {
        let mut rng = Pcg32::new(5, 9);
        let mut v: Vec<Vec2> = (0..n)
            .map(|_| Vec2::new(rng.uniform_f32(), rng.uniform_f32()))
            .collect();
        // Corners and edges, where the maps have their special cases.
        for &x in &[0.0, 0.25, 0.5, 0.75, 0.999_999] {
            for &y in &[0.0, 0.25, 0.5, 0.75, 0.999_999] {
                v.push(Vec2::new(x, y));
            }
        }
        v
    }

    /// Checks `invert(sample(u)) == u` for `u` with u₀ in `u0_range` (φ is undefined at a pole,
    /// where the map is not invertible).
    fn assert_round_trip(
        name: &str,
        u0_range: std::ops::Range<f32>,
        round_trip: impl Fn(Vec2) -> Vec2,
    ) {
        for u in uniform_points(20_000) {
            if !u0_range.contains(&u.x) {
                continue;
            }
            let back = round_trip(u);
            // The azimuth wraps at u₁ = 0 ~ 1; compare on the circle for that coordinate.
            let d = (back - u).abs();
            let dy = d.y.min(1.0 - d.y);
            assert!(
                d.x < 2e-3 && dy < 2e-3,
                "{name}: u = {u:?} came back as {back:?}"
            );
        }
    }

    #[test]
    fn round_trips() {
        let all = 0.0..1.0;
        let no_pole = 1e-3..1.0;
        assert_round_trip("disk", all.clone(), |u| {
            invert_uniform_disk_concentric_sample(sample_uniform_disk_concentric(u))
        });
        assert_round_trip("cosine hemisphere", all, |u| {
            invert_cosine_hemisphere_sample(sample_cosine_hemisphere(u))
        });
        assert_round_trip("uniform hemisphere", 0.0..0.999, |u| {
            invert_uniform_hemisphere_sample(sample_uniform_hemisphere(u))
        });
        assert_round_trip("sphere", 1e-3..0.999, |u| {
            invert_uniform_sphere_sample(sample_uniform_sphere(u))
        });
        assert_round_trip("cone", no_pole.clone(), |u| {
            invert_uniform_cone_sample(sample_uniform_cone(u, 0.3), 0.3)
        });
        assert_round_trip("triangle", no_pole, |u| {
            invert_uniform_triangle_sample(sample_uniform_triangle(u))
        });
    }

    #[test]
    fn samples_lie_in_their_domains() {
        for u in uniform_points(10_000) {
            let d = sample_uniform_disk_concentric(u);
            assert!(d.length() <= 1.0 + 1e-6);
            for w in [
                sample_uniform_hemisphere(u),
                sample_cosine_hemisphere(u),
                sample_uniform_sphere(u),
                sample_uniform_cone(u, 0.5),
            ] {
                assert!((w.length() - 1.0).abs() < 1e-5, "{w:?}");
            }
            assert!(sample_uniform_hemisphere(u).z >= 0.0);
            assert!(sample_cosine_hemisphere(u).z >= 0.0);
            assert!(sample_uniform_cone(u, 0.5).z >= 0.5 - 1e-6);
            let b = sample_uniform_triangle(u);
            assert!(b.iter().all(|&x| (0.0..=1.0).contains(&x)));
            assert!((b[0] + b[1] + b[2] - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn coordinate_system_is_orthonormal() {
        for u in uniform_points(2_000) {
            let n = sample_uniform_sphere(u);
            let (s, t) = coordinate_system(n);
            assert!((s.length() - 1.0).abs() < 1e-5 && (t.length() - 1.0).abs() < 1e-5);
            assert!(s.dot(n).abs() < 1e-5 && t.dot(n).abs() < 1e-5 && s.dot(t).abs() < 1e-5);
            assert!((s.cross(t) - n).length() < 1e-4);
        }
    }
}
