//! Shared helpers.
use mirrorball_core::{Projection, ProjectionKind};

/// The default projection of `k`.
pub fn proj(k: ProjectionKind) -> Projection {
    k.default_projection()
}

/// Asserts `|a/b − 1| ≤ tol` (or `|a − b| ≤ tol` when `b` is 0).
#[track_caller]
pub fn close(a: f64, b: f64, tol: f64, what: &str) {
    let err = if b == 0.0 {
        a.abs()
    } else {
        (a / b - 1.0).abs()
    };
    assert!(
        err <= tol,
        "{what}: {a} vs {b} (relative error {err:.3e} > {tol:.1e})"
    );
}

/// SplitMix64, for deterministic sample points.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
