//! `pathlab convert` and `pathlab diff`: the images pathlab writes, re-encoded and compared.

use crate::flags::within;
use anyhow::Result;
use clap::Args;
use pathlab_lab::images::diff_files;
use pathlab_lab::outputs::{image_format, OutputFormat};
use pathlab_render::image_io::{read_rgb, write_exr, write_png_with, ToneMap};
use pathlab_render::limits;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab convert`.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// The image to read (.exr, .hdr linear; .png, .jpg sRGB).
    pub input: PathBuf,
    /// The image to write: .png (sRGB after --exposure) or .exr (linear).
    pub output: PathBuf,
    /// Exposure in stops applied before PNG encoding.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// PNG encoding: srgb, or cs184 (the course's: times √2, half a stop up, then gamma 2.2).
    #[arg(long, default_value = "srgb")]
    pub tonemap: ToneMap,
}

/// Raw command-line arguments of `pathlab diff`.
#[derive(Args, Debug)]
pub struct DiffArgs {
    /// The image to judge.
    pub a: PathBuf,
    /// The image to compare it with (the reference for the relative error).
    pub b: PathBuf,
    /// Write the difference: .exr holds A - B per channel, .png a heat map of |A - B|
    /// (luminance) from black to white at the 99th percentile.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Print the numbers as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab convert`.
pub fn run_convert(args: &ConvertArgs) -> Result<()> {
    within("--exposure", Some(args.exposure), limits::exposure)?;
    let format = image_format(&args.output)?;
    let (w, h, px) = read_rgb(&args.input, true)?;
    if format == OutputFormat::Exr {
        write_exr(&args.output, w, h, &px, &[])?;
    } else {
        write_png_with(&args.output, w, h, &px, args.exposure, args.tonemap)?;
    }
    eprintln!(
        "{}: {w}x{h}; wrote {}",
        args.input.display(),
        args.output.display()
    );
    Ok(())
}

/// Runs `pathlab diff`.
pub fn run_diff(args: &DiffArgs) -> Result<()> {
    if let Some(o) = &args.output {
        image_format(o)?;
    }
    let diff = diff_files(&args.a, &args.b, args.output.as_deref())?;
    if let Some(top) = diff.heat_top {
        eprintln!(
            "difference image: black 0 to white {top:.4} (the 99th percentile of |A - B|, luminance)"
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&diff.json())?);
    } else {
        println!("{}", diff.text());
    }
    Ok(())
}
