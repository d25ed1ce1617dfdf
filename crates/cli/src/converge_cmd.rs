//! `pathlab converge`: the arguments and the report of [`pathlab_lab::converge`] (how the error
//! against a reference falls with samples and with time, for independent and Sobol sampling and
//! for uniform and error-driven sample allocation).

use crate::flags::{self, SceneArgs};
use anyhow::{bail, Context, Result};
use clap::Args;
use pathlab_lab::images::{depth_text, read_reference};
use pathlab_lab::plot;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::scene::Scene;
use serde_json::json;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab converge`.
#[derive(Args, Debug)]
pub struct ConvergeArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The reference image: a linear EXR of the scene at the render's resolution.
    #[arg(long = "ref", value_name = "REF.exr")]
    pub reference: PathBuf,
    /// Largest bounce (default 1: direct lighting).
    #[arg(short = 'm', long, default_value = "1", value_parser = flags::max_depth_arg)]
    pub max_depth: u32,
    /// Largest samples per pixel (powers of two from 1 up to this).
    #[arg(long, default_value_t = 256)]
    pub max_spp: u32,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The plot (.png or .svg).
    #[arg(short = 'o', long, default_value = "converge.png")]
    pub output: PathBuf,
    /// Print the data as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab converge`.
pub fn run(args: &ConvergeArgs) -> Result<()> {
    if !(1..=65536).contains(&args.max_spp) {
        bail!(
            "--max-spp must be between 1 and 65536, got {}",
            args.max_spp
        );
    }
    let format = plot::Format::from_path(&args.output)?;
    let desc = args.scene.load()?;
    let reference = read_reference(&args.reference, desc.resolution)?;
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let integrator = IntegratorKind::Path(PathIntegrator {
        max_depth: args.max_depth,
        ..Default::default()
    });
    let study =
        pathlab_lab::converge::converge(&scene, &integrator, &reference, args.max_spp, args.seed);
    let depth = depth_text(args.max_depth);
    if let Some(w) = pathlab_lab::images::reference_mismatch(
        &study.top_independent,
        &reference,
        &args.reference,
        &depth,
    ) {
        eprintln!("warning: {w}");
    }
    let (scene, depth) = (&args.scene.name, args.max_depth);
    study.write_plot(&args.output, format, scene, depth, &args.reference)?;
    if args.json {
        let out = json!({
            "scene": args.scene.name,
            "reference": args.reference,
            "plot": args.output,
            "curves": study.curves_json(),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("{} against {}", args.scene.name, args.reference.display());
    println!("{}", study.curves_text());
    println!("  plot written to {}", args.output.display());
    Ok(())
}
