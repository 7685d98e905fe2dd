//! Asking the cache for what a loop will read a few steps on: for per-mode tables read in the
//! order of some other list (dormant records), where the hardware cannot guess the next
//! address.

/// How many steps ahead to ask: enough for a miss to be served while the loop does the steps in
/// between.
pub const AHEAD: usize = 8;

/// Hints that `items[i]` will be read soon. Does nothing if `i` is out of range, or on targets
/// other than x86-64; never reads or faults.
#[inline(always)]
pub fn prefetch<T>(items: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(item) = items.get(i) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch only hints the cache, of a valid reference here; SSE is part of the
        // x86-64 baseline.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((item as *const T).cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (items, i);
}
