//! `pathlab sample`: draw samples by inversion or warping and compare them with the exact
//! distribution: moments, a chi-square goodness-of-fit test and plots.

use crate::plot;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use glam::{Vec2, Vec3};
use pathlab_mc::distribution::{AliasTable, Exponential, PiecewiseConstant1D, PiecewiseConstant2D};
use pathlab_mc::estimator::RunningStats;
use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
use pathlab_mc::stats::{
    azimuth, chi2_test_1d, chi2_test_2d, chi2_test_discrete, cos_theta_phi, z_test, ChiSquareTest,
};
use pathlab_mc::warp::*;
use serde_json::json;
use std::f64::consts::TAU;
use std::path::PathBuf;
use std::time::Instant;

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

/// A checked distribution, ready to sample.
enum Dist {
    Exponential(Exponential),
    Hemisphere,
    Cosine,
    Sphere,
    Cone(f32),
    Disk,
    Triangle,
    Piecewise(PiecewiseConstant1D),
    Piecewise2D(PiecewiseConstant2D, [usize; 2]),
    Alias(AliasTable),
}

/// Exact moments of one component of a sample.
struct Moment {
    name: &'static str,
    mean: f64,
    variance: f64,
}

/// A density of these weights needs a positive total: the library reads all zeros as
/// uniform (what an environment map's black row needs), which asked for by name is a mistake.
fn positive_sum(w: &[f32]) -> Result<()> {
    let total: f64 = w.iter().map(|&x| x as f64).sum();
    if !(total > 0.0 && total.is_finite()) {
        bail!("--weights: the weights must have a finite, positive sum (got {total})");
    }
    Ok(())
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

impl Dist {
    fn from_args(a: &SampleArgs) -> Result<Self> {
        Ok(match a.distribution {
            DistributionName::Exponential => Dist::Exponential(Exponential::new(a.lambda)?),
            DistributionName::UniformHemisphere => Dist::Hemisphere,
            DistributionName::CosineHemisphere => Dist::Cosine,
            DistributionName::UniformSphere => Dist::Sphere,
            DistributionName::UniformCone => {
                let c = a.cos_theta_max;
                if !(-1.0..1.0).contains(&c) {
                    bail!("--cos-theta-max must be in [-1, 1), got {c}");
                }
                Dist::Cone(c as f32)
            }
            DistributionName::ConcentricDisk => Dist::Disk,
            DistributionName::UniformTriangle => Dist::Triangle,
            DistributionName::Piecewise => {
                let w: Vec<f32> = parse_list(&a.weights)?.iter().map(|&x| x as f32).collect();
                let (lo, hi) = parse_range(&a.range)?;
                let d = PiecewiseConstant1D::new(&w, lo, hi)?;
                positive_sum(&w)?;
                Dist::Piecewise(d)
            }
            DistributionName::Piecewise2d => {
                let rows = a
                    .weights
                    .split(';')
                    .map(parse_list)
                    .collect::<Result<Vec<_>>>()?;
                let nu = rows[0].len();
                if rows.iter().any(|r| r.len() != nu) {
                    bail!("--weights: every row of a piecewise-2d density needs {nu} values");
                }
                let flat: Vec<f32> = rows.iter().flatten().map(|&x| x as f32).collect();
                let d = PiecewiseConstant2D::new(&flat, nu, rows.len(), Vec2::ZERO, Vec2::ONE)?;
                positive_sum(&flat)?;
                Dist::Piecewise2D(d, [nu, rows.len()])
            }
            DistributionName::Alias => Dist::Alias(AliasTable::new(&parse_list(&a.weights)?)?),
        })
    }

    fn describe(&self) -> String {
        match self {
            Dist::Exponential(e) => format!("exponential, λ = {}: x = -ln(1 - U)/λ", e.lambda()),
            Dist::Hemisphere => "uniform hemisphere, pdf 1/(2π)".into(),
            Dist::Cosine => "cosine-weighted hemisphere, pdf cos θ/π".into(),
            Dist::Sphere => "uniform sphere, pdf 1/(4π)".into(),
            Dist::Cone(c) => format!("uniform cone, cos θmax = {c}, pdf 1/(2π(1 - cos θmax))"),
            Dist::Disk => "concentric disk, pdf 1/π".into(),
            Dist::Triangle => "uniform triangle (barycentrics), pdf 1/area".into(),
            Dist::Piecewise(d) => format!("piecewise constant, {} pieces", d.len()),
            Dist::Piecewise2D(_, [nu, nv]) => format!("piecewise constant 2D, {nu} x {nv} cells"),
            Dist::Alias(t) => format!("alias table, {} outcomes", t.len()),
        }
    }

    /// One sample, as up to three components.
    #[inline]
    fn draw(&self, s: &mut AnySampler) -> [f64; 3] {
        let v3 = |w: Vec3| [w.x as f64, w.y as f64, w.z as f64];
        match self {
            Dist::Exponential(e) => [e.sample(s.next_1d() as f64), 0.0, 0.0],
            Dist::Hemisphere => v3(sample_uniform_hemisphere(s.next_2d())),
            Dist::Cosine => v3(sample_cosine_hemisphere(s.next_2d())),
            Dist::Sphere => v3(sample_uniform_sphere(s.next_2d())),
            Dist::Cone(c) => v3(sample_uniform_cone(s.next_2d(), *c)),
            Dist::Disk => {
                let p = sample_uniform_disk_concentric(s.next_2d());
                [p.x as f64, p.y as f64, 0.0]
            }
            Dist::Triangle => {
                let b = sample_uniform_triangle(s.next_2d());
                [b[0] as f64, b[1] as f64, b[2] as f64]
            }
            Dist::Piecewise(d) => [d.sample(s.next_1d()).x as f64, 0.0, 0.0],
            Dist::Piecewise2D(d, _) => {
                let (p, _) = d.sample(s.next_2d());
                [p.x as f64, p.y as f64, 0.0]
            }
            Dist::Alias(t) => [t.sample(s.next_1d()).index as f64, 0.0, 0.0],
        }
    }

    /// The exact mean and variance of each component.
    fn moments(&self) -> Vec<Moment> {
        let m = |name, mean, variance| Moment {
            name,
            mean,
            variance,
        };
        // Direction components with E[z], E[z²] given: x and y have mean 0 and variance
        // (1 - E[z²])/2 by symmetry in φ.
        let dir = |ez: f64, ez2: f64| {
            vec![
                m("x", 0.0, (1.0 - ez2) / 2.0),
                m("y", 0.0, (1.0 - ez2) / 2.0),
                m("z", ez, ez2 - ez * ez),
            ]
        };
        match self {
            Dist::Exponential(e) => vec![m("x", e.mean(), e.variance())],
            Dist::Hemisphere => dir(0.5, 1.0 / 3.0),
            Dist::Cosine => dir(2.0 / 3.0, 0.5),
            Dist::Sphere => dir(0.0, 1.0 / 3.0),
            Dist::Cone(c) => {
                // cos θ is uniform on [c, 1].
                let c = *c as f64;
                dir((1.0 + c) / 2.0, (1.0 + c + c * c) / 3.0)
            }
            Dist::Disk => vec![m("x", 0.0, 0.25), m("y", 0.0, 0.25)],
            Dist::Triangle => {
                // Each barycentric coordinate is Beta(1, 2): mean 1/3, variance 1/18.
                vec![
                    m("b0", 1.0 / 3.0, 1.0 / 18.0),
                    m("b1", 1.0 / 3.0, 1.0 / 18.0),
                    m("b2", 1.0 / 3.0, 1.0 / 18.0),
                ]
            }
            Dist::Piecewise(d) => {
                let (mean, var) = piecewise_moments(d);
                vec![m("x", mean, var)]
            }
            Dist::Piecewise2D(d, [nu, nv]) => {
                // Marginals: sum the cells' masses along rows and columns.
                let mut px = vec![0.0; *nu];
                let mut py = vec![0.0; *nv];
                for (j, py_j) in py.iter_mut().enumerate() {
                    for (i, px_i) in px.iter_mut().enumerate() {
                        let c =
                            Vec2::new((i as f32 + 0.5) / *nu as f32, (j as f32 + 0.5) / *nv as f32);
                        let mass = d.pdf(c) as f64 / (*nu * *nv) as f64;
                        *px_i += mass;
                        *py_j += mass;
                    }
                }
                let (mx, vx) = cell_moments(&px, 0.0, 1.0);
                let (my, vy) = cell_moments(&py, 0.0, 1.0);
                vec![m("x", mx, vx), m("y", my, vy)]
            }
            Dist::Alias(t) => {
                let mean: f64 = (0..t.len()).map(|i| i as f64 * t.pmf(i)).sum();
                let ex2: f64 = (0..t.len()).map(|i| (i * i) as f64 * t.pmf(i)).sum();
                vec![m("index", mean, ex2 - mean * mean)]
            }
        }
    }
}

/// Mean and variance of a density made of equal-width cells with masses `p` over [lo, hi].
fn cell_moments(p: &[f64], lo: f64, hi: f64) -> (f64, f64) {
    let w = (hi - lo) / p.len() as f64;
    let (mut ex, mut ex2) = (0.0, 0.0);
    for (i, &pi) in p.iter().enumerate() {
        let (a, b) = (lo + i as f64 * w, lo + (i + 1) as f64 * w);
        ex += pi * (a + b) / 2.0;
        ex2 += pi * (a * a + a * b + b * b) / 3.0;
    }
    (ex, ex2 - ex * ex)
}

fn piecewise_moments(d: &PiecewiseConstant1D) -> (f64, f64) {
    let p: Vec<f64> = (0..d.len()).map(|i| d.discrete_pmf(i) as f64).collect();
    let (lo, hi) = d.domain();
    cell_moments(&p, lo as f64, hi as f64)
}

/// Draws the `n` samples again (the same ones: same seed) and runs the chi-square test in the
/// parameterisation where the pdf is a density per unit area; also collects what the plot needs.
struct Fit {
    test: ChiSquareTest,
    plot: Option<plot::SamplePlot>,
}

fn samples(
    dist: &Dist,
    kind: SamplerKind,
    n: u32,
    seed: u64,
) -> impl Iterator<Item = [f64; 3]> + '_ {
    let mut s = kind.build(n, seed);
    (0..n).map(move |i| {
        s.start_pixel_sample([0, 0], i, 0);
        dist.draw(&mut s)
    })
}

fn fit(dist: &Dist, kind: SamplerKind, n: u32, seed: u64, want_plot: bool) -> Fit {
    const RES: [usize; 2] = [32, 32];
    let draw = || samples(dist, kind, n, seed);
    match dist {
        Dist::Exponential(e) => {
            let hi = 8.0 / e.lambda();
            let test = chi2_test_1d(draw().map(|p| p[0]), |x| e.pdf(x), [0.0, hi], 64);
            let plot = want_plot.then(|| {
                plot::SamplePlot::one_d(
                    draw().map(|p| p[0]),
                    [0.0, hi],
                    64,
                    |x| e.pdf(x),
                    |x| e.cdf(x),
                    Some((
                        0.75,
                        e.sample(0.75),
                        "U = 0.75 → x = -ln(1 - 0.75)/λ = ln 4/λ".into(),
                    )),
                    "x",
                )
            });
            Fit { test, plot }
        }
        Dist::Piecewise(d) => {
            let (lo, hi) = d.domain();
            let bins = d.len() * 4;
            let pdf = |x: f64| d.pdf(x as f32) as f64;
            let cdf = |x: f64| d.invert_sample(x as f32) as f64;
            let range = [lo as f64, hi as f64];
            let test = chi2_test_1d(draw().map(|p| p[0]), pdf, range, bins);
            let plot = want_plot.then(|| {
                plot::SamplePlot::one_d(draw().map(|p| p[0]), range, bins, pdf, cdf, None, "x")
            });
            Fit { test, plot }
        }
        Dist::Alias(t) => {
            let mut counts = vec![0u64; t.len()];
            draw().for_each(|p| counts[p[0] as usize] += 1);
            let pmf: Vec<f64> = (0..t.len()).map(|i| t.pmf(i)).collect();
            let test = chi2_test_discrete(&counts, &pmf);
            let plot = want_plot.then(|| plot::SamplePlot::discrete(&counts, &pmf));
            Fit { test, plot }
        }
        Dist::Piecewise2D(d, [nu, nv]) => {
            let pdf = |x: f64, y: f64| d.pdf(Vec2::new(x as f32, y as f32)) as f64;
            let res = [nu * 2, nv * 2];
            let dom = [[0.0, 1.0], [0.0, 1.0]];
            let test = chi2_test_2d(draw().map(|p| [p[0], p[1]]), pdf, dom, res);
            let plot = want_plot.then(|| {
                let xy = |p: [f64; 3]| [p[0], p[1]];
                plot::SamplePlot::two_d(draw(), (xy, dom), (xy, dom), pdf, res, ["x", "y"])
            });
            Fit { test, plot }
        }
        Dist::Disk => {
            // In polar coordinates (r, φ) the area density 1/π becomes r/π.
            let to_polar = |p: [f64; 3]| [(p[0] * p[0] + p[1] * p[1]).sqrt(), azimuth(p[1], p[0])];
            let pdf = |r: f64, _: f64| r * uniform_disk_pdf(Vec2::ZERO) as f64;
            let dom = [[0.0, 1.0], [0.0, TAU]];
            let test = chi2_test_2d(draw().map(to_polar), pdf, dom, RES);
            let plot = want_plot.then(|| {
                let xy = |p: [f64; 3]| [p[0], p[1]];
                let square = [[-1.0, 1.0], [-1.0, 1.0]];
                plot::SamplePlot::two_d(draw(), (xy, square), (to_polar, dom), pdf, RES, ["r", "φ"])
            });
            Fit { test, plot }
        }
        Dist::Triangle => {
            // In (b0, t = b1/(1 - b0)) the density 2 (per unit barycentric area) is 2 (1 - b0).
            let param = |p: [f64; 3]| [p[0], if p[0] < 1.0 { p[1] / (1.0 - p[0]) } else { 0.0 }];
            let pdf = |b0: f64, _: f64| uniform_triangle_pdf(0.5) as f64 * (1.0 - b0);
            let dom = [[0.0, 1.0], [0.0, 1.0]];
            let test = chi2_test_2d(draw().map(param), pdf, dom, RES);
            let plot = want_plot.then(|| {
                let xy = |p: [f64; 3]| [p[0], p[1]];
                plot::SamplePlot::two_d(
                    draw(),
                    (xy, dom),
                    (param, dom),
                    pdf,
                    RES,
                    ["b0", "b1/(1-b0)"],
                )
            });
            Fit { test, plot }
        }
        Dist::Hemisphere | Dist::Cosine | Dist::Sphere | Dist::Cone(_) => {
            let (z0, f): (f64, Box<dyn Fn(Vec3) -> f32>) = match dist {
                Dist::Hemisphere => (0.0, Box::new(|_| uniform_hemisphere_pdf())),
                Dist::Cosine => (0.0, Box::new(|w: Vec3| cosine_hemisphere_pdf(w.z))),
                Dist::Sphere => (-1.0, Box::new(|_| uniform_sphere_pdf())),
                Dist::Cone(c) => {
                    let c = *c;
                    (
                        c as f64,
                        Box::new(move |w: Vec3| if w.z >= c { uniform_cone_pdf(c) } else { 0.0 }),
                    )
                }
                _ => unreachable!("only direction distributions reach this arm"),
            };
            let pdf = |z: f64, phi: f64| {
                let r = (1.0 - z * z).max(0.0).sqrt();
                f(Vec3::new(
                    (r * phi.cos()) as f32,
                    (r * phi.sin()) as f32,
                    z as f32,
                )) as f64
            };
            let dom = [[z0, 1.0], [0.0, TAU]];
            let test = chi2_test_2d(draw().map(cos_theta_phi), pdf, dom, RES);
            let plot = want_plot.then(|| {
                // Points seen from above the pole: (x, y) of each direction.
                let xy = |p: [f64; 3]| [p[0], p[1]];
                let square = [[-1.0, 1.0], [-1.0, 1.0]];
                plot::SamplePlot::two_d(
                    draw(),
                    (xy, square),
                    (cos_theta_phi, dom),
                    pdf,
                    RES,
                    ["cos θ", "φ"],
                )
            });
            Fit { test, plot }
        }
    }
}

/// Runs `pathlab sample`.
/// The tests' conclusion in words, at α = 0.01.
fn verdict(n: u32, test: &pathlab_mc::stats::ChiSquareTest) -> String {
    if n < 2 {
        return format!(
            "{n} sample is too few: a standard error (and so z) needs at least 2, the chi-square test many more (use -n 10000 or more)"
        );
    }
    if test.dof == 0 {
        return format!(
            "{n} samples are too few for the chi-square test: every cell expects fewer than 5 (use -n 10000 or more)"
        );
    }
    if test.p_value >= 0.01 {
        format!(
            "consistent with the pdf at α = 0.01 (p = {:.3})",
            test.p_value
        )
    } else {
        format!(
            "NOT consistent with the pdf at α = 0.01 (p = {:.2e}): the samples do not follow it",
            test.p_value
        )
    }
}

pub fn run(args: &SampleArgs) -> Result<()> {
    if args.samples == 0 || args.samples > u32::MAX as u64 {
        bail!(
            "-n must be between 1 and {}, got {}",
            u32::MAX,
            args.samples
        );
    }
    let n = args.samples as u32;
    let format = args
        .plot
        .as_deref()
        .map(plot::Format::from_path)
        .transpose()?;
    let dist = Dist::from_args(args)?;
    let moments = dist.moments();

    // Pass 1, timed: draw and accumulate the moments.
    let start = Instant::now();
    let mut stats = vec![RunningStats::new(); moments.len()];
    for p in samples(&dist, args.sampler, n, args.seed) {
        for (s, v) in stats.iter_mut().zip(p) {
            s.push(v);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    // Pass 2: the same samples, binned for the goodness-of-fit test and the plot.
    let fit = fit(&dist, args.sampler, n, args.seed, format.is_some());

    let rows: Vec<_> = moments
        .iter()
        .zip(&stats)
        .map(|(m, s)| (m, s, z_test(s.mean(), s.std_error(), m.mean)))
        .collect();

    if let (Some(path), Some(format), Some(p)) = (&args.plot, format, &fit.plot) {
        let title = format!(
            "{} ({} samples, {})",
            dist.describe(),
            n,
            args.sampler.name()
        );
        plot::samples(path, format, &title, p)?;
    }

    if args.json {
        let out = json!({
            "distribution": format!("{:?}", args.distribution).to_lowercase(),
            "description": dist.describe(),
            "samples": n,
            "seed": args.seed,
            "sampler": args.sampler.name(),
            "components": rows.iter().map(|(m, s, z)| json!({
                "name": m.name,
                "mean": s.mean(),
                "std_error": s.std_error(),
                "exact_mean": m.mean,
                "z": if n >= 2 { json!(z.z) } else { json!(null) },
                "variance": s.variance(),
                "exact_variance": m.variance,
            })).collect::<Vec<_>>(),
            "chi_square": {
                "statistic": fit.test.statistic,
                "dof": fit.test.dof,
                "p_value": fit.test.p_value,
            },
            "verdict": verdict(n, &fit.test),
            "seconds": seconds,
            "samples_per_second": n as f64 / seconds.max(1e-9),
            "plot": args.plot,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }

    println!("{}", dist.describe());
    println!(
        "  {n} samples, {} sampler, seed {}",
        args.sampler.name(),
        args.seed
    );
    println!(
        "  {:<6} {:>12} {:>12} {:>8} {:>12} {:>12}",
        "", "mean", "exact mean", "z", "variance", "exact var"
    );
    for (m, s, z) in &rows {
        let z = if n >= 2 {
            format!("{:.2}", z.z)
        } else {
            "-".to_string()
        };
        println!(
            "  {:<6} {:>12.6} {:>12.6} {:>8} {:>12.6} {:>12.6}",
            m.name,
            s.mean(),
            m.mean,
            z,
            s.variance(),
            m.variance
        );
    }
    println!(
        "  chi-square fit against the pdf: statistic {:.1}, {} dof, p = {:.3}",
        fit.test.statistic, fit.test.dof, fit.test.p_value
    );
    println!("  {}", verdict(n, &fit.test));
    if args.sampler != SamplerKind::Independent {
        println!(
            "  (z and p assume independent samples; a {} sampler is more even than that)",
            args.sampler.name()
        );
    }
    println!("  {:.3e} samples/s", n as f64 / seconds.max(1e-9));
    if let Some(path) = &args.plot {
        println!("  plot written to {}", path.display());
    }
    Ok(())
}
