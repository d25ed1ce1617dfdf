//! The camera: its projection, field of view, lens and placement.

use super::*;

/// How a camera maps the image plane to rays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Projection {
    /// A pinhole (or thin lens) camera.
    #[default]
    Perspective,
    /// Parallel rays along the viewing direction from a rectangle of half-extents
    /// `half_extent` (right, up) centred on the camera's position.
    Orthographic {
        /// Half-width and half-height of the viewed rectangle, in scene units.
        half_extent: Vec2,
    },
}

/// Which image axis the field of view is measured along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FovAxis {
    /// Horizontal.
    X,
    /// Vertical.
    Y,
    /// The smaller of the two image dimensions.
    #[default]
    Smaller,
    /// The larger of the two image dimensions.
    Larger,
    /// The image diagonal.
    Diagonal,
}

/// A perspective camera (pinhole when `lens_radius` is zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    /// Position.
    pub origin: Vec3,
    /// A point it looks at.
    pub target: Vec3,
    /// The up direction.
    pub up: Vec3,
    /// Field of view in degrees, along `fov_axis`.
    pub fov_degrees: f32,
    /// The axis `fov_degrees` applies to.
    pub fov_axis: FovAxis,
    /// Radius of the thin lens (0: pinhole).
    pub lens_radius: f32,
    /// Distance to the plane in focus.
    pub focal_distance: f32,
    /// When set, the distance to the image plane in pixels: the field of view then follows
    /// from the resolution (a larger image shows more, at the same scale), as the CS184
    /// renderer does; `fov_degrees` is ignored.
    pub focal_pixels: Option<f32>,
    /// Camera rays start this far along the viewing direction (Mitsuba's `near_clip`).
    pub near_clip: f32,
    /// ... and end this far (Mitsuba's `far_clip`).
    pub far_clip: f32,
    /// Shift of the image window, in fractions of the image's width and height (right, down).
    pub principal_point_offset: Vec2,
    /// Perspective or orthographic.
    pub projection: Projection,
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            origin: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 40.0,
            fov_axis: FovAxis::Smaller,
            lens_radius: 0.0,
            focal_distance: 1.0,
            focal_pixels: None,
            near_clip: 0.0,
            far_clip: f32::INFINITY,
            principal_point_offset: Vec2::ZERO,
            projection: Projection::Perspective,
        }
    }
}
