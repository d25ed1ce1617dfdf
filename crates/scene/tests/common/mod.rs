//! What the reference tests of the Cornell box share: Mitsuba 3's reference images (mean and
//! standard error), renders of the box, and the pixel, block and image-mean comparisons.
#![allow(dead_code)]

use glam::DVec3;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::film::Film;
use pathlab_render::image_io::read_exr_rgb;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings, RenderStats};
use pathlab_render::scene::Scene;
use std::path::PathBuf;

/// A pixel channel is an outlier when |z| exceeds this.
pub const MAX_Z: f64 = 4.0;

/// Largest allowed fraction of outlier pixels per channel.
pub const MAX_OUTLIER_FRACTION: f64 = 0.001;

/// Relative rounding error of the reference's float32 accumulation of 4096 samples
/// (√4096 units in the last place), added in quadrature to the combined standard error: it
/// dominates where the radiance has no variance at all, such as pixels that see only the light.
pub const REFERENCE_ROUNDING: f64 = f32::EPSILON as f64 * 64.0;

/// The image means must agree within this many combined standard errors.
pub const MAX_MEAN_Z: f64 = 3.0;

pub struct Reference {
    pub mean: Vec<DVec3>,
    pub stderr: Vec<DVec3>,
}

pub fn reference(mitsuba_depth: &str) -> Reference {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/cornell-box");
    let read = |name: &str| {
        let (w, h, px) =
            read_exr_rgb(&dir.join(format!("{name}-maxdepth-{mitsuba_depth}.exr"))).unwrap();
        assert_eq!((w, h), (256, 256));
        px.iter().map(|p| p.as_dvec3()).collect::<Vec<_>>()
    };
    Reference {
        mean: read("mean"),
        stderr: read("stderr"),
    }
}

pub struct Comparison {
    pub outliers: [usize; 3],
    pub pixels: usize,
    pub mean_z: DVec3,
    pub ours_mean: DVec3,
    pub ref_mean: DVec3,
}

pub fn compare(film: &Film, r: &Reference) -> Comparison {
    let mut outliers = [0usize; 3];
    let mut ref_var_sum = DVec3::ZERO;
    let mut compared = 0usize;
    for (i, p) in film.pixels().iter().enumerate() {
        if p.count() == 0 {
            continue; // outside the rendered window
        }
        compared += 1;
        let ours = p.mean();
        let rounding = r.mean[i].abs() * REFERENCE_ROUNDING;
        let se2 = p.variance_of_mean() + r.stderr[i] * r.stderr[i] + rounding * rounding;
        ref_var_sum += r.stderr[i] * r.stderr[i];
        for c in 0..3 {
            let diff = (ours[c] - r.mean[i][c]).abs();
            outliers[c] += (diff > MAX_Z * se2[c].sqrt()) as usize;
        }
    }
    let n = compared as f64;
    let rendered = || {
        film.pixels()
            .iter()
            .zip(&r.mean)
            .filter(|(p, _)| p.count() > 0)
    };
    let ref_mean = rendered().map(|(_, m)| *m).sum::<DVec3>() / n;
    let ref_se = (ref_var_sum / (n * n)).map(f64::sqrt);
    let ours_mean = rendered().map(|(p, _)| p.mean()).sum::<DVec3>() / n;
    let ours_var = rendered().map(|(p, _)| p.variance_of_mean()).sum::<DVec3>() / (n * n);
    let se = (ours_var + ref_se * ref_se).map(f64::sqrt);
    Comparison {
        outliers,
        pixels: compared,
        mean_z: (ours_mean - ref_mean) / se,
        ours_mean,
        ref_mean,
    }
}

/// Per-pixel outliers as in [`compare`], but each variance (ours and the reference's) is the
/// larger of the pixel's own estimate and the mean over its 3 x 3 neighbourhood. Where radiance
/// arrives by rare paths (caustics seen through delta BSDFs, found only by BSDF sampling), a
/// pixel that drew none of them estimates a variance far below the true one, and its z is then
/// meaningless; its neighbours, which share the same rare paths, tell the true variance.
/// Taking the larger of the two never lowers a variance, so the test only loses power (how
/// much is checked by scaling our image by `scale` ≠ 1).
pub fn compare_pooled(film: &Film, r: &Reference, scale: f64) -> [usize; 3] {
    let (w, h) = (film.width() as usize, film.height() as usize);
    let ours: Vec<DVec3> = film.pixels().iter().map(|p| p.variance_of_mean()).collect();
    let reference: Vec<DVec3> = r.stderr.iter().map(|s| *s * *s).collect();
    let pooled = |v: &[DVec3], x: usize, y: usize| {
        let (mut sum, mut n) = (DVec3::ZERO, 0.0);
        for yy in y.saturating_sub(1)..(y + 2).min(h) {
            for xx in x.saturating_sub(1)..(x + 2).min(w) {
                sum += v[yy * w + xx];
                n += 1.0;
            }
        }
        v[y * w + x].max(sum / n)
    };
    let mut outliers = [0usize; 3];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let rounding = r.mean[i].abs() * REFERENCE_ROUNDING;
            let se2 = pooled(&ours, x, y) + pooled(&reference, x, y) + rounding * rounding;
            let diff = (film.pixels()[i].mean() * scale - r.mean[i]).abs();
            for c in 0..3 {
                outliers[c] += (diff[c] > MAX_Z * se2[c].sqrt()) as usize;
            }
        }
    }
    outliers
}

/// Block size of the block comparison.
pub const BLOCK: usize = 8;

/// z of the mean of each 8 x 8 block of pixels against the reference's, per channel: the
/// same test on a coarser grid, where each mean averages 64 pixels' samples and so is close to
/// normal even for estimators whose single pixels are not (rare, large contributions).
/// Only blocks whose reference mean (average of the channels) is at least `min_ref` count.
/// Returns the number of outlier blocks per channel and the number of blocks compared.
pub fn compare_blocks(film: &Film, r: &Reference, min_ref: f64) -> ([usize; 3], usize) {
    compare_blocks_of(film, r, min_ref, BLOCK)
}

/// [`compare_blocks`] with blocks of `block` x `block` pixels.
pub fn compare_blocks_of(
    film: &Film,
    r: &Reference,
    min_ref: f64,
    block: usize,
) -> ([usize; 3], usize) {
    let w = film.width() as usize;
    let (bw, bh) = (w / block, film.height() as usize / block);
    let mut outliers = [0usize; 3];
    let mut compared = 0;
    for by in 0..bh {
        for bx in 0..bw {
            let (mut diff, mut var, mut reference) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    let i = y * w + x;
                    let p = film.pixels()[i];
                    let rounding = r.mean[i].abs() * REFERENCE_ROUNDING;
                    diff += p.mean() - r.mean[i];
                    reference += r.mean[i];
                    var += p.variance_of_mean() + r.stderr[i] * r.stderr[i] + rounding * rounding;
                }
            }
            if reference.element_sum() / ((3 * block * block) as f64) < min_ref {
                continue;
            }
            compared += 1;
            for c in 0..3 {
                outliers[c] += (diff[c].abs() > MAX_Z * var[c].sqrt()) as usize;
            }
        }
    }
    (outliers, compared)
}

/// Per-pixel squared error against the reference mean, averaged over the channels.
pub fn squared_errors(film: &Film, r: &Reference) -> Vec<f64> {
    film.pixels()
        .iter()
        .zip(&r.mean)
        .map(|(p, m)| (p.mean() - *m).length_squared() / 3.0)
        .collect()
}

/// Mean and standard error of the paired differences `worse[i] - better[i]`.
pub fn paired_difference(worse: &[f64], better: &[f64]) -> (f64, f64) {
    let n = worse.len() as f64;
    let d: Vec<f64> = worse.iter().zip(better).map(|(w, b)| w - b).collect();
    let mean = d.iter().sum::<f64>() / n;
    let se = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    (mean, se)
}

/// Root of the mean of squared errors.
pub fn rms(e: &[f64]) -> f64 {
    (e.iter().sum::<f64>() / e.len() as f64).sqrt()
}

pub fn assert_agrees(name: &str, c: &Comparison) {
    eprintln!(
        "{name}: outliers per channel {:?} of {} pixels; image mean {:.5?} vs reference {:.5?}, z {:.2?}",
        c.outliers, c.pixels, c.ours_mean, c.ref_mean, c.mean_z
    );
    for (ch, &o) in c.outliers.iter().enumerate() {
        assert!(
            (o as f64) < MAX_OUTLIER_FRACTION * c.pixels as f64,
            "{name}: channel {ch} has {o} pixels with |z| > {MAX_Z}"
        );
    }
    assert!(
        c.mean_z.abs().max_element() <= MAX_MEAN_Z,
        "{name}: image mean differs by {:?} standard errors",
        c.mean_z
    );
}

pub fn render_cornell(integrator: IntegratorKind, spp: u32, seed: u64) -> Film {
    render_cornell_window(integrator, spp, seed, None)
}

pub fn render_cornell_window(
    integrator: IntegratorKind,
    spp: u32,
    seed: u64,
    crop: Option<[u32; 4]>,
) -> Film {
    let desc = pathlab_scene::builtin::cornell_box().unwrap();
    let scene = Scene::build(&desc).unwrap();
    let settings = RenderSettings {
        crop,
        ..RenderSettings::new(spp, seed, SamplerKind::Independent)
    };
    render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0
}

/// Renders `scene` by path tracing to `max_depth` with `spp` independent samples per pixel.
pub fn render_independent(
    scene: &Scene,
    max_depth: u32,
    spp: u32,
    seed: u64,
) -> (Film, RenderStats) {
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    render(
        scene,
        &path(max_depth),
        &settings,
        &|_| {},
        &Default::default(),
    )
}

pub fn path(max_depth: u32) -> IntegratorKind {
    IntegratorKind::Path(PathIntegrator {
        max_depth,
        ..Default::default()
    })
}

/// Renders a reference folder's scene.xml at -m inf and loads its reference.
pub fn render_reference_scene(folder: &str, spp: u32, seed: u64) -> (Film, Reference) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(folder);
    let desc = pathlab_scene::mitsuba::load(&dir.join("scene.xml")).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let scene = Scene::build(&desc).unwrap();
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    let film = render(
        &scene,
        &path(u32::MAX),
        &settings,
        &|_| {},
        &Default::default(),
    )
    .0;
    let read = |name: &str| -> Vec<DVec3> {
        read_exr_rgb(&dir.join(name))
            .unwrap()
            .2
            .iter()
            .map(|p| p.as_dvec3())
            .collect()
    };
    let r = Reference {
        mean: read("mean-maxdepth-inf.exr"),
        stderr: read("stderr-maxdepth-inf.exr"),
    };
    (film, r)
}

/// Two seeds of an adaptive render of the Cornell box at -m inf with batches of 32, tolerance
/// 0.05 and a cap of 512 (the course's settings), merged: (film, mean spp of the estimate,
/// mean pilot spp).
pub fn adaptive_two_seeds(rule: pathlab_render::render::AdaptiveRule) -> (Film, f64, f64) {
    use pathlab_render::render::Adaptive;
    let desc = pathlab_scene::builtin::cornell_box().unwrap();
    let scene = Scene::build(&desc).unwrap();
    let mut merged: Option<Film> = None;
    let (mut samples, mut pilot) = (0u64, 0u64);
    for seed in [61, 62] {
        let mut settings = RenderSettings::new(512, seed, SamplerKind::Independent);
        settings.adaptive = Some(Adaptive {
            rule,
            ..Adaptive::DEFAULT
        });
        let (film, stats) = render(
            &scene,
            &path(u32::MAX),
            &settings,
            &|_| {},
            &Default::default(),
        );
        samples += stats.samples;
        pilot += stats.pilot_samples;
        match merged.as_mut() {
            None => merged = Some(film),
            Some(m) => {
                for (a, b) in m.pixels_mut().iter_mut().zip(film.pixels()) {
                    a.merge(b);
                }
            }
        }
    }
    let film = merged.unwrap();
    let per_pixel = 2.0 * film.pixels().len() as f64;
    (film, samples as f64 / per_pixel, pilot as f64 / per_pixel)
}
