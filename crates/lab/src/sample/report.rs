//! A sampling experiment's report: as text (a table of moments, the chi-square test and its
//! verdict) and as the JSON object of `pathlab sample --json`.

use super::{verdict, SampleReport};
use pathlab_mc::sampler::SamplerKind;
use serde_json::{json, Value};
use std::path::Path;

impl SampleReport {
    /// Plots the samples against the pdf to `path` (PNG or SVG, as `format` says), when the
    /// run kept the plot's data.
    pub fn write_plot(&self, path: &Path, format: crate::plot::Format) -> anyhow::Result<()> {
        if let Some(p) = &self.plot {
            let title = format!(
                "{} ({} samples, {})",
                self.description,
                self.samples,
                self.sampler.name()
            );
            crate::plot::samples(path, format, &title, p)?;
        }
        Ok(())
    }

    /// Samples drawn per second.
    fn rate(&self) -> f64 {
        self.samples as f64 / self.seconds.max(1e-9)
    }

    /// The report as JSON.
    pub fn json(&self) -> Value {
        let (n, fit) = (self.samples, &self.chi_square);
        json!({
            "description": self.description,
            "samples": n,
            "seed": self.seed,
            "sampler": self.sampler.name(),
            "components": self.components.iter().map(|(m, s, z)| json!({
                "name": m.name,
                "mean": s.mean(),
                "std_error": s.std_error(),
                "exact_mean": m.mean,
                "z": if n >= 2 { json!(z.z) } else { json!(null) },
                "variance": s.variance(),
                "exact_variance": m.variance,
            })).collect::<Vec<_>>(),
            "chi_square": {
                "statistic": fit.statistic,
                "dof": fit.dof,
                "p_value": fit.p_value,
            },
            "verdict": verdict(n, fit),
            "seconds": self.seconds,
            "samples_per_second": self.rate(),
        })
    }

    /// The report as lines of text.
    pub fn text(&self) -> String {
        let (n, fit, sampler) = (self.samples, &self.chi_square, self.sampler.name());
        let mut lines = vec![
            self.description.clone(),
            format!("  {n} samples, {sampler} sampler, seed {}", self.seed),
            format!(
                "  {:<6} {:>12} {:>12} {:>8} {:>12} {:>12}",
                "", "mean", "exact mean", "z", "variance", "exact var"
            ),
        ];
        for (m, s, z) in &self.components {
            let z = if n >= 2 {
                format!("{:.2}", z.z)
            } else {
                "-".to_string()
            };
            lines.push(format!(
                "  {:<6} {:>12.6} {:>12.6} {:>8} {:>12.6} {:>12.6}",
                m.name,
                s.mean(),
                m.mean,
                z,
                s.variance(),
                m.variance
            ));
        }
        lines.push(format!(
            "  chi-square fit against the pdf: statistic {:.1}, {} dof, p = {:.3}",
            fit.statistic, fit.dof, fit.p_value
        ));
        lines.push(format!("  {}", verdict(n, fit)));
        if self.sampler != SamplerKind::Independent {
            lines.push(format!(
                "  (z and p assume independent samples; a {sampler} sampler is more even than that)"
            ));
        }
        lines.push(format!("  {:.3e} samples/s", self.rate()));
        lines.join("\n")
    }
}
