//! Writing and reading images: linear OpenEXR (exact values, extra layers) and sRGB PNG.

use crate::desc::Rgb;
use exr::prelude::*;
use std::path::Path;
use thiserror::Error;

/// What went wrong reading or writing an image.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ImageError {
    /// The OpenEXR library failed.
    #[error("{path}: {message}")]
    Exr {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// An image could not be decoded.
    #[error("{path}: {message}")]
    Decode {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// The PNG encoder failed.
    #[error("{path}: {message}")]
    Png {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
}

/// A named single-channel image for extra EXR layers (e.g. `samples.Y`).
pub struct ExtraChannel<'a> {
    /// Full channel name, such as `variance.R`.
    pub name: String,
    /// Values, row-major.
    pub values: &'a [f32],
}

/// Writes `rgb` (row-major, row 0 at the top) as a float32 OpenEXR file with channels R, G, B
/// and any `extra` channels.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[Rgb],
    extra: &[ExtraChannel],
) -> std::result::Result<(), ImageError> {
    let err = |e: exr::error::Error| ImageError::Exr {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut channels: Vec<AnyChannel<FlatSamples>> = (0..3)
        .map(|c| {
            let name = ["R", "G", "B"][c];
            AnyChannel::new(name, FlatSamples::F32(rgb.iter().map(|v| v[c]).collect()))
        })
        .collect();
    for e in extra {
        channels.push(AnyChannel::new(
            e.name.as_str(),
            FlatSamples::F32(e.values.to_vec()),
        ));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        // Blocks in increasing order, so that the same image gives the same bytes however
        // the blocks' compression was spread over threads.
        Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        },
        AnyChannels::sort(channels.into()),
    );
    Image::from_layer(layer).write().to_file(path).map_err(err)
}

/// Reads the R, G, B channels of the first layer of an OpenEXR file: (width, height, pixels
/// row-major from the top).
pub fn read_exr_rgb(path: &Path) -> std::result::Result<(u32, u32, Vec<Rgb>), ImageError> {
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            let (w, h) = (resolution.width(), resolution.height());
            (w, h, vec![Rgb::ZERO; w * h])
        },
        |(w, _, px): &mut (usize, usize, Vec<Rgb>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Rgb::new(r, g, b);
        },
    )
    .map_err(|e| ImageError::Exr {
        path: path.display().to_string(),
        message: exr_message(&e),
    })?;
    let (w, h, px) = image.layer_data.channel_data.pixels;
    Ok((w as u32, h as u32, px))
}

/// The OpenEXR reader's error as a sentence: an unreadable file, or what is wrong inside one.
fn exr_message(e: &exr::error::Error) -> String {
    match e {
        exr::error::Error::Io(io) => format!("cannot read the file ({io})"),
        exr::error::Error::NotSupported(what) => {
            format!("an OpenEXR feature pathlab cannot read: {what}")
        }
        exr::error::Error::Invalid(what) => format!("not a valid OpenEXR file ({what})"),
        exr::error::Error::Aborted => "reading the OpenEXR file was aborted".to_string(),
    }
}

/// Image formats [`read_rgb`] decodes, by extension.
const READABLE: [&str; 6] = ["exr", "hdr", "png", "jpg", "jpeg", "bmp"];

/// Reads an image's RGB values: (width, height, pixels row-major from the top). OpenEXR and
/// Radiance HDR are linear already; 8- and 16-bit formats (PNG, JPEG) are sRGB-encoded colour,
/// decoded to linear when `decode_srgb` (otherwise taken as they are, scaled to [0, 1]).
pub fn read_rgb(
    path: &Path,
    decode_srgb: bool,
) -> std::result::Result<(u32, u32, Vec<Rgb>), ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if ext.as_deref() == Some("exr") {
        return read_exr_rgb(path);
    }
    let err = |message: String| ImageError::Decode {
        path: path.display().to_string(),
        message,
    };
    // A file without an extension is identified by its content.
    if ext.as_deref().is_some_and(|e| !READABLE.contains(&e)) {
        return Err(err(format!(
            "not an image format pathlab reads (.{})",
            READABLE.join(", .")
        )));
    }
    let img = image::ImageReader::open(path)
        .map_err(|e| err(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?
        .decode()
        .map_err(|e| err(e.to_string()))?;
    let (w, h) = (img.width(), img.height());
    let linear = !decode_srgb
        || matches!(
            img,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        );
    let px = img.to_rgb32f();
    let decode = |v: f32| if linear { v } else { srgb_decode(v) };
    let pixels = px
        .pixels()
        .map(|p| Rgb::new(decode(p[0]), decode(p[1]), decode(p[2])))
        .collect();
    Ok((w, h, pixels))
}

/// The inverse sRGB transfer function: an encoded value in [0, 1] to linear.
#[inline]
pub fn srgb_decode(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
#[inline]
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// How linear radiance becomes 8-bit PNG values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// Scale by 2^exposure, clamp to [0, 1], sRGB transfer function.
    #[default]
    Srgb,
    /// The CS184 course's images: clamp((√2 · 2^exposure · c)^(1/2.2), 0, 1), i.e. half a
    /// stop up (√2 = 2^0.5) and gamma 2.2: linear values from 1/√2 ≈ 0.71 up are white.
    Cs184,
}

impl ToneMap {
    /// Both tone maps.
    pub const ALL: [ToneMap; 2] = [ToneMap::Srgb, ToneMap::Cs184];

    /// The name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Srgb => "srgb",
            ToneMap::Cs184 => "cs184",
        }
    }

    /// The encoded value in [0, 1] of a linear value, after `scale` (2^exposure).
    #[inline]
    pub fn encode(self, v: f32, scale: f32) -> f32 {
        if !v.is_finite() {
            return 0.0;
        }
        match self {
            ToneMap::Srgb => srgb_encode((v * scale).clamp(0.0, 1.0)),
            ToneMap::Cs184 => (std::f32::consts::SQRT_2 * scale * v)
                .max(0.0)
                .powf(1.0 / 2.2)
                .min(1.0),
        }
    }
}

impl std::str::FromStr for ToneMap {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        pathlab_mc::named::by_name(s, &ToneMap::ALL, ToneMap::name, "tone map")
    }
}

/// Writes 8-bit RGB values (row-major, 3 bytes a pixel) as a PNG.
pub fn write_rgb8(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> std::result::Result<(), ImageError> {
    image::save_buffer(path, bytes, width, height, image::ExtendedColorType::Rgb8).map_err(|e| {
        ImageError::Png {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}

/// 8-bit values (3 bytes a pixel) of linear `rgb` after scaling by 2^`exposure` and the tone
/// map `tone`.
pub fn encode_rgb8(rgb: &[Rgb], exposure: f32, tone: ToneMap) -> Vec<u8> {
    let scale = exposure.exp2();
    rgb.iter()
        .flat_map(|c| c.to_array())
        .map(|v| (tone.encode(v, scale) * 255.0 + 0.5) as u8)
        .collect()
}

/// Writes `rgb` as an 8-bit PNG after scaling by 2^`exposure`, with the sRGB transfer function.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[Rgb],
    exposure: f32,
) -> std::result::Result<(), ImageError> {
    write_png_with(path, width, height, rgb, exposure, ToneMap::Srgb)
}

/// Writes `rgb` as an 8-bit PNG after scaling by 2^`exposure` and the tone map `tone`.
pub fn write_png_with(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[Rgb],
    exposure: f32,
    tone: ToneMap,
) -> std::result::Result<(), ImageError> {
    let bytes = encode_rgb8(rgb, exposure, tone);
    image::save_buffer(path, &bytes, width, height, image::ExtendedColorType::Rgb8).map_err(|e| {
        ImageError::Png {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_maps() {
        // sRGB: linear 0.5 encodes to 0.7354; the curve is continuous at its knee.
        assert!((ToneMap::Srgb.encode(0.5, 1.0) - 0.735_357).abs() < 1e-5);
        assert!((srgb_encode(0.003_130_8) - 12.92 * 0.003_130_8).abs() < 1e-6);
        assert!((srgb_encode(0.003_130_81) - srgb_encode(0.003_130_79)).abs() < 1e-6);
        // The course's: (√2 · 0.5)^(1/2.2).
        let expected = (std::f32::consts::SQRT_2 * 0.5).powf(1.0 / 2.2);
        assert!((ToneMap::Cs184.encode(0.5, 1.0) - expected).abs() < 1e-6);
        assert_eq!(ToneMap::Cs184.encode(10.0, 1.0), 1.0);
        assert_eq!(ToneMap::Srgb.encode(f32::NAN, 1.0), 0.0);
        // One stop of exposure doubles the linear value.
        assert_eq!(
            ToneMap::Srgb.encode(0.25, 2.0),
            ToneMap::Srgb.encode(0.5, 1.0)
        );
    }

    #[test]
    fn exr_round_trip_with_extra_channels() {
        let dir = std::env::temp_dir().join(format!("pathlab-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.exr");
        let rgb: Vec<Rgb> = (0..12)
            .map(|i| Rgb::new(i as f32, 0.5 * i as f32, 1e-3))
            .collect();
        let extra = vec![1.0f32; 12];
        write_exr(
            &path,
            4,
            3,
            &rgb,
            &[ExtraChannel {
                name: "samples.Y".into(),
                values: &extra,
            }],
        )
        .unwrap();
        let (w, h, back) = read_exr_rgb(&path).unwrap();
        assert_eq!((w, h), (4, 3));
        assert_eq!(back, rgb);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn the_same_image_is_written_as_the_same_bytes() {
        // Large enough for many 64 x 64 blocks, compressed on several threads.
        let (w, h) = (300u32, 200u32);
        let rgb: Vec<Rgb> = (0..w * h)
            .map(|i| Rgb::new((i % 7) as f32, (i % 13) as f32 * 0.5, (i / w) as f32))
            .collect();
        let counts: Vec<f32> = (0..w * h).map(|i| i as f32).collect();
        let channel = [ExtraChannel {
            name: "samples.Y".to_string(),
            values: &counts,
        }];
        let dir = std::env::temp_dir().join(format!("pathlab-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bytes: Vec<Vec<u8>> = (0..4)
            .map(|k| {
                let path = dir.join(format!("{k}.exr"));
                write_exr(&path, w, h, &rgb, &channel).unwrap();
                std::fs::read(&path).unwrap()
            })
            .collect();
        assert!(bytes.windows(2).all(|b| b[0] == b[1]));
        let (rw, rh, back) = read_exr_rgb(&dir.join("0.exr")).unwrap();
        assert_eq!((rw, rh), (w, h));
        assert!(back == rgb);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
