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
        Encoding::FAST_LOSSLESS,
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
        message: e.to_string(),
    })?;
    let (w, h, px) = image.layer_data.channel_data.pixels;
    Ok((w as u32, h as u32, px))
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

/// Writes `rgb` as an 8-bit sRGB PNG after scaling by 2^`exposure` and clamping to [0, 1].
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[Rgb],
    exposure: f32,
) -> std::result::Result<(), ImageError> {
    let scale = exposure.exp2();
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|c| c.to_array())
        .map(|v| {
            let v = if v.is_finite() {
                (v * scale).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (srgb_encode(v) * 255.0 + 0.5) as u8
        })
        .collect();
    image::save_buffer(path, &bytes, width, height, image::ExtendedColorType::Rgb8).map_err(|e| {
        ImageError::Png {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}
