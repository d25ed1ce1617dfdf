//! Plots of samples and convergence, drawn with `plotters` to PNG or SVG.
//!
//! Text is rendered with the DejaVu Sans font compiled into the binary, so plots look the same
//! on every machine and need no system fonts.

use anyhow::{anyhow, bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use std::path::Path;
use std::sync::Once;

/// Output format of a plot, from the file name's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// A PNG bitmap.
    Png,
    /// An SVG drawing.
    Svg,
}

impl Format {
    /// The format a path's extension asks for.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
        {
            Some(e) if e == "png" => Ok(Format::Png),
            Some(e) if e == "svg" => Ok(Format::Svg),
            _ => bail!("{}: plots are written as .png or .svg", path.display()),
        }
    }
}

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("plotting failed: {e}")
}

/// A plot that could not be written, naming its file (the backend's own error is the cause).
fn write_err<E: std::fmt::Display>(path: &Path, e: E) -> anyhow::Error {
    // The backend wraps the file's I/O error in its own debug text; ask the file system.
    if let Err(io) = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
    {
        return anyhow!("cannot write the plot {}: {io}", path.display());
    }
    anyhow!("cannot write the plot {}: {e}", path.display())
}

/// Registers the embedded font for plotters' text (idempotent).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a valid TrueType file shipped by the `dejavu` crate; if it were rejected,
        // text would be missing from plots but nothing else would break.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Runs `$body` with `$root` bound to a drawing area of the requested format, then writes it.
macro_rules! with_root {
    ($path:expr, $format:expr, $size:expr, |$root:ident| $body:expr) => {{
        register_font();
        match $format {
            Format::Png => {
                let $root = BitMapBackend::new($path, $size).into_drawing_area();
                $body?;
                $root.present().map_err(|e| write_err($path, e))?;
            }
            Format::Svg => {
                let $root = SVGBackend::new($path, $size).into_drawing_area();
                $body?;
                $root.present().map_err(|e| write_err($path, e))?;
            }
        }
        Ok(())
    }};
}

/// What `pathlab sample --plot` draws.
pub enum SamplePlot {
    /// A 1D density: histogram against the pdf, and empirical CDF against the CDF.
    OneD {
        /// (left, right, density) of each histogram bar.
        hist: Vec<(f64, f64, f64)>,
        /// The pdf on a fine grid.
        pdf: Vec<(f64, f64)>,
        /// The exact CDF on a fine grid.
        cdf: Vec<(f64, f64)>,
        /// The empirical CDF at the histogram's bin edges.
        empirical_cdf: Vec<(f64, f64)>,
        /// A point (U, x, label) to mark on the CDF: the inversion method at work.
        marker: Option<(f64, f64, String)>,
        /// Name of the variable.
        label: &'static str,
    },
    /// A discrete distribution: observed frequencies against the pmf.
    Discrete {
        /// Observed relative frequency of each outcome.
        freq: Vec<f64>,
        /// Its probability.
        pmf: Vec<f64>,
    },
    /// A 2D warp: the point set, and the sample density against the pdf in the
    /// parameterisation where the pdf is a density per unit area.
    TwoD {
        /// Up to a few thousand of the points, in their natural coordinates.
        points: Vec<[f64; 2]>,
        /// Axis ranges of the point plot.
        point_domain: [[f64; 2]; 2],
        /// Sample density per cell of the parameter grid (row-major).
        density: Vec<f64>,
        /// Mean pdf per cell of the parameter grid.
        pdf: Vec<f64>,
        /// The parameter grid's ranges and resolution.
        param_domain: [[f64; 2]; 2],
        /// Cells per axis.
        res: [usize; 2],
        /// Names of the parameters.
        labels: [&'static str; 2],
    },
}

/// Points shown in the scatter plot of a 2D warp.
const MAX_POINTS: usize = 4000;

impl SamplePlot {
    /// Histogram, pdf and CDF of 1D samples over `range` in `bins` bins.
    pub fn one_d(
        samples: impl Iterator<Item = f64>,
        range: [f64; 2],
        bins: usize,
        pdf: impl Fn(f64) -> f64,
        cdf: impl Fn(f64) -> f64,
        marker: Option<(f64, f64, String)>,
        label: &'static str,
    ) -> Self {
        let w = (range[1] - range[0]) / bins as f64;
        let mut counts = vec![0u64; bins];
        let mut below = 0u64;
        let mut n = 0u64;
        for x in samples {
            n += 1;
            if x < range[0] {
                below += 1;
            } else if x < range[1] {
                counts[(((x - range[0]) / w) as usize).min(bins - 1)] += 1;
            }
        }
        let n = n.max(1) as f64;
        let hist = (0..bins)
            .map(|i| {
                let a = range[0] + i as f64 * w;
                (a, a + w, counts[i] as f64 / (n * w))
            })
            .collect();
        let mut acc = below as f64;
        let mut empirical_cdf = vec![(range[0], acc / n)];
        for (i, &c) in counts.iter().enumerate() {
            acc += c as f64;
            empirical_cdf.push((range[0] + (i + 1) as f64 * w, acc / n));
        }
        let fine = |f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
            (0..=600)
                .map(|i| {
                    let x = range[0] + (range[1] - range[0]) * i as f64 / 600.0;
                    (x, f(x))
                })
                .collect()
        };
        SamplePlot::OneD {
            hist,
            pdf: fine(&pdf),
            cdf: fine(&cdf),
            empirical_cdf,
            marker,
            label,
        }
    }

    /// Observed counts against probabilities.
    pub fn discrete(counts: &[u64], pmf: &[f64]) -> Self {
        let n = counts.iter().sum::<u64>().max(1) as f64;
        SamplePlot::Discrete {
            freq: counts.iter().map(|&c| c as f64 / n).collect(),
            pmf: pmf.to_vec(),
        }
    }

    /// A 2D warp: `samples` shown by `to_point` over `point_domain`, and mapped by `to_param`
    /// into the parameter rectangle where `pdf` is a density per unit area.
    pub fn two_d(
        samples: impl Iterator<Item = [f64; 3]>,
        (to_point, point_domain): (impl Fn([f64; 3]) -> [f64; 2], [[f64; 2]; 2]),
        (to_param, param_domain): (impl Fn([f64; 3]) -> [f64; 2], [[f64; 2]; 2]),
        pdf: impl Fn(f64, f64) -> f64,
        res: [usize; 2],
        labels: [&'static str; 2],
    ) -> Self {
        let [[x0, x1], [y0, y1]] = param_domain;
        let (dx, dy) = ((x1 - x0) / res[0] as f64, (y1 - y0) / res[1] as f64);
        let mut counts = vec![0u64; res[0] * res[1]];
        let mut shown = Vec::with_capacity(MAX_POINTS);
        let mut n = 0u64;
        for p in samples {
            n += 1;
            if shown.len() < MAX_POINTS {
                shown.push(to_point(p));
            }
            let q = to_param(p);
            if q[0] >= x0 && q[0] < x1 && q[1] >= y0 && q[1] < y1 {
                let i = (((q[0] - x0) / dx) as usize).min(res[0] - 1);
                let j = (((q[1] - y0) / dy) as usize).min(res[1] - 1);
                counts[j * res[0] + i] += 1;
            }
        }
        let n = n.max(1) as f64;
        let density = counts.iter().map(|&c| c as f64 / (n * dx * dy)).collect();
        let mut pdf_grid = Vec::with_capacity(res[0] * res[1]);
        for j in 0..res[1] {
            for i in 0..res[0] {
                // Mean of the pdf over the cell, by a 4 x 4 midpoint rule.
                let mut s = 0.0;
                for b in 0..4 {
                    for a in 0..4 {
                        let x = x0 + (i as f64 + (a as f64 + 0.5) / 4.0) * dx;
                        let y = y0 + (j as f64 + (b as f64 + 0.5) / 4.0) * dy;
                        s += pdf(x, y);
                    }
                }
                pdf_grid.push(s / 16.0);
            }
        }
        SamplePlot::TwoD {
            points: shown,
            point_domain,
            density,
            pdf: pdf_grid,
            param_domain,
            res,
            labels,
        }
    }
}

/// Writes the plot of `pathlab sample`.
pub fn samples(path: &Path, format: Format, title: &str, plot: &SamplePlot) -> Result<()> {
    let size = match plot {
        SamplePlot::TwoD { .. } => (1500, 560),
        _ => (1200, 520),
    };
    with_root!(path, format, size, |root| draw_samples(&root, title, plot))
}

fn draw_samples<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    plot: &SamplePlot,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    match plot {
        SamplePlot::OneD {
            hist,
            pdf,
            cdf,
            empirical_cdf,
            marker,
            label,
        } => {
            let panels = root.split_evenly((1, 2));
            let (x0, x1) = (hist[0].0, hist[hist.len() - 1].1);
            let ymax = hist
                .iter()
                .map(|h| h.2)
                .chain(pdf.iter().map(|p| p.1))
                .fold(0.0f64, f64::max)
                * 1.1;
            let mut chart = ChartBuilder::on(&panels[0])
                .caption("histogram of samples and the pdf", ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, 0.0..ymax.max(1e-12))
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(*label)
                .y_desc("density")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(
                    hist.iter().map(|&(a, b, d)| {
                        Rectangle::new([(a, 0.0), (b, d)], BLUE.mix(0.35).filled())
                    }),
                )
                .map_err(err)?
                .label("samples (normalised histogram)")
                .legend(|(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 16, y + 5)], BLUE.mix(0.35).filled())
                });
            chart
                .draw_series(LineSeries::new(pdf.iter().copied(), RED.stroke_width(2)))
                .map_err(err)?
                .label("pdf")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(2)));
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;

            let mut chart = ChartBuilder::on(&panels[1])
                .caption("CDF: U = P(X ≤ x), inverted to sample", ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, 0.0..1.05)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(*label)
                .y_desc("U")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(LineSeries::new(cdf.iter().copied(), RED.stroke_width(2)))
                .map_err(err)?
                .label("CDF")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(2)));
            chart
                .draw_series(LineSeries::new(
                    empirical_cdf.iter().copied(),
                    BLUE.stroke_width(1),
                ))
                .map_err(err)?
                .label("empirical CDF of the samples")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE));
            if let Some((u, x, text)) = marker {
                let style = BLACK.stroke_width(1);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(x0, *u), (*x, *u), (*x, 0.0)],
                        style,
                    )))
                    .map_err(err)?;
                chart
                    .draw_series(std::iter::once(Circle::new((*x, *u), 4, BLACK.filled())))
                    .map_err(err)?;
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{text} = {x:.4}"),
                        (*x + 0.02 * (x1 - x0), *u - 0.08),
                        ("sans-serif", 15),
                    )))
                    .map_err(err)?;
            }
            legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        }
        SamplePlot::Discrete { freq, pmf } => {
            let k = freq.len();
            let ymax = freq.iter().chain(pmf).fold(0.0f64, |a, &b| a.max(b)) * 1.15;
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    "observed frequency and probability of each outcome",
                    ("sans-serif", 18),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(-0.5..(k as f64 - 0.5), 0.0..ymax.max(1e-12))
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("outcome")
                .y_desc("probability")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(freq.iter().enumerate().map(|(i, &f)| {
                    let x = i as f64;
                    Rectangle::new([(x - 0.35, 0.0), (x + 0.35, f)], BLUE.mix(0.35).filled())
                }))
                .map_err(err)?
                .label("observed frequency")
                .legend(|(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 16, y + 5)], BLUE.mix(0.35).filled())
                });
            chart
                .draw_series(pmf.iter().enumerate().map(|(i, &p)| {
                    let x = i as f64;
                    PathElement::new(vec![(x - 0.4, p), (x + 0.4, p)], RED.stroke_width(3))
                }))
                .map_err(err)?
                .label("pmf")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(3)));
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        SamplePlot::TwoD {
            points,
            point_domain,
            density,
            pdf,
            param_domain,
            res,
            labels,
        } => {
            let panels = root.split_evenly((1, 3));
            let [[px0, px1], [py0, py1]] = *point_domain;
            let mut chart = ChartBuilder::on(&panels[0])
                .caption(format!("first {} points", points.len()), ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d(px0..px1, py0..py1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .light_line_style(WHITE)
                .x_desc("x")
                .y_desc("y")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|p| Circle::new((p[0], p[1]), 1, BLUE.filled())),
                )
                .map_err(err)?;
            let vmax = density
                .iter()
                .chain(pdf)
                .fold(0.0f64, |a, &b| a.max(b))
                .max(1e-12);
            for (panel, values, caption) in [
                (&panels[1], density, "sample density"),
                (&panels[2], pdf, "pdf"),
            ] {
                heat_map(panel, values, *param_domain, *res, *labels, caption, vmax)?;
            }
        }
    }
    Ok(())
}

/// Draws the legend of `chart`'s labelled series at `position`.
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

fn heat_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    values: &[f64],
    domain: [[f64; 2]; 2],
    res: [usize; 2],
    labels: [&str; 2],
    caption: &str,
    vmax: f64,
) -> Result<()> {
    let [[x0, x1], [y0, y1]] = domain;
    let (dx, dy) = ((x1 - x0) / res[0] as f64, (y1 - y0) / res[1] as f64);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "{caption} over ({}, {}); colour 0 .. {vmax:.3}",
                labels[0], labels[1]
            ),
            ("sans-serif", 16),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(labels[0])
        .y_desc(labels[1])
        .draw()
        .map_err(err)?;
    chart
        .draw_series(values.iter().enumerate().map(|(c, &v)| {
            let (i, j) = (c % res[0], c / res[0]);
            let a = (x0 + i as f64 * dx, y0 + j as f64 * dy);
            let b = (a.0 + dx, a.1 + dy);
            Rectangle::new(
                [a, b],
                ViridisRGB::get_color_normalized(v.min(vmax), 0.0, vmax).filled(),
            )
        }))
        .map_err(err)?;
    Ok(())
}

/// One point of a convergence curve.
#[derive(Clone, Copy, Debug)]
pub struct ConvergencePoint {
    /// Number of samples.
    pub n: f64,
    /// The estimate of one run.
    pub estimate: f64,
    /// Half-width of the 95% interval of one run's estimate (1.96 × the spread of runs).
    pub ci_half: f64,
    /// Root-mean-square error of the runs.
    pub rmse: f64,
}

/// The convergence of one sampler.
pub struct ConvergenceSeries {
    /// Sampler name.
    pub name: String,
    /// Least-squares slope of log RMSE against log N.
    pub slope: f64,
    /// Points at increasing N.
    pub points: Vec<ConvergencePoint>,
}

/// Least-squares slope of log(rmse) against log(n), over the points with a positive error
/// ([`pathlab_mc::estimator::loglog_slope`]).
pub fn fitted_slope(points: &[ConvergencePoint]) -> f64 {
    pathlab_mc::estimator::loglog_slope(points.iter().map(|p| (p.n, p.rmse)))
}

const SERIES_COLOURS: [RGBColor; 3] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
];

/// Writes the convergence plot of `pathlab integrate --convergence`: estimates with their 95%
/// intervals against N, and RMSE against N on log-log axes with the fitted slopes.
pub fn convergence(
    path: &Path,
    format: Format,
    title: &str,
    series: &[ConvergenceSeries],
    exact: Option<f64>,
    vs_exact: bool,
) -> Result<()> {
    with_root!(path, format, (1400, 600), |root| draw_convergence(
        &root, title, series, exact, vs_exact
    ))
}

fn draw_convergence<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    series: &[ConvergenceSeries],
    exact: Option<f64>,
    vs_exact: bool,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let panels = root.split_evenly((1, 2));
    let all = || series.iter().flat_map(|s| s.points.iter());
    let nmin = all().map(|p| p.n).fold(f64::INFINITY, f64::min);
    let nmax = all().map(|p| p.n).fold(0.0, f64::max);
    let lo = all()
        .map(|p| p.estimate - p.ci_half)
        .fold(f64::INFINITY, f64::min);
    let hi = all()
        .map(|p| p.estimate + p.ci_half)
        .fold(f64::NEG_INFINITY, f64::max);
    let pad = ((hi - lo) * 0.05).max(1e-12);

    let mut chart = ChartBuilder::on(&panels[0])
        .caption("estimate with 95% interval (one run)", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d((nmin..nmax * 1.2).log_scale(), (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("samples N")
        .y_desc("estimate")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(err)?;
    for (s, colour) in series.iter().zip(SERIES_COLOURS) {
        chart
            .draw_series(s.points.iter().map(|p| {
                PathElement::new(
                    vec![(p.n, p.estimate - p.ci_half), (p.n, p.estimate + p.ci_half)],
                    colour.mix(0.6),
                )
            }))
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                s.points.iter().map(|p| (p.n, p.estimate)),
                colour.stroke_width(2),
            ))
            .map_err(err)?
            .label(s.name.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
    }
    if let Some(x) = exact {
        chart
            .draw_series(LineSeries::new(
                vec![(nmin, x), (nmax * 1.2, x)],
                BLACK.stroke_width(1),
            ))
            .map_err(err)?
            .label("exact")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;

    let errs = || all().map(|p| p.rmse).filter(|&e| e > 0.0 && e.is_finite());
    let emin = errs().fold(f64::INFINITY, f64::min);
    let emax = errs().fold(0.0, f64::max);
    let (emin, emax) = if emin.is_finite() && emax > 0.0 {
        (emin / 2.0, emax * 2.0)
    } else {
        (1e-6, 1.0)
    };
    let what = if vs_exact {
        "RMSE vs the exact value"
    } else {
        "RMSE vs the pooled largest runs"
    };
    let mut chart = ChartBuilder::on(&panels[1])
        .caption(format!("{what} (log-log)"), ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d((nmin..nmax * 1.2).log_scale(), (emin..emax).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("samples N")
        .y_desc("root-mean-square error")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    for (s, colour) in series.iter().zip(SERIES_COLOURS) {
        chart
            .draw_series(LineSeries::new(
                s.points
                    .iter()
                    .filter(|p| p.rmse > 0.0)
                    .map(|p| (p.n, p.rmse)),
                colour.stroke_width(2),
            ))
            .map_err(err)?
            .label(format!("{} (slope {:.2})", s.name, s.slope))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
    }
    // A reference line of slope -1/2 through the first independent point.
    if let Some(p) = series
        .first()
        .and_then(|s| s.points.first())
        .filter(|p| p.rmse > 0.0)
    {
        let line: Vec<(f64, f64)> = [p.n, nmax]
            .iter()
            .map(|&n| (n, p.rmse * (n / p.n).powf(-0.5)))
            .collect();
        chart
            .draw_series(LineSeries::new(line, BLACK.stroke_width(1)))
            .map_err(err)?
            .label("N^-1/2")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
    }
    legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}

/// One curve of `pathlab converge`: (samples per pixel, seconds, RMSE) points.
pub struct RmseCurve {
    /// Legend name.
    pub name: String,
    /// Points at increasing sample counts.
    pub points: Vec<(f64, f64, f64)>,
    /// Least-squares slope of log RMSE against log samples.
    pub slope: f64,
}

/// Writes RMSE against samples per pixel and against seconds, log-log, one curve each.
pub fn rmse_curves(path: &Path, format: Format, title: &str, curves: &[RmseCurve]) -> Result<()> {
    with_root!(path, format, (1400, 600), |root| draw_rmse_curves(
        &root, title, curves
    ))
}

fn draw_rmse_curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    curves: &[RmseCurve],
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let panels = root.split_evenly((1, 2));
    let all = || {
        curves
            .iter()
            .flat_map(|c| c.points.iter())
            .filter(|p| p.2 > 0.0 && p.1 > 0.0)
    };
    let range = |f: fn(&(f64, f64, f64)) -> f64| {
        let lo = all().map(f).fold(f64::INFINITY, f64::min);
        let hi = all().map(f).fold(0.0, f64::max);
        if lo.is_finite() && hi > lo {
            (lo / 1.5, hi * 1.5)
        } else {
            (1e-3, 1.0)
        }
    };
    let (e0, e1) = range(|p| p.2);
    for (panel, (xi, label)) in panels
        .iter()
        .zip([(0usize, "samples per pixel"), (1usize, "seconds")])
    {
        let (x0, x1) = if xi == 0 {
            range(|p| p.0)
        } else {
            range(|p| p.1)
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("RMSE against the reference vs {label} (log-log)"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (e0..e1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(label)
            .y_desc("root-mean-square error")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_label_formatter(&|v| {
                if *v >= 1.0 {
                    format!("{v:.0}")
                } else {
                    format!("{v:.2}")
                }
            })
            .draw()
            .map_err(err)?;
        for (c, colour) in curves.iter().zip(SERIES_COLOURS.iter().cycle()) {
            let colour = *colour;
            let pts: Vec<(f64, f64)> = c
                .points
                .iter()
                .filter(|p| p.2 > 0.0 && p.1 > 0.0)
                .map(|p| (if xi == 0 { p.0 } else { p.1 }, p.2))
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(if xi == 0 {
                    format!("{} (slope {:.2})", c.name, c.slope)
                } else {
                    c.name.clone()
                })
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(err)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    Ok(())
}
