use super::Sampler;
use crate::rng::{hash_pixel, hash_words, mix_bits};
use glam::Vec2;

/// Largest sample index the Sobol tables cover in one sequence (2^16).
const SEQUENCE_LENGTH: u32 = 1 << 16;

/// The Sobol sequence with Owen scrambling (Burley, "Practical Hash-based Owen Scrambling",
/// JCGT 2020; the `sobol_burley` crate, Joe–Kuo direction numbers).
///
/// Dimensions are "padded" (Burley 2020, §4; pbrt-v4's padded Sobol): every 1D or 2D request
/// uses the first one or two dimensions of the Sobol sequence — a (0, 2)-sequence in base 2,
/// the best-stratified there is — scrambled *and shuffled* with a seed hashed from the pixel,
/// the sampler's seed and the dimension. So within a pixel each request's samples are as
/// well stratified as the first two Sobol dimensions (the first 2^k samples of every `next_2d`
/// form a (0, k, 2)-net), while different requests, pixels and seeds are decorrelated by their
/// independent shuffles. The light and BSDF samples of the first bounces are thus stratified as
/// well as the pixel position.
///
/// Owen scrambling makes each sample uniform on [0, 1)^d, so estimators stay unbiased; their
/// variance falls faster than 1/N on smooth integrands. The sample variance of the estimates no
/// longer measures that error (the samples are not independent): compare independent
/// scramblings (different seeds) to estimate it.
///
/// Limits: `sobol_burley` covers 2^16 sample indices. Beyond them the sampler switches to a
/// fresh scramble for each block of 2^16 indices; every sample stays uniform, and the blocks
/// are independent randomisations. Dimensions are unlimited.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    samples_per_pixel: u32,
    seed: u64,
    /// Hash of the pixel, the seed and the block of 2^16 sample indices.
    sample_seed: u64,
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
            sample_seed: hash_pixel([0, 0], seed),
            sample_index: 0,
            dimension: 0,
        }
    }

    /// The scramble seed of the request at `dimension`: one mix of the pixel sample's hash
    /// (computed once per pixel sample) and the dimension.
    #[inline]
    fn seed_for(&self, dimension: u32) -> u32 {
        mix_bits(self.sample_seed ^ u64::from(dimension).wrapping_mul(0x9e37_79b9_7f4a_7c15)) as u32
    }

    #[inline]
    fn index(&self) -> u32 {
        self.sample_index % SEQUENCE_LENGTH
    }
}

impl Sampler for SobolSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        let index_block = u64::from(sample_index / SEQUENCE_LENGTH);
        self.sample_seed = hash_words(&[hash_pixel(pixel, self.seed), index_block]);
        self.sample_index = sample_index;
        self.dimension = dimension;
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        let v = sobol_burley::sample(self.index(), 0, self.seed_for(self.dimension));
        self.dimension += 1;
        v
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        // Dimensions 0 and 1 of the four `sample_4d` computes together (with SIMD, and one
        // index shuffle): the same values as two `sample` calls, at about a third of the cost.
        let [x, y, _, _] = sobol_burley::sample_4d(self.index(), 0, self.seed_for(self.dimension));
        let v = Vec2::new(x, y);
        self.dimension += 2;
        v
    }
}
