//! A render as a job that survives and scales: what identifies it (its film files' header, so
//! that a checkpoint or a shard is accepted only by the same render), and the run itself, with
//! checkpoints written after finished passes and when it is done or stopped.

use anyhow::{bail, Context, Result};
use pathlab_render::desc::SceneDesc;
use pathlab_render::film::Film;
use pathlab_render::film_file::{self, FilmHeader};
use pathlab_render::integrator::IntegratorKind;
use pathlab_render::progressive::{
    estimated_relative_rmse, render_progressive_from, ProgressiveReport, StopRule,
};
use pathlab_render::render::{render_from, RenderSettings, RenderStats, TileDone};
use pathlab_render::scene::Scene;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The samples of shard `i` (from 0) of `n` of a render of `spp` samples per pixel: the
/// range `[i spp / n, (i + 1) spp / n)`, so that the shards together take every sample once.
pub fn shard_samples(i: u64, n: u64, spp: u32) -> Result<[u32; 2]> {
    if n == 0 || i >= n {
        bail!("need 0 <= I < N");
    }
    if n > spp as u64 {
        bail!("{n} shards of {spp} samples per pixel would leave some empty");
    }
    let at = |k: u64| (k * spp as u64 / n) as u32;
    Ok([at(i), at(i + 1)])
}

/// A streaming FNV-1a hash of formatted text.
struct Hasher(u64);

impl std::fmt::Write for Hasher {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for &b in s.as_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        Ok(())
    }
}

/// A key for the scene, every setting that changes the image (`settings`) and the program's
/// version: checkpoints and shards are accepted only by a render with the same key.
pub fn render_key(desc: &SceneDesc, settings: &str) -> String {
    let mut h = Hasher(0xcbf2_9ce4_8422_2325);
    // The scene as the renderer gets it (after every command-line change), then the
    // settings, and the program's version (another version may sample differently).
    let _ = write!(h, "{desc:?}|{settings}|{}", env!("CARGO_PKG_VERSION"));
    format!("{:016x}", h.0)
}

/// The header of a render's film files: what identifies it (the scene as the renderer gets it
/// and every setting that changes the image, hashed only when `hashed`: film files are read or
/// written, since hashing a large scene takes time), its seed and sample range. A progressive
/// render (`progressive_cap`) holds up to its cap and resumes only under the same cap.
/// `integrator_name` names the integrator in the header's description.
pub fn film_header(
    desc: &SceneDesc,
    settings: &RenderSettings,
    integrator: &IntegratorKind,
    integrator_name: &str,
    progressive_cap: Option<u32>,
    hashed: bool,
) -> FilmHeader {
    let sampler = settings.sampler;
    let description = format!(
        "{integrator_name} integrator, {} sampler, seed {}, crop {:?}",
        sampler.name(),
        settings.seed,
        settings.crop
    )
    .to_lowercase();
    let key = if hashed {
        render_key(
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
    FilmHeader {
        resolution: desc.resolution,
        key,
        description,
        seed: settings.seed,
        spp,
        range,
        writer: format!("pathlab {}", env!("CARGO_PKG_VERSION")),
    }
}

/// Checks that the film file `path` (header `h`) belongs to the render of header `ours`.
pub fn check_matches(path: &Path, h: &FilmHeader, ours: &FilmHeader) -> Result<()> {
    let p = path.display();
    if h.resolution != ours.resolution {
        bail!(
            "{p}: the film is {}x{}, this render {}x{}",
            h.resolution[0],
            h.resolution[1],
            ours.resolution[0],
            ours.resolution[1]
        );
    }
    if h.key != ours.key {
        bail!(
            "{p}: it belongs to another scene or settings ({}), not this render's ({})",
            h.description,
            ours.description
        );
    }
    if h.seed != ours.seed || h.spp != ours.spp {
        bail!(
            "{p}: seed {} and {} spp, this render seed {} and {} spp",
            h.seed,
            h.spp,
            ours.seed,
            ours.spp
        );
    }
    if h.range != ours.range {
        bail!(
            "{p}: samples {}..{}, this render {}..{}",
            h.range[0],
            h.range[1],
            ours.range[0],
            ours.range[1]
        );
    }
    Ok(())
}

/// The film of the checkpoint `path`, checked against the render's `header`.
pub fn resumed_film(path: &Path, header: &FilmHeader) -> Result<Film> {
    let (h, film) = film_file::read(path)?;
    check_matches(path, &h, header)?;
    Ok(film)
}

/// Where and how often a job writes its checkpoint.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    /// The film file.
    pub path: PathBuf,
    /// Least seconds between two checkpoints written after passes.
    pub every_seconds: f64,
}

/// A render to run: fixed samples per pixel (or adaptive), or progressive to `stop`.
pub struct RenderJob<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The integrator.
    pub integrator: &'a IntegratorKind,
    /// The settings.
    pub settings: &'a RenderSettings,
    /// The header of its film files.
    pub header: &'a FilmHeader,
    /// Progressive: when to stop.
    pub stop: Option<StopRule>,
    /// Where to write checkpoints, if anywhere.
    pub checkpoint: Option<Checkpoint>,
}

/// What a job made.
pub struct JobOutcome {
    /// The film.
    pub film: Film,
    /// The render's statistics.
    pub stats: RenderStats,
    /// A progressive render's passes and why it stopped, and the estimated relative RMSE of
    /// the film (after a stop mid-pass too).
    pub progressive: Option<(ProgressiveReport, f64)>,
}

impl RenderJob<'_> {
    /// Renders from `film`, writing checkpoints after finished passes (at most every
    /// `every_seconds`) and when done or stopped. `after_pass` hears of each finished
    /// progressive pass and its estimated relative RMSE.
    pub fn run(
        &self,
        film: Film,
        progress: &(dyn Fn(&TileDone) + Sync),
        after_pass: &mut dyn FnMut(u32, f64),
        cancel: &AtomicBool,
    ) -> Result<JobOutcome> {
        let mut last_checkpoint = Instant::now();
        let mut checkpoint_error = None;
        let mut checkpoint = |film: &Film| {
            if let Some(c) = &self.checkpoint {
                if last_checkpoint.elapsed().as_secs_f64() >= c.every_seconds {
                    if let Err(e) = film_file::write(&c.path, self.header, film) {
                        checkpoint_error.get_or_insert(e);
                    }
                    last_checkpoint = Instant::now();
                }
            }
        };
        let (film, stats, progressive) = match &self.stop {
            Some(stop) => {
                let mut each_pass = |film: &Film, _: &RenderStats, pass: u32, error: f64| {
                    after_pass(pass, error);
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
                    &mut each_pass,
                );
                let error = estimated_relative_rmse(&film);
                (film, stats, Some((report, error)))
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
        if let Some(c) = &self.checkpoint {
            film_file::write(&c.path, self.header, &film).context("cannot write the checkpoint")?;
        }
        Ok(JobOutcome {
            film,
            stats,
            progressive,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::shard_samples;

    #[test]
    fn shards_take_every_sample_once() {
        for (n, spp) in [(1, 1), (3, 7), (4, 64), (7, 7), (5, 1000)] {
            let ranges: Vec<[u32; 2]> = (0..n).map(|i| shard_samples(i, n, spp).unwrap()).collect();
            assert_eq!(ranges[0][0], 0);
            assert_eq!(ranges[n as usize - 1][1], spp);
            assert!(ranges.windows(2).all(|w| w[0][1] == w[1][0]));
            assert!(ranges.iter().all(|r| r[1] > r[0]), "{ranges:?}");
        }
        assert!(shard_samples(4, 4, 64).is_err());
        assert!(shard_samples(0, 0, 64).is_err());
        assert!(shard_samples(0, 65, 64).is_err());
    }
}
