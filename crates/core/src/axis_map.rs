//! Signed axis permutations: the mirrors and quarter turns that carry the cube onto itself
//! (its 48 symmetries), the conventions engines differ by (three.js samples at (−x, y, z),
//! Bevy at (x, y, −z), Unreal's Z-up world is a permutation of ours). Applied to a cube
//! map, such a map moves texels and changes none: [`EnvMap::transformed`] is exact, where
//! [`crate::resample`] with the same [`Rotation`] would filter.

use crate::projection::{CubeFace, ProjectionKind};
use crate::{Axis, EnvMap, Image, Rotation};
use glam::{DMat3, DVec3};
use std::fmt;

/// A signed permutation of the axes, read as [`Rotation::source_of`] is: the output shows,
/// in direction `d`, what the source shows in direction `source_of(d)`, whose component `i`
/// is `sign[i] · d[axis[i]]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AxisMap {
    axis: [u8; 3],
    sign: [i8; 3],
}

impl Default for AxisMap {
    fn default() -> Self {
        AxisMap::IDENTITY
    }
}

impl AxisMap {
    /// Every direction shows what it showed.
    pub const IDENTITY: AxisMap = AxisMap {
        axis: [0, 1, 2],
        sign: [1, 1, 1],
    };

    /// `source_of(d) = (s₀·d[a₀], s₁·d[a₁], s₂·d[a₂])` for `rows = [(a₀, s₀), …]`; `None`
    /// unless the axes are a permutation and every sign is ±1.
    ///
    /// ```
    /// use mirrorball_core::{AxisMap, Axis};
    /// use glam::DVec3;
    /// // Unreal's world (X forward, Y right, Z up) seen from ours (−Z ahead, +X right, +Y up).
    /// let m = AxisMap::new([(Axis::Y, 1), (Axis::Z, 1), (Axis::X, -1)]).unwrap();
    /// assert_eq!(m.source_of(DVec3::new(1.0, 2.0, 3.0)), DVec3::new(2.0, 3.0, -1.0));
    /// assert!(AxisMap::new([(Axis::X, 1), (Axis::X, 1), (Axis::Z, 1)]).is_none());
    /// ```
    pub fn new(rows: [(Axis, i8); 3]) -> Option<AxisMap> {
        let axis = rows.map(|(a, _)| a as u8);
        let sign = rows.map(|(_, s)| s);
        let mut seen = [false; 3];
        for &a in &axis {
            if std::mem::replace(&mut seen[a as usize], true) {
                return None;
            }
        }
        sign.iter()
            .all(|s| s.abs() == 1)
            .then_some(AxisMap { axis, sign })
    }

    /// The mirror across the plane normal to `axis` (as [`Rotation::mirror`]).
    pub fn mirror(axis: Axis) -> AxisMap {
        let mut m = AxisMap::IDENTITY;
        m.sign[axis as usize] = -1;
        m
    }

    /// First `self`, then `then` (as [`Rotation::then`]): the source direction of `d` is
    /// `self.source_of(then.source_of(d))`.
    pub fn then(self, then: AxisMap) -> AxisMap {
        let mut out = AxisMap::IDENTITY;
        for i in 0..3 {
            // self.source_of(e)[i] = sign[i] · e[axis[i]], with e = then.source_of(d).
            let j = self.axis[i] as usize;
            out.axis[i] = then.axis[j];
            out.sign[i] = self.sign[i] * then.sign[j];
        }
        out
    }

    /// The source direction seen at `d`.
    pub fn source_of(&self, d: DVec3) -> DVec3 {
        DVec3::new(
            self.sign[0] as f64 * d[self.axis[0] as usize],
            self.sign[1] as f64 * d[self.axis[1] as usize],
            self.sign[2] as f64 * d[self.axis[2] as usize],
        )
    }

    /// The same map as a [`Rotation`] (an orthogonal one: it may mirror), for resampling
    /// into projections other than the cube.
    pub fn rotation(&self) -> Rotation {
        let to_source = DMat3::from_cols(
            self.source_of(DVec3::X),
            self.source_of(DVec3::Y),
            self.source_of(DVec3::Z),
        );
        Rotation::from_matrix(to_source.transpose()).expect("a signed permutation is orthogonal")
    }

    /// Whether this is the identity.
    pub fn is_identity(&self) -> bool {
        *self == AxisMap::IDENTITY
    }

    /// Whether it turns a right-handed world into a left-handed one (an odd number of
    /// mirrors).
    pub fn mirrors(&self) -> bool {
        let sign: i8 = self.sign.iter().product();
        // The permutation's parity: even for the identity and the two 3-cycles.
        let even = matches!(self.axis, [0, 1, 2] | [1, 2, 0] | [2, 0, 1]);
        (sign < 0) == even
    }

    /// Integer `source_of`, for the exact texel arithmetic.
    fn source_of_i(&self, d: [i64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|i| self.sign[i] as i64 * d[self.axis[i] as usize])
    }
}

/// `(x, y, z)` as the source direction's components: `(-x, y, z)` mirrors x.
impl fmt::Display for AxisMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = (0..3)
            .map(|i| {
                let name = ["x", "y", "z"][self.axis[i] as usize];
                if self.sign[i] < 0 {
                    format!("-{name}")
                } else {
                    name.to_string()
                }
            })
            .collect();
        write!(f, "({})", parts.join(", "))
    }
}

/// A cube face's frame in integers: its normal and the directions of increasing `s` and
/// `t`, read from [`CubeFace::point`] (the one table of OpenGL's face axes).
fn face_frame(face: CubeFace) -> [[i64; 3]; 3] {
    let v = |p: DVec3| [p.x.round() as i64, p.y.round() as i64, p.z.round() as i64];
    let n = face.point(0.0, 0.0);
    [
        v(n),
        v(face.point(1.0, 0.0) - n),
        v(face.point(0.0, 1.0) - n),
    ]
}

fn dot(a: [i64; 3], b: [i64; 3]) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl EnvMap {
    /// This cube map as seen through `map`: the texel of every output face and position is
    /// the source texel whose centre direction is `map.source_of` of its own, copied bit
    /// for bit (a signed axis permutation carries texel centres onto texel centres, so
    /// nothing is filtered). `None` unless this is a cube map ([`ProjectionKind::Cube`]).
    ///
    /// ```
    /// use mirrorball_core::{Axis, AxisMap, EnvMap, ProjectionKind};
    /// use glam::DVec3;
    /// let cube = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 8, 3, |d| {
    ///     [d.x as f32, d.y as f32, d.z as f32, 1.0]
    /// });
    /// let mirrored = cube.transformed(&AxisMap::mirror(Axis::X)).unwrap();
    /// let d = DVec3::new(0.3, 0.2, -0.9).normalize();
    /// let (a, b) = (mirrored.sample(d), cube.sample(DVec3::new(-d.x, d.y, d.z)));
    /// assert!((0..3).all(|i| (a[i] - b[i]).abs() < 1e-6));
    /// // The texels themselves are moved, not filtered: +X's first texel is −X's last in its row.
    /// assert_eq!(mirrored.layers()[0].get(0, 0), cube.layers()[1].get(7, 0));
    /// ```
    pub fn transformed(&self, map: &AxisMap) -> Option<EnvMap> {
        if self.projection().kind() != ProjectionKind::Cube || self.width() != self.height() {
            return None;
        }
        if map.is_identity() {
            return Some(self.clone());
        }
        let n = self.width() as i64;
        let c = self.channels();
        let layers = CubeFace::ALL
            .iter()
            .map(|&face| {
                let [normal, s_dir, t_dir] = face_frame(face);
                let (normal, s_dir, t_dir) = (
                    map.source_of_i(normal),
                    map.source_of_i(s_dir),
                    map.source_of_i(t_dir),
                );
                let src_face = *CubeFace::ALL
                    .iter()
                    .find(|&&f| face_frame(f)[0] == normal)
                    .expect("a signed permutation maps a face normal onto one");
                let [_, s2, t2] = face_frame(src_face);
                // In odd integers i = 2x + 1 − n (n times the face coordinate of the
                // texel centre): the source's (i', j') = M (i, j).
                let m = [
                    [dot(s_dir, s2), dot(t_dir, s2)],
                    [dot(s_dir, t2), dot(t_dir, t2)],
                ];
                let src = &self.layers()[src_face as usize];
                let mut img = Image::new(n as u32, n as u32, c);
                let data = img.data_mut();
                for y in 0..n {
                    let j = 2 * y + 1 - n;
                    for x in 0..n {
                        let i = 2 * x + 1 - n;
                        let si = m[0][0] * i + m[0][1] * j;
                        let sj = m[1][0] * i + m[1][1] * j;
                        let (sx, sy) = ((si + n - 1) / 2, (sj + n - 1) / 2);
                        let at = ((y * n + x) as usize) * c;
                        let from = ((sy * n + sx) as usize) * c;
                        data[at..at + c].copy_from_slice(&src.data()[from..from + c]);
                    }
                }
                img
            })
            .collect();
        Some(EnvMap::new(*self.projection(), layers).expect("the same shape as the source"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::WorldProjection;
    use glam::DVec2;

    /// Every one of the 48 signed permutations.
    fn all() -> Vec<AxisMap> {
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let mut out = Vec::new();
        for p in perms {
            for s in 0..8 {
                let sign = |k: usize| if s >> k & 1 == 1 { -1 } else { 1 };
                out.push(
                    AxisMap::new([
                        (axes[p[0]], sign(0)),
                        (axes[p[1]], sign(1)),
                        (axes[p[2]], sign(2)),
                    ])
                    .unwrap(),
                );
            }
        }
        out
    }

    #[test]
    fn composition_and_rotation_agree_with_source_of() {
        let d = DVec3::new(0.2, -0.5, 0.7);
        for a in all() {
            let r = a.rotation();
            assert!((r.source_of(d) - a.source_of(d)).length() < 1e-15, "{a}");
            let det = DMat3::from_cols(
                a.source_of(DVec3::X),
                a.source_of(DVec3::Y),
                a.source_of(DVec3::Z),
            )
            .determinant();
            assert_eq!(a.mirrors(), det < 0.0, "{a}");
            for b in all().into_iter().step_by(5) {
                assert_eq!(
                    a.then(b).source_of(d),
                    a.source_of(b.source_of(d)),
                    "{a} then {b}"
                );
                let rb = a.rotation().then(b.rotation());
                assert!((rb.source_of(d) - a.then(b).source_of(d)).length() < 1e-15);
            }
        }
        assert_eq!(AxisMap::mirror(Axis::X).to_string(), "(-x, y, z)");
    }

    /// A cube whose every texel value is distinct (its index), odd and even sizes.
    fn numbered(n: u32) -> EnvMap {
        let layers = (0..6)
            .map(|f| {
                let mut img = Image::new(n, n, 3);
                for (k, px) in img.data_mut().chunks_exact_mut(3).enumerate() {
                    px[0] = (f * 10_000 + k) as f32;
                    px[1] = -(k as f32) - 0.25;
                    px[2] = f32::from_bits(0x7fc0_0001 + k as u32); // a NaN payload
                }
                img
            })
            .collect();
        EnvMap::new(ProjectionKind::Cube.default_projection(), layers).unwrap()
    }

    /// Brute force: each output texel's centre direction, mapped, looked up as the texel
    /// that holds it in the source.
    #[test]
    fn transformed_is_the_brute_force_permutation_to_the_bit() {
        for n in [1u32, 2, 5, 8] {
            let cube = numbered(n);
            let proj = *cube.projection();
            for a in all() {
                let out = cube.transformed(&a).unwrap();
                for face in 0..6 {
                    for y in 0..n {
                        for x in 0..n {
                            let uv = DVec2::new(
                                (x as f64 + 0.5) / n as f64,
                                (y as f64 + 0.5) / n as f64,
                            );
                            let d = proj.uv_to_dir(face, uv).unwrap();
                            let (sf, suv) = proj.dir_to_uv(a.source_of(d)).unwrap();
                            let sx = ((suv.x * n as f64) as u32).min(n - 1);
                            let sy = ((suv.y * n as f64) as u32).min(n - 1);
                            let want = cube.layers()[sf].get(sx, sy);
                            let got = out.layers()[face].get(x, y);
                            assert_eq!(
                                got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                                want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                                "{a} n={n} face {face} ({x}, {y})"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Against resampling with the same map as a rotation (plain bilinear at texel
    /// centres): the same values, to rounding.
    #[test]
    fn transformed_matches_resampling() {
        let proj = ProjectionKind::Cube.default_projection();
        let cube = EnvMap::from_fn(proj, 16, 3, |d| {
            [
                (1.5 + d.x + 0.3 * d.y * d.z) as f32,
                (1.5 + d.y * d.x) as f32,
                (1.5 + d.z) as f32,
                1.0,
            ]
        });
        for a in all() {
            let exact = cube.transformed(&a).unwrap();
            let opts = crate::ResampleOptions {
                rotation: a.rotation(),
                max_samples: 1,
                ..Default::default()
            };
            let resampled = crate::resample(&cube, proj, 16, &opts);
            for (e, r) in exact.layers().iter().zip(resampled.layers()) {
                for (x, y) in e.data().iter().zip(r.data()) {
                    assert!((x - y).abs() < 1e-4, "{a}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn only_cubes_are_transformed() {
        let ll = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 8, 3, |_| {
            [1.0; 4]
        });
        assert!(ll.transformed(&AxisMap::mirror(Axis::Z)).is_none());
    }
}
