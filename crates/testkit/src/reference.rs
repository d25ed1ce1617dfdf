//! Reference images with per-pixel standard errors (Mitsuba 3's renders, the mean and standard
//! error of many independent runs) and a render's comparisons against them: per-pixel z-tests
//! (optionally with variances pooled over neighbours), z-tests of 8 x 8 block means and of the
//! image mean, and squared errors.

use crate::render::MAX_Z;
use glam::DVec3;
use pathlab_render::film::Film;
use pathlab_render::image_io::read_exr_rgb;
use std::path::Path;

/// Largest allowed fraction of outlier pixels per channel.
pub const MAX_OUTLIER_FRACTION: f64 = 0.001;

/// Relative rounding error of the reference's float32 accumulation of 4096 samples
/// (√4096 units in the last place), added in quadrature to the combined standard error: it
/// dominates where the radiance has no variance at all, such as pixels that see only the light.
pub const REFERENCE_ROUNDING: f64 = f32::EPSILON as f64 * 64.0;

/// The image means must agree within this many combined standard errors.
pub const MAX_MEAN_Z: f64 = 3.0;

/// A reference image: each pixel's mean and the standard error of that mean (row-major).
pub struct Reference {
    /// Per-pixel means.
    pub mean: Vec<DVec3>,
    /// Their standard errors.
    pub stderr: Vec<DVec3>,
}

impl Reference {
    /// `mean-maxdepth-{depth}.exr` and `stderr-maxdepth-{depth}.exr` of the folder `dir`
    /// (Mitsuba's `max_depth`, or `inf`).
    pub fn read(dir: &Path, depth: &str) -> Reference {
        let read = |name: &str| -> Vec<DVec3> {
            let path = dir.join(format!("{name}-maxdepth-{depth}.exr"));
            read_exr_rgb(&path)
                .unwrap_or_else(|e| panic!("the reference {} reads: {e}", path.display()))
                .2
                .iter()
                .map(|p| p.as_dvec3())
                .collect()
        };
        Reference {
            mean: read("mean"),
            stderr: read("stderr"),
        }
    }
}

/// A render against a reference, per pixel and as a whole.
pub struct Comparison {
    /// Pixels beyond [`MAX_Z`] combined standard errors, per channel.
    pub outliers: [usize; 3],
    /// Pixels compared (those the render gave samples).
    pub pixels: usize,
    /// The image means' difference in combined standard errors.
    pub mean_z: DVec3,
    /// Our image mean.
    pub ours_mean: DVec3,
    /// The reference's.
    pub ref_mean: DVec3,
}

/// Per-pixel z-tests of `film` against `r` (the pixels it rendered), and of the image means;
/// each pixel's variance is that of its own samples' mean.
pub fn compare(film: &Film, r: &Reference) -> Comparison {
    let estimates: Vec<Option<(DVec3, DVec3)>> = film
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, p)| (p.count() > 0).then(|| (film.pixel_value(i), p.variance_of_mean())))
        .collect();
    compare_estimates(&estimates, r, MAX_Z)
}

/// [`compare`] of the mean of independent renders (other seeds), each pixel's variance
/// estimated from how its value varies between them: for films whose pixels also hold light
/// traced from other pixels' samples (the bidirectional path tracer's splats), whose variance
/// a pixel's own samples do not tell. With few renders that estimate has few degrees of
/// freedom, so a pixel is an outlier beyond the quantile of Student's t (renders − 1 degrees
/// of freedom) with the tail probability that |z| > [`MAX_Z`] has for a normal z.
pub fn compare_replicated(films: &[Film], r: &Reference) -> Comparison {
    use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
    let tail = Normal::standard().cdf(-MAX_Z);
    let limit = StudentsT::new(0.0, 1.0, films.len() as f64 - 1.0)
        .map(|t| t.inverse_cdf(1.0 - tail))
        .unwrap_or(f64::INFINITY);
    compare_estimates(&replicated_estimates(films), r, limit)
}

/// Each pixel's value over independent renders of one image (other seeds): the mean of its
/// values and the variance of that mean, estimated from how they vary between the renders;
/// `None` for a pixel the first render did not render.
pub fn replicated_estimates(films: &[Film]) -> Vec<Option<(DVec3, DVec3)>> {
    let k = films.len() as f64;
    (0..films[0].pixels().len())
        .map(|i| {
            (films[0].pixels()[i].count() > 0).then(|| {
                let values: Vec<DVec3> = films.iter().map(|f| f.pixel_value(i)).collect();
                let mean = values.iter().sum::<DVec3>() / k;
                let var = values
                    .iter()
                    .map(|v| (*v - mean) * (*v - mean))
                    .sum::<DVec3>()
                    / (k - 1.0);
                (mean, var / k)
            })
        })
        .collect()
}

/// Per-pixel z-tests of estimates (value, variance of the value; `None` where nothing was
/// rendered) against `r`, outliers beyond `limit` standard errors; and of the image means.
pub fn compare_estimates(
    estimates: &[Option<(DVec3, DVec3)>],
    r: &Reference,
    limit: f64,
) -> Comparison {
    let mut outliers = [0usize; 3];
    let mut ref_var_sum = DVec3::ZERO;
    let (mut ours_sum, mut ours_var, mut ref_sum) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    let mut compared = 0usize;
    for (i, e) in estimates.iter().enumerate() {
        let Some((ours, var)) = *e else {
            continue; // outside the rendered window
        };
        compared += 1;
        let rounding = r.mean[i].abs() * REFERENCE_ROUNDING;
        let se2 = var + r.stderr[i] * r.stderr[i] + rounding * rounding;
        ref_var_sum += r.stderr[i] * r.stderr[i];
        ours_sum += ours;
        ours_var += var;
        ref_sum += r.mean[i];
        for c in 0..3 {
            let diff = (ours[c] - r.mean[i][c]).abs();
            outliers[c] += (diff > limit * se2[c].sqrt()) as usize;
        }
    }
    let n = compared as f64;
    let ref_mean = ref_sum / n;
    let ref_se = (ref_var_sum / (n * n)).map(f64::sqrt);
    let ours_mean = ours_sum / n;
    let se = (ours_var / (n * n) + ref_se * ref_se).map(f64::sqrt);
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

/// Asserts fewer than [`MAX_OUTLIER_FRACTION`] outlier pixels per channel and image means
/// within [`MAX_MEAN_Z`].
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
