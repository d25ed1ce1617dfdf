//! A film written as images: the mean as a linear EXR with per-pixel variance and sample-count
//! layers, and heat maps of per-pixel values (sample counts, BVH nodes) as PNG.

use crate::film::Film;
use crate::image_io::{write_exr, write_rgb8, ExtraChannel, ImageError};
use std::path::Path;

/// The film's mean as a linear EXR, with `variance.R/G/B` (the variance of each pixel's mean)
/// and `samples.Y` (its sample count) layers where asked.
pub fn write_exr_layers(
    film: &Film,
    path: &Path,
    variance: bool,
    samples: bool,
) -> Result<(), ImageError> {
    let variance = variance.then(|| film.variance_image());
    let channels: Vec<Vec<f32>> = variance
        .iter()
        .flat_map(|v| (0..3).map(move |c| v.iter().map(|p| p[c]).collect::<Vec<f32>>()))
        .collect();
    let counts = samples.then(|| film.sample_counts());
    let mut extra: Vec<ExtraChannel> = channels
        .iter()
        .zip(["variance.R", "variance.G", "variance.B"])
        .map(|(values, name)| ExtraChannel {
            name: name.to_string(),
            values,
        })
        .collect();
    if let Some(s) = &counts {
        extra.push(ExtraChannel {
            name: "samples.Y".to_string(),
            values: s,
        });
    }
    write_exr(
        path,
        film.width(),
        film.height(),
        &film.mean_image(),
        &extra,
    )
}

/// `values` (one per pixel of a `width` x `height` image) as a PNG heat map: blue (0) through
/// green to red (`max` and above).
pub fn write_heat_map(
    path: &Path,
    width: u32,
    height: u32,
    values: &[f32],
    max: f32,
) -> Result<(), ImageError> {
    let bytes: Vec<u8> = values
        .iter()
        .flat_map(|&n| heat_colour(n / max.max(f32::MIN_POSITIVE)))
        .collect();
    write_rgb8(path, width, height, &bytes)
}

/// The heat maps' colour of `t` in [0, 1] (clamped): blue through green to red.
pub fn heat_colour(t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let ramp = |c: f32| ((1.5 - (4.0 * t - c).abs()).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    [ramp(3.0), ramp(2.0), ramp(1.0)]
}

/// The smallest and largest of the film's per-pixel means (their first channel: a debug
/// view's value).
pub fn value_range(film: &Film) -> (f32, f32) {
    film.mean_image()
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.x), hi.max(v.x))
        })
}
