//! Image textures: linear RGB texels looked up by bilinear interpolation at surface (u, v).
//!
//! Convention: (0, 0) is the image's bottom-left corner and v grows upwards (OBJ, COLLADA,
//! OpenGL); loaders of formats with v growing downwards (glTF) flip v. Texel centres sit at
//! ((i + ½) / W, (j + ½) / H); lookups wrap around (repeat).

use crate::desc::Rgb;
use glam::Vec2;

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

    /// The bilinearly interpolated value at `uv` (repeating outside [0, 1]²).
    pub fn eval(&self, uv: Vec2) -> Rgb {
        if !uv.is_finite() {
            return self.texels[0];
        }
        let x = uv.x * self.width as f32 - 0.5;
        let y = (1.0 - uv.y) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: usize| (i as i64).rem_euclid(n as i64) as usize;
        let (xa, xb) = (wrap(x0, self.width), wrap(x0 + 1.0, self.width));
        let (ya, yb) = (wrap(y0, self.height), wrap(y0 + 1.0, self.height));
        let at = |x: usize, y: usize| self.texels[y * self.width + x];
        let top = at(xa, ya) * (1.0 - fx) + at(xb, ya) * fx;
        let bottom = at(xa, yb) * (1.0 - fx) + at(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

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
}
