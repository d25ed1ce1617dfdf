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

pub use args::{parse_depth_arg, RenderArgs, ToneMapName};
pub use outputs::write_film_image;
pub use setup::apply_resolution;

use anyhow::{Context, Result};
use args::IntegratorName;
use outputs::OutputFormat;
use pathlab_render::film::Film;
use pathlab_render::film_file::FilmHeader;
use pathlab_render::integrator::IntegratorKind;
use pathlab_render::progressive::{estimated_relative_rmse, render_progressive_from, StopRule};
use pathlab_render::render::{render_from, RenderSettings, RenderStats, TileDone};
use pathlab_render::scene::Scene;
use pathlab_render::tev::{Layers, TevDisplay};
use pathlab_scene::SceneDesc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Runs `pathlab render`; the exit status (0, or 130/143 when stopped by SIGINT/SIGTERM).
pub fn run(args: &RenderArgs) -> Result<u8> {
    let signals = crate::farm::Signals::install();
    let cancel: &AtomicBool = &signals.cancel;
    let checked = args::check(args)?;
    if !args.quiet {
        for w in &checked.warnings {
            eprintln!("warning: {w}");
        }
    }
    let (outputs, formats) = outputs::checked_outputs(args)?;
    let mut desc = setup::scene_desc(args, &checked.params)?;
    let spp = args.spp.or(desc.hints.spp).unwrap_or(64);
    let max_depth = checked
        .cli_depth
        .or(desc.hints.max_depth)
        .unwrap_or(u32::MAX);
    if let Some(k) = args.only_bounce.filter(|&k| k > max_depth) {
        anyhow::bail!("--only-bounce {k} is beyond the scene's largest bounce {max_depth}: the image would be black");
    }
    setup::apply_resolution(&mut desc, args.resolution.as_deref())?;
    setup::apply_view(&mut desc, args.scale, args.fov)?;
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let (integrator_name, integrator) = setup::integrator(args, &desc, max_depth);
    let settings = setup::settings(args, &checked, &desc, &scene, &integrator, spp, cancel)?;
    let progressive = checked.progressive;
    // Most samples a pixel may take: -s, or for the progressive modes 65536 by default.
    let stop_cap = if progressive {
        args.spp.unwrap_or(65536)
    } else {
        spp
    };
    let film_files =
        args.checkpoint.is_some() || args.resume.is_some() || formats.contains(&OutputFormat::Film);
    let header = film_header(
        &desc,
        &settings,
        &integrator,
        integrator_name,
        progressive.then_some(stop_cap),
        film_files,
    );
    let [w, h] = desc.resolution;
    let start_film = match &args.resume {
        Some(path) => resumed_film(path, &header, args.quiet)?,
        None => Film::new(w, h),
    };
    let display = args.display.as_deref().and_then(|addr| {
        let name = std::path::Path::new(&args.scene)
            .file_name()
            .map_or_else(|| args.scene.clone(), |n| n.to_string_lossy().into_owned());
        let layers = Layers {
            variance: args.aov.contains(&args::Aov::Variance),
            samples: args.aov.contains(&args::Aov::Samples),
        };
        TevDisplay::connect(addr, &name, &start_film, layers)
            .map_err(|w| eprintln!("warning: {w}"))
            .ok()
    });
    let pixels = settings.pixel_count(desc.resolution);
    let bar = Arc::new(report::progress_bar(args, progressive, pixels * spp as u64));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the worker threads")?;
    let job = Job {
        scene: &scene,
        integrator: &integrator,
        settings: &settings,
        header: &header,
        stop: progressive.then_some(StopRule {
            target_error: args.target_error,
            time_limit: args.time,
            max_spp: stop_cap,
        }),
    };
    let progress = |t: &TileDone| {
        bar.inc(t.samples);
        if let Some(d) = &display {
            d.tile(t);
        }
    };
    let (film, stats, estimated_error) =
        pool.install(|| job.run(args, start_film, &progress, &bar, cancel))?;
    bar.finish_and_clear();
    if let Some(w) = display.and_then(|d| d.finish(&film)) {
        eprintln!("warning: {w}");
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
    let bvh_view = integrator_name == IntegratorName::Bvh;
    let adaptive_cap = settings.adaptive.is_some().then_some(spp);
    let written = outputs::write_all(
        &film,
        &outputs,
        &formats,
        &header,
        args,
        bvh_view,
        adaptive_cap,
    )?;
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
    let summary = report::Summary {
        outputs: &outputs,
        settings: &settings,
        integrator_name,
        max_depth,
        progressive,
        stop_cap,
        threads: pool.current_num_threads(),
        estimated_error,
        heat_range: written.heat_range,
    };
    report::print_summary(args, &scene, &film, &stats, &summary)?;
    // Stopped by a signal: the shell's convention, 128 + the signal's number.
    Ok(if !stats.cancelled {
        0
    } else if signals.terminated.load(Ordering::Relaxed) {
        143
    } else {
        130
    })
}

/// The header of this render's film files: what identifies it (the scene as the renderer gets
/// it and every setting that changes the image, hashed only when `film_files` are read or
/// written, since hashing a large scene takes time), its seed and sample range. A progressive
/// render (`progressive_cap`) holds up to its cap and resumes only under the same cap.
fn film_header(
    desc: &SceneDesc,
    settings: &RenderSettings,
    integrator: &IntegratorKind,
    integrator_name: IntegratorName,
    progressive_cap: Option<u32>,
    film_files: bool,
) -> FilmHeader {
    let sampler = settings.sampler;
    let description = format!(
        "{integrator_name:?} integrator, {} sampler, seed {}, crop {:?}",
        sampler.name(),
        settings.seed,
        settings.crop
    )
    .to_lowercase();
    let key = if film_files {
        crate::farm::render_key(
            desc,
            &format!(
                "{integrator:?}|{sampler:?}|{:?}|{:?}|progressive {}",
                settings.crop,
                settings.adaptive,
                progressive_cap.is_some()
            ),
        )
    } else {
        String::new()
    };
    let (spp, range) = match progressive_cap {
        Some(cap) => (cap, [0, cap]),
        None => (
            settings.spp,
            settings.sample_range.unwrap_or([0, settings.spp]),
        ),
    };
    crate::farm::header(desc, &key, &description, settings.seed, spp, range)
}

/// The film of a checkpoint, checked against this render's header.
fn resumed_film(path: &std::path::Path, header: &FilmHeader, quiet: bool) -> Result<Film> {
    let (h, film) = pathlab_render::film_file::read(path)?;
    crate::farm::check_matches(path, &h, header)?;
    if !quiet {
        let n = film.pixels().iter().map(|p| p.count()).min().unwrap_or(0);
        eprintln!(
            "resuming {}: every pixel holds at least {n} of {} samples",
            path.display(),
            header.range[1] - header.range[0]
        );
    }
    Ok(film)
}

/// A render to run: fixed samples per pixel (or adaptive), or progressive to `stop`.
struct Job<'a> {
    scene: &'a Scene,
    integrator: &'a IntegratorKind,
    settings: &'a RenderSettings,
    header: &'a FilmHeader,
    stop: Option<StopRule>,
}

impl Job<'_> {
    /// Renders from `film`, writing checkpoints after finished passes (at most every
    /// `--checkpoint-every` seconds) and when done or stopped; the film, the statistics and,
    /// for progressive renders, the estimated relative RMSE.
    fn run(
        &self,
        args: &RenderArgs,
        film: Film,
        progress: &(dyn Fn(&TileDone) + Sync),
        bar: &Arc<indicatif::ProgressBar>,
        cancel: &AtomicBool,
    ) -> Result<(Film, RenderStats, Option<f64>)> {
        let mut last_checkpoint = std::time::Instant::now();
        let mut checkpoint_error = None;
        let mut checkpoint = |film: &Film| {
            if let Some(path) = &args.checkpoint {
                if last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every {
                    if let Err(e) = pathlab_render::film_file::write(path, self.header, film) {
                        checkpoint_error.get_or_insert(e);
                    }
                    last_checkpoint = std::time::Instant::now();
                }
            }
        };
        let (film, stats, estimated_error) = match &self.stop {
            Some(stop) => {
                let mut after_pass = |film: &Film, _: &RenderStats, pass: u32, error: f64| {
                    bar.set_message(format!("pass {pass}: estimated relative RMSE {error:.4}"));
                    checkpoint(film);
                };
                let (film, stats, report) = render_progressive_from(
                    self.scene,
                    self.integrator,
                    self.settings,
                    stop,
                    film,
                    progress,
                    cancel,
                    &mut after_pass,
                );
                // Of the film as written (after a stop mid-pass too).
                let error = estimated_relative_rmse(&film);
                if !args.quiet {
                    eprintln!(
                        "progressive: {} passes, stopped by {}; estimated relative RMSE {error:.4}",
                        report.passes, report.stopped_by
                    );
                }
                (film, stats, Some(error))
            }
            None => {
                let (film, stats) = render_from(
                    self.scene,
                    self.integrator,
                    self.settings,
                    film,
                    progress,
                    cancel,
                    &mut |film, _| checkpoint(film),
                );
                (film, stats, None)
            }
        };
        if let Some(e) = checkpoint_error {
            return Err(e).context("cannot write the checkpoint");
        }
        if let Some(path) = &args.checkpoint {
            pathlab_render::film_file::write(path, self.header, &film)
                .context("cannot write the checkpoint")?;
        }
        Ok((film, stats, estimated_error))
    }
}
