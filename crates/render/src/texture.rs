//! Textures: image textures (linear RGB texels looked up at surface (u, v), bilinearly or
//! nearest, repeating, mirrored or clamped), and [`Tex`], the evaluated form of a
//! [`TextureDesc`]: a constant, an image, a checkerboard or a mesh attribute.
//!
//! Convention: (0, 0) is the image's bottom-left corner and v grows upwards (OBJ, COLLADA,
//! OpenGL); loaders of formats with v growing downwards (glTF) flip v. Texel centres sit at
//! ((i + ½) / W, (j + ½) / H).

use crate::desc::{Rgb, TextureDesc, TextureFilter, WrapMode};
use glam::{Affine2, Vec2, Vec3};
use std::sync::Arc;

/// An image texture (linear RGB).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from, for messages.
    pub source: String,
    width: usize,
    height: usize,
    /// Row-major, row 0 at the top of the image.
    texels: Vec<Rgb>,
}

impl Texture {
    /// A texture of `width` × `height` linear texels (row 0 at the top); `None` if the sizes
    /// disagree or the image is empty.
    pub fn new(source: String, width: usize, height: usize, texels: Vec<Rgb>) -> Option<Self> {
        (width > 0 && height > 0 && texels.len() == width * height).then(|| Texture {
            source,
            width,
            height,
            texels: texels
                .into_iter()
                .map(|c| if c.is_finite() { c } else { Rgb::ZERO })
                .collect(),
        })
    }

    /// Size in texels.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The mean of the texels.
    pub fn mean(&self) -> Rgb {
        let sum: glam::DVec3 = self.texels.iter().map(|t| t.as_dvec3()).sum();
        (sum / self.texels.len() as f64).as_vec3()
    }

    /// The value at `uv` read with `filter`, `wrap` deciding what lies outside [0, 1]².
    pub fn lookup(&self, uv: Vec2, filter: TextureFilter, wrap: WrapMode) -> Rgb {
        if !uv.is_finite() {
            return self.texels[0];
        }
        let at = |x: Option<usize>, y: Option<usize>| match (x, y) {
            (Some(x), Some(y)) => self.texels[y * self.width + x],
            _ => Rgb::ZERO,
        };
        // Row 0 is the top of the image: v = 1.
        let x = uv.x * self.width as f32;
        let y = (1.0 - uv.y) * self.height as f32;
        match filter {
            TextureFilter::Nearest => {
                let column = wrap.texel(floor(x) as i64, self.width);
                at(column, wrap.texel(floor(y) as i64, self.height))
            }
            TextureFilter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (floor(x), floor(y));
                let (fx, fy) = (x - x0, y - y0);
                // Each axis's two texels wrapped once, not once per corner.
                let [xa, xb] = wrap.texel_pair(x0 as i64, self.width);
                let [ya, yb] = wrap.texel_pair(y0 as i64, self.height);
                let top = at(xa, ya) * (1.0 - fx) + at(xb, ya) * fx;
                let bottom = at(xa, yb) * (1.0 - fx) + at(xb, yb) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }

    /// The bilinearly interpolated value at `uv` (repeating outside [0, 1]²).
    pub fn eval(&self, uv: Vec2) -> Rgb {
        self.lookup(uv, TextureFilter::Bilinear, WrapMode::Repeat)
    }
}

impl WrapMode {
    /// The texel of an axis `n` texels long that coordinate `i` (in texels) reads; none where
    /// the image is black there.
    #[inline]
    fn texel(self, i: i64, n: usize) -> Option<usize> {
        let n = n as i64;
        let inside = (0..n).contains(&i);
        match self {
            // Inside the image, as nearly every lookup is, without the integer division.
            WrapMode::Repeat => Some(if inside { i } else { i.rem_euclid(n) } as usize),
            WrapMode::Clamp => Some(i.clamp(0, n - 1) as usize),
            WrapMode::Mirror => {
                let m = if inside { i } else { i.rem_euclid(2 * n) };
                Some((if m < n { m } else { 2 * n - 1 - m }) as usize)
            }
            WrapMode::Black => inside.then_some(i as usize),
        }
    }

    /// The texels that coordinates `i` and `i + 1` read ([`WrapMode::texel`]).
    #[inline]
    fn texel_pair(self, i: i64, n: usize) -> [Option<usize>; 2] {
        let first = self.texel(i, n);
        let second = match (self, first) {
            // The next texel of a repeating image, without wrapping again.
            (WrapMode::Repeat, Some(a)) => Some(if a + 1 == n { 0 } else { a + 1 }),
            _ => self.texel(i.saturating_add(1), n),
        };
        [first, second]
    }
}

/// `x.floor()`, to the bit (a -0 stays -0), computed inline: on x86-64 CPUs without SSE4.1,
/// the target the renderer is compiled for, `floor` is a library call.
#[inline]
pub(crate) fn floor(x: f32) -> f32 {
    // From 2^23 on every float is a whole number (and NaN is its own floor).
    if x.abs() >= 8_388_608.0 || x.is_nan() {
        return x;
    }
    // Truncation, exact in this range, with the sign kept (-0.3 truncates to -0).
    let t = (x as i32 as f32).copysign(x);
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// A mesh attribute's value at each corner of each triangle (in the scene's triangle order).
pub type AttributeTable = Vec<[Vec3; 3]>;

/// Where a texture is evaluated: surface coordinates, and the triangle and barycentrics (b1,
/// b2) for mesh attributes.
#[derive(Clone, Copy, Debug)]
pub struct TexPoint<'a> {
    /// Surface (u, v).
    pub uv: Vec2,
    /// The triangle and its barycentrics, when the point is on one.
    pub triangle: Option<(u32, Vec2)>,
    /// The scene's attribute tables.
    pub attributes: &'a [AttributeTable],
}

impl TexPoint<'_> {
    /// A point with (u, v) only.
    pub fn uv(uv: Vec2) -> TexPoint<'static> {
        TexPoint {
            uv,
            triangle: None,
            attributes: &[],
        }
    }
}

/// A texture ready to evaluate (see [`TextureDesc`]); mesh attributes are resolved to the
/// scene's tables.
#[derive(Clone, Debug, PartialEq)]
pub enum Tex {
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
    /// A checkerboard.
    Checkerboard {
        /// Where the fractional parts of both coordinates are on the same side of ½.
        color0: Rgb,
        /// Elsewhere.
        color1: Rgb,
        /// Surface (u, v) to checkerboard coordinates.
        to_uv: Affine2,
    },
    /// Four values at the corners of the mapped unit square, interpolated bilinearly.
    Bilerp {
        /// The values at (s, t) = (0, 0), (1, 0), (0, 1) and (1, 1) (boxed: a texture stays
        /// as small as an image's reference and mapping).
        corners: Box<[Rgb; 4]>,
        /// Surface (u, v) to (s, t).
        to_uv: Affine2,
    },
    /// Attribute table `index` of the scene (zero where the point is not on a triangle).
    Attribute(u32),
    /// The product of two textures.
    Product(Box<[Tex; 2]>),
    /// `(1 - a) first + a second`, `a` the first read as a number.
    Mix(Box<[Tex; 3]>),
    /// max(0, 1 - t) per channel.
    Invert(Box<Tex>),
    /// √max(0, t) per channel.
    Sqrt(Box<Tex>),
}

impl Tex {
    /// The texture of `desc`; `attribute` gives the table index of a named mesh attribute.
    pub fn new(desc: &TextureDesc, attribute: &mut dyn FnMut(&str) -> u32) -> Tex {
        match desc {
            TextureDesc::Constant(c) => Tex::Constant(*c),
            TextureDesc::Image {
                image,
                filter,
                wrap,
                to_uv,
            } => Tex::Image {
                image: image.clone(),
                filter: *filter,
                wrap: *wrap,
                to_uv: *to_uv,
            },
            TextureDesc::Checkerboard {
                color0,
                color1,
                to_uv,
            } => Tex::Checkerboard {
                color0: *color0,
                color1: *color1,
                to_uv: *to_uv,
            },
            TextureDesc::Bilerp { corners, to_uv } => Tex::Bilerp {
                corners: Box::new(*corners),
                to_uv: *to_uv,
            },
            TextureDesc::MeshAttribute { name } => Tex::Attribute(attribute(name)),
            TextureDesc::Product(ab) => Tex::Product(Box::new([
                Tex::new(&ab[0], attribute),
                Tex::new(&ab[1], attribute),
            ])),
            TextureDesc::Mix(m) => Tex::Mix(Box::new([
                Tex::new(&m[0], attribute),
                Tex::new(&m[1], attribute),
                Tex::new(&m[2], attribute),
            ])),
            TextureDesc::Invert(t) => Tex::Invert(Box::new(Tex::new(t, attribute))),
            TextureDesc::Sqrt(t) => Tex::Sqrt(Box::new(Tex::new(t, attribute))),
        }
    }

    /// A texture without mesh attributes (they read as zero).
    pub fn from_desc(desc: &TextureDesc) -> Tex {
        Tex::new(desc, &mut |_| u32::MAX)
    }

    /// The constant value, if the texture is one.
    pub fn as_constant(&self) -> Option<Rgb> {
        match self {
            Tex::Constant(c) => Some(*c),
            _ => None,
        }
    }

    /// The value at `p`.
    #[inline]
    pub fn eval(&self, p: &TexPoint) -> Rgb {
        match self {
            Tex::Constant(c) => *c,
            Tex::Image {
                image,
                filter,
                wrap,
                to_uv,
            } => image.lookup(to_uv.transform_point2(p.uv), *filter, *wrap),
            Tex::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                let q = to_uv.transform_point2(p.uv);
                let (x, y) = (q.x - floor(q.x) > 0.5, q.y - floor(q.y) > 0.5);
                if x == y {
                    *color0
                } else {
                    *color1
                }
            }
            Tex::Bilerp { corners, to_uv } => {
                crate::desc::bilerp(corners, to_uv.transform_point2(p.uv))
            }
            Tex::Attribute(table) => {
                let (Some((tri, b)), Some(t)) = (p.triangle, p.attributes.get(*table as usize))
                else {
                    return Rgb::ZERO;
                };
                let Some(c) = t.get(tri as usize) else {
                    return Rgb::ZERO;
                };
                (1.0 - b.x - b.y) * c[0] + b.x * c[1] + b.y * c[2]
            }
            Tex::Product(ab) => ab[0].eval(p) * ab[1].eval(p),
            Tex::Mix(m) => {
                // The amount's luminance (its value where grey), the checkerboard unswapped.
                let a = crate::color::mitsuba_luminance(m[0].eval(p));
                (1.0 - a) * m[1].eval(p) + a * m[2].eval(p)
            }
            Tex::Invert(t) => (Rgb::ONE - t.eval(p)).max(Rgb::ZERO),
            Tex::Sqrt(t) => t.eval(p).max(Rgb::ZERO).map(f32::sqrt),
        }
    }

    /// The gradient of [`Tex::eval_float`] with respect to surface (u, v) at `p`: exact for a
    /// bilinearly filtered image (the derivative of the interpolation, through `to_uv`), zero
    /// for every other texture.
    pub fn grad_float(&self, p: &TexPoint) -> Vec2 {
        let Tex::Image {
            image,
            filter: TextureFilter::Bilinear,
            wrap,
            to_uv,
        } = self
        else {
            return Vec2::ZERO;
        };
        let q = to_uv.transform_point2(p.uv);
        let (w, h) = (image.width as f32, image.height as f32);
        let lum = crate::color::mitsuba_luminance;
        let x = q.x * w - 0.5;
        let y = (1.0 - q.y) * h - 0.5;
        let (x0, y0) = (floor(x), floor(y));
        let (fx, fy) = (x - x0, y - y0);
        let at = |dx: f32, dy: f32| {
            // Texel centres: back to image coordinates for the wrapped lookup.
            let u = (x0 + dx + 0.5) / w;
            let v = 1.0 - (y0 + dy + 0.5) / h;
            lum(image.lookup(Vec2::new(u, v), TextureFilter::Nearest, *wrap))
        };
        let (f00, f10, f01, f11) = (at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(1.0, 1.0));
        // d/dx and d/dy in texels; y runs down the image, v up.
        let dx = ((f10 - f00) * (1.0 - fy) + (f11 - f01) * fy) * w;
        let dy = ((f01 - f00) * (1.0 - fx) + (f11 - f10) * fx) * h;
        let g = Vec2::new(dx, -dy);
        // Chain rule through the affine map: ∂/∂uv = Aᵀ ∂/∂q.
        to_uv.matrix2.transpose() * g
    }

    /// The value at `p` as a number: the luminance of the colour (the value itself for grey).
    /// A checkerboard read as a number has its two colours swapped, as Mitsuba's does (its
    /// `eval_1` tests the opposite parity from its `eval`), so that scenes written for it
    /// render the same.
    #[inline]
    pub fn eval_float(&self, p: &TexPoint) -> f32 {
        let c = match self {
            Tex::Checkerboard {
                color0,
                color1,
                to_uv,
            } => Tex::Checkerboard {
                color0: *color1,
                color1: *color0,
                to_uv: *to_uv,
            }
            .eval(p),
            other => other.eval(p),
        };
        crate::color::mitsuba_luminance(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn floor_is_the_standard_floor_to_the_bit() {
        let mut xs = vec![
            0.0f32,
            -0.0,
            0.3,
            -0.3,
            1.0,
            -1.0,
            2.5,
            -2.5,
            1e-30,
            -1e-30,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            -8_388_609.0,
            3e9,
            -3e9,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let mut rng = pathlab_mc::rng::Pcg32::new(9, 2);
        xs.extend((0..20_000).map(|_| (rng.uniform_f32() - 0.5) * 4096.0));
        xs.extend(
            xs.clone()
                .into_iter()
                .flat_map(|x| [x.next_up(), x.next_down()]),
        );
        for x in xs {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "x = {x}");
        }
        assert!(floor(f32::NAN).is_nan());
    }

    #[test]
    fn each_wrap_mode_reads_the_texel_the_formula_gives() {
        let expected = |wrap: WrapMode, i: i64, n: i64| -> Option<usize> {
            match wrap {
                WrapMode::Repeat => Some(i.rem_euclid(n) as usize),
                WrapMode::Clamp => Some(i.clamp(0, n - 1) as usize),
                WrapMode::Mirror => {
                    let m = i.rem_euclid(2 * n);
                    Some((if m < n { m } else { 2 * n - 1 - m }) as usize)
                }
                WrapMode::Black => (0..n).contains(&i).then_some(i as usize),
            }
        };
        for wrap in [
            WrapMode::Repeat,
            WrapMode::Mirror,
            WrapMode::Clamp,
            WrapMode::Black,
        ] {
            for n in [1usize, 2, 3, 7, 64] {
                let far = [i64::MIN, i64::MIN + 1, -(1 << 40), 1 << 40, i64::MAX - 1];
                for i in (-4 * n as i64..4 * n as i64).chain(far) {
                    let n64 = n as i64;
                    assert_eq!(wrap.texel(i, n), expected(wrap, i, n64), "{wrap:?} {i} {n}");
                    assert_eq!(
                        wrap.texel_pair(i, n),
                        [expected(wrap, i, n64), expected(wrap, i + 1, n64)],
                        "{wrap:?} {i} {n}"
                    );
                }
            }
        }
    }

    #[test]
    fn texel_centres_are_exact_and_between_is_interpolated() {
        // 2 x 2: top row red, green; bottom row blue, white.
        let t = Texture::new(
            "test".into(),
            2,
            2,
            vec![Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE],
        )
        .unwrap();
        // v grows upwards: the bottom-left texel centre is (¼, ¼).
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), Vec3::Z);
        assert_eq!(t.eval(Vec2::new(0.25, 0.75)), Vec3::X);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), Vec3::Y);
        let mid = t.eval(Vec2::new(0.5, 0.75));
        assert!((mid - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        // Repeat: one period away is the same value.
        assert!((t.eval(Vec2::new(1.25, -0.75)) - Vec3::Z).length() < 1e-6);
        assert!(Texture::new("bad".into(), 3, 1, vec![Vec3::ONE]).is_none());
    }

    #[test]
    fn filters_and_wrap_modes() {
        // 2 x 1: left red, right green.
        let t = Texture::new("t".into(), 2, 1, vec![Vec3::X, Vec3::Y]).unwrap();
        let near = |u: f32, wrap| t.lookup(Vec2::new(u, 0.5), TextureFilter::Nearest, wrap);
        assert_eq!(near(0.2, WrapMode::Repeat), Vec3::X);
        assert_eq!(near(0.7, WrapMode::Repeat), Vec3::Y);
        assert_eq!(near(1.2, WrapMode::Repeat), Vec3::X);
        assert_eq!(near(1.2, WrapMode::Mirror), Vec3::Y);
        assert_eq!(near(1.7, WrapMode::Mirror), Vec3::X);
        assert_eq!(near(1.7, WrapMode::Clamp), Vec3::Y);
        assert_eq!(near(-0.3, WrapMode::Clamp), Vec3::X);
        let bi = t.lookup(
            Vec2::new(0.5, 0.5),
            TextureFilter::Bilinear,
            WrapMode::Clamp,
        );
        assert!((bi - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        // Clamped, the edge holds the border texel; repeated, it blends with the far side.
        let edge = |wrap| t.lookup(Vec2::new(0.0, 0.5), TextureFilter::Bilinear, wrap);
        assert_eq!(edge(WrapMode::Clamp), Vec3::X);
        assert!((edge(WrapMode::Repeat) - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        assert!((t.mean() - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
    }

    #[test]
    fn checkerboard_and_attributes() {
        let c = Tex::Checkerboard {
            color0: Vec3::ONE,
            color1: Vec3::ZERO,
            to_uv: Affine2::IDENTITY,
        };
        let at = |u, v| c.eval(&TexPoint::uv(Vec2::new(u, v)));
        assert_eq!(at(0.25, 0.25), Vec3::ONE);
        assert_eq!(at(0.75, 0.75), Vec3::ONE);
        assert_eq!(at(0.75, 0.25), Vec3::ZERO);
        assert_eq!(at(1.25, 0.25), Vec3::ONE);
        let tables = vec![vec![[Vec3::X, Vec3::Y, Vec3::Z]]];
        let a = Tex::Attribute(0);
        let p = TexPoint {
            uv: Vec2::ZERO,
            triangle: Some((0, Vec2::new(0.25, 0.5))),
            attributes: &tables,
        };
        assert!((a.eval(&p) - Vec3::new(0.25, 0.25, 0.5)).length() < 1e-6);
        assert_eq!(a.eval(&TexPoint::uv(Vec2::ZERO)), Vec3::ZERO);
        assert!((Tex::Constant(Vec3::splat(0.3)).eval_float(&p) - 0.3).abs() < 1e-6);
    }
}
