//! The plain scene description that loaders produce and [`crate::scene::Scene::build`] consumes.

use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;

pub use crate::bsdf::{FresnelModel, NormalDistribution};
pub use crate::texture::Texture;

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
    /// Spot lights.
    pub spot_lights: Vec<SpotLightDesc>,
    /// Directional (distant) lights.
    pub directional_lights: Vec<DirectionalLightDesc>,
    /// Uniform environment radiance seen by rays that leave the scene (none: black).
    pub environment: Option<Rgb>,
    /// An environment map (takes the place of `environment` when both are set).
    pub environment_map: Option<EnvironmentMapDesc>,
    /// The camera.
    pub camera: CameraDesc,
    /// Image size in pixels `[width, height]`.
    pub resolution: [u32; 2],
    /// What the loader noticed and worked around (unsupported features, missing textures).
    pub warnings: Vec<String>,
    /// Render settings the scene file asks for (command-line flags take precedence).
    pub hints: RenderHints,
}

impl SceneDesc {
    /// The bounding box (min, max) of every mesh vertex and sphere, or `None` without shapes.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for &p in self.meshes.iter().flat_map(|m| &m.positions) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }
}

/// An equirectangular environment map (see [`crate::envmap`] for the convention).
#[derive(Clone, Debug)]
pub struct EnvironmentMapDesc {
    /// Where it was read from, for messages.
    pub source: String,
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Linear RGB texels, row 0 at the top.
    pub texels: Arc<Vec<Rgb>>,
    /// Rotation from the map's frame (y up) to the world.
    pub to_world: Mat3,
    /// Radiance scale.
    pub scale: f32,
}

/// Render settings a scene file can suggest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderHints {
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Largest bounce in pathlab's counting (`u32::MAX`: unbounded).
    pub max_depth: Option<u32>,
}

/// Which rays see a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Visibility {
    /// Camera rays (the first segment of a path).
    pub camera: bool,
    /// Every other ray: bounces, shadow rays, light sampling.
    pub indirect: bool,
}

impl Default for Visibility {
    fn default() -> Self {
        Visibility::ALL
    }
}

impl Visibility {
    /// Seen by every ray.
    pub const ALL: Visibility = Visibility {
        camera: true,
        indirect: true,
    };
    /// Seen only by camera rays (an emitter shown to the camera but lit by something else).
    pub const CAMERA_ONLY: Visibility = Visibility {
        camera: true,
        indirect: false,
    };
    /// Hidden from camera rays.
    pub const INDIRECT_ONLY: Visibility = Visibility {
        camera: false,
        indirect: true,
    };
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
    /// Per-vertex shading normals (empty: flat shading).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (empty: none).
    pub uvs: Vec<Vec2>,
    /// Which rays see the mesh.
    pub visibility: Visibility,
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
    /// Lambertian reflection whose albedo comes from an image texture (times `scale`).
    TexturedDiffuse {
        /// The albedo texture (linear RGB).
        texture: Arc<Texture>,
        /// Factor applied to the texture.
        scale: Rgb,
        /// Whether the back side reflects too.
        two_sided: bool,
    },
    /// Perfect specular reflection.
    Mirror {
        /// Reflectance per channel.
        reflectance: Rgb,
    },
    /// A smooth or rough dielectric.
    Glass {
        /// Reflectance scale.
        reflectance: Rgb,
        /// Transmittance scale.
        transmittance: Rgb,
        /// Roughness α of the microfacet distribution (0: smooth).
        roughness: f32,
        /// Index of refraction inside relative to outside.
        ior: f32,
        /// Microfacet distribution when rough.
        distribution: NormalDistribution,
        /// Fresnel reflectance of the smooth interface.
        fresnel: FresnelModel,
    },
    /// A conductor: smooth (α = 0) or rough (microfacet model).
    Conductor {
        /// Roughness α of the normal distribution.
        alpha: f32,
        /// Real part of the complex index of refraction, per channel.
        eta: Rgb,
        /// Imaginary part (absorption), per channel.
        k: Rgb,
        /// Microfacet distribution.
        distribution: NormalDistribution,
    },
    /// A diffuse base under a smooth dielectric coat.
    Plastic {
        /// Diffuse reflectance of the base.
        diffuse: Rgb,
        /// Index of refraction of the coat relative to outside.
        ior: f32,
        /// Whether internal reflections are tinted by the base.
        nonlinear: bool,
    },
}

impl MaterialDesc {
    /// The kind of material, for summaries.
    pub fn kind(&self) -> &'static str {
        match self {
            MaterialDesc::Diffuse { .. } => "diffuse",
            MaterialDesc::TexturedDiffuse { .. } => "textured diffuse",
            MaterialDesc::Mirror { .. } => "mirror",
            MaterialDesc::Glass { .. } => "glass",
            MaterialDesc::Conductor { .. } => "conductor",
            MaterialDesc::Plastic { .. } => "plastic",
        }
    }
}

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
        }
    }
}
