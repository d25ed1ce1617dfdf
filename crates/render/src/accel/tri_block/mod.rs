//! Four triangles laid out for one ray to test them together: the Möller–Trumbore test of
//! [`Triangle::intersect`], with the vertex and both edges of each lane stored side by side
//! (structure of arrays), so that the four lanes are computed together: in SSE registers on
//! x86-64, as loops over the lanes (which the compiler vectorises in part) elsewhere.
//!
//! Every lane computes exactly what [`Triangle::intersect`] computes, in the same order, so a
//! block reports the same distances and barycentrics to the bit.

use crate::geometry::Ray;
use crate::shape::Triangle;
use crate::simd::lanes::{F8, V8};
use glam::Vec3;

/// Triangles per leaf block, tested against a ray at once (the BVH's width is `Bvh8`'s 8,
/// the path tracer's [`pathlab_mc::simd::PATH_LANES`]).
pub const TRIS_PER_BLOCK: usize = 4;

/// Up to four triangles. Unused lanes have zero edges, which no ray hits (their determinant
/// is zero).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TriBlock {
    /// First vertex: `v0[axis][lane]`.
    v0: [[f32; TRIS_PER_BLOCK]; 3],
    /// Edge from the first to the second vertex.
    e1: [[f32; TRIS_PER_BLOCK]; 3],
    /// Edge from the first to the third vertex.
    e2: [[f32; TRIS_PER_BLOCK]; 3],
}

/// A lane's hit: distance and barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockHit {
    /// Which lane.
    pub lane: usize,
    /// Ray parameter.
    pub t: f32,
    /// Barycentric coordinate of vertex 1.
    pub b1: f32,
    /// Barycentric coordinate of vertex 2.
    pub b2: f32,
}

/// Per-lane results of testing a block.
struct LaneHits {
    t: [f32; TRIS_PER_BLOCK],
    b1: [f32; TRIS_PER_BLOCK],
    b2: [f32; TRIS_PER_BLOCK],
    /// Bit per lane that hits within the ray's extent.
    mask: u32,
}

impl TriBlock {
    /// A block of `triangles` (at most [`TRIS_PER_BLOCK`]), the rest of the lanes unused.
    pub fn new(triangles: &[Triangle]) -> TriBlock {
        assert!(
            triangles.len() <= TRIS_PER_BLOCK,
            "a block holds at most {TRIS_PER_BLOCK} triangles"
        );
        let mut b = TriBlock {
            v0: [[0.0; TRIS_PER_BLOCK]; 3],
            e1: [[0.0; TRIS_PER_BLOCK]; 3],
            e2: [[0.0; TRIS_PER_BLOCK]; 3],
        };
        for (lane, tri) in triangles.iter().enumerate() {
            let (e1, e2) = (tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
            for axis in 0..3 {
                b.v0[axis][lane] = tri.p[0][axis];
                b.e1[axis][lane] = e1[axis];
                b.e2[axis][lane] = e2[axis];
            }
        }
        b
    }

    /// Lane `lane`'s first vertex and its edges to the second and third, as the tests use
    /// them (the scene's surface interactions read its triangles from here).
    #[inline(always)]
    pub fn corner_and_edges(&self, lane: usize) -> [Vec3; 3] {
        let at = |a: &[[f32; TRIS_PER_BLOCK]; 3]| Vec3::new(a[0][lane], a[1][lane], a[2][lane]);
        [at(&self.v0), at(&self.e1), at(&self.e2)]
    }

    /// Tests all four lanes: in SSE registers on x86-64 (the comparisons too, which the
    /// compiler leaves as scalar code in the lane loop), with lane loops elsewhere. Both give
    /// the same results.
    #[inline(always)]
    fn test(&self, ray: &Ray) -> LaneHits {
        #[cfg(target_arch = "x86_64")]
        return self.test_sse(ray);
        #[cfg(not(target_arch = "x86_64"))]
        return self.test_lanes(ray);
    }

    /// [`TriBlock::test`] as loops over the lanes.
    // The lane conditions are comparisons joined by `&`: the range form branches.
    #[allow(clippy::manual_range_contains)]
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    #[inline(always)]
    fn test_lanes(&self, ray: &Ray) -> LaneHits {
        let (o, d) = (ray.o, ray.d);
        let mut t = [0.0f32; TRIS_PER_BLOCK];
        let mut b1 = [0.0f32; TRIS_PER_BLOCK];
        let mut b2 = [0.0f32; TRIS_PER_BLOCK];
        let mut ok = [false; TRIS_PER_BLOCK];
        for lane in 0..TRIS_PER_BLOCK {
            let e1 = [self.e1[0][lane], self.e1[1][lane], self.e1[2][lane]];
            let e2 = [self.e2[0][lane], self.e2[1][lane], self.e2[2][lane]];
            // pvec = d × e2, det = e1 · pvec (glam's cross and dot, term by term).
            let pvec = [
                d.y * e2[2] - e2[1] * d.z,
                d.z * e2[0] - e2[2] * d.x,
                d.x * e2[1] - e2[0] * d.y,
            ];
            let det = e1[0] * pvec[0] + e1[1] * pvec[1] + e1[2] * pvec[2];
            let inv_det = 1.0 / det;
            let tvec = [
                o.x - self.v0[0][lane],
                o.y - self.v0[1][lane],
                o.z - self.v0[2][lane],
            ];
            let u = (tvec[0] * pvec[0] + tvec[1] * pvec[1] + tvec[2] * pvec[2]) * inv_det;
            // qvec = tvec × e1.
            let qvec = [
                tvec[1] * e1[2] - e1[1] * tvec[2],
                tvec[2] * e1[0] - e1[2] * tvec[0],
                tvec[0] * e1[1] - e1[0] * tvec[1],
            ];
            let v = (d.x * qvec[0] + d.y * qvec[1] + d.z * qvec[2]) * inv_det;
            let dist = (e2[0] * qvec[0] + e2[1] * qvec[1] + e2[2] * qvec[2]) * inv_det;
            // The scalar test's conditions; NaNs fail every comparison, as there. (Written as
            // comparisons joined by `&`, not `&&` or range `contains`, so that no lane
            // branches.)
            ok[lane] = (det != 0.0)
                & (det.abs() < f32::INFINITY)
                & (u >= 0.0)
                & (u <= 1.0)
                & (v >= 0.0)
                & (u + v <= 1.0)
                & (dist > ray.t_min)
                & (dist < ray.t_max);
            t[lane] = dist;
            b1[lane] = u;
            b2[lane] = v;
        }
        let mut mask = 0u32;
        for (lane, &hit) in ok.iter().enumerate() {
            mask |= u32::from(hit) << lane;
        }
        LaneHits { t, b1, b2, mask }
    }

    /// [`TriBlock::test_lanes`] in SSE registers: the same operations in the same order (no
    /// fused multiply-adds), so the same bits; the comparisons have the scalar ones' NaN
    /// behaviour (`!=` is true for NaN, the others false).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn test_sse(&self, ray: &Ray) -> LaneHits {
        use std::arch::x86_64::*;
        // SAFETY: SSE and SSE2, all these intrinsics need, are part of the x86-64 baseline;
        // the loads and stores go through `[f32; 4]`s, 16 bytes each, all they move.
        unsafe {
            let load = |a: &[f32; TRIS_PER_BLOCK]| _mm_loadu_ps(a.as_ptr());
            let store = |v: __m128| {
                let mut a = [0.0f32; TRIS_PER_BLOCK];
                _mm_storeu_ps(a.as_mut_ptr(), v);
                a
            };
            let mul = |a, b| _mm_mul_ps(a, b);
            let sub = |a, b| _mm_sub_ps(a, b);
            let add = |a, b| _mm_add_ps(a, b);
            let splat = |x| _mm_set1_ps(x);
            let (dx, dy, dz) = (splat(ray.d.x), splat(ray.d.y), splat(ray.d.z));
            let e1 = [load(&self.e1[0]), load(&self.e1[1]), load(&self.e1[2])];
            let e2 = [load(&self.e2[0]), load(&self.e2[1]), load(&self.e2[2])];
            let pvec = [
                sub(mul(dy, e2[2]), mul(e2[1], dz)),
                sub(mul(dz, e2[0]), mul(e2[2], dx)),
                sub(mul(dx, e2[1]), mul(e2[0], dy)),
            ];
            let dot = |a: &[__m128; 3], b: &[__m128; 3]| {
                add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
            };
            let det = dot(&e1, &pvec);
            let inv_det = _mm_div_ps(splat(1.0), det);
            let tvec = [
                sub(splat(ray.o.x), load(&self.v0[0])),
                sub(splat(ray.o.y), load(&self.v0[1])),
                sub(splat(ray.o.z), load(&self.v0[2])),
            ];
            let u = mul(dot(&tvec, &pvec), inv_det);
            let qvec = [
                sub(mul(tvec[1], e1[2]), mul(e1[1], tvec[2])),
                sub(mul(tvec[2], e1[0]), mul(e1[2], tvec[0])),
                sub(mul(tvec[0], e1[1]), mul(e1[0], tvec[1])),
            ];
            let v = mul(dot(&[dx, dy, dz], &qvec), inv_det);
            let dist = mul(dot(&e2, &qvec), inv_det);
            let zero = _mm_setzero_ps();
            let one = splat(1.0);
            let abs_det = _mm_andnot_ps(splat(-0.0), det);
            let ok = [
                _mm_cmpneq_ps(det, zero),
                _mm_cmplt_ps(abs_det, splat(f32::INFINITY)),
                _mm_cmpge_ps(u, zero),
                _mm_cmple_ps(u, one),
                _mm_cmpge_ps(v, zero),
                _mm_cmple_ps(add(u, v), one),
                _mm_cmpgt_ps(dist, splat(ray.t_min)),
                _mm_cmplt_ps(dist, splat(ray.t_max)),
            ]
            .into_iter()
            .reduce(|a, b| _mm_and_ps(a, b))
            .unwrap_or(zero);
            LaneHits {
                t: store(dist),
                b1: store(u),
                b2: store(v),
                mask: _mm_movemask_ps(ok) as u32,
            }
        }
    }

    /// The nearest hit within `(ray.t_min, ray.t_max)` among the lanes in `lanes` (bit per
    /// lane); on equal distances, the lowest lane (as testing them in order would).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, lanes: u32) -> Option<BlockHit> {
        let h = self.test(ray);
        let mut mask = h.mask & lanes;
        if mask == 0 {
            return None;
        }
        let mut best = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if h.t[lane] < h.t[best] {
                best = lane;
            }
        }
        Some(BlockHit {
            lane: best,
            t: h.t[best],
            b1: h.b1[best],
            b2: h.b2[best],
        })
    }

    /// The lanes of `lanes` that `ray` hits within its extent (bit per lane).
    #[inline(always)]
    pub fn hits(&self, ray: &Ray, lanes: u32) -> u32 {
        self.test(ray).mask & lanes
    }

    /// Tests the triangle in lane `lane` against eight rays at once, [`Triangle::intersect`]'s
    /// arithmetic in each ray lane (so the same distances and barycentrics to the bit): a ray
    /// lane that hits it within `(t_min, nearest.t)` takes it as its nearest, with `slot`.
    #[inline(always)]
    pub fn nearest_for_rays(&self, lane: usize, slot: u32, rays: &RayLanes, nearest: &mut Nearest) {
        let splat = |a: &[[f32; TRIS_PER_BLOCK]; 3]| V8 {
            x: F8::splat(a[0][lane]),
            y: F8::splat(a[1][lane]),
            z: F8::splat(a[2][lane]),
        };
        let (v0, e1, e2) = (splat(&self.v0), splat(&self.e1), splat(&self.e2));
        let d = rays.d;
        let pvec = V8 {
            x: d.y * e2.z - e2.y * d.z,
            y: d.z * e2.x - e2.z * d.x,
            z: d.x * e2.y - e2.x * d.y,
        };
        let det = e1.dot(pvec);
        let inv_det = F8::splat(1.0) / det;
        let tvec = rays.o - v0;
        let u = tvec.dot(pvec) * inv_det;
        let qvec = V8 {
            x: tvec.y * e1.z - e1.y * tvec.z,
            y: tvec.z * e1.x - e1.z * tvec.x,
            z: tvec.x * e1.y - e1.x * tvec.y,
        };
        let v = d.dot(qvec) * inv_det;
        let t = e2.dot(qvec) * inv_det;
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        // `det != 0` is left out: where det is ±0, u is ±∞ or NaN and fails its range test
        // (written out, the two determinant tests would be merged into a per-lane
        // classification of det that the vector unit cannot do).
        let hit = det.abs().lt(F8::splat(f32::INFINITY))
            & zero.le(u)
            & u.le(one)
            & zero.le(v)
            & (u + v).le(one)
            & t.gt(rays.t_min)
            & t.lt(nearest.t);
        nearest.t = hit.select(t, nearest.t);
        nearest.b1 = hit.select(u, nearest.b1);
        nearest.b2 = hit.select(v, nearest.b2);
        nearest.slot = hit.select(F8::splat(f32::from_bits(slot)), nearest.slot);
    }

    /// [`TriBlock::nearest_for_rays`] written in AVX intrinsics: the same operations in the
    /// same order, so the same bits (tested), one instruction each (the lane-loop form leaves
    /// the compiler room to shuffle lanes between operations).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(crate) fn nearest_for_rays_avx(
        &self,
        lane: usize,
        slot: u32,
        rays: &AvxRays,
        nearest: &mut AvxNearest,
    ) {
        use std::arch::x86_64::*;
        let splat = |a: &[[f32; TRIS_PER_BLOCK]; 3]| {
            [
                _mm256_set1_ps(a[0][lane]),
                _mm256_set1_ps(a[1][lane]),
                _mm256_set1_ps(a[2][lane]),
            ]
        };
        let (v0, e1, e2) = (splat(&self.v0), splat(&self.e1), splat(&self.e2));
        let mul = |a, b| _mm256_mul_ps(a, b);
        let sub = |a, b| _mm256_sub_ps(a, b);
        let add = |a, b| _mm256_add_ps(a, b);
        let dot = |a: &[__m256; 3], b: &[__m256; 3]| {
            add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
        };
        let d = &rays.d;
        let pvec = [
            sub(mul(d[1], e2[2]), mul(e2[1], d[2])),
            sub(mul(d[2], e2[0]), mul(e2[2], d[0])),
            sub(mul(d[0], e2[1]), mul(e2[0], d[1])),
        ];
        let det = dot(&e1, &pvec);
        let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
        let tvec = [
            sub(rays.o[0], v0[0]),
            sub(rays.o[1], v0[1]),
            sub(rays.o[2], v0[2]),
        ];
        let u = mul(dot(&tvec, &pvec), inv_det);
        let qvec = [
            sub(mul(tvec[1], e1[2]), mul(e1[1], tvec[2])),
            sub(mul(tvec[2], e1[0]), mul(e1[2], tvec[0])),
            sub(mul(tvec[0], e1[1]), mul(e1[0], tvec[1])),
        ];
        let v = mul(dot(d, &qvec), inv_det);
        let t = mul(dot(&e2, &qvec), inv_det);
        let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
        let abs_det = _mm256_andnot_ps(_mm256_set1_ps(-0.0), det);
        let hit = [
            _mm256_cmp_ps::<_CMP_LT_OQ>(abs_det, _mm256_set1_ps(f32::INFINITY)),
            _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(u, one),
            _mm256_cmp_ps::<_CMP_GE_OQ>(v, zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(add(u, v), one),
            _mm256_cmp_ps::<_CMP_GT_OQ>(t, rays.t_min),
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, nearest.t),
        ]
        .into_iter()
        .reduce(|a, b| _mm256_and_ps(a, b))
        .unwrap_or(zero);
        nearest.t = _mm256_blendv_ps(nearest.t, t, hit);
        nearest.b1 = _mm256_blendv_ps(nearest.b1, u, hit);
        nearest.b2 = _mm256_blendv_ps(nearest.b2, v, hit);
        nearest.slot = _mm256_blendv_ps(nearest.slot, _mm256_set1_ps(f32::from_bits(slot)), hit);
    }
}

/// Two triangles against the same eight rays in one sixteen-lane AVX-512 pass: lanes 0–7 test
/// triangle `a` (lane `a.1` of block `a.0`, leaf slot `a.2`), lanes 8–15 triangle `b`, each
/// with [`TriBlock::nearest_for_rays_avx`]'s operations in its order (so the same distances
/// and barycentrics to the bit). Each half keeps its own nearest hit, so that one pair's
/// result does not wait for the other half's; [`Avx512Nearest::lanes`] joins them.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
#[inline]
pub(crate) fn nearest_for_rays_pair_avx512(
    a: (&TriBlock, usize, u32),
    b: (&TriBlock, usize, u32),
    rays: &Avx512Rays,
    nearest: &mut Avx512Nearest,
) {
    use std::arch::x86_64::*;
    // Triangle a's value in the low eight lanes, b's in the high eight.
    let halves =
        |x: f32, y: f32| _mm512_mask_blend_ps(0xff00, _mm512_set1_ps(x), _mm512_set1_ps(y));
    let pair = |fa: &[[f32; TRIS_PER_BLOCK]; 3], fb: &[[f32; TRIS_PER_BLOCK]; 3], axis: usize| {
        halves(fa[axis][a.1], fb[axis][b.1])
    };
    let splat = |fa, fb| [pair(fa, fb, 0), pair(fa, fb, 1), pair(fa, fb, 2)];
    let v0 = splat(&a.0.v0, &b.0.v0);
    let e1 = splat(&a.0.e1, &b.0.e1);
    let e2 = splat(&a.0.e2, &b.0.e2);
    let mul = |x, y| _mm512_mul_ps(x, y);
    let sub = |x, y| _mm512_sub_ps(x, y);
    let add = |x, y| _mm512_add_ps(x, y);
    let dot = |x: &[__m512; 3], y: &[__m512; 3]| {
        add(add(mul(x[0], y[0]), mul(x[1], y[1])), mul(x[2], y[2]))
    };
    let d = &rays.d;
    let pvec = [
        sub(mul(d[1], e2[2]), mul(e2[1], d[2])),
        sub(mul(d[2], e2[0]), mul(e2[2], d[0])),
        sub(mul(d[0], e2[1]), mul(e2[0], d[1])),
    ];
    let det = dot(&e1, &pvec);
    let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), det);
    let tvec = [
        sub(rays.o[0], v0[0]),
        sub(rays.o[1], v0[1]),
        sub(rays.o[2], v0[2]),
    ];
    let u = mul(dot(&tvec, &pvec), inv_det);
    let qvec = [
        sub(mul(tvec[1], e1[2]), mul(e1[1], tvec[2])),
        sub(mul(tvec[2], e1[0]), mul(e1[2], tvec[0])),
        sub(mul(tvec[0], e1[1]), mul(e1[0], tvec[1])),
    ];
    let v = mul(dot(d, &qvec), inv_det);
    let t = mul(dot(&e2, &qvec), inv_det);
    let (zero, one) = (_mm512_setzero_ps(), _mm512_set1_ps(1.0));
    let abs_det = _mm512_andnot_ps(_mm512_set1_ps(-0.0), det);
    let hit: __mmask16 = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(abs_det, _mm512_set1_ps(f32::INFINITY))
        & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(u, zero)
        & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(u, one)
        & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(v, zero)
        & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(add(u, v), one)
        & _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, rays.t_min)
        & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, nearest.t);
    nearest.t = _mm512_mask_blend_ps(hit, nearest.t, t);
    nearest.b1 = _mm512_mask_blend_ps(hit, nearest.b1, u);
    nearest.b2 = _mm512_mask_blend_ps(hit, nearest.b2, v);
    let slots = halves(f32::from_bits(a.2), f32::from_bits(b.2));
    nearest.slot = _mm512_mask_blend_ps(hit, nearest.slot, slots);
    nearest.pair = _mm512_mask_blend_ps(hit, nearest.pair, nearest.this_pair);
    nearest.this_pair = _mm512_castsi512_ps(_mm512_add_epi32(
        _mm512_castps_si512(nearest.this_pair),
        _mm512_set1_epi32(1),
    ));
}

/// The nearest hits of [`nearest_for_rays_pair_avx512`]: lanes 0–7 those among the first
/// triangles of the pairs, lanes 8–15 among the second ones, each with the index of its
/// pair.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(crate) struct Avx512Nearest {
    t: std::arch::x86_64::__m512,
    b1: std::arch::x86_64::__m512,
    b2: std::arch::x86_64::__m512,
    slot: std::arch::x86_64::__m512,
    /// The pair each lane's hit came from (`u32` bits).
    pair: std::arch::x86_64::__m512,
    /// The next pair's index in every lane.
    this_pair: std::arch::x86_64::__m512,
}

#[cfg(target_arch = "x86_64")]
impl Avx512Nearest {
    /// No hits yet, for rays ending at `t_max`.
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    #[inline]
    pub(crate) fn new(t_max: F8) -> Avx512Nearest {
        use std::arch::x86_64::*;
        Avx512Nearest {
            t: _mm512_broadcast_f32x8(to_avx(t_max)),
            b1: _mm512_setzero_ps(),
            b2: _mm512_setzero_ps(),
            slot: _mm512_set1_ps(f32::from_bits(u32::MAX)),
            pair: _mm512_setzero_ps(),
            this_pair: _mm512_setzero_ps(),
        }
    }

    /// Each ray's nearest distance so far (the nearer of its two halves').
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    #[inline]
    pub(crate) fn t(&self) -> F8 {
        use std::arch::x86_64::*;
        from_avx(_mm256_min_ps(
            _mm512_castps512_ps256(self.t),
            _mm512_extractf32x8_ps::<1>(self.t),
        ))
    }

    /// Each ray's hit as testing the triangles one by one, in order, would find it: the
    /// nearer of its two halves' hits, and of two at the same distance the earlier one (the
    /// lower pair, or the first triangle of the same pair).
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    #[inline]
    pub(crate) fn lanes(self) -> Nearest {
        use std::arch::x86_64::*;
        let low = |x: __m512| _mm512_castps512_ps256(x);
        let high = |x: __m512| _mm512_extractf32x8_ps::<1>(x);
        let (t_low, t_high) = (low(self.t), high(self.t));
        let pair = _mm512_castps_si512(self.pair);
        let (pair_low, pair_high) = (
            _mm512_castsi512_si256(pair),
            _mm512_extracti64x4_epi64::<1>(pair),
        );
        let take_high: __mmask8 = _mm256_cmp_ps_mask::<_CMP_LT_OQ>(t_high, t_low)
            | (_mm256_cmp_ps_mask::<_CMP_EQ_OQ>(t_high, t_low)
                & _mm256_cmplt_epu32_mask(pair_high, pair_low));
        let pick = |x: __m512| from_avx(_mm256_mask_blend_ps(take_high, low(x), high(x)));
        Nearest {
            t: pick(self.t),
            b1: pick(self.b1),
            b2: pick(self.b2),
            slot: pick(self.slot),
        }
    }
}

/// [`RayLanes`] twice over in AVX-512 registers (lanes 8–15 repeat lanes 0–7), for
/// [`nearest_for_rays_pair_avx512`].
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(crate) struct Avx512Rays {
    o: [std::arch::x86_64::__m512; 3],
    d: [std::arch::x86_64::__m512; 3],
    t_min: std::arch::x86_64::__m512,
}

#[cfg(target_arch = "x86_64")]
impl Avx512Rays {
    /// The rays of `rays`, each twice.
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    #[inline]
    pub(crate) fn new(rays: &AvxRays) -> Avx512Rays {
        use std::arch::x86_64::_mm512_broadcast_f32x8 as twice;
        Avx512Rays {
            o: [twice(rays.o[0]), twice(rays.o[1]), twice(rays.o[2])],
            d: [twice(rays.d[0]), twice(rays.d[1]), twice(rays.d[2])],
            t_min: twice(rays.t_min),
        }
    }
}

/// [`RayLanes`] in AVX registers.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(crate) struct AvxRays {
    o: [std::arch::x86_64::__m256; 3],
    d: [std::arch::x86_64::__m256; 3],
    t_min: std::arch::x86_64::__m256,
}

/// [`Nearest`] in AVX registers.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(crate) struct AvxNearest {
    t: std::arch::x86_64::__m256,
    b1: std::arch::x86_64::__m256,
    b2: std::arch::x86_64::__m256,
    slot: std::arch::x86_64::__m256,
}

#[cfg(target_arch = "x86_64")]
impl AvxRays {
    /// The rays of `rays` in registers.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(crate) fn new(rays: &RayLanes) -> AvxRays {
        let load = |a: &F8| to_avx(*a);
        AvxRays {
            o: [load(&rays.o.x), load(&rays.o.y), load(&rays.o.z)],
            d: [load(&rays.d.x), load(&rays.d.y), load(&rays.d.z)],
            t_min: load(&rays.t_min),
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl AvxNearest {
    /// [`Nearest::new`] in registers.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(crate) fn new(t_max: F8) -> AvxNearest {
        use std::arch::x86_64::*;
        AvxNearest {
            t: to_avx(t_max),
            b1: _mm256_setzero_ps(),
            b2: _mm256_setzero_ps(),
            slot: _mm256_set1_ps(f32::from_bits(u32::MAX)),
        }
    }

    /// Each ray's nearest distance so far.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(crate) fn t(&self) -> F8 {
        from_avx(self.t)
    }

    /// Back to lanes.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(crate) fn lanes(self) -> Nearest {
        Nearest {
            t: from_avx(self.t),
            b1: from_avx(self.b1),
            b2: from_avx(self.b2),
            slot: from_avx(self.slot),
        }
    }
}

/// Eight lanes into an AVX register.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn to_avx(a: F8) -> std::arch::x86_64::__m256 {
    let a = a.0;
    std::arch::x86_64::_mm256_setr_ps(a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7])
}

/// An AVX register's eight lanes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn from_avx(v: std::arch::x86_64::__m256) -> F8 {
    // SAFETY: `__m256` and `[f32; 8]` are both 32 bytes of plain data, and every bit
    // pattern is a valid `f32`.
    F8(unsafe { std::mem::transmute::<std::arch::x86_64::__m256, [f32; 8]>(v) })
}

/// Eight rays, a lane each: origins, directions and extents.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayLanes {
    /// Origins.
    pub o: V8,
    /// Directions.
    pub d: V8,
    /// Near ends of the extents.
    pub t_min: F8,
}

impl RayLanes {
    /// Lane `i` set to `ray`'s origin, direction and near end (its far end is the caller's:
    /// the nearest hits start from it).
    #[inline(always)]
    pub fn set(&mut self, i: usize, ray: &Ray) {
        self.o.set(i, ray.o);
        self.d.set(i, ray.d);
        self.t_min.0[i] = ray.t_min;
    }
}

/// Each ray lane's nearest hit so far: its distance (the ray's far end before any hit), the
/// barycentrics of vertices 1 and 2, and the hit primitive's leaf slot (as `f32` bits;
/// `u32::MAX` for none).
#[derive(Clone, Copy, Debug)]
pub struct Nearest {
    /// Distances.
    pub t: F8,
    /// Barycentric coordinates of vertex 1.
    pub b1: F8,
    /// Barycentric coordinates of vertex 2.
    pub b2: F8,
    /// Leaf slots, as bits.
    pub slot: F8,
}

impl Nearest {
    /// No hits yet, for rays ending at `t_max`.
    pub fn new(t_max: F8) -> Nearest {
        Nearest {
            t: t_max,
            b1: F8::splat(0.0),
            b2: F8::splat(0.0),
            slot: F8::splat(f32::from_bits(u32::MAX)),
        }
    }

    /// Lane `i`'s hit: (leaf slot, distance, b1, b2), or `None`.
    pub fn lane(&self, i: usize) -> Option<(u32, f32, f32, f32)> {
        let slot = self.slot.0[i].to_bits();
        (slot != u32::MAX).then(|| (slot, self.t.0[i], self.b1.0[i], self.b2.0[i]))
    }
}

#[cfg(test)]
mod tests;
