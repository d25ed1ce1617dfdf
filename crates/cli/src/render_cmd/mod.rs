//! `pathlab render`: render a scene to EXR, PNG or a film file.
//!
//! The steps, each in its own module: the flags are checked before anything is loaded
//! ([`args`]), the outputs are checked writable ([`outputs`]), the scene, integrator and
//! settings follow from flags and the scene's hints ([`setup`]), the render runs with its
//! checkpoints (here), the outputs are written ([`outputs`]) and the summary printed
//! ([`report`]).

mod args;
mod outputs;
mod report;
mod setup;

pub use args::{parse_defines, parse_depth_arg, RenderArgs, ToneMapName};
pub use setup::apply_resolution;

use anyhow::{Context, Result};
use args::{Aov, IntegratorName};
use pathlab_lab::job::{film_header, resumed_film, Checkpoint, JobOutcome, RenderJob};
use pathlab_lab::outputs::{write_all, ImageOptions, OutputFormat, Written};
use pathlab_render::film::Film;
use pathlab_render::film_file::FilmHeader;
use pathlab_render::image_io::ToneMap;
use pathlab_render::integrator::IntegratorKind;
use pathlab_render::progressive::StopRule;
use pathlab_render::render::{RenderSettings, TileDone};
use pathlab_render::scene::Scene;
use pathlab_render::tev::{Layers, TevDisplay};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `pathlab render`; the exit status (0, or 130/143 when stopped by SIGINT/SIGTERM).
pub fn run(args: &RenderArgs) -> Result<u8> {
    let signals = crate::farm::Signals::install();
    let cancel: &AtomicBool = &signals.cancel;
    let plan = Plan::new(args, cancel)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the worker threads")?;
    let outcome = pool.install(|| plan.render(args, cancel))?;
    plan.finish(args, &outcome, pool.current_num_threads())?;
    // Stopped by a signal: the shell's convention, 128 + the signal's number.
    Ok(if !outcome.stats.cancelled {
        0
    } else if signals.terminated.load(Ordering::Relaxed) {
        143
    } else {
        130
    })
}

/// A render as the flags and the scene's hints make it, checked, before it runs.
struct Plan {
    outputs: Vec<PathBuf>,
    formats: Vec<OutputFormat>,
    scene: Scene,
    integrator_name: IntegratorName,
    integrator: IntegratorKind,
    settings: RenderSettings,
    resolution: [u32; 2],
    spp: u32,
    max_depth: u32,
    progressive: bool,
    /// Most samples a pixel may take: -s, or for the progressive modes 65536 by default.
    stop_cap: u32,
    header: FilmHeader,
}

impl Plan {
    /// Checks the flags and the outputs, loads and builds the scene, and chooses the
    /// integrator and settings.
    fn new(args: &RenderArgs, cancel: &AtomicBool) -> Result<Plan> {
        let checked = args::check(args)?;
        if !args.quiet {
            for w in &checked.warnings {
                eprintln!("warning: {w}");
            }
        }
        let (outputs, formats) = outputs::checked_outputs(args)?;
        let mut desc = setup::scene_desc(args, &checked.params)?;
        let spp = args.spp.or(desc.hints.spp).unwrap_or(64);
        let choice = setup::integrator_choice(args, &checked);
        let max_depth = choice.max_depth(&desc.hints);
        if let Some(k) = args.only_bounce.filter(|&k| k > max_depth) {
            anyhow::bail!("--only-bounce {k} is beyond the scene's largest bounce {max_depth}: the image would be black");
        }
        setup::apply_resolution(&mut desc, args.resolution.as_deref())?;
        setup::apply_view(&mut desc, args.scale, args.fov)?;
        let scene = Scene::build(&desc).context("cannot build the scene")?;
        let (integrator_name, integrator) = choice.integrator(&desc.hints);
        let settings = setup::settings(args, &checked, &desc, &scene, &integrator, spp, cancel)?;
        let progressive = checked.progressive;
        let stop_cap = if progressive {
            args.spp.unwrap_or(65536)
        } else {
            spp
        };
        let film_files = args.checkpoint.is_some()
            || args.resume.is_some()
            || formats.contains(&OutputFormat::Film);
        let header = film_header(
            &desc,
            &settings,
            &integrator,
            &format!("{integrator_name:?}"),
            progressive.then_some(stop_cap),
            film_files,
        );
        Ok(Plan {
            outputs,
            formats,
            scene,
            integrator_name,
            integrator,
            settings,
            resolution: desc.resolution,
            spp,
            max_depth,
            progressive,
            stop_cap,
            header,
        })
    }

    /// The film to start from: the checkpoint `--resume` names, or an empty one.
    fn start_film(&self, args: &RenderArgs) -> Result<Film> {
        let Some(path) = &args.resume else {
            let [w, h] = self.resolution;
            return Ok(Film::new(w, h));
        };
        let film = resumed_film(path, &self.header)?;
        if !args.quiet {
            let n = film.pixels().iter().map(|p| p.count()).min().unwrap_or(0);
            eprintln!(
                "resuming {}: every pixel holds at least {n} of {} samples",
                path.display(),
                self.header.range[1] - self.header.range[0]
            );
        }
        Ok(film)
    }

    /// Runs the render with its progress bar, tev display and checkpoints.
    fn render(&self, args: &RenderArgs, cancel: &AtomicBool) -> Result<JobOutcome> {
        let start_film = self.start_film(args)?;
        let display = connect_display(args, &start_film);
        let pixels = self.settings.pixel_count(self.resolution);
        let bar = report::progress_bar(args, self.progressive, pixels * self.spp as u64);
        let job = RenderJob {
            scene: &self.scene,
            integrator: &self.integrator,
            settings: &self.settings,
            header: &self.header,
            stop: self.progressive.then_some(StopRule {
                target_error: args.target_error,
                time_limit: args.time,
                max_spp: self.stop_cap,
            }),
            checkpoint: args.checkpoint.clone().map(|path| Checkpoint {
                path,
                every_seconds: args.checkpoint_every,
            }),
        };
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

    /// Writes the outputs and tells the user what was made.
    fn finish(&self, args: &RenderArgs, outcome: &JobOutcome, threads: usize) -> Result<()> {
        let (film, stats) = (&outcome.film, &outcome.stats);
        if let (Some((report, error)), false) = (&outcome.progressive, args.quiet) {
            eprintln!(
                "progressive: {} passes, stopped by {}; estimated relative RMSE {error:.4}",
                report.passes, report.stopped_by
            );
        }
        if stats.cancelled {
            let spp = film.sample_count_range();
            let (lo, hi) = (spp.min, spp.max);
            eprintln!(
                "interrupted: writing the image of the {} samples finished, {lo:.0} to {hi:.0} per pixel{}",
                stats.samples,
                if args.checkpoint.is_some() { " (and the checkpoint)" } else { "" }
            );
        }
        let options = ImageOptions {
            variance: args.aov.contains(&Aov::Variance),
            samples: args.aov.contains(&Aov::Samples),
            tonemap: match args.tonemap {
                ToneMapName::Srgb => ToneMap::Srgb,
                ToneMapName::Cs184 => ToneMap::Cs184,
            },
            exposure: args.exposure,
        };
        let written = write_all(
            film,
            &self.outputs,
            &self.formats,
            &self.header,
            options,
            self.integrator_name == IntegratorName::Bvh,
            self.settings.adaptive.is_some().then_some(self.spp),
        )?;
        report_written(args, film, stats, &written, &self.formats, self.spp);
        let summary = report::Summary {
            outputs: &self.outputs,
            settings: &self.settings,
            integrator_name: self.integrator_name,
            max_depth: self.max_depth,
            progressive: self.progressive,
            stop_cap: self.stop_cap,
            threads,
            estimated_error: outcome.progressive.as_ref().map(|(_, error)| *error),
            heat_range: written.heat_range,
        };
        report::print_summary(args, &self.scene, film, stats, &summary)
    }
}

/// The tev viewer `--display` names, sent the film to start from; `None` (after one warning)
/// when nothing listens there.
fn connect_display(args: &RenderArgs, film: &Film) -> Option<TevDisplay> {
    let addr = args.display.as_deref()?;
    let name = std::path::Path::new(&args.scene)
        .file_name()
        .map_or_else(|| args.scene.clone(), |n| n.to_string_lossy().into_owned());
    let layers = Layers {
        variance: args.aov.contains(&Aov::Variance),
        samples: args.aov.contains(&Aov::Samples),
    };
    TevDisplay::connect(addr, &name, film, layers)
        .map_err(|w| eprintln!("warning: {w}"))
        .ok()
}

/// Tells what was written besides the outputs: the BVH view's range, the adaptive rate image.
fn report_written(
    args: &RenderArgs,
    film: &Film,
    stats: &pathlab_render::render::RenderStats,
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
        let mean = film.sample_count_range().mean;
        let pixels = film.pixels().len().max(1) as f64;
        let pilot = if stats.pilot_samples > 0 {
            format!(
                ", plus {:.1} pilot samples per pixel that chose the counts",
                stats.pilot_samples as f64 / pixels
            )
        } else {
            String::new()
        };
        eprintln!(
            "adaptive: {mean:.1} samples per pixel on average (at most {spp}){pilot}; rate image {}",
            rate.display()
        );
    }
}
