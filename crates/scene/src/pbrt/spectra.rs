//! pbrt-v4's spectra as RGB: `rgb` values, `blackbody` temperatures, named spectra (glasses,
//! metals, standard illuminants), (wavelength, value) lists and `.spd` files.
//!
//! `rgb` values are taken as they are (pbrt-v4's RGB illuminant spectra render as the same RGB
//! in an sRGB film); `blackbody` and sampled or named emission spectra are scaled to luminance
//! one, as pbrt-v4 normalises a light's spectrum (`scale /= SpectrumToPhotometric`);
//! reflectances and indices of refraction are converted as Mitsuba's RGB variants convert them
//! ([`crate::spectrum`]). Named metals are Mitsuba's RGB tables of the same data.

use super::params::{Param, ParamList};
use super::Builder;
use crate::mitsuba::ior::named_conductor;
use crate::spectrum::{blackbody_to_rgb, is_emission, sampled_to_rgb, xyz_to_srgb, SpectrumKind};
use crate::Error;
use glam::DVec3;
use pathlab_render::color::luminance_f64 as luminance;
use pathlab_render::desc::Rgb;

/// pbrt-v4's named glasses: their index at the sodium d line (587.6 nm).
const GLASSES: &[(&str, f32)] = &[
    ("glass-BK7", 1.5168),
    ("glass-BAF10", 1.6700),
    ("glass-FK51A", 1.4866),
    ("glass-LASF9", 1.8503),
    ("glass-F5", 1.6034),
    ("glass-F10", 1.6120),
    ("glass-F11", 1.6210),
    ("glass-SF5", 1.6727),
    ("glass-SF10", 1.7283),
    ("glass-SF11", 1.7847),
];

/// What a spectrum parameter stands for.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Use {
    /// A light's emission: spectra normalised to luminance one.
    Illuminant,
    /// A reflectance in [0, 1].
    Albedo,
    /// η or k.
    Unbounded,
}

impl Builder {
    /// A spectrum-valued parameter as RGB (`None` when absent).
    pub(crate) fn spectrum(
        &mut self,
        params: &ParamList,
        name: &str,
        usage: Use,
    ) -> Result<Option<Rgb>, Error> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.spectrum_of(p, usage).map(Some)
    }

    fn spectrum_of(&mut self, p: &Param, usage: Use) -> Result<Rgb, Error> {
        let decl = format!("\"{} {}\" (line {})", p.ty, p.name, p.line);
        let rgb = match (p.ty.as_str(), p.numbers(), p.strings()) {
            ("rgb" | "color", Some(v), _) => {
                if v.len() != 3 {
                    return Err(
                        self.error(format!("{decl}: expected 3 numbers, found {}", v.len()))
                    );
                }
                DVec3::new(v[0], v[1], v[2])
            }
            ("blackbody", Some(v), _) => {
                let &[t] = v else {
                    return Err(self.error(format!(
                        "{decl}: expected one temperature, found {} numbers",
                        v.len()
                    )));
                };
                if t <= 0.0 {
                    return Err(self.error(format!("{decl}: a temperature in kelvin > 0")));
                }
                let c = blackbody_to_rgb(t);
                c / luminance(c).max(f64::MIN_POSITIVE)
            }
            ("spectrum", Some(v), _) => {
                if v.len() < 2 || v.len() % 2 != 0 {
                    return Err(self.error(format!(
                        "{decl}: expected wavelength and value pairs, found {} numbers",
                        v.len()
                    )));
                }
                let pairs: Vec<(f64, f64)> = v.chunks(2).map(|c| (c[0], c[1])).collect();
                if let Some(&(nm, value)) = pairs
                    .iter()
                    .find(|(_, value)| *value < 0.0 || value.is_nan())
                {
                    if usage == Use::Illuminant {
                        return Err(self.error(format!(
                            "{decl}: a light's emission must be >= 0 at every wavelength, got {value} at {nm} nm"
                        )));
                    }
                }
                sampled_spectrum(&pairs, usage)
                    .ok_or_else(|| self.error(format!("{decl}: wavelengths must increase")))?
            }
            ("spectrum", _, Some(names)) => {
                let [name] = names else {
                    return Err(self.error(format!(
                        "{decl}: expected one spectrum name, found {}",
                        names.len()
                    )));
                };
                match self.named_spectrum(name, &decl) {
                    Ok(c) => c,
                    // Not a name pathlab knows: pbrt-v4 reads it as a file of wavelength and
                    // value pairs; a name that looks like no file stays an error.
                    Err(e) if !(name.contains('.') || name.contains('/')) => return Err(e),
                    Err(_) => self.spectrum_file(name, usage, &decl),
                }
            }
            (ty, _, _) => {
                return Err(self.error(format!("{decl}: a '{ty}' where a spectrum was expected")))
            }
        };
        let rgb = rgb.as_vec3();
        if usage == Use::Illuminant && !is_emission(rgb) {
            return Err(self.error(format!(
                "{decl}: a light's emission must be >= 0 in every channel, got {rgb}"
            )));
        }
        Ok(rgb)
    }

    /// The spectrum in file `name` (relative to the scene file): numbers separated by
    /// whitespace or commas, `#` starting a comment, read as wavelength (nm) and value pairs,
    /// as pbrt-v4 reads `.spd` files. A file that cannot be read is one warning naming it,
    /// and a neutral value stands in: white light, grey 0.5 albedo, or 1.
    fn spectrum_file(&mut self, name: &str, usage: Use, decl: &str) -> DVec3 {
        let path = self.resolve(name);
        let read = std::fs::read_to_string(&path)
            .map_err(|e| e.to_string())
            .and_then(|text| parse_spectrum_file(&text))
            .and_then(|pairs| {
                sampled_spectrum(&pairs, usage).ok_or_else(|| "wavelengths must increase".into())
            });
        read.unwrap_or_else(|why| {
            let (value, what) = match usage {
                Use::Illuminant => (DVec3::ONE, "white light"),
                Use::Albedo => (DVec3::splat(0.5), "grey 0.5"),
                Use::Unbounded => (DVec3::ONE, "1"),
            };
            self.warn(format!(
                "{decl}: cannot read the spectrum file {}: {why}; {what} is used",
                path.display()
            ));
            value
        })
    }

    /// pbrt-v4's named spectra that pathlab knows.
    fn named_spectrum(&mut self, name: &str, decl: &str) -> Result<DVec3, Error> {
        if let Some(&(_, eta)) = GLASSES.iter().find(|(n, _)| *n == name) {
            return Ok(DVec3::splat(eta as f64));
        }
        if let Some(metal) = name.strip_prefix("metal-") {
            let (element, part) = metal
                .rsplit_once('-')
                .ok_or_else(|| self.error(format!("{decl}: unknown spectrum \"{name}\"")))?;
            if let Some((eta, k)) = named_conductor(element) {
                return Ok(match part {
                    "eta" => DVec3::from(eta.map(f64::from)),
                    "k" => DVec3::from(k.map(f64::from)),
                    _ => return Err(self.error(format!("{decl}: unknown spectrum \"{name}\""))),
                });
            }
        }
        match name {
            "stdillum-D65" => Ok(DVec3::ONE),
            "stdillum-A" => {
                let c = blackbody_to_rgb(2856.0);
                Ok(c / luminance(c))
            }
            "stdillum-D50" => {
                let c = xyz_to_srgb(DVec3::new(0.9642, 1.0, 0.8251));
                Ok(c / luminance(c))
            }
            n if n.starts_with("stdillum-") || n.starts_with("illum-") => {
                self.warn(format!("{decl}: the spectrum \"{n}\" is not tabulated; white light of the same luminance is used"));
                Ok(DVec3::ONE)
            }
            _ => Err(self.error(format!(
                "{decl}: unknown spectrum \"{name}\" (pathlab knows glass-*, metal-*-eta/-k of Mitsuba's metals, stdillum-D65/A/D50)"
            ))),
        }
    }
}

/// RGB of a spectrum given as (wavelength in nm, value) pairs, as `usage` reads it (an
/// illuminant normalised to luminance one, as pbrt-v4 normalises its lights' spectra); `None`
/// where the wavelengths do not increase.
fn sampled_spectrum(pairs: &[(f64, f64)], usage: Use) -> Option<DVec3> {
    if pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
        return None;
    }
    let kind = match usage {
        Use::Illuminant => SpectrumKind::Emission,
        Use::Albedo => SpectrumKind::Reflectance,
        Use::Unbounded => SpectrumKind::Unbounded,
    };
    let c = sampled_to_rgb(pairs, kind);
    Some(if usage == Use::Illuminant {
        c / luminance(c).max(f64::MIN_POSITIVE)
    } else {
        c
    })
}

/// The (wavelength, value) pairs of a spectrum file's text.
fn parse_spectrum_file(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut numbers = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split(|c: char| c.is_whitespace() || c == ',') {
            if token.is_empty() {
                continue;
            }
            let x: f64 = token
                .parse()
                .map_err(|_| format!("line {}: '{token}' is not a number", i + 1))?;
            if !x.is_finite() {
                return Err(format!("line {}: '{token}' is not finite", i + 1));
            }
            numbers.push(x);
        }
    }
    if numbers.len() < 2 || numbers.len() % 2 != 0 {
        return Err(format!(
            "expected wavelength and value pairs, found {} numbers",
            numbers.len()
        ));
    }
    Ok(numbers.chunks(2).map(|c| (c[0], c[1])).collect())
}
