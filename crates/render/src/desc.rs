//! The plain scene description that loaders produce and [`crate::scene::Scene::build`] consumes.

use glam::{Affine2, Affine3A, Mat3, Vec2, Vec3};
use std::sync::Arc;

pub use crate::bsdf::{FresnelModel, NormalDistribution};
pub use crate::texture::Texture;

pub use crate::color::Rgb;

mod camera;
mod lights;
mod materials;

pub use camera::*;
pub use lights::*;
pub use materials::*;

/// A whole scene, as plain data.
#[derive(Clone, Debug, Default)]
pub struct SceneDesc {
    /// Triangle meshes.
    pub meshes: Vec<MeshDesc>,
    /// Spheres.
    pub spheres: Vec<SphereDesc>,
    /// Signed distance grids.
    pub sdf_grids: Vec<SdfGridDesc>,
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
    /// The pixel reconstruction filter.
    pub filter: PixelFilter,
    /// Spot lights whose cone carries an image, and projectors (see [`ProjectorDesc`]).
    pub projectors: Vec<ProjectorDesc>,
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
        for g in &self.sdf_grids {
            for i in 0..8 {
                let c = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
                let p = g.to_world.transform_point3(c);
                lo = lo.min(p);
                hi = hi.max(p);
            }
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
    /// First bounce at which Russian roulette may end a path.
    pub rr_depth: Option<u32>,
    /// The integrator the file names.
    pub integrator: Option<IntegratorHint>,
    /// Whether camera rays should not see emitters.
    pub hide_emitters: bool,
    /// The sampler the file names.
    pub sampler: Option<pathlab_mc::sampler::SamplerKind>,
    /// The part of the image the file asks to render.
    pub crop: Option<CropHint>,
}

impl RenderHints {
    /// Samples per pixel when the caller does not say: the file's, else 64.
    pub fn spp_or_default(&self) -> u32 {
        self.spp.unwrap_or(64)
    }

    /// The sampler when the caller does not say: the file's, else Sobol (independent samples
    /// for a progressive render, whose error estimate needs them).
    pub fn sampler_or_default(&self, progressive: bool) -> pathlab_mc::sampler::SamplerKind {
        use pathlab_mc::sampler::SamplerKind;
        self.sampler.unwrap_or(if progressive {
            SamplerKind::Independent
        } else {
            SamplerKind::Sobol
        })
    }
}

/// A crop window a scene file names: the pixels `x0 <= x < x1`, `y0 <= y < y1` of an image of
/// size `of`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropHint {
    /// `[x0, y0, x1, y1]`.
    pub window: [u32; 4],
    /// The image size the window is of.
    pub of: [u32; 2],
}

impl CropHint {
    /// The window in an image of `resolution`: as given at the file's size; at another size
    /// the same fraction of the image, each edge at the first pixel whose left (top) edge lies
    /// at or past it, as pbrt-v4 places a crop window's edges. `None` when nothing is left.
    pub fn window_for(&self, resolution: [u32; 2]) -> Option<[u32; 4]> {
        let [w, h] = resolution;
        let window = if resolution == self.of {
            self.window
        } else {
            let edge = |v: u32, from: u32, to: u32| {
                let x = (v as f64 * to as f64 / from.max(1) as f64).ceil();
                x.clamp(0.0, to as f64) as u32
            };
            let [x0, y0, x1, y1] = self.window;
            let [fw, fh] = self.of;
            [
                edge(x0, fw, w),
                edge(y0, fh, h),
                edge(x1, fw, w),
                edge(y1, fh, h),
            ]
        };
        let [x0, y0, x1, y1] = window;
        (x0 < x1.min(w) && y0 < y1.min(h)).then_some([x0, y0, x1.min(w), y1.min(h)])
    }
}

/// An integrator a scene file asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorHint {
    /// Path tracing (also what a particle tracer's image converges to).
    Path,
    /// Bidirectional path tracing.
    Bdpt,
    /// Direct lighting with `emitter_samples` light samples and `bsdf_samples` BSDF samples
    /// per pixel sample, combined by the power heuristic.
    Direct {
        /// Light samples.
        emitter_samples: u32,
        /// BSDF samples.
        bsdf_samples: u32,
    },
}

/// The pixel reconstruction filter: how much a sample at an offset from a pixel's centre
/// counts towards that pixel. pathlab draws each pixel's sample positions from the filter
/// (restricted to the image), which gives each pixel the filter-weighted average of radiance
/// that splatting every sample into its neighbours converges to.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PixelFilter {
    /// The pixel's own square, uniformly.
    #[default]
    Box,
    /// A tent 1 - |x|/radius in each axis.
    Tent {
        /// Radius in pixels.
        radius: f32,
    },
    /// A Gaussian of standard deviation `stddev` pixels, cut at `radius` and shifted down to
    /// zero there: Mitsuba's `gaussian` has radius 4σ ([`PixelFilter::gaussian`]), pbrt-v4's
    /// 1.5 pixels unless its file says otherwise.
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f32,
        /// Where the filter ends, in pixels.
        radius: f32,
    },
    /// Mitchell and Netravali's cubic of parameters B and C over `radius` (pbrt-v4's
    /// `mitchell`; negative lobes, so samples carry signed weights).
    Mitchell {
        /// Radius in pixels.
        radius: f32,
        /// B.
        b: f32,
        /// C.
        c: f32,
    },
    /// A sinc windowed by a Lanczos sinc of `tau` lobes over `radius` (pbrt-v4's `sinc`;
    /// negative lobes).
    LanczosSinc {
        /// Radius in pixels.
        radius: f32,
        /// Lobes of the window.
        tau: f32,
    },
}

impl PixelFilter {
    /// Mitsuba's Gaussian of standard deviation `stddev`, cut at 4 standard deviations.
    pub fn gaussian(stddev: f32) -> Self {
        PixelFilter::Gaussian {
            stddev,
            radius: 4.0 * stddev,
        }
    }
}

/// A named attribute of a mesh's vertices or faces (Mitsuba's `vertex_*` / `face_*` PLY
/// properties), up to three channels (one channel is stored in all three).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    /// Its name, with the `vertex_` or `face_` prefix.
    pub name: String,
    /// Whether there is one value per face (else one per vertex, interpolated).
    pub per_face: bool,
    /// The values.
    pub values: Vec<Vec3>,
}

/// Which rays see a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Visibility {
    /// Camera rays (the first segment of a path).
    pub camera: bool,
    /// Every other ray: bounces, shadow rays, light sampling.
    pub indirect: bool,
}

/// The kinds of ray a shape's [`Visibility`] tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// A camera ray: the first segment of a path.
    Camera,
    /// Every other ray: bounces, shadow rays, light sampling.
    Indirect,
}

impl RayKind {
    /// The kind of the ray that leaves a path's vertex `depth` (0: the camera).
    #[inline]
    pub fn at_depth(depth: u32) -> RayKind {
        if depth == 0 {
            RayKind::Camera
        } else {
            RayKind::Indirect
        }
    }
}

impl Visibility {
    /// Whether rays of `kind` see the shape.
    #[inline]
    pub fn seen_by(self, kind: RayKind) -> bool {
        match kind {
            RayKind::Camera => self.camera,
            RayKind::Indirect => self.indirect,
        }
    }
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
    /// A texture that multiplies the emitted radiance (its (u, v) are the mesh's).
    pub emission_texture: Option<TextureDesc>,
    /// Named vertex and face attributes (for [`TextureDesc::MeshAttribute`]).
    pub attributes: Vec<MeshAttribute>,
    /// Per-vertex tangents along increasing u (empty: derived from the texture coordinates,
    /// or arbitrary without them), for anisotropic materials and normal maps.
    pub tangents: Vec<Vec3>,
}

/// A signed distance grid (Mitsuba's `sdfgrid`): samples of a signed distance (negative
/// inside) over the object-space unit cube, placed in the world by `to_world`.
#[derive(Clone, Debug, Default)]
pub struct SdfGridDesc {
    /// Samples, x fastest, then y, then z; sample (i, j, k) sits at (i, j, k) / (res - 1).
    pub values: Vec<f32>,
    /// Samples along x, y and z.
    pub resolution: [u32; 3],
    /// Object-to-world transform.
    pub to_world: Affine3A,
    /// Shading normals blended across voxels (Mitsuba's `smooth`) rather than the
    /// interpolant's own gradient (`analytic`).
    pub smooth_normals: bool,
    /// Material index.
    pub material: usize,
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
    /// Rotation from world to the sphere's own frame, in which its texture coordinates are
    /// spherical angles about z: u = φ/2π, v = 1 - θ/π.
    pub to_object: Mat3,
    /// A texture that multiplies the emitted radiance.
    pub emission_texture: Option<TextureDesc>,
}

impl Default for SphereDesc {
    fn default() -> Self {
        SphereDesc {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
            emission: None,
            to_object: Mat3::IDENTITY,
            emission_texture: None,
        }
    }
}

/// Emission of an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Radiance emitted from the front side.
    pub radiance: Rgb,
    /// Whether the back side emits too.
    pub two_sided: bool,
}

#[cfg(test)]
mod tests {
    use super::CropHint;

    #[test]
    fn a_crop_window_keeps_its_fraction_of_the_image_at_another_size() {
        let hint = CropHint {
            window: [10, 20, 30, 40],
            of: [100, 50],
        };
        assert_eq!(hint.window_for([100, 50]), Some([10, 20, 30, 40]));
        // Twice the size: twice the pixels; a third of it: edges rounded up as pbrt-v4's are.
        assert_eq!(hint.window_for([200, 100]), Some([20, 40, 60, 80]));
        assert_eq!(hint.window_for([33, 17]), Some([4, 7, 10, 14]));
        // A window past the image is cut at its edge; one with nothing left is none.
        let past = CropHint {
            window: [90, 0, 150, 50],
            of: [100, 50],
        };
        assert_eq!(past.window_for([100, 50]), Some([90, 0, 100, 50]));
        let outside = CropHint {
            window: [100, 0, 150, 50],
            of: [100, 50],
        };
        assert_eq!(outside.window_for([100, 50]), None);
    }
}
