//! The camera as a sensor that light can reach (pbrt-v4's `We`, `PDF_We` and `SampleWi` of its
//! perspective camera): the importance a ray leaving the lens carries, the density with which
//! camera rays take each direction, a point on the lens sampled from a point in the scene, and
//! the pixels a film position counts towards under the pixel filter. What the bidirectional
//! path tracer's light-tracing strategy (t = 1) needs.
//!
//! Importance is normalised over the whole image: for a pinhole, W(θ) = 1 / (A cos⁴θ) inside
//! the image (A the area of the image on the plane at distance one), so that ∫ W cos θ dω = 1;
//! a thin lens divides it by the lens area. A pixel's share of what reaches a film position is
//! its filter's weight there ([`Camera::splat_weights`]), normalised as the filter that places
//! camera samples is, so that the image of light traced to the lens estimates the same
//! filter-weighted pixel averages as camera rays do.

use super::{Camera, FilterSampler};
use glam::{Vec2, Vec3};
use pathlab_mc::warp::sample_uniform_disk_concentric;
use std::f32::consts::PI;

/// A point on the lens sampled from a point in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraWiSample {
    /// The point on the lens.
    pub p_lens: Vec3,
    /// Unit direction from the scene point to it.
    pub wi: Vec3,
    /// Density per unit solid angle at the scene point.
    pub pdf: f32,
    /// Importance of the ray from the lens point towards the scene point.
    pub we: f32,
    /// Where that ray meets the film, in pixels.
    pub film: Vec2,
}

impl Camera {
    /// Whether light can be traced to this camera: a perspective one (pinhole or thin lens)
    /// without clipping planes.
    pub fn supports_light_tracing(&self) -> bool {
        !self.orthographic && self.near == 0.0 && !self.far.is_finite()
    }

    /// Area of the lens (one for a pinhole, as pbrt-v4 counts it).
    fn lens_area(&self) -> f32 {
        if self.lens_radius > 0.0 {
            PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// Area of the image on the plane at distance one.
    fn image_area(&self) -> f32 {
        4.0 * self.half.x * self.half.y
    }

    /// The film position (pixels) of the ray from lens point `p_lens` along unit `dir`, and
    /// cos θ to the viewing direction; `None` behind the camera or off the image.
    fn film_of(&self, p_lens: Vec3, dir: Vec3) -> Option<(Vec2, f32)> {
        let cos = dir.dot(self.forward);
        if cos <= 0.0 {
            return None;
        }
        // Every ray through the lens meets the pinhole ray through its film point at the plane
        // of focus (at distance one for a pinhole, any plane will do).
        let focus = if self.lens_radius > 0.0 {
            self.focal_distance
        } else {
            1.0
        };
        let film = self.raster_position(p_lens + dir * (focus / cos))?;
        let [w, h] = self.resolution.map(|r| r as f32);
        (film.x >= 0.0 && film.x < w && film.y >= 0.0 && film.y < h).then_some((film, cos))
    }

    /// Density per unit solid angle with which camera rays leave the lens along `dir` (the
    /// directions as if film positions were uniform over the image): 1 / (A cos³θ), zero off
    /// the image.
    pub fn pdf_we_dir(&self, p_lens: Vec3, dir: Vec3) -> f32 {
        match self.film_of(p_lens, dir) {
            Some((_, cos)) => 1.0 / (self.image_area() * cos * cos * cos),
            None => 0.0,
        }
    }

    /// A point on the lens seen from scene point `p` (`u` chooses it on a thin lens), with
    /// the importance arriving there from it; `None` where none does.
    pub fn sample_wi(&self, p: Vec3, u: Vec2) -> Option<CameraWiSample> {
        let lens = self.lens_radius * sample_uniform_disk_concentric(u);
        let p_lens = self.origin + lens.x * self.right + lens.y * self.up;
        let to_lens = p_lens - p;
        let dist2 = to_lens.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let wi = to_lens / dist2.sqrt();
        let (film, cos) = self.film_of(p_lens, -wi)?;
        let cos2 = cos * cos;
        Some(CameraWiSample {
            p_lens,
            wi,
            pdf: dist2 / (cos * self.lens_area()),
            we: 1.0 / (self.image_area() * self.lens_area() * cos2 * cos2),
            film,
        })
    }

    /// The pixels that radiance arriving at film position `film` counts towards, with their
    /// weights: under a box filter, the pixel it lies in with weight one; otherwise each pixel
    /// whose filter reaches it, with the filter's value there over its integral inside the
    /// image (the density from which [`Camera::film_sample`] places that pixel's samples,
    /// signed weight included). Pixels outside `window` `[x0, y0, x1, y1]` are left out.
    pub fn splat_weights(&self, film: Vec2, window: [u32; 4], out: &mut Vec<([u32; 2], f32)>) {
        out.clear();
        let [x0, y0, x1, y1] = window;
        let Some(f) = &self.filter else {
            let (x, y) = (film.x.floor(), film.y.floor());
            if x >= x0 as f32 && x < x1 as f32 && y >= y0 as f32 && y < y1 as f32 {
                out.push(([x as u32, y as u32], 1.0));
            }
            return;
        };
        let (w, h) = (self.resolution[0] as f32, self.resolution[1] as f32);
        let axis = |x: f32, lo: u32, hi: u32, size: f32| {
            let first = ((x - 0.5 - f.radius()).ceil() as i64).max(lo as i64);
            let last = ((x - 0.5 + f.radius()).floor() as i64).min(hi as i64 - 1);
            (first..=last).filter_map(move |j| {
                let c = j as f32 + 0.5;
                let wt = f.weight_at(x - c, -c, size - c);
                (wt != 0.0).then_some((j as u32, wt))
            })
        };
        for (j, wy) in axis(film.y, y0, y1, h) {
            for (i, wx) in axis(film.x, x0, x1, w) {
                out.push(([i, j], wx * wy));
            }
        }
    }
}

impl FilterSampler {
    /// The filter's value at offset `x` over its integral on [lo, hi] ∩ [-radius, radius]:
    /// the (signed) density, per pixel, whose weighted samples [`FilterSampler::sample`] draws.
    pub fn weight_at(&self, x: f32, lo: f32, hi: f32) -> f32 {
        if x.abs() >= self.radius || x < lo || x > hi {
            return 0.0;
        }
        let table = self.signed.as_deref().unwrap_or(&self.cdf);
        let (lo, hi) = (lo.max(-self.radius), hi.min(self.radius));
        let integral = self.cumulative_at(table, hi) - self.cumulative_at(table, lo);
        if integral <= 0.0 {
            return 0.0;
        }
        let bin_width = 2.0 * self.radius / Self::BINS as f32;
        let i = (((x + self.radius) / bin_width) as usize).min(Self::BINS - 1);
        (table[i + 1] - table[i]) / bin_width / integral
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::{CameraDesc, PixelFilter};

    fn camera(lens_radius: f32) -> Camera {
        Camera::new(
            &CameraDesc {
                origin: Vec3::new(0.3, -0.2, 4.0),
                target: Vec3::new(0.0, 0.1, 0.0),
                fov_degrees: 40.0,
                lens_radius,
                focal_distance: 3.5,
                ..Default::default()
            },
            [48, 32],
        )
    }

    /// Light traced to the lens lands where the camera's own ray through that film position
    /// and lens point goes, and the importance integrates to one over the image.
    #[test]
    fn importance_is_the_inverse_of_camera_rays_and_integrates_to_one() {
        for lens in [0.0, 0.1] {
            let cam = camera(lens);
            let mut rng = pathlab_mc::rng::Pcg32::new(4, lens.to_bits() as u64);
            for _ in 0..200 {
                let film = Vec2::new(rng.uniform_f32() * 48.0, rng.uniform_f32() * 32.0);
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let ray = cam.generate_ray(film, u);
                let p = ray.o + ray.d * (1.0 + 5.0 * rng.uniform_f32());
                let s = cam.sample_wi(p, u).expect("a point the camera sees");
                assert!((s.p_lens - ray.o).length() < 1e-4);
                assert!((s.film - film).length() < 2e-3, "{:?} vs {film:?}", s.film);
                assert!((s.wi + ray.d).length() < 1e-4);
            }
            // ∫ W cos θ dω over the pinhole's directions = 1: W cos θ / pdf_dir = 1 / lens area
            // for every direction, and the directions' density integrates to one over the
            // image (midpoint rule over film positions, dω = cos³θ dA on the plane).
            let o = cam.origin;
            let mut total = 0.0f64;
            let n = 400;
            for iy in 0..n {
                for ix in 0..n {
                    let film = Vec2::new(
                        (ix as f32 + 0.5) / n as f32 * 48.0,
                        (iy as f32 + 0.5) / n as f32 * 32.0,
                    );
                    // The lens centre's ray: the pinhole's direction for this film point.
                    let d = cam.generate_ray(film, Vec2::splat(0.5)).d;
                    let cos = d.dot(cam.forward) as f64;
                    let d_area = cam.image_area() as f64 / (n * n) as f64;
                    total += cam.pdf_we_dir(o, d) as f64 * cos.powi(3) * d_area;
                }
            }
            assert!((total - 1.0).abs() < 1e-3, "lens {lens}: ∫ pdf = {total}");
        }
    }

    #[test]
    fn splat_weights_are_the_filters_density_and_sum_to_one_inside() {
        let mut cam = camera(0.0);
        let mut out = Vec::new();
        cam.splat_weights(Vec2::new(10.3, 7.9), [0, 0, 48, 32], &mut out);
        assert_eq!(out, vec![([10, 7], 1.0)]);
        cam.splat_weights(Vec2::new(10.3, 7.9), [0, 0, 10, 32], &mut out);
        assert!(out.is_empty(), "outside the window");
        for filter in [
            PixelFilter::Tent { radius: 1.5 },
            PixelFilter::Gaussian {
                stddev: 0.5,
                radius: 1.5,
            },
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
        ] {
            cam = camera(0.0).with_filter(filter);
            // Each pixel's weights over the film integrate to one (its samples' filter is
            // normalised inside the image): summed over a fine grid of film positions.
            let mut per_pixel = std::collections::HashMap::<[u32; 2], f64>::new();
            let n = 40;
            for iy in 0..32 * n {
                for ix in 0..48 * n {
                    let film =
                        Vec2::new((ix as f32 + 0.5) / n as f32, (iy as f32 + 0.5) / n as f32);
                    cam.splat_weights(film, [0, 0, 48, 32], &mut out);
                    for &(p, w) in &out {
                        *per_pixel.entry(p).or_default() += w as f64 / (n * n) as f64;
                    }
                }
            }
            for (p, total) in per_pixel {
                assert!(
                    (total - 1.0).abs() < 2e-3,
                    "{filter:?} pixel {p:?}: {total}"
                );
            }
        }
    }
}
