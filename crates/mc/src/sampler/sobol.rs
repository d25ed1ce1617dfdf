//! The Sobol' sampler ([`SobolSampler`]): the first dimensions of Sobol's sequence in pairs,
//! each pair shuffled and Owen-scrambled by hashing, and its eight-lane draws.

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
        let v = padded_1d(self.index(), self.seed_for(self.dimension));
        self.dimension += 1;
        v
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        // Dimensions 0 and 1 with one index shuffle (see `padded_2d`).
        let [x, y] = padded_2d(self.index(), self.seed_for(self.dimension));
        let v = Vec2::new(x, y);
        self.dimension += 2;
        v
    }
}

// The first two Sobol dimensions in closed form. `sobol_burley` evaluates any dimension by
// XOR-ing one direction vector per set bit of the shuffled index (a loop of up to 16 steps with
// an unpredictable exit); the padded sampler needs only dimensions 0 and 1, whose generator
// matrices are the identity (van der Corput) and Pascal's triangle mod 2, both computable in a
// few bit operations. The index shuffle and the scrambles are the crate's own (`parts`), so the
// samples are `sobol_burley::sample(i, 0, seed)` and the first two of
// `sobol_burley::sample_4d(i, 0, seed)` to the bit (tested over every index).

/// The seed of the index shuffle, as `sobol_burley` derives it.
const SHUFFLE_SEED: u32 = 0x79c6_8e4a;
/// `sobol_burley`'s seed multiplier and per-dimension constants of the output scrambles.
const SCRAMBLE_MUL: u32 = 0x9c8f_2d3b;
const SCRAMBLE_DIM: [u32; 2] = [0x912f_69ba, 0x174f_18ab];

/// The 16-bit shuffled sample index (`sobol_burley` keeps its top 16 bits reversed).
#[inline(always)]
fn shuffled_index(sample_index: u32, seed: u32) -> u32 {
    use sobol_burley::parts::{hash, owen_scramble_rev};
    let rev = owen_scramble_rev(sample_index.reverse_bits(), hash(seed ^ SHUFFLE_SEED));
    (rev & 0xffff_0000).reverse_bits()
}

/// Sobol dimension 1 of index `n` (< 2^16), bit-reversed: bit `j` is the parity of the set bits
/// `k` of `n` with binomial(k, j) odd, i.e. with `j`'s bits a subset of `k`'s (Lucas), so the
/// sum over supersets of each bit position, taken one position bit at a time.
#[inline(always)]
fn pascal_rev(n: u32) -> u32 {
    let mut y = n;
    y ^= (y >> 1) & 0x5555;
    y ^= (y >> 2) & 0x3333;
    y ^= (y >> 4) & 0x0f0f;
    y ^= (y >> 8) & 0x00ff;
    y
}

/// Owen-scrambles the bit-reversed Sobol value `sobol_rev` of dimension `dim` as
/// `sobol_burley` does, and maps it to [0, 1).
#[inline(always)]
fn scrambled(sobol_rev: u32, dim: usize, seed: u32) -> f32 {
    use sobol_burley::parts::{hash, owen_scramble_rev, u32_to_f32_norm};
    let scramble = seed.wrapping_mul(SCRAMBLE_MUL) ^ SCRAMBLE_DIM[dim];
    u32_to_f32_norm(owen_scramble_rev(sobol_rev, hash(scramble)).reverse_bits())
}

/// `sobol_burley::sample(sample_index, 0, seed)`.
#[inline(always)]
fn padded_1d(sample_index: u32, seed: u32) -> f32 {
    // Dimension 0's generator is the identity: the bit-reversed value is the index itself.
    scrambled(shuffled_index(sample_index, seed), 0, seed)
}

/// The first two values of `sobol_burley::sample_4d(sample_index, 0, seed)`.
#[inline(always)]
fn padded_2d(sample_index: u32, seed: u32) -> [f32; 2] {
    let n = shuffled_index(sample_index, seed);
    [scrambled(n, 0, seed), scrambled(pascal_rev(n), 1, seed)]
}

pub use crate::simd::PATH_LANES;

impl SobolSampler {
    /// Draws for eight samplers at once what each would give for the requests `dims` (1 for
    /// [`Sampler::next_1d`], 2 for [`Sampler::next_2d`]) made in order, into `out`: a value per
    /// dimension, lane by lane (`out[k][lane]`). Only lanes whose bit is set in `lanes` draw.
    /// The same numbers as those calls (tested); the scrambles, which are most of the work,
    /// are computed for all lanes together, in vector registers.
    pub fn next_lanes(
        samplers: &mut [&mut SobolSampler; PATH_LANES],
        lanes: u32,
        dims: &[u32],
        out: &mut [[f32; PATH_LANES]],
    ) {
        let index: [u32; PATH_LANES] = std::array::from_fn(|lane| samplers[lane].index());
        let mut k = 0;
        for &n in dims {
            let mut seed = [0u32; PATH_LANES];
            for (lane, s) in samplers.iter_mut().enumerate() {
                if lanes & (1 << lane) != 0 {
                    seed[lane] = s.seed_for(s.dimension);
                    s.dimension += n;
                }
            }
            if n == 1 {
                out[k] = padded_lanes::<1>(&index, &seed)[0];
                k += 1;
            } else {
                [out[k], out[k + 1]] = padded_lanes::<2>(&index, &seed);
                k += 2;
            }
        }
    }
}

/// [`padded_1d`] (`N` = 1) or [`padded_2d`] (`N` = 2) for eight lanes: with AVX2 where the
/// CPU has it (eight 32-bit multiplies per instruction), else in the baseline's SSE2.
#[inline]
fn padded_lanes<const N: usize>(
    index: &[u32; PATH_LANES],
    seed: &[u32; PATH_LANES],
) -> [[f32; PATH_LANES]; N] {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `padded_lanes_avx2` requires AVX2, which this CPU has: the token `avx2`
        // exists. Its body is safe code.
        return unsafe { padded_lanes_avx2::<N>(avx2, index, seed) };
    }
    padded_lanes_portable::<N>(index, seed)
}

/// [`padded_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn padded_lanes_avx2<const N: usize>(
    _: crate::simd::Avx2,
    index: &[u32; PATH_LANES],
    seed: &[u32; PATH_LANES],
) -> [[f32; PATH_LANES]; N] {
    padded_lanes_portable::<N>(index, seed)
}

/// [`padded_lanes`] as loops over the lanes, which the compiler vectorises.
#[inline(always)]
fn padded_lanes_portable<const N: usize>(
    index: &[u32; PATH_LANES],
    seed: &[u32; PATH_LANES],
) -> [[f32; PATH_LANES]; N] {
    let mut out = [[0.0; PATH_LANES]; N];
    for lane in 0..PATH_LANES {
        if N == 1 {
            out[0][lane] = padded_1d(index[lane], seed[lane]);
        } else {
            let [x, y] = padded_2d(index[lane], seed[lane]);
            out[0][lane] = x;
            out[N - 1][lane] = y; // N is 2 here
        }
    }
    out
}

#[cfg(test)]
mod closed_form_tests {
    use super::*;

    #[test]
    fn first_two_dimensions_match_sobol_burley_at_every_index() {
        for seed in [0u32, 1, 0xdead_beef, 0x8000_0000, u32::MAX] {
            for i in 0..SEQUENCE_LENGTH {
                let [x, y, _, _] = sobol_burley::sample_4d(i, 0, seed);
                let [a, b] = padded_2d(i, seed);
                assert_eq!(
                    (a.to_bits(), b.to_bits()),
                    (x.to_bits(), y.to_bits()),
                    "{i} {seed}"
                );
                let one = sobol_burley::sample(i, 0, seed);
                assert_eq!(padded_1d(i, seed).to_bits(), one.to_bits(), "{i} {seed}");
            }
        }
    }
}
