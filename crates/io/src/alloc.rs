//! A memory allocator for binaries: the system's, with large blocks advised to huge pages.
//!
//! A large block comes straight from the kernel (fresh pages, zero), and every 4 KiB page of
//! it faults once when first written: filling a 6×1024² float cube so costs ~18,000 faults,
//! about as long as the conversion itself. On Linux with transparent huge pages in
//! `madvise` mode (the default), asking for huge pages before the first write makes that
//! 36 faults of 2 MiB (numpy does the same for its arrays of 4 MiB and more), and a map read
//! at random (a renderer's environment) misses the TLB far less. The libraries allocate
//! plainly; this is a binary's choice (`#[global_allocator]`), so that a program embedding
//! them keeps its own. Elsewhere than Linux, the system allocator unchanged.

use std::alloc::{GlobalAlloc, Layout, System};

/// [`System`], with every block of 4 MiB and more advised to transparent huge pages on
/// Linux (`madvise(MADV_HUGEPAGE)`): fewer page faults when a large buffer is first
/// written, fewer TLB misses when it is read at random. The `mirrorball` binary runs with
/// it:
///
/// ```
/// #[global_allocator]
/// static ALLOC: mirrorball_io::HugePages = mirrorball_io::HugePages;
///
/// let big = vec![0.0f32; 4 << 20]; // 16 MiB, advised
/// assert!(big.iter().all(|&v| v == 0.0));
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct HugePages;

// SAFETY: every call is passed to `System` unchanged; `advise` only tells the kernel how to
// back pages inside the block just returned, which changes no byte of it.
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        advise(p, new_size);
        p
    }
}

/// Advises the whole 4 KiB pages inside `len` bytes at `p` to huge pages, for blocks of two
/// huge pages (4 MiB) or more. A failure (no THP support) leaves them as they were.
#[cfg(target_os = "linux")]
fn advise(p: *mut u8, len: usize) {
    const HUGE: usize = 2 << 20;
    const PAGE: usize = 4096;
    if p.is_null() || len < 2 * HUGE {
        return;
    }
    // madvise wants a page-aligned start.
    let start = (p as usize).next_multiple_of(PAGE);
    let end = (p as usize + len) & !(PAGE - 1);
    if end > start {
        // SAFETY: the range lies inside the block just allocated; the advice changes only
        // how the kernel backs its pages, not their contents.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_: *mut u8, _: usize) {}
