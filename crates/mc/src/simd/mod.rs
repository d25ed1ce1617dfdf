//! The one home of the project's SIMD: the lane types, the names of the widths, and the
//! proof tokens of CPU extensions that run-time dispatch hands out.
//!
//! - [`trig`]: trigonometric functions written over [`lanes::Real`] ([`trig::atan2`]).
//! - [`lanes`]: eight `f32` lanes ([`lanes::F8`], [`lanes::M8`], [`lanes::V8`]) and the
//!   [`lanes::Real`] / [`lanes::Vector3`] traits, so that code written once runs on one value
//!   or on eight, each lane to the bit as the one-value code.
//! - Widths, each named for what it counts: [`PATH_LANES`] (paths traced together, and the
//!   samplers' lane draws); the BVH's width (`pathlab_render::accel::BVH_WIDTH`) and
//!   triangles per leaf block (`pathlab_render::accel::TRIS_PER_BLOCK`) live with the BVH.
//! - Run-time dispatch: code that wants an extension's instructions is a function with
//!   `#[target_feature(enable = ...)]` that takes the extension's token ([`Avx2`]) as its
//!   first argument, beside a portable twin; the caller asks [`Avx2::detect`] (or
//!   [`Avx512::detect`], for the sixteen-lane kernels) once and calls one or the other. The token is the proof that calling the feature-enabled function is
//!   sound, so the `unsafe` block at each call site has one reason to give. Tests compare the
//!   two versions bit for bit.

pub mod lanes;
pub mod trig;

/// Asks the CPU to bring the cache line holding `value` into its caches, ahead of a read that
/// comes later: a hint, with no effect on any result (and no instruction where the CPU has
/// none). For reads of large tables at addresses known well before they are read, such as an
/// environment map's texels, found when a direction is sampled and read after its shadow ray.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `prefetcht0` belongs to SSE, which every x86-64 CPU has; it changes no register
    // or memory a program can see and never faults, and the address is that of a live
    // reference besides.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>((value as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// Paths traced together by the eight-lane path and drawn together by the samplers' lane
/// routines: one lane of [`lanes::F8`] each.
pub const PATH_LANES: usize = lanes::W;

/// Whether this CPU runs code built for x86-64 psABI level 3 (`-C target-cpu=x86-64-v3`):
/// AVX2, FMA, BMI1 and BMI2, F16C, LZCNT, MOVBE and XSAVE, with level 2's SSE3 to SSE4.2,
/// POPCNT and CMPXCHG16B.
#[cfg(target_arch = "x86_64")]
pub fn runs_x86_64_v3() -> bool {
    use std::arch::is_x86_feature_detected as has;
    has!("sse3")
        && has!("ssse3")
        && has!("sse4.1")
        && has!("sse4.2")
        && has!("popcnt")
        && has!("cmpxchg16b")
        && has!("avx")
        && has!("avx2")
        && has!("bmi1")
        && has!("bmi2")
        && has!("f16c")
        && has!("fma")
        && has!("lzcnt")
        && has!("movbe")
        && has!("xsave")
}

/// Whether this CPU runs code built for x86-64 psABI level 4 (`-C target-cpu=x86-64-v4`):
/// level 3 and AVX-512 F, BW, CD, DQ and VL.
#[cfg(target_arch = "x86_64")]
pub fn runs_x86_64_v4() -> bool {
    use std::arch::is_x86_feature_detected as has;
    runs_x86_64_v3()
        && has!("avx512f")
        && has!("avx512bw")
        && has!("avx512cd")
        && has!("avx512dq")
        && has!("avx512vl")
}

/// Proof that this CPU has AVX2 and FMA: only [`Avx2::detect`] makes one, after checking.
/// Code that holds one may run instructions of those extensions.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx2 {
    _checked: (),
}

#[cfg(target_arch = "x86_64")]
impl Avx2 {
    /// `Some` where the CPU has AVX2 and FMA (the standard library caches the answer).
    #[inline]
    pub fn detect() -> Option<Avx2> {
        (std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma"))
            .then_some(Avx2 { _checked: () })
    }
}

/// Proof that this CPU has the AVX-512 subsets the sixteen-lane kernels use (foundation,
/// vector-length and doubleword/quadword instructions, as on every AVX-512 CPU since
/// Skylake-SP), besides AVX2 and FMA: only [`Avx512::detect`] makes one, after checking.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx512 {
    _checked: (),
}

#[cfg(target_arch = "x86_64")]
impl Avx512 {
    /// `Some` where the CPU has AVX-512 F, VL and DQ, AVX2 and FMA, and the environment
    /// variable `PATHLAB_NO_AVX512` is not set (so that the AVX2 code can be run, and
    /// compared, on the same machine).
    #[inline]
    pub fn detect() -> Option<Avx512> {
        static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        let has = *HAS.get_or_init(|| {
            std::env::var_os("PATHLAB_NO_AVX512").is_none()
                && std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512dq")
                && Avx2::detect().is_some()
        });
        has.then_some(Avx512 { _checked: () })
    }

    /// The AVX2 and FMA this CPU also has.
    #[inline]
    pub fn avx2(self) -> Avx2 {
        Avx2 { _checked: () }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    #[test]
    fn the_levels_nest_and_agree_with_the_kernels_tokens() {
        if runs_x86_64_v4() {
            assert!(runs_x86_64_v3());
        }
        if runs_x86_64_v3() {
            // Level 3 code may run the AVX2 kernels.
            assert!(Avx2::detect().is_some());
        }
    }

    #[test]
    fn prefetching_changes_nothing() {
        // Elements of a 12 MB table (beyond a core's own caches), its last included, and
        // values of other sizes: the hint may touch no byte.
        let table: Vec<[f32; 3]> = (0..1 << 20).map(|i| [i as f32, -(i as f32), 0.5]).collect();
        for k in (0..table.len()).step_by(97).chain([table.len() - 1]) {
            prefetch(&table[k]);
        }
        let small = (1u8, 2u64);
        prefetch(&small);
        prefetch(&table);
        assert_eq!(small, (1, 2));
        assert!(table
            .iter()
            .enumerate()
            .all(|(i, v)| *v == [i as f32, -(i as f32), 0.5]));
    }
}
