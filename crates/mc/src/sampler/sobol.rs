use super::Sampler;
use crate::rng::{hash_pixel, hash_words};
use glam::Vec2;

/// Largest sample index the Sobol tables cover in one sequence (2^16).
const SEQUENCE_LENGTH: u32 = 1 << 16;
/// Dimensions of the underlying Sobol tables.
const TABLE_DIMENSIONS: u32 = sobol_burley::NUM_DIMENSIONS;

/// The Sobol sequence with Owen scrambling (Burley, "Practical Hash-based Owen Scrambling",
/// JCGT 2020; the `sobol_burley` crate, Joe–Kuo direction numbers).
///
/// Every pixel gets its own, independently scrambled and shuffled copy of the sequence (the
/// scrambling seed is a hash of the pixel and the sampler's seed), so neighbouring pixels are
/// decorrelated while the samples *within* a pixel keep the sequence's stratification: the first
/// 2^k samples of any dimension pair form a (0, k, 2)-net in base 2 for the first pairs.
///
/// Owen scrambling makes each sample uniform on [0, 1)^d, so estimators stay unbiased; their
/// variance falls faster than 1/N on smooth integrands. The sample variance of the estimates no
/// longer measures that error (the samples are not independent): compare independent
/// scramblings (different seeds) to estimate it.
///
/// Limits: `sobol_burley` covers 2^16 sample indices and 256 dimensions. Beyond them the sampler
/// switches to a fresh scramble for each block of 2^16 indices and each block of 256
/// dimensions; every sample stays uniform, and the blocks are independent randomisations.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    samples_per_pixel: u32,
    seed: u64,
    pixel_seed: u64,
    sample_index: u32,
    dimension: u32,
}

impl SobolSampler {
    /// A sampler for `samples_per_pixel` samples (any index works; powers of two are best
    /// stratified).
    pub fn new(samples_per_pixel: u32, seed: u64) -> Self {
        SobolSampler {
            samples_per_pixel,
            seed,
            pixel_seed: hash_pixel([0, 0], seed),
            sample_index: 0,
            dimension: 0,
        }
    }

    #[inline]
    fn sample_dimension(&self, dimension: u32) -> f32 {
        let index_block = self.sample_index / SEQUENCE_LENGTH;
        let dim_block = dimension / TABLE_DIMENSIONS;
        let scramble = if index_block == 0 && dim_block == 0 {
            self.pixel_seed
        } else {
            hash_words(&[self.pixel_seed, index_block as u64, dim_block as u64])
        };
        sobol_burley::sample(
            self.sample_index % SEQUENCE_LENGTH,
            dimension % TABLE_DIMENSIONS,
            scramble as u32,
        )
    }
}

impl Sampler for SobolSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        self.pixel_seed = hash_pixel(pixel, self.seed);
        self.sample_index = sample_index;
        self.dimension = dimension;
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        let v = self.sample_dimension(self.dimension);
        self.dimension += 1;
        v
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        let v = Vec2::new(
            self.sample_dimension(self.dimension),
            self.sample_dimension(self.dimension + 1),
        );
        self.dimension += 2;
        v
    }
}
