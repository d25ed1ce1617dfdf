//! `pathlab render`: render a scene to EXR, PNG or a film file.
//!
//! The steps: the flags are checked and made a request before anything is loaded
//! ([`args`]), the outputs are checked writable ([`outputs`]), the library plans the render
//! from the request and the scene's hints ([`pathlab_lab::render::Plan`]), the render runs
//! with its progress bar, tev display and checkpoints (here), the outputs are written
//! ([`outputs`]) and the summary printed ([`report`]).

mod args;
mod outputs;
mod report;

pub use args::RenderArgs;

use anyhow::{Context, Result};
use args::{Aov, IntegratorName};
use pathlab_lab::job::{Checkpoint, JobOutcome};
use pathlab_lab::outputs::{write_all, ImageOptions, OutputFormat};
use pathlab_lab::render::summary::Summary;
use pathlab_lab::render::Plan;
use pathlab_render::film::Film;
use pathlab_render::render::TileDone;
use pathlab_render::tev::{Layers, TevDisplay};
use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `pathlab render`; the exit status (0, or 130/143 when stopped by SIGINT/SIGTERM).
pub fn run(args: &RenderArgs) -> Result<u8> {
    let signals = crate::farm::Signals::install();
    let cancel: &AtomicBool = &signals.cancel;
    let checked = args::check(args)?;
    let (outputs, formats) = outputs::checked_outputs(args)?;
    let mut request = checked.request;
    request.film_files =
        args.checkpoint.is_some() || args.resume.is_some() || formats.contains(&OutputFormat::Film);
    let mut warn = |w: &str| {
        if !args.quiet {
            eprintln!("warning: {w}");
        }
    };
    for w in &checked.warnings {
        warn(w);
    }
    let plan = Plan::new(&request, &mut warn, cancel)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the worker threads")?;
    let outcome = pool.install(|| render(&plan, args, cancel))?;
    if let (Some((report, error)), false) = (&outcome.progressive, args.quiet) {
        eprintln!(
            "progressive: {} passes, stopped by {}; estimated relative RMSE {error:.4}",
            report.passes, report.stopped_by
        );
    }
    let (film, stats) = (&outcome.film, &outcome.stats);
    if stats.cancelled {
        let spp = film.sample_count_range();
        eprintln!(
            "interrupted: writing the image of the {} samples finished, {:.0} to {:.0} per pixel{}",
            stats.samples,
            spp.min,
            spp.max,
            if args.checkpoint.is_some() {
                " (and the checkpoint)"
            } else {
                ""
            }
        );
    }
    let options = ImageOptions {
        variance: args.aov.contains(&Aov::Variance),
        samples: args.aov.contains(&Aov::Samples),
        tonemap: args.tonemap,
        exposure: args.exposure,
    };
    let written = write_all(
        film,
        &outputs,
        &formats,
        &plan.header,
        options,
        plan.integrator_name == IntegratorName::Bvh,
        plan.settings.adaptive.is_some().then_some(plan.spp),
    )?;
    report::written(args, &outcome, &written, &formats, plan.spp);
    report::summary(
        args,
        &Summary {
            scene: &args.scene.name,
            outputs: &outputs,
            plan: &plan,
            film,
            stats,
            threads: pool.current_num_threads(),
            estimated_error: outcome.progressive.as_ref().map(|(_, error)| *error),
            heat_range: written.heat_range,
        },
    )?;
    // Stopped by a signal: the shell's convention, 128 + the signal's number.
    Ok(if !stats.cancelled {
        0
    } else if signals.terminated.load(Ordering::Relaxed) {
        143
    } else {
        130
    })
}

/// Runs the render with its progress bar, tev display and checkpoints.
fn render(plan: &Plan, args: &RenderArgs, cancel: &AtomicBool) -> Result<JobOutcome> {
    let start_film = plan.start_film(args.resume.as_deref())?;
    if let (Some(path), false) = (&args.resume, args.quiet) {
        let (n, range) = (start_film.sample_count_range().min, plan.header.range);
        eprintln!(
            "resuming {}: every pixel holds at least {n:.0} of {} samples",
            path.display(),
            range[1] - range[0]
        );
    }
    let display = connect_display(args, &start_film);
    let bar = report::progress_bar(args, plan.progressive.is_some(), plan.total_samples());
    let job = plan.job(args.checkpoint.clone().map(|path| Checkpoint {
        path,
        every_seconds: args.checkpoint_every,
    }));
    let progress = |t: &TileDone| {
        bar.inc(t.samples);
        if let Some(d) = &display {
            d.tile(t);
        }
    };
    let mut after_pass = |pass: u32, error: f64| {
        bar.set_message(format!("pass {pass}: estimated relative RMSE {error:.4}"));
    };
    let outcome = job.run(start_film, &progress, &mut after_pass, cancel)?;
    bar.finish_and_clear();
    if let Some(w) = display.and_then(|d| d.finish(&outcome.film)) {
        eprintln!("warning: {w}");
    }
    Ok(outcome)
}

/// The tev viewer `--display` names, sent the film to start from; `None` (after one warning)
/// when nothing listens there.
fn connect_display(args: &RenderArgs, film: &Film) -> Option<TevDisplay> {
    let addr = args.display.as_deref()?;
    let scene = &args.scene.name;
    let name = std::path::Path::new(scene)
        .file_name()
        .map_or_else(|| scene.clone(), |n| n.to_string_lossy().into_owned());
    let layers = Layers {
        variance: args.aov.contains(&Aov::Variance),
        samples: args.aov.contains(&Aov::Samples),
    };
    TevDisplay::connect(addr, &name, film, layers)
        .map_err(|w| eprintln!("warning: {w}"))
        .ok()
}
