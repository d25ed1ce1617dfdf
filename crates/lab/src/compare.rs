//! Strategies side by side: one scene rendered with several direct-lighting or path-tracing
//! strategies at the same samples per pixel, with each one's time, mean pixel variance, RMSE
//! against a reference and efficiency 1 / (variance × time). The experiment of
//! `pathlab compare`.

use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use pathlab_render::film::Film;
use pathlab_render::image_io::{write_rgb8, ToneMap};
use pathlab_render::integrator::{
    DirectIntegrator, DirectStrategy, IntegratorKind, PathIntegrator, PathLighting,
};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use plotters::prelude::*;
use serde_json::{json, Value};
use std::path::Path;

/// The strategy names [`strategy`] knows.
pub const STRATEGIES: &str = "hemisphere, cosine, light, mis (direct lighting) and path, path-bsdf, path-light (path tracing with MIS, BSDF sampling only, light sampling only)";

/// The integrator of a strategy: `hemisphere`, `cosine`, `light` or `mis` (direct lighting
/// with one sample), or `path`, `path-bsdf`, `path-light` (path tracing to `max_depth` with
/// MIS, BSDF sampling only, light sampling only).
pub fn strategy(name: &str, max_depth: u32) -> Result<IntegratorKind> {
    let lighting = match name {
        "path" => Some(PathLighting::Mis),
        "path-bsdf" => Some(PathLighting::Bsdf),
        "path-light" => Some(PathLighting::Light),
        _ => None,
    };
    if let Some(lighting) = lighting {
        return Ok(IntegratorKind::Path(PathIntegrator {
            max_depth,
            lighting,
            ..Default::default()
        }));
    }
    let strategy: DirectStrategy = name.parse().map_err(|e: String| anyhow!(e))?;
    Ok(IntegratorKind::Direct(DirectIntegrator {
        strategy,
        samples: 1,
        ..Default::default()
    }))
}

/// Every strategy `names` lists (at least one), each by [`strategy`].
pub fn strategies(names: &[String], max_depth: u32) -> Result<Vec<(String, IntegratorKind)>> {
    if names.is_empty() {
        bail!("name at least one");
    }
    names
        .iter()
        .map(|n| Ok((n.trim().to_string(), strategy(n.trim(), max_depth)?)))
        .collect()
}

/// The warning when `reference` (read from `path`) seems not to be an image of what the rows
/// render ([`crate::images::reference_mismatch`] on the render of least variance), at the depth
/// they render: 1 for direct lighting, `max_depth` when a path strategy is among them.
pub fn reference_warning(
    rows: &[Row],
    reference: &[Vec3],
    path: &Path,
    max_depth: u32,
) -> Option<String> {
    let best = rows
        .iter()
        .min_by(|a, b| a.variance.total_cmp(&b.variance))?;
    let traces_paths = rows.iter().any(|r| r.name.starts_with("path"));
    let depth = crate::images::depth_text(if traces_paths { max_depth } else { 1 });
    crate::images::reference_mismatch(&best.film, reference, path, &depth)
}

/// One strategy's render and its numbers.
pub struct Row {
    /// The strategy's name.
    pub name: String,
    /// Seconds of its render.
    pub seconds: f64,
    /// The variance of one sample, averaged over pixels and channels.
    pub variance: f64,
    /// RMSE against the reference, if one was given.
    pub rmse: Option<f64>,
    /// The render.
    pub film: Film,
}

impl Row {
    /// 1 / (variance × seconds), when both are known: with one sample per pixel there is no
    /// variance, and a render too short to time has no cost.
    pub fn efficiency(&self, spp: u32) -> Option<f64> {
        let cost = self.variance * self.seconds;
        (spp > 1 && cost > 0.0).then(|| 1.0 / cost)
    }
}

/// Renders `scene` with each `(name, integrator)` at `settings`, measured against `reference`.
pub fn compare(
    scene: &Scene,
    strategies: &[(String, IntegratorKind)],
    settings: &RenderSettings,
    reference: Option<&[Vec3]>,
) -> Vec<Row> {
    strategies
        .iter()
        .map(|(name, integrator)| {
            let (film, stats) = render(scene, integrator, settings, &|_| {}, &Default::default());
            let n = film.pixels().len().max(1) as f64;
            let variance = film
                .pixels()
                .iter()
                .map(|p| p.variance().element_sum() / 3.0)
                .sum::<f64>()
                / n;
            let rmse = reference.map(|r| crate::images::film_rmse(&film, r));
            Row {
                name: name.clone(),
                seconds: stats.seconds,
                variance,
                rmse,
                film,
            }
        })
        .collect()
}

/// Writes the renders next to each other as a PNG, each labelled with its strategy.
pub fn write_side_by_side(rows: &[Row], path: &Path) -> Result<()> {
    let Some(first) = rows.first() else {
        return Ok(());
    };
    let (w, h) = (first.film.width(), first.film.height());
    let label = 28u32;
    let (tw, th) = (w * rows.len() as u32, h + label);
    let mut buf = vec![255u8; (tw * th * 3) as usize];
    for (k, r) in rows.iter().enumerate() {
        for (i, c) in r.film.mean_image().iter().enumerate() {
            let (x, y) = (k as u32 * w + i as u32 % w, label + i as u32 / w);
            let o = ((y * tw + x) * 3) as usize;
            for ch in 0..3 {
                buf[o + ch] = (ToneMap::Srgb.encode(c[ch], 1.0) * 255.0 + 0.5) as u8;
            }
        }
    }
    crate::plot::register_font();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (tw, th)).into_drawing_area();
        for (k, r) in rows.iter().enumerate() {
            root.draw(&Text::new(
                r.name.clone(),
                (k as i32 * w as i32 + 6, 6),
                ("sans-serif", 18).into_font().color(&BLACK),
            ))
            .map_err(|e| anyhow!("labelling the comparison failed: {e:?}"))?;
        }
        root.present()
            .map_err(|e| anyhow!("labelling the comparison failed: {e:?}"))?;
    }
    write_rgb8(path, tw, th, &buf)?;
    Ok(())
}

/// The rows as the JSON list of `pathlab compare --json`.
pub fn rows_json(rows: &[Row], spp: u32) -> Value {
    json!(rows
        .iter()
        .map(|r| json!({
            "name": r.name,
            "seconds": r.seconds,
            "mean_pixel_variance": r.variance,
            "rmse": r.rmse,
            "efficiency": r.efficiency(spp),
        }))
        .collect::<Vec<_>>())
}

/// The rows as a table of text, with a line saying what the columns mean.
pub fn rows_table(rows: &[Row], spp: u32) -> String {
    let mut lines = vec![format!(
        "  {:<12} {:>9} {:>16} {:>12} {:>14}",
        "strategy", "seconds", "mean variance", "RMSE", "efficiency"
    )];
    for r in rows {
        let rmse = r.rmse.map_or("-".to_string(), |e| format!("{e:.5}"));
        let efficiency = r
            .efficiency(spp)
            .map_or("-".to_string(), |e| format!("{e:.4e}"));
        lines.push(format!(
            "  {:<12} {:>9.3} {:>16.6} {:>12} {:>14}",
            r.name, r.seconds, r.variance, rmse, efficiency
        ));
    }
    lines.push(
        "  (variance: per sample, averaged over pixels; efficiency = 1 / (variance x seconds))"
            .to_string(),
    );
    lines.join("\n")
}
