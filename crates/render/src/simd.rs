//! What the CPU offers beyond the target's baseline, checked at run time: the traversal is
//! compiled a second time for AVX2 and FMA and takes that version where the CPU has them.

/// Proof that this CPU has AVX2 and FMA: only [`Avx2::detect`] makes one, after checking.
/// Code that holds one may run instructions of those extensions.
#[derive(Clone, Copy, Debug)]
pub struct Avx2 {
    _checked: (),
}

impl Avx2 {
    /// `Some` where the CPU has AVX2 and FMA (the standard library caches the answer).
    #[inline]
    pub fn detect() -> Option<Avx2> {
        (std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma"))
            .then_some(Avx2 { _checked: () })
    }
}
