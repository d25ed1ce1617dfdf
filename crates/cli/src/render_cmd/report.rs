//! What a render tells its user: the progress bar while it runs, and the summary (text on
//! stderr, or `--json` on stdout) when it is done.

use super::args::{IntegratorName, RenderArgs};
use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use pathlab_render::film::Film;
use pathlab_render::render::{RenderSettings, RenderStats};
use pathlab_render::scene::Scene;
use serde_json::json;
use std::io::IsTerminal;
use std::path::PathBuf;

/// The progress bar: hidden with `-q` or when stderr is not a terminal; a spinner with the
/// pass's estimated error for progressive renders; otherwise samples done of `total`, rate
/// and ETA.
pub(super) fn progress_bar(args: &RenderArgs, progressive: bool, total: u64) -> ProgressBar {
    if args.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else if progressive {
        let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{spinner} {elapsed} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        // The bar takes what the terminal's width leaves; counts and rates with SI prefixes.
        b.set_style(
            ProgressStyle::with_template(
                "{wide_bar} {percent:>3}% {done}/{all} samples {rate} ETA {eta}",
            )
            .map(|s| {
                s.with_key("done", |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", si_prefixed(st.pos() as f64));
                })
                .with_key("all", |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", si_prefixed(st.len().unwrap_or(0) as f64));
                })
                .with_key(
                    "rate",
                    |st: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{}/s", si_prefixed(st.per_sec()));
                    },
                )
            })
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    }
}

/// What the summary reports besides the film and the statistics.
pub(super) struct Summary<'a> {
    pub outputs: &'a [PathBuf],
    pub settings: &'a RenderSettings,
    pub integrator_name: IntegratorName,
    pub max_depth: u32,
    pub progressive: bool,
    /// The most samples a pixel may take (adaptive and progressive renders).
    pub stop_cap: u32,
    pub threads: usize,
    pub estimated_error: Option<f64>,
    /// The BVH view's range of node counts.
    pub heat_range: Option<(f32, f32)>,
}

/// Prints the summary: one line on stderr (with a warning for non-finite samples), or the
/// `--json` object on stdout.
pub(super) fn print_summary(
    args: &RenderArgs,
    scene: &Scene,
    film: &Film,
    stats: &RenderStats,
    s: &Summary,
) -> Result<()> {
    let [w, h] = [film.width(), film.height()];
    let (outputs, settings, progressive) = (s.outputs, s.settings, s.progressive);
    let output = &outputs[0];
    let build = scene.stats();
    let mean = film.image_mean();
    // Samples per pixel as taken: adaptive and progressive renders vary them per pixel.
    let spp = film.sample_count_range();
    let (spp_lo, spp_hi, spp_mean) = (spp.min, spp.max, spp.mean);
    let varies = spp_lo != spp_hi || progressive || settings.adaptive.is_some();
    let spp_text = if varies {
        format!("{spp_mean:.1} spp on average ({spp_lo:.0} to {spp_hi:.0})")
    } else {
        format!("{spp_mean:.0} spp")
    };
    if args.json {
        let out = json!({
            "scene": args.scene,
            "output": output,
            "outputs": outputs,
            "resolution": [w, h],
            "spp": if varies { json!(spp_mean) } else { json!(spp_mean.round() as u64) },
            "spp_range": [spp_lo, spp_hi],
            "spp_cap": if progressive || settings.adaptive.is_some() { json!(s.stop_cap) } else { json!(null) },
            "integrator": format!("{:?}", s.integrator_name).to_lowercase(),
            "max_depth": if s.max_depth == u32::MAX { json!("inf") } else { json!(s.max_depth) },
            "threads": s.threads,
            "seconds": stats.seconds,
            "samples": stats.samples,
            "pilot_samples": stats.pilot_samples,
            "samples_per_second": stats.samples as f64 / stats.seconds.max(1e-9),
            "rays": stats.rays,
            "rays_per_second": stats.rays as f64 / stats.seconds.max(1e-9),
            "bvh_build_seconds": build.bvh_seconds,
            "bvh_nodes": build.bvh_nodes,
            "triangles": build.triangles,
            "image_mean_rgb": [mean.x, mean.y, mean.z],
            "nonfinite_samples": stats.nonfinite_samples,
            "cancelled": stats.cancelled,
            "sampler": settings.sampler.name(),
            "estimated_relative_rmse": s.estimated_error,
            "debug_range": s.heat_range.map(|(lo, hi)| json!({"min": lo, "max": hi})),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else if !args.quiet {
        eprintln!(
            "{}: {}x{}, {spp_text}, {:.2} s, {} samples/s, {} rays/s, BVH {} nodes in {:.1} ms; wrote {}",
            args.scene,
            w,
            h,
            stats.seconds,
            si_prefixed(stats.samples as f64 / stats.seconds.max(1e-9)),
            si_prefixed(stats.rays as f64 / stats.seconds.max(1e-9)),
            build.bvh_nodes,
            build.bvh_seconds * 1e3,
            outputs
                .iter()
                .map(|o| o.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        if stats.nonfinite_samples > 0 {
            eprintln!(
                "warning: {} samples were NaN or infinite and were counted as black",
                stats.nonfinite_samples
            );
        }
    }
    Ok(())
}

/// A count or rate with an SI prefix and three significant digits: 950, 12.3 k, 4.56 M.
pub(crate) fn si_prefixed(v: f64) -> String {
    if !v.is_finite() || v < 0.0 {
        return "-".to_string();
    }
    let (scaled, prefix) = [(1e12, " T"), (1e9, " G"), (1e6, " M"), (1e3, " k")]
        .iter()
        .find(|(p, _)| v >= *p)
        .map_or((v, ""), |&(p, n)| (v / p, n));
    let digits = if scaled >= 100.0 || prefix.is_empty() {
        0
    } else if scaled >= 10.0 {
        1
    } else {
        2
    };
    format!("{scaled:.digits$}{prefix}")
}

#[cfg(test)]
mod tests {
    use super::si_prefixed;

    #[test]
    fn counts_and_rates_get_si_prefixes_and_three_digits() {
        assert_eq!(si_prefixed(950.0), "950");
        assert_eq!(si_prefixed(12_345.0), "12.3 k");
        assert_eq!(si_prefixed(4_567_891.0), "4.57 M");
        assert_eq!(si_prefixed(123_456_789_012.0), "123 G");
        assert_eq!(si_prefixed(f64::NAN), "-");
    }
}
