//! The render loop: tiles on rayon, one sampler stream per pixel, pixel statistics on the film.

use crate::film::{Film, PixelStats};
use crate::integrator::{Integrator, PathStats, SampleRef};
use crate::scene::Scene;
use pathlab_mc::sampler::SamplerKind;
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
    /// Per-pixel adaptive sampling (`spp` is then the most a pixel takes).
    pub adaptive: Option<Adaptive>,
}

/// The course's per-pixel adaptive sampling: samples come in batches; after each, a pixel
/// whose n samples have luminance mean μ and standard deviation σ stops when
/// 1.96 σ / √n ≤ `tolerance` · μ, i.e. when the 95% confidence interval of its mean is within
/// ± `tolerance` relative.
///
/// Guards: no pixel stops before `min_samples`; a pixel whose samples are all equal (σ = 0, for
/// instance all zero because none has found a small light yet, or all on the light though the
/// pixel straddles its edge) never counts as converged, since a zero sample variance says
/// nothing about the true one; and a single bright sample among dark ones cannot stop a pixel,
/// since then σ ≈ μ √n and the test would need 1.96 ≤ `tolerance`.
///
/// Stopping on a pixel's own samples makes its estimate slightly biased (optional stopping: a
/// pixel tends to stop after a run of samples that happened to agree), by an amount that shrinks
/// with `min_samples` and `tolerance`; the tests measure it against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Samples per batch between convergence checks.
    pub batch: u32,
    /// Relative half-width of the 95% interval at which a pixel stops.
    pub tolerance: f32,
    /// Samples every pixel takes before it may stop.
    pub min_samples: u32,
    /// Which stopping rule.
    pub rule: AdaptiveRule,
}

/// When an adaptive pixel stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AdaptiveRule {
    /// The course's: the 95% interval of the pixel's mean is within ± tolerance of that mean,
    /// 1.96 σ/√n ≤ tolerance · μ. It gives n ∝ (σ/μ)², spending most on dark, noisy pixels.
    Course,
    /// n ≥ (1.96/tolerance)² · σ / L̄, with L̄ the image's mean luminance (from a short pilot
    /// render): the course's test with μ replaced by √(σ L̄). It gives n ∝ σ, the allocation
    /// that minimises the image's mean squared error for a given total (Neyman allocation).
    Neyman {
        /// The image's mean luminance.
        image_luminance: f64,
    },
}

impl Adaptive {
    /// The course's defaults: batches of 32, tolerance 0.05; at least four batches.
    pub const DEFAULT: Adaptive = Adaptive {
        batch: 32,
        tolerance: 0.05,
        min_samples: 128,
        rule: AdaptiveRule::Course,
    };

    /// Whether a pixel with these luminance statistics may stop.
    pub fn converged(&self, luminance: &pathlab_mc::estimator::RunningStats) -> bool {
        let n = luminance.count();
        if n < self.min_samples.max(2) as u64 {
            return false;
        }
        let sigma = luminance.std_dev();
        if sigma <= 0.0 {
            return false;
        }
        let z = 1.96 / self.tolerance as f64;
        match self.rule {
            AdaptiveRule::Course => z * sigma / (n as f64).sqrt() <= luminance.mean(),
            AdaptiveRule::Neyman { image_luminance } => n as f64 * image_luminance >= z * z * sigma,
        }
    }
}

impl RenderSettings {
    /// `spp` samples per pixel of the whole image with the given seed and sampler.
    pub fn new(spp: u32, seed: u64, sampler: SamplerKind) -> Self {
        RenderSettings {
            spp,
            seed,
            sampler,
            crop: None,
            adaptive: None,
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

/// Adds radiance `l` to `px` when it is finite (counting it in `ok`), else counts it in `bad`.
#[inline]
fn add_sample(px: &mut PixelStats, l: crate::desc::Rgb, ok: &mut u64, bad: &mut u64) {
    if l.is_finite() {
        px.add(l);
        *ok += 1;
    } else {
        *bad += 1;
    }
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
            if let Some(adaptive) = settings.adaptive {
                for y in y0..y0 + h {
                    for x in x0..x0 + w {
                        if cancel.load(Ordering::Relaxed) {
                            continue;
                        }
                        let px = &mut out.pixels[((y - y0) * w + (x - x0)) as usize];
                        let batch = adaptive.batch.max(1);
                        let mut i = 0;
                        while i < settings.spp {
                            if i > 0 && adaptive.converged(px.luminance()) {
                                break;
                            }
                            let end = (i + batch).min(settings.spp);
                            let (ok, bad) = sample_pixel(
                                scene,
                                integrator,
                                &mut sampler,
                                [x, y],
                                i..end,
                                px,
                                &mut out.path,
                            );
                            out.samples += ok;
                            out.nonfinite += bad;
                            i = end;
                        }
                    }
                }
            } else {
                // The whole tile in one go, pixel after pixel, so that an integrator following
                // several paths at once keeps them all busy to the tile's end. A cancelled
                // render starts no further pixel.
                let spp = settings.spp;
                let mut samples = (0..w * h)
                    .take_while(|_| !cancel.load(Ordering::Relaxed))
                    .flat_map(|tag| {
                        let pixel = [x0 + tag % w, y0 + tag / w];
                        (0..spp).map(move |index| SampleRef { pixel, index, tag })
                    });
                let (mut ok, mut bad) = (0, 0);
                let pixels = &mut out.pixels;
                integrator.li_samples(
                    scene,
                    &mut sampler,
                    &mut samples,
                    &mut |tag, l| add_sample(&mut pixels[tag as usize], l, &mut ok, &mut bad),
                    &mut out.path,
                );
                out.samples += ok;
                out.nonfinite += bad;
            }
            // Progress counts the budget of every pixel done, also where adaptive sampling
            // stopped early, so that the bar ends at 100%.
            progress(w as u64 * h as u64 * settings.spp as u64);
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

#[cfg(test)]
mod tests {
    use super::*;
    use pathlab_mc::estimator::RunningStats;

    fn stats(values: &[f64]) -> RunningStats {
        let mut s = RunningStats::new();
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
        assert!(!a.converged(&stats(&[1.0; 100])));
        assert!(!a.converged(&stats(&[0.0; 100])));
        // Nearly constant samples stop once the minimum is reached.
        let near: Vec<f64> = (0..16).map(|i| 1.0 + 1e-3 * (i % 2) as f64).collect();
        assert!(!a.converged(&stats(&near[..8])));
        assert!(a.converged(&stats(&near)));
        // One bright sample among dark ones never stops a pixel.
        let mut firefly = vec![0.0; 999];
        firefly.push(100.0);
        assert!(!a.converged(&stats(&firefly)));
        // The course's rule: 1.96 σ/√n ≤ tol μ. Values 1 ± 0.5 (σ ≈ 0.5) need n ≥ (1.96·0.5/0.05)² ≈ 384.
        let alternating =
            |n: usize| -> Vec<f64> { (0..n).map(|i| if i % 2 == 0 { 0.5 } else { 1.5 }).collect() };
        assert!(!a.converged(&stats(&alternating(300))));
        assert!(a.converged(&stats(&alternating(400))));
        // Neyman: n ≥ (1.96/tol)² σ / L̄; with σ = 0.5 and L̄ = 1 that is n ≥ 768.4.
        let neyman = Adaptive {
            rule: AdaptiveRule::Neyman {
                image_luminance: 1.0,
            },
            ..a
        };
        assert!(!neyman.converged(&stats(&alternating(760))));
        assert!(neyman.converged(&stats(&alternating(780))));
    }
}
