//! How a ray is tested against a node's `W` boxes: the ray's precomputed quantities, the
//! portable loop over lanes and the AVX2 version for eight lanes.

use super::node::Node;
use crate::geometry::Ray;

/// Relative widening of the far distance of a box test, so that rounding never culls a box
/// the ray touches (pbrt-v4's 1 + 2γ₃).
pub const FAR_SCALE: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON * 0.5 / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// The ray quantities every box test uses.
#[doc(hidden)]
pub struct RayBoxes {
    /// Where entry distances start: the ray's `t_min` (+0 if not positive, -0 and NaN
    /// included), so that boxes the ray leaves before it are culled (a ray leaving a surface
    /// with `t_min` > 0 does not descend into the boxes around its origin). Never negative,
    /// not even -0, whose bits would sort the stack entries as the largest distances.
    pub(super) t_min: f32,
    pub(super) o: [f32; 3],
    pub(super) inv_d: [f32; 3],
    /// `inv_d` widened by [`FAR_SCALE`], for far planes.
    pub(super) inv_far: [f32; 3],
    /// Per axis, the index in [`Node::planes`] of the plane the ray enters by (the upper one
    /// when the direction is negative) and of the one it leaves by.
    pub(super) near: [usize; 3],
    pub(super) far: [usize; 3],
}

impl RayBoxes {
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> Self {
        let inv_d = ray.d.recip();
        // Written out rather than with `array::map`, which is not inlined here.
        let plane = |axis: usize, upper: bool| axis + 3 * usize::from(upper);
        // The planes come from the direction's signs, which 1/d keeps (-0 gives -∞), rather
        // than from 1/d: the node's loads then need not wait for the division. (A NaN
        // component makes every distance on its axis NaN, whichever planes it picks.)
        let neg = [
            ray.d.x.is_sign_negative(),
            ray.d.y.is_sign_negative(),
            ray.d.z.is_sign_negative(),
        ];
        RayBoxes {
            t_min: if ray.t_min > 0.0 { ray.t_min } else { 0.0 },
            o: ray.o.to_array(),
            inv_d: inv_d.to_array(),
            inv_far: (inv_d * FAR_SCALE).to_array(),
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
            let (o, inv, inv_far) = (self.o[axis], self.inv_d[axis], self.inv_far[axis]);
            for lane in 0..W {
                // Comparisons rather than f32::max/min: they compile to single SIMD min/max
                // instructions, and a NaN (0 · ∞ for a ray in a box's plane) leaves the
                // running value unchanged, which keeps the test conservative.
                let tn = (near[lane] - o) * inv;
                let tf = (far[lane] - o) * inv_far;
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
/// (`max`/`min` keep their second operand when the first is NaN, as the portable comparisons
/// do), so the results are identical.
///
/// # Safety
///
/// The CPU must have AVX. (Not a `#[target_feature]` function, so that it can be inlined
/// into its callers, which are.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn test8_avx2(ray: &RayBoxes, n: &Node<8>, t_max: f32) -> ([f32; 8], u32) {
    use std::arch::x86_64::*;
    // SAFETY: the caller guarantees AVX; the loads and the store go through pointers to
    // `[f32; 8]`, valid for exactly the 32 bytes each moves.
    unsafe {
        let mut t_near = _mm256_set1_ps(ray.t_min);
        let mut t_far = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let o = _mm256_set1_ps(ray.o[axis]);
            let near = _mm256_loadu_ps(n.planes[ray.near[axis]].as_ptr());
            let far = _mm256_loadu_ps(n.planes[ray.far[axis]].as_ptr());
            let tn = _mm256_mul_ps(_mm256_sub_ps(near, o), _mm256_set1_ps(ray.inv_d[axis]));
            let tf = _mm256_mul_ps(_mm256_sub_ps(far, o), _mm256_set1_ps(ray.inv_far[axis]));
            t_near = _mm256_max_ps(tn, t_near);
            t_far = _mm256_min_ps(tf, t_far);
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (out, mask & n.valid)
    }
}
