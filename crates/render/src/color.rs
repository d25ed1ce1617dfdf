//! Colour: linear sRGB / Rec. 709 radiance and reflectance, and the two luminances the
//! renderer uses (its own, and Mitsuba's where its definitions are followed).

use glam::Vec3;

/// Linear sRGB / Rec. 709 radiance or reflectance.
pub type Rgb = Vec3;

/// The weights of relative luminance Y for linear sRGB / Rec. 709 primaries.
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Relative luminance of linear sRGB / Rec. 709 primaries.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    let [r, g, b] = LUMINANCE_WEIGHTS;
    r as f32 * c.x + g as f32 * c.y + b as f32 * c.z
}

/// [`luminance`] in double precision (of image means and other sums).
#[inline]
pub fn luminance_f64(c: glam::DVec3) -> f64 {
    let [r, g, b] = LUMINANCE_WEIGHTS;
    r * c.x + g * c.y + b * c.z
}

/// Mitsuba 3's luminance: the Y row of its linear sRGB to XYZ matrix, at full precision. What
/// follows Mitsuba's definitions uses it (the principled BSDF's tints, a colour texture read
/// as a number: roughness, opacity, a bump map's height), so that it matches Mitsuba's
/// references; what needs only *a* luminance (choosing lights, adaptive sampling, image
/// statistics) uses [`luminance`].
#[inline]
pub fn mitsuba_luminance(c: Rgb) -> f32 {
    mitsuba_luminance_real(c)
}

/// [`mitsuba_luminance`] of one colour or of lanes' colours.
#[inline(always)]
pub fn mitsuba_luminance_real<V: crate::simd::lanes::Vector3>(c: V) -> V::R {
    use crate::simd::lanes::Real;
    V::R::splat(0.212671) * c.x() + V::R::splat(0.715160) * c.y() + V::R::splat(0.072169) * c.z()
}
