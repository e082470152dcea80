//! The equi-angular cube as a Spherical Video V2 mesh projection (`mshp`), the way YouTube
//! marks its EAC streams: the specification has no box for an equi-angular cube.
//!
//! **The mesh.** Each of the six cells of v360's `eac` picture of any size (core's
//! [`CubeCells::EAC`], [`CubeCells::eac_point`]: its two-pixel borders included in the
//! picture size, faces not square in general) is a grid of `K`×`K` quads. A vertex
//! at cell coordinates `(c, d)` ∈ `[−1, 1]²` (right, down) shows the face coordinates
//! [`CubeCells::face_coords`] gives; its position is the point on the unit cube
//! `face.point(tan(π/4·s), tan(π/4·t))` in mirrorball's world axes, which are the
//! specification's (right-handed, −Z forward, +Y up), and its texture coordinates are
//! where it lies in one eye's picture, `(x/W, 1 − y/H)` (origin at the lower left). Between
//! vertices a player interpolates the texture coordinates linearly over the flat triangle
//! in the face's plane, where EAC's are `atan` of the position: with `K = 32` the picture
//! position is off by at most 0.037% of a face's width (0.4 pixel on a 1024-pixel face;
//! tested).
//!
//! **The encoding** (RFC, "Mesh Projection Box"): `crc` (CRC-32 of everything after it),
//! `encoding` `raw `, one `mesh` box: the distinct coordinates as `f32`, each vertex's five
//! coordinate indices as zig-zag deltas in `ceil(log2(2·count))` bits, then one vertex list:
//! a single triangle strip (texture 0, type 1) of every row of quads, rows joined by two
//! repeated indices (degenerate triangles; each row has an even count, so every row keeps
//! the strip's winding). One list, because players differ on whether a list's bits are
//! padded to a byte before the next (ExoPlayer's `ProjectionDecoder` reads on without
//! padding); after the only list the padding is the box's end either way. Triangles wind
//! counter-clockwise seen from outside the sphere, as the VR180 reference mesh generator
//! (`docs/vr180.md`) makes them.

use crate::Error;
use mirrorball_core::{CubeCells, Eac};

/// Quads along each face edge.
pub const K: u32 = 32;

/// CRC-32 (ISO 3309 / ITU-T V.42, the reflected polynomial 0xEDB88320), as zlib, PNG and
/// the mesh box compute it.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A mesh: vertices `[x, y, z, u, v]` and one triangle strip of indices into them.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Position and texture coordinates of each vertex.
    pub vertices: Vec<[f32; 5]>,
    /// The strip.
    pub strip: Vec<u32>,
}

/// The EAC mesh for one eye of `w`×`h` pixels in v360's `eac` layout.
pub fn eac_mesh(w: u32, h: u32) -> Result<Mesh, Error> {
    let cells = CubeCells::EAC;
    if CubeCells::eac_frame(w, h).is_none() {
        return Err(Error::unfit(format!(
            "an EAC picture of {w}×{h} is too small to hold its six faces and their borders"
        )));
    }
    let (wf, hf, kf) = (f64::from(w), f64::from(h), f64::from(K));
    let side = K + 1;
    let mut vertices = Vec::with_capacity(6 * (side * side) as usize);
    let mut strip = Vec::new();
    for cell in 0..6 {
        let face = cells.faces[cell];
        let first = vertices.len() as u32;
        for gy in 0..side {
            for gx in 0..side {
                let (c, d) = (
                    2.0 * f64::from(gx) / kf - 1.0,
                    2.0 * f64::from(gy) / kf - 1.0,
                );
                let (s, t) = cells.face_coords(cell, c, d);
                let p = face.point(Eac::unwarp(s), Eac::unwarp(t));
                let (x, y) = cells.eac_point((w, h), cell, c, d);
                vertices.push([
                    p.x as f32,
                    p.y as f32,
                    p.z as f32,
                    (x / wf) as f32,
                    (1.0 - y / hf) as f32,
                ]);
            }
        }
        for gy in 0..K {
            if !strip.is_empty() {
                // Two degenerate triangles join this row to the last.
                strip.push(*strip.last().expect("not empty"));
                strip.push(first + (gy + 1) * side);
            }
            for gx in 0..side {
                // Lower row first: the strip's first triangle (lower-left, upper-left,
                // lower-right) is clockwise in the picture, counter-clockwise from outside.
                strip.push(first + (gy + 1) * side + gx);
                strip.push(first + gy * side + gx);
            }
        }
    }
    Ok(Mesh { vertices, strip })
}

/// Bits written most significant first.
struct Bits {
    out: Vec<u8>,
    acc: u64,
    n: u32,
}

impl Bits {
    fn new(out: Vec<u8>) -> Bits {
        Bits { out, acc: 0, n: 0 }
    }
    fn put(&mut self, value: u32, bits: u32) {
        self.acc = (self.acc << bits) | u64::from(value);
        self.n += bits;
        while self.n >= 8 {
            self.n -= 8;
            self.out.push((self.acc >> self.n) as u8);
        }
        self.acc &= (1 << self.n) - 1;
    }
    /// Pads with zero bits to a byte boundary.
    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            let pad = 8 - self.n;
            self.put(0, pad);
        }
        self.out
    }
}

/// Zig-zag: 0, −1, 1, −2, … as 0, 1, 2, 3, ….
fn zigzag(d: i64) -> u32 {
    (if d >= 0 { 2 * d } else { -2 * d - 1 }) as u32
}

/// `ceil(log2(2·count))`: the bits of an index delta among `count` things.
fn index_bits(count: usize) -> u32 {
    usize::BITS - (2 * count - 1).leading_zeros()
}

/// The `mesh` box of `m`.
pub fn mesh_box(m: &Mesh) -> Vec<u8> {
    let mut coords: Vec<f32> = m.vertices.iter().flatten().copied().collect();
    coords.sort_by(f32::total_cmp);
    coords.dedup_by(|a, b| a.to_bits() == b.to_bits());
    let index_of = |v: f32| {
        coords
            .binary_search_by(|c| c.total_cmp(&v))
            .expect("listed") as i64
    };
    let mut body = (coords.len() as u32).to_be_bytes().to_vec();
    for c in &coords {
        body.extend_from_slice(&c.to_be_bytes());
    }
    body.extend_from_slice(&(m.vertices.len() as u32).to_be_bytes());
    let ccsb = index_bits(coords.len());
    let mut bits = Bits::new(body);
    let mut last = [0i64; 5];
    for v in &m.vertices {
        for (k, &c) in v.iter().enumerate() {
            let i = index_of(c);
            bits.put(zigzag(i - last[k]), ccsb);
            last[k] = i;
        }
    }
    let mut body = bits.finish();
    body.extend_from_slice(&1u32.to_be_bytes()); // one vertex list
    body.extend_from_slice(&[0, 1]); // texture 0 (the video), a triangle strip
    body.extend_from_slice(&(m.strip.len() as u32).to_be_bytes());
    let vcsb = index_bits(m.vertices.len());
    let mut bits = Bits::new(body);
    let mut last = 0i64;
    for &i in &m.strip {
        bits.put(zigzag(i64::from(i) - last), vcsb);
        last = i64::from(i);
    }
    let body = bits.finish();
    let mut out = ((body.len() + 8) as u32).to_be_bytes().to_vec();
    out.extend_from_slice(b"mesh");
    out.extend_from_slice(&body);
    out
}

/// The `mshp` payload after its version and flags (`crc`, `raw `, the mesh) for the EAC
/// picture of one eye of `w`×`h` pixels.
pub fn eac_mshp(w: u32, h: u32) -> Result<Vec<u8>, Error> {
    let mut rest = b"raw ".to_vec();
    rest.extend_from_slice(&mesh_box(&eac_mesh(w, h)?));
    let mut out = crc32(&rest).to_be_bytes().to_vec();
    out.extend_from_slice(&rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::glam::DVec3;
    use mirrorball_core::{EnvMap, Layout, ProjectionKind};

    /// Reads bits most significant first.
    struct Reader<'a> {
        b: &'a [u8],
        at: usize,
    }
    impl Reader<'_> {
        fn get(&mut self, bits: u32) -> u32 {
            let mut v = 0;
            for _ in 0..bits {
                let bit = (self.b[self.at / 8] >> (7 - self.at % 8)) & 1;
                v = (v << 1) | u32::from(bit);
                self.at += 1;
            }
            v
        }
        fn align(&mut self) {
            self.at = self.at.div_ceil(8) * 8;
        }
    }

    fn unzigzag(v: u32) -> i64 {
        let v = i64::from(v);
        if v & 1 == 0 {
            v / 2
        } else {
            -(v + 1) / 2
        }
    }

    /// An independent reading of the payload, as ExoPlayer's `ProjectionDecoder` reads
    /// it (one list, indices reset to 0 per list).
    fn decode(mshp: &[u8]) -> Mesh {
        let crc = u32::from_be_bytes(mshp[..4].try_into().unwrap());
        assert_eq!(crc, crc32(&mshp[4..]));
        assert_eq!(&mshp[4..8], b"raw ");
        let mesh = &mshp[8..];
        let size = u32::from_be_bytes(mesh[..4].try_into().unwrap()) as usize;
        assert_eq!((size, &mesh[4..8]), (mesh.len(), &b"mesh"[..]));
        let mut r = Reader {
            b: &mesh[8..],
            at: 0,
        };
        let count = r.get(32) as usize;
        let coords: Vec<f32> = (0..count).map(|_| f32::from_bits(r.get(32))).collect();
        let nv = r.get(32) as usize;
        let ccsb = (2.0 * count as f64).log2().ceil() as u32;
        let mut last = [0i64; 5];
        let mut vertices = Vec::new();
        for _ in 0..nv {
            let mut v = [0f32; 5];
            for k in 0..5 {
                last[k] += unzigzag(r.get(ccsb));
                v[k] = coords[last[k] as usize];
            }
            vertices.push(v);
        }
        r.align();
        assert_eq!(r.get(32), 1);
        assert_eq!((r.get(8), r.get(8)), (0, 1));
        let ni = r.get(32) as usize;
        let vcsb = (2.0 * nv as f64).log2().ceil() as u32;
        let mut i = 0i64;
        let strip = (0..ni)
            .map(|_| {
                i += unzigzag(r.get(vcsb));
                i as u32
            })
            .collect();
        r.align();
        assert_eq!(r.at / 8, mesh.len() - 8, "no bytes left over");
        Mesh { vertices, strip }
    }

    #[test]
    fn crc_matches_the_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn the_mesh_decodes_to_what_was_made() {
        let (w, h) = (3 * 64 + 4, 2 * 64 + 8);
        let m = eac_mesh(w, h).unwrap();
        assert_eq!(decode(&eac_mshp(w, h).unwrap()), m);
        assert_eq!(m.vertices.len(), 6 * 33 * 33);
        assert!(eac_mesh(6, 9).is_err());
        // v360's EAC at a size of its own (YouTube's 3840x2160 scaled by a fifth): the
        // cells' corners where v360 puts them, faces 254⅔ by 212 pixels.
        let m = eac_mesh(768, 432).unwrap();
        let xs: Vec<f32> = m.vertices.iter().map(|v| v[3] * 768.0).collect();
        let ys: Vec<f32> = m.vertices.iter().map(|v| (1.0 - v[4]) * 432.0).collect();
        let lo = |v: &[f32]| v.iter().cloned().fold(f32::MAX, f32::min);
        let hi = |v: &[f32]| v.iter().cloned().fold(f32::MIN, f32::max);
        assert!((lo(&xs) - 2.0).abs() < 1e-3 && (hi(&xs) - 766.0).abs() < 1e-3);
        assert!((lo(&ys) - 2.0).abs() < 1e-3 && (hi(&ys) - 430.0).abs() < 1e-3);
        assert!(xs.iter().any(|&x| (x - (2.0 + 764.0 / 3.0)).abs() < 1e-3));
        // The rows' faces end at 2 + 212 and start again at 216 + 2.
        for edge in [214.0, 218.0] {
            assert!(ys.iter().any(|&y| (y - edge).abs() < 1e-3), "{edge}");
        }
        assert!(!ys.iter().any(|&y| y > 214.5 && y < 217.5));
    }

    /// Each triangle of the strip with its winding undone (odd ones are flipped), the
    /// degenerate joins left out.
    fn triangles(m: &Mesh) -> Vec<[DVec3; 3]> {
        let p = |i: u32| {
            let v = m.vertices[i as usize];
            DVec3::new(v[0].into(), v[1].into(), v[2].into())
        };
        m.strip
            .windows(3)
            .enumerate()
            .filter(|(_, t)| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .map(|(j, t)| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                if j % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect()
    }

    #[test]
    fn triangles_cover_the_sphere_once_wound_outwards() {
        let m = eac_mesh(3 * 32 + 4, 2 * 32 + 8).unwrap();
        let tris = triangles(&m);
        assert_eq!(tris.len(), (6 * K * K * 2) as usize);
        let mut solid = 0.0;
        for [a, b, c] in &tris {
            let normal = (*b - *a).cross(*c - *a);
            let centre = (*a + *b + *c) / 3.0;
            assert!(normal.dot(centre) > 0.0, "counter-clockwise from outside");
            // Van Oosterom and Strackee's solid angle of the triangle seen from the centre.
            let (a, b, c) = (a.normalize(), b.normalize(), c.normalize());
            let num = a.dot(b.cross(c));
            let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
            solid += 2.0 * num.atan2(den);
        }
        assert!((solid - 4.0 * std::f64::consts::PI).abs() < 1e-4, "{solid}");
    }

    #[test]
    fn vertices_show_what_the_eac_picture_shows_there() {
        // Faces of n = 2K pixels: every vertex lies on a pixel corner. The picture is core's
        // `eac` layout of a map whose texels hold their own directions; a vertex's
        // direction must be that of the texels of its cell around its texture coordinates.
        let n = 2 * K;
        let env = EnvMap::from_fn(ProjectionKind::Eac.default_projection(), n, 3, |d| {
            [d.x as f32, d.y as f32, d.z as f32, 1.0]
        });
        let pic = Layout::Cells(CubeCells::EAC).pack(&env).unwrap();
        let (w, h) = (pic.width(), pic.height());
        let m = eac_mesh(w, h).unwrap();
        let texel = std::f64::consts::FRAC_PI_2 / f64::from(n);
        for (i, v) in m.vertices.iter().enumerate() {
            let cell = i / (33 * 33);
            let (ox, oy) = CubeCells::EAC.origin(cell, n);
            let x = (f64::from(v[3]) * f64::from(w)).round() as i64;
            let y = ((1.0 - f64::from(v[4])) * f64::from(h)).round() as i64;
            let mut sum = DVec3::ZERO;
            for (tx, ty) in [(x - 1, y - 1), (x, y - 1), (x - 1, y), (x, y)] {
                let inside = |t: i64, o: u32| t >= i64::from(o) && t < i64::from(o + n);
                if inside(tx, ox) && inside(ty, oy) {
                    let t = pic.get(tx as u32, ty as u32);
                    sum += DVec3::new(t[0].into(), t[1].into(), t[2].into());
                }
            }
            let want = DVec3::new(v[0].into(), v[1].into(), v[2].into()).normalize();
            let angle = sum.normalize().dot(want).clamp(-1.0, 1.0).acos();
            assert!(
                angle < 0.75 * texel,
                "vertex {i}: {} texels off",
                angle / texel
            );
        }
    }

    #[test]
    fn between_vertices_the_picture_is_off_by_under_four_ten_thousandths_of_a_face() {
        // Along a face's mid-line, where EAC's warp bends most: the picture position a
        // player interpolates linearly between two vertices, against the exact one.
        let mut worst = 0.0f64;
        for q in 0..K {
            let (p0, p1) = (
                2.0 * f64::from(q) / f64::from(K) - 1.0,
                2.0 * f64::from(q + 1) / f64::from(K) - 1.0,
            );
            let (a0, a1) = (Eac::unwarp(p0), Eac::unwarp(p1));
            for k in 1..16 {
                let f = f64::from(k) / 16.0;
                let a = a0 + f * (a1 - a0); // the point the flat triangle shows
                let linear = p0 + f * (p1 - p0); // where the player samples it
                worst = worst.max((Eac::warp(a) - linear).abs() / 2.0);
            }
        }
        assert!(worst < 3.7e-4, "{worst} of a face");
    }
}
