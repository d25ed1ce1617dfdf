//! An integration's report: as text (estimate, interval, relative error, the error against an
//! exact value) and as the JSON object of `pathlab integrate --json`, with the convergence
//! study's series.

use super::{Convergence, Integral, IntegralRun};
use pathlab_mc::sampler::SamplerKind;
use pathlab_mc::stats::z_test;
use serde_json::{json, Value};
use std::path::Path;

/// The convergence study of the three samplers ([`super::convergence`]), plotted to `path`
/// (PNG or SVG by its extension), as the JSON of `pathlab integrate --json`.
pub fn convergence_plot(
    problem: &Integral,
    n: u32,
    reps: u32,
    seed: u64,
    exact: Option<f64>,
    path: &Path,
) -> anyhow::Result<Value> {
    let format = crate::plot::Format::from_path(path)?;
    let study = super::convergence(problem, n, reps, seed, exact);
    let title = format!("∫ {} over {}", problem.f.text(), problem.domain_text());
    crate::plot::convergence(path, format, &title, &study.series, exact, exact.is_some())?;
    Ok(study.json(reps, exact.is_some()))
}

/// An integration as it was asked for and what it found.
pub struct IntegrateReport<'a> {
    /// The integrand as written.
    pub expression: &'a str,
    /// The importance density as written, if any.
    pub importance: Option<&'a str>,
    /// The integral.
    pub problem: &'a Integral,
    /// What the run found.
    pub run: &'a IntegralRun,
    /// Where the uniform numbers came from.
    pub sampler: SamplerKind,
    /// Randomisations behind the error of a stratified or Sobol run.
    pub reps: u32,
    /// The seed.
    pub seed: u64,
    /// The exact value, if known.
    pub exact: Option<f64>,
}

impl IntegrateReport<'_> {
    /// The report as JSON.
    pub fn json(&self) -> Value {
        let (est, run) = (&self.run.estimate, self.run);
        let mut out = json!({
            "expression": self.expression,
            "domain": self.problem.domains.iter().map(|d| [d.0, d.1]).collect::<Vec<_>>(),
            "importance": self.importance,
            "sampler": self.sampler.name(),
            "samples": est.n,
            "seed": self.seed,
            "estimate": est.mean,
            "std_error": est.std_error,
            "ci95": [est.ci95.0, est.ci95.1],
            "relative_error": est.relative_error(),
            "variance_per_sample": est.variance,
            "seconds": run.seconds,
            "samples_per_second": est.n as f64 / run.seconds.max(1e-9),
            "largest_sample_share": run.largest_share,
            "heavy_tailed": run.heavy_tailed,
            "warnings": run.warnings,
        });
        if let Some(x) = self.exact {
            out["exact"] = json!(x);
            out["error"] = json!(est.mean - x);
            out["z"] = json!(z_test(est.mean, est.std_error, x).z);
        }
        out
    }

    /// The report as lines of text.
    pub fn text(&self) -> String {
        let est = &self.run.estimate;
        let how = match self.importance {
            Some(g) => format!("importance sampling from a density proportional to {g}"),
            None => "uniform sampling".to_string(),
        };
        let mut lines = vec![
            format!(
                "integral of {} over {}",
                self.expression,
                self.problem.domain_text()
            ),
            format!(
                "  {how}, {} sampler, {} samples, seed {}",
                self.sampler.name(),
                est.n,
                self.seed
            ),
            format!(
                "  estimate        {:.8} ± {:.2e} (standard error)",
                est.mean, est.std_error
            ),
            format!("  95% CI          [{:.8}, {:.8}]", est.ci95.0, est.ci95.1),
            format!("  relative error  {}", percent(est.relative_error())),
        ];
        if self.sampler != SamplerKind::Independent && self.reps > 1 {
            lines.push(format!(
                "  (error from {} independent randomisations of {} samples each)",
                self.reps,
                est.n / self.reps as u64
            ));
        }
        if let Some(x) = self.exact {
            let z = z_test(est.mean, est.std_error, x);
            lines.push(format!(
                "  exact           {x:.8}: error {:+.2e}, {:.2} standard errors",
                est.mean - x,
                z.z
            ));
        }
        let rate = est.n as f64 / self.run.seconds.max(1e-9);
        lines.push(format!(
            "  {:.3} s, {:.3e} samples/s",
            self.run.seconds, rate
        ));
        lines.join("\n")
    }
}

impl Convergence {
    /// The study as JSON: its reference, and per sampler the fitted slope and the points.
    pub fn json(&self, reps: u32, reference_is_exact: bool) -> Value {
        json!({
            "reference": self.reference,
            "reference_is_exact": reference_is_exact,
            "replications": reps,
            "series": self.series.iter().map(|s| json!({
                "sampler": s.name,
                "fitted_slope": s.slope,
                "n": s.points.iter().map(|p| p.n).collect::<Vec<_>>(),
                "estimate": s.points.iter().map(|p| p.estimate).collect::<Vec<_>>(),
                "ci95_half_width": s.points.iter().map(|p| p.ci_half).collect::<Vec<_>>(),
                "rmse": s.points.iter().map(|p| p.rmse).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// A fraction as a percentage: three decimals, or three significant digits when small.
fn percent(v: f64) -> String {
    if v >= 1e-3 || v == 0.0 {
        format!("{:.3}%", 100.0 * v)
    } else {
        format!("{:.2e}%", 100.0 * v)
    }
}
