//! `pathlab render`'s flags, and their checks before anything is loaded.

use crate::flags::{self, within, SceneArgs};
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use pathlab_lab::render::{ProgressiveStop, RenderRequest, SceneEdits};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::image_io::ToneMap;
use pathlab_render::integrator::{DirectStrategy, IntegratorChoice, PathLighting};
use pathlab_render::limits;
use pathlab_render::render::{Adaptive, AdaptiveRule};
use std::path::PathBuf;

pub use pathlab_render::integrator::IntegratorName;

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

/// Extra outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Aov {
    /// Variance of each pixel's mean (squared standard error), per channel.
    Variance,
    /// Samples per pixel.
    Samples,
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
    #[command(flatten)]
    pub scene: SceneArgs,
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
    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 (the rest stays black). Default: the
    /// scene file's crop window, if it has one.
    #[arg(long, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"], allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..))]
    pub crop: Option<Vec<u32>>,
    /// Output image: .exr (linear) or .png (sRGB). Repeat for several files from one render
    /// (-o a.exr -o a.png). Default: SCENE.png.
    #[arg(short = 'o', long, visible_short_alias = 'f', value_name = "FILE")]
    pub output: Vec<PathBuf>,
    /// The integrator: path (path tracing with next-event estimation, MIS and Russian
    /// roulette), bdpt (bidirectional path tracing: camera and light subpaths joined by every
    /// strategy, light traced to the lens included, weighted by MIS), direct (direct lighting
    /// only, by the strategy --direct names), or the debug
    /// views normals (shading normals), depth (distance to the first surface) and bvh (BVH
    /// nodes visited per camera ray). Default: the one the scene file names, else path.
    #[arg(long)]
    pub integrator: Option<IntegratorName>,
    /// How the path tracer finds light at each vertex: mis (light and BSDF sampling combined),
    /// bsdf (BSDF sampling only) or light (light sampling only). Default: mis. Path tracer
    /// only.
    #[arg(long)]
    pub lighting: Option<PathLighting>,
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
    /// Default: the one the scene file names (Mitsuba's `<sampler type=...>`, pbrt's
    /// `Sampler`), else sobol, or independent with --target-error/--time (whose error estimate
    /// is exact only for independent samples).
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
    #[arg(long, default_value = "srgb")]
    pub tonemap: ToneMap,
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
    /// Show the render in the tev image viewer as it converges: tev's HOST:PORT (tev listens
    /// on 127.0.0.1:14158, the port taken when only a HOST is given; start it with `tev`).
    /// With --aov, the variance and sample-count layers too. If nothing listens: a warning,
    /// and the render goes on.
    #[arg(long, value_name = "HOST:PORT")]
    pub display: Option<String>,
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

/// Flags that the chosen integrator does not read: a warning each.
fn unread_flags(args: &RenderArgs) -> Vec<String> {
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
    if (debug || integrator == Some(IntegratorName::Bdpt)) && args.light_samples > 1 {
        unused("--light-samples", "the path and direct integrators");
    }
    if args.adaptive_rule.is_some() && args.adaptive.is_none() {
        unused("--adaptive-rule", "adaptive sampling (-a)");
    }
    warnings
}

/// The flags as a checked request, and warnings about flags the chosen integrator does not
/// read.
pub(super) struct Checked {
    pub request: RenderRequest,
    pub warnings: Vec<String>,
}

/// Checks every flag that needs no scene (an error names the flag and what was expected),
/// and makes the request of them.
pub(super) fn check(args: &RenderArgs) -> Result<Checked> {
    within("--exposure", Some(args.exposure), limits::exposure)?;
    let every = Some(args.checkpoint_every);
    within("--checkpoint-every", every, limits::checkpoint_seconds)?;
    let progressive =
        (args.target_error.is_some() || args.time.is_some()).then_some(ProgressiveStop {
            target_error: args.target_error,
            time: args.time,
        });
    let adaptive = args
        .adaptive
        .as_deref()
        .map(|a| parse_adaptive(a, args.adaptive_rule))
        .transpose()?;
    let request = RenderRequest {
        scene: args.scene.name.clone(),
        params: args.scene.params()?,
        edits: SceneEdits {
            lens_radius: args.lens_radius,
            focal_distance: args.focal_distance,
            envmap: args.envmap.clone().map(|e| (e, args.envmap_scale)),
            schlick_fresnel: args.fresnel == FresnelName::Schlick,
            resolution: args.scene.size(),
            scale: args.scale,
            fov: args.fov,
        },
        spp: args.spp,
        seed: args.seed,
        sampler: args.sampler,
        integrator: IntegratorChoice {
            name: args.integrator,
            max_depth: args
                .max_depth
                .as_deref()
                .map(flags::max_depth)
                .transpose()?,
            rr_depth: args.rr_depth,
            only_bounce: args.only_bounce,
            light_samples: args.light_samples,
            lighting: args.lighting.unwrap_or_default(),
            direct: args.direct,
        },
        neyman: adaptive.is_some() && args.adaptive_rule == Some(RuleName::Neyman),
        adaptive,
        progressive,
        crop: args.crop.as_deref().map(|c| [c[0], c[1], c[2], c[3]]),
        shard: args.shard.as_deref().map(str::parse).transpose()?,
        film_files: false,
        checkpoints: args.checkpoint.is_some() || args.resume.is_some(),
    };
    request.check()?;
    let warnings = unread_flags(args);
    Ok(Checked { request, warnings })
}
