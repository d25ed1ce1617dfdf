//! The plain scene description that loaders produce and [`crate::scene::Scene::build`] consumes.

use glam::Vec3;

/// Linear RGB.
pub type Rgb = Vec3;

/// A whole scene, as plain data.
#[derive(Clone, Debug, Default)]
pub struct SceneDesc {
    /// Triangle meshes.
    pub meshes: Vec<MeshDesc>,
    /// Spheres.
    pub spheres: Vec<SphereDesc>,
    /// Materials, referenced by index.
    pub materials: Vec<MaterialDesc>,
    /// Point lights.
    pub point_lights: Vec<PointLightDesc>,
    /// Uniform environment radiance seen by rays that leave the scene (none: black).
    pub environment: Option<Rgb>,
    /// The camera.
    pub camera: CameraDesc,
    /// Image size in pixels `[width, height]`.
    pub resolution: [u32; 2],
}

/// A triangle mesh in world space.
#[derive(Clone, Debug, Default)]
pub struct MeshDesc {
    /// Name, for messages.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex indices, three per triangle, counter-clockwise = front.
    pub indices: Vec<u32>,
    /// Material index.
    pub material: usize,
    /// Emitted radiance, if the mesh is an area light.
    pub emission: Option<Emission>,
}

/// A sphere in world space.
#[derive(Clone, Debug)]
pub struct SphereDesc {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
    /// Material index.
    pub material: usize,
    /// Emitted radiance, if the sphere is an area light.
    pub emission: Option<Emission>,
}

/// Emission of an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Radiance emitted from the front side.
    pub radiance: Rgb,
    /// Whether the back side emits too.
    pub two_sided: bool,
}

/// A material.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    /// Lambertian reflection: f = reflectance / π.
    Diffuse {
        /// Albedo per channel, in [0, 1].
        reflectance: Rgb,
        /// Whether the back side reflects too (otherwise it is black, as Mitsuba's `diffuse`).
        two_sided: bool,
    },
}

/// A point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLightDesc {
    /// Position.
    pub position: Vec3,
    /// Radiant intensity (W/sr per channel).
    pub intensity: Rgb,
}

/// Which image axis the field of view is measured along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FovAxis {
    /// Horizontal.
    X,
    /// Vertical.
    Y,
    /// The smaller of the two image dimensions (Mitsuba's default).
    #[default]
    Smaller,
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
        }
    }
}
