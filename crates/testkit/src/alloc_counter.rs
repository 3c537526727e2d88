//! A global allocator that counts this thread's allocations, for the tests that prove a hot
//! path allocates nothing. A test executable installs it with
//!
//! ```ignore
//! #[global_allocator]
//! static GLOBAL: flexdyn_testkit::alloc_counter::Counting = flexdyn_testkit::alloc_counter::Counting;
//! ```
//!
//! and reads [`allocations`] before and after the code under test. The count is per thread, so
//! tests running beside each other in one executable do not disturb each other's counts.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The counting allocator: forwards to [`System`] and counts on the calling thread.
pub struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
}

/// Allocations (and reallocations) made so far by the calling thread.
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// Fails unless [`Counting`] is this executable's global allocator and counts: without this
/// check every "allocates nothing" test would pass for nothing. Call it from one test of each
/// executable that installs the counter.
pub fn assert_installed() {
    let before = allocations();
    let v = std::hint::black_box(vec![1_u8; 16]);
    assert!(
        allocations() > before,
        "the counting allocator is not installed (allocated {} bytes unseen)",
        v.len()
    );
}
