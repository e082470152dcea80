//! Triangle meshes and the built-in objects: sphere, torus, cube, quad and the Utah teapot.
//!
//! Every built-in takes its tessellation as a parameter, because with per-vertex indexing
//! (fixed-function texture-coordinate generation) the tessellation *is* the sampling rate of
//! the environment: a coarse sphere shows the straight chords and bow ties of Zimmons'
//! figures, a fine one converges to per-pixel reflection.
//!
//! Built-ins are centred on the origin, about unit size (radius 1 for the sphere, a 2×2 quad
//! in the `z = 0` plane facing +Z, a cube of edge 2), with outward unit normals.
//!
//! ```
//! use mirrorball_render::{mesh, Builtin};
//! let sphere = mesh::sphere(32);
//! assert!(sphere.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
//! assert!(sphere.is_closed_outward());
//! // Each built-in by name, at a tessellation: what the CLI's `--object sphere` makes.
//! let named: Builtin = "sphere".parse().unwrap();
//! assert_eq!(named.mesh(32).triangles, sphere.triangles);
//! // The teapot's 32 patches, each (level + 1)² vertices.
//! assert_eq!(mesh::teapot(4).positions.len(), 32 * 25);
//! ```

use glam::{Mat3, Mat4, Vec2, Vec3};
use mirrorball_core::Choice;

pub use crate::teapot::teapot;

/// An indexed triangle mesh with per-vertex unit normals (and optional texture coordinates).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per vertex, or empty.
    pub uvs: Vec<Vec2>,
    /// Triangles, counter-clockwise seen from the side the normals point to.
    pub triangles: Vec<[u32; 3]>,
    /// [`Mesh::is_closed_outward`], remembered with a fingerprint of the mesh it was
    /// worked out for (the fields are public, so the mesh may have changed since).
    pub(crate) solid: SolidCache,
}

/// The last answer of [`Mesh::is_closed_outward`] and the fingerprint of the positions and
/// triangles it answered for.
#[derive(Default)]
pub(crate) struct SolidCache(std::sync::Mutex<Option<(u64, bool)>>);

impl SolidCache {
    fn get(&self) -> Option<(u64, bool)> {
        *self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
    fn set(&self, v: (u64, bool)) {
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = Some(v);
    }
}

impl Clone for SolidCache {
    fn clone(&self) -> Self {
        SolidCache(std::sync::Mutex::new(self.get()))
    }
}

impl std::fmt::Debug for SolidCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SolidCache")
    }
}

/// A cache is no part of what a mesh is.
impl PartialEq for SolidCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Mesh {
    /// A mesh of these vertices (positions, unit normals, texture coordinates or none) and
    /// triangles, counter-clockwise seen from the side the normals point to.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
        triangles: Vec<[u32; 3]>,
    ) -> Mesh {
        Mesh {
            positions,
            normals,
            uvs,
            triangles,
            solid: SolidCache::default(),
        }
    }

    /// Whether the mesh is the boundary of solids, facing out: every directed edge `a → b`
    /// of a triangle is matched by exactly one `b → a` of another (closed, consistently
    /// oriented, two triangles at every edge) and every connected piece encloses a positive
    /// signed volume `Σ p₀·(p₁ × p₂)/6` (its counter-clockwise sides face out).
    ///
    /// Seen from outside such a solid, a ray enters it before it can leave it, so the first
    /// triangle it meets faces the viewer: back faces are hidden, and the renderer skips
    /// them (exactly, for a solid whose inside has a winding number ≥ 0 everywhere, which
    /// a surface that does not pass through itself inside out always has). The answer is
    /// remembered until the positions or triangles change.
    ///
    /// ```
    /// use mirrorball_render::mesh;
    /// assert!(mesh::sphere(16).is_closed_outward());
    /// assert!(!mesh::quad(2).is_closed_outward()); // an open sheet
    /// ```
    pub fn is_closed_outward(&self) -> bool {
        let key = self.fingerprint();
        if let Some((k, v)) = self.solid.get() {
            if k == key {
                return v;
            }
        }
        let v = self.work_out_closed_outward();
        self.solid.set((key, v));
        v
    }

    /// A hash of the positions and triangles (what [`Mesh::is_closed_outward`] depends on).
    fn fingerprint(&self) -> u64 {
        // FxHash-style: rotate, xor, multiply; a word at a time.
        const K: u64 = 0x517c_c1b7_2722_0a95;
        let mix = |h: u64, w: u64| (h.rotate_left(5) ^ w).wrapping_mul(K);
        let mut h = mix(self.positions.len() as u64, self.triangles.len() as u64);
        for p in &self.positions {
            h = mix(h, (p.x.to_bits() as u64) << 32 | p.y.to_bits() as u64);
            h = mix(h, p.z.to_bits() as u64);
        }
        for t in &self.triangles {
            h = mix(h, (t[0] as u64) << 32 | t[1] as u64);
            h = mix(h, t[2] as u64);
        }
        h
    }

    fn work_out_closed_outward(&self) -> bool {
        let n = self.positions.len();
        if self
            .triangles
            .iter()
            .any(|t| t.iter().any(|&i| i as usize >= n))
        {
            return false;
        }
        // Vertices at the same point are one (a sphere's seam and poles, an OBJ's vertices
        // split by normal or texture coordinate); `+ 0.0` makes −0 and +0 the same key.
        let mut first = std::collections::HashMap::with_capacity(n);
        let weld: Vec<u32> = self
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
                *first.entry(key).or_insert(i as u32)
            })
            .collect();
        // Triangles with two corners at one point cover nothing (and their edges pair up
        // among themselves): left out.
        let tris: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|i| weld[i as usize]))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .collect();
        if tris.is_empty() {
            return false;
        }
        // Every directed edge once, and its reverse once.
        let mut edges: Vec<u64> = tris
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| (a as u64) << 32 | b as u64)
            .collect();
        edges.sort_unstable();
        if edges.windows(2).any(|w| w[0] == w[1]) {
            return false;
        }
        if !edges
            .iter()
            .all(|&e| edges.binary_search(&e.rotate_right(32)).is_ok())
        {
            return false;
        }
        // Connected pieces (union-find over the triangles' vertices), each with its signed
        // volume.
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
        for t in &tris {
            let r0 = root(&mut parent, t[0]);
            for &i in &t[1..] {
                let r = root(&mut parent, i);
                parent[r as usize] = r0;
            }
        }
        // Per piece (indexed by its root): signed volume ×6, and whether it has triangles.
        let mut volume = vec![(0.0f64, false); n];
        for t in &tris {
            let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
            let v = &mut volume[root(&mut parent, t[0]) as usize];
            *v = (v.0 + a.dot(b.cross(c)), true);
        }
        volume.iter().all(|&(v, has)| !has || v > 0.0)
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Checks that every index is in range and every array has one entry per vertex; a
    /// mesh that fails is the input's fault (its data).
    pub fn validate(&self) -> Result<(), crate::RenderError> {
        self.problem().map_err(crate::RenderError::input)
    }

    fn problem(&self) -> Result<(), String> {
        let n = self.positions.len();
        if self.normals.len() != n {
            return Err(format!("{} normals for {n} vertices", self.normals.len()));
        }
        if !self.uvs.is_empty() && self.uvs.len() != n {
            return Err(format!("{} uvs for {n} vertices", self.uvs.len()));
        }
        if let Some((i, p)) = self
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            return Err(format!(
                "vertex {i} ({}, {}, {}) is not finite",
                p.x, p.y, p.z
            ));
        }
        if let Some((i, p)) = self.uvs.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(format!(
                "the texture coordinates ({}, {}) of vertex {i} are not finite",
                p.x, p.y
            ));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(format!("triangle {t:?} indexes past {n} vertices"));
        }
        Ok(())
    }

    /// Replaces the normals by area-weighted averages of the face normals (for meshes read
    /// without normals). Triangles that index past the vertices are skipped (a loader
    /// calls this before [`Mesh::validate`], which reports them).
    pub fn compute_normals(&mut self) {
        let n = self.positions.len();
        let mut acc = vec![Vec3::ZERO; n];
        for t in self
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&i| (i as usize) < n))
        {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                acc[i as usize] += n;
            }
        }
        self.normals = acc
            .into_iter()
            .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
            .collect();
    }

    /// The mesh transformed by `m` (normals by the inverse transpose, renormalised).
    pub fn transformed(&self, m: Mat4) -> Mesh {
        let nm = Mat3::from_mat4(m).inverse().transpose();
        Mesh {
            positions: self
                .positions
                .iter()
                .map(|&p| m.transform_point3(p))
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|&n| (nm * n).try_normalize().unwrap_or(n))
                .collect(),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
            solid: SolidCache::default(),
        }
    }

    /// Appends `other` (indices shifted).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let had_uvs = !self.uvs.is_empty() || self.positions.is_empty();
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        if had_uvs && !other.uvs.is_empty() {
            self.uvs.extend_from_slice(&other.uvs);
        } else {
            self.uvs.clear();
        }
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// Axis-aligned bounds `(min, max)`, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// The transform that centres the mesh's bounds on the origin and scales its largest
    /// half-extent to 1 (so any file can be framed like the built-ins).
    pub fn normalizing_transform(&self) -> Mat4 {
        match self.bounds() {
            Some((lo, hi)) => {
                let c = (lo + hi) * 0.5;
                let r = ((hi - lo) * 0.5).max_element().max(1e-12);
                Mat4::from_scale(Vec3::splat(1.0 / r)) * Mat4::from_translation(-c)
            }
            None => Mat4::IDENTITY,
        }
    }
}

/// A UV sphere of radius 1: `segments` around (longitude) and `segments / 2` rings (at
/// least 3 and 2). Its texture coordinates are longitude and latitude. The seam's two
/// columns of vertices, and each pole's, sit at exactly the same points, so the mesh is
/// closed ([`Mesh::is_closed_outward`]).
pub fn sphere(segments: u32) -> Mesh {
    let nu = segments.max(3);
    let nv = (segments / 2).max(2);
    let mut m = Mesh::default();
    for j in 0..=nv {
        let v = j as f32 / nv as f32;
        let phi = std::f32::consts::PI * v; // from +Y down
        let (sp, cp) = match j {
            0 => (0.0, 1.0),
            _ if j == nv => (0.0, -1.0),
            _ => phi.sin_cos(),
        };
        for i in 0..=nu {
            let u = i as f32 / nu as f32;
            let lam = std::f32::consts::TAU * (i % nu) as f32 / nu as f32;
            let p = Vec3::new(sp * lam.sin(), cp, sp * lam.cos());
            m.positions.push(p);
            m.normals.push(p);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = nu + 1;
    for j in 0..nv {
        for i in 0..nu {
            let a = j * row + i;
            let b = a + row;
            if j != 0 {
                m.triangles.push([a, b, a + 1]);
            }
            if j != nv - 1 {
                m.triangles.push([a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// A torus about the Y axis with ring radius `major` and tube radius `minor`, `segments`
/// around the ring and `segments / 2` around the tube. Its seams' vertices coincide
/// exactly, so the mesh is closed ([`Mesh::is_closed_outward`]).
pub fn torus(major: f32, minor: f32, segments: u32) -> Mesh {
    let nu = segments.max(3);
    let nv = (segments / 2).max(3);
    let mut m = Mesh::default();
    for j in 0..=nv {
        let v = j as f32 / nv as f32;
        let b = std::f32::consts::TAU * (j % nv) as f32 / nv as f32;
        for i in 0..=nu {
            let u = i as f32 / nu as f32;
            let a = std::f32::consts::TAU * (i % nu) as f32 / nu as f32;
            let ring = Vec3::new(a.sin(), 0.0, a.cos());
            let n = ring * b.cos() + Vec3::Y * b.sin();
            m.positions.push(ring * major + n * minor);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = nu + 1;
    for j in 0..nv {
        for i in 0..nu {
            let a = j * row + i;
            let b = a + row;
            m.triangles.push([a, a + 1, b]);
            m.triangles.push([a + 1, b + 1, b]);
        }
    }
    m
}

/// A `2×2` square in the `z = 0` plane facing +Z, split into `segments × segments` cells
/// (two triangles each). Texture coordinates run `(0, 0)` top left to `(1, 1)`.
pub fn quad(segments: u32) -> Mesh {
    let n = segments.max(1);
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let u = i as f32 / n as f32;
            let v = j as f32 / n as f32;
            m.positions
                .push(Vec3::new(2.0 * u - 1.0, 1.0 - 2.0 * v, 0.0));
            m.normals.push(Vec3::Z);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = n + 1;
    for j in 0..n {
        for i in 0..n {
            let a = j * row + i;
            let b = a + row;
            m.triangles.push([a, b, a + 1]);
            m.triangles.push([a + 1, b, b + 1]);
        }
    }
    m
}

/// A cube of edge 2 centred on the origin, each face a [`quad`] of `segments²` cells with
/// its own (flat) normals. Vertices of neighbouring faces along an edge sit at exactly the
/// same points, so the mesh is closed ([`Mesh::is_closed_outward`]).
pub fn cube(segments: u32) -> Mesh {
    let face = quad(segments).transformed(Mat4::from_translation(Vec3::Z));
    let rots = [
        Mat4::IDENTITY,
        Mat4::from_rotation_y(std::f32::consts::PI),
        Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Mat4::from_rotation_y(-std::f32::consts::FRAC_PI_2),
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2),
    ];
    let mut m = Mesh::default();
    for r in rots {
        m.append(&face.transformed(r));
    }
    // The rotations leave rounding (cos 90° is not 0 in f32): back onto the grid of
    // coordinates −1 + 2k/segments.
    let n = segments.max(1) as f32;
    for p in &mut m.positions {
        *p = ((*p + 1.0) * (n / 2.0)).round() * (2.0 / n) - 1.0;
    }
    m
}

/// The built-in objects by name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Builtin {
    /// [`sphere`].
    Sphere,
    /// [`torus`] with radii 0.7 and 0.3.
    Torus,
    /// [`cube`].
    Cube,
    /// [`quad`].
    Quad,
    /// [`teapot`].
    Teapot,
}

/// The most triangles a built-in may be tessellated into: 2²⁴, which the sphere and the
/// torus stay within up to their largest tessellation (4096). The teapot at 4096 would be
/// 2³⁰ triangles and the cube 2·10⁸, more than the renderer's per-triangle buffers fit in
/// memory.
pub const MAX_TRIANGLES: u64 = 1 << 24;

impl Choice for Builtin {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Builtin::Sphere, &["sphere", "ball"]),
        (Builtin::Torus, &["torus", "donut"]),
        (Builtin::Cube, &["cube", "box"]),
        (Builtin::Quad, &["quad", "plane", "door"]),
        (Builtin::Teapot, &["teapot", "utah"]),
    ];
}
mirrorball_core::choice_traits!(Builtin);

impl Builtin {
    /// Every built-in.
    pub const ALL: [Builtin; 5] = [
        Builtin::Sphere,
        Builtin::Torus,
        Builtin::Cube,
        Builtin::Quad,
        Builtin::Teapot,
    ];

    /// The canonical name (see [`Choice`]).
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }

    /// A sensible default tessellation: sphere and torus segments, quad and cube cells per
    /// edge, teapot subdivisions per patch edge.
    pub fn default_tessellation(self) -> u32 {
        match self {
            Builtin::Sphere => 64,
            Builtin::Torus => 64,
            Builtin::Cube | Builtin::Quad => 1,
            Builtin::Teapot => 8,
        }
    }

    /// How many triangles [`Builtin::mesh`] makes at tessellation `level`, worked out
    /// without building it: exact for the sphere, torus, cube and quad; for the teapot an
    /// upper bound (patch edges that collapse to a point lose a few).
    pub fn triangle_count(self, level: u32) -> u64 {
        let l = level as u64;
        // Saturating: `max_tessellation` asks about levels up to 2³¹.
        let sq = |a: u64, b: u64, k: u64| k.saturating_mul(a).saturating_mul(b);
        match self {
            Builtin::Sphere => {
                let (nu, nv) = (l.max(3), (l / 2).max(2));
                // Each of the nv rings of nu cells has two triangles, but the polar rings one.
                sq(nu, nv, 2) - 2 * nu
            }
            Builtin::Torus => sq(l.max(3), (l / 2).max(3), 2),
            Builtin::Cube => sq(l.max(1), l.max(1), 12),
            Builtin::Quad => sq(l.max(1), l.max(1), 2),
            Builtin::Teapot => sq(l.max(1), l.max(1), 64),
        }
    }

    /// The largest tessellation whose [`Builtin::triangle_count`] is at most `max`
    /// (at least 1).
    pub fn max_tessellation(self, max: u64) -> u32 {
        // triangle_count grows with the level: bisect for the last level within `max`.
        let (mut lo, mut hi) = (1u32, u32::MAX / 2);
        while lo < hi {
            let mid = lo + (hi - lo).div_ceil(2);
            if self.triangle_count(mid) <= max {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        lo
    }

    /// The mesh at tessellation `level`.
    pub fn mesh(self, level: u32) -> Mesh {
        match self {
            Builtin::Sphere => sphere(level),
            Builtin::Torus => torus(0.7, 0.3, level),
            Builtin::Cube => cube(level),
            Builtin::Quad => quad(level),
            Builtin::Teapot => teapot(level),
        }
    }
}
