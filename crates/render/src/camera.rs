//! The camera: perspective (pinhole, or thin lens when it has an aperture) or orthographic,
//! and the pixel filter that places each pixel's samples; its importance, for light traced to
//! the lens (`importance`).

use crate::desc::{CameraDesc, FovAxis, PixelFilter, Projection};
use crate::geometry::Ray;
use crate::simd::lanes::{Real, Vector3, F8, W};
use glam::{Vec2, Vec3};
use pathlab_mc::warp::sample_uniform_disk_concentric;
use std::sync::Arc;

mod importance;
pub use importance::CameraWiSample;

/// A camera generating rays through film positions.
///
/// Film coordinates are in pixels, `(0, 0)` at the top-left corner of the image, x to the right
/// and y down; the image's right is the camera's right (`forward × up`) and its top is `up`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    origin: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Half-extents of the image on the plane at distance 1 (orthographic: in scene units).
    half: Vec2,
    /// Shift of the image window in normalised device coordinates.
    shift: Vec2,
    orthographic: bool,
    resolution: [u32; 2],
    lens_radius: f32,
    focal_distance: f32,
    near: f32,
    far: f32,
    filter: Option<Arc<FilterSampler>>,
}

impl Camera {
    /// The camera of `desc` for an image of `resolution`.
    pub fn new(desc: &CameraDesc, resolution: [u32; 2]) -> Self {
        let forward = (desc.target - desc.origin).normalize_or(Vec3::NEG_Z);
        let mut right = forward.cross(desc.up).normalize_or_zero();
        if right == Vec3::ZERO {
            right = pathlab_mc::warp::coordinate_system(forward).0;
        }
        let up = right.cross(forward);
        let (w, h) = (resolution[0].max(1) as f32, resolution[1].max(1) as f32);
        let (tan, along) = match desc.focal_pixels {
            Some(d) if d > 0.0 && d.is_finite() => (0.5, d),
            _ => (
                (desc.fov_degrees.to_radians() * 0.5).tan(),
                match desc.fov_axis {
                    FovAxis::X => w,
                    FovAxis::Y => h,
                    FovAxis::Smaller => w.min(h),
                    FovAxis::Larger => w.max(h),
                    FovAxis::Diagonal => (w * w + h * h).sqrt(),
                },
            ),
        };
        let (half, orthographic) = match desc.projection {
            Projection::Perspective => (Vec2::new(tan * w / along, tan * h / along), false),
            Projection::Orthographic { half_extent } => (half_extent, true),
        };
        Camera {
            origin: desc.origin,
            right,
            up,
            forward,
            half,
            shift: Vec2::new(
                2.0 * desc.principal_point_offset.x,
                -2.0 * desc.principal_point_offset.y,
            ),
            orthographic,
            resolution,
            lens_radius: desc.lens_radius.max(0.0),
            focal_distance: desc.focal_distance,
            near: desc.near_clip.max(0.0),
            far: if desc.far_clip > desc.near_clip {
                desc.far_clip
            } else {
                f32::INFINITY
            },
            filter: None,
        }
    }

    /// The camera with pixel filter `filter` placing its samples.
    pub fn with_filter(mut self, filter: PixelFilter) -> Self {
        self.filter = FilterSampler::new(filter).map(Arc::new);
        self
    }

    /// The film position of the sample `u` ∈ [0, 1)² of pixel `pixel` and the weight its
    /// radiance takes: uniform in the pixel for a box filter, otherwise drawn from the filter
    /// around the pixel's centre, restricted to the image (so that each pixel's expected
    /// value is the filter-weighted average of the radiance over the image, as splatting
    /// samples into neighbouring pixels gives). The weight is one except under filters with
    /// negative lobes (see [`FilterSampler`]).
    #[inline]
    pub fn film_sample(&self, pixel: [u32; 2], u: Vec2) -> (Vec2, f32) {
        let p = Vec2::new(pixel[0] as f32, pixel[1] as f32);
        match &self.filter {
            None => (p + u, 1.0),
            Some(f) => {
                let c = p + 0.5;
                let (w, h) = (self.resolution[0] as f32, self.resolution[1] as f32);
                let (x, wx) = f.sample(u.x, -c.x, w - c.x);
                let (y, wy) = f.sample(u.y, -c.y, h - c.y);
                (Vec2::new(c.x + x, c.y + y), wx * wy)
            }
        }
    }

    /// Image size in pixels.
    pub fn resolution(&self) -> [u32; 2] {
        self.resolution
    }

    /// The camera position.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The vertical field of view in degrees.
    pub fn vertical_fov_degrees(&self) -> f32 {
        2.0 * self.half.y.atan().to_degrees()
    }

    /// The ray through film position `film` (pixels), through the lens point chosen by
    /// `u_lens` when the camera has an aperture. The direction has unit length.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, u_lens: Vec2) -> Ray {
        let (o, d, cos) = self.pinhole_ray(film.x, film.y);
        if self.orthographic || self.lens_radius <= 0.0 {
            let (t_min, t_max) = self.clip(cos);
            return Ray { o, d, t_min, t_max };
        }
        // Thin lens: every ray through the lens point meets the pinhole ray at the plane of
        // focus.
        let lens = self.lens_radius * sample_uniform_disk_concentric(u_lens);
        let o = self.origin + lens.x * self.right + lens.y * self.up;
        let focus = self.origin + d * (self.focal_distance / d.dot(self.forward));
        let d = (focus - o).normalize();
        let (t_min, t_max) = self.clip(d.dot(self.forward));
        Ray { o, d, t_min, t_max }
    }

    /// [`Camera::generate_ray`] for eight film positions at once, the same rays to the bit,
    /// where the camera has no lens (pinhole or orthographic; `None` for a thin lens, whose
    /// rays made eight at a time, the lens warp on lanes too, measured slower than one at a
    /// time: cornell-thinlens ×0.98).
    pub fn generate_rays(&self, film: [Vec2; W]) -> Option<[Ray; W]> {
        if !self.orthographic && self.lens_radius > 0.0 {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = crate::simd::Avx2::detect() {
            // SAFETY: `rays_avx2` requires AVX2 and FMA, which `avx2` proves this CPU has. Its
            // body is safe code.
            return Some(unsafe { self.rays_avx2(avx2, &film) });
        }
        Some(self.rays_lanes(&film))
    }

    /// [`Camera::rays_lanes`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn rays_avx2(&self, _: crate::simd::Avx2, film: &[Vec2; W]) -> [Ray; W] {
        self.rays_lanes(film)
    }

    /// The rays of a camera without a lens through eight film positions, on lanes.
    #[inline(always)]
    fn rays_lanes(&self, film: &[Vec2; W]) -> [Ray; W] {
        let (o, d, cos) = self.pinhole_ray(F8(film.map(|f| f.x)), F8(film.map(|f| f.y)));
        let (t_min, t_max) = self.clip(cos);
        std::array::from_fn(|i| Ray {
            o: o.get(i),
            d: d.get(i),
            t_min: t_min.0[i],
            t_max: t_max.0[i],
        })
    }

    /// The ray through film position (`fx`, `fy`) of the camera without its lens, for one
    /// position or for lanes: origin, unit direction, and the cosine to the viewing direction
    /// that turns the clipping distances into distances along the ray (one for an
    /// orthographic camera).
    #[inline(always)]
    fn pinhole_ray<T: Real>(&self, fx: T, fy: T) -> (T::V3, T::V3, T) {
        let [w, h] = self.resolution.map(|r| T::splat(r as f32));
        let (one, two) = (T::splat(1.0), T::splat(2.0));
        let (mut x, mut y) = (two * fx / w - one, one - two * fy / h);
        if self.shift != Vec2::ZERO {
            x = x + T::splat(self.shift.x);
            y = y + T::splat(self.shift.y);
        }
        let right = T::V3::splat(self.right).scale(x * T::splat(self.half.x));
        let up = T::V3::splat(self.up).scale(y * T::splat(self.half.y));
        let forward = T::V3::splat(self.forward);
        if self.orthographic {
            return (T::V3::splat(self.origin) + right + up, forward, one);
        }
        let d = (right + up + forward).normalize();
        (T::V3::splat(self.origin), d, d.dot(forward))
    }

    /// The film position (pixel units, as [`Camera::film_sample`] gives them) where world
    /// point `p` appears: the inverse of [`Camera::generate_ray`] through the lens's centre.
    /// `None` behind a perspective camera or for a non-finite point.
    pub fn raster_position(&self, p: Vec3) -> Option<Vec2> {
        let v = p - self.origin;
        let (x, y, z) = (v.dot(self.right), v.dot(self.up), v.dot(self.forward));
        let ndc = if self.orthographic {
            Vec2::new(x / self.half.x, y / self.half.y)
        } else {
            if z <= 0.0 {
                return None;
            }
            Vec2::new(x / (z * self.half.x), y / (z * self.half.y))
        } - self.shift;
        let [w, h] = self.resolution.map(|r| r as f32);
        let film = Vec2::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h);
        film.is_finite().then_some(film)
    }

    /// The extent of a ray between the near and far clipping planes, `(t_min, t_max)` (`cos`:
    /// the cosine between the ray and the viewing direction); unbounded without clipping.
    #[inline(always)]
    fn clip<T: Real>(&self, cos: T) -> (T, T) {
        if self.near > 0.0 || self.far.is_finite() {
            let inv = T::splat(1.0) / cos.max(T::splat(1e-6));
            (T::splat(self.near) * inv, T::splat(self.far) * inv)
        } else {
            (T::splat(0.0), T::splat(f32::INFINITY))
        }
    }
}

/// Draws pixel sample offsets from a filter's one-dimensional profile (the filters are
/// separable): the inverse of its tabulated cumulative distribution of |f|, restricted to an
/// interval (the part of the filter inside the image). Filters with negative lobes give each
/// offset a signed weight, sign(f) ∫|f| / ∫f over the interval, whose mean is one: the
/// weighted samples' mean is then the filter-weighted average of the radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSampler {
    radius: f32,
    /// Cumulative |f| at the edges of `BINS` equal bins over [-radius, radius], from 0 to 1.
    cdf: Vec<f32>,
    /// Cumulative f at the same edges, on the same scale; `None` where f ≥ 0 (it equals
    /// `cdf`, and every weight is one).
    signed: Option<Vec<f32>>,
    /// `cumulative_at(&cdf, x)` at x = -radius and x = radius, where the interval of a pixel
    /// away from the image's edges starts and ends: computed once rather than per sample.
    cdf_at_ends: [f32; 2],
}

/// Mitchell and Netravali's cubic at |x| ≤ 2.
fn mitchell_1d(x: f64, b: f64, c: f64) -> f64 {
    let x = x.abs();
    let v = if x <= 1.0 {
        (12.0 - 9.0 * b - 6.0 * c) * x * x * x
            + (-18.0 + 12.0 * b + 6.0 * c) * x * x
            + (6.0 - 2.0 * b)
    } else if x <= 2.0 {
        (-b - 6.0 * c) * x * x * x
            + (6.0 * b + 30.0 * c) * x * x
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c)
    } else {
        0.0
    };
    v / 6.0
}

/// sin(πx) / (πx).
fn sinc(x: f64) -> f64 {
    let px = std::f64::consts::PI * x;
    if px.abs() < 1e-5 {
        1.0 - px * px / 6.0
    } else {
        px.sin() / px
    }
}

impl FilterSampler {
    const BINS: usize = 1024;

    /// The sampler for `filter` (`None` for the box filter, which needs none).
    pub fn new(filter: PixelFilter) -> Option<Self> {
        let (radius, weight): (f32, Box<dyn Fn(f32) -> f64>) = match filter {
            PixelFilter::Box => return None,
            PixelFilter::Tent { radius } => {
                let r = radius.max(1e-3);
                (
                    r,
                    Box::new(move |x: f32| (1.0 - (x / r).abs()).max(0.0) as f64),
                )
            }
            PixelFilter::Gaussian { stddev, radius } => {
                let s = stddev.max(1e-3) as f64;
                let r = radius.max(1e-3) as f64;
                let cut = (-r * r / (2.0 * s * s)).exp();
                (
                    r as f32,
                    Box::new(move |x: f32| {
                        let x = x as f64;
                        ((-x * x / (2.0 * s * s)).exp() - cut).max(0.0)
                    }),
                )
            }
            PixelFilter::Mitchell { radius, b, c } => {
                let r = radius.max(1e-3);
                let (b, c) = (b as f64, c as f64);
                (
                    r,
                    Box::new(move |x: f32| mitchell_1d(2.0 * x as f64 / r as f64, b, c)),
                )
            }
            PixelFilter::LanczosSinc { radius, tau } => {
                let r = radius.max(1e-3);
                let tau = tau.max(1e-3) as f64;
                (
                    r,
                    Box::new(move |x: f32| {
                        let x = x as f64;
                        if x.abs() > r as f64 {
                            0.0
                        } else {
                            sinc(x) * sinc(x / tau)
                        }
                    }),
                )
            }
        };
        let n = Self::BINS;
        let step = 2.0 * radius / n as f32;
        // Midpoint rule in each bin.
        let values: Vec<f64> = (0..n)
            .map(|i| weight(-radius + (i as f32 + 0.5) * step))
            .collect();
        let cumulative = |f: &dyn Fn(f64) -> f64| {
            let mut sum = 0.0f64;
            let mut c = Vec::with_capacity(n + 1);
            c.push(0.0);
            for v in &values {
                sum += f(*v);
                c.push(sum);
            }
            c
        };
        let abs = cumulative(&f64::abs);
        let total = abs[n];
        let scale = |c: Vec<f64>| c.into_iter().map(|v| (v / total) as f32).collect();
        let signed = values
            .iter()
            .any(|v| *v < 0.0)
            .then(|| scale(cumulative(&|v| v)));
        let mut sampler = FilterSampler {
            radius,
            cdf: scale(abs),
            signed,
            cdf_at_ends: [0.0; 2],
        };
        sampler.cdf_at_ends = [
            sampler.cumulative_at(&sampler.cdf, -radius),
            sampler.cumulative_at(&sampler.cdf, radius),
        ];
        Some(sampler)
    }

    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// `table` (a cumulative distribution) at offset `x`.
    fn cumulative_at(&self, table: &[f32], x: f32) -> f32 {
        let t = ((x + self.radius) / (2.0 * self.radius) * Self::BINS as f32)
            .clamp(0.0, Self::BINS as f32);
        let i = (t as usize).min(Self::BINS - 1);
        let f = t - i as f32;
        table[i] + f * (table[i + 1] - table[i])
    }

    /// An offset in [lo, hi] ∩ [-radius, radius] drawn with density ∝ |f|, from `u`, and its
    /// weight (one for filters without negative lobes).
    pub fn sample(&self, u: f32, lo: f32, hi: f32) -> (f32, f32) {
        let (lo, hi) = (lo.max(-self.radius), hi.min(self.radius));
        // The same values as `cumulative_at` at the ends, computed once.
        let a = if lo == -self.radius {
            self.cdf_at_ends[0]
        } else {
            self.cumulative_at(&self.cdf, lo)
        };
        let b = if hi == self.radius {
            self.cdf_at_ends[1]
        } else {
            self.cumulative_at(&self.cdf, hi)
        };
        let target = a + u * (b - a);
        // The bin holding `target`, then linear within it (the density is constant per bin).
        let i = self
            .cdf
            .partition_point(|&c| c <= target)
            .clamp(1, Self::BINS)
            - 1;
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let f = if c1 > c0 {
            (target - c0) / (c1 - c0)
        } else {
            0.5
        };
        let step = 2.0 * self.radius / Self::BINS as f32;
        let x = (-self.radius + (i as f32 + f) * step).clamp(lo, hi);
        let Some(signed) = &self.signed else {
            return (x, 1.0);
        };
        // sign(f) in the bin, times ∫|f| / ∫f over the interval.
        let negative = signed[i + 1] < signed[i];
        let net = self.cumulative_at(signed, hi) - self.cumulative_at(signed, lo);
        let w = if net > 0.0 { (b - a) / net } else { 0.0 };
        (x, if negative { -w } else { w })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_filters_weigh_samples_to_the_filter_weighted_average() {
        use pathlab_mc::estimator::RunningStats;
        use pathlab_mc::rng::Pcg32;
        // E[w g(x)] = ∫ f g / ∫ f over the interval, for g = 1, x, x²: the weighted samples
        // estimate the filter-normalised average of any function of the offset.
        let filters = [
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 0.0,
                c: 0.5,
            },
            PixelFilter::LanczosSinc {
                radius: 4.0,
                tau: 3.0,
            },
        ];
        let profile = |filter: PixelFilter, x: f64| match filter {
            PixelFilter::Mitchell { radius, b, c } => {
                mitchell_1d(2.0 * x / radius as f64, b as f64, c as f64)
            }
            PixelFilter::LanczosSinc { radius, tau } if x.abs() <= radius as f64 => {
                sinc(x) * sinc(x / tau as f64)
            }
            _ => 0.0,
        };
        let mut rng = Pcg32::new(2, 8);
        for filter in filters {
            let sampler = FilterSampler::new(filter).unwrap();
            let r = sampler.radius();
            for (lo, hi) in [(-10.0f32, 10.0f32), (-0.5, 10.0), (-10.0, 1.2)] {
                let (a, b) = (lo.max(-r) as f64, hi.min(r) as f64);
                let n = 200_000;
                let h = (b - a) / n as f64;
                let moment = |k: i32| -> f64 {
                    (0..n)
                        .map(|i| {
                            let x = a + (i as f64 + 0.5) * h;
                            profile(filter, x) * x.powi(k)
                        })
                        .sum::<f64>()
                        * h
                };
                let mass = moment(0);
                let mut stats = [
                    RunningStats::new(),
                    RunningStats::new(),
                    RunningStats::new(),
                ];
                let mut negative = 0;
                for _ in 0..400_000 {
                    let (x, w) = sampler.sample(rng.uniform_f32(), lo, hi);
                    negative += (w < 0.0) as u32;
                    for (k, s) in stats.iter_mut().enumerate() {
                        s.push(w as f64 * (x as f64).powi(k as i32));
                    }
                }
                assert!(negative > 0, "{filter:?}: no negative lobe sampled");
                for (k, s) in stats.iter().enumerate() {
                    let exact = moment(k as i32) / mass;
                    assert!(
                        (s.mean() - exact).abs() < 4.0 * s.std_error() + 2e-3,
                        "{filter:?} over [{lo}, {hi}], moment {k}: {} ± {} vs {exact}",
                        s.mean(),
                        s.std_error()
                    );
                }
            }
        }
        // Filters without negative lobes weigh every sample exactly one.
        let tent = FilterSampler::new(PixelFilter::Tent { radius: 1.5 }).unwrap();
        for i in 0..100 {
            assert_eq!(tent.sample(i as f32 / 100.0, -0.7, 3.0).1, 1.0);
        }
    }

    #[test]
    fn filter_offsets_fit_the_filter_profile_over_any_interval() {
        use pathlab_mc::rng::Pcg32;
        use pathlab_mc::stats::{bonferroni, chi2_test_1d};
        // Each filter's profile, for the test to normalise over the interval it samples.
        let gaussian = |s: f64, r: f64| {
            move |x: f64| {
                let g = |x: f64| (-x * x / (2.0 * s * s)).exp();
                if x.abs() < r {
                    (g(x) - g(r)).max(0.0)
                } else {
                    0.0
                }
            }
        };
        type Profile = Box<dyn Fn(f64) -> f64>;
        let filters: [(PixelFilter, Profile); 4] = [
            (
                PixelFilter::Tent { radius: 1.0 },
                Box::new(|x: f64| (1.0 - x.abs()).max(0.0)),
            ),
            // A filter with negative lobes is sampled in proportion to |f|.
            (
                PixelFilter::Mitchell {
                    radius: 2.0,
                    b: 1.0 / 3.0,
                    c: 1.0 / 3.0,
                },
                Box::new(|x: f64| mitchell_1d(x, 1.0 / 3.0, 1.0 / 3.0).abs()),
            ),
            (PixelFilter::gaussian(0.5), Box::new(gaussian(0.5, 2.0))),
            (
                PixelFilter::Gaussian {
                    stddev: 0.5,
                    radius: 1.5,
                },
                Box::new(gaussian(0.5, 1.5)),
            ),
        ];
        let intervals = [(-10.0f32, 10.0f32), (-0.3, 10.0), (-10.0, 0.6)];
        let alpha = bonferroni(0.01, filters.len() * intervals.len());
        let mut rng = Pcg32::new(11, 4);
        for (filter, profile) in &filters {
            let sampler = FilterSampler::new(*filter).unwrap();
            let r = sampler.radius();
            for &(lo, hi) in &intervals {
                let (a, b) = (lo.max(-r) as f64, hi.min(r) as f64);
                // The profile's integral over [a, b] by the midpoint rule.
                let n = 100_000;
                let h = (b - a) / n as f64;
                let mass: f64 = (0..n)
                    .map(|i| profile(a + (i as f64 + 0.5) * h))
                    .sum::<f64>()
                    * h;
                let samples: Vec<f64> = (0..200_000)
                    .map(|_| sampler.sample(rng.uniform_f32(), lo, hi).0 as f64)
                    .collect();
                assert!(samples.iter().all(|&x| x >= a && x <= b));
                let t = chi2_test_1d(samples, |x| profile(x) / mass, [a, b], 40);
                assert!(
                    t.passes(alpha),
                    "{filter:?} over [{lo}, {hi}]: p = {:.2e}",
                    t.p_value
                );
            }
        }
    }

    #[test]
    fn raster_positions_invert_camera_rays() {
        let mut desc = CameraDesc {
            origin: Vec3::new(0.3, 0.5, 3.9),
            target: Vec3::new(0.0, 0.2, 0.0),
            up: Vec3::Y,
            fov_degrees: 50.0,
            principal_point_offset: Vec2::new(0.1, -0.05),
            ..Default::default()
        };
        let ortho = Projection::Orthographic {
            half_extent: Vec2::new(2.0, 1.2),
        };
        for projection in [Projection::Perspective, ortho] {
            desc.projection = projection;
            let cam = Camera::new(&desc, [160, 90]);
            for film in [
                Vec2::new(0.0, 0.0),
                Vec2::new(80.0, 45.0),
                Vec2::new(151.3, 7.9),
            ] {
                let ray = cam.generate_ray(film, Vec2::ZERO);
                let back = cam.raster_position(ray.o + 2.5 * ray.d).unwrap();
                assert!(
                    (back - film).length() < 1e-3,
                    "{projection:?}: {film} -> {back}"
                );
            }
        }
        desc.projection = Projection::Perspective;
        let cam = Camera::new(&desc, [160, 90]);
        assert_eq!(cam.raster_position(desc.origin * 2.0 - desc.target), None);
    }

    #[test]
    fn centre_and_corners() {
        let desc = CameraDesc {
            origin: Vec3::new(0.0, 0.0, 3.9),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 90.0,
            ..Default::default()
        };
        let cam = Camera::new(&desc, [200, 100]);
        let c = cam.generate_ray(Vec2::new(100.0, 50.0), Vec2::ZERO);
        assert!((c.d - Vec3::NEG_Z).length() < 1e-6);
        // fov 90° on the smaller (vertical) axis: the top edge is 45° up, the right edge at
        // tan = 2 to the right (+x, since the camera looks down -z with +y up).
        let top = cam.generate_ray(Vec2::new(100.0, 0.0), Vec2::ZERO);
        assert!((top.d - Vec3::new(0.0, 1.0, -1.0).normalize()).length() < 1e-6);
        let right = cam.generate_ray(Vec2::new(200.0, 50.0), Vec2::ZERO);
        assert!((right.d - Vec3::new(2.0, 0.0, -1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn principal_point_offset_moves_the_window_as_mitsuba_does() {
        // Mitsuba adds offset × film size to the film position before projecting: with an
        // offset of (0.25, 0.1), pixel (x, y) sees what the centred camera sees at
        // (x + 0.25 W, y + 0.1 H).
        let desc = CameraDesc {
            fov_degrees: 50.0,
            ..Default::default()
        };
        let shifted = Camera::new(
            &CameraDesc {
                principal_point_offset: Vec2::new(0.25, 0.1),
                ..desc
            },
            [200, 100],
        );
        let centred = Camera::new(&desc, [200, 100]);
        for film in [Vec2::new(100.0, 50.0), Vec2::new(30.0, 80.0)] {
            let a = shifted.generate_ray(film, Vec2::ZERO).d;
            let b = centred
                .generate_ray(film + Vec2::new(50.0, 10.0), Vec2::ZERO)
                .d;
            assert!((a - b).length() < 1e-5, "{a} vs {b}");
        }
    }

    #[test]
    fn thin_lens_focuses() {
        let desc = CameraDesc {
            lens_radius: 0.5,
            focal_distance: 3.0,
            ..Default::default()
        };
        let cam = Camera::new(&desc, [64, 64]);
        let film = Vec2::new(20.0, 40.0);
        let pin = Camera::new(
            &CameraDesc {
                lens_radius: 0.0,
                ..desc
            },
            [64, 64],
        )
        .generate_ray(film, Vec2::ZERO);
        let focus = pin.at(3.0 / pin.d.dot(Vec3::NEG_Z));
        for u in [Vec2::new(0.1, 0.9), Vec2::new(0.7, 0.3)] {
            let r = cam.generate_ray(film, u);
            let t = (focus - r.o).dot(r.d);
            assert!((r.at(t) - focus).length() < 1e-4);
        }
    }

    #[test]
    fn eight_rays_at_once_are_the_one_ray_code_to_the_bit() {
        use pathlab_mc::rng::Pcg32;
        let base = CameraDesc {
            origin: Vec3::new(0.3, 0.5, 3.9),
            target: Vec3::new(0.0, 0.2, 0.0),
            up: Vec3::Y,
            fov_degrees: 39.3,
            ..Default::default()
        };
        let cameras = [
            base,
            CameraDesc {
                principal_point_offset: Vec2::new(0.1, -0.05),
                near_clip: 0.01,
                far_clip: 100.0,
                ..base
            },
            CameraDesc {
                projection: Projection::Orthographic {
                    half_extent: Vec2::new(2.0, 1.2),
                },
                far_clip: 50.0,
                ..base
            },
        ];
        let mut rng = Pcg32::new(3, 5);
        for desc in cameras {
            let cam = Camera::new(&desc, [160, 90]);
            for _ in 0..64 {
                // Film positions inside the image and a little outside it.
                let film: [Vec2; W] = std::array::from_fn(|_| {
                    Vec2::new(
                        rng.uniform_f32() * 200.0 - 20.0,
                        rng.uniform_f32() * 130.0 - 20.0,
                    )
                });
                let one = film.map(|f| cam.generate_ray(f, Vec2::ZERO));
                let bits = |r: &Ray| {
                    [r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.t_min, r.t_max].map(f32::to_bits)
                };
                let dispatched = cam.generate_rays(film).unwrap();
                let portable = cam.rays_lanes(&film);
                for i in 0..W {
                    assert_eq!(
                        bits(&dispatched[i]),
                        bits(&one[i]),
                        "{desc:?} at {}",
                        film[i]
                    );
                    assert_eq!(bits(&portable[i]), bits(&one[i]), "{desc:?} at {}", film[i]);
                }
            }
        }
        let lens = Camera::new(
            &CameraDesc {
                lens_radius: 0.1,
                focal_distance: 3.0,
                ..base
            },
            [160, 90],
        );
        assert!(lens.generate_rays([Vec2::ZERO; W]).is_none());
    }
}
