//! Lights other than emitting shapes: point, spot, directional lights and projectors.

use super::*;

/// A point light: radiance arriving from it at distance d is
/// intensity / (c + l d + q d²) with `attenuation = [c, l, q]` (`[0, 0, 1]`: inverse square).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLightDesc {
    /// Position.
    pub position: Vec3,
    /// Radiant intensity (W/sr per channel).
    pub intensity: Rgb,
    /// Constant, linear and quadratic attenuation coefficients.
    pub attenuation: [f32; 3],
}

/// The attenuation of a physical point light: inverse square.
pub const INVERSE_SQUARE: [f32; 3] = [0.0, 0.0, 1.0];

/// A spot light: a point light whose intensity is scaled by cos^exponent θ inside a cone of
/// half-angle `cutoff_degrees` around `direction` and is zero outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLightDesc {
    /// Position.
    pub position: Vec3,
    /// Axis of the cone (unit).
    pub direction: Vec3,
    /// Intensity on the axis.
    pub intensity: Rgb,
    /// Half-angle of the cone in degrees.
    pub cutoff_degrees: f32,
    /// Falloff exponent of cos θ.
    pub exponent: f32,
    /// Constant, linear and quadratic attenuation coefficients.
    pub attenuation: [f32; 3],
}

/// A distant light: radiance arriving along a single direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLightDesc {
    /// The direction the light travels (unit).
    pub direction: Vec3,
    /// Irradiance on a surface facing the light.
    pub irradiance: Rgb,
}

/// A point light that shines through an image plane at distance 1 along its axis: Mitsuba's
/// `spot` (a cone with a smooth edge, optionally carrying an image) and `projector` (an image
/// projected like a slide).
#[derive(Clone, Debug, PartialEq)]
pub struct ProjectorDesc {
    /// Position.
    pub position: Vec3,
    /// The light's frame: columns are its local x, y and z axes in world space (orthonormal);
    /// it shines along z.
    pub frame: Mat3,
    /// What the image plane shows, in image coordinates (u, v) with v growing upwards (see
    /// [`ProjectorKind`] for where a direction lands).
    pub texture: TextureDesc,
    /// The emission profile.
    pub kind: ProjectorKind,
}

/// How a [`ProjectorDesc`] emits. Directions are in the light's frame, (x, y, z) with z > 0;
/// image coordinates (u, v) are pathlab's (v up): Mitsuba's with v flipped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProjectorKind {
    /// Mitsuba's `spot`: intensity × image(u, v) × falloff, the falloff 1 within
    /// `beam_width` of the axis, falling linearly in angle to 0 at `cutoff`; the image spans
    /// the cutoff cone, u = ½ + ½ x / (z tan cutoff), Mitsuba's v = ½ + ½ y / (z tan cutoff).
    Spot {
        /// Intensity on the axis.
        intensity: Rgb,
        /// Half-angle of the cone (radians).
        cutoff: f32,
        /// Half-angle of the full-intensity beam (radians).
        beam_width: f32,
        /// How the intensity falls from the beam to the cutoff.
        falloff: SpotFalloff,
    },
    /// Mitsuba's `projector`: the image on the plane z = 1 spans a horizontal field of view
    /// (u = ½ - ½ x / (z t), Mitsuba's v = ½ - ½ aspect y / (z t), t = tan(fov_x / 2)); the
    /// intensity towards a direction is π · scale · image(u, v) / cos³θ, which gives a plane
    /// facing the light at distance 1 the irradiance π · scale · image.
    Projector {
        /// Scale of the image's values.
        scale: f32,
        /// tan(fov_x / 2).
        tan_half_fov_x: f32,
        /// The image's width / height.
        aspect: f32,
    },
}

/// How a spot light's intensity falls from full at its beam's edge to zero at its cutoff.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpotFalloff {
    /// Linearly in the angle from the axis (Mitsuba's `spot`).
    LinearInAngle,
    /// By the smoothstep t² (3 - 2t) of t = (cos θ - cos cutoff) / (cos beam - cos cutoff)
    /// (pbrt-v4's `spot`).
    SmoothStepInCosine,
}
