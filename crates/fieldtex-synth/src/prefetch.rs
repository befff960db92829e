//! The one cache-prefetch hint of the crate: asks the CPU to fetch the line holding a
//! value ahead of its use, so that table lookups whose addresses are known early
//! overlap other work instead of stalling where they are read. It never changes a
//! result (on targets other than x86-64 it does nothing).

/// Hints the CPU to bring `v`'s cache line into all cache levels.
#[inline(always)]
pub(crate) fn prefetch_read<T>(v: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: SSE is part of the x86_64 baseline, and a prefetch only hints the
        // cache (the address comes from a reference, so it is valid anyway).
        unsafe { _mm_prefetch::<_MM_HINT_T0>((v as *const T).cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}
