//! `pathlab convert` and `pathlab diff`: the images pathlab writes, re-encoded and compared.

use crate::render_cmd::ToneMapName;
use anyhow::{bail, Result};
use clap::Args;
use pathlab_lab::images::{diff_files, FileDifference};
use pathlab_render::image_io::{read_rgb, write_exr, write_png_with};
use serde_json::json;
use std::path::{Path, PathBuf};

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
    #[arg(long, value_enum, default_value_t = ToneMapName::Srgb)]
    pub tonemap: ToneMapName,
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

/// What `--output` may end in.
fn check_extension(path: &Path, allowed: &[&str]) -> Result<String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        bail!(
            "{}: the output must end in .{}",
            path.display(),
            allowed.join(" or .")
        );
    }
    Ok(ext)
}

/// Runs `pathlab convert`.
pub fn run_convert(args: &ConvertArgs) -> Result<()> {
    if !args.exposure.is_finite() {
        bail!(
            "--exposure {}: must be a finite number of stops",
            args.exposure
        );
    }
    let ext = check_extension(&args.output, &["png", "exr"])?;
    let (w, h, px) = read_rgb(&args.input, true)?;
    if ext == "exr" {
        write_exr(&args.output, w, h, &px, &[])?;
    } else {
        write_png_with(&args.output, w, h, &px, args.exposure, args.tonemap.into())?;
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
        check_extension(o, &["png", "exr"])?;
    }
    let FileDifference {
        resolution: [wa, ha],
        difference: d,
        heat_top,
    } = diff_files(&args.a, &args.b, args.output.as_deref())?;
    let (e, rel, largest, ma, mb) = (d.rmse, d.relative_mse, d.max_abs, d.mean_a, d.mean_b);
    if let Some(top) = heat_top {
        eprintln!(
            "difference image: black 0 to white {top:.4} (the 99th percentile of |A - B|, luminance)"
        );
    }
    if args.json {
        let out = json!({
            "a": args.a,
            "b": args.b,
            "resolution": [wa, ha],
            "rmse": e,
            "relative_mse": rel,
            "max_abs_difference": largest,
            "mean_a": [ma.x, ma.y, ma.z],
            "mean_b": [mb.x, mb.y, mb.z],
            "output": args.output,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{wa}x{ha}: RMSE {e:.6}, relative MSE {rel:.6}, largest difference {largest:.6}; mean {:.5} vs {:.5}{}",
            ma.element_sum() / 3.0,
            mb.element_sum() / 3.0,
            args.output
                .as_ref()
                .map_or(String::new(), |o| format!("; wrote {}", o.display()))
        );
    }
    Ok(())
}
