//! The independent sampler ([`IndependentSampler`]): uniform numbers from a PCG32 stream per
//! pixel, each sample and dimension at its own position in it, independent of one another.

use super::{Sampler, PATH_LANES};
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
    /// The pixel and sample index last started, and the generator at its dimension 0: a later
    /// sample of the same pixel starts from there (by squaring the one-sample jump) instead of
    /// from the hash.
    start: ([u32; 2], u32, Pcg32),
}

impl IndependentSampler {
    /// A sampler for `samples_per_pixel` samples (the count is only reported; any index works).
    pub fn new(samples_per_pixel: u32, seed: u64) -> Self {
        let rng = Pcg32::for_pixel_sample(seed, [0, 0], 0, 0);
        IndependentSampler {
            samples_per_pixel,
            seed,
            rng: rng.clone(),
            start: ([0, 0], 0, rng),
        }
    }
}

impl IndependentSampler {
    /// [`super::AnySampler::next_lanes`] for eight independent samplers: every request is one
    /// draw per dimension, in order, so the requests `dims` are their total of draws from
    /// each lane's generator, all lanes at once ([`Pcg32::uniform_f32_lanes`]).
    pub(crate) fn next_lanes(
        samplers: [&mut IndependentSampler; PATH_LANES],
        lanes: u32,
        dims: &[u32],
        out: &mut [[f32; PATH_LANES]],
    ) {
        let draws = dims.iter().sum::<u32>() as usize;
        Pcg32::uniform_f32_lanes(samplers.map(|s| &mut s.rng), lanes, &mut out[..draws]);
    }
}

impl Sampler for IndependentSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        // The same numbers as `Pcg32::for_pixel_sample(seed, pixel, sample_index, dimension)`
        // (tested); renders ask for a pixel's samples in order, one apart (or a few, when
        // several paths are followed at once).
        let (last_pixel, last_index, ref last) = self.start;
        let at_zero = if last_pixel == pixel && last_index <= sample_index {
            let mut rng = last.clone();
            rng.skip_pixel_samples(sample_index - last_index);
            rng
        } else {
            Pcg32::for_pixel_sample(self.seed, pixel, sample_index, 0)
        };
        self.rng = at_zero.clone();
        if dimension > 0 {
            self.rng.advance(u64::from(dimension));
        }
        self.start = (pixel, sample_index, at_zero);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_where_the_hashed_stream_does_in_any_order() {
        let mut s = IndependentSampler::new(16, 9);
        let mut order = Pcg32::new(1, 2);
        let mut requests = Vec::new();
        for pixel in [[0, 0], [3, 4], [3, 5]] {
            requests.extend((0..20).map(|i| (pixel, i, 0)));
        }
        for _ in 0..200 {
            let pixel = [order.next_u32() % 3, order.next_u32() % 2];
            let i = order.next_u32() % 4;
            let d = if order.next_u32().is_multiple_of(4) {
                order.next_u32() % 100
            } else {
                0
            };
            requests.push((pixel, i, d));
        }
        // Forward jumps of several samples, as lanes following paths together make.
        requests.extend((0..300).step_by(7).map(|i| ([2, 1], i, 0)));
        requests.push(([1, 1], u32::MAX, 0));
        requests.push(([1, 1], 0, 0));
        requests.push(([1, 1], u32::MAX, 0));
        for (pixel, i, d) in requests {
            s.start_pixel_sample(pixel, i, d);
            let mut expected = Pcg32::for_pixel_sample(9, pixel, i, d);
            for _ in 0..3 {
                assert_eq!(s.next_1d(), expected.uniform_f32(), "{pixel:?} {i} {d}");
            }
        }
    }
}
