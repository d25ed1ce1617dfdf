//! Trigonometric functions written once over [`Real`], so that one `f32` and eight lanes
//! compute the same bits, and faster than the C library's where the renderer calls them
//! often: [`atan2`] (an environment map's u of a direction).

use super::lanes::Real;
use std::f32::consts::{FRAC_PI_2, PI};

/// atan(t) = t + t³ P(t²) on [0, 1]: P's coefficients, lowest first, a minimax fit of the
/// relative error (Lawson's weighted least squares, in `f64`); evaluated in `f32` by Horner's
/// rule the result is within 1.2 units in the last place of atan(t) on [0, 1].
const ATAN: [f32; 8] = [
    -0.333_331_53,
    0.199_937_73,
    -0.142_110_56,
    0.106_660_04,
    -0.075_522_125,
    0.043_211_836,
    -0.016_367_912,
    0.002_920_688,
];

/// The angle of the point (x, y) from the positive x axis, in [-π, π], as `f32::atan2`
/// (within 2 units in the last place; 0 at the origin, where the C library gives 0 or ±π by
/// the signs of the zeros; NaN where either is NaN or both are infinite). Branch-free: the
/// ratio of the smaller to the larger of |x|, |y| into the polynomial [`ATAN`], then the
/// octant's reflections.
#[inline(always)]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay.gt(ax);
    let (num, den) = (R::select(steep, ax, ay), R::select(steep, ay, ax));
    let zero = R::splat(0.0);
    // den is 0 only at the origin (0/0, not selected there).
    let t = R::select(den.equals(zero), zero, num / den);
    let s = t * t;
    let mut p = R::splat(ATAN[7]);
    for &c in ATAN[..7].iter().rev() {
        p = p * s + R::splat(c);
    }
    let a = t + t * s * p;
    let a = R::select(steep, R::splat(FRAC_PI_2) - a, a);
    let a = R::select(x.lt(zero), R::splat(PI) - a, a);
    a * y.sign_one()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::lanes::F8;

    /// Distance in units in the last place between `a` and the `f64` value `exact`.
    fn ulps(a: f32, exact: f64) -> f64 {
        let e = exact as f32;
        ((f64::from(a) - exact) / f64::from(e.abs().max(f32::MIN_POSITIVE) * f32::EPSILON)).abs()
    }

    #[test]
    fn atan2_is_within_two_units_in_the_last_place_of_the_exact_angle() {
        let mut worst = 0.0f64;
        // Every direction on a fine circle, and radii from tiny to huge.
        for k in 0..200_000 {
            let phi = (k as f64 + 0.37) / 200_000.0 * std::f64::consts::TAU - std::f64::consts::PI;
            for r in [1e-30f64, 1e-3, 1.0, 7.5, 1e30] {
                let (x, y) = ((r * phi.cos()) as f32, (r * phi.sin()) as f32);
                let exact = f64::from(y).atan2(f64::from(x));
                let got = atan2(y, x);
                worst = worst.max(ulps(got, exact));
                assert!(
                    ulps(got, exact) <= 2.0,
                    "atan2({y}, {x}) = {got}, exactly {exact}"
                );
            }
        }
        assert!(worst > 0.5, "the comparison measures something ({worst})");
    }

    #[test]
    fn atan2_on_the_axes_and_at_the_origin() {
        for (y, x, want) in [
            (0.0f32, 1.0f32, 0.0f32),
            (1.0, 0.0, FRAC_PI_2),
            (-1.0, 0.0, -FRAC_PI_2),
            (0.0, -1.0, PI),
            (-0.0, -1.0, -PI),
            (-0.0, 1.0, -0.0),
            (1.0, 1.0, std::f32::consts::FRAC_PI_4),
            (0.0, 0.0, 0.0),
        ] {
            assert_eq!(atan2(y, x).to_bits(), want.to_bits(), "atan2({y}, {x})");
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }

    #[test]
    fn eight_lanes_give_the_one_value_bits() {
        let mut rng = crate::rng::Pcg32::new(3, 7);
        for _ in 0..10_000 {
            let mut u = || (rng.uniform_f32() - 0.5) * 4.0;
            let (y, x) = (
                F8(std::array::from_fn(|_| u())),
                F8(std::array::from_fn(|_| u())),
            );
            let lanes = atan2(y, x);
            for l in 0..8 {
                assert_eq!(lanes.0[l].to_bits(), atan2(y.0[l], x.0[l]).to_bits());
            }
        }
    }
}
