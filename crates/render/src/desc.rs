//! The plain scene description that loaders produce and [`crate::scene::Scene::build`] consumes.

use glam::{Affine2, Affine3A, Mat3, Vec2, Vec3};
use std::sync::Arc;

pub use crate::bsdf::{FresnelModel, NormalDistribution};
pub use crate::texture::Texture;

pub use crate::color::Rgb;

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
}

/// An integrator a scene file asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorHint {
    /// Path tracing (also what a particle tracer's image converges to).
    Path,
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
    /// A Gaussian of standard deviation `stddev` pixels, cut at 4 standard deviations and
    /// shifted down to zero there (Mitsuba's `gaussian`).
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f32,
    },
}

/// How an image texture is read between texel centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureFilter {
    /// The nearest texel.
    Nearest,
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Bilinear,
}

/// What an image texture shows outside [0, 1]².
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WrapMode {
    /// The image repeats.
    #[default]
    Repeat,
    /// The image repeats, every other copy mirrored.
    Mirror,
    /// The border texels extend.
    Clamp,
}

/// A quantity that varies over a surface: a colour, or a number (read as the luminance of the
/// colour, which for grey values is the value itself).
///
/// Surface coordinates are pathlab's (u, v), v growing upwards (OBJ, OpenGL); `to_uv` maps
/// them to the texture's own coordinates: an image's are the same convention (its bottom-left
/// corner at (0, 0)), a checkerboard's are Mitsuba's (v growing downwards).
#[derive(Clone, Debug, PartialEq)]
pub enum TextureDesc {
    /// The same value everywhere.
    Constant(Rgb),
    /// An image.
    Image {
        /// The texels.
        image: Arc<Texture>,
        /// Interpolation.
        filter: TextureFilter,
        /// Outside [0, 1]².
        wrap: WrapMode,
        /// Surface (u, v) to image coordinates.
        to_uv: Affine2,
    },
    /// Mitsuba's checkerboard: `color0` where the fractional parts of u and v are both below
    /// or both above ½, `color1` elsewhere.
    Checkerboard {
        /// The first colour.
        color0: Rgb,
        /// The second colour.
        color1: Rgb,
        /// Surface (u, v) to checkerboard coordinates.
        to_uv: Affine2,
    },
    /// A per-vertex (interpolated) or per-face attribute of the mesh, by name.
    MeshAttribute {
        /// The attribute's name (e.g. `vertex_color`, `face_weight`).
        name: String,
    },
}

impl TextureDesc {
    /// The same number everywhere.
    pub fn value(v: f32) -> Self {
        TextureDesc::Constant(Rgb::splat(v))
    }

    /// An image, read bilinearly and repeating, in surface coordinates.
    pub fn image(image: Arc<Texture>) -> Self {
        TextureDesc::Image {
            image,
            filter: TextureFilter::Bilinear,
            wrap: WrapMode::Repeat,
            to_uv: Affine2::IDENTITY,
        }
    }

    /// The constant value, if the texture is one.
    pub fn as_constant(&self) -> Option<Rgb> {
        match self {
            TextureDesc::Constant(c) => Some(*c),
            _ => None,
        }
    }

    /// A summary value: the constant, the image's mean, the checkerboard's average colour.
    pub fn mean(&self) -> Rgb {
        match self {
            TextureDesc::Constant(c) => *c,
            TextureDesc::Image { image, .. } => image.mean(),
            TextureDesc::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
            TextureDesc::MeshAttribute { .. } => Rgb::splat(0.5),
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
    /// Lambertian reflection whose albedo comes from a texture (times `scale`).
    TexturedDiffuse {
        /// The albedo texture (linear RGB).
        texture: TextureDesc,
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
    /// A thin sheet of glass: reflection and straight-through transmission (Mitsuba's
    /// `thindielectric`).
    ThinGlass {
        /// Reflectance scale.
        reflectance: Rgb,
        /// Transmittance scale.
        transmittance: Rgb,
        /// Index of refraction of the sheet relative to its surroundings.
        ior: f32,
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
        /// Scale of the coat's reflection (1 is physical).
        specular: Rgb,
        /// Index of refraction of the coat relative to outside.
        ior: f32,
        /// Whether internal reflections are tinted by the base.
        nonlinear: bool,
    },
    /// A conductor with textured, possibly anisotropic roughness (α along the surface's
    /// u tangent and along v) and a reflectance scale (Mitsuba's `roughconductor`).
    RoughConductor {
        /// Roughness along the u tangent.
        alpha_u: TextureDesc,
        /// Roughness along the v tangent.
        alpha_v: TextureDesc,
        /// Real part of the complex index of refraction, per channel.
        eta: Rgb,
        /// Imaginary part, per channel.
        k: Rgb,
        /// Scale of the reflection.
        specular: TextureDesc,
        /// Microfacet distribution.
        distribution: NormalDistribution,
    },
    /// A diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`).
    RoughPlastic {
        /// Diffuse reflectance of the base.
        diffuse: TextureDesc,
        /// Scale of the coat's reflection.
        specular: Rgb,
        /// Roughness α of the coat.
        alpha: f32,
        /// Index of refraction of the coat relative to outside.
        ior: f32,
        /// Whether internal reflections are tinted by the base.
        nonlinear: bool,
        /// Microfacet distribution.
        distribution: NormalDistribution,
    },
    /// A material seen through where `opacity` < 1: it counts `opacity` of the inner
    /// material, the rest of the light passes straight through (Mitsuba's `mask`).
    Mask {
        /// Opacity in [0, 1].
        opacity: TextureDesc,
        /// The material where opaque.
        inner: Box<MaterialDesc>,
    },
    /// `(1 - weight) first + weight second` (Mitsuba's `blendbsdf`).
    Blend {
        /// Weight of the second material, in [0, 1].
        weight: TextureDesc,
        /// The first material.
        first: Box<MaterialDesc>,
        /// The second material.
        second: Box<MaterialDesc>,
    },
    /// Disney's principled BSDF (Mitsuba's `principled`, or `principledthin` for a thin
    /// sheet).
    Principled(Box<PrincipledDesc>),
    /// One material on the front side (the shading normal's), another on the back.
    TwoSided {
        /// Front side.
        front: Box<MaterialDesc>,
        /// Back side (seen as its front).
        back: Box<MaterialDesc>,
    },
    /// The inner material with its shading normal from a tangent-space normal map
    /// (n = 2 × texture - 1 in the frame of the u tangent, the v bitangent and the normal).
    NormalMap {
        /// The normal map (read raw).
        normals: TextureDesc,
        /// The material.
        inner: Box<MaterialDesc>,
    },
    /// The inner material with its shading normal from a height field's gradient (Mitsuba's
    /// `bumpmap`: the surface displaced by `scale` × height along its normal).
    BumpMap {
        /// Heights (read raw).
        height: TextureDesc,
        /// Scale of the displacement.
        scale: f32,
        /// The material.
        inner: Box<MaterialDesc>,
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
            MaterialDesc::ThinGlass { .. } => "thin glass",
            MaterialDesc::Conductor { .. } => "conductor",
            MaterialDesc::Plastic { .. } => "plastic",
            MaterialDesc::RoughConductor { .. } => "rough conductor",
            MaterialDesc::RoughPlastic { .. } => "rough plastic",
            MaterialDesc::Principled(p) if p.thin => "principled thin",
            MaterialDesc::Principled(_) => "principled",
            MaterialDesc::Mask { .. } => "mask",
            MaterialDesc::Blend { .. } => "blend",
            MaterialDesc::TwoSided { .. } => "two-sided",
            MaterialDesc::NormalMap { .. } => "normal map",
            MaterialDesc::BumpMap { .. } => "bump map",
        }
    }
}

/// The parameters of a principled material, each a texture (numbers read as luminance), with
/// `Some` for the optional ones the scene gives (Mitsuba switches lobes on that way).
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipledDesc {
    /// Base colour.
    pub base_color: TextureDesc,
    /// Roughness.
    pub roughness: TextureDesc,
    /// Anisotropy.
    pub anisotropic: Option<TextureDesc>,
    /// Specular transmission.
    pub spec_trans: Option<TextureDesc>,
    /// Metalness (solid only).
    pub metallic: Option<TextureDesc>,
    /// Clear coat (solid only).
    pub clearcoat: Option<TextureDesc>,
    /// Clear coat glossiness (solid only).
    pub clearcoat_gloss: TextureDesc,
    /// Sheen.
    pub sheen: Option<TextureDesc>,
    /// Sheen tint.
    pub sheen_tint: Option<TextureDesc>,
    /// Specular tint.
    pub spec_tint: Option<TextureDesc>,
    /// Flatness.
    pub flatness: Option<TextureDesc>,
    /// Diffuse transmission, 0 to 2 (thin only).
    pub diff_trans: Option<TextureDesc>,
    /// Relative index of refraction (a texture for the thin sheet, a number for a solid).
    pub eta: TextureDesc,
    /// A thin sheet.
    pub thin: bool,
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
