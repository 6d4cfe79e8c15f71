//! A counting global allocator for the zero-allocation tests: every allocation made by a thread
//! that armed it is counted. Each test binary installs it with
//! `#[global_allocator] static GLOBAL: Counting = Counting;`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Allocations (alloc, alloc_zeroed, realloc) made by an armed thread.
static ALLOCS: AtomicU64 = AtomicU64::new(0);
/// Deallocations made by an armed thread (for reports only).
static DEALLOCS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// Counting is armed on this thread. Const-initialised and without destructor, so reading
    /// it inside the allocator never allocates or recurses.
    static ARMED: Cell<bool> = const { Cell::new(false) };
}

fn armed() -> bool {
    ARMED.try_with(Cell::get).unwrap_or(false)
}

/// Forwards to `System`, counting what an armed thread does.
pub struct Counting;

// A global allocator needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if armed() {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if armed() {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if armed() {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if armed() {
            DEALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Arms the counter on this thread and zeroes it.
pub fn arm() {
    ALLOCS.store(0, Ordering::SeqCst);
    DEALLOCS.store(0, Ordering::SeqCst);
    ARMED.with(|a| a.set(true));
}

/// Disarms the counter; returns (allocations, deallocations) since [`arm`].
pub fn disarm() -> (u64, u64) {
    ARMED.with(|a| a.set(false));
    (
        ALLOCS.load(Ordering::SeqCst),
        DEALLOCS.load(Ordering::SeqCst),
    )
}
