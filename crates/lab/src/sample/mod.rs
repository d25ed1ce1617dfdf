//! A distribution's samples against its exact pdf: the moments of each component with their
//! z-scores, a chi-square goodness-of-fit test in a parameterisation where the pdf is a density
//! per unit area, and what a plot of them needs. The experiment of `pathlab sample`.

mod report;

use crate::plot;
use anyhow::{bail, Result};
use glam::{Vec2, Vec3};
use pathlab_mc::distribution::{AliasTable, Exponential, PiecewiseConstant1D, PiecewiseConstant2D};
use pathlab_mc::estimator::RunningStats;
use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
use pathlab_mc::stats::{
    azimuth, chi2_test_1d, chi2_test_2d, chi2_test_discrete, cos_theta_phi, z_test, ChiSquareTest,
    ZTest,
};
use pathlab_mc::warp::*;
use std::f64::consts::TAU;
use std::time::Instant;

/// A checked distribution, ready to sample.
pub enum Distribution {
    /// Exponential, by inversion: x = -ln(1 - U)/λ.
    Exponential(Exponential),
    /// Directions uniform over the hemisphere.
    Hemisphere,
    /// Directions over the hemisphere with density cos θ / π.
    Cosine,
    /// Directions uniform over the sphere.
    Sphere,
    /// Directions uniform in the cone cos θ >= this.
    Cone(f32),
    /// Points uniform on the unit disk (concentric map).
    Disk,
    /// Barycentric coordinates uniform over a triangle.
    Triangle,
    /// A piecewise-constant density.
    Piecewise(PiecewiseConstant1D),
    /// A 2D piecewise-constant density over the unit square, with its `[columns, rows]`.
    Piecewise2D(PiecewiseConstant2D, [usize; 2]),
    /// Discrete outcomes by the alias method.
    Alias(AliasTable),
}

/// Exact moments of one component of a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moment {
    /// The component's name (`x`, `z`, `b0`, `index`, ...).
    pub name: &'static str,
    /// Its exact mean.
    pub mean: f64,
    /// Its exact variance.
    pub variance: f64,
}

/// A density of these weights needs a positive total: the library reads all zeros as
/// uniform (what an environment map's black row needs), which asked for by name is a mistake.
fn positive_sum(w: &[f32]) -> Result<()> {
    let total: f64 = w.iter().map(|&x| x as f64).sum();
    if !(total > 0.0 && total.is_finite()) {
        bail!("the weights must have a finite, positive sum (got {total})");
    }
    Ok(())
}

impl Distribution {
    /// The exponential distribution of rate `lambda`.
    pub fn exponential(lambda: f64) -> Result<Self> {
        Ok(Distribution::Exponential(Exponential::new(lambda)?))
    }

    /// Directions uniform in the cone of half-angle acos(`cos_theta_max`).
    pub fn cone(cos_theta_max: f64) -> Result<Self> {
        if !(-1.0..1.0).contains(&cos_theta_max) {
            bail!("cos θmax must be in [-1, 1), got {cos_theta_max}");
        }
        Ok(Distribution::Cone(cos_theta_max as f32))
    }

    /// The piecewise-constant density of `weights` over `[lo, hi)`.
    pub fn piecewise(weights: &[f64], lo: f32, hi: f32) -> Result<Self> {
        let w: Vec<f32> = weights.iter().map(|&x| x as f32).collect();
        let d = PiecewiseConstant1D::new(&w, lo, hi)?;
        positive_sum(&w)?;
        Ok(Distribution::Piecewise(d))
    }

    /// The 2D piecewise-constant density over the unit square whose rows are `rows`.
    pub fn piecewise_2d(rows: &[Vec<f64>]) -> Result<Self> {
        let nu = rows.first().map_or(0, Vec::len);
        if rows.iter().any(|r| r.len() != nu) {
            bail!("every row of a piecewise-2d density needs {nu} values");
        }
        let flat: Vec<f32> = rows.iter().flatten().map(|&x| x as f32).collect();
        let d = PiecewiseConstant2D::new(&flat, nu, rows.len(), Vec2::ZERO, Vec2::ONE)?;
        positive_sum(&flat)?;
        Ok(Distribution::Piecewise2D(d, [nu, rows.len()]))
    }

    /// Outcomes 0..n with probabilities proportional to `weights`.
    pub fn alias(weights: &[f64]) -> Result<Self> {
        Ok(Distribution::Alias(AliasTable::new(weights)?))
    }

    /// A line saying what is sampled and how.
    pub fn describe(&self) -> String {
        match self {
            Distribution::Exponential(e) => {
                format!("exponential, λ = {}: x = -ln(1 - U)/λ", e.lambda())
            }
            Distribution::Hemisphere => "uniform hemisphere, pdf 1/(2π)".into(),
            Distribution::Cosine => "cosine-weighted hemisphere, pdf cos θ/π".into(),
            Distribution::Sphere => "uniform sphere, pdf 1/(4π)".into(),
            Distribution::Cone(c) => {
                format!("uniform cone, cos θmax = {c}, pdf 1/(2π(1 - cos θmax))")
            }
            Distribution::Disk => "concentric disk, pdf 1/π".into(),
            Distribution::Triangle => "uniform triangle (barycentrics), pdf 1/area".into(),
            Distribution::Piecewise(d) => format!("piecewise constant, {} pieces", d.len()),
            Distribution::Piecewise2D(_, [nu, nv]) => {
                format!("piecewise constant 2D, {nu} x {nv} cells")
            }
            Distribution::Alias(t) => format!("alias table, {} outcomes", t.len()),
        }
    }

    /// One sample, as up to three components.
    #[inline]
    pub fn draw(&self, s: &mut AnySampler) -> [f64; 3] {
        let v3 = |w: Vec3| [w.x as f64, w.y as f64, w.z as f64];
        match self {
            Distribution::Exponential(e) => [e.sample(s.next_1d() as f64), 0.0, 0.0],
            Distribution::Hemisphere => v3(sample_uniform_hemisphere(s.next_2d())),
            Distribution::Cosine => v3(sample_cosine_hemisphere(s.next_2d())),
            Distribution::Sphere => v3(sample_uniform_sphere(s.next_2d())),
            Distribution::Cone(c) => v3(sample_uniform_cone(s.next_2d(), *c)),
            Distribution::Disk => {
                let p = sample_uniform_disk_concentric(s.next_2d());
                [p.x as f64, p.y as f64, 0.0]
            }
            Distribution::Triangle => {
                let b = sample_uniform_triangle(s.next_2d());
                [b[0] as f64, b[1] as f64, b[2] as f64]
            }
            Distribution::Piecewise(d) => [d.sample(s.next_1d()).x as f64, 0.0, 0.0],
            Distribution::Piecewise2D(d, _) => {
                let (p, _) = d.sample(s.next_2d());
                [p.x as f64, p.y as f64, 0.0]
            }
            Distribution::Alias(t) => [t.sample(s.next_1d()).index as f64, 0.0, 0.0],
        }
    }

    /// The exact mean and variance of each component.
    pub fn moments(&self) -> Vec<Moment> {
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
            Distribution::Exponential(e) => vec![m("x", e.mean(), e.variance())],
            Distribution::Hemisphere => dir(0.5, 1.0 / 3.0),
            Distribution::Cosine => dir(2.0 / 3.0, 0.5),
            Distribution::Sphere => dir(0.0, 1.0 / 3.0),
            Distribution::Cone(c) => {
                // cos θ is uniform on [c, 1].
                let c = *c as f64;
                dir((1.0 + c) / 2.0, (1.0 + c + c * c) / 3.0)
            }
            Distribution::Disk => vec![m("x", 0.0, 0.25), m("y", 0.0, 0.25)],
            Distribution::Triangle => {
                // Each barycentric coordinate is Beta(1, 2): mean 1/3, variance 1/18.
                vec![
                    m("b0", 1.0 / 3.0, 1.0 / 18.0),
                    m("b1", 1.0 / 3.0, 1.0 / 18.0),
                    m("b2", 1.0 / 3.0, 1.0 / 18.0),
                ]
            }
            Distribution::Piecewise(d) => {
                let (mean, var) = piecewise_moments(d);
                vec![m("x", mean, var)]
            }
            Distribution::Piecewise2D(d, [nu, nv]) => {
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
            Distribution::Alias(t) => {
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

/// The chi-square test of the samples and, if asked for, what the plot needs.
struct Fit {
    test: ChiSquareTest,
    plot: Option<plot::SamplePlot>,
}

/// The `n` samples of `dist` with this sampler and seed (the same ones on every call).
fn samples(
    dist: &Distribution,
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

/// Draws the `n` samples again (the same ones: same seed) and runs the chi-square test in the
/// parameterisation where the pdf is a density per unit area.
fn fit(dist: &Distribution, kind: SamplerKind, n: u32, seed: u64, want_plot: bool) -> Fit {
    const RES: [usize; 2] = [32, 32];
    let draw = || samples(dist, kind, n, seed);
    match dist {
        Distribution::Exponential(e) => {
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
        Distribution::Piecewise(d) => {
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
        Distribution::Alias(t) => {
            let mut counts = vec![0u64; t.len()];
            draw().for_each(|p| counts[p[0] as usize] += 1);
            let pmf: Vec<f64> = (0..t.len()).map(|i| t.pmf(i)).collect();
            let test = chi2_test_discrete(&counts, &pmf);
            let plot = want_plot.then(|| plot::SamplePlot::discrete(&counts, &pmf));
            Fit { test, plot }
        }
        Distribution::Piecewise2D(d, [nu, nv]) => {
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
        Distribution::Disk => {
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
        Distribution::Triangle => {
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
        Distribution::Hemisphere
        | Distribution::Cosine
        | Distribution::Sphere
        | Distribution::Cone(_) => direction_fit(dist, draw, want_plot),
    }
}

/// [`fit`] of a distribution of directions, in (cos θ, φ), where the pdf per solid angle is a
/// density per unit area.
fn direction_fit<I: Iterator<Item = [f64; 3]>>(
    dist: &Distribution,
    draw: impl Fn() -> I,
    want_plot: bool,
) -> Fit {
    const RES: [usize; 2] = [32, 32];
    let (z0, f): (f64, Box<dyn Fn(Vec3) -> f32>) = match dist {
        Distribution::Hemisphere => (0.0, Box::new(|_| uniform_hemisphere_pdf())),
        Distribution::Cosine => (0.0, Box::new(|w: Vec3| cosine_hemisphere_pdf(w.z))),
        Distribution::Sphere => (-1.0, Box::new(|_| uniform_sphere_pdf())),
        Distribution::Cone(c) => {
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

/// What sampling a distribution showed.
pub struct SampleReport {
    /// What was sampled ([`Distribution::describe`]).
    pub description: String,
    /// Per component: its exact moments, the samples' statistics and the z-test of the mean.
    pub components: Vec<(Moment, RunningStats, ZTest)>,
    /// The chi-square goodness-of-fit test against the pdf.
    pub chi_square: ChiSquareTest,
    /// Seconds to draw the samples and accumulate their moments.
    pub seconds: f64,
    /// The plot's data, when asked for.
    pub plot: Option<plot::SamplePlot>,
    /// Samples drawn.
    pub samples: u32,
    /// Where the uniform numbers came from.
    pub sampler: SamplerKind,
    /// Their seed.
    pub seed: u64,
}

/// Draws `n` samples of `dist` (timed, accumulating each component's moments), then the same
/// samples again for the chi-square test and, with `want_plot`, the plot.
pub fn run(
    dist: &Distribution,
    sampler: SamplerKind,
    n: u32,
    seed: u64,
    want_plot: bool,
) -> SampleReport {
    let moments = dist.moments();
    let start = Instant::now();
    let mut stats = vec![RunningStats::new(); moments.len()];
    for p in samples(dist, sampler, n, seed) {
        for (s, v) in stats.iter_mut().zip(p) {
            s.push(v);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let fit = fit(dist, sampler, n, seed, want_plot);
    let components = moments
        .into_iter()
        .zip(stats)
        .map(|(m, s)| {
            let z = z_test(s.mean(), s.std_error(), m.mean);
            (m, s, z)
        })
        .collect();
    SampleReport {
        description: dist.describe(),
        components,
        chi_square: fit.test,
        seconds,
        plot: fit.plot,
        samples: n,
        sampler,
        seed,
    }
}

/// The tests' conclusion in words, at α = 0.01.
pub fn verdict(n: u32, test: &pathlab_mc::stats::ChiSquareTest) -> String {
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
