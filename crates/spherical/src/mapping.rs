//! Which of mirrorball's projections the 360° metadata formats can state, and how each one
//! is stated: the one table the video boxes, V1's XML and GPano's XMP are read and written
//! through.
//!
//! | mapping | mirrorball | V2 (`sv3d`/`proj`) | V1 / GPano |
//! | --- | --- | --- | --- |
//! | equirect, H°×V° | `latlong` (360×180), else `half-equirect:hfov=H:vfov=V` | `equi`, bounds `(1 − H/360)/2` left and right, `(1 − V/180)/2` top and bottom | equirectangular, cropped from a full panorama `360/H` times as wide |
//! | cube | `cube`, layout `c3x2` (v360's `rludfb`, no turns) | `cbmp` layout 0, padding 0 | — |
//! | eac | `eac`, layout `eac` (v360's) | `mshp`: the faces as a mesh (`mesh.rs`) | — |
//!
//! `cbmp` layout 0 is the 3×2 grid right, left, up / down, front, back with the side faces
//! upright: v360's default `c3x2`, which is also how VLC draws it (`BuildCube` in its
//! OpenGL renderer: the up face's top edge towards the back, the down face's towards the
//! front). The V2 specification defines no equi-angular cube; YouTube marks its EAC streams
//! with a mesh, and so does this crate.

use crate::v2::{Bounds, ProjectionData};
use crate::xml;
use crate::Error;
use mirrorball_core::projection::{Cylinder, CylinderRule};
use mirrorball_core::{CellGrid, Choice, CubeCells, Layout, Projection};

/// A projection the metadata can state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// Equirectangular over `hfov`×`vfov` degrees, centred on the forward direction: the
    /// whole sphere at 360×180 (mirrorball's `latlong`), VR180 at 180×180.
    Equirect {
        /// Degrees of longitude across the picture.
        hfov: f64,
        /// Degrees of latitude down the picture.
        vfov: f64,
    },
    /// A cube in v360's `c3x2` (`cbmp` layout 0).
    Cube,
    /// The equi-angular cube in v360's `eac` layout.
    Eac,
}

/// The mappings `mirrorball tag --projection` names: one table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The whole sphere, equirectangular.
    Equirect,
    /// The front half, equirectangular (VR180).
    HalfEquirect,
    /// A cube in `c3x2`.
    Cube,
    /// An equi-angular cube in v360's `eac` layout.
    Eac,
}

impl Choice for Kind {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (
            Kind::Equirect,
            &["equirect", "equirectangular", "latlong", "lat-long"],
        ),
        (Kind::HalfEquirect, &["half-equirect", "vr180", "hequirect"]),
        (Kind::Cube, &["cube", "cubemap", "c3x2"]),
        (Kind::Eac, &["eac", "equi-angular-cube"]),
    ];
}
mirrorball_core::choice_traits!(Kind);

impl Kind {
    /// The mapping this name stands for.
    pub fn mapping(self) -> Mapping {
        match self {
            Kind::Equirect => Mapping::FULL,
            Kind::HalfEquirect => Mapping::Equirect {
                hfov: 180.0,
                vfov: 180.0,
            },
            Kind::Cube => Mapping::Cube,
            Kind::Eac => Mapping::Eac,
        }
    }
}

/// 2^32, the unit of `equi`'s 0.32 fixed-point bounds.
const FIXED_ONE: f64 = 4_294_967_296.0;

impl Mapping {
    /// The whole sphere, equirectangular.
    pub const FULL: Mapping = Mapping::Equirect {
        hfov: 360.0,
        vfov: 180.0,
    };

    /// The `c3x2` cells `cbmp` layout 0 means.
    pub const CUBE_CELLS: CubeCells = CubeCells::v360(CellGrid::C3x2);

    /// The mapping of a picture of projection `p` laid out as `layout`, if the metadata can
    /// state it.
    pub fn of(p: &Projection, layout: Option<Layout>) -> Option<Mapping> {
        match p {
            Projection::LatLong(_) => Some(Mapping::FULL),
            Projection::Cylinder(c) if c.rule() == CylinderRule::Equidistant => {
                Some(Mapping::Equirect {
                    hfov: c.hfov_deg(),
                    vfov: c.vfov_deg(),
                })
            }
            Projection::Cube(_) if layout == Some(Layout::Cells(Mapping::CUBE_CELLS)) => {
                Some(Mapping::Cube)
            }
            // v360's eac at any size (`CubeCells::eac_frame`).
            Projection::Eac(_)
                if matches!(
                    layout,
                    None | Some(Layout::Cells(CubeCells { eac_pad: true, .. }))
                ) =>
            {
                Some(Mapping::Eac)
            }
            _ => None,
        }
    }

    /// mirrorball's projection for it.
    pub fn projection(&self) -> Projection {
        match *self {
            Mapping::Equirect { hfov, vfov } if hfov == 360.0 && vfov == 180.0 => {
                Projection::LatLong(mirrorball_core::LatLong)
            }
            Mapping::Equirect { hfov, vfov } => {
                match Cylinder::new(CylinderRule::Equidistant, hfov, vfov) {
                    Some(c) => Projection::Cylinder(c),
                    None => Projection::LatLong(mirrorball_core::LatLong),
                }
            }
            Mapping::Cube => Projection::Cube(mirrorball_core::CubeMap),
            Mapping::Eac => Projection::Eac(mirrorball_core::Eac),
        }
    }

    /// mirrorball's layout for it (for the cubes).
    pub fn layout(&self) -> Option<Layout> {
        match self {
            Mapping::Equirect { .. } => None,
            Mapping::Cube => Some(Layout::Cells(Mapping::CUBE_CELLS)),
            Mapping::Eac => Some(Layout::Cells(CubeCells::EAC)),
        }
    }

    /// How mirrorball reads such a picture: `--from SPEC` and, for the cubes,
    /// `--in-layout LAYOUT`.
    pub fn flags(&self) -> String {
        let mut s = format!("--from {}", self.projection());
        if let Some(l) = self.layout() {
            s.push_str(&format!(" --in-layout {l}"));
        }
        s
    }

    /// Whether an eye of `w`×`h` pixels has this mapping's shape: the cube's grid exactly,
    /// v360's EAC at any size that holds its faces,
    /// an equirectangular picture `hfov/vfov` as wide as high (within a pixel). The error is
    /// the rule broken.
    pub fn check_eye(&self, w: u32, h: u32) -> Result<(), Error> {
        let fits = match self {
            Mapping::Equirect { hfov, vfov } => {
                (f64::from(w) - f64::from(h) * hfov / vfov).abs() <= 1.0
            }
            Mapping::Cube => Mapping::CUBE_CELLS.face_size(w, h).is_some(),
            Mapping::Eac => CubeCells::eac_frame(w, h).is_some(),
        };
        if fits {
            return Ok(());
        }
        Err(Error::unfit(match self {
            Mapping::Equirect { hfov, vfov } => format!(
                "an equirectangular picture of {hfov}°×{vfov}° is {}:1",
                hfov / vfov
            ),
            Mapping::Cube => "a cube in c3x2 is 3 faces wide and 2 high (3n×2n)".into(),
            Mapping::Eac => {
                "an EAC picture holds six faces between two-pixel borders: at least 7×10".into()
            }
        }))
    }

    /// `equi`'s bounds for an equirectangular mapping.
    pub fn bounds(hfov: f64, vfov: f64) -> Bounds {
        let share = |fov: f64, full: f64| {
            let v = ((1.0 - fov / full) / 2.0 * FIXED_ONE).round();
            v.clamp(0.0, f64::from(u32::MAX)) as u32
        };
        let (side, edge) = (share(hfov, 360.0), share(vfov, 180.0));
        Bounds {
            top: edge,
            bottom: edge,
            left: side,
            right: side,
        }
    }

    /// The mapping `equi` bounds state, if it is centred (left = right, top = bottom,
    /// within one part in 2^32): the fields of view, rounded to a millionth of a degree.
    pub fn from_bounds(b: &Bounds) -> Option<Mapping> {
        if b.left.abs_diff(b.right) > 1 || b.top.abs_diff(b.bottom) > 1 {
            return None;
        }
        let fov = |a: u32, c: u32, full: f64| {
            let v = full * (1.0 - (f64::from(a) + f64::from(c)) / FIXED_ONE);
            (v * 1e6).round() / 1e6
        };
        Some(Mapping::Equirect {
            hfov: fov(b.left, b.right, 360.0),
            vfov: fov(b.top, b.bottom, 180.0),
        })
    }

    /// The `proj` data box for a picture whose eye is `w`×`h` pixels.
    pub fn projection_data(&self, w: u32, h: u32) -> Result<ProjectionData, Error> {
        self.check_eye(w, h)?;
        Ok(match *self {
            Mapping::Equirect { hfov, vfov } => {
                ProjectionData::Equirect(Mapping::bounds(hfov, vfov))
            }
            Mapping::Cube => ProjectionData::Cubemap {
                layout: 0,
                padding: 0,
            },
            Mapping::Eac => ProjectionData::Mesh(crate::mesh::eac_mshp(w, h)?),
        })
    }

    /// The mapping a `proj` data box states for an eye of `w`×`h` pixels, or why
    /// mirrorball cannot read it.
    pub fn from_data(data: &ProjectionData, w: u32, h: u32) -> Result<Mapping, Error> {
        let mapping = match data {
            ProjectionData::Equirect(b) => Mapping::from_bounds(b).ok_or_else(|| {
                format!(
                    "an equirectangular picture cropped off-centre (bounds top {}, bottom {}, left {}, right {} of 2^32)",
                    b.top, b.bottom, b.left, b.right
                )
            }),
            ProjectionData::Cubemap { layout: 0, padding: 0 } => Ok(Mapping::Cube),
            ProjectionData::Cubemap { layout, padding } => Err(format!(
                "a cube map of layout {layout} with {padding} pixels of padding (mirrorball reads layout 0 unpadded)"
            )),
            ProjectionData::Mesh(m) => match crate::mesh::eac_mshp(w, h) {
                Ok(ours) if &ours == m => Ok(Mapping::Eac),
                _ => Err("a mesh projection other than the equi-angular cube mirrorball writes".into()),
            },
            ProjectionData::Other(k) => Err(format!(
                "projection box {} is not one of the specification's",
                crate::bmff::name(k)
            )),
        };
        mapping.map_err(Error::malformed)
    }
}

/// The cropping fields V1's GSpherical XML and GPano's XMP share: a picture of
/// `width`×`height` cut at (`left`, `top`) from a full equirectangular panorama of
/// `full_width`×`full_height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// `FullPanoWidthPixels`.
    pub full_width: u32,
    /// `FullPanoHeightPixels`.
    pub full_height: u32,
    /// `CroppedAreaImageWidthPixels`.
    pub width: u32,
    /// `CroppedAreaImageHeightPixels`.
    pub height: u32,
    /// `CroppedAreaLeftPixels`.
    pub left: u32,
    /// `CroppedAreaTopPixels`.
    pub top: u32,
}

/// The field names, in the order written.
const CROP_FIELDS: [&str; 6] = [
    "CroppedAreaImageWidthPixels",
    "CroppedAreaImageHeightPixels",
    "FullPanoWidthPixels",
    "FullPanoHeightPixels",
    "CroppedAreaLeftPixels",
    "CroppedAreaTopPixels",
];

impl Crop {
    /// The crop of a `w`×`h` picture of an equirectangular mapping from its full panorama,
    /// centred.
    pub fn of(m: &Mapping, w: u32, h: u32) -> Option<Crop> {
        let Mapping::Equirect { hfov, vfov } = *m else {
            return None;
        };
        let full_width = (f64::from(w) * 360.0 / hfov).round() as u32;
        let full_height = (f64::from(h) * 180.0 / vfov).round() as u32;
        Some(Crop {
            full_width,
            full_height,
            width: w,
            height: h,
            left: full_width.saturating_sub(w) / 2,
            top: full_height.saturating_sub(h) / 2,
        })
    }

    /// The mapping, if the crop is centred (within a pixel) and inside the panorama.
    pub fn mapping(&self) -> Option<Mapping> {
        let fits = self.width > 0
            && self.height > 0
            && self.width <= self.full_width
            && self.height <= self.full_height;
        let centred = |at: u32, size: u32, full: u32| {
            (f64::from(at) - f64::from(full - size) / 2.0).abs() <= 1.0
        };
        if !fits
            || !centred(self.left, self.width, self.full_width)
            || !centred(self.top, self.height, self.full_height)
        {
            return None;
        }
        let fov = |size: u32, full: u32, turn: f64| {
            (turn * f64::from(size) / f64::from(full) * 1e6).round() / 1e6
        };
        Some(Mapping::Equirect {
            hfov: fov(self.width, self.full_width, 360.0),
            vfov: fov(self.height, self.full_height, 180.0),
        })
    }

    /// The six fields as elements `<PREFIX:Name>value</PREFIX:Name>`.
    pub fn elements(&self, prefix: &str) -> String {
        let values = [
            self.width,
            self.height,
            self.full_width,
            self.full_height,
            self.left,
            self.top,
        ];
        CROP_FIELDS
            .iter()
            .zip(values)
            .map(|(name, v)| format!("<{prefix}:{name}>{v}</{prefix}:{name}>"))
            .collect()
    }

    /// The fields read from XML, if all six are there as integers.
    pub fn parse(text: &str) -> Option<Crop> {
        let mut v = [0u32; 6];
        for (slot, name) in v.iter_mut().zip(CROP_FIELDS) {
            *slot = xml::value(text, name)?.parse().ok()?;
        }
        Some(Crop {
            width: v[0],
            height: v[1],
            full_width: v[2],
            full_height: v[3],
            left: v[4],
            top: v[5],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    #[test]
    fn bounds_round_trip_and_vr180_is_a_quarter_off_each_side() {
        let b = Mapping::bounds(180.0, 180.0);
        assert_eq!((b.left, b.right, b.top, b.bottom), (1 << 30, 1 << 30, 0, 0));
        assert_eq!(Mapping::bounds(360.0, 180.0), Bounds::default());
        for (h, v) in [
            (360.0, 180.0),
            (180.0, 180.0),
            (200.0, 120.0),
            (90.5, 33.25),
        ] {
            let m = Mapping::Equirect { hfov: h, vfov: v };
            assert_eq!(Mapping::from_bounds(&Mapping::bounds(h, v)), Some(m));
        }
        let off = Bounds {
            left: 10,
            ..Bounds::default()
        };
        assert_eq!(Mapping::from_bounds(&off), None);
    }

    #[test]
    fn every_kind_maps_to_mirrorball_and_back() {
        for kind in Kind::all() {
            let m = kind.mapping();
            assert_eq!(Mapping::of(&m.projection(), m.layout()), Some(m), "{kind}");
        }
        assert_eq!(
            Kind::HalfEquirect.mapping().projection().kind(),
            ProjectionKind::HalfEquirect
        );
        assert_eq!(Kind::Equirect.mapping().flags(), "--from latlong");
        assert_eq!(Kind::Cube.mapping().flags(), "--from cube --in-layout c3x2");
        assert_eq!(Kind::Eac.mapping().flags(), "--from eac --in-layout eac");
        // A cube in another layout, or a sphere map, has no metadata.
        let cube = ProjectionKind::Cube.default_projection();
        assert_eq!(Mapping::of(&cube, Some(Layout::HorizontalCross)), None);
        assert_eq!(
            Mapping::of(&ProjectionKind::Sphere.default_projection(), None),
            None
        );
    }

    #[test]
    fn shapes_are_checked() {
        assert!(Mapping::FULL.check_eye(64, 32).is_ok());
        assert!(Mapping::FULL.check_eye(64, 48).is_err());
        assert!(Kind::HalfEquirect.mapping().check_eye(32, 32).is_ok());
        assert!(Mapping::Cube.check_eye(96, 64).is_ok());
        assert!(Mapping::Cube.check_eye(96, 60).is_err());
        assert!(Mapping::Eac.check_eye(3 * 32 + 4, 2 * 32 + 8).is_ok());
        // v360's EAC at any size that holds its faces: YouTube's 3840x2160.
        assert!(Mapping::Eac.check_eye(3840, 2160).is_ok());
        assert!(Mapping::Eac.check_eye(6, 9).is_err());
    }

    #[test]
    fn crops_round_trip_through_their_xml() {
        let c = Crop::of(&Kind::HalfEquirect.mapping(), 2048, 2048).unwrap();
        assert_eq!(
            (c.full_width, c.full_height, c.left, c.top),
            (4096, 2048, 1024, 0)
        );
        assert_eq!(c.mapping(), Some(Kind::HalfEquirect.mapping()));
        assert_eq!(Crop::parse(&c.elements("GPano")), Some(c));
        assert_eq!(Crop::of(&Mapping::Cube, 10, 10), None);
        let off = Crop { left: 0, ..c };
        assert_eq!(off.mapping(), None);
    }
}
