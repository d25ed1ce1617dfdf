//! Materials and textures as scene descriptions give them.

use super::*;

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
    /// Black outside the image (pbrt-v4's `black`): texels beyond the border read as zero.
    Black,
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
    /// Bilinear interpolation between four values at the corners of the unit square of the
    /// mapped coordinates (s, t), extrapolated beyond it (pbrt-v4's `bilerp`).
    Bilerp {
        /// The values at (s, t) = (0, 0), (1, 0), (0, 1) and (1, 1).
        corners: [Rgb; 4],
        /// Surface (u, v) to (s, t).
        to_uv: Affine2,
    },
    /// A per-vertex (interpolated) or per-face attribute of the mesh, by name.
    MeshAttribute {
        /// The attribute's name (e.g. `vertex_color`, `face_weight`).
        name: String,
    },
    /// The product of two textures (pbrt-v4's `scale`).
    Product(Box<[TextureDesc; 2]>),
    /// `(1 - a) first + a second`, `a` the first texture read as a number (pbrt-v4's `mix`).
    Mix(Box<[TextureDesc; 3]>),
    /// max(0, 1 - t) per channel (pbrt-v4's image textures' `invert`).
    Invert(Box<TextureDesc>),
    /// √max(0, t) per channel (pbrt-v4's remapping of a textured roughness to α).
    Sqrt(Box<TextureDesc>),
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

    /// `self` × `other` (a constant where both are).
    pub fn product(self, other: TextureDesc) -> Self {
        match (self.as_constant(), other.as_constant()) {
            (Some(a), Some(b)) => TextureDesc::Constant(a * b),
            (Some(a), None) if a == Rgb::ONE => other,
            (None, Some(b)) if b == Rgb::ONE => self,
            _ => TextureDesc::Product(Box::new([self, other])),
        }
    }

    /// `self` × `s`.
    pub fn scaled(self, s: f32) -> Self {
        self.product(TextureDesc::value(s))
    }

    /// `(1 - amount) first + amount second` (a constant where all three are).
    pub fn mix(amount: TextureDesc, first: TextureDesc, second: TextureDesc) -> Self {
        match (
            amount.as_constant(),
            first.as_constant(),
            second.as_constant(),
        ) {
            (Some(a), Some(f), Some(s)) => {
                let a = crate::color::mitsuba_luminance(a);
                TextureDesc::Constant((1.0 - a) * f + a * s)
            }
            _ => TextureDesc::Mix(Box::new([amount, first, second])),
        }
    }

    /// max(0, 1 - self) per channel.
    pub fn inverted(self) -> Self {
        match self.as_constant() {
            Some(c) => TextureDesc::Constant((Rgb::ONE - c).max(Rgb::ZERO)),
            None => TextureDesc::Invert(Box::new(self)),
        }
    }

    /// √max(0, self) per channel.
    pub fn sqrt(self) -> Self {
        match self.as_constant() {
            Some(c) => TextureDesc::Constant(c.max(Rgb::ZERO).map(f32::sqrt)),
            None => TextureDesc::Sqrt(Box::new(self)),
        }
    }

    /// A summary value: the constant, the image's mean, the checkerboard's average colour,
    /// and the combinations' values of those.
    pub fn mean(&self) -> Rgb {
        match self {
            TextureDesc::Constant(c) => *c,
            TextureDesc::Image { image, .. } => image.mean(),
            TextureDesc::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
            // Bilinear in s and t apart, so its mean over the unit uv square is its value at
            // the square's centre (for the uv mappings, which scale and shift).
            TextureDesc::Bilerp { corners, to_uv } => {
                bilerp(corners, to_uv.transform_point2(glam::Vec2::splat(0.5)))
            }
            TextureDesc::MeshAttribute { .. } => Rgb::splat(0.5),
            TextureDesc::Product(ab) => ab[0].mean() * ab[1].mean(),
            TextureDesc::Mix(m) => {
                let a = crate::color::mitsuba_luminance(m[0].mean());
                (1.0 - a) * m[1].mean() + a * m[2].mean()
            }
            TextureDesc::Invert(t) => (Rgb::ONE - t.mean()).max(Rgb::ZERO),
            TextureDesc::Sqrt(t) => t.mean().max(Rgb::ZERO).map(f32::sqrt),
        }
    }
}

/// The bilinear interpolation of `corners` (at (0, 0), (1, 0), (0, 1), (1, 1)) at `st`, as
/// pbrt-v4 orders its terms.
#[inline]
pub fn bilerp(corners: &[Rgb; 4], st: glam::Vec2) -> Rgb {
    let (s, t) = (st.x, st.y);
    (1.0 - s) * (1.0 - t) * corners[0]
        + s * (1.0 - t) * corners[1]
        + (1.0 - s) * t * corners[2]
        + s * t * corners[3]
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
    /// Lambertian reflection on the side light comes from and Lambertian transmission to the
    /// other (pbrt-v4's `diffusetransmission`); both sides alike.
    DiffuseTransmission {
        /// Albedo of the reflection.
        reflectance: TextureDesc,
        /// Albedo of the transmission.
        transmittance: TextureDesc,
    },
    /// A dielectric coat over a diffuse or conductor base with a scattering layer between
    /// (pbrt-v4's `coateddiffuse` and `coatedconductor`, evaluated by random walks).
    Coated(Box<CoatedDesc>),
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
    /// Rough glass whose roughness is textured or anisotropic (α along the surface's u tangent
    /// and along v; pbrt-v4's `dielectric` with roughness textures or `uroughness` ≠
    /// `vroughness`, Mitsuba's `roughdielectric` with `alpha_u` ≠ `alpha_v`), smooth where both are
    /// negligible.
    RoughGlass {
        /// Roughness along the u tangent.
        alpha_u: TextureDesc,
        /// Roughness along the v tangent.
        alpha_v: TextureDesc,
        /// Index of refraction inside relative to outside.
        ior: f32,
        /// Microfacet distribution.
        distribution: NormalDistribution,
        /// Reflectance scale.
        reflectance: Rgb,
        /// Transmittance scale.
        transmittance: Rgb,
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
    /// `m` on the front and, seen as its front, on the back: a material that reflects alike
    /// from both sides.
    pub fn on_both_sides(m: MaterialDesc) -> MaterialDesc {
        MaterialDesc::TwoSided {
            front: Box::new(m.clone()),
            back: Box::new(m),
        }
    }

    /// The kind of material, for summaries.
    pub fn kind(&self) -> &'static str {
        match self {
            MaterialDesc::Diffuse { .. } => "diffuse",
            MaterialDesc::TexturedDiffuse { .. } => "textured diffuse",
            MaterialDesc::Mirror { .. } => "mirror",
            MaterialDesc::DiffuseTransmission { .. } => "diffuse transmission",
            MaterialDesc::Coated(c) => match c.base {
                CoatedBase::Diffuse(_) => "coated diffuse",
                CoatedBase::Conductor { .. } => "coated conductor",
            },
            MaterialDesc::Glass { .. } => "glass",
            MaterialDesc::ThinGlass { .. } => "thin glass",
            MaterialDesc::Conductor { .. } => "conductor",
            MaterialDesc::Plastic { .. } => "plastic",
            MaterialDesc::RoughConductor { .. } => "rough conductor",
            MaterialDesc::RoughGlass { .. } => "rough glass",
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

/// What lies under a [`MaterialDesc::Coated`] coat.
#[derive(Clone, Debug, PartialEq)]
pub enum CoatedBase {
    /// Lambertian of this albedo.
    Diffuse(TextureDesc),
    /// A conductor.
    Conductor {
        /// Real part of the complex index of refraction, per channel.
        eta: Rgb,
        /// Imaginary part, per channel.
        k: Rgb,
        /// Roughness α along u and v, each a texture (numbers read as luminance; 0: smooth;
        /// GGX).
        alpha: [TextureDesc; 2],
    },
}

/// A coated material (pbrt-v4's layered BSDFs): coat, base and the layer between.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatedDesc {
    /// The base.
    pub base: CoatedBase,
    /// The coat's index of refraction relative to outside.
    pub coat_eta: f32,
    /// The coat's roughness α along u and v, each a texture (numbers read as luminance; 0:
    /// smooth; GGX).
    pub coat_alpha: [TextureDesc; 2],
    /// Optical thickness of the layer (a texture: numbers read as luminance).
    pub thickness: TextureDesc,
    /// Single-scattering albedo of the layer's medium (zero: none).
    pub albedo: TextureDesc,
    /// Henyey–Greenstein asymmetry of the medium (a texture, as `thickness`).
    pub g: TextureDesc,
    /// Most scattering events a walk follows.
    pub max_depth: u32,
    /// Walks averaged by each evaluation.
    pub samples: u32,
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
