//! A global allocator that counts the heap bytes held by the whole process and their peak, so
//! that [`run`](super::run) can report the peak memory of one simplify call, threads included. The
//! `meshslim` binary installs it; elsewhere [`measure`] reports `None`.
//!
//! Chosen over the process's peak RSS (VmHWM after `echo 5 > /proc/self/clear_refs`): it works
//! on every platform, does not depend on when the allocator returns pages to the system, and
//! counts exactly the bytes the call asked for. Its cost is two relaxed atomic operations per
//! allocation.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

/// Install with `#[global_allocator] static A: CountingAlloc = CountingAlloc;`.
pub struct CountingAlloc;

fn grew(by: usize) {
    let live = LIVE.fetch_add(by, Relaxed) + by;
    if live > PEAK.load(Relaxed) {
        PEAK.fetch_max(live, Relaxed);
    }
}

// SAFETY: every call forwards to `System` with the caller's own layout and pointer, so the
// allocator contract is System's; the bookkeeping only touches atomics and never allocates.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Relaxed);
            }
        }
        p
    }
}

/// Whether [`CountingAlloc`] is the global allocator (it has counted something).
pub fn installed() -> bool {
    PEAK.load(Relaxed) > 0
}

/// Runs `f` and returns the peak bytes held during it above what was held when it started
/// (by any thread); `None` when the counting allocator is not installed.
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    if !installed() {
        return (f(), None);
    }
    let base = LIVE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let out = f();
    (out, Some(PEAK.load(Relaxed).saturating_sub(base) as u64))
}
