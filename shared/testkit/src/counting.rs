//! A counting global allocator for the zero-allocation tests: every allocation made by a thread
//! that armed it is counted, the rest of the program (the test harness, other threads) is not.
//! The counts are per thread, so tests that count at the same time in one binary (the test
//! harness runs them on parallel threads) do not see each other's allocations.
//!
//! The allocator of a program is chosen once, at the top of its binary, so each test binary that
//! counts installs it itself, with [`counting_allocator!`](crate::counting_allocator) (or by hand:
//! `#[global_allocator] static GLOBAL: Counting = Counting;`). Then it brackets the code under
//! test with [`arm`] and [`disarm`], or hands it to [`measure`]:
//!
//! ```
//! use tandem_testkit::counting::{arm, disarm, measure};
//!
//! tandem_testkit::counting_allocator!();
//!
//! fn main() {
//!     let mut samples: Vec<f64> = Vec::with_capacity(8);
//!     arm();
//!     samples.push(1.0);
//!     let (allocations, _deallocations) = disarm();
//!     assert_eq!(allocations, 0, "within its capacity, a push does not allocate");
//!
//!     let grown = measure(|| samples.extend_from_slice(&[2.0; 8]));
//!     assert_eq!(grown.allocations, 1, "past its capacity, the vector grows once");
//! }
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::thread::LocalKey;

thread_local! {
    /// Counting is armed on this thread. Const-initialised and without destructor, so reading
    /// it inside the allocator never allocates or recurses (as the counters below).
    static ARMED: Cell<bool> = const { Cell::new(false) };
    /// Allocations (alloc, alloc_zeroed, realloc) made by this thread while armed.
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
    /// Deallocations made by this thread while armed (for reports only).
    static DEALLOCS: Cell<u64> = const { Cell::new(0) };
}

fn armed() -> bool {
    ARMED.try_with(Cell::get).unwrap_or(false)
}

fn count(counter: &'static LocalKey<Cell<u64>>) {
    if armed() {
        // During thread teardown the counter may be gone: nothing to count then.
        let _ = counter.try_with(|c| c.set(c.get() + 1));
    }
}

fn read(counter: &'static LocalKey<Cell<u64>>) -> u64 {
    counter.try_with(Cell::get).unwrap_or(0)
}

/// The counting allocator: forwards to [`System`], counting what an armed thread does.
/// Install it with [`counting_allocator!`](crate::counting_allocator).
#[derive(Debug, Clone, Copy, Default)]
pub struct Counting;

// A global allocator needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(&ALLOCS);
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(&ALLOCS);
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(&ALLOCS);
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count(&DEALLOCS);
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Installs [`Counting`] as the global allocator of the test binary that invokes it (once, at
/// the top level of the test file).
#[macro_export]
macro_rules! counting_allocator {
    () => {
        #[global_allocator]
        static GLOBAL: $crate::counting::Counting = $crate::counting::Counting;
    };
}

/// What an armed thread did between [`arm`] and [`disarm`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Allocations, zeroed allocations and reallocations.
    pub allocations: u64,
    /// Deallocations.
    pub deallocations: u64,
}

/// Arms the counter on this thread and zeroes it.
///
/// # Panics
/// When [`Counting`] is not the global allocator of this binary (a probe allocation went
/// uncounted): a zero-allocation test would otherwise pass without counting anything.
///
/// ```should_panic
/// // A binary without `tandem_testkit::counting_allocator!();`:
/// tandem_testkit::counting::arm();
/// ```
pub fn arm() {
    ARMED.with(|a| a.set(true));
    let before = read(&ALLOCS);
    drop(std::hint::black_box(Box::new(0u64)));
    let installed = read(&ALLOCS) > before;
    ALLOCS.with(|c| c.set(0));
    DEALLOCS.with(|c| c.set(0));
    if !installed {
        ARMED.with(|a| a.set(false));
        panic!(
            "the counting allocator is not installed: add `tandem_testkit::counting_allocator!();` \
             at the top of this test file"
        );
    }
}

/// Disarms the counter; returns (allocations, deallocations) since [`arm`].
pub fn disarm() -> (u64, u64) {
    ARMED.with(|a| a.set(false));
    (read(&ALLOCS), read(&DEALLOCS))
}

/// Runs `f` armed on this thread and returns what it allocated and freed.
pub fn measure(f: impl FnOnce()) -> Counts {
    arm();
    f();
    let (allocations, deallocations) = disarm();
    Counts {
        allocations,
        deallocations,
    }
}
