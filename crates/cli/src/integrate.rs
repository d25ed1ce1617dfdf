//! `pathlab integrate`: Monte Carlo estimate of an integral over a box.

use crate::expr::{parse_constant, Expression, MAX_DIMS};
use crate::plot;
use anyhow::{bail, Context, Result};
use clap::Args;
use glam::Vec2;
use pathlab_mc::distribution::{PiecewiseConstant1D, PiecewiseConstant2D};
use pathlab_mc::estimator::{
    integrate_parallel, largest_term_share, looks_heavy_tailed, Estimate, RunningStats,
};
use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
use pathlab_mc::stats::z_test;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::Instant;

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

/// How points are drawn: uniformly in the box, or from a tabulated importance density.
enum Proposal {
    Uniform {
        lo: Vec<f64>,
        size: Vec<f64>,
        pdf: f64,
    },
    Table1D(PiecewiseConstant1D),
    Table2D(PiecewiseConstant2D),
}

impl Proposal {
    /// Draws a point into `x` and returns its density.
    #[inline]
    fn draw(&self, s: &mut AnySampler, x: &mut [f64; MAX_DIMS]) -> f64 {
        match self {
            Proposal::Uniform { lo, size, pdf } => {
                let d = lo.len();
                let mut i = 0;
                while i + 1 < d {
                    let u = s.next_2d();
                    x[i] = lo[i] + size[i] * u.x as f64;
                    x[i + 1] = lo[i + 1] + size[i + 1] * u.y as f64;
                    i += 2;
                }
                if i < d {
                    x[i] = lo[i] + size[i] * s.next_1d() as f64;
                }
                *pdf
            }
            Proposal::Table1D(t) => {
                let smp = t.sample(s.next_1d());
                x[0] = smp.x as f64;
                smp.pdf as f64
            }
            Proposal::Table2D(t) => {
                let (p, pdf) = t.sample(s.next_2d());
                x[0] = p.x as f64;
                x[1] = p.y as f64;
                pdf as f64
            }
        }
    }
}

/// Checked settings of a run.
struct Problem {
    f: Expression,
    domains: Vec<(f64, f64)>,
    proposal: Proposal,
    warnings: Vec<String>,
}

fn parse_domain(text: &str) -> Result<(f64, f64)> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 2 {
        bail!("--domain {text}: expected two bounds a,b such as -2,2");
    }
    let a = parse_constant(parts[0]).with_context(|| format!("--domain {text}"))?;
    let b = parse_constant(parts[1]).with_context(|| format!("--domain {text}"))?;
    if !(a.is_finite() && b.is_finite()) {
        bail!("--domain {text}: bounds must be finite");
    }
    if a >= b {
        bail!("--domain {text}: the interval is empty (need a < b)");
    }
    Ok((a, b))
}

fn build_problem(args: &IntegrateArgs) -> Result<Problem> {
    if args.domain.len() > MAX_DIMS {
        bail!(
            "at most {MAX_DIMS} dimensions are supported, got {}",
            args.domain.len()
        );
    }
    let domains = args
        .domain
        .iter()
        .map(|d| parse_domain(d))
        .collect::<Result<Vec<_>>>()?;
    let dims = domains.len();
    let f = Expression::parse(&args.expression, dims, "the integrand")?;
    let mut warnings = Vec::new();
    let proposal = match &args.importance {
        None => {
            let lo: Vec<f64> = domains.iter().map(|d| d.0).collect();
            let size: Vec<f64> = domains.iter().map(|d| d.1 - d.0).collect();
            let volume: f64 = size.iter().product();
            Proposal::Uniform {
                lo,
                size,
                pdf: 1.0 / volume,
            }
        }
        Some(text) => {
            if dims > 2 {
                bail!(
                    "--importance tabulates its density on a grid and supports 1 or 2 \
                     dimensions; this domain has {dims}"
                );
            }
            let res = args.importance_res;
            if !(1..=4096).contains(&res) {
                bail!("--importance-res must be between 1 and 4096, got {res}");
            }
            let g = Expression::parse(text, dims, "the --importance density")?;
            let cells = if dims == 1 { res } else { res * res };
            let mut values = Vec::with_capacity(cells);
            for c in 0..cells {
                let (i, j) = (c % res, c / res);
                let mut x = [0.0; 2];
                x[0] = domains[0].0 + (i as f64 + 0.5) / res as f64 * (domains[0].1 - domains[0].0);
                if dims == 2 {
                    x[1] = domains[1].0
                        + (j as f64 + 0.5) / res as f64 * (domains[1].1 - domains[1].0);
                }
                let v = g.eval(&x[..dims]);
                if !v.is_finite() || v < 0.0 {
                    bail!(
                        "the --importance density must be finite and >= 0, but \"{text}\" is {v} \
                         at {}",
                        point_text(&x[..dims])
                    );
                }
                values.push(v as f32);
            }
            let zeros = values.iter().filter(|&&v| v == 0.0).count();
            if zeros == values.len() {
                bail!("the --importance density \"{text}\" is zero everywhere on the domain");
            }
            if zeros > 0 {
                warnings.push(format!(
                    "the --importance density is zero on {zeros} of {} grid cells: the estimate \
                     only covers the region where it is positive",
                    values.len()
                ));
            }
            if dims == 1 {
                Proposal::Table1D(PiecewiseConstant1D::new(
                    &values,
                    domains[0].0 as f32,
                    domains[0].1 as f32,
                )?)
            } else {
                Proposal::Table2D(PiecewiseConstant2D::new(
                    &values,
                    res,
                    res,
                    Vec2::new(domains[0].0 as f32, domains[1].0 as f32),
                    Vec2::new(domains[0].1 as f32, domains[1].1 as f32),
                )?)
            }
        }
    };
    Ok(Problem {
        f,
        domains,
        proposal,
        warnings,
    })
}

fn point_text(x: &[f64]) -> String {
    let names: Vec<String> = if x.len() <= 4 {
        ["x", "y", "z", "w"][..x.len()]
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        (1..=x.len()).map(|i| format!("x{i}")).collect()
    };
    let parts: Vec<String> = names
        .iter()
        .zip(x)
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    parts.join(", ")
}

impl Problem {
    /// The integrand at a point.
    fn integrand(&self, x: &[f64; MAX_DIMS]) -> f64 {
        self.f.eval(&x[..self.domains.len()])
    }

    /// A point drawn from the proposal, and its density.
    fn draw_point(&self, s: &mut pathlab_mc::sampler::AnySampler) -> ([f64; MAX_DIMS], f64) {
        let mut x = [0.0; MAX_DIMS];
        let pdf = self.proposal.draw(s, &mut x);
        (x, pdf)
    }

    /// The estimate from `n` samples of `kind` with `seed`.
    fn estimate(&self, kind: SamplerKind, n: u32, seed: u64) -> Estimate {
        let sampler = kind.build(n, seed);
        integrate_parallel(|x| self.integrand(x), &sampler, |s| self.draw_point(s), n)
    }

    /// The estimate and a valid standard error for any sampler: independent samples use their
    /// sample variance; stratified and Sobol use `reps` independent randomisations (seeds) of
    /// `n / reps` samples each, the standard error being that of the mean of the replicates.
    fn estimate_with_error(&self, kind: SamplerKind, n: u32, reps: u32, seed: u64) -> Estimate {
        if kind == SamplerKind::Independent || reps < 2 {
            return self.estimate(kind, n, seed);
        }
        let per = (n / reps).max(1);
        let means: Vec<f64> = (0..reps)
            .into_par_iter()
            .map(|r| {
                self.estimate(kind, per, seed.wrapping_add(r as u64 * 0x9e37_79b9))
                    .mean
            })
            .collect();
        let mut stats = RunningStats::new();
        means.iter().for_each(|&m| stats.push(m));
        let mut e = stats.estimate();
        e.n = per as u64 * reps as u64;
        e.variance *= per as f64; // variance of one term, for comparability
        e
    }

    /// The share of the sample variance carried by the largest of the terms f/p (see
    /// [`largest_term_share`]).
    fn largest_share(&self, kind: SamplerKind, n: u32, seed: u64, mean: f64) -> f64 {
        let sampler = kind.build(n, seed);
        largest_term_share(
            |x| self.integrand(x),
            &sampler,
            |s| self.draw_point(s),
            n,
            mean,
        )
    }

    /// Finds a sample point where the integrand is not finite (for the error message).
    fn find_non_finite(&self, kind: SamplerKind, n: u32, seed: u64) -> Option<[f64; MAX_DIMS]> {
        let mut s = kind.build(n, seed);
        (0..n).find_map(|i| {
            s.start_pixel_sample([0, 0], i, 0);
            let mut x = [0.0; MAX_DIMS];
            let pdf = self.proposal.draw(&mut s, &mut x);
            (pdf > 0.0 && !self.f.eval(&x[..self.domains.len()]).is_finite()).then_some(x)
        })
    }

    fn domain_text(&self) -> String {
        let parts: Vec<String> = self
            .domains
            .iter()
            .map(|(a, b)| format!("[{}, {}]", fmt_num(*a), fmt_num(*b)))
            .collect();
        parts.join(" x ")
    }
}

fn percent(v: f64) -> String {
    if v >= 1e-3 || v == 0.0 {
        format!("{:.3}%", 100.0 * v)
    } else {
        format!("{:.2e}%", 100.0 * v)
    }
}

fn fmt_num(v: f64) -> String {
    format!("{}", (v * 1e9).round() / 1e9)
}

/// Runs `pathlab integrate`.
pub fn run(args: &IntegrateArgs) -> Result<()> {
    if args.samples == 0 || args.samples > u32::MAX as u64 {
        bail!(
            "-n must be between 1 and {}, got {}",
            u32::MAX,
            args.samples
        );
    }
    if args.reps == 0 {
        bail!("--reps must be at least 1");
    }
    if args.sampler != SamplerKind::Independent && args.reps as u64 > args.samples {
        bail!(
            "--reps {} randomisations need at least as many samples, got -n {}",
            args.reps,
            args.samples
        );
    }
    let n = args.samples as u32;
    let exact = args
        .exact
        .as_deref()
        .map(|t| parse_constant(t).with_context(|| format!("--exact {t}")))
        .transpose()?;
    let problem = build_problem(args)?;
    for w in &problem.warnings {
        eprintln!("warning: {w}");
    }

    let start = Instant::now();
    let est = problem.estimate_with_error(args.sampler, n, args.reps, args.seed);
    let seconds = start.elapsed().as_secs_f64();
    if !est.mean.is_finite() {
        let at = problem
            .find_non_finite(args.sampler, n, args.seed)
            .map(|x| format!(" at {}", point_text(&x[..problem.domains.len()])))
            .unwrap_or_default();
        bail!(
            "the integrand \"{}\" is not finite{at}: its integral cannot be estimated",
            args.expression
        );
    }
    let rate = est.n as f64 / seconds.max(1e-9);
    let share = problem.largest_share(args.sampler, n, args.seed, est.mean);
    let heavy = looks_heavy_tailed(share, n as u64);
    let mut warnings = problem.warnings.clone();
    if heavy {
        let w = format!(
            "one of the {n} samples carries {:.0}% of the sample variance: f/p looks heavy-tailed (infinite variance, or a divergent integral such as 1/x at 0), so the standard error and interval are not to be trusted; sample in proportion to the integrand's peak (--importance) or change variables",
            100.0 * share
        );
        eprintln!("warning: {w}");
        warnings.push(w);
    }

    let convergence = match &args.convergence {
        Some(path) => Some(convergence(
            &problem,
            n,
            args.reps.max(4),
            args.seed,
            exact,
            path,
        )?),
        None => None,
    };

    if args.json {
        let mut out = json!({
            "expression": args.expression,
            "domain": problem.domains.iter().map(|d| [d.0, d.1]).collect::<Vec<_>>(),
            "importance": args.importance,
            "sampler": args.sampler.name(),
            "samples": est.n,
            "seed": args.seed,
            "estimate": est.mean,
            "std_error": est.std_error,
            "ci95": [est.ci95.0, est.ci95.1],
            "relative_error": est.relative_error(),
            "variance_per_sample": est.variance,
            "seconds": seconds,
            "samples_per_second": rate,
            "largest_sample_share": share,
            "heavy_tailed": heavy,
            "warnings": warnings,
        });
        if let Some(x) = exact {
            let z = z_test(est.mean, est.std_error, x);
            out["exact"] = json!(x);
            out["error"] = json!(est.mean - x);
            out["z"] = json!(z.z);
        }
        if let Some(c) = convergence {
            out["convergence"] = c;
        }
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }

    println!(
        "integral of {} over {}",
        args.expression,
        problem.domain_text()
    );
    let how = match &args.importance {
        Some(g) => format!("importance sampling from a density proportional to {g}"),
        None => "uniform sampling".to_string(),
    };
    println!(
        "  {how}, {} sampler, {} samples, seed {}",
        args.sampler.name(),
        est.n,
        args.seed
    );
    println!(
        "  estimate        {:.8} ± {:.2e} (standard error)",
        est.mean, est.std_error
    );
    println!("  95% CI          [{:.8}, {:.8}]", est.ci95.0, est.ci95.1);
    println!("  relative error  {}", percent(est.relative_error()));
    if args.sampler != SamplerKind::Independent && args.reps > 1 {
        println!(
            "  (error from {} independent randomisations of {} samples each)",
            args.reps,
            est.n / args.reps as u64
        );
    }
    if let Some(x) = exact {
        let z = z_test(est.mean, est.std_error, x);
        println!(
            "  exact           {x:.8}: error {:+.2e}, {:.2} standard errors",
            est.mean - x,
            z.z
        );
    }
    println!("  {:.3} s, {:.3e} samples/s", seconds, rate);
    if let Some(path) = &args.convergence {
        println!("  convergence plot written to {}", path.display());
    }
    Ok(())
}

/// Estimates at N = 2^k for each sampler, `reps` independent randomisations each; plots them.
fn convergence(
    problem: &Problem,
    n: u32,
    reps: u32,
    seed: u64,
    exact: Option<f64>,
    path: &std::path::Path,
) -> Result<Value> {
    let format = plot::Format::from_path(path)?;
    let max_k = (n as f64).log2().floor() as u32;
    let min_k = 4.min(max_k);
    let ks: Vec<u32> = (min_k..=max_k).collect();
    let jobs: Vec<(usize, u32, u32)> = SamplerKind::ALL
        .iter()
        .enumerate()
        .flat_map(|(si, _)| {
            ks.iter()
                .flat_map(move |&k| (0..reps).map(move |r| (si, k, r)))
        })
        .collect();
    let results: Vec<f64> = jobs
        .par_iter()
        .map(|&(si, k, r)| {
            let seed = seed.wrapping_add(1 + r as u64 * 7919);
            problem.estimate(SamplerKind::ALL[si], 1 << k, seed).mean
        })
        .collect();
    // The reference for the error: the exact value, or the pooled mean of the largest runs.
    let reference = exact.unwrap_or_else(|| {
        let largest: Vec<f64> = jobs
            .iter()
            .zip(&results)
            .filter(|((_, k, _), _)| *k == max_k)
            .map(|(_, &m)| m)
            .collect();
        largest.iter().sum::<f64>() / largest.len() as f64
    });
    let mut series = Vec::new();
    for (si, kind) in SamplerKind::ALL.iter().enumerate() {
        let mut points = Vec::new();
        for &k in &ks {
            let vals: Vec<f64> = jobs
                .iter()
                .zip(&results)
                .filter(|((s, kk, _), _)| *s == si && *kk == k)
                .map(|(_, &m)| m)
                .collect();
            let mut st = RunningStats::new();
            vals.iter().for_each(|&v| st.push(v));
            let rmse = (vals.iter().map(|v| (v - reference).powi(2)).sum::<f64>()
                / vals.len() as f64)
                .sqrt();
            points.push(plot::ConvergencePoint {
                n: (1u64 << k) as f64,
                estimate: vals[0],
                ci_half: 1.96 * st.std_dev(),
                rmse,
            });
        }
        series.push(plot::ConvergenceSeries {
            name: kind.name().to_string(),
            slope: plot::fitted_slope(&points),
            points,
        });
    }
    let title = format!("∫ {} over {}", problem.f.text(), problem.domain_text());
    plot::convergence(path, format, &title, &series, exact, exact.is_some())?;
    Ok(json!({
        "reference": reference,
        "reference_is_exact": exact.is_some(),
        "replications": reps,
        "series": series.iter().map(|s| json!({
            "sampler": s.name,
            "fitted_slope": s.slope,
            "n": s.points.iter().map(|p| p.n).collect::<Vec<_>>(),
            "estimate": s.points.iter().map(|p| p.estimate).collect::<Vec<_>>(),
            "ci95_half_width": s.points.iter().map(|p| p.ci_half).collect::<Vec<_>>(),
            "rmse": s.points.iter().map(|p| p.rmse).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    }))
}
