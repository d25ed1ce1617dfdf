//! Monte Carlo integration of an expression over a box, F_N = 1/N Σ f(X_i)/p(X_i), with X_i
//! uniform in the box or drawn from a tabulated importance density, and a standard error that
//! holds for every sampler (the sample variance for independent samples, independent
//! randomisations for stratified and Sobol ones); and the convergence study of the three
//! samplers. The experiment of `pathlab integrate`.

mod report;

pub use report::{convergence_plot, IntegrateReport};

use crate::expr::{Expression, MAX_DIMS};
use crate::plot::{fitted_slope, ConvergencePoint, ConvergenceSeries};
use anyhow::{bail, Result};
use glam::Vec2;
use pathlab_mc::distribution::{PiecewiseConstant1D, PiecewiseConstant2D};
use pathlab_mc::estimator::{
    integrate_parallel, largest_term_share, looks_heavy_tailed, replicate_estimate, Estimate,
    RunningStats,
};
use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
use rayon::prelude::*;

/// How points are drawn: uniformly in the box, or from a tabulated importance density.
pub enum Proposal {
    /// Uniform in the box from `lo` with edge lengths `size`: density `pdf` = 1/volume.
    Uniform {
        /// The box's lower corner.
        lo: Vec<f64>,
        /// Its edge lengths.
        size: Vec<f64>,
        /// 1/volume.
        pdf: f64,
    },
    /// A piecewise-constant density over the interval.
    Table1D(PiecewiseConstant1D),
    /// A piecewise-constant density over the rectangle.
    Table2D(PiecewiseConstant2D),
}

impl Proposal {
    /// Draws a point into `x` and returns its density.
    #[inline]
    pub fn draw(&self, s: &mut AnySampler, x: &mut [f64; MAX_DIMS]) -> f64 {
        match self {
            Proposal::Uniform { lo, size, pdf } => {
                let d = lo.len();
                s.next_point(&mut x[..d]);
                for ((xi, lo), size) in x.iter_mut().zip(lo).zip(size) {
                    *xi = lo + size * *xi;
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

/// A checked integral: the integrand, its box and how points are drawn.
pub struct Integral {
    /// The integrand.
    pub f: Expression,
    /// One interval per dimension.
    pub domains: Vec<(f64, f64)>,
    /// How points are drawn.
    pub proposal: Proposal,
    /// What the caller should be told (an importance density that is zero on part of the box).
    pub warnings: Vec<String>,
}

impl Integral {
    /// The integral of `expression` over the box `domains`, by uniform sampling, or with
    /// `importance = Some((g, res))` from a density proportional to the expression `g`
    /// (tabulated on `res` cells per axis; 1 or 2 dimensions).
    pub fn new(
        expression: &str,
        domains: Vec<(f64, f64)>,
        importance: Option<(&str, usize)>,
    ) -> Result<Integral> {
        if domains.len() > MAX_DIMS {
            bail!(
                "at most {MAX_DIMS} dimensions are supported, got {}",
                domains.len()
            );
        }
        let dims = domains.len();
        let f = Expression::parse(expression, dims, "the integrand")?;
        let mut warnings = Vec::new();
        let proposal = match importance {
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
            Some((text, res)) => {
                if dims > 2 {
                    bail!(
                        "importance sampling tabulates its density on a grid and supports 1 or 2 \
                     dimensions; this domain has {dims}"
                    );
                }
                if !(1..=4096).contains(&res) {
                    bail!("the importance grid must have between 1 and 4096 cells per axis, got {res}");
                }
                let g = Expression::parse(text, dims, "the importance density")?;
                let cells = if dims == 1 { res } else { res * res };
                let mut values = Vec::with_capacity(cells);
                for c in 0..cells {
                    let (i, j) = (c % res, c / res);
                    let mut x = [0.0; 2];
                    x[0] = domains[0].0
                        + (i as f64 + 0.5) / res as f64 * (domains[0].1 - domains[0].0);
                    if dims == 2 {
                        x[1] = domains[1].0
                            + (j as f64 + 0.5) / res as f64 * (domains[1].1 - domains[1].0);
                    }
                    let v = g.eval(&x[..dims]);
                    if !v.is_finite() || v < 0.0 {
                        bail!(
                        "the importance density must be finite and >= 0, but \"{text}\" is {v} \
                         at {}",
                        point_text(&x[..dims])
                    );
                    }
                    values.push(v as f32);
                }
                let zeros = values.iter().filter(|&&v| v == 0.0).count();
                if zeros == values.len() {
                    bail!("the importance density \"{text}\" is zero everywhere on the domain");
                }
                if zeros > 0 {
                    warnings.push(format!(
                        "the importance density is zero on {zeros} of {} grid cells: the estimate \
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
        Ok(Integral {
            f,
            domains,
            proposal,
            warnings,
        })
    }
}

/// A point as `x = 1, y = 2` (or `x1 = ...` beyond four dimensions).
pub fn point_text(x: &[f64]) -> String {
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

impl Integral {
    /// The integrand at a point.
    pub fn integrand(&self, x: &[f64; MAX_DIMS]) -> f64 {
        self.f.eval(&x[..self.domains.len()])
    }

    /// A point drawn from the proposal, and its density.
    pub fn draw_point(&self, s: &mut pathlab_mc::sampler::AnySampler) -> ([f64; MAX_DIMS], f64) {
        let mut x = [0.0; MAX_DIMS];
        let pdf = self.proposal.draw(s, &mut x);
        (x, pdf)
    }

    /// The estimate from `n` samples of `kind` with `seed`.
    pub fn estimate(&self, kind: SamplerKind, n: u32, seed: u64) -> Estimate {
        let sampler = kind.build(n, seed);
        integrate_parallel(|x| self.integrand(x), &sampler, |s| self.draw_point(s), n)
    }

    /// The estimate and a valid standard error for any sampler: independent samples use their
    /// sample variance; stratified and Sobol use `reps` independent randomisations (seeds) of
    /// `n / reps` samples each, the standard error being that of the mean of the replicates.
    pub fn estimate_with_error(&self, kind: SamplerKind, n: u32, reps: u32, seed: u64) -> Estimate {
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
        replicate_estimate(&means, per as u64)
    }

    /// The share of the sample variance carried by the largest of the terms f/p (see
    /// [`largest_term_share`]).
    pub fn largest_share(&self, kind: SamplerKind, n: u32, seed: u64, mean: f64) -> f64 {
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
    pub fn find_non_finite(&self, kind: SamplerKind, n: u32, seed: u64) -> Option<[f64; MAX_DIMS]> {
        let mut s = kind.build(n, seed);
        (0..n).find_map(|i| {
            s.start_pixel_sample([0, 0], i, 0);
            let mut x = [0.0; MAX_DIMS];
            let pdf = self.proposal.draw(&mut s, &mut x);
            (pdf > 0.0 && !self.f.eval(&x[..self.domains.len()]).is_finite()).then_some(x)
        })
    }

    /// The integral estimated from `n` samples of `kind` (stratified and Sobol with `reps`
    /// randomisations for their error), timed, with the check that f/p is not heavy-tailed
    /// (a warning in [`IntegralRun::warnings`], after the problem's own). An integrand that is
    /// not finite somewhere is an error naming a point where it is not.
    pub fn run(&self, kind: SamplerKind, n: u32, reps: u32, seed: u64) -> Result<IntegralRun> {
        if reps == 0 {
            bail!("--reps must be at least 1");
        }
        if kind != SamplerKind::Independent && reps > n {
            bail!("--reps {reps} randomisations need at least as many samples, got -n {n}");
        }
        let start = std::time::Instant::now();
        let estimate = self.estimate_with_error(kind, n, reps, seed);
        let seconds = start.elapsed().as_secs_f64();
        if !estimate.mean.is_finite() {
            let at = self
                .find_non_finite(kind, n, seed)
                .map(|x| format!(" at {}", point_text(&x[..self.domains.len()])))
                .unwrap_or_default();
            bail!(
                "the integrand \"{}\" is not finite{at}: its integral cannot be estimated",
                self.f.text()
            );
        }
        let largest_share = self.largest_share(kind, n, seed, estimate.mean);
        let heavy_tailed = looks_heavy_tailed(largest_share, n as u64);
        let mut warnings = self.warnings.clone();
        if heavy_tailed {
            warnings.push(format!(
                "one of the {n} samples carries {:.0}% of the sample variance: f/p looks heavy-tailed (infinite variance, or a divergent integral such as 1/x at 0), so the standard error and interval are not to be trusted; sample in proportion to the integrand's peak (--importance) or change variables",
                100.0 * largest_share
            ));
        }
        Ok(IntegralRun {
            estimate,
            seconds,
            largest_share,
            heavy_tailed,
            warnings,
        })
    }

    /// The box as `[a, b] x [c, d]`.
    pub fn domain_text(&self) -> String {
        let parts: Vec<String> = self
            .domains
            .iter()
            .map(|(a, b)| format!("[{}, {}]", fmt_num(*a), fmt_num(*b)))
            .collect();
        parts.join(" x ")
    }
}

/// What [`Integral::run`] found.
#[derive(Clone, Debug)]
pub struct IntegralRun {
    /// The estimate, its standard error and interval.
    pub estimate: Estimate,
    /// Seconds the estimate took.
    pub seconds: f64,
    /// The share of the sample variance carried by the largest term f/p.
    pub largest_share: f64,
    /// Whether that share says f/p is heavy-tailed.
    pub heavy_tailed: bool,
    /// The problem's warnings, then the heavy-tail warning if any.
    pub warnings: Vec<String>,
}

/// A bound rounded to 9 decimals for display.
fn fmt_num(v: f64) -> String {
    format!("{}", (v * 1e9).round() / 1e9)
}

/// A convergence study: for each sampler, estimates at N = 2^k up to `n`, `reps` independent
/// randomisations each, against `reference` (the exact value, or the pooled mean of the largest
/// runs).
pub struct Convergence {
    /// What the errors are measured against.
    pub reference: f64,
    /// One series per sampler (independent, stratified, Sobol).
    pub series: Vec<ConvergenceSeries>,
}

/// Runs the convergence study of `integral` (see [`Convergence`]).
pub fn convergence(
    integral: &Integral,
    n: u32,
    reps: u32,
    seed: u64,
    exact: Option<f64>,
) -> Convergence {
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
            integral.estimate(SamplerKind::ALL[si], 1 << k, seed).mean
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
            points.push(ConvergencePoint {
                n: (1u64 << k) as f64,
                estimate: vals[0],
                ci_half: 1.96 * st.std_dev(),
                rmse,
            });
        }
        series.push(ConvergenceSeries {
            name: kind.name().to_string(),
            slope: fitted_slope(&points),
            points,
        });
    }
    Convergence { reference, series }
}
