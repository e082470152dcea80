//! Well-spread sets of directions, for tests, error reports and window searches.

use glam::DVec3;

/// `n` directions on the spherical Fibonacci lattice (Swinbank & Purser 2006): equal-area
/// bands in `y`, golden-angle steps in longitude. Deterministic, nearly uniform.
pub fn fibonacci(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}
