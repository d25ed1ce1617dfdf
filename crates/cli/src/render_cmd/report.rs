//! What a render tells its user: the progress bar while it runs, and the summary (text on
//! stderr, or `--json` on stdout) when it is done.

use super::args::RenderArgs;
use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use pathlab_lab::job::JobOutcome;
use pathlab_lab::outputs::{OutputFormat, Written};
use pathlab_lab::render::summary::{si_prefixed, Summary};
use std::io::IsTerminal;

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

/// Tells what was written besides the outputs: the BVH view's range, the adaptive rate image.
pub(super) fn written(
    args: &RenderArgs,
    outcome: &JobOutcome,
    written: &Written,
    formats: &[OutputFormat],
    spp: u32,
) {
    if !(args.quiet || args.json) {
        if let Some((lo, hi)) = written.heat_range {
            let how = if formats.contains(&OutputFormat::Png) {
                format!("the PNG runs blue (0) through green to red ({hi:.0})")
            } else {
                "the EXR holds the counts".to_string()
            };
            eprintln!("bvh view: {lo:.0} to {hi:.0} nodes visited per camera ray; {how}");
        }
    }
    if let (Some(rate), false) = (&written.rate_image, args.quiet) {
        let film = &outcome.film;
        let mean = film.sample_count_range().mean;
        let pixels = film.pixels().len().max(1) as f64;
        let pilot = match outcome.stats.pilot_samples {
            0 => String::new(),
            n => format!(
                ", plus {:.1} pilot samples per pixel that chose the counts",
                n as f64 / pixels
            ),
        };
        eprintln!(
            "adaptive: {mean:.1} samples per pixel on average (at most {spp}){pilot}; rate image {}",
            rate.display()
        );
    }
}

/// Prints the summary: one line on stderr (with a warning for non-finite samples), or the
/// `--json` object on stdout.
pub(super) fn summary(args: &RenderArgs, s: &Summary) -> Result<()> {
    if args.json {
        let mut json = s.json();
        // Which build ran: the baseline, or a variant for this CPU (`crate::variant`).
        if let Some(fields) = json.as_object_mut() {
            fields.insert("build".into(), crate::variant::BUILD_LEVEL.into());
        }
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else if !args.quiet {
        eprintln!("{}", s.text());
        if s.stats.nonfinite_samples > 0 {
            eprintln!(
                "warning: {} samples were NaN or infinite and were counted as black",
                s.stats.nonfinite_samples
            );
        }
    }
    Ok(())
}
