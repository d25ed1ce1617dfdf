//! `pathlab render`: render a scene to EXR or PNG.

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::desc::{
    FovAxis, FresnelModel, IntegratorHint, MaterialDesc, Projection, SceneDesc,
};
use pathlab_render::film::Film;
use pathlab_render::image_io::{write_exr, write_png_with, write_rgb8, ExtraChannel, ToneMap};
use pathlab_render::integrator::{
    DebugView, DirectIntegrator, DirectStrategy, IntegratorKind, PathIntegrator, PathLighting,
};
use pathlab_render::progressive::{
    estimated_relative_rmse, render_progressive_from, ProgressiveReport, StopRule,
};
use pathlab_render::render::{render_from, Adaptive, AdaptiveRule, RenderSettings};
use pathlab_render::scene::Scene;
use serde_json::json;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Which integrator renders the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorName {
    /// Path tracing with next-event estimation, MIS and Russian roulette.
    Path,
    /// Direct lighting only, by the strategy chosen with --direct.
    Direct,
    /// Debug view: shading normals.
    Normals,
    /// Debug view: distance to the first surface.
    Depth,
    /// Debug view: BVH nodes visited per camera ray.
    Bvh,
}

/// Adaptive stopping rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RuleName {
    /// Unbiased: a pilot batch from its own stream plans each pixel's count (the course's
    /// precision target), and only the planned samples make the image.
    TwoStage,
    /// The course's relative-precision rule, checked after each batch (biased by optional
    /// stopping).
    Course,
    /// Samples in proportion to each pixel's standard deviation.
    Neyman,
}

/// PNG tone maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ToneMapName {
    /// Exposure, clamp, sRGB transfer function.
    Srgb,
    /// The CS184 course's renderer: clamp((√2 c)^(1/2.2)), √2 being half a stop up.
    Cs184,
}

/// Extra outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Aov {
    /// Variance of each pixel's mean (squared standard error), per channel.
    Variance,
    /// Samples per pixel.
    Samples,
}

/// `--lighting` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightingName {
    /// Light sampling and BSDF sampling with MIS.
    Mis,
    /// BSDF sampling only.
    Bsdf,
    /// Light sampling only.
    Light,
}

/// `--fresnel` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FresnelName {
    /// The exact dielectric Fresnel equations.
    Exact,
    /// Schlick's approximation.
    Schlick,
}

/// Raw command-line arguments of `pathlab render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene: a file (.xml Mitsuba 3, .pbrt pbrt-v4, .dae the course's COLLADA, .obj, .ply,
    /// .gltf, .glb) or
    /// a built-in scene's name (cornell-box).
    #[arg(default_value = "cornell-box")]
    pub scene: String,
    /// Samples per pixel (default: the scene file's, else 64).
    #[arg(short = 's', long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Light samples per surface point (direct lighting: directions or light points per pixel
    /// sample).
    #[arg(short = 'l', long, default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub light_samples: u32,
    /// Largest bounce: 0 = light seen directly, 1 = direct lighting, 2 = one indirect bounce,
    /// ..., inf (or -1, as Mitsuba writes it) = unbounded (with Russian roulette). Default: the
    /// scene file's, else inf.
    #[arg(short = 'm', long, allow_negative_numbers = true)]
    pub max_depth: Option<String>,
    /// First bounce at which Russian roulette may end a path (default: the scene file's, else
    /// 5).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..))]
    pub rr_depth: Option<u32>,
    /// Only the radiance of bounce K (0 = emission seen directly, 1 = direct, ...).
    #[arg(long, value_name = "K", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..))]
    pub only_bounce: Option<u32>,
    /// Worker threads (0: all cores).
    #[arg(short = 't', long, default_value_t = 0, allow_negative_numbers = true, value_parser = threads_arg)]
    pub threads: usize,
    /// Image size in pixels (default: the scene's). The view is scaled to fit, except for the
    /// course's .dae scenes, whose camera keeps the course viewer's pixel scale: a smaller
    /// size shows a centred crop, a larger one more around it (use --scale to resize those).
    #[arg(short = 'r', long, num_args = 2, value_names = ["W", "H"], allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub resolution: Option<Vec<u32>>,
    /// The scene's own view at F times its resolution (any format; the .dae scenes' way to
    /// change their size without cropping).
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub scale: Option<f32>,
    /// Field of view in degrees on the image's smaller axis, in place of the scene camera's.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub fov: Option<f32>,
    /// Adaptive sampling: each pixel takes the samples that bring the 95% interval of its mean
    /// luminance within ± TOL relative (at most --spp), in batches of BATCH; by default planned
    /// from a pilot batch that is not part of the image, so that the image stays unbiased
    /// (see --adaptive-rule). Defaults 32 0.05. Writes the samples-per-pixel heat map to
    /// NAME_rate.png.
    #[arg(short = 'a', long, num_args = 0..=2, value_names = ["BATCH", "TOL"], default_missing_values = ["32", "0.05"])]
    pub adaptive: Option<Vec<String>>,
    /// Thin lens: aperture radius (0: pinhole). Overrides the scene's.
    #[arg(
        short = 'b',
        long,
        value_name = "RADIUS",
        allow_negative_numbers = true
    )]
    pub lens_radius: Option<f32>,
    /// Thin lens: distance to the plane in focus. Overrides the scene's.
    #[arg(
        short = 'd',
        long,
        value_name = "DISTANCE",
        allow_negative_numbers = true
    )]
    pub focal_distance: Option<f32>,
    /// Adaptive rule: two-stage (default; n = (1.96σ/(TOL·μ))² from a pilot batch of its own,
    /// unbiased), course (stop after a batch once 1.96σ/√n ≤ TOL·μ, the course's rule, biased
    /// by optional stopping), or neyman (stop once n ≥ (1.96/TOL)² σ/L̄ with L̄ from a 4-spp
    /// pilot: samples in proportion to σ, which minimises the image's MSE; biased as course).
    /// Only with -a.
    #[arg(long, value_enum)]
    pub adaptive_rule: Option<RuleName>,
    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 (the rest stays black).
    #[arg(long, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"], allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..))]
    pub crop: Option<Vec<u32>>,
    /// Output image: .exr (linear) or .png (sRGB). Repeat for several files from one render
    /// (-o a.exr -o a.png). Default: SCENE.png.
    #[arg(short = 'o', long, visible_short_alias = 'f', value_name = "FILE")]
    pub output: Vec<PathBuf>,
    /// The integrator (default: the one the scene file names, else path).
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorName>,
    /// A scene parameter, NAME=VALUE, for the `$NAME` references of a Mitsuba scene (its
    /// `<default>`s give the others). Repeat for several.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE")]
    pub define: Vec<String>,
    /// How the path tracer finds light at each vertex: mis (light and BSDF sampling combined),
    /// bsdf (BSDF sampling only) or light (light sampling only). Default: mis. Path tracer
    /// only.
    #[arg(long, value_enum)]
    pub lighting: Option<LightingName>,
    /// Light the scene with this environment map (equirectangular .exr, .hdr, .png or .jpg, in
    /// Mitsuba's convention), in place of the scene's own environment.
    #[arg(short = 'e', long, value_name = "FILE")]
    pub envmap: Option<PathBuf>,
    /// Scale of the --envmap radiance.
    #[arg(long, default_value_t = 1.0, value_name = "SCALE")]
    pub envmap_scale: f32,
    /// Fresnel reflectance of smooth glass: exact, or schlick (the course's approximation).
    #[arg(long, value_enum, default_value_t = FresnelName::Exact)]
    pub fresnel: FresnelName,
    /// Direct-lighting strategy for --integrator direct: hemisphere, cosine, light or mis
    /// (default).
    #[arg(long)]
    pub direct: Option<DirectStrategy>,
    /// Where the uniform numbers come from: sobol (Owen-scrambled, padded per dimension),
    /// stratified or independent. Per-pixel variances (--aov variance) are exact estimates only
    /// for independent samples; for the others they overstate the error.
    /// Default: sobol, or independent with --target-error/--time (whose error estimate is
    /// exact only for independent samples).
    #[arg(long)]
    pub sampler: Option<SamplerKind>,
    /// Render in passes until the estimated relative RMSE of the image is at most E, spending
    /// each pass where it lowers the error most (-s then caps the average spp; default 65536).
    #[arg(long, value_name = "E", allow_negative_numbers = true)]
    pub target_error: Option<f64>,
    /// Render in passes for this many seconds, spending each pass where it lowers the error most.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Exposure in stops applied before PNG encoding.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// PNG encoding: srgb (exposure, clamp, the sRGB curve), or cs184 (the course's renderer:
    /// radiance times √2, which is half a stop up, then gamma 2.2 and clamp).
    #[arg(long, value_enum, default_value_t = ToneMapName::Srgb)]
    pub tonemap: ToneMapName,
    /// Extra outputs, comma-separated: variance, samples (EXR channels, or files next to a PNG).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub aov: Vec<Aov>,
    /// Write the film's exact state to FILE (.plf) after passes, at most every
    /// --checkpoint-every seconds, and when the render is stopped: `--resume FILE` goes on
    /// from it to the same image, bit for bit.
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (default 60).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 60.0,
        allow_negative_numbers = true
    )]
    pub checkpoint_every: f64,
    /// Go on from a checkpoint of this render (the same scene, flags and seed) to -s (or, with
    /// --target-error/--time, to the target or for the time; with -a, to each pixel's count).
    #[arg(long, value_name = "FILE")]
    pub resume: Option<PathBuf>,
    /// Render only the I-th (from 0) of N equal ranges of every pixel's samples: a whole-frame
    /// image of spp/N samples per pixel. Write it as a film (-o PART.plf); `pathlab merge`
    /// adds the N parts into the image one render would give, bit for bit.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// No progress bar.
    #[arg(short = 'q', long)]
    pub quiet: bool,
    /// Print run statistics as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// A `--threads` value: a count of worker threads, 0 for all cores.
fn threads_arg(text: &str) -> std::result::Result<usize, String> {
    text.parse::<usize>()
        .map_err(|_| format!("'{text}' is not a number of threads (0 for all cores, 1, 2, ...)"))
}

/// [`parse_max_depth`] as a clap value parser.
pub(crate) fn parse_depth_arg(text: &str) -> std::result::Result<u32, String> {
    parse_max_depth(text).map_err(|e| e.to_string())
}

/// A `--max-depth` value: a number of bounces or `inf` (also `-1`).
pub(crate) fn parse_max_depth(text: &str) -> Result<u32> {
    if text.eq_ignore_ascii_case("inf") || text == "-1" {
        return Ok(u32::MAX);
    }
    text.parse::<u32>().with_context(|| {
        format!("--max-depth {text}: expected a number of bounces (0, 1, 2, ...) or inf")
    })
}

fn parse_adaptive(values: &[String], rule: Option<RuleName>) -> Result<Adaptive> {
    let batch = match values.first() {
        Some(b) => b.parse::<u32>().ok().filter(|&b| b > 0).with_context(|| {
            format!("--adaptive {b}: BATCH must be a positive number of samples")
        })?,
        None => Adaptive::DEFAULT.batch,
    };
    let tolerance = match values.get(1) {
        Some(t) => t
            .parse::<f32>()
            .ok()
            .filter(|t| t.is_finite() && *t > 0.0)
            .with_context(|| {
                format!("--adaptive {batch} {t}: TOL must be a positive number such as 0.05")
            })?,
        None => Adaptive::DEFAULT.tolerance,
    };
    Ok(Adaptive {
        batch,
        tolerance,
        min_samples: 4 * batch,
        rule: match rule {
            Some(RuleName::Course) => AdaptiveRule::Course,
            // The Neyman rule's image luminance comes from its pilot render, later.
            Some(RuleName::Neyman) => AdaptiveRule::Course,
            Some(RuleName::TwoStage) | None => AdaptiveRule::TwoStage,
        },
    })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum OutputFormat {
    Exr,
    Png,
    /// The film's exact state (`pathlab_render::film_file`).
    Film,
}

fn output_format(path: &Path) -> Result<OutputFormat> {
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

/// Applies a `-r W H` override to a scene, checking the size.
pub fn apply_resolution(desc: &mut SceneDesc, resolution: Option<&[u32]>) -> Result<()> {
    if let Some(&[w, h]) = resolution {
        if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
            bail!("--resolution {w} {h}: width and height must be between 1 and 16384");
        }
        desc.resolution = [w, h];
    }
    Ok(())
}

/// Applies `--scale F` (the scene's view at F times its resolution) and `--fov DEG`.
pub fn apply_view(desc: &mut SceneDesc, scale: Option<f32>, fov: Option<f32>) -> Result<()> {
    if let Some(f) = scale {
        if !(f.is_finite() && f > 0.0) {
            bail!("--scale {f}: must be a positive factor such as 0.5 or 2");
        }
        let [w, h] = desc.resolution;
        let size = |n: u32| (n as f64 * f as f64).round();
        let (sw, sh) = (size(w), size(h));
        if !(1.0..=16384.0).contains(&sw) || !(1.0..=16384.0).contains(&sh) {
            bail!("--scale {f}: {w}x{h} would become {sw}x{sh}; width and height must be between 1 and 16384");
        }
        desc.resolution = [sw as u32, sh as u32];
        // A camera whose field of view follows from its resolution keeps its view.
        if let Some(p) = desc.camera.focal_pixels.as_mut() {
            *p *= sw as f32 / w as f32;
        }
    }
    if let Some(deg) = fov {
        if !(deg.is_finite() && deg > 0.0 && deg < 180.0) {
            bail!("--fov {deg}: must be an angle between 0 and 180 degrees");
        }
        if !matches!(desc.camera.projection, Projection::Perspective) {
            bail!("--fov {deg}: the scene's camera is orthographic, which has no field of view");
        }
        desc.camera.fov_degrees = deg;
        desc.camera.fov_axis = FovAxis::Smaller;
        desc.camera.focal_pixels = None;
    }
    Ok(())
}

/// An output path that can be written: its folder exists and a file can be made there
/// (checked before rendering, so that no render is lost to a typo).
fn check_writable(path: &Path) -> Result<()> {
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

/// A count or rate with an SI prefix and three significant digits: 950, 12.3 k, 4.56 M.
pub(crate) fn si_prefixed(v: f64) -> String {
    if !v.is_finite() || v < 0.0 {
        return "-".to_string();
    }
    let (scaled, prefix) = [(1e12, " T"), (1e9, " G"), (1e6, " M"), (1e3, " k")]
        .iter()
        .find(|(p, _)| v >= *p)
        .map_or((v, ""), |&(p, n)| (v / p, n));
    let digits = if scaled >= 100.0 || prefix.is_empty() {
        0
    } else if scaled >= 10.0 {
        1
    } else {
        2
    };
    format!("{scaled:.digits$}{prefix}")
}

/// Flags that contradict each other or a value no image can show: an error, before anything
/// is loaded; flags that the chosen integrator does not read: a warning each (returned).
fn check_flags(args: &RenderArgs, cli_depth: Option<u32>) -> Result<Vec<String>> {
    if !args.exposure.is_finite() {
        bail!(
            "--exposure {}: must be a finite number of stops",
            args.exposure
        );
    }
    if let (Some(k), Some(m)) = (args.only_bounce, cli_depth) {
        if k > m {
            bail!("--only-bounce {k} is beyond --max-depth {m}: the image would be black");
        }
    }
    let mut warnings = Vec::new();
    let mut unused = |flag: &str, applies: &str| {
        warnings.push(format!("{flag} applies to {applies} only; ignored"))
    };
    let integrator = args.integrator;
    let path = matches!(integrator, None | Some(IntegratorName::Path));
    let debug = matches!(
        integrator,
        Some(IntegratorName::Normals | IntegratorName::Depth | IntegratorName::Bvh)
    );
    if args.direct.is_some() && integrator != Some(IntegratorName::Direct) {
        unused("--direct", "--integrator direct");
    }
    if args.lighting.is_some() && !path {
        unused("--lighting", "the path tracer (--integrator path)");
    }
    if args.only_bounce.is_some() && !path {
        unused("--only-bounce", "the path tracer (--integrator path)");
    }
    if debug && args.light_samples > 1 {
        unused("--light-samples", "the path and direct integrators");
    }
    if args.adaptive_rule.is_some() && args.adaptive.is_none() {
        unused("--adaptive-rule", "adaptive sampling (-a)");
    }
    Ok(warnings)
}

/// Runs `pathlab render`.
pub fn run(args: &RenderArgs) -> Result<u8> {
    let signals = crate::farm::Signals::install();
    let cancel: &AtomicBool = &signals.cancel;
    let cli_depth = args.max_depth.as_deref().map(parse_max_depth).transpose()?;
    for w in check_flags(args, cli_depth)? {
        if !args.quiet {
            eprintln!("warning: {w}");
        }
    }
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
    if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
        bail!(
            "--checkpoint-every {}: must be a number of seconds >= 0",
            args.checkpoint_every
        );
    }
    let output = outputs[0].clone();
    let params = args
        .define
        .iter()
        .map(|d| match d.split_once('=') {
            Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.to_string())),
            _ => bail!("-D {d}: expected NAME=VALUE"),
        })
        .collect::<Result<Vec<_>>>()?;
    let mut desc = pathlab_scene::load_with(&args.scene, &params)?;
    if !args.quiet {
        for w in &desc.warnings {
            eprintln!("warning: {w}");
        }
    }
    if let Some(b) = args.lens_radius {
        if !(b.is_finite() && b >= 0.0) {
            bail!("--lens-radius {b}: must be a finite number >= 0");
        }
        desc.camera.lens_radius = b;
    }
    if let Some(d) = args.focal_distance {
        if !(d.is_finite() && d > 0.0) {
            bail!("--focal-distance {d}: must be a positive distance");
        }
        desc.camera.focal_distance = d;
    }
    if let Some(file) = &args.envmap {
        if !(args.envmap_scale.is_finite() && args.envmap_scale >= 0.0) {
            bail!(
                "--envmap-scale {}: must be a number >= 0",
                args.envmap_scale
            );
        }
        desc.environment_map = Some(pathlab_scene::envmap::load(
            file,
            glam::Mat3::IDENTITY,
            args.envmap_scale,
        )?);
        desc.environment = None;
    }
    if args.fresnel == FresnelName::Schlick {
        for m in &mut desc.materials {
            if let MaterialDesc::Glass { fresnel, .. } = m {
                *fresnel = FresnelModel::Schlick;
            }
        }
    }
    let spp = args.spp.or(desc.hints.spp).unwrap_or(64);
    let max_depth = cli_depth.or(desc.hints.max_depth).unwrap_or(u32::MAX);
    if let Some(k) = args.only_bounce.filter(|&k| k > max_depth) {
        bail!("--only-bounce {k} is beyond the scene's largest bounce {max_depth}: the image would be black");
    }
    apply_resolution(&mut desc, args.resolution.as_deref())?;
    apply_view(&mut desc, args.scale, args.fov)?;
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let rr_depth = args.rr_depth.or(desc.hints.rr_depth).unwrap_or(5);
    let integrator_name = args.integrator.unwrap_or(match desc.hints.integrator {
        Some(IntegratorHint::Direct { .. }) => IntegratorName::Direct,
        _ => IntegratorName::Path,
    });
    let integrator = match integrator_name {
        IntegratorName::Direct if args.integrator.is_none() => {
            IntegratorKind::from_hints(&desc.hints)
        }
        IntegratorName::Path => IntegratorKind::Path(PathIntegrator {
            max_depth,
            rr_depth,
            hide_emitters: desc.hints.hide_emitters,
            only_bounce: args.only_bounce,
            light_samples: args.light_samples,
            lighting: match args.lighting.unwrap_or(LightingName::Mis) {
                LightingName::Mis => PathLighting::Mis,
                LightingName::Bsdf => PathLighting::Bsdf,
                LightingName::Light => PathLighting::Light,
            },
        }),
        IntegratorName::Direct => IntegratorKind::Direct(DirectIntegrator {
            strategy: args.direct.unwrap_or(DirectStrategy::Mis),
            samples: args.light_samples,
            hide_emitters: desc.hints.hide_emitters,
            ..Default::default()
        }),
        IntegratorName::Normals => IntegratorKind::Debug(DebugView::Normals),
        IntegratorName::Depth => IntegratorKind::Debug(DebugView::Depth),
        IntegratorName::Bvh => IntegratorKind::Debug(DebugView::BvhHeat),
    };
    let progressive = args.target_error.is_some() || args.time.is_some();
    // Most samples a pixel may take: -s, or for the progressive modes 65536 by default.
    let stop_cap = if progressive {
        args.spp.unwrap_or(65536)
    } else {
        spp
    };
    if let Some(e) = args.target_error {
        if !(e.is_finite() && e > 0.0) {
            bail!("--target-error {e}: must be a positive number such as 0.02");
        }
    }
    if let Some(t) = args.time {
        if !(t.is_finite() && t > 0.0) {
            bail!("--time {t}: must be a positive number of seconds");
        }
    }
    if progressive && args.adaptive.is_some() {
        bail!(
            "--adaptive and --target-error/--time are different ways to place samples; choose one"
        );
    }
    let sampler = args
        .sampler
        .or(desc.hints.sampler)
        .unwrap_or(if progressive {
            SamplerKind::Independent
        } else {
            SamplerKind::Sobol
        });
    let mut settings = RenderSettings::new(spp, args.seed, sampler);
    if let Some(a) = &args.adaptive {
        settings.adaptive = Some(parse_adaptive(a, args.adaptive_rule)?);
    }
    if let Some(c) = &args.crop {
        let [w, h] = desc.resolution;
        if c[0] >= c[2] || c[1] >= c[3] || c[2] > w || c[3] > h {
            bail!(
                "--crop {} {} {} {}: need x0 < x1 <= {w} and y0 < y1 <= {h}",
                c[0],
                c[1],
                c[2],
                c[3]
            );
        }
        settings.crop = Some([c[0], c[1], c[2], c[3]]);
    }
    if args.adaptive_rule == Some(RuleName::Neyman) {
        if let Some(a) = settings.adaptive.as_mut() {
            let seed = args.seed.wrapping_add(1);
            let (rule, _) =
                AdaptiveRule::neyman_from_pilot(&scene, &integrator, seed, sampler, cancel);
            if let Some(rule) = rule {
                a.rule = rule;
            }
        }
    }
    if let Some(shard) = &args.shard {
        if progressive || settings.adaptive.is_some() {
            bail!("--shard splits a render of fixed samples per pixel; it cannot be combined with -a, --target-error or --time");
        }
        settings.sample_range = Some(crate::farm::shard_range(shard, spp)?);
    }
    if (args.checkpoint.is_some() || args.resume.is_some())
        && settings
            .adaptive
            .is_some_and(|a| a.rule != AdaptiveRule::TwoStage)
    {
        bail!("--checkpoint and --resume: the course and neyman adaptive rules decide on every sample a pixel has drawn, which a film does not keep; use the default two-stage rule");
    }
    // What identifies this render: the scene as the renderer gets it and every setting that
    // changes the image.
    let range = settings.sample_range.unwrap_or([0, spp]);
    let description = format!(
        "{integrator_name:?} integrator, {} sampler, seed {}, crop {:?}",
        sampler.name(),
        args.seed,
        settings.crop
    )
    .to_lowercase();
    // Hashing the whole scene takes time on large ones: only renders that read or write film
    // files need the key.
    let film_files =
        args.checkpoint.is_some() || args.resume.is_some() || formats.contains(&OutputFormat::Film);
    let key = if film_files {
        crate::farm::render_key(
            &desc,
            &format!(
                "{integrator:?}|{sampler:?}|{:?}|{:?}|progressive {progressive}",
                settings.crop, settings.adaptive
            ),
        )
    } else {
        String::new()
    };
    // A progressive render's film holds up to its cap (and resumes only under the same cap).
    let header_spp = if progressive { stop_cap } else { spp };
    let range = if progressive { [0, stop_cap] } else { range };
    let header = crate::farm::header(&desc, &key, &description, args.seed, header_spp, range);
    let start_film = match &args.resume {
        Some(path) => {
            let (h, film) = pathlab_render::film_file::read(path)?;
            crate::farm::check_matches(path, &h, &header)?;
            if !args.quiet {
                let n = film.pixels().iter().map(|p| p.count()).min().unwrap_or(0);
                eprintln!(
                    "resuming {}: every pixel holds at least {n} of {} samples",
                    path.display(),
                    range[1] - range[0]
                );
            }
            Some(film)
        }
        None => None,
    };
    let [w, h] = desc.resolution;
    let total = settings.crop.map_or(w as u64 * h as u64, |c| {
        (c[2] - c[0]) as u64 * (c[3] - c[1]) as u64
    }) * spp as u64;
    let bar = if args.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else if progressive {
        let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{spinner} {elapsed} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        // The bar takes what the terminal's width leaves; counts and rates with SI prefixes.
        b.set_style(
            ProgressStyle::with_template(
                "{wide_bar} {percent:>3}% {done}/{all} samples {rate} ETA {eta}",
            )
            .map(|s| {
                s.with_key("done", |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", si_prefixed(st.pos() as f64));
                })
                .with_key("all", |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", si_prefixed(st.len().unwrap_or(0) as f64));
                })
                .with_key(
                    "rate",
                    |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{}/s", si_prefixed(st.per_sec()));
                    },
                )
            })
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let bar = Arc::new(bar);
    let progress_bar = Arc::clone(&bar);
    let progress = move |n: u64| progress_bar.inc(n);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the worker threads")?;
    let threads = pool.current_num_threads();
    let film0 = start_film.unwrap_or_else(|| pathlab_render::film::Film::new(w, h));
    // Checkpoints after finished passes, at most every --checkpoint-every seconds.
    let mut last_checkpoint = std::time::Instant::now();
    let mut checkpoint_error = None;
    let mut checkpoint = |film: &pathlab_render::film::Film| {
        if let Some(path) = &args.checkpoint {
            if last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every {
                if let Err(e) = pathlab_render::film_file::write(path, &header, film) {
                    checkpoint_error.get_or_insert(e);
                }
                last_checkpoint = std::time::Instant::now();
            }
        }
    };
    let mut estimated_error = None;
    let (film, stats) = if progressive {
        let stop = StopRule {
            target_error: args.target_error,
            time_limit: args.time,
            max_spp: stop_cap,
        };
        let bar_pass = Arc::clone(&bar);
        let mut after_pass = |film: &pathlab_render::film::Film,
                              _: &pathlab_render::render::RenderStats,
                              pass: u32,
                              error: f64| {
            bar_pass.set_message(format!("pass {pass}: estimated relative RMSE {error:.4}"));
            checkpoint(film);
        };
        let (film, stats, report) = pool.install(|| {
            render_progressive_from(
                &scene,
                &integrator,
                &settings,
                &stop,
                film0,
                &|_| {},
                cancel,
                &mut after_pass,
            )
        });
        let error = estimate_or_last(&film, &report);
        if !args.quiet {
            eprintln!(
                "progressive: {} passes, stopped by {}; estimated relative RMSE {error:.4}",
                report.passes, report.stopped_by
            );
        }
        estimated_error = Some(error);
        (film, stats)
    } else {
        let mut after_pass =
            |film: &pathlab_render::film::Film, _: &pathlab_render::render::RenderStats| {
                checkpoint(film)
            };
        pool.install(|| {
            render_from(
                &scene,
                &integrator,
                &settings,
                film0,
                &progress,
                cancel,
                &mut after_pass,
            )
        })
    };
    if let Some(e) = checkpoint_error {
        return Err(e).context("cannot write the checkpoint");
    }
    if let Some(path) = &args.checkpoint {
        pathlab_render::film_file::write(path, &header, &film)
            .context("cannot write the checkpoint")?;
    }
    bar.finish_and_clear();
    if stats.cancelled {
        let counts = film.sample_counts();
        let (lo, hi) = counts.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
        eprintln!(
            "interrupted: writing the image of the {} samples finished, {lo:.0} to {hi:.0} per pixel{}",
            stats.samples,
            if args.checkpoint.is_some() { " (and the checkpoint)" } else { "" }
        );
    }
    // The BVH view counts nodes (1 to a few hundred): a PNG shows them as a heat map scaled
    // to the image's own range, the EXR keeps the counts.
    let heat_range = (integrator_name == IntegratorName::Bvh).then(|| value_range(&film));
    for (path, &format) in outputs.iter().zip(&formats) {
        match heat_range {
            Some((_, hi)) if format == OutputFormat::Png => {
                let counts: Vec<f32> = film.mean_image().iter().map(|v| v.x).collect();
                write_heat_image(&film, &counts, hi, path)?;
            }
            _ if format == OutputFormat::Film => {
                pathlab_render::film_file::write(path, &header, &film)?
            }
            _ => write_outputs(&film, path, format, args)?,
        }
    }
    if let (Some((lo, hi)), false) = (heat_range, args.quiet || args.json) {
        let how = if formats.contains(&OutputFormat::Png) {
            format!("the PNG runs blue (0) through green to red ({hi:.0})")
        } else {
            "the EXR holds the counts".to_string()
        };
        eprintln!("bvh view: {lo:.0} to {hi:.0} nodes visited per camera ray; {how}");
    }
    if settings.adaptive.is_some() {
        let rate = PathBuf::from(format!("{}_rate.png", output.with_extension("").display()));
        write_rate_image(&film, spp, &rate)?;
        if !args.quiet {
            let counts = film.sample_counts();
            let mean = counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
            let pixels = counts.len().max(1) as f64;
            let pilot = if stats.pilot_samples > 0 {
                format!(
                    ", plus {:.1} pilot samples per pixel that chose the counts",
                    stats.pilot_samples as f64 / pixels
                )
            } else {
                String::new()
            };
            eprintln!(
                "adaptive: {mean:.1} samples per pixel on average (at most {spp}){pilot}; rate image {}",
                rate.display()
            );
        }
    }

    let build = scene.stats();
    let mean = film.image_mean();
    // Samples per pixel as taken: adaptive and progressive renders vary them per pixel.
    let counts = film.sample_counts();
    let (spp_lo, spp_hi) = counts.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &c| {
        (lo.min(c), hi.max(c))
    });
    let spp_mean = counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
    let varies = spp_lo != spp_hi || progressive || settings.adaptive.is_some();
    let spp_text = if varies {
        format!("{spp_mean:.1} spp on average ({spp_lo:.0} to {spp_hi:.0})")
    } else {
        format!("{spp_mean:.0} spp")
    };
    if args.json {
        let out = json!({
            "scene": args.scene,
            "output": output,
            "outputs": outputs,
            "resolution": [w, h],
            "spp": if varies { json!(spp_mean) } else { json!(spp_mean.round() as u64) },
            "spp_range": [spp_lo, spp_hi],
            "spp_cap": if progressive || settings.adaptive.is_some() { json!(stop_cap) } else { json!(null) },
            "integrator": format!("{integrator_name:?}").to_lowercase(),
            "max_depth": if max_depth == u32::MAX { json!("inf") } else { json!(max_depth) },
            "threads": threads,
            "seconds": stats.seconds,
            "samples": stats.samples,
            "pilot_samples": stats.pilot_samples,
            "samples_per_second": stats.samples as f64 / stats.seconds.max(1e-9),
            "rays": stats.rays,
            "rays_per_second": stats.rays as f64 / stats.seconds.max(1e-9),
            "bvh_build_seconds": build.bvh_seconds,
            "bvh_nodes": build.bvh_nodes,
            "triangles": build.triangles,
            "image_mean_rgb": [mean.x, mean.y, mean.z],
            "nonfinite_samples": stats.nonfinite_samples,
            "cancelled": stats.cancelled,
            "sampler": sampler.name(),
            "estimated_relative_rmse": estimated_error,
            "debug_range": heat_range.map(|(lo, hi)| json!({"min": lo, "max": hi})),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else if !args.quiet {
        eprintln!(
            "{}: {}x{}, {spp_text}, {:.2} s, {} samples/s, {} rays/s, BVH {} nodes in {:.1} ms; wrote {}",
            args.scene,
            w,
            h,
            stats.seconds,
            si_prefixed(stats.samples as f64 / stats.seconds.max(1e-9)),
            si_prefixed(stats.rays as f64 / stats.seconds.max(1e-9)),
            build.bvh_nodes,
            build.bvh_seconds * 1e3,
            outputs
                .iter()
                .map(|o| o.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        if stats.nonfinite_samples > 0 {
            eprintln!(
                "warning: {} samples were NaN or infinite and were counted as black",
                stats.nonfinite_samples
            );
        }
    }
    // Stopped by a signal: the shell's convention, 128 + the signal's number.
    Ok(if !stats.cancelled {
        0
    } else if signals
        .terminated
        .load(std::sync::atomic::Ordering::Relaxed)
    {
        143
    } else {
        130
    })
}

/// The estimated relative RMSE after the last pass, or of the film when no pass finished
/// (stopped at once, or a resumed film already at its target).
fn estimate_or_last(film: &pathlab_render::film::Film, report: &ProgressiveReport) -> f64 {
    report
        .error_history
        .last()
        .copied()
        .unwrap_or_else(|| estimated_relative_rmse(film))
}

/// Writes `film` (of a whole render described by `header`) as `.exr` (the mean with
/// `variance.R/G/B` and `samples.Y` layers), `.png` (sRGB after `exposure` stops) or `.plf`.
pub fn write_film_image(
    film: &Film,
    path: &Path,
    header: &pathlab_render::film_file::FilmHeader,
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

/// The film's mean as a linear EXR, with `variance.R/G/B` (of each pixel's mean) and
/// `samples.Y` layers where asked.
fn write_exr_layers(film: &Film, path: &Path, variance: bool, samples: bool) -> Result<()> {
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
    )?;
    Ok(())
}

/// The samples-per-pixel heat map: blue (few) through green to red (`spp`).
fn write_rate_image(film: &Film, spp: u32, path: &Path) -> Result<()> {
    write_heat_image(film, &film.sample_counts(), spp as f32, path)
}

/// `values` (one per pixel) as a heat map: blue (0) through green to red (`max` and above).
fn write_heat_image(film: &Film, values: &[f32], max: f32, path: &Path) -> Result<()> {
    let bytes: Vec<u8> = values
        .iter()
        .flat_map(|&n| {
            let t = (n / max.max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
            let ramp = |c: f32| ((1.5 - (4.0 * t - c).abs()).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            [ramp(3.0), ramp(2.0), ramp(1.0)]
        })
        .collect();
    write_rgb8(path, film.width(), film.height(), &bytes)?;
    Ok(())
}

/// The smallest and largest of the view's per-pixel values (its first channel).
fn value_range(film: &Film) -> (f32, f32) {
    film.mean_image()
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.x), hi.max(v.x))
        })
}

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

#[cfg(test)]
mod tests {
    use super::si_prefixed;

    #[test]
    fn counts_and_rates_get_si_prefixes_and_three_digits() {
        assert_eq!(si_prefixed(950.0), "950");
        assert_eq!(si_prefixed(12_345.0), "12.3 k");
        assert_eq!(si_prefixed(4_567_891.0), "4.57 M");
        assert_eq!(si_prefixed(123_456_789_012.0), "123 G");
        assert_eq!(si_prefixed(f64::NAN), "-");
    }
}
