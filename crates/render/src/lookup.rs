//! Environment lookups beyond one bilinear fetch, all through `mirrorball-filter`, and the
//! per-environment work they need, done once and kept in the [`Environment`]'s [`EnvCache`]:
//!
//! * **Footprint filters** ([`Filter::Trilinear`], [`Filter::Ewa`]): a
//!   [`mirrorball_filter::Sampler`] over the filter crate's solid-angle-weighted mip pyramid.
//!   A pixel's footprint is the ray differentials of the direction looked up, taken from the
//!   directions through the pixel's four corners ([`footprint`]): the reflected rays at the
//!   corners for objects (Greene's pixel cone, [`crate::Indexing::Cone`]), the camera rays
//!   at the corners for the background.
//! * **Greene's material** ([`crate::Material::Greene`]): the diffuse illumination map
//!   (Lambert, `E/π`) and the specular map of each lobe, made by
//!   [`mirrorball_filter::Prefilterer`] in the environment's own projection (at most 512
//!   texels along a side, so from a working cube no finer than such a map needs, whatever
//!   the environment's size).
//!
//! The cache is keyed by the environment map's `Arc`: replacing `Environment::map` makes it
//! start again; clones of the environment share it, so a turntable's frames build nothing.
//!
//! [`Environment`]: crate::Environment
//! [`Filter::Trilinear`]: crate::Filter::Trilinear
//! [`Filter::Ewa`]: crate::Filter::Ewa

use crate::scene::{Filter, Indexing};
use glam::DVec3;
use mirrorball_core::EnvMap;
use mirrorball_filter::{Footprint, Lobe, PrefilterOptions, Prefilterer, Sampler};
use std::sync::{Arc, Mutex, Weak};

/// The specular lobe of Greene's material: the filter crate's [`Lobe`] (Phong, GGX, or
/// Lambert), under the name the scene has always used.
pub type SpecularLobe = Lobe;

/// Greene's two prefiltered maps for one lobe, in the environment's projection.
#[derive(Debug)]
pub(crate) struct GreeneMaps {
    /// `E/π` (Lambert), read at the normal.
    pub(crate) diffuse: Arc<EnvMap>,
    /// The lobe's prefiltered radiance, read at the reflected vector.
    pub(crate) specular: Arc<EnvMap>,
}

#[derive(Default)]
struct Inner {
    /// The map everything here was made from.
    key: Weak<EnvMap>,
    prefilterer: Option<Arc<Prefilterer>>,
    samplers: Vec<(Filter, Arc<Sampler>)>,
    diffuse: Option<Arc<EnvMap>>,
    specular: Vec<(SpecularLobe, Arc<EnvMap>)>,
    builds: usize,
}

/// Derived data of an environment map (the filter crate's mip pyramid and samplers,
/// Greene's prefiltered maps), built on first use and shared by every render of the
/// environment and by its clones: an animation builds them once.
///
/// ```
/// use glam::{Mat4, Vec3};
/// use mirrorball_core::{EnvMap, ProjectionKind};
/// use mirrorball_render::{mesh, render, Camera, Environment, Indexing, Material, Object, Scene, Settings};
/// use std::sync::Arc;
/// let cube = ProjectionKind::Cube.default_projection();
/// let env = Environment::new(EnvMap::from_fn(cube, 16, 3, |d| [d.x as f32, 0.5, 0.5, 1.0]));
/// let cache = env.cache.clone();
/// let scene = Scene {
///     objects: vec![Object { mesh: Arc::new(mesh::sphere(16)), model: Mat4::IDENTITY, material: Material::mirror() }],
///     environment: Some(env),
///     background: false,
/// };
/// let settings = Settings { indexing: Indexing::Cone, ..Settings::default() };
/// assert_eq!(cache.builds(), 0);
/// for turn in 0..3 {
///     let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0, 16, 16)
///         .orbited(turn as f32 * 0.3);
///     render(&scene, &cam, &settings).unwrap();
///     assert_eq!(cache.builds(), 1, "mode 4's pyramid is built by the first frame only");
/// }
/// ```
#[derive(Clone, Default)]
pub struct EnvCache(Arc<Mutex<Inner>>);

impl std::fmt::Debug for EnvCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("EnvCache")
    }
}

impl EnvCache {
    /// How many pyramids and prefiltered maps have been built so far (for tests: a second
    /// frame must build nothing).
    pub fn builds(&self) -> usize {
        self.lock().builds
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The cache for `map`, emptied first if it was made from another map.
    fn for_map(&self, map: &Arc<EnvMap>) -> std::sync::MutexGuard<'_, Inner> {
        let mut g = self.lock();
        let same = g.key.upgrade().is_some_and(|k| Arc::ptr_eq(&k, map));
        if !same {
            let builds = g.builds;
            *g = Inner {
                key: Arc::downgrade(map),
                builds,
                ..Inner::default()
            };
        }
        g
    }

    /// The footprint sampler of `map` for `filter` (trilinear or EWA).
    pub(crate) fn sampler(&self, map: &Arc<EnvMap>, filter: Filter) -> Arc<Sampler> {
        let mut g = self.for_map(map);
        if let Some((_, s)) = g.samplers.iter().find(|(f, _)| *f == filter) {
            return s.clone();
        }
        let s = Arc::new(Sampler::new(map, filter));
        g.samplers.push((filter, s.clone()));
        g.builds += 1;
        s
    }

    /// Greene's diffuse and specular maps of `map` for `lobe`.
    pub(crate) fn greene(&self, map: &Arc<EnvMap>, lobe: SpecularLobe) -> GreeneMaps {
        let mut g = self.for_map(map);
        let pf = match &g.prefilterer {
            Some(p) => p.clone(),
            None => {
                // One working cube serves every lobe asked for later: it is made as fine as
                // the finest map this cache makes needs, a mirror at the largest extent.
                let (w, h) = extent_for(map, 0.0);
                let mirror = Lobe::Phong {
                    exponent: f64::INFINITY,
                };
                let p = Arc::new(Prefilterer::for_outputs(
                    map,
                    &[(mirror, *map.projection(), w, h)],
                    PrefilterOptions::default(),
                ));
                g.prefilterer = Some(p.clone());
                p
            }
        };
        let diffuse = match &g.diffuse {
            Some(d) => d.clone(),
            None => {
                let (w, h) = extent_for(map, Lobe::Lambert.angular_scale() / 8.0);
                let d = Arc::new(pf.render_extent(&Lobe::Lambert, *map.projection(), w, h));
                g.diffuse = Some(d.clone());
                g.builds += 1;
                d
            }
        };
        let specular = match g.specular.iter().find(|(l, _)| *l == lobe) {
            Some((_, s)) => s.clone(),
            None => {
                let l = lobe;
                let (w, h) = extent_for(map, l.angular_scale() / 4.0);
                let s = Arc::new(pf.render_extent(&l, *map.projection(), w, h));
                g.specular.push((lobe, s.clone()));
                g.builds += 1;
                s
            }
        };
        GreeneMaps { diffuse, specular }
    }
}

/// The layer extent, in `map`'s projection, whose texels are about `angle` radians across
/// (never finer than the map, at most 512 texels along a side, at least 8 on the shorter
/// side): a prefiltered map needs only resolve its lobe.
fn extent_for(map: &EnvMap, angle: f64) -> (u32, u32) {
    let (w, h) = (map.width() as f64, map.height() as f64);
    let texel = (4.0 * std::f64::consts::PI / (w * h * map.layers().len() as f64)).sqrt();
    let mut f = (angle / texel).max(1.0);
    f = f.max(w.max(h) / 512.0);
    f = f.min(w.min(h) / 8.0).max(1.0);
    (
        ((w / f).round() as u32).max(1),
        ((h / f).round() as u32).max(1),
    )
}

/// The filter a mode actually uses: mode 4 always filters its cone (EWA unless trilinear is
/// asked for); the other modes use the environment's filter.
pub(crate) fn effective(filter: Filter, mode: Indexing) -> Filter {
    match (mode, filter) {
        (Indexing::Cone, Filter::Trilinear) => Filter::Trilinear,
        (Indexing::Cone, _) => Filter::Ewa,
        (_, f) => f,
    }
}

/// A pixel's footprint from the unit directions through its four corners (pixel order
/// `(−,−) (+,−) (+,+) (−,+)`): the ray differentials `∂d/∂x`, `∂d/∂y` as the mean of the
/// two opposite edges (a point where a corner is degenerate).
pub(crate) fn footprint(c: &[DVec3; 4]) -> Footprint {
    if c.iter().any(|x| !x.is_finite() || x.length_squared() < 0.5) {
        return Footprint::Point;
    }
    let dx = ((c[1] - c[0]) + (c[2] - c[3])) * 0.5;
    let dy = ((c[3] - c[0]) + (c[2] - c[1])) * 0.5;
    Footprint::Differentials { dx, dy }
}
