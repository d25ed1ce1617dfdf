//! A render as its caller asks for it ([`RenderRequest`], checked before anything is loaded
//! by [`RenderRequest::check`]) and as the scene's hints complete it ([`Plan`]): the scene
//! loaded, edited and built, the integrator chosen, the samples, sampler and adaptive rule
//! settled, and its film files' header. The plan then runs as a [`RenderJob`], and
//! [`summary`] says what was made.
//!
//! Errors about what depends on the scene (a crop window past its image, a bounce beyond its
//! largest, a shard of more parts than samples) name the command line's flags, whose values
//! the request carries.

pub mod edits;
mod request;
pub mod summary;

pub use edits::{apply_resolution, apply_view, SceneEdits};
pub use request::{within, ProgressiveStop, RenderRequest, Shard};

use crate::job::{film_header, resumed_film, Checkpoint, RenderJob};
use anyhow::{bail, Context, Result};
use pathlab_render::film::Film;
use pathlab_render::film_file::FilmHeader;
use pathlab_render::integrator::{IntegratorKind, IntegratorName};
use pathlab_render::progressive::StopRule;
use pathlab_render::render::{AdaptiveRule, RenderSettings};
use pathlab_render::scene::Scene;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Most samples a progressive render's pixel takes unless the caller caps it.
pub const PROGRESSIVE_CAP: u32 = 65536;

/// A render ready to run, with everything the request left open decided.
pub struct Plan {
    /// The scene, built.
    pub scene: Scene,
    /// The integrator's name, as the request or the scene chose it.
    pub integrator_name: IntegratorName,
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The render settings.
    pub settings: RenderSettings,
    /// The image size.
    pub resolution: [u32; 2],
    /// Samples per pixel of a fixed render (the adaptive rule's most).
    pub spp: u32,
    /// Longest path, in bounces (`u32::MAX`: unbounded).
    pub max_depth: u32,
    /// When a progressive render stops.
    pub progressive: Option<ProgressiveStop>,
    /// Most samples a pixel may take: the request's spp, or for a progressive render
    /// [`PROGRESSIVE_CAP`] by default.
    pub stop_cap: u32,
    /// The header of its film files.
    pub header: FilmHeader,
}

impl Plan {
    /// Loads the scene (`warn` hears its warnings), applies the edits, builds it, and settles
    /// the integrator and settings; with the Neyman rule, renders its pilot.
    pub fn new(
        req: &RenderRequest,
        warn: &mut dyn FnMut(&str),
        cancel: &AtomicBool,
    ) -> Result<Plan> {
        req.check()?;
        let mut desc = pathlab_scene::load_with(&req.scene, &req.params)?;
        for w in &desc.warnings {
            warn(w);
        }
        let choice = &req.integrator;
        let max_depth = choice.max_depth(&desc.hints);
        if let Some(k) = choice.only_bounce.filter(|&k| k > max_depth) {
            bail!("--only-bounce {k} is beyond the scene's largest bounce {max_depth}: the image would be black");
        }
        req.edits.apply(&mut desc)?;
        let scene = Scene::build(&desc).context("cannot build the scene")?;
        let (integrator_name, integrator) = choice.integrator(&desc.hints);
        if let IntegratorKind::Bdpt(_) = integrator {
            // Light traced to the lens lands on any pixel, which only whole-frame passes take.
            if req.adaptive.is_some() {
                warn("bdpt with adaptive sampling: no light tracing to the lens (t = 1); the other strategies take its share");
            } else if !scene.camera().supports_light_tracing() {
                warn("bdpt: this camera (orthographic, or with clipping planes) takes no light traced to it (t = 1); the other strategies take its share");
            }
        }
        let spp = req.spp.unwrap_or(desc.hints.spp_or_default());
        let sampler = req
            .sampler
            .unwrap_or(desc.hints.sampler_or_default(req.progressive.is_some()));
        let mut settings = RenderSettings::new(spp, req.seed, sampler);
        settings.adaptive = req.adaptive;
        settings.crop = match req.crop {
            Some(c) => {
                let [w, h] = desc.resolution;
                if c[2] > w || c[3] > h {
                    bail!(
                        "--crop {} {} {} {}: need x1 <= {w} and y1 <= {h}",
                        c[0],
                        c[1],
                        c[2],
                        c[3]
                    );
                }
                Some(c)
            }
            // The file's window, at the size the image now has.
            None => desc.hints.crop.and_then(|c| c.window_for(desc.resolution)),
        };
        if let (Some(a), true) = (settings.adaptive.as_mut(), req.neyman) {
            let seed = req.seed.wrapping_add(1);
            let (rule, _) =
                AdaptiveRule::neyman_from_pilot(&scene, &integrator, seed, sampler, cancel);
            if let Some(rule) = rule {
                a.rule = rule;
            }
        }
        if let Some(Shard { index, count }) = req.shard {
            let range = crate::job::shard_samples(index, count, spp)
                .with_context(|| format!("--shard {index}/{count}"))?;
            settings.sample_range = Some(range);
        }
        let stop_cap = match req.progressive {
            Some(_) => req.spp.unwrap_or(PROGRESSIVE_CAP),
            None => spp,
        };
        let header = film_header(
            &desc,
            &settings,
            &integrator,
            &format!("{integrator_name:?}"),
            req.progressive.is_some().then_some(stop_cap),
            req.film_files,
        );
        Ok(Plan {
            scene,
            integrator_name,
            integrator,
            settings,
            resolution: desc.resolution,
            spp,
            max_depth,
            progressive: req.progressive,
            stop_cap,
            header,
        })
    }

    /// The film to start from: the checkpoint `resume` names (checked to be of this render),
    /// or an empty one.
    pub fn start_film(&self, resume: Option<&Path>) -> Result<Film> {
        match resume {
            Some(path) => resumed_film(path, &self.header),
            None => {
                let [w, h] = self.resolution;
                Film::try_new(w, h).map_err(anyhow::Error::msg)
            }
        }
    }

    /// The plan as a job, writing checkpoints as `checkpoint` says.
    pub fn job(&self, checkpoint: Option<Checkpoint>) -> RenderJob<'_> {
        RenderJob {
            scene: &self.scene,
            integrator: &self.integrator,
            settings: &self.settings,
            header: &self.header,
            stop: self.progressive.map(|p| StopRule {
                target_error: p.target_error,
                time_limit: p.time,
                max_spp: self.stop_cap,
            }),
            checkpoint,
        }
    }

    /// Samples the render takes at most: pixels times samples per pixel.
    pub fn total_samples(&self) -> u64 {
        self.settings.pixel_count(self.resolution) * self.spp as u64
    }
}
