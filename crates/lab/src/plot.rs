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

pub(super) fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
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
        $crate::plot::register_font();
        match $format {
            Format::Png => {
                let $root = BitMapBackend::new($path, $size).into_drawing_area();
                $body?;
                $root
                    .present()
                    .map_err(|e| $crate::plot::write_err($path, e))?;
            }
            Format::Svg => {
                let $root = SVGBackend::new($path, $size).into_drawing_area();
                $body?;
                $root
                    .present()
                    .map_err(|e| $crate::plot::write_err($path, e))?;
            }
        }
        Ok(())
    }};
}

mod convergence_plots;
mod sample_plots;

pub use convergence_plots::*;
pub use sample_plots::*;

/// Draws the legend of `chart`'s labelled series at `position`.
pub(super) fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
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

pub(super) fn heat_map<DB: DrawingBackend>(
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
