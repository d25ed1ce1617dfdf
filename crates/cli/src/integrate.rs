//! `pathlab integrate`: the arguments and the report of [`pathlab_lab::integrate`] (a Monte
//! Carlo estimate of an integral over a box, with its error and a convergence study).

use anyhow::{Context, Result};
use clap::Args;
use pathlab_lab::expr::{parse_constant, parse_interval};
use pathlab_lab::integrate::{convergence_plot, Integral, IntegrateReport};
use pathlab_mc::sampler::SamplerKind;
use std::path::PathBuf;

/// Raw command-line arguments of `pathlab integrate`.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct IntegrateArgs {
    /// The integrand, e.g. "exp(-(x^2+y^2)/2)". Variables: x, y, z, w (or x1, x2, ...), one
    /// per --domain; functions such as sin, cos, exp, ln, sqrt, abs; constants PI (or pi), E.
    #[arg(allow_hyphen_values = true)]
    pub expression: String,
    /// One interval a,b per dimension (repeat for more dimensions), e.g. --domain -2,2.
    /// Bounds may be constant expressions such as -pi/2.
    #[arg(
        long,
        short = 'd',
        required = true,
        allow_hyphen_values = true,
        value_name = "A,B"
    )]
    pub domain: Vec<String>,
    /// Number of samples.
    #[arg(short = 'n', long, default_value_t = 1_000_000)]
    pub samples: u64,
    /// Where the uniform numbers come from: independent, stratified or sobol.
    #[arg(long, default_value = "independent")]
    pub sampler: SamplerKind,
    /// Sample from a density proportional to this non-negative expression (tabulated on a
    /// grid, 1 or 2 dimensions) instead of uniformly: importance sampling.
    #[arg(long, value_name = "EXPR")]
    pub importance: Option<String>,
    /// Grid cells per axis of the tabulated --importance density.
    #[arg(long, default_value_t = 128, value_name = "N")]
    pub importance_res: usize,
    /// Independent randomisations used to estimate the error of the stratified and Sobol
    /// samplers, whose samples are not independent.
    #[arg(long, default_value_t = 16)]
    pub reps: u32,
    /// The exact value, if known: the error and its z-score are reported.
    #[arg(long, allow_hyphen_values = true)]
    pub exact: Option<String>,
    /// Plot estimate and error against N for independent, stratified and Sobol sampling
    /// (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub convergence: Option<PathBuf>,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab integrate`.
pub fn run(args: &IntegrateArgs) -> Result<()> {
    let n = crate::flags::sample_count(args.samples)?;
    let exact = args
        .exact
        .as_deref()
        .map(|t| parse_constant(t).with_context(|| format!("--exact {t}")))
        .transpose()?;
    let domains = args
        .domain
        .iter()
        .map(|d| parse_interval("--domain", d))
        .collect::<Result<Vec<_>>>()?;
    let problem = Integral::new(
        &args.expression,
        domains,
        args.importance.as_deref().map(|g| (g, args.importance_res)),
    )
    .map_err(|e| match &args.importance {
        // Name the flags behind the importance density's errors.
        Some(_) if e.to_string().contains("importance grid") => e.context("--importance-res"),
        Some(_) if e.to_string().contains("importance") => e.context("--importance"),
        _ => e,
    })?;
    for w in &problem.warnings {
        eprintln!("warning: {w}");
    }
    let run = problem.run(args.sampler, n, args.reps, args.seed)?;
    if run.heavy_tailed {
        if let Some(w) = run.warnings.last() {
            eprintln!("warning: {w}");
        }
    }
    let convergence = match &args.convergence {
        Some(path) => Some(convergence_plot(
            &problem,
            n,
            args.reps.max(4),
            args.seed,
            exact,
            path,
        )?),
        None => None,
    };
    let report = IntegrateReport {
        expression: &args.expression,
        importance: args.importance.as_deref(),
        problem: &problem,
        run: &run,
        sampler: args.sampler,
        reps: args.reps,
        seed: args.seed,
        exact,
    };
    if args.json {
        let mut out = report.json();
        if let Some(c) = convergence {
            out["convergence"] = c;
        }
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("{}", report.text());
        if let Some(path) = &args.convergence {
            println!("  convergence plot written to {}", path.display());
        }
    }
    Ok(())
}
