//! Where a render goes: output paths checked before rendering, and the film written as EXR
//! (with AOV layers), PNG (with AOV files beside it), the film's exact state, the adaptive
//! rate image and the BVH view's heat map.

use anyhow::{bail, Context, Result};
use pathlab_render::film::Film;
use pathlab_render::film_file::{self, FilmHeader};
use pathlab_render::film_image::{value_range, write_exr_layers, write_heat_map};
use pathlab_render::image_io::{write_exr, write_png_with, ToneMap};
use std::path::{Path, PathBuf};

/// What an output file holds, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// A linear EXR.
    Exr,
    /// An 8-bit sRGB (or cs184) PNG.
    Png,
    /// The film's exact state (`pathlab_render::film_file`).
    Film,
}

/// The format a path's extension names.
pub fn output_format(path: &Path) -> Result<OutputFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("exr") => Ok(OutputFormat::Exr),
        Some("png") => Ok(OutputFormat::Png),
        Some("plf") => Ok(OutputFormat::Film),
        _ => bail!(
            "{}: the output must end in .exr or .png (or .plf for the film's exact state)",
            path.display()
        ),
    }
}

/// The format of an image path that `convert` and `diff` write: .exr or .png (a film is not an
/// image).
pub fn image_format(path: &Path) -> Result<OutputFormat> {
    match output_format(path) {
        Ok(f) if f != OutputFormat::Film => Ok(f),
        _ => bail!("{}: the output must end in .png or .exr", path.display()),
    }
}

/// An output path that can be written: its folder exists and a file can be made there
/// (checked before rendering, so that no render is lost to a typo).
pub fn check_writable(path: &Path) -> Result<()> {
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .with_context(|| format!("{}: cannot write the output", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// Writes `film` (of a whole render described by `header`) as `.exr` (the mean with
/// `variance.R/G/B` and `samples.Y` layers), `.png` (sRGB after `exposure` stops) or `.plf`.
pub fn write_film_image(
    film: &Film,
    path: &Path,
    header: &FilmHeader,
    exposure: f32,
) -> Result<()> {
    let (w, h) = (film.width(), film.height());
    match output_format(path)? {
        OutputFormat::Film => film_file::write(path, header, film)?,
        OutputFormat::Png => {
            write_png_with(path, w, h, &film.mean_image(), exposure, ToneMap::Srgb)?
        }
        OutputFormat::Exr => write_exr_layers(film, path, true, true)?,
    }
    Ok(())
}

/// How a render's images are written.
#[derive(Clone, Copy, Debug)]
pub struct ImageOptions {
    /// Write the per-pixel variance (an EXR layer, or `NAME_variance.exr` beside a PNG).
    pub variance: bool,
    /// Write the per-pixel sample count (an EXR layer, or `NAME_samples.exr`).
    pub samples: bool,
    /// The PNG's tone map.
    pub tonemap: ToneMap,
    /// Exposure in stops before PNG encoding.
    pub exposure: f32,
}

/// Writes `film` to one image output (not a film file: that needs the header).
fn write_image(film: &Film, output: &Path, format: OutputFormat, opts: ImageOptions) -> Result<()> {
    let (w, h) = (film.width(), film.height());
    match format {
        OutputFormat::Film => {}
        OutputFormat::Exr => write_exr_layers(film, output, opts.variance, opts.samples)?,
        OutputFormat::Png => {
            write_png_with(
                output,
                w,
                h,
                &film.mean_image(),
                opts.exposure,
                opts.tonemap,
            )?;
            let stem = output.with_extension("");
            if opts.variance {
                write_exr(
                    &PathBuf::from(format!("{}_variance.exr", stem.display())),
                    w,
                    h,
                    &film.variance_image(),
                    &[],
                )?;
            }
            if opts.samples {
                let grey: Vec<glam::Vec3> = film
                    .sample_counts()
                    .iter()
                    .map(|&n| glam::Vec3::splat(n))
                    .collect();
                write_exr(
                    &PathBuf::from(format!("{}_samples.exr", stem.display())),
                    w,
                    h,
                    &grey,
                    &[],
                )?;
            }
        }
    }
    Ok(())
}

/// What [`write_all`] wrote besides the outputs named.
pub struct Written {
    /// The BVH view's range of node counts (its PNG's heat map runs over it).
    pub heat_range: Option<(f32, f32)>,
    /// An adaptive render's samples-per-pixel heat map, `NAME_rate.png`.
    pub rate_image: Option<PathBuf>,
}

/// Writes every output (`formats` of `outputs`); the BVH view's PNG is a heat map of the
/// counts (scaled to their range), an adaptive render's sample counts (at most
/// `adaptive_cap`) go to `NAME_rate.png` beside the first output.
pub fn write_all(
    film: &Film,
    outputs: &[PathBuf],
    formats: &[OutputFormat],
    header: &FilmHeader,
    opts: ImageOptions,
    bvh_view: bool,
    adaptive_cap: Option<u32>,
) -> Result<Written> {
    let heat_range = bvh_view.then(|| value_range(film));
    let (w, h) = (film.width(), film.height());
    for (path, &format) in outputs.iter().zip(formats) {
        match heat_range {
            Some((_, hi)) if format == OutputFormat::Png => {
                let counts: Vec<f32> = film.mean_image().iter().map(|v| v.x).collect();
                write_heat_map(path, w, h, &counts, hi)?;
            }
            _ if format == OutputFormat::Film => film_file::write(path, header, film)?,
            _ => write_image(film, path, format, opts)?,
        }
    }
    let rate_image = match (adaptive_cap, outputs.first()) {
        (Some(cap), Some(first)) => {
            let stem = first.with_extension("");
            let rate = PathBuf::from(format!("{}_rate.png", stem.display()));
            write_heat_map(&rate, w, h, &film.sample_counts(), cap as f32)?;
            Some(rate)
        }
        _ => None,
    };
    Ok(Written {
        heat_range,
        rate_image,
    })
}
