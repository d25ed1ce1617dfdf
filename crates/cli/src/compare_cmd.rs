//! `pathlab compare`: the arguments and the table of [`pathlab_lab::compare`] (one scene with
//! several strategies, side by side, with the numbers that say which converges fastest).

use anyhow::{bail, Context, Result};
use clap::Args;
use pathlab_lab::compare::{compare, rows_json, rows_table, strategy, write_side_by_side};
use pathlab_lab::images::{depth_text, read_reference};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::render::RenderSettings;
use pathlab_render::scene::Scene;
use serde_json::json;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The scene: a file (.xml Mitsuba 3, .pbrt pbrt-v4, .dae the course's COLLADA, .obj, .ply,
    /// .gltf, .glb) or
    /// a built-in scene's name (cornell-box).
    #[arg(default_value = "cornell-box")]
    pub scene: String,
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
    #[arg(short = 'm', long, default_value = "1", value_parser = crate::render_cmd::parse_depth_arg)]
    pub max_depth: u32,
    /// A reference image (linear EXR of the same size) for RMSE.
    #[arg(long = "ref", value_name = "REF.exr")]
    pub reference: Option<PathBuf>,
    /// Image size (default: the scene's).
    #[arg(short = 'r', long, num_args = 2, value_names = ["W", "H"])]
    pub resolution: Option<Vec<u32>>,
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
    if args.strategies.is_empty() {
        bail!("--strategies: name at least one");
    }
    let strategies = args
        .strategies
        .iter()
        .map(|s| {
            let name = s.trim().to_string();
            let integrator = strategy(&name, args.max_depth).context("--strategies")?;
            Ok((name, integrator))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut desc = pathlab_scene::load(&args.scene)?;
    pathlab_lab::render::apply_resolution(&mut desc, crate::image_size(&args.resolution))?;
    let [w, h] = desc.resolution;
    let reference = args
        .reference
        .as_deref()
        .map(|p| read_reference(p, desc.resolution))
        .transpose()?;
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let settings = RenderSettings::new(args.spp, args.seed, args.sampler);
    let rows = compare(&scene, &strategies, &settings, reference.as_deref());
    if let (Some(r), Some(p), Some(best)) = (
        &reference,
        &args.reference,
        rows.iter().min_by(|a, b| a.variance.total_cmp(&b.variance)),
    ) {
        // Direct-lighting strategies stop at the first bounce; path strategies at -m.
        let path = args.strategies.iter().any(|s| s.trim().starts_with("path"));
        let depth = depth_text(if path { args.max_depth } else { 1 });
        if let Some(w) = pathlab_lab::images::reference_mismatch(&best.film, r, p, &depth) {
            eprintln!("warning: {w}");
        }
    }
    write_side_by_side(&rows, &args.output)?;
    if args.json {
        let out = json!({
            "scene": args.scene,
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
        args.scene,
        args.spp,
        args.sampler.name()
    );
    println!("{}", rows_table(&rows, args.spp));
    println!("  side-by-side image written to {}", args.output.display());
    Ok(())
}
