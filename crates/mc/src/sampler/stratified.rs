//! The stratified sampler ([`StratifiedSampler`]): jittered strata in every dimension, their
//! order permuted per pixel and dimension, so that a pixel's samples cover every stratum once.

use super::Sampler;
use crate::rng::{hash_words, Pcg32};
use glam::Vec2;

/// Jittered stratified sampling.
///
/// The pixel's `x_samples · y_samples` samples are spread over as many strata: in each 2D
/// dimension pair the unit square is cut into an `x_samples × y_samples` grid, in each 1D
/// dimension the unit interval into `x_samples · y_samples` cells, and every sample takes one
/// cell, jittered uniformly inside it (or its centre when jitter is off). Which sample takes
/// which cell is a hashed permutation that differs per pixel and per dimension, so the strata of
/// different dimensions are not correlated ("padded" stratification, as in pbrt-v4).
///
/// Each sample on its own is uniform on [0, 1)^d (its cell is uniform over the cells when the
/// permutation is, and the jitter is uniform inside the cell), so estimators stay unbiased; the
/// set of samples of a pixel covers every stratum exactly once, which removes the variance
/// between strata.
#[derive(Clone, Debug)]
pub struct StratifiedSampler {
    x_samples: u32,
    y_samples: u32,
    samples_per_pixel: u32,
    jitter: bool,
    seed: u64,
    pixel: [u32; 2],
    sample_index: u32,
    dimension: u32,
    rng: Pcg32,
}

impl StratifiedSampler {
    /// A sampler with an `x_samples × y_samples` grid of strata (each at least 1).
    pub fn new(x_samples: u32, y_samples: u32, jitter: bool, seed: u64) -> Self {
        let x_samples = x_samples.max(1);
        let y_samples = y_samples.max(1);
        StratifiedSampler {
            x_samples,
            y_samples,
            samples_per_pixel: x_samples.saturating_mul(y_samples),
            jitter,
            seed,
            pixel: [0, 0],
            sample_index: 0,
            dimension: 0,
            rng: Pcg32::for_pixel_sample(seed, [0, 0], 0, 0),
        }
    }

    /// A sampler for `count` samples per pixel. The grid is `a × b = count` with `a` the
    /// largest divisor of `count` not above √count, when that grid is no more than 4:1
    /// (e.g. 8 × 16 for 128); otherwise `⌊√count⌋` columns and enough rows to hold `count`
    /// samples, of which the first `count` take a random subset of the cells (which keeps every
    /// sample uniform).
    pub fn with_count(count: u32, jitter: bool, seed: u64) -> Self {
        let count = count.max(1);
        let root = (count as f64).sqrt().floor().max(1.0) as u32;
        let divisor = (1..=root)
            .rev()
            .find(|d| count.is_multiple_of(*d))
            .unwrap_or(1);
        if count / divisor <= 4 * divisor {
            StratifiedSampler::new(divisor, count / divisor, jitter, seed)
        } else {
            StratifiedSampler::new(root, count.div_ceil(root), jitter, seed)
        }
    }

    /// The grid of strata, `[x_samples, y_samples]`.
    pub fn grid(&self) -> [u32; 2] {
        [self.x_samples, self.y_samples]
    }

    #[inline]
    fn stratum(&self) -> u32 {
        let hash = hash_words(&[
            ((self.pixel[0] as u64) << 32) | self.pixel[1] as u64,
            self.dimension as u64,
            self.seed,
        ]);
        let n = self.samples_per_pixel;
        permutation_element(self.sample_index % n, n, hash as u32)
    }

    #[inline]
    fn offset(&mut self) -> f32 {
        if self.jitter {
            self.rng.uniform_f32()
        } else {
            0.5
        }
    }
}

impl Sampler for StratifiedSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        self.pixel = pixel;
        self.sample_index = sample_index;
        self.dimension = dimension;
        self.rng = Pcg32::for_pixel_sample(self.seed, pixel, sample_index, dimension);
    }

    fn next_1d(&mut self) -> f32 {
        let stratum = self.stratum();
        self.dimension += 1;
        let delta = self.offset();
        // Computed in f64 so that (stratum + delta) / n stays strictly below 1.
        let v = (stratum as f64 + delta as f64) / self.samples_per_pixel as f64;
        (v as f32).min(ONE_MINUS_EPSILON)
    }

    fn next_2d(&mut self) -> Vec2 {
        let stratum = self.stratum();
        self.dimension += 2;
        let x = stratum % self.x_samples;
        let y = stratum / self.x_samples;
        let dx = self.offset();
        let dy = self.offset();
        Vec2::new(
            ((x as f32 + dx) / self.x_samples as f32).min(ONE_MINUS_EPSILON),
            ((y as f32 + dy) / self.y_samples as f32).min(ONE_MINUS_EPSILON),
        )
    }
}

/// The largest `f32` below 1.
pub(crate) const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Element `i` of a pseudo-random permutation of `0..n` selected by `seed`, without building the
/// permutation (Kensler, "Correlated Multi-Jittered Sampling", 2013): a hash that is a bijection
/// on the smallest power-of-two range containing `n`, applied again ("cycle walking") until the
/// result falls below `n`.
///
/// Requires `i < n` and `n > 0`; returns a value in `0..n`.
pub fn permutation_element(i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(n > 0 && i < n);
    if n <= 1 {
        return 0;
    }
    let mut mask = n - 1;
    mask |= mask >> 1;
    mask |= mask >> 2;
    mask |= mask >> 4;
    mask |= mask >> 8;
    mask |= mask >> 16;
    let p = seed;
    let mut i = i;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & mask) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & mask) >> 1;
        i = i.wrapping_mul(1 | (p >> 27));
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & mask) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= mask;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    // (i + p) mod n without overflow.
    ((i as u64 + p as u64) % n as u64) as u32
}
