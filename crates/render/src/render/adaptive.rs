//! Adaptive sampling: the rules that say how many samples a pixel needs ([`Adaptive`],
//! [`AdaptiveRule`]) and the render that follows them in whole-frame rounds.

use super::*;

/// Per-pixel adaptive sampling: each pixel's sample count is chosen from its samples'
/// luminance, at most [`RenderSettings::spp`].
///
/// With [`AdaptiveRule::TwoStage`] (the default) the count comes from a pilot of `batch`
/// samples drawn from a stream of their own and left out of the estimate, so the estimate is
/// an average of a number of samples fixed before any of them is drawn: unbiased by
/// construction. With [`AdaptiveRule::Course`] and [`AdaptiveRule::Neyman`] samples come in
/// batches and a pixel stops after a batch when its own samples say so; that is optional
/// stopping, which biases each pixel slightly (a pixel tends to stop after a run of samples
/// that happened to agree), by an amount that shrinks with `min_samples` and `tolerance`; the
/// tests measure it against the reference.
///
/// Guards: no pixel stops before `min_samples` (the two-stage rule plans at least `batch`); a
/// pixel whose samples are all equal (σ = 0) counts as converged only when its radiance cannot
/// vary, because no sample met a surface that scatters (camera rays that escaped, or met black
/// emitters: [`crate::integrator::PathStats::random_vertices`]); otherwise a zero sample
/// variance says nothing about the true one (all zero because none has found a small light
/// yet). A single bright sample among dark ones cannot stop a pixel, since then σ ≈ μ √n and
/// the test would need 1.96 ≤ `tolerance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Samples per batch between convergence checks (two-stage: the pilot's size).
    pub batch: u32,
    /// Relative half-width of the 95% interval at which a pixel stops.
    pub tolerance: f32,
    /// Samples every pixel takes before it may stop (course and Neyman rules).
    pub min_samples: u32,
    /// Which stopping rule.
    pub rule: AdaptiveRule,
}

/// How an adaptive pixel's sample count is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AdaptiveRule {
    /// Kirk and Arvo's two-stage scheme with the course's precision target: a pilot of one
    /// batch from an independent stream gives μ and σ; the pixel then takes
    /// n = (1.96 σ / (tolerance μ))² samples (rounded up to whole batches, at least one, at
    /// most the cap) of its own stream, and only those make the estimate. Unbiased.
    TwoStage,
    /// The course's: after each batch, stop once the 95% interval of the pixel's mean is
    /// within ± tolerance of that mean, 1.96 σ/√n ≤ tolerance · μ. It gives n ∝ (σ/μ)²,
    /// spending most on dark, noisy pixels; biased by optional stopping.
    Course,
    /// n ≥ (1.96/tolerance)² · σ / L̄, with L̄ the image's mean luminance (from a short pilot
    /// render): the course's test with μ replaced by √(σ L̄). It gives n ∝ σ, the allocation
    /// that minimises the image's mean squared error for a given total (Neyman allocation).
    /// Biased by optional stopping, as the course's rule.
    Neyman {
        /// The image's mean luminance.
        image_luminance: f64,
    },
}

impl Adaptive {
    /// The defaults: batches of 32, tolerance 0.05, the two-stage rule; at least four batches
    /// for the stopping rules.
    pub const DEFAULT: Adaptive = Adaptive {
        batch: 32,
        tolerance: 0.05,
        min_samples: 128,
        rule: AdaptiveRule::TwoStage,
    };

    /// Seed offset of the two-stage pilot's stream (independent of the estimate's).
    const PILOT_STREAM: u64 = 0x5851_f42d_4c95_7f2d;

    /// Whether a pixel with these luminance statistics may stop (course and Neyman rules;
    /// the two-stage rule uses the course's test). `deterministic`: none of the samples met a
    /// surface that scatters, so equal samples are the pixel's exact value.
    pub fn converged(
        &self,
        luminance: &pathlab_mc::exact::ExactStats,
        deterministic: bool,
    ) -> bool {
        let n = luminance.count();
        if n < self.min_samples.max(2) as u64 {
            return false;
        }
        let sigma = luminance.std_dev();
        if sigma <= 0.0 {
            return deterministic;
        }
        let z = 1.96 / self.tolerance as f64;
        match self.rule {
            AdaptiveRule::Course | AdaptiveRule::TwoStage => {
                z * sigma / (n as f64).sqrt() <= luminance.mean()
            }
            AdaptiveRule::Neyman { image_luminance } => n as f64 * image_luminance >= z * z * sigma,
        }
    }

    /// The two-stage rule's sample count for a pixel whose pilot had these luminance
    /// statistics, at most `cap`: the course's n = (1.96 σ / (tolerance μ))² in whole
    /// batches, at least one batch; one batch where the pilot shows the pixel cannot vary, and
    /// `cap` where its samples are equal for no such reason (or its mean is zero) and so say
    /// nothing.
    pub fn planned_samples(
        &self,
        pilot: &pathlab_mc::exact::ExactStats,
        deterministic: bool,
        cap: u32,
    ) -> u32 {
        let batch = self.batch.max(1);
        let sigma = pilot.std_dev();
        let mean = pilot.mean();
        let n = if sigma <= 0.0 && deterministic {
            batch as f64
        } else if sigma <= 0.0 || mean <= 0.0 || pilot.count() < 2 {
            cap as f64
        } else {
            let r = 1.96 * sigma / (self.tolerance as f64 * mean);
            r * r
        };
        let batches = (n / batch as f64).ceil().clamp(1.0, u32::MAX as f64);
        (batches as u64 * batch as u64).min(cap as u64) as u32
    }
}

impl AdaptiveRule {
    /// Samples per pixel of the Neyman rule's pilot render.
    pub const NEYMAN_PILOT_SPP: u32 = 4;

    /// The Neyman rule for `scene`: a short pilot render (`NEYMAN_PILOT_SPP` samples per
    /// pixel with `seed`, not reused in the image) gives the image's mean luminance L̄. `None`
    /// when the pilot saw no light (L̄ = 0: the rule's n ∝ σ/L̄ is undefined). Also what the
    /// pilot cost.
    pub fn neyman_from_pilot(
        scene: &Scene,
        integrator: &dyn Integrator,
        seed: u64,
        sampler: SamplerKind,
        cancel: &AtomicBool,
    ) -> (Option<AdaptiveRule>, RenderStats) {
        let pilot = RenderSettings::new(Self::NEYMAN_PILOT_SPP, seed, sampler);
        let (film, stats) = render(scene, integrator, &pilot, &|_| {}, cancel);
        let image_luminance = crate::color::luminance_f64(film.image_mean());
        let rule = (image_luminance > 0.0).then_some(AdaptiveRule::Neyman { image_luminance });
        (rule, stats)
    }
}

/// Adaptive sampling in whole-frame rounds: with the two-stage rule a first pass draws every
/// pixel's pilot and plans its count; then each round gives every pixel below its count one
/// batch, and with the stopping rules a pixel whose samples say it has converged stops. Each
/// pixel gets the same sample indices, in the same batches, as rendering it alone would give.
///
/// Continuing a film: the two-stage plan is drawn again (its pilot is a stream of its own, so
/// the counts are the same) and every pixel goes on to its count, so the image is the one an
/// uninterrupted render gives. The stopping rules cannot know whether the samples a film
/// already holds met a scattering surface, so such pixels never count as unable to vary.
pub(super) fn render_adaptive(
    frame: &Frame,
    adaptive: Adaptive,
    film: &mut Film,
    stats: &mut RenderStats,
    progress: &(dyn Fn(&TileDone) + Sync),
    cancel: &AtomicBool,
    after_round: &mut dyn FnMut(&Film, &RenderStats),
) {
    let settings = frame.settings;
    let batch = adaptive.batch.max(1);
    let width = film.width();
    let index = |x: u32, y: u32| (y * width + x) as usize;
    // Per pixel: the count it is to reach, and whether none of its samples so far met a
    // scattering surface (see `Adaptive::converged`).
    let mut target = vec![settings.spp; film.pixels().len()];
    let mut fixed: Vec<bool> = film.pixels().iter().map(|p| p.count() == 0).collect();
    let two_stage = adaptive.rule == AdaptiveRule::TwoStage;
    let start = Instant::now();
    if two_stage {
        for ((x0, y0, w), plan) in
            pilot_plans(frame, adaptive, batch, film, stats, progress, cancel)
        {
            for (k, &n) in plan.iter().enumerate() {
                target[index(x0 + k as u32 % w, y0 + k as u32 / w)] = n;
            }
        }
    }
    while !cancel.load(Ordering::Relaxed) {
        let rounds = adaptive_round(frame, batch, film, stats, &target, progress, cancel);
        let mut worked = false;
        for ((x0, y0, w), tile_fixed) in rounds {
            for (k, f) in tile_fixed.iter().enumerate() {
                // Pixels that took samples this round.
                if let Some(f) = f {
                    worked = true;
                    fixed[index(x0 + k as u32 % w, y0 + k as u32 / w)] &= f;
                }
            }
        }
        if !worked {
            break;
        }
        // The stopping rules: a pixel whose samples say it has converged stops there.
        // (Pixels outside a crop hold no samples, so never count as converged.)
        if !two_stage {
            for (i, px) in film.pixels().iter().enumerate() {
                if px.count() < target[i] as u64 && adaptive.converged(&px.luminance(), fixed[i]) {
                    target[i] = px.count() as u32;
                }
            }
        }
        stats.seconds = start.elapsed().as_secs_f64();
        if !cancel.load(Ordering::Relaxed) {
            after_round(film, stats);
        }
    }
}

/// The two-stage rule's pilot pass: every pixel's `batch` pilot samples (from a stream of
/// their own, left out of the image) and the count it plans, per tile.
fn pilot_plans(
    frame: &Frame,
    adaptive: Adaptive,
    batch: u32,
    film: &mut Film,
    stats: &mut RenderStats,
    progress: &(dyn Fn(&TileDone) + Sync),
    cancel: &AtomicBool,
) -> Vec<(TileAt, Vec<u32>)> {
    let settings = frame.settings;
    frame.run_tiles(film, stats, |mut out, h, _| {
        let (x0, y0, w) = (out.x0, out.y0, out.w);
        let seed = settings.seed ^ Adaptive::PILOT_STREAM;
        let mut pilot_sampler = settings.sampler.build(batch, seed);
        let mut plan = vec![0u32; (w * h) as usize];
        for k in 0..w * h {
            if cancel.load(Ordering::Relaxed) {
                break;
            }
            let pixel = [x0 + k % w, y0 + k / w];
            let mut pilot = PixelStats::default();
            let before = out.path.random_vertices;
            let (ok, bad) = sample_pixel(
                frame.scene,
                frame.integrator,
                &mut pilot_sampler,
                pixel,
                0..batch,
                &mut pilot,
                &mut out.path,
            );
            out.pilot += ok + bad;
            let deterministic = out.path.random_vertices == before;
            plan[k as usize] =
                adaptive.planned_samples(&pilot.luminance(), deterministic, settings.spp);
        }
        progress(&TileDone {
            samples: out.pilot,
            x0,
            y0,
            w,
            pixels: &[],
        });
        (out, plan)
    })
}

/// One adaptive round: every pixel below its `target` count takes up to `batch` more samples;
/// per tile, the samples and whether each pixel's met no scattering surface.
fn adaptive_round(
    frame: &Frame,
    batch: u32,
    film: &mut Film,
    stats: &mut RenderStats,
    target: &[u32],
    progress: &(dyn Fn(&TileDone) + Sync),
    cancel: &AtomicBool,
) -> Vec<(TileAt, Vec<Option<bool>>)> {
    let settings = frame.settings;
    let width = film.width();
    let index = |x: u32, y: u32| (y * width + x) as usize;
    frame.run_tiles(film, stats, |mut out, h, held| {
        let (x0, y0, w) = (out.x0, out.y0, out.w);
        let mut sampler = settings.sampler.build(settings.spp, settings.seed);
        let mut tile_fixed = vec![None; (w * h) as usize];
        for k in 0..w * h {
            if cancel.load(Ordering::Relaxed) {
                break;
            }
            let (x, y) = (x0 + k % w, y0 + k / w);
            let held = held[k as usize] as u32;
            let end = held.saturating_add(batch).min(target[index(x, y)]);
            if held >= end {
                continue;
            }
            let before = out.path.random_vertices;
            let (ok, bad) = sample_pixel(
                frame.scene,
                frame.integrator,
                &mut sampler,
                [x, y],
                held..end,
                &mut out.pixels[k as usize],
                &mut out.path,
            );
            out.samples += ok;
            out.nonfinite += bad;
            // As the film counts them: finite samples.
            if ok > 0 {
                tile_fixed[k as usize] = Some(out.path.random_vertices == before);
            }
        }
        progress(&TileDone {
            samples: out.samples + out.nonfinite,
            x0,
            y0,
            w,
            pixels: &out.pixels,
        });
        (out, tile_fixed)
    })
}
