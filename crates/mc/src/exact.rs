//! Exact, order-independent sums of samples: Σx and Σx² in 128-bit fixed point.
//!
//! Floating-point sums depend on the order of their terms, so an image accumulated pass by
//! pass, resumed from a checkpoint, or merged from shards rendered on other machines would
//! differ in its last bits from one rendered in one go. Here each sample is rounded once, on
//! its own, to a multiple of 2^-[`FRACTION_BITS`] (every `f32` of magnitude at least 2^-24 is
//! represented exactly), and the rounded values are added as integers: the sums, and every
//! statistic computed from them, are the same for any order and grouping of the samples.
//! Sums saturate instead of wrapping (at about 6·10^23, far beyond radiance × samples).

/// Fraction bits of the fixed point.
pub const FRACTION_BITS: i32 = 48;

/// 2^FRACTION_BITS.
const ONE: f64 = (1u64 << FRACTION_BITS) as f64;

/// Count, Σx and Σx² of a set of values, exactly (see the module notes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactStats {
    n: u64,
    sum: i128,
    sum_sq: i128,
}

/// `x` in fixed point, rounded to nearest, halves away from zero (saturating; NaN as 0).
#[inline]
pub fn to_fixed(x: f64) -> i128 {
    // Scaling by a power of two is exact. Below 2^52 adding ±½ and truncating rounds (one
    // hardware conversion to i64, where i128 conversion and `round` are library calls);
    // from 2^52 on the scaled value is already an integer.
    let v = x * ONE;
    if v.abs() < (1u64 << 52) as f64 {
        let w = v + 0.5f64.copysign(v);
        // SAFETY: |v| < 2^52, so w is finite with |w| <= 2^52 + 1/2, and its truncation fits
        // in an i64: the conditions of `to_int_unchecked`. (NaN fails the test above.) It
        // spares the checks `as i64` makes for an arbitrary `f64`.
        i128::from(unsafe { w.to_int_unchecked::<i64>() })
    } else {
        v as i128
    }
}

/// `sum.saturating_add(to_fixed(x))`, the same to the bit, with the common case (a sum far
/// from the bounds) in fewer instructions: the 128-bit addition saturates only when it
/// overflows, which sums of radiance never do in practice.
#[inline]
pub fn add_fixed(sum: i128, x: f64) -> i128 {
    let r = to_fixed(x);
    match sum.checked_add(r) {
        Some(s) => s,
        None => sum.saturating_add(r),
    }
}

/// Eight 128-bit fixed-point sums, each held as its low 64 bits (in `lo`) and its high 64 bits
/// (in `hi`): the eight low halves side by side, then the eight high halves, so that
/// [`add_fixed_with_squares`] in AVX-512 registers reads and writes each half of all eight as
/// one block, with no shuffling between halves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub struct Sums8 {
    lo: [u64; 8],
    hi: [i64; 8],
}

impl Sums8 {
    /// The sums `v`.
    pub fn from_array(v: [i128; 8]) -> Sums8 {
        let mut s = Sums8::default();
        for (k, &v) in v.iter().enumerate() {
            s.set(k, v);
        }
        s
    }

    /// The eight sums.
    pub fn to_array(&self) -> [i128; 8] {
        std::array::from_fn(|k| self.get(k))
    }

    /// Sum `k`.
    #[inline]
    pub fn get(&self, k: usize) -> i128 {
        (i128::from(self.hi[k]) << 64) | i128::from(self.lo[k])
    }

    /// Sets sum `k` to `v`.
    #[inline]
    pub fn set(&mut self, k: usize, v: i128) {
        // The low 64 bits, and the high 64 (an arithmetic shift: exact).
        self.lo[k] = v as u64;
        self.hi[k] = (v >> 64) as i64;
    }
}

/// Four values and their squares added to eight sums: sum `k` gains `x[k]` and sum `4 + k`
/// gains `x[k]²` (the value widened to `f64`, then squared), each by [`add_fixed`]. In a build
/// for AVX-512 CPUs the eight go together (F and DQ, whose conversion of eight `f64` to `i64`
/// is the one-value path's conversion) where every value converts within `i64` and no sum
/// saturates; otherwise one at a time. The same sums to the bit either way. (Only where the
/// whole build has AVX-512, so that the eight-lane code is inlined: called out of line from a
/// build for older CPUs it measured slower than the one-at-a-time code inlined; and inlined
/// always, since its values passed through memory would be stored one at a time and read back
/// as one block.)
#[inline(always)]
pub fn add_fixed_with_squares(sums: &mut Sums8, x: [f32; 4]) {
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx512f",
        target_feature = "avx512dq"
    ))]
    if let Some(avx512) = crate::simd::Avx512::detect() {
        // SAFETY: `add_fixed_with_squares_avx512` requires AVX-512 F and DQ, which `avx512`
        // proves this CPU has.
        if unsafe { add_fixed_with_squares_avx512(avx512, sums, x) } {
            return;
        }
    }
    let [r, g, b, y] = x;
    add_fixed_with_squares_one_at_a_time(sums, r, g, b, y);
}

/// [`add_fixed_with_squares`] one value at a time, the values passed one by one: as an array
/// they would go through memory, stored one at a time and read back as one block, a read that
/// waits for the stores (as they would in a loop over an array).
#[inline]
fn add_fixed_with_squares_one_at_a_time(sums: &mut Sums8, r: f32, g: f32, b: f32, y: f32) {
    let mut add = |k: usize, x: f32| {
        let v = f64::from(x);
        sums.set(k, add_fixed(sums.get(k), v));
        sums.set(4 + k, add_fixed(sums.get(4 + k), v * v));
    };
    add(0, r);
    add(1, g);
    add(2, b);
    add(3, y);
}

/// [`add_fixed_with_squares`] in AVX-512 registers: the values and squares widened and
/// multiplied as there, each scaled and rounded as [`to_fixed`] does (adding ±½ below 2^52,
/// where the scaled value may have a fraction; truncating), and added to the sums' low halves,
/// the carry and the sign extension to their high halves. Returns false, with `sums`
/// untouched, where a scaled value is 2^63 or more in magnitude or NaN (its conversion is not
/// an `i64`'s) or a sum would saturate: the one-value path handles those.
#[cfg(target_arch = "x86_64")]
#[cfg_attr(
    not(all(target_feature = "avx512f", target_feature = "avx512dq")),
    allow(dead_code)
)]
#[target_feature(enable = "avx512f,avx512dq")]
#[inline]
fn add_fixed_with_squares_avx512(_: crate::simd::Avx512, sums: &mut Sums8, x: [f32; 4]) -> bool {
    use std::arch::x86_64::*;
    // Set from the four values, not loaded as one block: a caller that has just stored them
    // one at a time would make a 16-byte load wait for the four stores to retire.
    let values = _mm256_cvtps_pd(_mm_setr_ps(x[0], x[1], x[2], x[3]));
    let squares = _mm256_mul_pd(values, values);
    let x = _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(values), squares);
    let v = _mm512_mul_pd(x, _mm512_set1_pd(ONE));
    let sign = _mm512_set1_pd(-0.0);
    let abs = _mm512_andnot_pd(sign, v);
    // Below 2^63 in magnitude (NaN compares false): the truncation fits in an i64.
    if _mm512_cmp_pd_mask::<_CMP_LT_OQ>(abs, _mm512_set1_pd(2f64.powi(63))) != 0xff {
        return false;
    }
    let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(abs, _mm512_set1_pd((1u64 << 52) as f64));
    let half = _mm512_or_pd(_mm512_and_pd(v, sign), _mm512_set1_pd(0.5));
    let r = _mm512_cvttpd_epi64(_mm512_mask_add_pd(v, small, v, half));
    // SAFETY: `lo` and `hi` are eight 64-bit integers each, read unaligned as one block.
    let (lo, hi) = unsafe {
        (
            _mm512_loadu_si512(sums.lo.as_ptr().cast()),
            _mm512_loadu_si512(sums.hi.as_ptr().cast()),
        )
    };
    // (hi, lo) + (r's sign extension, r): the low halves wrap, and carry where the wrapped
    // sum is below the addend (as unsigned numbers).
    let lo_sum = _mm512_add_epi64(lo, r);
    let carry = _mm512_cmplt_epu64_mask(lo_sum, r);
    let extension = _mm512_srai_epi64::<63>(r);
    let hi_plain = _mm512_add_epi64(hi, extension);
    let hi_sum = _mm512_mask_sub_epi64(hi_plain, carry, hi_plain, _mm512_set1_epi64(-1));
    // Signed overflow: the addends' signs agree and the sum's differs from them.
    let overflow = _mm512_andnot_si512(
        _mm512_xor_si512(hi, extension),
        _mm512_xor_si512(hi, hi_sum),
    );
    if _mm512_movepi64_mask(overflow) != 0 {
        return false;
    }
    // SAFETY: as the loads above, written back.
    unsafe {
        _mm512_storeu_si512(sums.lo.as_mut_ptr().cast(), lo_sum);
        _mm512_storeu_si512(sums.hi.as_mut_ptr().cast(), hi_sum);
    }
    true
}

/// A fixed-point value as `f64` (rounded to nearest).
#[inline]
pub fn from_fixed(v: i128) -> f64 {
    v as f64 / ONE
}

impl ExactStats {
    /// No values yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The statistics of raw parts (as [`ExactStats::raw`] gives them).
    pub fn from_raw(n: u64, sum: i128, sum_sq: i128) -> Self {
        ExactStats { n, sum, sum_sq }
    }

    /// Count, Σx and Σx² in fixed point.
    pub fn raw(&self) -> (u64, i128, i128) {
        (self.n, self.sum, self.sum_sq)
    }

    /// Adds one value.
    #[inline]
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        self.sum = add_fixed(self.sum, x);
        self.sum_sq = add_fixed(self.sum_sq, x * x);
    }

    /// Adds the values of another set: exactly the same as pushing them here.
    #[inline]
    pub fn merge(&mut self, o: &ExactStats) {
        self.n += o.n;
        self.sum = self.sum.saturating_add(o.sum);
        self.sum_sq = self.sum_sq.saturating_add(o.sum_sq);
    }

    /// Number of values.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Their mean (0 when empty).
    pub fn mean(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            from_fixed(self.sum) / self.n as f64
        }
    }

    /// The unbiased sample variance (0 with fewer than two values). It is computed as
    /// n/(n-1) (Σx²/n - mean²); differences within the rounding of the fixed-point squares and
    /// of that subtraction count as zero, so equal values have variance exactly 0.
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        let n = self.n as f64;
        let mean = self.mean();
        let mean_sq = from_fixed(self.sum_sq) / n;
        let population = mean_sq - mean * mean;
        let rounding = 1.0 / ONE + 8.0 * f64::EPSILON * mean_sq.abs();
        if population <= rounding {
            0.0
        } else {
            population * n / (n - 1.0)
        }
    }

    /// Standard deviation, √variance.
    pub fn std_dev(&self) -> f64 {
        self.variance().sqrt()
    }

    /// Standard error of the mean, √(variance / n).
    pub fn std_error(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.variance() / self.n as f64).sqrt()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::RunningStats;

    #[test]
    fn sums_do_not_depend_on_order_or_grouping() {
        let xs: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919 % 1013) as f64 * 0.37).sin().abs() * 10f64.powi(i % 7 - 3))
            .collect();
        let mut forward = ExactStats::new();
        xs.iter().for_each(|&x| forward.push(x));
        let mut backward = ExactStats::new();
        xs.iter().rev().for_each(|&x| backward.push(x));
        let (mut a, mut b) = (ExactStats::new(), ExactStats::new());
        xs[..333].iter().for_each(|&x| a.push(x));
        xs[333..].iter().for_each(|&x| b.push(x));
        b.merge(&a);
        assert_eq!(forward, backward);
        assert_eq!(forward, b);
        // ... and agree with Welford's running statistics to rounding.
        let mut w = RunningStats::new();
        xs.iter().for_each(|&x| w.push(x));
        assert!((forward.mean() - w.mean()).abs() < 1e-12 * w.mean());
        assert!((forward.variance() - w.variance()).abs() < 1e-9 * w.variance());
    }

    #[test]
    fn adding_in_fixed_point_is_saturating_add_of_the_checked_conversion() {
        // Values on both sides of the fast path's bound (|x| < 16, v = x 2^48 < 2^52), halves
        // of the fixed point's unit, non-finite values; sums at zero and by both bounds.
        let unit = 1.0 / ONE;
        let bound = 16.0f64;
        let mut values = vec![
            0.0,
            -0.0,
            unit / 2.0,
            -unit / 2.0,
            1.5 * unit,
            -2.5 * unit,
            bound,
            -bound,
            bound.next_down(),
            (-bound).next_up(),
            1e30,
            -1e30,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut rng = crate::rng::Pcg32::new(3, 9);
        values.extend((0..200).map(|_| (rng.uniform_f64() - 0.5) * 40.0));
        let sums = [
            0,
            1,
            -1,
            i128::MAX,
            i128::MIN,
            i128::MAX - (1 << 40),
            i128::MIN + (1 << 40),
        ];
        for &x in &values {
            // The fast path's conversion is the checked cast's.
            let v = x * ONE;
            if v.abs() < (1u64 << 52) as f64 {
                assert_eq!(to_fixed(x), (v + 0.5f64.copysign(v)) as i64 as i128, "{x}");
            }
            for &sum in &sums {
                assert_eq!(
                    add_fixed(sum, x),
                    sum.saturating_add(to_fixed(x)),
                    "{sum} + {x}"
                );
            }
        }
    }

    #[test]
    fn values_and_squares_at_once_are_the_one_at_a_time_sums() {
        // Values whose scaled value or square sits by the AVX-512 path's bounds (2^52 for the
        // rounding, 2^63 for the conversion: x 2^48 and x² 2^48 at 16, 4, 2^15 and 181.02),
        // halves of the fixed point's unit, non-finite values, and sums at zero and by both
        // bounds, four values at a time in the arrangements a seeded shuffle gives: the
        // AVX-512 path either declines (leaving the sums alone) or gives the one-value path's
        // sums, and `add_fixed_with_squares` always gives them.
        let unit = (1.0 / ONE) as f32;
        let mut values = vec![
            0.0f32,
            -0.0,
            unit / 2.0,
            -unit * 1.5,
            2f32.powi(-24),
            4.0,
            4f32.next_down(),
            -4f32.next_up(),
            16.0,
            16f32.next_down(),
            -16.0,
            181.0,
            182.0,
            32768.0,
            32768f32.next_down(),
            -32768.0,
            1e30,
            f32::MAX,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let special = values.len();
        let mut rng = crate::rng::Pcg32::new(5, 7);
        values.extend((0..300).map(|_| {
            let scale = 10f64.powi((rng.uniform_f64() * 10.0) as i32 - 7);
            ((rng.uniform_f64() - 0.5) * scale) as f32
        }));
        let sums = [
            0,
            1,
            -1,
            1 << 70,
            -(1 << 90),
            i128::MAX,
            i128::MIN,
            i128::MAX - (1 << 40),
            i128::MIN + (1 << 40),
        ];
        let mut at_once = 0;
        for round in 0..4000 {
            let mut pick = |n: usize| (rng.uniform_f64() * n as f64) as usize % n;
            // Mostly ordinary values and sums, so that the AVX-512 path runs.
            let x: [f32; 4] = std::array::from_fn(|_| match round % 4 {
                0 => values[pick(values.len())],
                _ => values[special + pick(300)],
            });
            let start: [i128; 8] = std::array::from_fn(|_| match round % 3 {
                0 => sums[pick(sums.len())],
                _ => sums[pick(5)],
            });
            // The one-value path on plain 128-bit integers.
            let mut want = start;
            let mut add = |k: usize, x: f32| {
                let v = f64::from(x);
                want[k] = add_fixed(want[k], v);
                want[4 + k] = add_fixed(want[4 + k], v * v);
            };
            (0..4).for_each(|k| add(k, x[k]));
            let plain = start;
            let start = Sums8::from_array(start);
            assert_eq!(start.to_array(), plain, "split into halves and back");
            let mut one = start;
            add_fixed_with_squares_one_at_a_time(&mut one, x[0], x[1], x[2], x[3]);
            assert_eq!(one.to_array(), want, "{start:?} + {x:?}");
            let mut got = start;
            add_fixed_with_squares(&mut got, x);
            assert_eq!(got.to_array(), want, "{start:?} + {x:?}");
            #[cfg(target_arch = "x86_64")]
            if let Some(avx512) = crate::simd::Avx512::detect() {
                let mut lanes = start;
                // SAFETY: `avx512` proves the features the function requires.
                if unsafe { add_fixed_with_squares_avx512(avx512, &mut lanes, x) } {
                    assert_eq!(lanes.to_array(), want, "{start:?} + {x:?}");
                    at_once += 1;
                } else {
                    assert_eq!(lanes, start, "declined, yet changed");
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if crate::simd::Avx512::detect().is_some() {
            assert!(at_once > 1000, "the AVX-512 path ran {at_once} times");
        }
    }

    #[test]
    fn fixed_point_rounds_to_nearest() {
        let unit = 1.0 / ONE;
        for (x, want) in [
            (0.0, 0i128),
            (unit * 2.5, 3),
            (-unit * 2.5, -3),
            (unit * 2.4, 2),
            (1.0, 1i128 << 48),
            (-3.25, -(13i128 << 46)),
            (1e10, (1e10 * ONE) as i128),
            (f64::NAN, 0),
        ] {
            assert_eq!(to_fixed(x), want, "{x}");
        }
        assert_eq!(to_fixed(f64::INFINITY), i128::MAX);
        // Every f32 from 2^-24 up is exact.
        for x in [2f32.powi(-24), 0.3, 1234.5678, 3e7] {
            assert_eq!(from_fixed(to_fixed(x as f64)), x as f64);
        }
    }

    #[test]
    fn equal_values_have_no_variance_and_f32_values_are_exact() {
        let mut s = ExactStats::new();
        for _ in 0..1000 {
            s.push(0.3f32 as f64);
        }
        assert_eq!(s.variance(), 0.0);
        assert_eq!(s.mean(), 0.3f32 as f64);
        let mut t = ExactStats::new();
        t.push(1.0);
        t.push(3.0);
        assert_eq!((t.mean(), t.variance()), (2.0, 2.0));
        assert_eq!(ExactStats::new().mean(), 0.0);
    }
}
