//! The plots of `pathlab sample`: a 1D density, a discrete distribution, a 2D warp.

use super::{err, heat_map, legend, Format};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// What `pathlab sample --plot` draws.
pub enum SamplePlot {
    /// A 1D density: histogram against the pdf, and empirical CDF against the CDF.
    OneD(Density1D),
    /// A discrete distribution: observed frequencies against the pmf.
    Discrete(Frequencies),
    /// A 2D warp: the point set, and the sample density against the pdf.
    TwoD(Warp2D),
}

/// A 1D density: histogram against the pdf, and empirical CDF against the CDF.
#[derive(Clone, Debug)]
pub struct Density1D {
    /// (left, right, density) of each histogram bar.
    pub hist: Vec<(f64, f64, f64)>,
    /// The pdf on a fine grid.
    pub pdf: Vec<(f64, f64)>,
    /// The exact CDF on a fine grid.
    pub cdf: Vec<(f64, f64)>,
    /// The empirical CDF at the histogram's bin edges.
    pub empirical_cdf: Vec<(f64, f64)>,
    /// A point (U, x, label) to mark on the CDF: the inversion method at work.
    pub marker: Option<(f64, f64, String)>,
    /// Name of the variable.
    pub label: &'static str,
}

/// A discrete distribution: observed frequencies against the pmf.
#[derive(Clone, Debug)]
pub struct Frequencies {
    /// Observed relative frequency of each outcome.
    pub freq: Vec<f64>,
    /// Its probability.
    pub pmf: Vec<f64>,
}

/// A 2D warp: the point set, and the sample density against the pdf in the
/// parameterisation where the pdf is a density per unit area.
#[derive(Clone, Debug)]
pub struct Warp2D {
    /// Up to a few thousand of the points, in their natural coordinates.
    pub points: Vec<[f64; 2]>,
    /// Axis ranges of the point plot.
    pub point_domain: [[f64; 2]; 2],
    /// Sample density per cell of the parameter grid (row-major).
    pub density: Vec<f64>,
    /// Mean pdf per cell of the parameter grid.
    pub pdf: Vec<f64>,
    /// The parameter grid's ranges and resolution.
    pub param_domain: [[f64; 2]; 2],
    /// Cells per axis.
    pub res: [usize; 2],
    /// Names of the parameters.
    pub labels: [&'static str; 2],
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
        SamplePlot::OneD(Density1D {
            hist,
            pdf: fine(&pdf),
            cdf: fine(&cdf),
            empirical_cdf,
            marker,
            label,
        })
    }

    /// Observed counts against probabilities.
    pub fn discrete(counts: &[u64], pmf: &[f64]) -> Self {
        let n = counts.iter().sum::<u64>().max(1) as f64;
        SamplePlot::Discrete(Frequencies {
            freq: counts.iter().map(|&c| c as f64 / n).collect(),
            pmf: pmf.to_vec(),
        })
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
        SamplePlot::TwoD(Warp2D {
            points: shown,
            point_domain,
            density,
            pdf: pdf_grid,
            param_domain,
            res,
            labels,
        })
    }
}

/// Writes the plot of `pathlab sample`.
pub fn samples(path: &Path, format: Format, title: &str, plot: &SamplePlot) -> Result<()> {
    let size = match plot {
        SamplePlot::TwoD(_) => (1500, 560),
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
        SamplePlot::OneD(p) => draw_density_1d(&root, p),
        SamplePlot::Discrete(p) => draw_frequencies(&root, p),
        SamplePlot::TwoD(p) => draw_warp_2d(&root, p),
    }
}

/// The 1D plot: histogram against the pdf, empirical CDF against the CDF, the inversion marked.
fn draw_density_1d<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Density1D,
) -> Result<()> {
    let Density1D {
        hist,
        pdf,
        cdf,
        empirical_cdf,
        marker,
        label,
    } = plot;
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
            hist.iter()
                .map(|&(a, b, d)| Rectangle::new([(a, 0.0), (b, d)], BLUE.mix(0.35).filled())),
        )
        .map_err(err)?
        .label("samples (normalised histogram)")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], BLUE.mix(0.35).filled()));
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
    Ok(())
}

/// The discrete plot: observed frequencies against the pmf.
fn draw_frequencies<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Frequencies,
) -> Result<()> {
    let Frequencies { freq, pmf } = plot;
    let k = freq.len();
    let ymax = freq.iter().chain(pmf).fold(0.0f64, |a, &b| a.max(b)) * 1.15;
    let mut chart = ChartBuilder::on(root)
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
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], BLUE.mix(0.35).filled()));
    chart
        .draw_series(pmf.iter().enumerate().map(|(i, &p)| {
            let x = i as f64;
            PathElement::new(vec![(x - 0.4, p), (x + 0.4, p)], RED.stroke_width(3))
        }))
        .map_err(err)?
        .label("pmf")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(3)));
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// The 2D plot: the points, and their density against the pdf as heat maps.
fn draw_warp_2d<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, plot: &Warp2D) -> Result<()> {
    let Warp2D {
        points,
        point_domain,
        density,
        pdf,
        param_domain,
        res,
        labels,
    } = plot;
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
    Ok(())
}
