//! `pathlab sample`: the arguments and the report of [`pathlab_lab::sample`] (samples by
//! inversion or warping against the exact distribution: moments, a chi-square test, plots).

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use pathlab_lab::plot;
use pathlab_lab::sample::Distribution;
use pathlab_mc::sampler::SamplerKind;
use serde_json::json;
use std::path::PathBuf;

/// The distributions `pathlab sample` knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DistributionName {
    /// Exponential with rate --lambda, by inversion: x = -ln(1 - U)/λ.
    Exponential,
    /// Directions uniform over the hemisphere.
    UniformHemisphere,
    /// Directions over the hemisphere with density cos θ / π.
    CosineHemisphere,
    /// Directions uniform over the sphere.
    UniformSphere,
    /// Directions uniform in a cone of half-angle acos(--cos-theta-max).
    UniformCone,
    /// Points uniform on the unit disk (Shirley–Chiu concentric map).
    ConcentricDisk,
    /// Barycentric coordinates uniform over a triangle.
    UniformTriangle,
    /// Piecewise-constant density with values --weights over --range.
    Piecewise,
    /// 2D piecewise-constant density with rows of --weights separated by ';'.
    Piecewise2d,
    /// Discrete outcomes 0..n with probabilities proportional to --weights (alias method).
    Alias,
}

/// Raw command-line arguments of `pathlab sample`.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct SampleArgs {
    /// Which distribution to sample.
    #[arg(value_enum)]
    pub distribution: DistributionName,
    /// Number of samples.
    #[arg(short = 'n', long, default_value_t = 100_000)]
    pub samples: u64,
    /// Rate λ of the exponential distribution.
    #[arg(long, default_value_t = 1.0)]
    pub lambda: f64,
    /// cos θmax of the cone.
    #[arg(long, default_value_t = 0.8)]
    pub cos_theta_max: f64,
    /// Values of a piecewise density or alias table: "1,2,3"; for piecewise-2d, rows separated
    /// by ';': "1,2;3,4".
    #[arg(long, default_value = "1,3,0,2,4,1")]
    pub weights: String,
    /// Interval a,b of the piecewise density (for piecewise-2d: the unit square).
    #[arg(long, default_value = "0,1", allow_hyphen_values = true)]
    pub range: String,
    /// Where the uniform numbers come from: independent, stratified or sobol.
    #[arg(long, default_value = "independent")]
    pub sampler: SamplerKind,
    /// Plot the samples against the pdf (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

fn parse_list(text: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|t| {
            let t = t.trim();
            t.parse::<f64>()
                .with_context(|| format!("--weights: '{t}' is not a number"))
        })
        .collect()
}

fn parse_range(text: &str) -> Result<(f32, f32)> {
    let v = parse_list(text).context("--range")?;
    if v.len() != 2 || !(v[0].is_finite() && v[1].is_finite()) || v[0] >= v[1] {
        bail!("--range {text}: expected a non-empty interval a,b with a < b");
    }
    Ok((v[0] as f32, v[1] as f32))
}

/// The distribution the arguments name, checked.
fn distribution(a: &SampleArgs) -> Result<Distribution> {
    Ok(match a.distribution {
        DistributionName::Exponential => Distribution::exponential(a.lambda).context("--lambda")?,
        DistributionName::UniformHemisphere => Distribution::Hemisphere,
        DistributionName::CosineHemisphere => Distribution::Cosine,
        DistributionName::UniformSphere => Distribution::Sphere,
        DistributionName::UniformCone => {
            Distribution::cone(a.cos_theta_max).context("--cos-theta-max")?
        }
        DistributionName::ConcentricDisk => Distribution::Disk,
        DistributionName::UniformTriangle => Distribution::Triangle,
        DistributionName::Piecewise => {
            let w = parse_list(&a.weights)?;
            let (lo, hi) = parse_range(&a.range)?;
            Distribution::piecewise(&w, lo, hi).context("--weights")?
        }
        DistributionName::Piecewise2d => {
            let rows = a
                .weights
                .split(';')
                .map(parse_list)
                .collect::<Result<Vec<_>>>()?;
            Distribution::piecewise_2d(&rows).context("--weights")?
        }
        DistributionName::Alias => {
            Distribution::alias(&parse_list(&a.weights)?).context("--weights")?
        }
    })
}

pub fn run(args: &SampleArgs) -> Result<()> {
    let n = crate::flags::sample_count(args.samples)?;
    let format = args
        .plot
        .as_deref()
        .map(plot::Format::from_path)
        .transpose()?;
    let dist = distribution(args)?;
    let report = pathlab_lab::sample::run(&dist, args.sampler, n, args.seed, format.is_some());
    if let (Some(path), Some(format)) = (&args.plot, format) {
        report.write_plot(path, format)?;
    }

    if args.json {
        let mut out = report.json();
        out["distribution"] = json!(format!("{:?}", args.distribution).to_lowercase());
        out["plot"] = json!(args.plot);
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("{}", report.text());
    if let Some(path) = &args.plot {
        println!("  plot written to {}", path.display());
    }
    Ok(())
}
