//! Analytic environments for tests, shared by the crate's unit tests and its integration
//! tests (which include this file by path); each uses a part of it.
#![allow(dead_code)]

use glam::DVec3;
use mirrorball_core::{EnvMap, Projection, ProjectionKind};

/// A smooth analytic environment: colour = ½ + ½·d (so every axis flip shows).
pub fn smooth(d: DVec3) -> [f32; 3] {
    [
        (0.5 + 0.5 * d.x) as f32,
        (0.5 + 0.5 * d.y) as f32,
        (0.5 + 0.5 * d.z) as f32,
    ]
}

/// A busier analytic environment (bands in longitude and latitude) for visible artifacts.
pub fn busy(d: DVec3) -> [f32; 3] {
    let lon = d.x.atan2(-d.z);
    let lat = d.y.asin();
    let a = (0.5 + 0.5 * (6.0 * lon).sin()) as f32;
    let b = (0.5 + 0.5 * (8.0 * lat).cos()) as f32;
    [a, b, 0.5 * (d.y as f32 + 1.0)]
}

pub fn env_of(kind: ProjectionKind, size: u32, f: fn(DVec3) -> [f32; 3]) -> EnvMap {
    env_in(kind.default_projection(), size, f)
}

pub fn env_in(p: Projection, size: u32, f: fn(DVec3) -> [f32; 3]) -> EnvMap {
    EnvMap::from_fn(p, size, 3, move |d| {
        let c = f(d);
        [c[0], c[1], c[2], 1.0]
    })
}

pub fn max_diff(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max)
}
