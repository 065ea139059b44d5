//! Hints to the cache: loads a loop will make soon, asked for ahead so that they overlap
//! instead of each waiting on a miss.

/// How many items ahead a loop over faces asks for their vertices' data: far enough for a
/// miss to arrive (a face's work is tens of nanoseconds), near enough to stay in the L1 cache.
pub(crate) const AHEAD: usize = 16;

/// A hint that the cache line holding `items[i]` is read soon; past the end, nothing is read.
#[inline(always)]
pub(crate) fn prefetch<T>(items: &[T], i: usize) {
    prefetch_ptr(items.as_ptr().wrapping_add(i) as *const u8);
}

/// A hint that the cache line at `p` is read soon.
#[inline(always)]
pub(crate) fn prefetch_ptr(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it reads nothing the program sees and never faults,
    // whatever the address (wrapping_add may point past an array's end); SSE is in every
    // x86_64 target's baseline.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p as *const i8)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
