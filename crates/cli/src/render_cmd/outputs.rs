//! Where a render goes: output paths checked before rendering, and the film written as EXR
//! (with AOV layers), PNG (with AOV files beside it), the film's exact state, the adaptive
//! rate image and the BVH view's heat map.

use super::args::{Aov, RenderArgs, ToneMapName};
use anyhow::{bail, Context, Result};
use pathlab_render::film::Film;
use pathlab_render::film_file::FilmHeader;
use pathlab_render::film_image::{value_range, write_exr_layers, write_heat_map};
use pathlab_render::image_io::{write_exr, write_png_with, ToneMap};
use std::path::{Path, PathBuf};

/// What an output file holds, by its extension.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum OutputFormat {
    /// A linear EXR.
    Exr,
    /// An 8-bit sRGB (or cs184) PNG.
    Png,
    /// The film's exact state (`pathlab_render::film_file`).
    Film,
}

/// The format a path's extension names.
pub(super) fn output_format(path: &Path) -> Result<OutputFormat> {
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

/// An output path that can be written: its folder exists and a file can be made there
/// (checked before rendering, so that no render is lost to a typo).
pub(super) fn check_writable(path: &Path) -> Result<()> {
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
        OutputFormat::Film => pathlab_render::film_file::write(path, header, film)?,
        OutputFormat::Png => {
            write_png_with(path, w, h, &film.mean_image(), exposure, ToneMap::Srgb)?
        }
        OutputFormat::Exr => write_exr_layers(film, path, true, true)?,
    }
    Ok(())
}

/// Writes `film` to one output (a film file is written by the caller, which has the header).
fn write_outputs(
    film: &Film,
    output: &Path,
    format: OutputFormat,
    args: &RenderArgs,
) -> Result<()> {
    let (w, h) = (film.width(), film.height());
    let mean = film.mean_image();
    let variance = args
        .aov
        .contains(&Aov::Variance)
        .then(|| film.variance_image());
    let samples = args
        .aov
        .contains(&Aov::Samples)
        .then(|| film.sample_counts());
    match format {
        // Written by the caller, which has the render's header.
        OutputFormat::Film => {}
        OutputFormat::Exr => write_exr_layers(film, output, variance.is_some(), samples.is_some())?,
        OutputFormat::Png => {
            let tone = match args.tonemap {
                ToneMapName::Srgb => ToneMap::Srgb,
                ToneMapName::Cs184 => ToneMap::Cs184,
            };
            write_png_with(output, w, h, &mean, args.exposure, tone)?;
            let stem = output.with_extension("");
            if let Some(v) = &variance {
                write_exr(
                    &PathBuf::from(format!("{}_variance.exr", stem.display())),
                    w,
                    h,
                    v,
                    &[],
                )?;
            }
            if let Some(s) = &samples {
                let grey: Vec<glam::Vec3> = s.iter().map(|&n| glam::Vec3::splat(n)).collect();
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

/// The outputs `-o` names (default: the scene's name as PNG), each checked writable, and the
/// checkpoint's.
pub(super) fn checked_outputs(args: &RenderArgs) -> Result<(Vec<PathBuf>, Vec<OutputFormat>)> {
    let outputs = if args.output.is_empty() {
        let stem = Path::new(&args.scene)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("render");
        vec![PathBuf::from(format!("{stem}.png"))]
    } else {
        args.output.clone()
    };
    let formats = outputs
        .iter()
        .map(|o| output_format(o))
        .collect::<Result<Vec<_>>>()?;
    for o in outputs.iter().chain(&args.checkpoint) {
        check_writable(o)?;
    }
    if args.shard.is_some() && !formats.contains(&OutputFormat::Film) {
        bail!("--shard: write the part as a film (-o PART.plf) so that `pathlab merge` can add the parts exactly");
    }
    Ok((outputs, formats))
}

/// What [`write_all`] wrote besides the outputs named.
pub(super) struct Written {
    /// The BVH view's range of node counts (its PNG's heat map runs over it).
    pub heat_range: Option<(f32, f32)>,
    /// An adaptive render's samples-per-pixel heat map, `NAME_rate.png`.
    pub rate_image: Option<PathBuf>,
}

/// Writes every output; the BVH view's PNG is a heat map of the counts (scaled to their
/// range), an adaptive render's sample counts go to `NAME_rate.png`.
pub(super) fn write_all(
    film: &Film,
    outputs: &[PathBuf],
    formats: &[OutputFormat],
    header: &FilmHeader,
    args: &RenderArgs,
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
            _ if format == OutputFormat::Film => {
                pathlab_render::film_file::write(path, header, film)?
            }
            _ => write_outputs(film, path, format, args)?,
        }
    }
    let rate = match adaptive_cap {
        Some(cap) => {
            let stem = outputs[0].with_extension("");
            let rate = PathBuf::from(format!("{}_rate.png", stem.display()));
            write_heat_map(&rate, w, h, &film.sample_counts(), cap as f32)?;
            Some(rate)
        }
        None => None,
    };
    Ok(Written {
        heat_range,
        rate_image: rate,
    })
}
