//! Which vectorised paths run: the eight-lane paths (depth pass, mirror rows) run where
//! [`X8::get`] hands out its token (on x86-64, a processor with AVX2, chosen at run time)
//! and give the same bits as the per-sample paths they replace (tested by switching them
//! off with [`set_portable`]).

use mirrorball_core::simd::X8;

/// The eight-lane token, unless [`set_portable`] has turned the eight-lane paths off or the
/// processor lacks them.
#[inline]
pub(crate) fn x8() -> Option<X8> {
    if PORTABLE.load(std::sync::atomic::Ordering::Relaxed) {
        return None;
    }
    X8::get()
}

static PORTABLE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Makes the renderer's eight-lane paths (AVX2 on x86-64, chosen at run time) step aside
/// for the per-sample ones (`true`), or use them again where the processor has them
/// (`false`, the default). The pictures are the same to the bit either way; tests and
/// benchmarks use this to show it and to measure the difference.
pub fn set_portable(portable: bool) {
    PORTABLE.store(portable, std::sync::atomic::Ordering::Relaxed);
}
