//! The perspective camera: pinhole, or thin lens when it has an aperture.

use crate::desc::{CameraDesc, FovAxis};
use crate::geometry::Ray;
use glam::{Vec2, Vec3};
use pathlab_mc::warp::sample_uniform_disk_concentric;

/// A perspective camera generating rays through film positions.
///
/// Film coordinates are in pixels, `(0, 0)` at the top-left corner of the image, x to the right
/// and y down; the image's right is the camera's right (`forward × up`) and its top is `up`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    origin: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Half-extents of the image on the plane at distance 1.
    half: Vec2,
    resolution: [u32; 2],
    lens_radius: f32,
    focal_distance: f32,
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
        Camera {
            origin: desc.origin,
            right,
            up,
            forward,
            half: Vec2::new(tan * w / along, tan * h / along),
            resolution,
            lens_radius: desc.lens_radius.max(0.0),
            focal_distance: desc.focal_distance,
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
    pub fn generate_ray(&self, film: Vec2, u_lens: Vec2) -> Ray {
        let ndc = Vec2::new(
            2.0 * film.x / self.resolution[0] as f32 - 1.0,
            1.0 - 2.0 * film.y / self.resolution[1] as f32,
        );
        let d = (ndc.x * self.half.x * self.right + ndc.y * self.half.y * self.up + self.forward)
            .normalize();
        if self.lens_radius <= 0.0 {
            return Ray::new(self.origin, d);
        }
        // Thin lens: every ray through the lens point meets the pinhole ray at the plane of
        // focus.
        let lens = self.lens_radius * sample_uniform_disk_concentric(u_lens);
        let o = self.origin + lens.x * self.right + lens.y * self.up;
        let focus = self.origin + d * (self.focal_distance / d.dot(self.forward));
        Ray::new(o, (focus - o).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
