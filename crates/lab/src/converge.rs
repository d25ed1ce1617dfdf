//! How the error against a reference falls with samples and with time: renders at 1, 2, 4, ...
//! samples per pixel with independent and Sobol sampling, and with error-driven allocation
//! (the progressive renderer at the same average counts), each point's RMSE against the
//! reference and the fitted order of convergence. The experiment of `pathlab converge`.

use crate::images::film_rmse;
use crate::plot::{self, RmseCurve};
use glam::Vec3;
use pathlab_mc::estimator::loglog_slope;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::film::Film;
use pathlab_render::integrator::IntegratorKind;
use pathlab_render::progressive::{render_progressive, StopRule};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use serde_json::{json, Value};
use std::path::Path;

/// What a convergence study found.
pub struct Study {
    /// One curve per way of sampling: independent, sobol, error-driven (from 32 spp).
    pub curves: Vec<RmseCurve>,
    /// The independent render at the most samples (to check that the reference belongs to it).
    pub top_independent: Film,
}

impl Study {
    /// The curves as the JSON list of `pathlab converge --json`.
    pub fn curves_json(&self) -> Value {
        json!(self
            .curves
            .iter()
            .map(|c| json!({
                "name": c.name,
                "fitted_slope": c.slope,
                "spp": c.points.iter().map(|p| p.0).collect::<Vec<_>>(),
                "seconds": c.points.iter().map(|p| p.1).collect::<Vec<_>>(),
                "rmse": c.points.iter().map(|p| p.2).collect::<Vec<_>>(),
            }))
            .collect::<Vec<_>>())
    }

    /// Plots the curves to `path` (PNG or SVG, as `format` says), titled with the scene's and
    /// the reference's file names and the depth.
    pub fn write_plot(
        &self,
        path: &Path,
        format: plot::Format,
        scene: &str,
        max_depth: u32,
        reference: &Path,
    ) -> anyhow::Result<()> {
        let name = |p: &Path| {
            p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        };
        let title = format!(
            "{}: -m {max_depth}, error against {}",
            name(Path::new(scene)),
            name(reference)
        );
        plot::rmse_curves(path, format, &title, &self.curves)
    }

    /// A line per curve: its fitted order and its error at the most samples.
    pub fn curves_text(&self) -> String {
        let lines: Vec<String> = self
            .curves
            .iter()
            .map(|c| {
                let last = c.points.last().map_or(f64::NAN, |p| p.2);
                format!(
                    "  {:<13} RMSE ∝ N^{:.2}; at the most samples {last:.5}",
                    c.name, c.slope
                )
            })
            .collect();
        lines.join("\n")
    }
}

/// A curve through `points` of (samples per pixel, seconds, RMSE), with its fitted slope.
fn curve(name: &str, points: Vec<(f64, f64, f64)>) -> RmseCurve {
    RmseCurve {
        name: name.to_string(),
        slope: loglog_slope(points.iter().map(|p| (p.0, p.2))),
        points,
    }
}

/// Renders `scene` with `integrator` at powers of two up to `max_spp` samples per pixel, each
/// way of sampling, and measures each image against `reference`.
pub fn converge(
    scene: &Scene,
    integrator: &IntegratorKind,
    reference: &[Vec3],
    max_spp: u32,
    seed: u64,
) -> Study {
    let levels: Vec<u32> = (0..=16)
        .map(|k| 1u32 << k)
        .filter(|&s| s <= max_spp.max(1))
        .collect();
    let mut curves = Vec::new();
    let mut top_independent = None;
    for (name, kind) in [
        ("independent", SamplerKind::Independent),
        ("sobol", SamplerKind::Sobol),
    ] {
        let points = levels
            .iter()
            .map(|&spp| {
                let settings = RenderSettings::new(spp, seed, kind);
                let (film, stats) =
                    render(scene, integrator, &settings, &|_| {}, &Default::default());
                let point = (spp as f64, stats.seconds, film_rmse(&film, reference));
                if kind == SamplerKind::Independent && Some(&spp) == levels.last() {
                    top_independent = Some(film);
                }
                point
            })
            .collect::<Vec<_>>();
        curves.push(curve(name, points));
    }
    // Error-driven allocation (independent samples): the same average sample counts, placed
    // where the estimated error falls most.
    let points = levels
        .iter()
        .filter(|&&spp| spp >= 32)
        .map(|&spp| {
            let stop = StopRule {
                target_error: None,
                time_limit: None,
                max_spp: spp,
            };
            let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
            let (film, stats, _) = render_progressive(
                scene,
                integrator,
                &settings,
                &stop,
                &|_, _| {},
                &Default::default(),
            );
            let n = film.pixels().len().max(1) as f64;
            (
                stats.samples as f64 / n,
                stats.seconds,
                film_rmse(&film, reference),
            )
        })
        .collect::<Vec<_>>();
    if !points.is_empty() {
        curves.push(curve("error-driven", points));
    }
    let [w, h] = scene.camera().resolution();
    Study {
        curves,
        top_independent: top_independent.unwrap_or_else(|| Film::new(w, h)),
    }
}
