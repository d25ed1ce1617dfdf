//! The render loop: tiles on rayon, one sampler stream per pixel, pixel statistics on the film.

use crate::film::{Film, PixelStats};
use crate::integrator::{camera_ray, Integrator, PathStats, SampleRef};
use crate::scene::Scene;
use pathlab_mc::sampler::SamplerKind;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

mod adaptive;

use adaptive::render_adaptive;
pub use adaptive::{Adaptive, AdaptiveRule};

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
    /// Per-pixel adaptive sampling (`spp` is then the most a pixel takes).
    pub adaptive: Option<Adaptive>,
    /// Only the sample indices `[start, end)` of every pixel (a shard of a render split
    /// over machines); `None`: `[0, spp)`.
    pub sample_range: Option<[u32; 2]>,
}

impl RenderSettings {
    /// `[x0, y0, x1, y1]` of the pixels rendered in an image of `resolution`: the crop window
    /// (clamped to the image), or the whole image.
    pub fn window(&self, [width, height]: [u32; 2]) -> [u32; 4] {
        self.crop.map_or([0, 0, width, height], |[x0, y0, x1, y1]| {
            [x0.min(width), y0.min(height), x1.min(width), y1.min(height)]
        })
    }

    /// How many pixels of an image of `resolution` are rendered ([`RenderSettings::window`]).
    pub fn pixel_count(&self, resolution: [u32; 2]) -> u64 {
        let [x0, y0, x1, y1] = self.window(resolution);
        x1.saturating_sub(x0) as u64 * y1.saturating_sub(y0) as u64
    }

    /// `spp` samples per pixel of the whole image with the given seed and sampler.
    pub fn new(spp: u32, seed: u64, sampler: SamplerKind) -> Self {
        RenderSettings {
            spp,
            seed,
            sampler,
            crop: None,
            adaptive: None,
            sample_range: None,
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
    /// Pilot samples of the two-stage adaptive rule: traced to choose sample counts, not
    /// part of the image.
    pub pilot_samples: u64,
    /// Rays traced.
    pub rays: u64,
    /// BVH nodes visited by closest-hit rays.
    pub nodes_visited: u64,
    /// Whether the render was stopped before it finished.
    pub cancelled: bool,
}

/// A tile's work, told to a render's `progress` as it finishes (from worker threads).
#[derive(Clone, Copy, Debug)]
pub struct TileDone<'a> {
    /// Samples traced (finite and not).
    pub samples: u64,
    /// The tile's top-left pixel.
    pub x0: u32,
    /// Its top-left pixel's row.
    pub y0: u32,
    /// Its width in pixels.
    pub w: u32,
    /// What this pass adds to each of the tile's pixels (row-major, `w` wide): merged into a
    /// copy of the film as the pass began, they give the film as it will be when the pass
    /// ends (a live view's). Empty for work that adds nothing to the film (the two-stage
    /// adaptive rule's pilot).
    pub pixels: &'a [PixelStats],
}

/// Where a tile lies: `(x0, y0, width)`.
pub(crate) type TileAt = (u32, u32, u32);

/// Radiance that light traced to the lens brings to a film position (pixels).
type Splat = (glam::Vec2, crate::desc::Rgb);

pub(crate) struct TileResult {
    x0: u32,
    y0: u32,
    w: u32,
    pixels: Vec<PixelStats>,
    path: PathStats,
    samples: u64,
    nonfinite: u64,
    pilot: u64,
    /// Radiance that light traced to the lens brought to film positions (pixels).
    splats: Vec<Splat>,
    /// Light paths traced for them.
    light_paths: u64,
}

/// Adds the samples with indices `range` of pixel `[x, y]` to `px`; returns how many were
/// finite (added) and how many were NaN or infinite (discarded).
#[inline]
pub fn sample_pixel(
    scene: &Scene,
    integrator: &dyn Integrator,
    sampler: &mut pathlab_mc::sampler::AnySampler,
    [x, y]: [u32; 2],
    range: std::ops::Range<u32>,
    px: &mut PixelStats,
    path: &mut PathStats,
) -> (u64, u64) {
    let (mut ok, mut bad) = (0, 0);
    let mut samples = range.map(|index| SampleRef {
        pixel: [x, y],
        index,
        tag: 0,
    });
    integrator.li_samples(
        scene,
        sampler,
        &mut samples,
        &mut |_, l| add_sample(px, l, &mut ok, &mut bad),
        path,
    );
    (ok, bad)
}

/// The radiance of each of the samples with indices `range` of pixel `pixel`, in order: the
/// samples a render with `sampler` built for `spp` samples and `seed` adds to that pixel (a
/// NaN or infinite one as black, as the film adds it). For looking at one pixel's samples
/// (their histogram, their split by bounce) beside its film statistics.
pub fn pixel_sample_values(
    scene: &Scene,
    integrator: &dyn Integrator,
    (sampler, spp, seed): (SamplerKind, u32, u64),
    pixel: [u32; 2],
    range: std::ops::Range<u32>,
) -> Vec<crate::desc::Rgb> {
    let mut sampler = sampler.build(spp, seed);
    let mut values = vec![crate::desc::Rgb::ZERO; range.len()];
    let first = range.start;
    let mut samples = range.map(|index| SampleRef {
        pixel,
        index,
        tag: index - first,
    });
    integrator.li_samples(
        scene,
        &mut sampler,
        &mut samples,
        &mut |tag, l| {
            if l.is_finite() {
                values[tag as usize] = l;
            }
        },
        &mut PathStats::default(),
    );
    values
}

/// `l` read one 4-byte component at a time. A sample's radiance arrives in the memory where
/// the integrator has just stored it, component by component; a wider load spanning two of
/// those stores cannot take its value from them and waits until they reach the cache, which
/// the film's additions were measured to pay on every sample (the compiler otherwise reads
/// y and z as one 8-byte load).
#[inline(always)]
fn component_by_component(l: &crate::desc::Rgb) -> crate::desc::Rgb {
    // SAFETY: each pointer comes from a reference to an initialised, aligned `f32`; a
    // volatile read of it is an ordinary read that the compiler may not merge with another.
    unsafe {
        crate::desc::Rgb::new(
            std::ptr::read_volatile(&l.x),
            std::ptr::read_volatile(&l.y),
            std::ptr::read_volatile(&l.z),
        )
    }
}

/// Adds radiance `l` to `px` when it is finite (counting it in `ok`); a NaN or infinite
/// sample is added as black and counted in `bad` (as pbrt does), so that a pixel's count is
/// always the number of its sample indices done.
#[inline]
fn add_sample(px: &mut PixelStats, l: crate::desc::Rgb, ok: &mut u64, bad: &mut u64) {
    let l = component_by_component(&l);
    if l.is_finite() {
        px.add(l);
        *ok += 1;
    } else {
        px.add(crate::desc::Rgb::ZERO);
        *bad += 1;
    }
}

/// Renders `scene` with `integrator` from an empty film.
///
/// Each pixel's samples use the sampler positioned at (pixel, sample index), and the film
/// sums them exactly, so the image is the same for the same seed whatever the thread count,
/// tile order or pass schedule. `progress` is told of each tile as it finishes (from worker
/// threads: its samples, and what it adds to the film, see [`TileDone`]); when `cancel`
/// becomes true the render stops within a sample per thread and the film holds every sample
/// finished (whole passes, and part of the last).
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    settings: &RenderSettings,
    progress: &(dyn Fn(&TileDone) + Sync),
    cancel: &AtomicBool,
) -> (Film, RenderStats) {
    let [width, height] = scene.camera().resolution();
    render_from(
        scene,
        integrator,
        settings,
        Film::new(width, height),
        progress,
        cancel,
        &mut |_, _| {},
    )
}

/// The end of each pass: whole-frame passes of 1, 1, 2, 4, ... samples per pixel from
/// `first`, then steady passes of `steady` samples, up to `end`.
pub fn pass_ends(first: u32, end: u32, steady: u32) -> Vec<u32> {
    let mut ends = Vec::new();
    let (mut at, mut step) = (first, 1u32);
    while at < end {
        at = at.saturating_add(step).min(end);
        ends.push(at);
        // Each pass doubles the samples so far, up to the steady size.
        step = (at - first).clamp(1, steady.max(1));
    }
    ends
}

/// Samples per pixel of a steady pass: 64, or more for small images, so that a pass holds at
/// least about a million samples (passes stay cheap to schedule) and at most 4096 per pixel.
fn steady_pass(pixels: u64) -> u32 {
    (((1u64 << 20) / pixels.max(1)) as u32).clamp(64, 4096)
}

/// The pixels a render covers (its crop window, or the whole image) cut into tiles, and the
/// one routine that adds samples to them: every mode (fixed spp, adaptive rounds, the
/// progressive passes of `--time`/`--target-error`) renders in whole-frame passes through it.
pub(crate) struct Frame<'a> {
    scene: &'a Scene,
    integrator: &'a dyn Integrator,
    settings: &'a RenderSettings,
    /// `[x0, y0, x1, y1]` of the pixels rendered.
    window: [u32; 4],
    tiles: Vec<(u32, u32)>,
}

impl<'a> Frame<'a> {
    pub(crate) fn new(
        scene: &'a Scene,
        integrator: &'a dyn Integrator,
        settings: &'a RenderSettings,
    ) -> Self {
        let window = settings.window(scene.camera().resolution());
        let [cx0, cy0, cx1, cy1] = window;
        let tiles = (cy0..cy1)
            .step_by(TILE_SIZE as usize)
            .flat_map(|y| (cx0..cx1).step_by(TILE_SIZE as usize).map(move |x| (x, y)))
            .collect();
        Frame {
            scene,
            integrator,
            settings,
            window,
            tiles,
        }
    }

    /// Whether pixel `[x, y]` is rendered.
    pub(crate) fn covers(&self, x: u32, y: u32) -> bool {
        let [x0, y0, x1, y1] = self.window;
        (x0..x1).contains(&x) && (y0..y1).contains(&y)
    }

    /// How many pixels are rendered.
    pub(crate) fn pixel_count(&self) -> u64 {
        self.settings.pixel_count(self.scene.camera().resolution())
    }

    fn new_tile(&self, x0: u32, y0: u32) -> (u32, u32, TileResult) {
        let w = TILE_SIZE.min(self.window[2] - x0);
        let h = TILE_SIZE.min(self.window[3] - y0);
        let out = TileResult {
            x0,
            y0,
            w,
            pixels: vec![PixelStats::default(); (w * h) as usize],
            path: PathStats::default(),
            samples: 0,
            nonfinite: 0,
            pilot: 0,
            splats: Vec::new(),
            light_paths: 0,
        };
        (w, h, out)
    }

    /// Adds a tile's samples to the film and its counts to the statistics.
    fn merge_tile(film: &mut Film, stats: &mut RenderStats, t: &TileResult) {
        for (i, p) in t.pixels.iter().enumerate() {
            let (x, y) = (t.x0 + i as u32 % t.w, t.y0 + i as u32 / t.w);
            film.pixel_mut(x, y).merge(p);
        }
        stats.samples += t.samples;
        stats.nonfinite_samples += t.nonfinite;
        stats.pilot_samples += t.pilot;
        stats.rays += t.path.rays;
        stats.nodes_visited += t.path.nodes_visited;
    }

    /// Runs `tile` on every tile on the thread pool and returns, in tile order, each tile's
    /// `(x0, y0, width)` and what it gives besides its samples. `tile(out, height, held)` is
    /// given the tile's empty result to fill ([`Frame::new_tile`]), its height, and the sample
    /// counts its pixels hold as it starts (row-major; only this tile adds to them). Each tile's samples go into
    /// `film` (its counts into `stats`) as soon as it is done, so a pass holds a tile per
    /// thread besides the film, not a second film; the film's sums are exact, so the order in
    /// which tiles finish does not change them. Light traced to the lens lands anywhere: the
    /// tiles' splats are added at the end, in tile order.
    pub(crate) fn run_tiles<R: Send>(
        &self,
        film: &mut Film,
        stats: &mut RenderStats,
        tile: impl Fn(TileResult, u32, &[u64]) -> (TileResult, R) + Sync,
    ) -> Vec<(TileAt, R)> {
        let shared = std::sync::Mutex::new((film, stats));
        let lock = || shared.lock().unwrap_or_else(|e| e.into_inner());
        let done: Vec<(Vec<Splat>, u64, TileAt, R)> = self
            .tiles
            .par_iter()
            .map(|&(x0, y0)| {
                let (w, h, out) = self.new_tile(x0, y0);
                let held: Vec<u64> = {
                    let g = lock();
                    (0..w * h)
                        .map(|k| g.0.pixel(x0 + k % w, y0 + k / w).count())
                        .collect()
                };
                let (t, extra) = tile(out, h, &held);
                let mut g = lock();
                let (film, stats) = &mut *g;
                Self::merge_tile(film, stats, &t);
                (t.splats, t.light_paths, (x0, y0, w), extra)
            })
            .collect();
        let (film, _) = shared.into_inner().unwrap_or_else(|e| e.into_inner());
        done.into_iter()
            .map(|(splats, light_paths, at, extra)| {
                self.add_splats(film, &splats, light_paths);
                (at, extra)
            })
            .collect()
    }

    /// One whole-frame pass: pixel `[x, y]` holding `held` samples takes the sample indices
    /// from `range start + held` up to `end(x, y, held)` (none if that is not beyond), tile
    /// by tile on the thread pool; the film gets them when the pass is done. Cancelling stops
    /// at the next sample and keeps those finished.
    pub(crate) fn pass(
        &self,
        film: &mut Film,
        stats: &mut RenderStats,
        end: &(dyn Fn(u32, u32, u64) -> u32 + Sync),
        progress: &(dyn Fn(&TileDone) + Sync),
        cancel: &AtomicBool,
    ) {
        let first = self.settings.sample_range.map_or(0, |r| r[0]);
        let splatting = self.integrator.splats(self.scene);
        self.run_tiles(film, stats, |mut out, h, held| {
            let (x0, y0, w) = (out.x0, out.y0, out.w);
            let mut sampler = self
                .settings
                .sampler
                .build(self.settings.spp, self.settings.seed);
            // The tile's pixels one after another, each from the samples it holds to its
            // end, so that an integrator following several paths at once keeps them all
            // busy to the tile's end.
            let mut samples = (0..w * h).flat_map(|tag| {
                let pixel = [x0 + tag % w, y0 + tag / w];
                let held = held[tag as usize];
                let to = end(pixel[0], pixel[1], held);
                let from = (first as u64 + held).min(to as u64) as u32;
                (from..to)
                    .take_while(|_| !cancel.load(Ordering::Relaxed))
                    .map(move |index| SampleRef { pixel, index, tag })
            });
            let (mut ok, mut bad) = (0, 0);
            let pixels = &mut out.pixels;
            if splatting {
                // One sample after another, each tracing light to the lens too.
                for s in &mut samples {
                    let (ray, weight) = camera_ray(self.scene, &mut sampler, s);
                    let l = self.integrator.li_splat(
                        self.scene,
                        ray,
                        &mut sampler,
                        &mut out.path,
                        &mut |x, v| out.splats.push((x, v)),
                    );
                    add_sample(&mut pixels[s.tag as usize], l * weight, &mut ok, &mut bad);
                    out.light_paths += 1;
                }
            } else {
                self.integrator.li_samples(
                    self.scene,
                    &mut sampler,
                    &mut samples,
                    &mut |tag, l| add_sample(&mut pixels[tag as usize], l, &mut ok, &mut bad),
                    &mut out.path,
                );
            }
            out.samples += ok;
            out.nonfinite += bad;
            progress(&TileDone {
                samples: ok + bad,
                x0,
                y0,
                w,
                pixels: &out.pixels,
            });
            (out, ())
        });
    }

    /// Adds a tile's splats to the pixels of the window the filter gives them (exact sums:
    /// the same in any order), and counts its light paths.
    fn add_splats(&self, film: &mut Film, splats: &[Splat], light_paths: u64) {
        let mut weights = Vec::new();
        film.add_light_paths(light_paths);
        for &(x, v) in splats {
            if !v.is_finite() {
                continue;
            }
            self.scene
                .camera()
                .splat_weights(x, self.window, &mut weights);
            for &([px, py], w) in &weights {
                film.add_splat(px, py, v * w);
            }
        }
    }
}

/// [`render`] continuing `film` (a checkpoint's, or an empty one): every pixel goes on from
/// the samples it holds to the end of the settings' sample range, in whole-frame passes
/// ([`pass_ends`]); after each finished pass `after_pass(film, stats so far)` is called (to
/// write checkpoints). Adaptive sampling runs in rounds of per-pixel batches instead.
pub fn render_from(
    scene: &Scene,
    integrator: &dyn Integrator,
    settings: &RenderSettings,
    mut film: Film,
    progress: &(dyn Fn(&TileDone) + Sync),
    cancel: &AtomicBool,
    after_pass: &mut dyn FnMut(&Film, &RenderStats),
) -> (Film, RenderStats) {
    let frame = Frame::new(scene, integrator, settings);
    let start = Instant::now();
    let mut stats = RenderStats::default();
    if let Some(adaptive) = settings.adaptive {
        render_adaptive(
            &frame, adaptive, &mut film, &mut stats, progress, cancel, after_pass,
        );
    } else {
        let [first, end] = settings.sample_range.unwrap_or([0, settings.spp]);
        for pass_end in pass_ends(first, end, steady_pass(frame.pixel_count())) {
            if cancel.load(Ordering::Relaxed) {
                break;
            }
            frame.pass(&mut film, &mut stats, &|_, _, _| pass_end, progress, cancel);
            stats.seconds = start.elapsed().as_secs_f64();
            if !cancel.load(Ordering::Relaxed) {
                after_pass(&film, &stats);
            }
        }
    }
    stats.seconds = start.elapsed().as_secs_f64();
    stats.cancelled = cancel.load(Ordering::Relaxed);
    (film, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlab_mc::exact::ExactStats;

    fn stats(values: &[f64]) -> ExactStats {
        let mut s = ExactStats::new();
        values.iter().for_each(|&v| s.push(v));
        s
    }

    #[test]
    fn adaptive_stopping_rule() {
        let a = Adaptive {
            batch: 8,
            tolerance: 0.05,
            min_samples: 16,
            rule: AdaptiveRule::Course,
        };
        // Equal samples (all black, or all on a light) never stop a pixel: their variance
        // estimate of zero is no evidence of a tight interval.
        assert!(!a.converged(&stats(&[1.0; 100]), false));
        assert!(!a.converged(&stats(&[0.0; 100]), false));
        // ... unless no sample met a scattering surface: then they are the pixel's value.
        assert!(a.converged(&stats(&[0.0; 16]), true));
        assert!(!a.converged(&stats(&[0.0; 15]), true));
        // Nearly constant samples stop once the minimum is reached.
        let near: Vec<f64> = (0..16).map(|i| 1.0 + 1e-3 * (i % 2) as f64).collect();
        assert!(!a.converged(&stats(&near[..8]), false));
        assert!(a.converged(&stats(&near), false));
        // One bright sample among dark ones never stops a pixel.
        let mut firefly = vec![0.0; 999];
        firefly.push(100.0);
        assert!(!a.converged(&stats(&firefly), false));
        // The course's rule: 1.96 σ/√n ≤ tol μ. Values 1 ± 0.5 (σ ≈ 0.5) need n ≥ (1.96·0.5/0.05)² ≈ 384.
        let alternating =
            |n: usize| -> Vec<f64> { (0..n).map(|i| if i % 2 == 0 { 0.5 } else { 1.5 }).collect() };
        assert!(!a.converged(&stats(&alternating(300)), false));
        assert!(a.converged(&stats(&alternating(400)), false));
        // Neyman: n ≥ (1.96/tol)² σ / L̄; with σ = 0.5 and L̄ = 1 that is n ≥ 768.4.
        let neyman = Adaptive {
            rule: AdaptiveRule::Neyman {
                image_luminance: 1.0,
            },
            ..a
        };
        assert!(!neyman.converged(&stats(&alternating(760)), false));
        assert!(neyman.converged(&stats(&alternating(780)), false));
    }

    #[test]
    fn two_stage_plans_the_courses_count_from_its_pilot() {
        let a = Adaptive {
            batch: 8,
            tolerance: 0.05,
            min_samples: 16,
            rule: AdaptiveRule::TwoStage,
        };
        // σ = 0.5 (values 0.5, 1.5), μ = 1: n = (1.96 · 0.5 / 0.05)² = 384.16, so 49 batches.
        let pilot = stats(&(0..8).map(|i| 0.5 + (i % 2) as f64).collect::<Vec<_>>());
        let sigma = pilot.std_dev();
        let expect = ((1.96 * sigma / 0.05).powi(2) / 8.0).ceil() as u32 * 8;
        assert_eq!(a.planned_samples(&pilot, false, 100_000), expect);
        assert_eq!(a.planned_samples(&pilot, false, 100), 100);
        // A pixel that cannot vary takes one batch; equal samples that could vary, the cap.
        assert_eq!(a.planned_samples(&stats(&[0.0; 8]), true, 512), 8);
        assert_eq!(a.planned_samples(&stats(&[0.0; 8]), false, 512), 512);
        assert_eq!(a.planned_samples(&stats(&[2.0; 8]), false, 512), 512);
        // A tiny relative spread still takes one batch.
        let tight = stats(&(0..8).map(|i| 1.0 + 1e-6 * i as f64).collect::<Vec<_>>());
        assert_eq!(a.planned_samples(&tight, false, 512), 8);
    }
}
