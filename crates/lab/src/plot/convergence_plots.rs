//! Convergence plots: estimates with their intervals and errors against N per sampler, with
//! fitted slopes, and RMSE curves of images.

use super::{err, legend, Format};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

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

    draw_rmse_panel(&panels[1], series, (nmin, nmax), vs_exact)
}

/// The right panel of [`convergence`]: each series' RMSE against N on log-log axes,
/// with its fitted slope and a reference line of slope -1/2 (N from `nmin` to `nmax`).
fn draw_rmse_panel<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    series: &[ConvergenceSeries],
    (nmin, nmax): (f64, f64),
    vs_exact: bool,
) -> Result<()> {
    let all = || series.iter().flat_map(|s| s.points.iter());
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
    let mut chart = ChartBuilder::on(panel)
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
