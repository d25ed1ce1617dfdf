//! How a ray is tested against a node's `W` boxes: the ray's precomputed quantities, the
//! portable loop over lanes and the AVX2 version for eight lanes (one fused multiply-add per
//! plane, kept conservative: see [`RayBoxes`]).

use super::node::Node;
use crate::geometry::Ray;

/// Relative widening of the far distance of a box test, so that rounding never culls a box
/// the ray touches (pbrt-v4's 1 + 2γ₃).
pub const FAR_SCALE: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON * 0.5 / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// The smallest direction component a box test divides by: smaller ones (zero included)
/// are taken as this with their sign, so that 1/d and o/d stay finite (see [`RayBoxes`]).
const MIN_DIRECTION: f32 = 1e-30;

/// The ray quantities every box test uses.
///
/// A plane at `p` is met at `t = (p - o) / d`, which the tests compute as one fused
/// multiply-add, `p · (1/d) - o/d` (half the operations of a subtraction and a product, and a
/// shorter chain of them). Rounding `o/d` to `f32` can move that `t` by an absolute amount,
/// so the subtracted term is rounded away from the box: up for entry distances, down for
/// exit distances, by more than that rounding (`NEAR_ROUNDING`), which keeps the test
/// conservative; the relative errors of `1/d` and of the fused operation's one rounding are
/// covered, as in pbrt-v4, by widening exit distances by [`FAR_SCALE`]. A direction
/// component below [`MIN_DIRECTION`] in size (zero included) is taken as that size with its
/// sign: a ray parallel to a slab then meets it at distances of about ±10³⁰ times its offset
/// from the planes, which is what the test needs (inside: the slab does not limit it;
/// outside: it never enters), where 1/0 would give ∞ − ∞ = NaN and leave the axis untested.
///
/// The bound on the rounding of `o/d` is relative, so it holds where `o/d` and `o` are normal
/// numbers or zero; an origin coordinate in `f32`'s subnormal range (below 2⁻¹²⁶ in size, not
/// zero) can put a plane's distance 2⁻¹⁴⁹ on the wrong side. The portable test rounds once
/// as the fused instruction does (`f32::mul_add`): one instruction on other architectures
/// (AArch64 has it), a library call on an x86-64 CPU without FMA (before 2013), which has no
/// AVX2 either and so is the one x86-64 CPU on which the renderer runs the portable test.
#[doc(hidden)]
pub struct RayBoxes {
    /// Where entry distances start: the ray's `t_min` (+0 if not positive, -0 and NaN
    /// included), so that boxes the ray leaves before it are culled (a ray leaving a surface
    /// with `t_min` > 0 does not descend into the boxes around its origin). Never negative,
    /// not even -0, whose bits would sort the stack entries as the largest distances.
    pub(super) t_min: f32,
    /// 1/d per axis.
    pub(super) inv_d: [f32; 3],
    /// `inv_d` widened by [`FAR_SCALE`], for far planes.
    pub(super) inv_far: [f32; 3],
    /// `o · inv_d`, rounded up by more than its rounding error: what entry distances subtract.
    pub(super) o_near: [f32; 3],
    /// `o · inv_far`, rounded down likewise: what exit distances subtract.
    pub(super) o_far: [f32; 3],
    /// Per axis, the index in [`Node::planes`] of the plane the ray enters by (the upper one
    /// when the direction is negative) and of the one it leaves by.
    pub(super) near: [usize; 3],
    pub(super) far: [usize; 3],
}

impl RayBoxes {
    /// More than the relative rounding errors of o/d computed as `(o ± 2⁻²²|o|) · (1/d)` in
    /// `f32` (two roundings, each a half unit in the last place, at most 2⁻²⁴ of the value).
    const NEAR_ROUNDING: f32 = 1.0 / (1u32 << 22) as f32;

    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> Self {
        let d = ray.d.to_array();
        let o = ray.o.to_array();
        // |d| raised to MIN_DIRECTION with d's sign: a comparison, which compiles to one
        // `max` (a NaN gives MIN_DIRECTION; such a ray meets no triangle whatever boxes it
        // enters), and no branches.
        let safe = |x: f32| {
            let a = x.abs();
            (if a > MIN_DIRECTION { a } else { MIN_DIRECTION }).copysign(x)
        };
        let inv_d = [1.0 / safe(d[0]), 1.0 / safe(d[1]), 1.0 / safe(d[2])];
        let inv_far = [
            inv_d[0] * FAR_SCALE,
            inv_d[1] * FAR_SCALE,
            inv_d[2] * FAR_SCALE,
        ];
        // o/d moved up for entry distances (down for exit distances) by 2⁻²² of its size:
        // o + 2⁻²²|o| sgn(d) (the product exact, the sum rounded once), times 1/d (rounded
        // again). Two roundings of at most 2⁻²⁴ each leave it beyond the exact o · (1/d) on
        // the chosen side; and only the last product waits for the division.
        let shifted = |o: f32, d: f32, up: bool| {
            let m = o.abs() * Self::NEAR_ROUNDING.copysign(d);
            if up {
                o + m
            } else {
                o - m
            }
        };
        // Where o/d overflows (an origin beyond 10⁸ on an axis the ray runs parallel to),
        // the largest finite value is still on the chosen side, and keeps the exit distance
        // from becoming -∞. (`max` and `min` take a NaN, from a NaN origin, for the bound,
        // which culls every box for a ray that meets no triangle anyway.)
        let o_near = |k: usize| (shifted(o[k], d[k], true) * inv_d[k]).max(-f32::MAX);
        let o_far = |k: usize| (shifted(o[k], d[k], false) * inv_far[k]).min(f32::MAX);
        // Written out rather than with `array::map`, which is not inlined here.
        let plane = |axis: usize, upper: bool| axis + 3 * usize::from(upper);
        // The planes come from the direction's signs, which 1/d keeps (-0 gives -10³⁰),
        // rather than from 1/d: the node's loads then need not wait for the division.
        let neg = [
            d[0].is_sign_negative(),
            d[1].is_sign_negative(),
            d[2].is_sign_negative(),
        ];
        RayBoxes {
            t_min: if ray.t_min > 0.0 { ray.t_min } else { 0.0 },
            inv_d,
            inv_far,
            o_near: [o_near(0), o_near(1), o_near(2)],
            o_far: [o_far(0), o_far(1), o_far(2)],
            near: [plane(0, neg[0]), plane(1, neg[1]), plane(2, neg[2])],
            far: [plane(0, !neg[0]), plane(1, !neg[1]), plane(2, !neg[2])],
        }
    }

    /// Entry distances of the `W` lanes and the mask (bit per lane) of those the ray meets
    /// within (t_min, t_max).
    #[inline(always)]
    pub(super) fn test<const W: usize>(&self, n: &Node<W>, t_max: f32) -> ([f32; W], u32) {
        let mut t_near = [self.t_min; W];
        let mut t_far = [t_max; W];
        for axis in 0..3 {
            let near = &n.planes[self.near[axis]];
            let far = &n.planes[self.far[axis]];
            let (inv, inv_far) = (self.inv_d[axis], self.inv_far[axis]);
            let (o_near, o_far) = (self.o_near[axis], self.o_far[axis]);
            for lane in 0..W {
                // Comparisons rather than f32::max/min: they compile to single SIMD min/max
                // instructions, and a NaN (from a NaN ray) leaves the running value
                // unchanged, which keeps the test conservative.
                let tn = near[lane].mul_add(inv, -o_near);
                let tf = far[lane].mul_add(inv_far, -o_far);
                t_near[lane] = if tn > t_near[lane] { tn } else { t_near[lane] };
                t_far[lane] = if tf < t_far[lane] { tf } else { t_far[lane] };
            }
        }
        (t_near, met_mask(&t_near, &t_far, n.valid))
    }
}

/// The lanes of `valid` whose box is met: entry at most exit (a NaN compares false).
#[inline(always)]
pub(super) fn met_mask<const W: usize>(t_near: &[f32; W], t_far: &[f32; W], valid: u32) -> u32 {
    let mut mask = 0u32;
    for lane in 0..W {
        mask |= u32::from(t_near[lane] <= t_far[lane]) << lane;
    }
    mask & valid
}

/// How a traversal tests a ray against a node's `W` boxes: [`Portable`] on any CPU, or with
/// the instructions a CPU extension offers (on x86-64, [`crate::simd::Avx2`] for eight lanes).
/// Every implementation gives the same entry distances and mask.
pub trait BoxTest<const W: usize>: Copy {
    /// Entry distances of the lanes and the mask of those `ray` meets within
    /// `(t_min, t_max)` (`t_min` the ray's).
    #[doc(hidden)]
    fn test(self, ray: &RayBoxes, node: &Node<W>, t_max: f32) -> ([f32; W], u32);
}

/// The box test written as loops over lanes, which the compiler vectorises for the target's
/// baseline instructions.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl<const W: usize> BoxTest<W> for Portable {
    #[inline(always)]
    fn test(self, ray: &RayBoxes, node: &Node<W>, t_max: f32) -> ([f32; W], u32) {
        ray.test(node, t_max)
    }
}

#[cfg(target_arch = "x86_64")]
impl BoxTest<8> for crate::simd::Avx2 {
    #[inline(always)]
    fn test(self, ray: &RayBoxes, node: &Node<8>, t_max: f32) -> ([f32; 8], u32) {
        // SAFETY: `self` exists only where the CPU has AVX2 and FMA, all that
        // `test8_avx2` requires.
        unsafe { test8_avx2(ray, node, t_max) }
    }
}

/// [`RayBoxes::test`] for eight lanes in AVX registers: the same operations in the same order
/// (a fused multiply-subtract rounds once, as `mul_add` does; `max`/`min` keep their second
/// operand when the first is NaN, as the portable comparisons do), so the results are
/// identical.
///
/// # Safety
///
/// The CPU must have AVX and FMA. (Not a `#[target_feature]` function, so that it can be inlined
/// into its callers, which are.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn test8_avx2(ray: &RayBoxes, n: &Node<8>, t_max: f32) -> ([f32; 8], u32) {
    use std::arch::x86_64::*;
    // SAFETY: the caller guarantees AVX and FMA; the loads and the store go through pointers to
    // `[f32; 8]`, valid for exactly the 32 bytes each moves.
    unsafe {
        let mut t_near = _mm256_set1_ps(ray.t_min);
        let mut t_far = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let near = _mm256_loadu_ps(n.planes[ray.near[axis]].as_ptr());
            let far = _mm256_loadu_ps(n.planes[ray.far[axis]].as_ptr());
            let (inv, inv_far) = (ray.inv_d[axis], ray.inv_far[axis]);
            let tn = _mm256_fmsub_ps(near, _mm256_set1_ps(inv), _mm256_set1_ps(ray.o_near[axis]));
            let tf = _mm256_fmsub_ps(
                far,
                _mm256_set1_ps(inv_far),
                _mm256_set1_ps(ray.o_far[axis]),
            );
            t_near = _mm256_max_ps(tn, t_near);
            t_far = _mm256_min_ps(tf, t_far);
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (out, mask & n.valid)
    }
}
