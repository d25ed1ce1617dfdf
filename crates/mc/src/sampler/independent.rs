use super::Sampler;
use crate::rng::Pcg32;
use glam::Vec2;

/// Independent uniform random numbers: every dimension of every sample is an independent draw.
///
/// Dimension `d` of sample `i` of a pixel is number `i * 2^16 + d` of a PCG32 stream chosen by
/// hashing `(pixel, seed)`; so a pixel sample may use up to 65 536 dimensions before it would
/// overlap the next sample's numbers.
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    samples_per_pixel: u32,
    seed: u64,
    rng: Pcg32,
}

impl IndependentSampler {
    /// A sampler for `samples_per_pixel` samples (the count is only reported; any index works).
    pub fn new(samples_per_pixel: u32, seed: u64) -> Self {
        IndependentSampler {
            samples_per_pixel,
            seed,
            rng: Pcg32::for_pixel_sample(seed, [0, 0], 0, 0),
        }
    }
}

impl Sampler for IndependentSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        self.rng = Pcg32::for_pixel_sample(self.seed, pixel, sample_index, dimension);
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        self.rng.uniform_f32()
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        let x = self.rng.uniform_f32();
        Vec2::new(x, self.rng.uniform_f32())
    }
}
