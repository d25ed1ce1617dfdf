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
