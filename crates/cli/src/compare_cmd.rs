//! `pathlab compare`: the arguments and the table of [`pathlab_lab::compare`] (one scene with
//! several strategies, side by side, with the numbers that say which converges fastest).

use crate::flags::{self, SceneArgs};
use anyhow::{bail, Context, Result};
use clap::Args;
use pathlab_lab::compare::{
    compare, reference_warning, rows_json, rows_table, strategies, write_side_by_side,
};
use pathlab_lab::images::read_reference;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::render::RenderSettings;
use pathlab_render::scene::Scene;
use serde_json::json;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Strategies to compare, comma-separated: hemisphere, cosine, light, mis (direct lighting)
    /// and path, path-bsdf, path-light (path tracing at --max-depth with MIS, BSDF sampling
    /// only, light sampling only).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "hemisphere,cosine,light,mis"
    )]
    pub strategies: Vec<String>,
    /// Samples per pixel for every strategy.
    #[arg(short = 's', long, default_value_t = 16)]
    pub spp: u32,
    /// Largest bounce for the path strategy.
    #[arg(short = 'm', long, default_value = "1", value_parser = flags::max_depth_arg)]
    pub max_depth: u32,
    /// A reference image (linear EXR of the same size) for RMSE.
    #[arg(long = "ref", value_name = "REF.exr")]
    pub reference: Option<PathBuf>,
    /// Sampler: independent (the default here, so that variances are exact), stratified, sobol.
    #[arg(long, default_value = "independent")]
    pub sampler: SamplerKind,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The side-by-side image (PNG).
    #[arg(short = 'o', long, default_value = "compare.png")]
    pub output: PathBuf,
    /// Print the table as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    let strategies = strategies(&args.strategies, args.max_depth).context("--strategies")?;
    let desc = args.scene.load()?;
    let [w, h] = desc.resolution;
    let reference = args
        .reference
        .as_deref()
        .map(|p| read_reference(p, desc.resolution))
        .transpose()?;
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let settings = RenderSettings::new(args.spp, args.seed, args.sampler);
    let rows = compare(&scene, &strategies, &settings, reference.as_deref());
    if let (Some(r), Some(p)) = (&reference, &args.reference) {
        if let Some(w) = reference_warning(&rows, r, p, args.max_depth) {
            eprintln!("warning: {w}");
        }
    }
    write_side_by_side(&rows, &args.output)?;
    if args.json {
        let out = json!({
            "scene": args.scene.name,
            "spp": args.spp,
            "sampler": args.sampler.name(),
            "image": args.output,
            "strategies": rows_json(&rows, args.spp),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "{} at {w}x{h}, {} spp, {} sampler",
        args.scene.name,
        args.spp,
        args.sampler.name()
    );
    println!("{}", rows_table(&rows, args.spp));
    println!("  side-by-side image written to {}", args.output.display());
    Ok(())
}
