//! Eight `f32` lanes and their masks, for code that computes several samples at once, and the
//! traits [`Real`] and [`Vector3`] that let such code be written once: a function generic
//! over `T: Real` runs on one `f32` (with `bool` masks and glam's `Vec3`) or on eight lanes
//! ([`F8`], [`M8`], [`V8`]), and each lane computes exactly what the one-value instance
//! computes, to the bit.
//!
//! Every lane operation is a loop over the lanes that the compiler turns into one vector
//! instruction (AVX where the caller is compiled for it, two SSE halves otherwise), with the
//! scalar operation's rounding: the same operations in the same order, no fused
//! multiply-adds, the same NaN rules (`max_element` is glam's, `max` is `f32::max`, up to the
//! sign of a zero between zeros). Generic code selects where scalar code would branch, so
//! both sides of a choice are computed (a division by zero there is harmless: the lane that
//! takes it is not selected).

use glam::Vec3;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Lanes per vector.
pub const W: usize = 8;

/// Eight `f32`s.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F8(pub [f32; W]);

/// A lane mask: all bits set where true, clear where false.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8(pub [u32; W]);

#[inline(always)]
fn map(a: F8, f: impl Fn(f32) -> f32) -> F8 {
    let mut r = [0.0; W];
    for (r, &x) in r.iter_mut().zip(&a.0) {
        *r = f(x);
    }
    F8(r)
}

#[inline(always)]
fn zip(a: F8, b: F8, f: impl Fn(f32, f32) -> f32) -> F8 {
    let mut r = [0.0; W];
    for (r, (&x, &y)) in r.iter_mut().zip(a.0.iter().zip(&b.0)) {
        *r = f(x, y);
    }
    F8(r)
}

#[inline(always)]
fn compare(a: F8, b: F8, f: impl Fn(f32, f32) -> bool) -> M8 {
    M8(std::array::from_fn(
        |i| if f(a.0[i], b.0[i]) { !0 } else { 0 },
    ))
}

impl F8 {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f32) -> F8 {
        F8([x; W])
    }

    /// Lane-wise square root.
    #[inline(always)]
    pub fn sqrt(self) -> F8 {
        map(self, f32::sqrt)
    }

    /// Lane-wise absolute value.
    #[inline(always)]
    pub fn abs(self) -> F8 {
        map(self, f32::abs)
    }

    /// Lane-wise `f32::max` (a NaN lane takes the other operand; for +0 and -0 either zero,
    /// as IEEE allows, possibly not the one scalar code picks).
    #[inline(always)]
    pub fn max(self, o: F8) -> F8 {
        zip(self, o, f32::max)
    }

    /// Lane-wise `f32::min` (NaN gives the other operand; of two zeros, either).
    #[inline(always)]
    pub fn min(self, o: F8) -> F8 {
        zip(self, o, f32::min)
    }

    /// Lane-wise `1.0f32.copysign(self)`: ±1 with each lane's sign.
    #[inline(always)]
    pub fn sign_one(self) -> F8 {
        map(self, |x| 1.0f32.copysign(x))
    }

    /// Lane-wise `a < b`, and so on (false wherever a NaN is involved, except `ne`).
    #[inline(always)]
    pub fn lt(self, o: F8) -> M8 {
        compare(self, o, |a, b| a < b)
    }
    /// Lane-wise `a <= b`.
    #[inline(always)]
    pub fn le(self, o: F8) -> M8 {
        compare(self, o, |a, b| a <= b)
    }
    /// Lane-wise `a > b`.
    #[inline(always)]
    pub fn gt(self, o: F8) -> M8 {
        compare(self, o, |a, b| a > b)
    }
    /// Lane-wise `a == b`.
    #[inline(always)]
    pub fn equals(self, o: F8) -> M8 {
        compare(self, o, |a, b| a == b)
    }
    /// Lane-wise `a != b` (true for NaN).
    #[inline(always)]
    pub fn not_equal(self, o: F8) -> M8 {
        compare(self, o, |a, b| a != b)
    }
    /// Lanes that are neither infinite nor NaN.
    #[inline(always)]
    pub fn is_finite(self) -> M8 {
        compare(self, self, |a, _| a.is_finite())
    }
    /// Lanes that are ±infinity.
    #[inline(always)]
    pub fn is_infinite(self) -> M8 {
        compare(self, self, |a, _| a.is_infinite())
    }
}

impl M8 {
    /// `a` where the mask is set, `b` elsewhere.
    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        let mut r = [0.0; W];
        for (r, (&m, (&x, &y))) in r.iter_mut().zip(self.0.iter().zip(a.0.iter().zip(&b.0))) {
            *r = f32::from_bits((x.to_bits() & m) | (y.to_bits() & !m));
        }
        F8(r)
    }

    /// [`M8::select`] for each axis.
    #[inline(always)]
    pub fn select3(self, a: V8, b: V8) -> V8 {
        V8 {
            x: self.select(a.x, b.x),
            y: self.select(a.y, b.y),
            z: self.select(a.z, b.z),
        }
    }

    /// Whether lane `i` is set.
    #[inline(always)]
    pub fn get(self, i: usize) -> bool {
        self.0[i] != 0
    }

    /// Sets lane `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, on: bool) {
        self.0[i] = if on { !0 } else { 0 };
    }

    /// Whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, &m| a | m) != 0
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $ty:ty, $op:tt) => {
        impl $trait for $ty {
            type Output = $ty;
            #[inline(always)]
            fn $method(self, o: $ty) -> $ty {
                let mut r = self;
                for i in 0..W {
                    r.0[i] = self.0[i] $op o.0[i];
                }
                r
            }
        }
    };
}
lane_op!(Add, add, F8, +);
lane_op!(Sub, sub, F8, -);
lane_op!(Mul, mul, F8, *);
lane_op!(Div, div, F8, /);
lane_op!(BitAnd, bitand, M8, &);
lane_op!(BitOr, bitor, M8, |);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        map(self, |x| -x)
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(self.0.map(|m| !m))
    }
}

/// Eight 3-vectors, an [`F8`] per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V8 {
    /// x of every lane.
    pub x: F8,
    /// y of every lane.
    pub y: F8,
    /// z of every lane.
    pub z: F8,
}

impl V8 {
    /// Lane `i` as a `Vec3`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Sets lane `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: Vec3) {
        (self.x.0[i], self.y.0[i], self.z.0[i]) = (v.x, v.y, v.z);
    }

    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: Vec3) -> V8 {
        V8 {
            x: F8::splat(v.x),
            y: F8::splat(v.y),
            z: F8::splat(v.z),
        }
    }

    /// glam's `dot`: (x x') + (y y') + (z z').
    #[inline(always)]
    pub fn dot(self, o: V8) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Each axis times `s` (glam's `Vec3 * f32`).
    #[inline(always)]
    pub fn scale(self, s: F8) -> V8 {
        V8 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Each axis divided by `s` (glam's `Vec3 / f32`).
    #[inline(always)]
    pub fn div_by(self, s: F8) -> V8 {
        V8 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// Axis-wise product (glam's `Vec3 * Vec3`).
    #[inline(always)]
    pub fn mul_axes(self, o: V8) -> V8 {
        V8 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// Axis-wise absolute value.
    #[inline(always)]
    pub fn abs(self) -> V8 {
        V8 {
            x: self.x.abs(),
            y: self.y.abs(),
            z: self.z.abs(),
        }
    }

    /// glam's `max_element`: `max(max(x, y), z)` with `max(a, b) = if a > b { a } else { b }`.
    #[inline(always)]
    pub fn max_element(self) -> F8 {
        let max = |a: F8, b: F8| a.gt(b).select(a, b);
        max(max(self.x, self.y), self.z)
    }
}

impl Add for V8 {
    type Output = V8;
    #[inline(always)]
    fn add(self, o: V8) -> V8 {
        V8 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V8 {
    type Output = V8;
    #[inline(always)]
    fn sub(self, o: V8) -> V8 {
        V8 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for V8 {
    type Output = V8;
    #[inline(always)]
    fn neg(self) -> V8 {
        V8 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

/// A number type for code written once for one value (`f32`) and for eight lanes ([`F8`]).
/// The operations are those of [`F8`]; for `f32` they are the plain `f32` operations.
pub trait Real:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Per-lane truth values (`bool` for one value).
    type Mask: Copy
        + std::fmt::Debug
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// 3-vectors of this number type (glam's `Vec3` for one value).
    type V3: Vector3<R = Self>;
    /// `x` in every lane.
    fn splat(x: f32) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `f32::max`.
    fn max(self, o: Self) -> Self;
    /// `f32::min`.
    fn min(self, o: Self) -> Self;
    /// `1.0f32.copysign(self)`.
    fn sign_one(self) -> Self;
    /// `self < o`.
    fn lt(self, o: Self) -> Self::Mask;
    /// `self <= o`.
    fn le(self, o: Self) -> Self::Mask;
    /// `self > o`.
    fn gt(self, o: Self) -> Self::Mask;
    /// `self == o`.
    fn equals(self, o: Self) -> Self::Mask;
    /// `self != o` (true for NaN).
    fn not_equal(self, o: Self) -> Self::Mask;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> Self::Mask;
    /// ±infinity.
    fn is_infinite(self) -> Self::Mask;
    /// `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Whether `m` is true in some lane.
    fn any(m: Self::Mask) -> bool;
    /// True in every lane.
    #[inline(always)]
    fn every_lane() -> Self::Mask {
        let zero = Self::splat(0.0);
        zero.equals(zero)
    }
    /// True in no lane.
    #[inline(always)]
    fn no_lane() -> Self::Mask {
        !Self::every_lane()
    }
    /// `f` of each lane in the lanes `m` (zero in the others, where `f` is not called): for
    /// functions that have no lane form, such as `exp`, whose lanes' values are then those of
    /// `f`, to the bit.
    fn map_where(self, m: Self::Mask, f: impl Fn(f32) -> f32) -> Self;
    /// `f` of each lane of `self` and `o` in the lanes `m`, as [`Real::map_where`].
    fn map2_where(self, o: Self, m: Self::Mask, f: impl Fn(f32, f32) -> f32) -> Self;
}

/// 3-vectors of a [`Real`]: glam's `Vec3` for `f32`, [`V8`] for eight lanes, with glam's
/// operation order.
pub trait Vector3:
    Copy + std::fmt::Debug + Add<Output = Self> + Sub<Output = Self> + Neg<Output = Self>
{
    /// The number type of the axes.
    type R: Real<V3 = Self>;
    /// The vector (x, y, z).
    fn new(x: Self::R, y: Self::R, z: Self::R) -> Self;
    /// `v` in every lane.
    fn splat(v: Vec3) -> Self;
    /// The x axis.
    fn x(self) -> Self::R;
    /// The y axis.
    fn y(self) -> Self::R;
    /// The z axis.
    fn z(self) -> Self::R;
    /// glam's `dot`: (x x') + (y y') + (z z').
    fn dot(self, o: Self) -> Self::R;
    /// Each axis times `s`.
    fn scale(self, s: Self::R) -> Self;
    /// Each axis divided by `s`.
    fn div_by(self, s: Self::R) -> Self;
    /// Axis-wise product.
    fn mul_axes(self, o: Self) -> Self;
    /// Axis-wise absolute value.
    fn abs(self) -> Self;
    /// glam's `max_element`.
    fn max_element(self) -> Self::R;
    /// `a` where `m`, else `b`, for each axis.
    fn select(m: <Self::R as Real>::Mask, a: Self, b: Self) -> Self;
    /// glam's `cross`: (y z' - y' z, z x' - z' x, x y' - x' y).
    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        Self::new(
            self.y() * o.z() - o.y() * self.z(),
            self.z() * o.x() - o.z() * self.x(),
            self.x() * o.y() - o.x() * self.y(),
        )
    }
    /// Axis-wise quotient (glam's `Vec3 / Vec3`).
    #[inline(always)]
    fn div_axes(self, o: Self) -> Self {
        Self::new(self.x() / o.x(), self.y() / o.y(), self.z() / o.z())
    }
    /// glam's `normalize`: the vector times the reciprocal of its length (the same bits as
    /// glam's for `Vec3`, without its debug check of a finite result).
    #[inline(always)]
    fn normalize(self) -> Self {
        self.scale(Self::R::splat(1.0) / self.dot(self).sqrt())
    }
}

impl Real for f32 {
    type Mask = bool;
    type V3 = Vec3;
    #[inline(always)]
    fn splat(x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn max(self, o: f32) -> f32 {
        f32::max(self, o)
    }
    #[inline(always)]
    fn min(self, o: f32) -> f32 {
        f32::min(self, o)
    }
    #[inline(always)]
    fn sign_one(self) -> f32 {
        1.0f32.copysign(self)
    }
    #[inline(always)]
    fn lt(self, o: f32) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: f32) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: f32) -> bool {
        self > o
    }
    #[inline(always)]
    fn equals(self, o: f32) -> bool {
        self == o
    }
    #[inline(always)]
    fn not_equal(self, o: f32) -> bool {
        self != o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn is_infinite(self) -> bool {
        f32::is_infinite(self)
    }
    #[inline(always)]
    fn select(m: bool, a: f32, b: f32) -> f32 {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn any(m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn map_where(self, m: bool, f: impl Fn(f32) -> f32) -> f32 {
        if m {
            f(self)
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn map2_where(self, o: f32, m: bool, f: impl Fn(f32, f32) -> f32) -> f32 {
        if m {
            f(self, o)
        } else {
            0.0
        }
    }
}

impl Vector3 for Vec3 {
    type R = f32;
    #[inline(always)]
    fn new(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }
    #[inline(always)]
    fn splat(v: Vec3) -> Vec3 {
        v
    }
    #[inline(always)]
    fn x(self) -> f32 {
        self.x
    }
    #[inline(always)]
    fn y(self) -> f32 {
        self.y
    }
    #[inline(always)]
    fn z(self) -> f32 {
        self.z
    }
    #[inline(always)]
    fn dot(self, o: Vec3) -> f32 {
        Vec3::dot(self, o)
    }
    #[inline(always)]
    fn scale(self, s: f32) -> Vec3 {
        self * s
    }
    #[inline(always)]
    fn div_by(self, s: f32) -> Vec3 {
        self / s
    }
    #[inline(always)]
    fn mul_axes(self, o: Vec3) -> Vec3 {
        self * o
    }
    #[inline(always)]
    fn abs(self) -> Vec3 {
        Vec3::abs(self)
    }
    #[inline(always)]
    fn max_element(self) -> f32 {
        Vec3::max_element(self)
    }
    #[inline(always)]
    fn select(m: bool, a: Vec3, b: Vec3) -> Vec3 {
        if m {
            a
        } else {
            b
        }
    }
}

impl Real for F8 {
    type Mask = M8;
    type V3 = V8;
    #[inline(always)]
    fn splat(x: f32) -> F8 {
        F8::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> F8 {
        F8::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> F8 {
        F8::abs(self)
    }
    #[inline(always)]
    fn max(self, o: F8) -> F8 {
        F8::max(self, o)
    }
    #[inline(always)]
    fn min(self, o: F8) -> F8 {
        F8::min(self, o)
    }
    #[inline(always)]
    fn sign_one(self) -> F8 {
        F8::sign_one(self)
    }
    #[inline(always)]
    fn lt(self, o: F8) -> M8 {
        F8::lt(self, o)
    }
    #[inline(always)]
    fn le(self, o: F8) -> M8 {
        F8::le(self, o)
    }
    #[inline(always)]
    fn gt(self, o: F8) -> M8 {
        F8::gt(self, o)
    }
    #[inline(always)]
    fn equals(self, o: F8) -> M8 {
        F8::equals(self, o)
    }
    #[inline(always)]
    fn not_equal(self, o: F8) -> M8 {
        F8::not_equal(self, o)
    }
    #[inline(always)]
    fn is_finite(self) -> M8 {
        F8::is_finite(self)
    }
    #[inline(always)]
    fn is_infinite(self) -> M8 {
        F8::is_infinite(self)
    }
    #[inline(always)]
    fn select(m: M8, a: F8, b: F8) -> F8 {
        m.select(a, b)
    }
    #[inline(always)]
    fn any(m: M8) -> bool {
        m.any()
    }
    #[inline(always)]
    fn map_where(self, m: M8, f: impl Fn(f32) -> f32) -> F8 {
        self.map2_where(self, m, |x, _| f(x))
    }
    #[inline(always)]
    fn map2_where(self, o: F8, m: M8, f: impl Fn(f32, f32) -> f32) -> F8 {
        let mut r = [0.0; W];
        for i in (0..W).filter(|&i| m.get(i)) {
            r[i] = f(self.0[i], o.0[i]);
        }
        F8(r)
    }
}

impl Vector3 for V8 {
    type R = F8;
    #[inline(always)]
    fn new(x: F8, y: F8, z: F8) -> V8 {
        V8 { x, y, z }
    }
    #[inline(always)]
    fn splat(v: Vec3) -> V8 {
        V8::splat(v)
    }
    #[inline(always)]
    fn x(self) -> F8 {
        self.x
    }
    #[inline(always)]
    fn y(self) -> F8 {
        self.y
    }
    #[inline(always)]
    fn z(self) -> F8 {
        self.z
    }
    #[inline(always)]
    fn dot(self, o: V8) -> F8 {
        V8::dot(self, o)
    }
    #[inline(always)]
    fn scale(self, s: F8) -> V8 {
        V8::scale(self, s)
    }
    #[inline(always)]
    fn div_by(self, s: F8) -> V8 {
        V8::div_by(self, s)
    }
    #[inline(always)]
    fn mul_axes(self, o: V8) -> V8 {
        V8::mul_axes(self, o)
    }
    #[inline(always)]
    fn abs(self) -> V8 {
        V8::abs(self)
    }
    #[inline(always)]
    fn max_element(self) -> F8 {
        V8::max_element(self)
    }
    #[inline(always)]
    fn select(m: M8, a: V8, b: V8) -> V8 {
        m.select3(a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_compute_what_scalar_code_computes() {
        let a = F8([1.5, -0.0, f32::NAN, f32::INFINITY, -2.0, 3.0, 0.0, 1e-30]);
        let b = F8([2.0, 0.0, 1.0, 1.0, f32::NAN, -3.0, -0.0, 1e30]);
        for i in 0..W {
            let (x, y) = (a.0[i], b.0[i]);
            let same = |l: f32, s: f32| l.to_bits() == s.to_bits() || (l.is_nan() && s.is_nan());
            assert!(same((a + b).0[i], x + y));
            assert!(same((a * b).0[i], x * y));
            assert!(same((a / b).0[i], x / y));
            // IEEE leaves open which zero the maximum of +0 and -0 is, and scalar and vector
            // code pick differently; the value is the same.
            assert!(same(a.max(b).0[i], x.max(y)) || (x == 0.0 && y == 0.0));
            assert!(same(a.min(b).0[i], x.min(y)) || (x == 0.0 && y == 0.0));
            assert!(same(a.sign_one().0[i], 1.0f32.copysign(x)));
            assert!(same(a.abs().sqrt().0[i], x.abs().sqrt()));
            assert_eq!(a.lt(b).get(i), x < y);
            assert_eq!(a.le(b).get(i), x <= y);
            assert_eq!(a.not_equal(b).get(i), x != y);
            assert_eq!(a.equals(b).get(i), x == y);
            assert_eq!(a.is_finite().get(i), x.is_finite());
            assert_eq!(a.is_infinite().get(i), x.is_infinite());
            assert!(F8::every_lane().get(i) && !F8::no_lane().get(i));
            assert!(<f32 as Real>::every_lane() && !<f32 as Real>::no_lane());
            assert!(same(a.lt(b).select(a, b).0[i], if x < y { x } else { y }));
            let v = V8 {
                x: a,
                y: b,
                z: a * b,
            };
            let u = V8 { x: b, y: a, z: b };
            assert!(same(v.dot(u).0[i], v.get(i).dot(u.get(i))));
            assert!(same(v.max_element().0[i], v.get(i).max_element()));
            let (c, g) = (Vector3::cross(v, u).get(i), v.get(i).cross(u.get(i)));
            assert!(
                same(c.x, g.x) && same(c.y, g.y) && same(c.z, g.z),
                "{c} vs {g}"
            );
            assert_eq!(a.lt(b).any(), (0..W).any(|j| a.0[j] < b.0[j]));
        }
    }
}
