//! A render as its caller asks for it, and the checks of what it asks that need no scene.
//!
//! Errors name the command line's flags, whose values the request carries.

use super::SceneEdits;
use anyhow::{anyhow, bail, Context, Result};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::integrator::IntegratorChoice;
use pathlab_render::limits::{self, Expected};
use pathlab_render::render::{Adaptive, AdaptiveRule};
use std::fmt::Display;
use std::str::FromStr;

/// When a progressive render stops (at the first rule met, or at the cap of samples).
#[derive(Clone, Copy, Debug, Default)]
pub struct ProgressiveStop {
    /// The estimated relative RMSE to reach.
    pub target_error: Option<f64>,
    /// Seconds to render for.
    pub time: Option<f64>,
}

/// Which part of a render's samples this run takes: shard `index` (from 0) of `count`.
#[derive(Clone, Copy, Debug)]
pub struct Shard {
    /// This shard, from 0.
    pub index: u64,
    /// How many shards share the samples.
    pub count: u64,
}

impl FromStr for Shard {
    type Err = anyhow::Error;

    /// `I/N`, as `--shard` takes it.
    fn from_str(text: &str) -> Result<Shard> {
        let (index, count) = text
            .split_once('/')
            .and_then(|(a, b)| Some((a.trim().parse().ok()?, b.trim().parse().ok()?)))
            .with_context(|| format!("--shard {text}: expected I/N, such as 0/4"))?;
        Ok(Shard { index, count })
    }
}

/// What the caller asks for; what it leaves open the scene's hints, then the defaults, fill.
#[derive(Clone, Debug, Default)]
pub struct RenderRequest {
    /// The scene: a file, or the name of a built-in scene.
    pub scene: String,
    /// The scene's parameters (`$name` in Mitsuba files).
    pub params: Vec<(String, String)>,
    /// Changes to the scene before it is built.
    pub edits: SceneEdits,
    /// Samples per pixel (for a progressive render: its cap).
    pub spp: Option<u32>,
    /// Seed of the samplers.
    pub seed: u64,
    /// The sampler (default: the scene's, else Sobol; independent for progressive renders).
    pub sampler: Option<SamplerKind>,
    /// The integrator asked for.
    pub integrator: IntegratorChoice,
    /// Adaptive sampling; with `neyman`, its rule comes from a pilot render.
    pub adaptive: Option<Adaptive>,
    /// The Neyman allocation rule of adaptive sampling (needs `adaptive`).
    pub neyman: bool,
    /// A progressive render, and when it stops.
    pub progressive: Option<ProgressiveStop>,
    /// Only these pixels: x0, y0, x1, y1 (default: the scene file's crop window, if any).
    pub crop: Option<[u32; 4]>,
    /// Only this shard of the samples.
    pub shard: Option<Shard>,
    /// Film files are read or written (checkpoints, resumes, `.plf` outputs): the header
    /// then carries the render's hashed identity.
    pub film_files: bool,
    /// The render writes checkpoints or goes on from one.
    pub checkpoints: bool,
}

impl RenderRequest {
    /// Refuses, before anything is loaded, values no scene could take (each by its rule in
    /// [`limits`]) and settings that contradict each other.
    pub fn check(&self) -> Result<()> {
        let choice = &self.integrator;
        if let (Some(k), Some(m)) = (choice.only_bounce, choice.max_depth) {
            if k > m {
                bail!("--only-bounce {k} is beyond --max-depth {m}: the image would be black");
            }
        }
        self.check_edits()?;
        if let Some(c) = self.crop.filter(|c| c[0] >= c[2] || c[1] >= c[3]) {
            let [x0, y0, x1, y1] = c;
            bail!("--crop {x0} {y0} {x1} {y1}: need x0 < x1 and y0 < y1");
        }
        if let Some(p) = self.progressive {
            within("--target-error", p.target_error, limits::target_error)?;
            within("--time", p.time, limits::render_seconds)?;
            if self.adaptive.is_some() {
                bail!("--adaptive and --target-error/--time are different ways to place samples; choose one");
            }
        }
        if self.shard.is_some() && (self.progressive.is_some() || self.adaptive.is_some()) {
            bail!("--shard splits a render of fixed samples per pixel; it cannot be combined with -a, --target-error or --time");
        }
        // The two-stage rule plans every count from its pilot, which the film's seed redraws;
        // the others decide on each sample drawn, which a film does not keep.
        let stopping_rule = self.neyman
            || self.adaptive.is_some_and(|a| {
                matches!(a.rule, AdaptiveRule::Course | AdaptiveRule::Neyman { .. })
            });
        if self.checkpoints && stopping_rule {
            bail!("--checkpoint and --resume: the course and neyman adaptive rules decide on every sample a pixel has drawn, which a film does not keep; use the default two-stage rule");
        }
        Ok(())
    }

    /// The camera's and the environment's values.
    fn check_edits(&self) -> Result<()> {
        let e = &self.edits;
        within("--lens-radius", e.lens_radius, limits::lens_radius)?;
        within("--focal-distance", e.focal_distance, limits::focal_distance)?;
        let envmap_scale = e.envmap.as_ref().map(|(_, s)| *s);
        within("--envmap-scale", envmap_scale, limits::radiance_scale)?;
        within("--scale", e.scale, limits::image_scale)?;
        within("--fov", e.fov, limits::fov_degrees)?;
        Ok(())
    }
}

/// A setting's value by its rule in [`limits`]: an error names the setting, the value and what
/// was expected.
pub fn within<T: Copy + Display>(
    name: &str,
    value: Option<T>,
    rule: fn(T) -> std::result::Result<T, Expected>,
) -> Result<Option<T>> {
    value
        .map(|v| rule(v).map_err(|e| anyhow!("{name} {v}: {e}")))
        .transpose()
}
