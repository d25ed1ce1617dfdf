//! The render loop: tiles on rayon, one sampler stream per pixel, pixel statistics on the film.

use crate::film::{Film, PixelStats};
use crate::integrator::{Integrator, PathStats};
use crate::scene::Scene;
use glam::Vec2;
use pathlab_mc::sampler::{Sampler, SamplerKind};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Edge length of the square tiles the image is cut into.
pub const TILE_SIZE: u32 = 16;

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of every pixel's random numbers.
    pub seed: u64,
    /// Which sampler.
    pub sampler: SamplerKind,
    /// Only the pixels `x0 <= x < x1`, `y0 <= y < y1` of `[x0, y0, x1, y1]`; the others get
    /// no samples. `None`: the whole image.
    pub crop: Option<[u32; 4]>,
}

impl RenderSettings {
    /// `spp` samples per pixel of the whole image with the given seed and sampler.
    pub fn new(spp: u32, seed: u64, sampler: SamplerKind) -> Self {
        RenderSettings {
            spp,
            seed,
            sampler,
            crop: None,
        }
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Wall-clock seconds of the render loop.
    pub seconds: f64,
    /// Samples added to the film.
    pub samples: u64,
    /// Samples whose radiance was NaN or infinite, discarded.
    pub nonfinite_samples: u64,
    /// Rays traced.
    pub rays: u64,
    /// BVH nodes visited by closest-hit rays.
    pub nodes_visited: u64,
    /// Whether the render was stopped before it finished.
    pub cancelled: bool,
}

struct TileResult {
    x0: u32,
    y0: u32,
    w: u32,
    pixels: Vec<PixelStats>,
    path: PathStats,
    samples: u64,
    nonfinite: u64,
}

/// Renders `scene` with `integrator`.
///
/// Each pixel's samples use the sampler positioned at (pixel, sample index), so the image is
/// the same for the same seed whatever the thread count or tile order. `progress(samples)` is
/// called from worker threads as tiles finish; when `cancel` becomes true, pixels not yet
/// started are skipped and the film holds what was done (their sample count stays 0).
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> (Film, RenderStats) {
    let [width, height] = scene.camera().resolution();
    let [cx0, cy0, cx1, cy1] = settings
        .crop
        .map_or([0, 0, width, height], |[x0, y0, x1, y1]| {
            [x0.min(width), y0.min(height), x1.min(width), y1.min(height)]
        });
    let tiles: Vec<(u32, u32)> = (cy0..cy1)
        .step_by(TILE_SIZE as usize)
        .flat_map(|y| (cx0..cx1).step_by(TILE_SIZE as usize).map(move |x| (x, y)))
        .collect();
    let start = Instant::now();
    let results: Vec<TileResult> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let w = TILE_SIZE.min(cx1 - x0);
            let h = TILE_SIZE.min(cy1 - y0);
            let mut sampler = settings.sampler.build(settings.spp, settings.seed);
            let mut out = TileResult {
                x0,
                y0,
                w,
                pixels: vec![PixelStats::default(); (w * h) as usize],
                path: PathStats::default(),
                samples: 0,
                nonfinite: 0,
            };
            for y in y0..y0 + h {
                for x in x0..x0 + w {
                    if cancel.load(Ordering::Relaxed) {
                        continue;
                    }
                    let px = &mut out.pixels[((y - y0) * w + (x - x0)) as usize];
                    for i in 0..settings.spp {
                        sampler.start_pixel_sample([x, y], i, 0);
                        let film = Vec2::new(x as f32, y as f32) + sampler.next_pixel_2d();
                        let u_lens = sampler.next_2d();
                        let ray = scene.camera().generate_ray(film, u_lens);
                        let l = integrator.li(scene, ray, &mut sampler, &mut out.path);
                        if l.is_finite() {
                            px.add(l);
                            out.samples += 1;
                        } else {
                            out.nonfinite += 1;
                        }
                    }
                }
            }
            progress(out.samples + out.nonfinite);
            out
        })
        .collect();
    let mut film = Film::new(width, height);
    let mut stats = RenderStats::default();
    for t in &results {
        for (i, p) in t.pixels.iter().enumerate() {
            let (x, y) = (t.x0 + i as u32 % t.w, t.y0 + i as u32 / t.w);
            film.pixel_mut(x, y).merge(p);
        }
        stats.samples += t.samples;
        stats.nonfinite_samples += t.nonfinite;
        stats.rays += t.path.rays;
        stats.nodes_visited += t.path.nodes_visited;
    }
    stats.seconds = start.elapsed().as_secs_f64();
    stats.cancelled = cancel.load(Ordering::Relaxed);
    (film, stats)
}
