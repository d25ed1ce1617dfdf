//! Materials: what a scene's [`MaterialDesc`] becomes, and the [`Bsdf`] it has at a surface
//! point. A material is a tree: leaves are reflectance models whose parameters may be
//! textured ([`Model`]); inner nodes mask (part of the light passes through), blend two
//! materials, put different materials on the two sides, or perturb the shading normal by a
//! normal map or a bump map. At a point the tree becomes a weighted mixture of lobes, each in
//! its own shading frame.

use super::rough_plastic::CoatTable;
use super::*;
use crate::desc::{MaterialDesc, NormalDistribution, Rgb};
use crate::geometry::Frame;
use crate::texture::{Tex, TexPoint};
use glam::{Vec2, Vec3};

/// Where a material is evaluated.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint<'a> {
    /// Unit shading normal.
    pub n: Vec3,
    /// ∂p/∂u and ∂p/∂v (pathlab's v), zero when unknown: the tangents anisotropic models,
    /// normal maps and bump maps need.
    pub dpdu: Vec3,
    /// See `dpdu`.
    pub dpdv: Vec3,
    /// Unit geometric normal (bump maps keep their normal on its side).
    pub ng: Vec3,
    /// Where textures are read.
    pub tex: TexPoint<'a>,
}

impl ShadingPoint<'static> {
    /// A point with normal `n` only (textures read at (0, 0), no tangents).
    pub fn at(n: Vec3) -> Self {
        ShadingPoint {
            n,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
            ng: n,
            tex: TexPoint::uv(Vec2::ZERO),
        }
    }
}

/// A reflectance model with its (possibly textured) parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// A model whose parameters are the same everywhere.
    Fixed(Bxdf),
    /// Lambertian with albedo `scale` × texture.
    Diffuse {
        /// The albedo texture.
        texture: Tex,
        /// Its scale.
        scale: Rgb,
    },
    /// Diffuse reflection and transmission with textured albedos.
    DiffuseTransmission {
        /// Albedo of the reflection.
        reflectance: Tex,
        /// Albedo of the transmission.
        transmittance: Tex,
    },
    /// A layered model whose parameters may be textured: base albedo, roughnesses, medium.
    Coated {
        /// The model, each textured parameter replaced by its texture's value at the point.
        layered: Layered,
        /// The diffuse base's albedo.
        base_texture: Option<Tex>,
        /// The coat's roughness α along u and v (GGX).
        coat_alpha: Option<Box<[Tex; 2]>>,
        /// A conductor base's roughness α along u and v (GGX).
        base_alpha: Option<Box<[Tex; 2]>>,
        /// The layer's medium: thickness, albedo and asymmetry g.
        medium: Option<Box<[Tex; 3]>>,
        /// Whether the coat or the base is anisotropic.
        anisotropic: bool,
    },
    /// A rough conductor with textured, possibly anisotropic roughness.
    Conductor {
        /// Roughness along the u tangent.
        alpha_u: Tex,
        /// Roughness along the v tangent.
        alpha_v: Tex,
        /// Complex index, real part.
        eta: Rgb,
        /// Complex index, imaginary part.
        k: Rgb,
        /// Reflectance scale.
        specular: Tex,
        /// The distribution.
        kind: NormalDistribution,
    },
    /// Glass with textured, possibly anisotropic roughness (smooth where it is negligible).
    Dielectric {
        /// Roughness along the u tangent.
        alpha_u: Tex,
        /// Roughness along the v tangent.
        alpha_v: Tex,
        /// Index of refraction inside relative to outside.
        eta: f32,
        /// The distribution.
        kind: NormalDistribution,
        /// Reflectance scale.
        reflectance: Rgb,
        /// Transmittance scale.
        transmittance: Rgb,
    },
    /// Rough plastic with a textured base.
    RoughPlastic {
        /// The base's albedo.
        diffuse: Tex,
        /// The coat's reflectance scale.
        specular: Rgb,
        /// The coat's relative index.
        eta: f32,
        /// The coat's roughness.
        distribution: Microfacet,
        /// Internal reflections tinted by the base.
        nonlinear: bool,
        /// The coat's transmittance.
        table: &'static CoatTable,
    },
    /// Disney's principled BSDF.
    Principled(Box<PrincipledModel>),
}

/// A principled material's textured parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipledModel {
    pub(super) base_color: Tex,
    pub(super) roughness: Tex,
    pub(super) anisotropic: Option<Tex>,
    pub(super) spec_trans: Option<Tex>,
    pub(super) metallic: Option<Tex>,
    pub(super) clearcoat: Option<Tex>,
    pub(super) clearcoat_gloss: Tex,
    pub(super) sheen: Option<Tex>,
    pub(super) sheen_tint: Option<Tex>,
    pub(super) spec_tint: Option<Tex>,
    pub(super) flatness: Option<Tex>,
    pub(super) diff_trans: Option<Tex>,
    pub(super) eta: Tex,
    pub(super) thin: bool,
}

impl PrincipledModel {
    fn at(&self, p: &TexPoint) -> Principled {
        let opt = |t: &Option<Tex>| t.as_ref().map_or(0.0, |t| t.eval_float(p));
        let flags = PrincipledFlags {
            anisotropic: self.anisotropic.is_some(),
            spec_trans: self.spec_trans.is_some(),
            metallic: self.metallic.is_some(),
            clearcoat: self.clearcoat.is_some(),
            sheen: self.sheen.is_some(),
            sheen_tint: self.sheen_tint.is_some(),
            spec_tint: self.spec_tint.is_some(),
            flatness: self.flatness.is_some(),
            diff_trans: self.diff_trans.is_some(),
        };
        let mut eta = self.eta.eval_float(p);
        if (self.thin || flags.spec_trans) && eta == 1.0 {
            // Mitsuba: η = 1 is not plausible for transmission.
            eta = 1.001;
        }
        Principled {
            base_color: self.base_color.eval(p),
            roughness: self.roughness.eval_float(p),
            anisotropic: opt(&self.anisotropic),
            spec_trans: opt(&self.spec_trans),
            metallic: opt(&self.metallic),
            clearcoat: opt(&self.clearcoat),
            clearcoat_gloss: self.clearcoat_gloss.eval_float(p),
            sheen: opt(&self.sheen),
            sheen_tint: opt(&self.sheen_tint),
            spec_tint: opt(&self.spec_tint),
            flatness: opt(&self.flatness),
            diff_trans: opt(&self.diff_trans),
            eta,
            flags,
            thin: self.thin,
        }
    }
}

/// A leaf of the material tree: a model and whether its back side reflects too.
#[derive(Clone, Debug, PartialEq)]
pub struct Leaf {
    /// The model.
    pub model: Model,
    /// Whether the back side reflects as the front.
    pub two_sided: bool,
}

/// A material (see the module's description).
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// A reflectance model.
    Leaf(Leaf),
    /// Opacity (a number texture) and the material where opaque; the rest passes through.
    Mask(Tex, Box<Material>),
    /// (1 - w) × first + w × second.
    Blend(Tex, Box<(Material, Material)>),
    /// Front and back materials.
    TwoSided(Box<(Material, Material)>),
    /// A tangent-space normal map over a material.
    NormalMap(Tex, Box<Material>),
    /// A height field (and its scale) over a material.
    BumpMap(Tex, f32, Box<Material>),
}

/// The frame at a node of the tree: the shading normal (perhaps perturbed), the tangents,
/// and the surface's own shading normal once a map has moved it.
#[derive(Clone, Copy)]
struct Local {
    n: Vec3,
    dpdu: Vec3,
    dpdv: Vec3,
    guard: Option<Guard>,
}

impl Local {
    /// The frame at the top of a material's tree at `p`.
    fn at(p: &ShadingPoint) -> Local {
        Local {
            n: p.n,
            dpdu: p.dpdu,
            dpdv: p.dpdv,
            guard: None,
        }
    }

    /// The frame a normal or bump map makes from `n_local`, the perturbed normal in this
    /// frame's tangent coordinates (unnormalised), as Mitsuba's perturbed BSDFs make it: a
    /// normal that `wo` sees from behind is mirrored about this normal (Schüssler et al.
    /// 2017); the tangent is this frame's, made orthogonal to the new normal.
    fn perturbed(&self, mut n_local: Vec3, wo: Vec3) -> Local {
        let base = tangent_frame(self.n, self.dpdu);
        let wo_local = base.to_local(wo);
        if wo_local.z * wo_local.dot(n_local) <= 0.0 {
            n_local = Vec3::new(-n_local.x, -n_local.y, n_local.z);
        }
        let n_local = n_local.try_normalize().unwrap_or(Vec3::Z);
        let s_local = (Vec3::X - n_local * n_local.x)
            .try_normalize()
            .unwrap_or(Vec3::Y);
        let cos2 = n_local.z * n_local.z;
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        let n = base.to_world(n_local);
        let s = base.to_world(s_local);
        Local {
            n,
            dpdu: s,
            dpdv: n.cross(s),
            guard: Some(Guard {
                n: self.n,
                alpha2: (0.125 * tan2).min(1.0),
            }),
        }
    }
}

/// The side of a two-sided pair of materials that `wo` is on, `cos_o` its cosine to the
/// normal of the pair's frame: the front material where it is positive; the back one
/// otherwise (`wo` in the surface or the cosine NaN included), seen around the reversed
/// normal.
struct Side<'m> {
    material: &'m Material,
    back: bool,
}

impl<'m> Side<'m> {
    #[inline(always)]
    fn of((front, back): &'m (Material, Material), cos_o: f32) -> Side<'m> {
        match cos_o > 0.0 {
            true => Side {
                material: front,
                back: false,
            },
            false => Side {
                material: back,
                back: true,
            },
        }
    }

    /// The frame `at` as this side sees it: its normal reversed on the back.
    #[inline(always)]
    fn frame(&self, at: &Local) -> Local {
        match self.back {
            true => Local { n: -at.n, ..*at },
            false => *at,
        }
    }
}

/// The frame with normal `n` and first axis `dpdu` made orthogonal to it (Mitsuba's shading
/// frame); an arbitrary tangent where `dpdu` is zero or along `n`.
fn tangent_frame(n: Vec3, dpdu: Vec3) -> Frame {
    match (dpdu - n * n.dot(dpdu)).try_normalize() {
        Some(s) => Frame {
            s,
            t: n.cross(s),
            n,
        },
        None => Frame::from_normal(n),
    }
}

/// The shading frame of a leaf's lobe at unit normal `n` seen from `wo`: around `n`, turned
/// towards `wo` where the leaf is two-sided and `wo` is below; or, where `tangent` (an
/// anisotropic lobe, or a normal map's), its x axis along `dpdu` projected off `n`, and on a
/// two-sided leaf's back side only its z mirrored (as Mitsuba does). The one-path BSDF takes
/// every leaf's frame from here, and the path tracer's lanes the frames along the tangent
/// ([`Material::lane_frame`]; the others they make around the normal themselves).
#[inline]
fn leaf_frame(n: Vec3, dpdu: Vec3, two_sided: bool, wo: Vec3, tangent: bool) -> Frame {
    let side = if two_sided && wo.dot(n) < 0.0 { -n } else { n };
    if tangent {
        let mut f = tangent_frame(n, dpdu);
        if side != n {
            f.n = -f.n;
        }
        f
    } else {
        Frame::from_normal(side)
    }
}

/// The lobes a material tree gathers at a point, in order: those of positive weight, the
/// first [`MAX_LOBES`] of them (a BSDF holds no more), on the stack.
#[derive(Default)]
struct LobeList([Option<Lobe>; MAX_LOBES]);

impl LobeList {
    fn push(&mut self, lobe: Lobe) {
        // Only lobes of weight > 0 (not NaN either).
        if lobe.weight <= 0.0 || lobe.weight.is_nan() {
            return;
        }
        // A Lambertian lobe joins one already there of the same frame: the two are one
        // Lambertian lobe (the same f, density and samples), which is cheaper to evaluate and
        // which the path tracer's lanes shade (a blend of two diffuse materials).
        if let (Bxdf::Diffuse(d), None) = (lobe.bxdf, lobe.guard) {
            for l in self.0.iter_mut().flatten() {
                if let (Bxdf::Diffuse(e), None) = (&mut l.bxdf, l.guard) {
                    if l.frame == lobe.frame {
                        (l.weight, *e) = merged_diffuse(l.weight, *e, lobe.weight, d);
                        return;
                    }
                }
            }
        }
        if let Some(slot) = self.0.iter_mut().find(|l| l.is_none()) {
            *slot = Some(lobe);
        }
    }
}

/// Lambertian lobes `a` and `b` of one frame, of mixture weights `wa` and `wb` (both > 0), as
/// one lobe: its weight the sum, its reflectance the weights' mean of theirs, so that its
/// f, weight times reflectance over π, is the sum of theirs. Their samples are the same
/// cosine-weighted directions, so the mixture's density is the merged lobe's too.
fn merged_diffuse(wa: f32, a: Diffuse, wb: f32, b: Diffuse) -> (f32, Diffuse) {
    let w = wa + wb;
    let reflectance = (a.reflectance * wa + b.reflectance * wb) / w;
    (w, Diffuse { reflectance })
}

/// A lobe the path tracer's lanes shade together ([`Material::lane_bxdf`]), its sidedness,
/// and whether its frame is one [`Material::lane_frame`] gives: what [`Material::bsdf`] makes
/// of a material of that one lobe.
#[derive(Clone, Copy, Debug)]
pub struct LaneLobe {
    /// The lobe.
    pub bxdf: LaneBxdf,
    /// Whether the material is two-sided.
    pub two_sided: bool,
    /// Whether its frame follows the surface's tangent (anisotropic roughness, or a normal or
    /// bump map's frame, with the map's guard): [`Material::lane_frame`]. Otherwise its frame
    /// is the one around the shading normal, turned towards wo on a two-sided material's back
    /// side.
    pub mapped: bool,
    /// The lobe's weight, in (0, 1]: the rest of the light passes straight through (a mask
    /// where it lets some through; [`crate::bsdf::Bsdf::sample_f`] chooses between the lobe
    /// and passing through). Zero where all of it passes through (a black Lambertian lobe
    /// of weight zero, around the shading normal, holds the frame).
    pub weight: f32,
}

/// A lobe's model in the path tracer's lanes ([`LaneLobe`]).
#[derive(Clone, Copy, Debug)]
pub enum LaneBxdf {
    /// Lambertian.
    Diffuse(Diffuse),
    /// A rough conductor of GGX or Beckmann normals, of one roughness or anisotropic.
    Conductor(RoughConductor<Rgb, Microfacet>),
    /// Rough glass of GGX or Beckmann normals, of one roughness or anisotropic.
    RoughDielectric(RoughDielectric),
    /// A perfect mirror.
    Mirror(Mirror),
    /// A smooth conductor.
    SmoothConductor(SmoothConductor<Rgb>),
    /// Smooth glass (of exact Fresnel reflectance or Schlick's).
    Dielectric(SmoothDielectric),
    /// Diffuse under a smooth coat.
    Plastic(Plastic),
    /// Diffuse under a rough coat.
    RoughPlastic(RoughPlastic),
    /// A thin dielectric sheet.
    ThinDielectric(ThinDielectric),
    /// Lambertian reflection and transmission.
    DiffuseTransmission(DiffuseTransmission),
    /// Disney's principled BSDF, solid or thin.
    Principled(Principled),
}

impl LaneBxdf {
    /// The lane lobe `bxdf` is, where it is one.
    #[inline]
    fn of(bxdf: &Bxdf) -> Option<LaneBxdf> {
        Some(match bxdf {
            Bxdf::Diffuse(d) => LaneBxdf::Diffuse(*d),
            Bxdf::Conductor(c) => match c.as_smooth() {
                Some(smooth) => LaneBxdf::SmoothConductor(smooth),
                None => LaneBxdf::Conductor(c.rough()?),
            },
            Bxdf::RoughDielectric(d) => LaneBxdf::RoughDielectric(*d),
            Bxdf::Mirror(m) => LaneBxdf::Mirror(*m),
            Bxdf::Dielectric(d) => LaneBxdf::Dielectric(*d),
            Bxdf::Plastic(p) => LaneBxdf::Plastic(*p),
            Bxdf::RoughPlastic(p) => LaneBxdf::RoughPlastic(*p),
            Bxdf::ThinDielectric(d) => LaneBxdf::ThinDielectric(*d),
            Bxdf::DiffuseTransmission(d) => LaneBxdf::DiffuseTransmission(*d),
            Bxdf::Principled(p) => LaneBxdf::Principled(*p),
            _ => return None,
        })
    }
}

impl Leaf {
    /// [`Material::lane_bxdf`] of this leaf, its textures read at `tex`; `mapped` where it is
    /// under a normal or bump map. Inlined always: called, it would pass the textured model's
    /// `Bxdf` (large) through memory.
    #[inline(always)]
    fn lane_lobe<'a>(&self, tex: impl FnOnce() -> TexPoint<'a>, mapped: bool) -> Option<LaneLobe> {
        // Borrowed where the model is fixed: a `Bxdf` is large, and only its lobe is taken.
        let textured;
        let (bxdf, anisotropic) = match &self.model {
            Model::Fixed(bxdf) => (bxdf, false),
            Model::Diffuse { .. }
            | Model::DiffuseTransmission { .. }
            | Model::Conductor { .. }
            | Model::Dielectric { .. }
            | Model::RoughPlastic { .. }
            | Model::Principled(_) => {
                textured = self.model.bxdf(&tex());
                (&textured.0, textured.1)
            }
            _ => return None,
        };
        Some(LaneLobe {
            bxdf: LaneBxdf::of(bxdf)?,
            two_sided: self.two_sided,
            mapped: mapped || anisotropic,
            weight: 1.0,
        })
    }
}

/// [`Material::lane_bxdf`] of a two-sided pair of materials (front, back), `cos_o` the cosine
/// of wo to the shading normal: the front leaf's lobe where wo is on the front side, as
/// [`Material::collect`] takes it; the back leaf's where wo is behind, given as two-sided so
/// that its frame is the one around the reversed normal `collect` gives it (the lanes turn a
/// two-sided lobe's normal towards wo); none where wo lies in the surface, or where the side
/// is not a leaf the lanes shade.
#[inline(always)]
fn lane_side<'a>(
    pair: &(Material, Material),
    tex: impl FnOnce() -> TexPoint<'a>,
    cos_o: f32,
) -> Option<LaneLobe> {
    // In the surface (or NaN) `collect` takes the back, around the reversed normal; the lanes,
    // which turn a two-sided lobe's normal towards `wo`, would not reverse it there.
    if cos_o == 0.0 || cos_o.is_nan() {
        return None;
    }
    let side = Side::of(pair, cos_o);
    let Material::Leaf(leaf) = side.material else {
        return None;
    };
    let lobe = leaf.lane_lobe(tex, false)?;
    Some(LaneLobe {
        two_sided: lobe.two_sided || side.back,
        ..lobe
    })
}

/// [`Material::lane_bxdf`] of a mask of `opacity` over `inner` at `tex`, the BSDF
/// [`Material::collect`] makes of it: where the mask is opaque (an opacity of one or more),
/// the inner material's lobe alone; where it lets some light through, that lobe (of weight
/// one, in its own frame and under its map's guard if it has them) weighted by the opacity,
/// the rest passing through; where it lets all through, passing through alone. None where the
/// opacity is NaN, or where the inner lobe is none the lanes shade, or has a weight below one.
/// Out of line, and not generic: a mask holds a material, which may be a mask.
#[inline(never)]
fn lane_mask(
    opacity: &Tex,
    inner: &Material,
    tex: TexPoint,
    wo: Vec3,
    n: Vec3,
) -> Option<LaneLobe> {
    // `collect`'s weights at the top of the tree: the lobe's one times the opacity.
    let a = opacity.eval_float(&tex).clamp(0.0, 1.0);
    if a.is_nan() {
        return None;
    }
    if a >= 1.0 {
        return inner.lane_bxdf(|| tex, wo, n);
    }
    if a <= 0.0 {
        // No lobe: `bsdf`'s black one, of weight zero, holds the frame.
        return Some(LaneLobe {
            bxdf: LaneBxdf::Diffuse(Diffuse {
                reflectance: Rgb::ZERO,
            }),
            two_sided: false,
            mapped: false,
            weight: 0.0,
        });
    }
    let lobe = inner.lane_bxdf(|| tex, wo, n)?;
    if lobe.weight < 1.0 {
        return None;
    }
    Some(LaneLobe { weight: a, ..lobe })
}

impl Material {
    /// A material of one model without textures.
    pub fn new(bxdf: Bxdf, two_sided: bool) -> Self {
        Material::Leaf(Leaf {
            model: Model::Fixed(bxdf),
            two_sided,
        })
    }

    /// The reflectance and sidedness of a plain (untextured) Lambertian material.
    #[inline]
    pub fn as_lambertian(&self) -> Option<(Diffuse, bool)> {
        match self {
            Material::Leaf(Leaf {
                model: Model::Fixed(Bxdf::Diffuse(d)),
                two_sided,
            }) => Some((*d, *two_sided)),
            _ => None,
        }
    }

    /// The lobe of a material of one lobe that the path tracer's lanes shade together, its
    /// textures read at `tex`: Lambertian, a rough conductor or rough glass of GGX or Beckmann
    /// normals (of one roughness or anisotropic), a mirror, a smooth conductor, smooth glass
    /// (of exact Fresnel reflectance or Schlick's), a thin sheet of glass, smooth or rough
    /// plastic, diffuse reflection and transmission, the principled model; one of those under
    /// a normal or bump map; or a blend of two Lambertian materials, which is one Lambertian
    /// lobe. Textured models are evaluated (as [`Material::bsdf`] evaluates them) only where they
    /// may give one of those: diffuse (and diffuse transmission), conductors, glass, rough
    /// plastic and the principled model. Of a two-sided pair of materials, the one on the
    /// side of `wo` (against the shading normal `n`), where that is one of those models
    /// (none where `wo` lies in the surface); of a mask, its material's lobe weighted by its
    /// opacity, the rest of the light passing through ([`LaneLobe::weight`]).
    #[inline]
    pub fn lane_bxdf<'a>(
        &self,
        tex: impl FnOnce() -> TexPoint<'a>,
        wo: Vec3,
        n: Vec3,
    ) -> Option<LaneLobe> {
        match self {
            Material::Leaf(leaf) => leaf.lane_lobe(tex, false),
            Material::TwoSided(ab) => lane_side(ab, tex, wo.dot(n)),
            Material::Mask(opacity, inner) => lane_mask(opacity, inner, tex(), wo, n),
            Material::Blend(..) => self.lane_blend(tex),
            Material::NormalMap(_, inner) | Material::BumpMap(_, _, inner) => match &**inner {
                Material::Leaf(leaf) => leaf.lane_lobe(tex, true),
                _ => None,
            },
        }
    }

    /// The frame (and a normal or bump map's guard) of a lobe [`Material::lane_bxdf`] gives as
    /// `mapped`, at `p` seen from `wo`: what [`Material::bsdf`] gives its leaf, the frame
    /// along the tangent of the shading point's or the map's frame.
    #[inline(never)]
    pub fn lane_frame(&self, p: &ShadingPoint, wo: Vec3) -> (Frame, Option<Guard>) {
        let at = Local::at(p);
        let (at, two_sided) = match self {
            Material::Leaf(leaf) => (at, leaf.two_sided),
            // A mask: its material's frame.
            Material::Mask(_, inner) => return inner.lane_frame(p, wo),
            // The side `collect` takes.
            Material::TwoSided(ab) => {
                let side = Side::of(ab, wo.dot(at.n));
                (side.frame(&at), side.material.leaf_two_sided())
            }
            _ => match self.perturbation(p, &at, wo) {
                Some((perturbed, Material::Leaf(leaf))) => (perturbed, leaf.two_sided),
                // Not a lobe `lane_bxdf` gives as mapped.
                _ => (at, false),
            },
        };
        (leaf_frame(at.n, at.dpdu, two_sided, wo, true), at.guard)
    }

    /// A leaf's sidedness (false for any other material).
    fn leaf_two_sided(&self) -> bool {
        matches!(self, Material::Leaf(leaf) if leaf.two_sided)
    }

    /// [`Material::lane_bxdf`] of a blend of two Lambertian materials of one sidedness: the
    /// one Lambertian lobe [`Material::collect`] merges them into (`LobeList::push`), or none
    /// for any other material.
    fn lane_blend<'a>(&self, tex: impl FnOnce() -> TexPoint<'a>) -> Option<LaneLobe> {
        let Material::Blend(weight, ab) = self else {
            return None;
        };
        let (Material::Leaf(a), Material::Leaf(b)) = (&ab.0, &ab.1) else {
            return None;
        };
        if a.two_sided != b.two_sided {
            return None;
        }
        let tex = tex();
        let diffuse = |leaf: &Leaf| match leaf.model.bxdf(&tex) {
            (Bxdf::Diffuse(d), false) => Some(d),
            _ => None,
        };
        let (da, db) = (diffuse(a)?, diffuse(b)?);
        // The weights `collect` gives the two at the top of the tree (1 - w and w, times one).
        let w = weight.eval_float(&tex).clamp(0.0, 1.0);
        let d = match (1.0 - w, w) {
            (wa, wb) if wa > 0.0 && wb > 0.0 => merged_diffuse(wa, da, wb, db).1,
            (wa, _) if wa > 0.0 => da,
            (_, wb) if wb > 0.0 => db,
            _ => return None,
        };
        Some(LaneLobe {
            bxdf: LaneBxdf::Diffuse(d),
            two_sided: a.two_sided,
            mapped: false,
            weight: 1.0,
        })
    }

    /// Whether evaluating the material may read a texture at the surface's (u, v): every
    /// material but one of fixed models (or two, one per side) is taken to.
    pub fn reads_textures(&self) -> bool {
        match self {
            Material::Leaf(l) => !matches!(l.model, Model::Fixed(_)),
            Material::TwoSided(ab) => ab.0.reads_textures() || ab.1.reads_textures(),
            Material::Mask(..)
            | Material::Blend(..)
            | Material::NormalMap(..)
            | Material::BumpMap(..) => true,
        }
    }

    /// Whether evaluating the material needs the surface's tangents.
    pub fn needs_tangents(&self) -> bool {
        match self {
            Material::Leaf(l) => match &l.model {
                Model::Conductor { .. } | Model::Dielectric { .. } => true,
                Model::Coated { anisotropic, .. } => *anisotropic,
                Model::Principled(p) => p.anisotropic.is_some(),
                _ => false,
            },
            Material::Mask(_, m) => m.needs_tangents(),
            Material::Blend(_, ab) | Material::TwoSided(ab) => {
                ab.0.needs_tangents() || ab.1.needs_tangents()
            }
            Material::NormalMap(..) | Material::BumpMap(..) => true,
        }
    }

    /// The BSDF at `p` seen from `wo`.
    #[inline]
    pub fn bsdf(&self, p: &ShadingPoint, wo: Vec3) -> Bsdf {
        if let Material::Leaf(Leaf {
            model: Model::Fixed(bxdf),
            two_sided,
        }) = self
        {
            return Bsdf::from_bxdf(*bxdf, *two_sided, p.n, wo);
        }
        self.bsdf_general(p, wo)
    }

    #[inline(never)]
    fn bsdf_general(&self, p: &ShadingPoint, wo: Vec3) -> Bsdf {
        let mut lobes = LobeList::default();
        let mut null = 0.0;
        let local = Local {
            n: p.n,
            dpdu: p.dpdu,
            dpdv: p.dpdv,
            guard: None,
        };
        self.collect(p, &local, wo, 1.0, &mut lobes, &mut null);
        let [first, rest @ ..] = lobes.0;
        // Nothing but passing through (or nothing at all): a black lobe holds the frame.
        let first = first.unwrap_or_else(|| Lobe {
            weight: 0.0,
            frame: Frame::from_normal(p.n),
            bxdf: Bxdf::Diffuse(Diffuse {
                reflectance: Rgb::ZERO,
            }),
            guard: None,
        });
        Bsdf::mixture(first, rest, null)
    }

    /// A normal or bump map's frame for its inner material at `p` (the frame `at` there)
    /// seen from `wo`, and that material; `None` for any other material.
    fn perturbation(&self, p: &ShadingPoint, at: &Local, wo: Vec3) -> Option<(Local, &Material)> {
        match self {
            Material::NormalMap(map, inner) => {
                let n_local = map.eval(&p.tex) * 2.0 - Rgb::ONE;
                Some((at.perturbed(n_local, wo), inner))
            }
            Material::BumpMap(height, scale, inner) => {
                // Mitsuba's bumpmap: the tangents displaced by the height's gradient (its
                // v grows the other way: pathlab's ∂/∂v and ∂p/∂v are its negatives).
                let g = height.grad_float(&p.tex) * *scale;
                let dpdu = at.dpdu + at.n * (g.x - at.n.dot(at.dpdu));
                let dpdv = at.dpdv + at.n * (g.y - at.n.dot(at.dpdv));
                let mut n = dpdu.cross(dpdv);
                if n.dot(p.ng) < 0.0 {
                    n = -n;
                }
                let n_local = tangent_frame(at.n, at.dpdu).to_local(n);
                Some((at.perturbed(n_local, wo), inner))
            }
            _ => None,
        }
    }

    fn collect(
        &self,
        p: &ShadingPoint,
        at: &Local,
        wo: Vec3,
        weight: f32,
        lobes: &mut LobeList,
        null: &mut f32,
    ) {
        if weight <= 0.0 {
            return;
        }
        match self {
            Material::Leaf(leaf) => {
                let (bxdf, anisotropic) = leaf.model.bxdf(&p.tex);
                let tangent = anisotropic || at.guard.is_some();
                let frame = leaf_frame(at.n, at.dpdu, leaf.two_sided, wo, tangent);
                lobes.push(Lobe {
                    weight,
                    frame,
                    bxdf,
                    guard: at.guard,
                });
            }
            Material::Mask(opacity, inner) => {
                let a = opacity.eval_float(&p.tex).clamp(0.0, 1.0);
                inner.collect(p, at, wo, weight * a, lobes, null);
                *null += weight * (1.0 - a);
            }
            Material::Blend(w, ab) => {
                let w = w.eval_float(&p.tex).clamp(0.0, 1.0);
                ab.0.collect(p, at, wo, weight * (1.0 - w), lobes, null);
                ab.1.collect(p, at, wo, weight * w, lobes, null);
            }
            Material::TwoSided(ab) => {
                let side = Side::of(ab, wo.dot(at.n));
                side.material
                    .collect(p, &side.frame(at), wo, weight, lobes, null);
            }
            Material::NormalMap(..) | Material::BumpMap(..) => {
                if let Some((perturbed, inner)) = self.perturbation(p, at, wo) {
                    inner.collect(p, &perturbed, wo, weight, lobes, null);
                }
            }
        }
    }
}

impl Model {
    /// The model's BxDF at a point with textures read at `p`, and whether it is anisotropic
    /// (its frame must follow the surface's tangent).
    fn bxdf(&self, p: &TexPoint) -> (Bxdf, bool) {
        match self {
            Model::Fixed(b) => (*b, false),
            Model::Diffuse { texture, scale } => (
                Bxdf::Diffuse(Diffuse {
                    reflectance: (*scale * texture.eval(p)).clamp(Vec3::ZERO, Vec3::ONE),
                }),
                false,
            ),
            Model::DiffuseTransmission {
                reflectance,
                transmittance,
            } => (
                Bxdf::DiffuseTransmission(DiffuseTransmission {
                    reflectance: reflectance.eval(p).clamp(Vec3::ZERO, Vec3::ONE),
                    transmittance: transmittance.eval(p).clamp(Vec3::ZERO, Vec3::ONE),
                }),
                false,
            ),
            Model::Coated {
                layered,
                base_texture,
                coat_alpha,
                base_alpha,
                medium,
                anisotropic,
            } => {
                let mut l = *layered;
                if let Some(t) = base_texture {
                    l.reflectance = t.eval(p).clamp(Vec3::ZERO, Vec3::ONE);
                }
                let ggx = |[au, av]: &[Tex; 2]| {
                    Microfacet::unless_smooth(
                        NormalDistribution::Ggx,
                        au.eval_float(p),
                        av.eval_float(p),
                    )
                };
                if let Some(alpha) = coat_alpha.as_deref() {
                    l.coat_roughness = ggx(alpha);
                }
                if let Some(alpha) = base_alpha.as_deref() {
                    l.base_roughness = ggx(alpha);
                }
                if let Some([thickness, albedo, g]) = medium.as_deref() {
                    l.medium =
                        LayerMedium::new(thickness.eval_float(p), albedo.eval(p), g.eval_float(p));
                }
                (Bxdf::Layered(l), *anisotropic)
            }
            Model::Conductor {
                alpha_u,
                alpha_v,
                eta,
                k,
                specular,
                kind,
            } => {
                let (au, av) = (alpha_u.eval_float(p), alpha_v.eval_float(p));
                let distribution = Microfacet::unless_smooth(*kind, au, av);
                (
                    Bxdf::Conductor(Conductor {
                        eta: *eta,
                        k: *k,
                        specular: specular.eval(p),
                        distribution,
                    }),
                    au != av,
                )
            }
            Model::Dielectric {
                alpha_u,
                alpha_v,
                eta,
                kind,
                reflectance,
                transmittance,
            } => {
                let (au, av) = (alpha_u.eval_float(p), alpha_v.eval_float(p));
                let bxdf = match Microfacet::unless_smooth(*kind, au, av) {
                    Some(distribution) => Bxdf::RoughDielectric(RoughDielectric {
                        eta: *eta,
                        distribution,
                        reflectance: *reflectance,
                        transmittance: *transmittance,
                    }),
                    None => Bxdf::Dielectric(SmoothDielectric {
                        eta: *eta,
                        reflectance: *reflectance,
                        transmittance: *transmittance,
                        fresnel: crate::desc::FresnelModel::Exact,
                    }),
                };
                (bxdf, au != av)
            }
            Model::RoughPlastic {
                diffuse,
                specular,
                eta,
                distribution,
                nonlinear,
                table,
            } => (
                Bxdf::RoughPlastic(RoughPlastic {
                    diffuse: diffuse.eval(p).clamp(Vec3::ZERO, Vec3::ONE),
                    specular: *specular,
                    eta: *eta,
                    distribution: *distribution,
                    nonlinear: *nonlinear,
                    table,
                }),
                false,
            ),
            Model::Principled(m) => (Bxdf::Principled(m.at(p)), m.anisotropic.is_some()),
        }
    }
}

impl From<&MaterialDesc> for Material {
    /// The material for a description (mesh attributes read as zero).
    fn from(d: &MaterialDesc) -> Self {
        Material::from_desc(d, &mut |_| u32::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diffuse(r: f32) -> Material {
        Material::new(
            Bxdf::Diffuse(Diffuse {
                reflectance: Rgb::splat(r),
            }),
            false,
        )
    }

    fn blend(w: f32, a: Material, b: Material) -> Material {
        Material::Blend(Tex::Constant(Rgb::splat(w)), Box::new((a, b)))
    }

    fn mirror(r: f32) -> Material {
        Material::new(
            Bxdf::Mirror(Mirror {
                reflectance: Rgb::splat(r),
            }),
            false,
        )
    }

    #[test]
    fn a_tree_gives_its_first_lobes_in_order_up_to_the_most_a_bsdf_holds() {
        // Five leaves, the last two at an eighth each: the BSDF keeps the first four.
        let tree = blend(
            0.5,
            blend(0.5, mirror(0.1), mirror(0.2)),
            blend(0.5, mirror(0.3), blend(0.5, mirror(0.4), mirror(0.5))),
        );
        let bsdf = tree.bsdf(&ShadingPoint::at(Vec3::Z), Vec3::Z);
        let lobes: Vec<(f32, Bxdf)> = bsdf.lobes().map(|l| (l.weight, l.bxdf)).collect();
        assert_eq!(lobes.len(), MAX_LOBES);
        for (k, (weight, r)) in [(0.25, 0.1), (0.25, 0.2), (0.25, 0.3), (0.125, 0.4)]
            .into_iter()
            .enumerate()
        {
            let Bxdf::Mirror(m) = lobes[k].1 else {
                panic!("lobe {k}: {:?}", lobes[k].1);
            };
            assert_eq!(
                (lobes[k].0, m.reflectance),
                (weight, Rgb::splat(r)),
                "lobe {k}"
            );
        }
        assert_eq!(bsdf.pass_through(), 0.0);
    }

    #[test]
    fn lambertian_lobes_of_one_frame_are_one_lobe_of_the_same_value_and_density() {
        // Five Lambertian leaves (the tree above's, diffuse): one lobe, nothing dropped, of
        // weight one and the weights' mean reflectance.
        let tree = blend(
            0.5,
            blend(0.5, diffuse(0.1), diffuse(0.2)),
            blend(0.5, diffuse(0.3), blend(0.5, diffuse(0.4), diffuse(0.5))),
        );
        let bsdf = tree.bsdf(&ShadingPoint::at(Vec3::Z), Vec3::Z);
        let lobes: Vec<&Lobe> = bsdf.lobes().collect();
        assert_eq!(lobes.len(), 1);
        assert_eq!(lobes[0].weight, 1.0);
        let mean = 0.25 * (0.1 + 0.2 + 0.3) + 0.125 * (0.4 + 0.5);
        let Bxdf::Diffuse(d) = lobes[0].bxdf else {
            panic!("{:?}", lobes[0].bxdf);
        };
        assert!((d.reflectance - Rgb::splat(mean)).abs().max_element() < 1e-6);
        // f and the density against the sums the mixture of five would give.
        let (wo, wi) = (
            Vec3::new(0.3, 0.1, 0.9).normalize(),
            Vec3::new(-0.5, 0.2, 0.6).normalize(),
        );
        let f = bsdf.f(wo, wi);
        assert!(
            (f - Rgb::splat(mean * std::f32::consts::FRAC_1_PI))
                .abs()
                .max_element()
                < 1e-6
        );
        let cos = wi.z;
        assert!((bsdf.pdf(wo, wi) - cos * std::f32::consts::FRAC_1_PI).abs() < 1e-6);
        // Under a mask, the merged lobe keeps the mask's share; passing through the rest.
        let masked = Material::Mask(
            Tex::Constant(Rgb::splat(0.4)),
            Box::new(blend(0.3, diffuse(0.2), diffuse(0.8))),
        );
        let bsdf = masked.bsdf(&ShadingPoint::at(Vec3::Z), Vec3::Z);
        let lobes: Vec<&Lobe> = bsdf.lobes().collect();
        assert_eq!(lobes.len(), 1);
        assert!((lobes[0].weight - 0.4).abs() < 1e-6);
        assert!((bsdf.pass_through() - 0.6).abs() < 1e-6);
        let Bxdf::Diffuse(d) = lobes[0].bxdf else {
            panic!("{:?}", lobes[0].bxdf);
        };
        assert!(
            (d.reflectance - Rgb::splat(0.7 * 0.2 + 0.3 * 0.8))
                .abs()
                .max_element()
                < 1e-6
        );
        // A Lambertian leaf and a mirror stay two lobes.
        let two = blend(0.5, diffuse(0.5), mirror(0.5));
        assert_eq!(
            two.bsdf(&ShadingPoint::at(Vec3::Z), Vec3::Z)
                .lobes()
                .count(),
            2
        );
    }

    #[test]
    fn a_fully_transparent_material_is_a_black_lobe_and_passing_through() {
        let mask = Material::Mask(Tex::Constant(Rgb::ZERO), Box::new(diffuse(0.5)));
        let bsdf = mask.bsdf(&ShadingPoint::at(Vec3::Z), Vec3::Z);
        let lobes: Vec<&Lobe> = bsdf.lobes().collect();
        assert_eq!(lobes.len(), 1);
        assert_eq!(lobes[0].weight, 0.0);
        assert!(matches!(lobes[0].bxdf, Bxdf::Diffuse(d) if d.reflectance == Rgb::ZERO));
        assert_eq!(bsdf.pass_through(), 1.0);
    }

    #[test]
    fn a_two_sided_pair_is_its_front_in_front_and_its_back_around_the_reversed_normal() {
        // One-sided Lambertian sides of two reflectances: each reflects on its own side only.
        let pair = Material::TwoSided(Box::new((diffuse(0.2), diffuse(0.6))));
        let p = ShadingPoint::at(Vec3::Z);
        let (above, below) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, -0.8));
        let f = |wo: Vec3, wi: Vec3| pair.bsdf(&p, wo).f(wo, wi);
        let lambert = |r: f32| Rgb::splat(r / std::f32::consts::PI);
        assert!((f(above, above) - lambert(0.2)).abs().max_element() < 1e-6);
        assert!((f(below, below) - lambert(0.6)).abs().max_element() < 1e-6);
        assert_eq!(f(above, below), Rgb::ZERO);
        assert_eq!(f(below, above), Rgb::ZERO);
        // In the surface: the back, around the reversed normal.
        let in_plane = pair.bsdf(&p, Vec3::X);
        assert_eq!(in_plane.frame().n, -Vec3::Z);
        assert!(matches!(in_plane.bxdf(), Bxdf::Diffuse(d) if d.reflectance == Rgb::splat(0.6)));
    }

    #[test]
    fn a_two_sided_pairs_lane_lobe_is_the_side_of_wo() {
        // In front, the front leaf as it is; behind, the back leaf, two-sided (its normal
        // reversed, as `collect` reverses it); in the surface, none (left to `bsdf`).
        let pair = Material::TwoSided(Box::new((diffuse(0.2), mirror(0.7))));
        let tex = || TexPoint::uv(Vec2::ZERO);
        let n = Vec3::Z;
        let front = pair.lane_bxdf(tex, Vec3::new(0.3, 0.0, 0.9), n).unwrap();
        assert!(matches!(front.bxdf, LaneBxdf::Diffuse(d) if d.reflectance == Rgb::splat(0.2)));
        assert!(!front.two_sided && !front.mapped);
        let back = pair.lane_bxdf(tex, Vec3::new(0.3, 0.0, -0.9), n).unwrap();
        assert!(matches!(back.bxdf, LaneBxdf::Mirror(m) if m.reflectance == Rgb::splat(0.7)));
        assert!(back.two_sided && !back.mapped);
        assert!(pair.lane_bxdf(tex, Vec3::X, n).is_none());
        // A side the lanes do not shade (a mask) leaves the pair to `bsdf` on that side.
        let masked = Material::Mask(Tex::Constant(Rgb::splat(0.5)), Box::new(diffuse(0.5)));
        let pair = Material::TwoSided(Box::new((diffuse(0.2), masked)));
        assert!(pair.lane_bxdf(tex, Vec3::Z, n).is_some());
        assert!(pair.lane_bxdf(tex, -Vec3::Z, n).is_none());
    }

    #[test]
    fn a_masks_lane_lobe_is_its_materials_weighted_by_its_opacity() {
        let tex = || TexPoint::uv(Vec2::ZERO);
        let (wo, n) = (Vec3::Z, Vec3::Z);
        let mask =
            |a: f32, inner: Material| Material::Mask(Tex::Constant(Rgb::splat(a)), Box::new(inner));
        // Opaque: the material's lobe alone.
        for a in [1.0, 2.0] {
            let lobe = mask(a, mirror(0.7)).lane_bxdf(tex, wo, n).unwrap();
            assert!(matches!(lobe.bxdf, LaneBxdf::Mirror(m) if m.reflectance == Rgb::splat(0.7)));
            assert_eq!(lobe.weight, 1.0);
        }
        // Letting some light through: the lobe, weighted as `collect` weighs it.
        for a in [0.5, 1.0 - f32::EPSILON, f32::MIN_POSITIVE] {
            let lobe = mask(a, mirror(0.7)).lane_bxdf(tex, wo, n).unwrap();
            assert!(matches!(lobe.bxdf, LaneBxdf::Mirror(_)));
            assert!(lobe.weight > 0.0 && lobe.weight < 1.0 && (lobe.weight - a).abs() < 1e-6);
            let bsdf = mask(a, mirror(0.7)).bsdf(&ShadingPoint::at(n), wo);
            assert_eq!(
                bsdf.lobes().map(|l| l.weight).collect::<Vec<_>>(),
                [lobe.weight]
            );
            assert_eq!(bsdf.pass_through(), 1.0 - lobe.weight);
        }
        // Letting all through: a black lobe of weight zero.
        for a in [0.0, -1.0] {
            let lobe = mask(a, mirror(0.7)).lane_bxdf(tex, wo, n).unwrap();
            assert!(matches!(lobe.bxdf, LaneBxdf::Diffuse(d) if d.reflectance == Rgb::ZERO));
            assert_eq!(
                (lobe.weight, lobe.two_sided, lobe.mapped),
                (0.0, false, false)
            );
        }
        // Over a lobe with a frame of its own (a normal map's): that lobe, weighted.
        let normals = Tex::Constant(Rgb::new(0.6, 0.5, 0.9));
        let mapped = Material::NormalMap(normals, Box::new(mirror(0.7)));
        let lobe = mask(0.25, mapped).lane_bxdf(tex, wo, n).unwrap();
        assert!(matches!(lobe.bxdf, LaneBxdf::Mirror(_)));
        assert_eq!((lobe.weight, lobe.mapped), (0.25, true));
        // A NaN opacity, or a see-through mask over a weighted lobe: left to `bsdf`.
        assert!(mask(f32::NAN, mirror(0.7)).lane_bxdf(tex, wo, n).is_none());
        let nested = mask(0.5, mask(0.5, diffuse(0.5)));
        assert!(nested.lane_bxdf(tex, wo, n).is_none());
        assert!(mask(1.0, mask(0.5, diffuse(0.5)))
            .lane_bxdf(tex, wo, n)
            .is_some());
    }
}
