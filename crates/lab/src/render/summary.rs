//! What a finished render tells its user: a line of text, or the JSON object of
//! `pathlab render --json` (its fields are listed in the CLI's README).

use super::Plan;
use pathlab_render::film::Film;
use pathlab_render::render::RenderStats;
use serde_json::{json, Value};
use std::path::PathBuf;

/// A finished render's numbers.
pub struct Summary<'a> {
    /// The scene as the request named it.
    pub scene: &'a str,
    /// The images written.
    pub outputs: &'a [PathBuf],
    /// The plan that ran.
    pub plan: &'a Plan,
    /// The film it made.
    pub film: &'a Film,
    /// Its statistics.
    pub stats: &'a RenderStats,
    /// Worker threads.
    pub threads: usize,
    /// A progressive render's estimated relative RMSE.
    pub estimated_error: Option<f64>,
    /// The BVH view's range of node counts.
    pub heat_range: Option<(f32, f32)>,
}

impl Summary<'_> {
    /// Whether pixels took different numbers of samples (or could have).
    fn spp_varies(&self) -> bool {
        let spp = self.film.sample_count_range();
        spp.min != spp.max
            || self.plan.progressive.is_some()
            || self.plan.settings.adaptive.is_some()
    }

    /// One line: size, samples, time, rates, the BVH, and the files written.
    pub fn text(&self) -> String {
        let (stats, build) = (self.stats, self.plan.scene.stats());
        let spp = self.film.sample_count_range();
        let spp_text = if self.spp_varies() {
            format!(
                "{:.1} spp on average ({:.0} to {:.0})",
                spp.mean, spp.min, spp.max
            )
        } else {
            format!("{:.0} spp", spp.mean)
        };
        let outputs: Vec<String> = self
            .outputs
            .iter()
            .map(|o| o.display().to_string())
            .collect();
        format!(
            "{}: {}x{}, {spp_text}, {:.2} s, {} samples/s, {} rays/s, BVH {} nodes in {:.1} ms; wrote {}",
            self.scene,
            self.film.width(),
            self.film.height(),
            stats.seconds,
            si_prefixed(stats.samples as f64 / stats.seconds.max(1e-9)),
            si_prefixed(stats.rays as f64 / stats.seconds.max(1e-9)),
            build.bvh_nodes,
            build.bvh_seconds * 1e3,
            outputs.join(", ")
        )
    }

    /// The `--json` object.
    pub fn json(&self) -> Value {
        let (plan, stats, build) = (self.plan, self.stats, self.plan.scene.stats());
        let mean = self.film.image_mean();
        let spp = self.film.sample_count_range();
        let capped = plan.progressive.is_some() || plan.settings.adaptive.is_some();
        json!({
            "scene": self.scene,
            "output": self.outputs.first(),
            "outputs": self.outputs,
            "resolution": [self.film.width(), self.film.height()],
            "spp": if self.spp_varies() { json!(spp.mean) } else { json!(spp.mean.round() as u64) },
            "spp_range": [spp.min, spp.max],
            "spp_cap": if capped { json!(plan.stop_cap) } else { json!(null) },
            "integrator": format!("{:?}", plan.integrator_name).to_lowercase(),
            "max_depth": if plan.max_depth == u32::MAX { json!("inf") } else { json!(plan.max_depth) },
            "threads": self.threads,
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
            "sampler": plan.settings.sampler.name(),
            "estimated_relative_rmse": self.estimated_error,
            "debug_range": self.heat_range.map(|(lo, hi)| json!({"min": lo, "max": hi})),
        })
    }
}

/// A count or rate with an SI prefix and three significant digits: 950, 12.3 k, 4.56 M.
pub fn si_prefixed(v: f64) -> String {
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
