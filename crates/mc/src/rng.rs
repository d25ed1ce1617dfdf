//! Random numbers: the PCG32 generator and the hashing that derives reproducible streams.
//!
//! PCG32 (O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically Good Algorithms
//! for Random Number Generation", 2014) has 64 bits of state, 2^63 selectable streams and can
//! jump ahead by any distance in O(log distance) steps. Those two properties give every pixel
//! sample its own stream that depends only on `(seed, pixel, sample index, dimension)`:
//! the stream is chosen by a hash of `(pixel, seed)` and the position in it by
//! `sample index * 2^16 + dimension`, so the numbers a pixel sample sees never depend on which
//! thread computed it or in what order.

const PCG32_DEFAULT_STATE: u64 = 0x853c_49e6_748f_ea9b;
const PCG32_DEFAULT_STREAM: u64 = 0xda3e_39cb_94b9_5bdb;
const PCG32_MULT: u64 = 0x5851_f42d_4c95_7f2d;

/// Dimensions reserved for one pixel sample in a PCG32 stream: sample `i` of a pixel starts at
/// position `i * DIMENSIONS_PER_SAMPLE`.
pub const DIMENSIONS_PER_SAMPLE: u64 = 1 << 16;

/// The PCG32 generator (XSH-RR output on a 64-bit LCG).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Default for Pcg32 {
    fn default() -> Self {
        Pcg32 {
            state: PCG32_DEFAULT_STATE,
            inc: PCG32_DEFAULT_STREAM,
        }
    }
}

impl Pcg32 {
    /// A generator on stream `sequence`, started from `seed`.
    pub fn new(sequence: u64, seed: u64) -> Self {
        let mut rng = Pcg32::default();
        rng.set_sequence(sequence, seed);
        rng
    }

    /// Restarts the generator on stream `sequence` (any value; the top bit is ignored) with `seed`.
    pub fn set_sequence(&mut self, sequence: u64, seed: u64) {
        self.state = 0;
        self.inc = (sequence << 1) | 1;
        self.next_u32();
        self.state = self.state.wrapping_add(seed);
        self.next_u32();
    }

    /// The next 32 uniformly distributed bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = step(old, self.inc);
        output(old)
    }

    /// A uniform `f32` in [0, 1), with 24 random bits (every value is exactly representable).
    #[inline]
    pub fn uniform_f32(&mut self) -> f32 {
        to_unit_f32(self.next_u32())
    }

    /// A uniform `f64` in [0, 1), with 53 random bits.
    #[inline]
    pub fn uniform_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Jumps `delta` steps ahead in O(log delta) time (Brown, "Random number generation with
    /// arbitrary strides", 1994): the result equals calling [`Pcg32::next_u32`] `delta` times.
    #[inline]
    pub fn advance(&mut self, delta: u64) {
        let (mult, plus) = jump_coefficients(delta);
        self.state = mult
            .wrapping_mul(self.state)
            .wrapping_add(plus.wrapping_mul(self.inc));
    }

    /// Moves to the same dimension `samples` pixel samples on: [`Pcg32::advance`] by
    /// `samples` times [`DIMENSIONS_PER_SAMPLE`] (a jump per bit set in `samples`).
    #[inline]
    pub fn skip_pixel_samples(&mut self, samples: u32) {
        self.advance(u64::from(samples) * DIMENSIONS_PER_SAMPLE);
    }

    /// The generator for one pixel sample: stream chosen by `(seed, pixel)`, positioned at
    /// `sample_index * 2^16 + dimension`. A pure function of its arguments.
    #[inline]
    pub fn for_pixel_sample(seed: u64, pixel: [u32; 2], sample_index: u32, dimension: u32) -> Self {
        let mut rng = Pcg32::new(hash_pixel(pixel, seed), mix_bits(seed));
        rng.advance(sample_index as u64 * DIMENSIONS_PER_SAMPLE + dimension as u64);
        rng
    }
}

/// The LCG step from state `old` on the stream of increment `inc`.
#[inline(always)]
fn step(old: u64, inc: u64) -> u64 {
    old.wrapping_mul(PCG32_MULT).wrapping_add(inc)
}

/// The XSH-RR output of state `old`: 32 bits.
#[inline(always)]
fn output(old: u64) -> u32 {
    let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
    xorshifted.rotate_right((old >> 59) as u32)
}

/// 32 random bits as a uniform `f32` in [0, 1): the top 24, each value exactly representable.
#[inline(always)]
fn to_unit_f32(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Eight generators side by side, a lane each, for drawing from all of them at once.
pub(crate) const LANES: usize = 8;

impl Pcg32 {
    /// [`Pcg32::uniform_f32`] `out.len()` times from each generator of `rngs` whose bit is set
    /// in `lanes`: draw k into `out[k][lane]`. The same numbers as those calls, and each of
    /// those generators is left where the calls leave it; the other lanes of `out` and their
    /// generators are untouched. All lanes step together: with AVX-512 in one register of
    /// eight 64-bit states, with AVX2 in two.
    #[inline]
    pub(crate) fn uniform_f32_lanes(
        rngs: [&mut Pcg32; LANES],
        lanes: u32,
        out: &mut [[f32; LANES]],
    ) {
        let mut state: [u64; LANES] = std::array::from_fn(|i| rngs[i].state);
        let inc: [u64; LANES] = std::array::from_fn(|i| rngs[i].inc);
        let mut drawn = [[0.0f32; LANES]; 8];
        // The lanes' draws replace `out`'s values where a lane is active: by a mask of bits
        // rather than a branch per lane, so that the copy is one blend per row.
        let keep: [u32; LANES] = std::array::from_fn(|i| 0u32.wrapping_sub((lanes >> i) & 1));
        for chunk in out.chunks_mut(drawn.len()) {
            let drawn = &mut drawn[..chunk.len()];
            draw_lanes(&mut state, &inc, drawn);
            for (o, d) in chunk.iter_mut().zip(drawn.iter()) {
                for i in 0..LANES {
                    let bits = (d[i].to_bits() & keep[i]) | (o[i].to_bits() & !keep[i]);
                    o[i] = f32::from_bits(bits);
                }
            }
        }
        for (i, rng) in rngs.into_iter().enumerate() {
            if lanes & (1 << i) != 0 {
                rng.state = state[i];
            }
        }
    }
}

/// `out.len()` draws of [`Pcg32::uniform_f32`] from every lane's generator (`state`, `inc`),
/// on the best vector unit this CPU has.
#[inline]
fn draw_lanes(state: &mut [u64; LANES], inc: &[u64; LANES], out: &mut [[f32; LANES]]) {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx512) = crate::simd::Avx512::detect() {
        // SAFETY: `draw_lanes_avx512` requires the AVX-512 subsets, AVX2 and FMA that
        // `avx512` proves this CPU has. Its body is safe code.
        return unsafe { draw_lanes_avx512(avx512, state, inc, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = crate::simd::Avx2::detect() {
        // SAFETY: `draw_lanes_avx2` requires AVX2 and FMA, which `avx2` proves this CPU has.
        // Its body is safe code.
        return unsafe { draw_lanes_avx2(avx2, state, inc, out) };
    }
    draw_lanes_portable(state, inc, out)
}

/// [`draw_lanes_portable`] compiled for AVX-512 (a 64-bit multiply per lane in one
/// instruction, and a rotate by a variable amount).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
fn draw_lanes_avx512(
    _: crate::simd::Avx512,
    state: &mut [u64; LANES],
    inc: &[u64; LANES],
    out: &mut [[f32; LANES]],
) {
    draw_lanes_portable(state, inc, out)
}

/// [`draw_lanes_portable`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn draw_lanes_avx2(
    _: crate::simd::Avx2,
    state: &mut [u64; LANES],
    inc: &[u64; LANES],
    out: &mut [[f32; LANES]],
) {
    draw_lanes_portable(state, inc, out)
}

/// [`Pcg32::uniform_f32`]'s step, output and conversion on every lane: loops over the lanes
/// that the compiler turns into vector instructions.
#[inline(always)]
fn draw_lanes_portable(state: &mut [u64; LANES], inc: &[u64; LANES], out: &mut [[f32; LANES]]) {
    for row in out.iter_mut() {
        for i in 0..LANES {
            let old = state[i];
            state[i] = step(old, inc[i]);
            row[i] = to_unit_f32(output(old));
        }
    }
}

/// `(m, p)` such that `delta` steps of the generator take `state` to `m · state + p · inc`
/// (Brown, "Random Number Generation with Arbitrary Strides", 1994): the jumps of 2^k steps
/// ([`POWER_OF_TWO_JUMPS`]) of the bits set in `delta`, composed. Every jump is a power of
/// the one-step map, so they commute and the result is the one map of `delta` steps.
#[inline]
fn jump_coefficients(mut delta: u64) -> (u64, u64) {
    let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
    while delta != 0 {
        let (mult, plus) = POWER_OF_TWO_JUMPS[delta.trailing_zeros() as usize];
        acc_mult = acc_mult.wrapping_mul(mult);
        acc_plus = acc_plus.wrapping_mul(mult).wrapping_add(plus);
        delta &= delta - 1;
    }
    (acc_mult, acc_plus)
}

/// Entry k: the coefficients `(m, p)` of 2^k steps, by squaring the one-step map k times.
const POWER_OF_TWO_JUMPS: [(u64, u64); 64] = {
    let mut table = [(0u64, 0u64); 64];
    let (mut mult, mut plus) = (PCG32_MULT, 1u64);
    let mut k = 0;
    while k < 64 {
        table[k] = (mult, plus);
        plus = mult.wrapping_add(1).wrapping_mul(plus);
        mult = mult.wrapping_mul(mult);
        k += 1;
    }
    table
};

/// A 64-bit finaliser with good avalanche (every input bit flips each output bit with
/// probability close to 1/2); the constants are those of Stafford's "Mix13" variant.
#[inline]
pub fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Hashes a list of words into 64 bits (order matters).
#[inline]
pub fn hash_words(words: &[u64]) -> u64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for &w in words {
        h = mix_bits(h ^ mix_bits(w.wrapping_add(0x632b_e59b_d9b4_e019)));
    }
    h
}

/// Hash of a pixel and a seed, used to pick a pixel's stream or scramble.
#[inline]
pub fn hash_pixel(pixel: [u32; 2], seed: u64) -> u64 {
    hash_words(&[((pixel[0] as u64) << 32) | pixel[1] as u64, seed])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_matches_stepping() {
        let mut a = Pcg32::new(7, 11);
        let mut b = a.clone();
        for _ in 0..1000 {
            a.next_u32();
        }
        b.advance(1000);
        assert_eq!(a, b);
        assert_eq!(a.next_u32(), b.next_u32());
    }

    #[test]
    fn jumps_of_any_distance_are_the_squared_one_step_map() {
        // The reference: Brown's algorithm, squaring the one-step map for every bit.
        let squared = |mut delta: u64| {
            let (mut mult, mut plus) = (PCG32_MULT, 1u64);
            let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
            while delta > 0 {
                if delta & 1 == 1 {
                    acc_mult = acc_mult.wrapping_mul(mult);
                    acc_plus = acc_plus.wrapping_mul(mult).wrapping_add(plus);
                }
                plus = mult.wrapping_add(1).wrapping_mul(plus);
                mult = mult.wrapping_mul(mult);
                delta >>= 1;
            }
            (acc_mult, acc_plus)
        };
        let mut rng = Pcg32::new(5, 6);
        let edges = [0, 1, 2, 1 << 16, (1 << 16) + 3, 1 << 63, u64::MAX];
        let random = (0..1000).map(|_| u64::from(rng.next_u32()) << 32 | u64::from(rng.next_u32()));
        for delta in edges.into_iter().chain(random) {
            assert_eq!(jump_coefficients(delta), squared(delta), "{delta}");
        }
        // Skipping k samples is advancing by their dimensions, and jumps add.
        for k in [0u32, 1, 7, 64, 1 << 20] {
            let mut a = Pcg32::new(3, 4);
            let mut b = a.clone();
            a.skip_pixel_samples(k);
            b.advance(u64::from(k) * DIMENSIONS_PER_SAMPLE / 2);
            b.advance(u64::from(k) * DIMENSIONS_PER_SAMPLE / 2);
            assert_eq!(a, b, "{k}");
        }
    }

    #[test]
    fn streams_differ_and_repeat() {
        let mut a = Pcg32::new(1, 42);
        let mut b = Pcg32::new(2, 42);
        let mut c = Pcg32::new(1, 42);
        let va: Vec<u32> = (0..8).map(|_| a.next_u32()).collect();
        let vb: Vec<u32> = (0..8).map(|_| b.next_u32()).collect();
        let vc: Vec<u32> = (0..8).map(|_| c.next_u32()).collect();
        assert_ne!(va, vb);
        assert_eq!(va, vc);
    }

    #[test]
    fn pixel_sample_streams_are_positioned() {
        // Dimension d of sample i is the (i * 2^16 + d)-th number of the pixel's stream.
        let mut base = Pcg32::for_pixel_sample(3, [10, 20], 0, 0);
        base.advance(5 * DIMENSIONS_PER_SAMPLE + 2);
        let mut direct = Pcg32::for_pixel_sample(3, [10, 20], 5, 2);
        assert_eq!(base.next_u32(), direct.next_u32());
        let other_pixel = Pcg32::for_pixel_sample(3, [20, 10], 5, 2);
        assert_ne!(other_pixel, Pcg32::for_pixel_sample(3, [10, 20], 5, 2));
    }

    #[test]
    fn uniform_ranges() {
        let mut rng = Pcg32::new(0, 0);
        for _ in 0..100_000 {
            let f = rng.uniform_f32();
            assert!((0.0..1.0).contains(&f));
            let d = rng.uniform_f64();
            assert!((0.0..1.0).contains(&d));
        }
    }

    #[test]
    fn lanes_draw_what_each_generator_draws_on_every_vector_unit() {
        let gens: [Pcg32; LANES] =
            std::array::from_fn(|i| Pcg32::new(7 * i as u64 + 1, 3 * i as u64));
        for mask in [0xff, 0b1010_0110, 0b1, 0] {
            for n in [1, 7, 8, 9, 17] {
                let mut expect = gens.clone();
                let mut want = vec![[-1.0f32; LANES]; n];
                for (i, rng) in expect.iter_mut().enumerate() {
                    if mask & (1 << i) != 0 {
                        for row in want.iter_mut() {
                            row[i] = rng.uniform_f32();
                        }
                    }
                }
                let mut got_gens = gens.clone();
                let mut got = vec![[-1.0f32; LANES]; n];
                Pcg32::uniform_f32_lanes(got_gens.each_mut(), mask, &mut got);
                assert_eq!(got, want, "mask {mask:#b}, {n} draws");
                assert_eq!(got_gens, expect, "mask {mask:#b}, {n} draws");
            }
        }
        // Each vector unit's compilation of the step, against the portable one.
        let state0: [u64; LANES] = std::array::from_fn(|i| gens[i].state);
        let inc: [u64; LANES] = std::array::from_fn(|i| gens[i].inc);
        type Draw<'a> = &'a dyn Fn(&mut [u64; LANES], &mut [[f32; LANES]]);
        let run = |f: Draw| {
            let mut state = state0;
            let mut out = vec![[0.0f32; LANES]; 33];
            f(&mut state, &mut out);
            (state, out)
        };
        let portable = run(&|s, o| draw_lanes_portable(s, &inc, o));
        assert_eq!(run(&|s, o| draw_lanes(s, &inc, o)), portable);
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(avx2) = crate::simd::Avx2::detect() {
                // SAFETY: `avx2` proves the CPU has what the function is compiled for.
                assert_eq!(
                    run(&|s, o| unsafe { draw_lanes_avx2(avx2, s, &inc, o) }),
                    portable
                );
            }
            if let Some(avx512) = crate::simd::Avx512::detect() {
                // SAFETY: `avx512` proves the CPU has what the function is compiled for.
                assert_eq!(
                    run(&|s, o| unsafe { draw_lanes_avx512(avx512, s, &inc, o) }),
                    portable
                );
            }
        }
    }
}
