//! The one home of the project's SIMD: the lane types, the names of the widths, and the
//! proof tokens of CPU extensions that run-time dispatch hands out.
//!
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

/// Paths traced together by the eight-lane path and drawn together by the samplers' lane
/// routines: one lane of [`lanes::F8`] each.
pub const PATH_LANES: usize = lanes::W;

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
