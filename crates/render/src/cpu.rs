//! Which vectorised paths run: those that need more than the target's baseline (AVX2 on
//! x86-64) are chosen at run time, once the processor has said it has the feature, and
//! give the same bits as the portable paths they replace (tested by switching them off
//! with [`set_portable`]).

/// Whether the AVX2 path runs: the processor has AVX2 and [`set_portable`] has not turned
/// it off.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn avx2() -> bool {
    !PORTABLE.load(std::sync::atomic::Ordering::Relaxed) && std::is_x86_feature_detected!("avx2")
}

static PORTABLE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Makes the renderer's vectorised paths that depend on the processor (AVX2) step aside for
/// the portable ones (`true`), or use them again where the processor has them (`false`,
/// the default). The pictures are the same to the bit either way; tests and benchmarks
/// use this to show it and to measure the difference.
pub fn set_portable(portable: bool) {
    PORTABLE.store(portable, std::sync::atomic::Ordering::Relaxed);
}
