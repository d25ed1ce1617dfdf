//! Trigonometric functions written once over [`Real`], so that one `f32` and eight lanes
//! compute the same bits, and faster than the C library's where the renderer calls them
//! often: [`atan2`] and [`acos`] (an environment map's (u, v) of a direction) and
//! [`sin_cos_turns`] (the direction of an environment map's (u, v)).

use super::lanes::Real;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

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

/// asin(s) = s + s z A(z), z = s², on [0, ½]: A's coefficients, lowest first, a minimax fit
/// of the relative error (Lawson's weighted least squares, in `f64`; 4.8e-9 before rounding
/// to `f32`, 0.61 units in the last place evaluated in `f32`).
const ASIN: [f32; 5] = [
    0.166_667_52,
    0.074_952_975,
    0.045_470_376,
    0.024_179_518,
    0.042_166_304,
];

/// The angle whose cosine is `y`, in [0, π], as `f32::acos` (within 2 units in the last place;
/// NaN for |y| > 1 and NaN). Branch-free: asin of |y| (at most ½) or of √((1 - |y|)/2) (from
/// ½ to 1, where acos |y| = 2 asin √((1 - |y|)/2), the difference and the halving exact) by
/// the polynomial [`ASIN`], then acos y = π/2 - asin y, or π - acos |y| for y < -½.
#[inline(always)]
pub fn acos<R: Real>(y: R) -> R {
    let a = y.abs();
    let far = a.gt(R::splat(0.5));
    let z = R::select(far, (R::splat(1.0) - a) * R::splat(0.5), y * y);
    let s = R::select(far, z.sqrt(), a);
    let mut p = R::splat(ASIN[4]);
    for &c in ASIN[..4].iter().rev() {
        p = p * z + R::splat(c);
    }
    let asin = s + s * z * p;
    let near_zero = R::splat(FRAC_PI_2) - asin * y.sign_one();
    let twice = asin + asin;
    let near_one = R::select(y.lt(R::splat(0.0)), R::splat(PI) - twice, twice);
    R::select(far, near_one, near_zero)
}

/// (sin a, cos a) for a = π/4 · t with t in [-1, 1]: the angles of the concentric map, which
/// need no range reduction, and of [`sin_cos_turns`] after its reduction. Taylor series to a⁹
/// and a¹⁰, whose truncation errors on |a| ≤ π/4 are below (π/4)¹¹/11! ≈ 2e-9 and
/// (π/4)¹²/12! ≈ 1e-10, far under f32's rounding; the results are within two ulps of sin and
/// cos of π/4 · t (1.95 and 1.64 at worst over every f32 in [0, 1], and symmetric for
/// negative t; a test checks a grid). Plain arithmetic, for one value or for lanes.
#[inline(always)]
pub fn sin_cos_quarter_turn<T: Real>(t: T) -> (T, T) {
    const S: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
    const C: [f32; 5] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
    ];
    let k = |c: f32| T::splat(c);
    let a = k(FRAC_PI_4) * t;
    let a2 = a * a;
    let sin = a + a * a2 * (k(S[0]) + a2 * (k(S[1]) + a2 * (k(S[2]) + a2 * k(S[3]))));
    let cos =
        k(1.0) + a2 * (k(C[0]) + a2 * (k(C[1]) + a2 * (k(C[2]) + a2 * (k(C[3]) + a2 * k(C[4])))));
    (sin, cos)
}

/// 1.5 · 2²³: adding and subtracting it rounds an `f32` of magnitude below 2²² to the nearest
/// whole number (ties to even).
const ROUND: f32 = 12_582_912.0;

/// (sin 2πx, cos 2πx) of `x` turns, |x| < 2²⁰ (NaN beyond), within 2 units in the last
/// place. The reduction is exact: 4x less the nearest whole number q is r in [-½, ½], so
/// that 2πx = qπ/2 + rπ/2, and the quadrant q mod 4 swaps and negates sin(rπ/2) and
/// cos(rπ/2) ([`sin_cos_quarter_turn`]). Branch-free.
#[inline(always)]
pub fn sin_cos_turns<R: Real>(x: R) -> (R, R) {
    let round = |y: R| (y + R::splat(ROUND)) - R::splat(ROUND);
    let four_x = x * R::splat(4.0);
    let q = round(four_x);
    // Exact: q is within ½ of 4x, so either q = 0 or 4x lies in [q/2, 2q] (Sterbenz).
    let r = four_x - q;
    // m = q mod 4, exactly (q/4 and its floor are exact).
    let h = q * R::splat(0.25);
    let f = round(h);
    let f = R::select(f.gt(h), f - R::splat(1.0), f);
    let m = q - f * R::splat(4.0);
    // sin and cos of rπ/2 = π/4 · 2r (2r exact, in [-1, 1]).
    let (s, c) = sin_cos_quarter_turn(r + r);
    // Quadrant 1: (cos, -sin); 2: (-sin, -cos); 3: (-cos, sin).
    let (one, two) = (R::splat(1.0), R::splat(2.0));
    let odd = m.equals(one) | m.equals(R::splat(3.0));
    let (sin, cos) = (R::select(odd, c, s), R::select(odd, s, c));
    let sin = R::select(m.gt(R::splat(1.5)), -sin, sin);
    let cos = R::select(m.equals(one) | m.equals(two), -cos, cos);
    (sin, cos)
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

    #[test]
    fn sin_cos_turns_is_within_two_units_in_the_last_place() {
        let mut worst = 0.0f64;
        let mut rng = crate::rng::Pcg32::new(11, 5);
        // Every quarter's edges and their neighbours, then a fine sweep and random turns.
        let mut xs: Vec<f32> = (-8..=8).map(|k| k as f32 / 8.0).collect();
        xs.extend(xs.clone().iter().flat_map(|x| [x.next_up(), x.next_down()]));
        xs.extend((0..400_000).map(|k| (k as f32 + 0.5) / 200_000.0 - 1.0));
        xs.extend((0..100_000).map(|_| rng.uniform_f32() * 64.0 - 32.0));
        xs.extend([1e-30, -1e-30, 1e-8, 3e-5, 1000.37]);
        for x in xs {
            // The reference in f64, from the nearest quarter turn (taken off exactly), so that
            // it is exact to its own rounding at the quarters too (cos π/2 in f64 is 6e-17).
            let four = 4.0 * f64::from(x);
            let q = four.round();
            let (rs, rc) = ((four - q) * std::f64::consts::FRAC_PI_2).sin_cos();
            let (exact_s, exact_c) = match (q as i64).rem_euclid(4) {
                0 => (rs, rc),
                1 => (rc, -rs),
                2 => (-rs, -rc),
                _ => (-rc, rs),
            };
            let (s, c) = sin_cos_turns(x);
            // Against the exact value, in units of the exact value's last place (a zero's
            // neighbours are measured against the smallest normal's).
            let (es, ec) = (ulps(s, exact_s), ulps(c, exact_c));
            worst = worst.max(es).max(ec);
            assert!(
                es <= 2.0 && ec <= 2.0,
                "x = {x}: ({s}, {c}) vs ({exact_s}, {exact_c})"
            );
        }
        assert!(worst > 0.5, "the comparison measures something ({worst})");
    }

    #[test]
    fn sin_cos_turns_is_exact_at_the_quarters_and_nan_beyond_its_range() {
        for (x, s, c) in [
            (0.0f32, 0.0f32, 1.0f32),
            (0.25, 1.0, 0.0),
            (0.5, 0.0, -1.0),
            (0.75, -1.0, 0.0),
            (1.0, 0.0, 1.0),
            (-0.25, -1.0, 0.0),
        ] {
            assert_eq!(sin_cos_turns(x), (s, c), "x = {x}");
        }
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let (s, c) = sin_cos_turns(x);
            assert!(s.is_nan() && c.is_nan(), "x = {x}");
        }
    }

    #[test]
    fn sin_cos_turns_in_eight_lanes_gives_the_one_value_bits() {
        let mut rng = crate::rng::Pcg32::new(5, 9);
        for _ in 0..10_000 {
            let x = F8(std::array::from_fn(|_| (rng.uniform_f32() - 0.5) * 6.0));
            let (s, c) = sin_cos_turns(x);
            for l in 0..8 {
                let (s1, c1) = sin_cos_turns(x.0[l]);
                assert_eq!(
                    (s.0[l].to_bits(), c.0[l].to_bits()),
                    (s1.to_bits(), c1.to_bits())
                );
            }
        }
    }

    #[test]
    fn acos_is_within_two_units_in_the_last_place() {
        let mut worst = 0.0f64;
        let mut ys: Vec<f32> = vec![-1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 1e-30, -1e-30];
        ys.extend(ys.clone().iter().flat_map(|y| [y.next_up(), y.next_down()]));
        ys.extend((0..=1_000_000).map(|k| k as f32 / 500_000.0 - 1.0));
        for y in ys.into_iter().filter(|y| y.abs() <= 1.0) {
            let exact = f64::from(y).acos();
            let got = acos(y);
            worst = worst.max(ulps(got, exact));
            assert!(
                ulps(got, exact) <= 2.0,
                "acos({y}) = {got}, exactly {exact}"
            );
        }
        assert!(worst > 0.5, "the comparison measures something ({worst})");
        assert_eq!((acos(1.0f32), acos(-1.0f32)), (0.0, PI));
        assert_eq!((acos(0.0f32), acos(-0.0f32)), (FRAC_PI_2, FRAC_PI_2));
        for y in [1.0f32.next_up(), -2.0, f32::NAN, f32::INFINITY] {
            assert!(acos(y).is_nan(), "acos({y})");
        }
    }

    #[test]
    fn acos_in_eight_lanes_gives_the_one_value_bits() {
        let mut rng = crate::rng::Pcg32::new(8, 1);
        for _ in 0..10_000 {
            let y = F8(std::array::from_fn(|_| rng.uniform_f32() * 2.0 - 1.0));
            let lanes = acos(y);
            for l in 0..8 {
                assert_eq!(lanes.0[l].to_bits(), acos(y.0[l]).to_bits());
            }
        }
    }
}
