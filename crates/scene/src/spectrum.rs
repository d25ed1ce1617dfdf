//! Spectra in an RGB renderer: wavelength:value lists integrated against the CIE 1931
//! colour-matching functions and turned into linear sRGB, as Mitsuba 3's RGB variants do when
//! they read a `<spectrum>` (its `spectrum_list_to_srgb`), and blackbody emission.
//!
//! The conventions are Mitsuba's, so that a scene written for it renders the same colours:
//! values are scaled by 1/∫ȳ (a constant spectrum of 1 has luminance 1); reflectances are
//! weighted by the D65 illuminant (so a flat reflectance of 1 is white, (1, 1, 1)); emission is
//! not (so a flat emission spectrum is the colour of equal-energy light, slightly purple in
//! sRGB, whose white point is D65); the integral is a 1000-point Riemann sum over 360–830 nm
//! that skips wavelengths outside the list's range.

use glam::{DVec3, Vec3};

/// First wavelength of the tables (nm).
pub const CIE_MIN: f64 = 360.0;
/// Last wavelength of the tables (nm).
pub const CIE_MAX: f64 = 830.0;
/// Entries per table (5 nm steps).
const SAMPLES: usize = 95;

/// 1 / ∫ ȳ(λ) dλ: a unit spectrum integrates to luminance 1.
pub const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;
/// 1 / ∫ ȳ(λ) D65(λ) dλ: the D65 curve below integrates to luminance 1.
const D65_NORMALIZATION: f64 = 1.0 / 98.997_417_518_762_55;

include!("spectrum_tables.rs");

/// Linear interpolation in a 5 nm table; zero outside 360–830 nm.
fn lookup(table: &[f64; SAMPLES], w: f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&w) {
        return 0.0;
    }
    let t = (w - CIE_MIN) * ((SAMPLES - 1) as f64 / (CIE_MAX - CIE_MIN));
    let i0 = (t as usize).min(SAMPLES - 2);
    let w1 = t - i0 as f64;
    (1.0 - w1) * table[i0] + w1 * table[i0 + 1]
}

/// Whether `c` is a colour a light may emit: finite and at least zero in every channel (a
/// negative one means nothing, and rendered it would carry no light: a black image, without a
/// word). Every loader refuses a light's colour that is not.
pub(crate) fn is_emission(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

/// The CIE 1931 colour-matching functions (x̄, ȳ, z̄) at wavelength `w` (nm).
pub fn cie1931_xyz(w: f64) -> DVec3 {
    DVec3::new(lookup(&CIE_X, w), lookup(&CIE_Y, w), lookup(&CIE_Z, w))
}

/// The D65 illuminant at wavelength `w`, normalised to luminance 1.
pub fn cie_d65(w: f64) -> f64 {
    lookup(&D65, w) * D65_NORMALIZATION
}

/// XYZ tristimulus values to linear sRGB (Rec. 709 primaries, D65 white).
pub fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    DVec3::new(
        3.240479 * xyz.x - 1.537150 * xyz.y - 0.498535 * xyz.z,
        -0.969256 * xyz.x + 1.875991 * xyz.y + 0.041556 * xyz.z,
        0.055648 * xyz.x - 0.204043 * xyz.y + 1.057311 * xyz.z,
    )
}

/// Linear sRGB to XYZ (the inverse of [`xyz_to_srgb`]).
pub fn srgb_to_xyz(rgb: DVec3) -> DVec3 {
    DVec3::new(
        0.412453 * rgb.x + 0.357580 * rgb.y + 0.180423 * rgb.z,
        0.212671 * rgb.x + 0.715160 * rgb.y + 0.072169 * rgb.z,
        0.019334 * rgb.x + 0.119193 * rgb.y + 0.950227 * rgb.z,
    )
}

/// What a spectrum describes, which decides how it becomes RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumKind {
    /// A reflectance or transmittance: weighted by D65, clamped to [0, 1].
    Reflectance,
    /// Emitted radiance or intensity: not weighted, negative components clamped to 0.
    Emission,
    /// An unbounded material constant (an index of refraction η or k): not weighted,
    /// negative components clamped to 0.
    Unbounded,
}

/// A spectrum given as (wavelength in nm, value) pairs, linearly interpolated, as linear
/// sRGB: Mitsuba's `spectrum_list_to_srgb` with its unit conversion. The pairs must be in
/// increasing order of wavelength (the caller checks).
pub fn sampled_to_rgb(samples: &[(f64, f64)], kind: SpectrumKind) -> DVec3 {
    let Some((&(first, _), &(last, _))) = samples.first().zip(samples.last()) else {
        return DVec3::ZERO;
    };
    let steps = 1000;
    let mut xyz = DVec3::ZERO;
    let mut index = 0;
    for i in 0..steps {
        let w = CIE_MIN + (i as f64 / (steps - 1) as f64) * (CIE_MAX - CIE_MIN);
        if w < first || w > last {
            continue;
        }
        while index + 2 < samples.len() && samples[index + 1].0 <= w {
            index += 1;
        }
        let value = if samples.len() == 1 {
            samples[0].1
        } else {
            let ((w0, v0), (w1, v1)) = (samples[index], samples[index + 1]);
            if w1 > w0 {
                ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1)
            } else {
                v0
            }
        };
        let weight = if kind == SpectrumKind::Reflectance {
            cie_d65(w)
        } else {
            1.0
        };
        xyz += cie1931_xyz(w) * (value * CIE_Y_NORMALIZATION * weight);
    }
    xyz *= (CIE_MAX - CIE_MIN) / steps as f64;
    let rgb = xyz_to_srgb(xyz);
    match kind {
        SpectrumKind::Reflectance => rgb.clamp(DVec3::ZERO, DVec3::ONE),
        SpectrumKind::Emission | SpectrumKind::Unbounded => rgb.max(DVec3::ZERO),
    }
}

/// A constant spectrum of `value` as linear sRGB. Mitsuba's RGB variants give a constant
/// *emission* spectrum the sRGB colour of equal-energy light (`value` × xyz_to_srgb(1, 1, 1));
/// any other constant stays grey.
pub fn constant_to_rgb(value: f64, kind: SpectrumKind) -> DVec3 {
    match kind {
        SpectrumKind::Emission => xyz_to_srgb(DVec3::ONE) * value,
        SpectrumKind::Reflectance | SpectrumKind::Unbounded => DVec3::splat(value),
    }
}

/// Spectral radiance of a blackbody at `kelvin` (Planck's law, W / (m² sr nm)) at wavelength
/// `nm`.
pub fn planck(nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = nm * 1e-9;
    let v = (2.0 * H * C * C) / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp_m1()));
    v * 1e-9
}

/// A blackbody's emitted radiance at `kelvin` as linear sRGB, as Mitsuba's `blackbody`
/// spectrum in its RGB variants: Planck's law sampled over 360–830 nm and converted as an
/// emission spectrum.
pub fn blackbody_to_rgb(kelvin: f64) -> DVec3 {
    let samples: Vec<(f64, f64)> = (0..=((CIE_MAX - CIE_MIN) as usize))
        .map(|i| {
            let w = CIE_MIN + i as f64;
            (w, planck(w, kelvin))
        })
        .collect();
    sampled_to_rgb(&samples, SpectrumKind::Emission)
}

/// Parses a spectral data file: one "wavelength value" pair per line, `#` comments.
pub fn parse_spd(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut it = line.split_ascii_whitespace();
        let pair = (it.next(), it.next(), it.next());
        let (Some(w), Some(v), None) = pair else {
            return Err(format!(
                "line {}: expected 'wavelength value', found '{}'",
                i + 1,
                crate::xml::truncate(line)
            ));
        };
        let (w, v) = match (w.parse::<f64>(), v.parse::<f64>()) {
            (Ok(w), Ok(v)) if w.is_finite() && v.is_finite() => (w, v),
            _ => {
                return Err(format!(
                    "line {}: '{}' is not a pair of numbers",
                    i + 1,
                    crate::xml::truncate(line)
                ))
            }
        };
        if out.last().is_some_and(|&(p, _): &(f64, f64)| w <= p) {
            return Err(format!(
                "line {}: wavelengths must increase ({w} after {})",
                i + 1,
                out.last().map_or(0.0, |p: &(f64, f64)| p.0)
            ));
        }
        out.push((w, v));
    }
    if out.is_empty() {
        return Err("no wavelength-value pairs".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_spectra_have_unit_luminance_and_white_reflectance() {
        // ∫ȳ over the table is the normalisation constant (trapezoid rule at 5 nm).
        let y: f64 = (0..SAMPLES - 1)
            .map(|i| 2.5 * (CIE_Y[i] + CIE_Y[i + 1]))
            .sum();
        assert!((y * CIE_Y_NORMALIZATION - 1.0).abs() < 2e-3, "{y}");
        // A flat reflectance of 1 is white (D65 weighting), to the Riemann sum's accuracy.
        let white = sampled_to_rgb(&[(360.0, 1.0), (830.0, 1.0)], SpectrumKind::Reflectance);
        assert!((white - DVec3::ONE).abs().max_element() < 5e-3, "{white}");
        // A flat emission is equal-energy light: xyz (1, 1, 1).
        let e = sampled_to_rgb(&[(360.0, 1.0), (830.0, 1.0)], SpectrumKind::Emission);
        let xyz = srgb_to_xyz(e);
        assert!((xyz - DVec3::ONE).abs().max_element() < 5e-3, "{xyz}");
        assert!(
            (constant_to_rgb(2.0, SpectrumKind::Emission) - 2.0 * xyz_to_srgb(DVec3::ONE)).length()
                < 1e-12
        );
        // The matrices are inverses.
        let v = DVec3::new(0.3, 0.5, 0.9);
        assert!((xyz_to_srgb(srgb_to_xyz(v)) - v).length() < 1e-5);
    }

    #[test]
    fn a_blackbody_near_6504_kelvin_is_nearly_neutral() {
        let bb = blackbody_to_rgb(6504.0);
        assert!(bb.min_element() > 0.0);
        assert!((bb / bb.y - DVec3::ONE).abs().max_element() < 0.1, "{bb}");
        let flat = sampled_to_rgb(&[(400.0, 0.5), (700.0, 0.5)], SpectrumKind::Unbounded);
        assert!(flat.min_element() > 0.0);
    }

    #[test]
    fn spd_files_parse_with_located_errors() {
        let s = parse_spd("# comment\n400 1.5\n500 2 # trailing\n\n").unwrap();
        assert_eq!(s, vec![(400.0, 1.5), (500.0, 2.0)]);
        assert!(parse_spd("400 1\n300 2").unwrap_err().contains("line 2"));
        assert!(parse_spd("400 x").unwrap_err().contains("line 1"));
        assert!(parse_spd("400 1 2").unwrap_err().contains("line 1"));
        assert!(parse_spd("").is_err());
    }
}
