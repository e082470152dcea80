//! Triangle meshes and the built-in objects: sphere, torus, cube, quad and the Utah teapot.
//!
//! Every built-in takes its tessellation as a parameter, because with per-vertex indexing
//! (fixed-function texture-coordinate generation) the tessellation *is* the sampling rate of
//! the environment: a coarse sphere shows the straight chords and bow ties of Zimmons'
//! figures, a fine one converges to per-pixel reflection.
//!
//! Built-ins are centred on the origin, about unit size (radius 1 for the sphere, a 2×2 quad
//! in the `z = 0` plane facing +Z, a cube of edge 2), with outward unit normals.

use glam::{Mat3, Mat4, Vec2, Vec3};

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
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Checks that every index is in range and every array has one entry per vertex.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.positions.len();
        if self.normals.len() != n {
            return Err(format!("{} normals for {n} vertices", self.normals.len()));
        }
        if !self.uvs.is_empty() && self.uvs.len() != n {
            return Err(format!("{} uvs for {n} vertices", self.uvs.len()));
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
    /// without normals).
    pub fn compute_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.triangles {
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
/// least 3 and 2). Its texture coordinates are longitude and latitude.
pub fn sphere(segments: u32) -> Mesh {
    let nu = segments.max(3);
    let nv = (segments / 2).max(2);
    let mut m = Mesh::default();
    for j in 0..=nv {
        let v = j as f32 / nv as f32;
        let phi = std::f32::consts::PI * v; // from +Y down
        for i in 0..=nu {
            let u = i as f32 / nu as f32;
            let lam = std::f32::consts::TAU * u;
            let p = Vec3::new(phi.sin() * lam.sin(), phi.cos(), phi.sin() * lam.cos());
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
/// around the ring and `segments / 2` around the tube.
pub fn torus(major: f32, minor: f32, segments: u32) -> Mesh {
    let nu = segments.max(3);
    let nv = (segments / 2).max(3);
    let mut m = Mesh::default();
    for j in 0..=nv {
        let v = j as f32 / nv as f32;
        let b = std::f32::consts::TAU * v;
        for i in 0..=nu {
            let u = i as f32 / nu as f32;
            let a = std::f32::consts::TAU * u;
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
/// its own (flat) normals.
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
    /// [`crate::teapot::teapot`].
    Teapot,
}

impl Builtin {
    /// Every built-in.
    pub const ALL: [Builtin; 5] = [
        Builtin::Sphere,
        Builtin::Torus,
        Builtin::Cube,
        Builtin::Quad,
        Builtin::Teapot,
    ];

    /// Parses `sphere`, `torus`, `cube`, `quad` (or `plane`, `door`), `teapot`.
    pub fn from_name(s: &str) -> Option<Builtin> {
        Some(match s.to_ascii_lowercase().as_str() {
            "sphere" | "ball" => Builtin::Sphere,
            "torus" | "donut" => Builtin::Torus,
            "cube" | "box" => Builtin::Cube,
            "quad" | "plane" | "door" => Builtin::Quad,
            "teapot" | "utah" => Builtin::Teapot,
            _ => return None,
        })
    }

    /// The name `from_name` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Builtin::Sphere => "sphere",
            Builtin::Torus => "torus",
            Builtin::Cube => "cube",
            Builtin::Quad => "quad",
            Builtin::Teapot => "teapot",
        }
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

    /// The mesh at tessellation `level`.
    pub fn mesh(self, level: u32) -> Mesh {
        match self {
            Builtin::Sphere => sphere(level),
            Builtin::Torus => torus(0.7, 0.3, level),
            Builtin::Cube => cube(level),
            Builtin::Quad => quad(level),
            Builtin::Teapot => crate::teapot::teapot(level),
        }
    }
}
