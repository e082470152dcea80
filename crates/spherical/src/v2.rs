//! Spherical Video V2 (google/spatial-media `docs/spherical-video-v2-rfc.md`): the boxes a
//! video track's visual sample entry carries.
//!
//! ```text
//! st3d  FullBox: stereo_mode (u8)
//! sv3d  Box
//!   svhd  FullBox: metadata_source (UTF-8, NUL-terminated)
//!   proj  Box
//!     prhd  FullBox: pose_yaw, pose_pitch, pose_roll (i32, 16.16 degrees)
//!     equi  FullBox: bounds top, bottom, left, right (u32, 0.32: the share cropped)
//!   | cbmp  FullBox: layout (u32), padding (u32)
//!   | mshp  FullBox: crc (u32), encoding (fourcc), mesh boxes (see `mesh.rs`)
//! ```
//!
//! FFmpeg's MOV demuxer (`mov_read_sv3d`) reads the boxes in exactly this order, `svhd`
//! first, so they are written so.

use crate::bmff::{be_u32, full_box, headers_in, name, FourCC, Node};
use crate::Error;
use mirrorball_core::Stereo;

/// The name written in `svhd`.
pub const SOURCE: &str = "mirrorball";

/// `st3d`'s `stereo_mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StereoMode {
    /// 0: one view.
    Mono,
    /// 1: the left eye in the top half, the right in the bottom.
    TopBottom,
    /// 2: the left eye in the left half, the right in the right.
    LeftRight,
    /// 3: both eyes, laid out as the projection (a mesh per eye) says.
    Custom,
    /// 4: the right eye in the left half, the left in the right.
    RightLeft,
    /// Any other value (reserved by the specification).
    Reserved(u8),
}

impl StereoMode {
    /// The value stored.
    pub fn code(self) -> u8 {
        match self {
            StereoMode::Mono => 0,
            StereoMode::TopBottom => 1,
            StereoMode::LeftRight => 2,
            StereoMode::Custom => 3,
            StereoMode::RightLeft => 4,
            StereoMode::Reserved(c) => c,
        }
    }

    /// The mode stored as `code`.
    pub fn from_code(code: u8) -> StereoMode {
        match code {
            0 => StereoMode::Mono,
            1 => StereoMode::TopBottom,
            2 => StereoMode::LeftRight,
            3 => StereoMode::Custom,
            4 => StereoMode::RightLeft,
            c => StereoMode::Reserved(c),
        }
    }

    /// The mode of mirrorball's stereo arrangement (`core::Stereo`, as v360's `in_stereo`:
    /// `sbs` is the left eye on the left, `tb` the left eye on top).
    pub fn of(s: Stereo) -> StereoMode {
        match s {
            Stereo::Mono => StereoMode::Mono,
            Stereo::TopBottom => StereoMode::TopBottom,
            Stereo::SideBySide => StereoMode::LeftRight,
        }
    }

    /// mirrorball's arrangement for this mode, where it has one.
    pub fn stereo(self) -> Option<Stereo> {
        match self {
            StereoMode::Mono => Some(Stereo::Mono),
            StereoMode::TopBottom => Some(Stereo::TopBottom),
            StereoMode::LeftRight => Some(Stereo::SideBySide),
            _ => None,
        }
    }

    /// The specification's name of the mode, for people.
    pub fn describe(self) -> String {
        match self {
            StereoMode::Mono => "mono".into(),
            StereoMode::TopBottom => "top-bottom".into(),
            StereoMode::LeftRight => "left-right".into(),
            StereoMode::Custom => "stereo-custom".into(),
            StereoMode::RightLeft => "right-left".into(),
            StereoMode::Reserved(c) => format!("reserved stereo mode {c}"),
        }
    }
}

/// `equi`'s bounds: the share of the full sphere's picture cropped from each edge, in 0.32
/// fixed point (all zero: the whole sphere).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Bounds {
    /// Cropped from the top.
    pub top: u32,
    /// Cropped from the bottom.
    pub bottom: u32,
    /// Cropped from the left.
    pub left: u32,
    /// Cropped from the right.
    pub right: u32,
}

/// The projection data box in `proj`.
#[derive(Clone, Debug, PartialEq)]
pub enum ProjectionData {
    /// `equi`.
    Equirect(Bounds),
    /// `cbmp`.
    Cubemap {
        /// 0: the 3×2 grid right, left, up / down, front, back (the only one defined).
        layout: u32,
        /// Pixels of padding at each face's edges.
        padding: u32,
    },
    /// `mshp`: its payload after version and flags (crc, encoding, meshes), as stored.
    Mesh(Vec<u8>),
    /// A projection data box this crate does not know.
    Other(FourCC),
}

/// `prhd`'s pose: yaw, pitch and roll in degrees, 16.16 fixed point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pose {
    /// Counter-clockwise about the up vector.
    pub yaw: i32,
    /// Counter-clockwise about the right vector, after yaw.
    pub pitch: i32,
    /// Clockwise about the forward vector, after yaw and pitch.
    pub roll: i32,
}

/// What an `sv3d` box says.
#[derive(Clone, Debug, PartialEq)]
pub struct Sv3d {
    /// `svhd`'s metadata source: the tool that wrote the box.
    pub source: String,
    /// `prhd`.
    pub pose: Pose,
    /// The projection data box.
    pub data: ProjectionData,
}

/// The `st3d` box.
pub fn st3d(mode: StereoMode) -> Node {
    Node::leaf(b"st3d", full_box(0, 0, &[mode.code()]))
}

/// The `sv3d` box: `svhd`, then `proj` with `prhd` and the projection data box.
pub fn sv3d(s: &Sv3d) -> Node {
    let mut source = s.source.as_bytes().to_vec();
    source.push(0);
    let svhd = Node::leaf(b"svhd", full_box(0, 0, &source));
    let pose: Vec<u8> = [s.pose.yaw, s.pose.pitch, s.pose.roll]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    let prhd = Node::leaf(b"prhd", full_box(0, 0, &pose));
    let data = match &s.data {
        ProjectionData::Equirect(b) => {
            let v: Vec<u8> = [b.top, b.bottom, b.left, b.right]
                .iter()
                .flat_map(|v| v.to_be_bytes())
                .collect();
            Node::leaf(b"equi", full_box(0, 0, &v))
        }
        ProjectionData::Cubemap { layout, padding } => {
            let mut v = layout.to_be_bytes().to_vec();
            v.extend_from_slice(&padding.to_be_bytes());
            Node::leaf(b"cbmp", full_box(0, 0, &v))
        }
        ProjectionData::Mesh(p) => Node::leaf(b"mshp", full_box(0, 0, p)),
        ProjectionData::Other(kind) => Node::leaf(kind, full_box(0, 0, &[])),
    };
    let proj = Node::tree(b"proj", Vec::new(), vec![prhd, data]);
    Node::tree(b"sv3d", Vec::new(), vec![svhd, proj])
}

/// `st3d`'s mode from its payload.
pub fn parse_st3d(payload: &[u8]) -> Result<StereoMode, Error> {
    match payload {
        [0, _, _, _, mode, ..] => Ok(StereoMode::from_code(*mode)),
        [v, _, _, _, _, ..] => Err(Error::malformed(format!(
            "'st3d' has version {v}; only version 0 is defined"
        ))),
        _ => Err(Error::malformed(format!(
            "'st3d' holds {} bytes, fewer than 5",
            payload.len()
        ))),
    }
}

/// The boxes in a payload, by type, as `(type, payload)`; unknown ones are passed over by
/// the caller, as the specification asks.
fn boxes(payload: &[u8], what: &str) -> Result<Vec<(FourCC, Vec<u8>)>, Error> {
    let (hs, _) = headers_in(payload, 0).map_err(|e| e.within(format_args!("in '{what}'")))?;
    Ok(hs
        .iter()
        .map(|h| {
            let p = &payload[h.payload_start() as usize..h.end() as usize];
            (h.kind, p.to_vec())
        })
        .collect())
}

/// A full box's body after version 0 and its flags.
fn version0<'a>(kind: &FourCC, p: &'a [u8]) -> Result<&'a [u8], Error> {
    match p {
        [0, _, _, _, rest @ ..] => Ok(rest),
        [v, ..] => Err(Error::malformed(format!(
            "{} has version {v}; only version 0 is defined",
            name(kind)
        ))),
        [] => Err(Error::malformed(format!("{} is empty", name(kind)))),
    }
}

/// What an `sv3d` box's payload says.
pub fn parse_sv3d(payload: &[u8]) -> Result<Sv3d, Error> {
    let inner = boxes(payload, "sv3d")?;
    let find = |list: &[(FourCC, Vec<u8>)], k: &FourCC| {
        list.iter()
            .find(|(kind, _)| kind == k)
            .map(|(_, p)| p.clone())
            .ok_or_else(|| Error::malformed(format!("'sv3d' has no {} box", name(k))))
    };
    let svhd = find(&inner, b"svhd")?;
    let source = version0(b"svhd", &svhd)?;
    let source = source.split(|&b| b == 0).next().unwrap_or_default();
    let source = String::from_utf8_lossy(source).into_owned();
    let proj = boxes(&find(&inner, b"proj")?, "proj")?;
    let prhd = find(&proj, b"prhd")?;
    let body = version0(b"prhd", &prhd)?;
    let field = |i: usize| {
        be_u32(body, 4 * i)
            .map(|v| v as i32)
            .ok_or_else(|| Error::malformed("'prhd' is shorter than its three angles"))
    };
    let pose = Pose {
        yaw: field(0)?,
        pitch: field(1)?,
        roll: field(2)?,
    };
    let (kind, p) = proj.iter().find(|(k, _)| k != b"prhd").ok_or_else(|| {
        Error::malformed("'proj' has no projection data box ('equi', 'cbmp' or 'mshp')")
    })?;
    let data = projection_data(kind, p)?;
    Ok(Sv3d { source, pose, data })
}

fn projection_data(kind: &FourCC, p: &[u8]) -> Result<ProjectionData, Error> {
    let short = || Error::malformed(format!("{} is shorter than its fields", name(kind)));
    Ok(match kind {
        b"equi" => {
            let b = version0(kind, p)?;
            let f = |i: usize| be_u32(b, 4 * i).ok_or_else(short);
            let bounds = Bounds {
                top: f(0)?,
                bottom: f(1)?,
                left: f(2)?,
                right: f(3)?,
            };
            // FFmpeg's `mov_read_sv3d` refuses `bottom >= UINT_MAX - top`, likewise left.
            let max = u64::from(u32::MAX);
            if u64::from(bounds.top) + u64::from(bounds.bottom) >= max
                || u64::from(bounds.left) + u64::from(bounds.right) >= max
            {
                return Err(Error::malformed(format!(
                    "'equi' crops everything (bounds top {}, bottom {}, left {}, right {} of 2^32)",
                    bounds.top, bounds.bottom, bounds.left, bounds.right
                )));
            }
            ProjectionData::Equirect(bounds)
        }
        b"cbmp" => {
            let b = version0(kind, p)?;
            ProjectionData::Cubemap {
                layout: be_u32(b, 0).ok_or_else(short)?,
                padding: be_u32(b, 4).ok_or_else(short)?,
            }
        }
        b"mshp" => ProjectionData::Mesh(version0(kind, p)?.to_vec()),
        other => ProjectionData::Other(*other),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_are_laid_out_as_the_rfc_says() {
        let s = Sv3d {
            source: "x".into(),
            pose: Pose {
                yaw: 90 << 16,
                pitch: -(45 << 16),
                roll: 0,
            },
            data: ProjectionData::Equirect(Bounds::default()),
        };
        let b = sv3d(&s).to_bytes();
        // sv3d(8) + svhd(8 + 4 + "x\0") + proj(8) + prhd(8 + 4 + 12) + equi(8 + 4 + 16).
        assert_eq!(b.len(), 8 + 14 + 8 + 24 + 28);
        assert_eq!(&b[4..8], b"sv3d");
        assert_eq!(&b[12..16], b"svhd");
        assert_eq!(&b[26..30], b"proj");
        assert_eq!(&b[34..38], b"prhd");
        assert_eq!(&b[42..46], &(90i32 << 16).to_be_bytes());
        assert_eq!(&b[58..62], b"equi");
        assert_eq!(parse_sv3d(&b[8..]).unwrap(), s);
        assert_eq!(
            st3d(StereoMode::TopBottom).to_bytes(),
            [0, 0, 0, 13, b's', b't', b'3', b'd', 0, 0, 0, 0, 1]
        );
        for code in 0..=255u8 {
            let m = StereoMode::from_code(code);
            assert_eq!(m.code(), code);
            assert_eq!(parse_st3d(&st3d(m).to_bytes()[8..]), Ok(m));
        }
        for s in [Stereo::Mono, Stereo::SideBySide, Stereo::TopBottom] {
            assert_eq!(StereoMode::of(s).stereo(), Some(s));
        }
    }

    #[test]
    fn bad_boxes_are_described() {
        assert!(parse_st3d(&[1, 0, 0, 0, 0])
            .unwrap_err()
            .to_string()
            .contains("version 1"));
        assert!(parse_sv3d(&[0, 0, 0, 9, b'x']).is_err());
        let cube = Sv3d {
            source: String::new(),
            pose: Pose::default(),
            data: ProjectionData::Cubemap {
                layout: 0,
                padding: 0,
            },
        };
        let b = sv3d(&cube).to_bytes();
        assert_eq!(parse_sv3d(&b[8..]).unwrap(), cube);
        // Bounds that crop everything are refused, as FFmpeg refuses them.
        let all = Sv3d {
            data: ProjectionData::Equirect(Bounds {
                left: u32::MAX,
                right: 1,
                ..Bounds::default()
            }),
            ..cube
        };
        let e = parse_sv3d(&sv3d(&all).to_bytes()[8..])
            .unwrap_err()
            .to_string();
        assert!(e.contains("crops everything"), "{e}");
    }
}
