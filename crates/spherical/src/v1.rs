//! Spherical Video V1 (google/spatial-media `docs/spherical-video-rfc.md`): GSpherical XML
//! in a `uuid` box (`ffcc8263-f855-4a93-8814-587a02521fdd`) in the video `trak`, for the
//! services that still read only it. V1 knows only equirectangular pictures; a cropped one
//! (VR180) carries the crop fields, one eye's.

use crate::bmff::Node;
use crate::mapping::{Crop, Mapping};
use crate::v2::StereoMode;
use crate::xml;
use crate::Error;

/// The `uuid` box's user type.
pub const UUID: [u8; 16] = [
    0xff, 0xcc, 0x82, 0x63, 0xf8, 0x55, 0x4a, 0x93, 0x88, 0x14, 0x58, 0x7a, 0x02, 0x52, 0x1f, 0xdd,
];

/// What the GSpherical XML says.
#[derive(Clone, Debug, PartialEq)]
pub struct V1 {
    /// `Spherical`: whether the video is spherical.
    pub spherical: bool,
    /// `ProjectionType` (`equirectangular` is the only one defined).
    pub projection_type: String,
    /// `StereoMode`: `mono`, `left-right` or `top-bottom` (absent: mono).
    pub stereo_mode: Option<String>,
    /// The crop fields, when all six are there.
    pub crop: Option<Crop>,
}

impl V1 {
    /// The stereo mode in V2's terms, if it is one V1 defines.
    pub fn stereo(&self) -> Option<StereoMode> {
        match self.stereo_mode.as_deref().map(str::trim) {
            None | Some("mono") => Some(StereoMode::Mono),
            Some("top-bottom") => Some(StereoMode::TopBottom),
            Some("left-right") => Some(StereoMode::LeftRight),
            Some(_) => None,
        }
    }

    /// The mapping, if the video is a spherical equirectangular one mirrorball reads.
    pub fn mapping(&self) -> Option<Mapping> {
        if !self.spherical || self.projection_type.trim() != "equirectangular" {
            return None;
        }
        match self.crop {
            None => Some(Mapping::FULL),
            Some(c) => c.mapping(),
        }
    }
}

/// The XML for `mapping` (an equirectangular one) of eyes of `w`×`h` pixels in `stereo`.
pub fn xml(mapping: &Mapping, stereo: StereoMode, w: u32, h: u32) -> Result<String, Error> {
    if !matches!(mapping, Mapping::Equirect { .. }) {
        return Err(Error::unfit(
            "Spherical Video V1 describes only equirectangular video; leave out --v1 for a cube",
        ));
    }
    let mut x = String::from(
        "<?xml version=\"1.0\"?><rdf:SphericalVideo\n\
         xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\"\n\
         xmlns:GSpherical=\"http://ns.google.com/videos/1.0/spherical/\">",
    );
    x.push_str("<GSpherical:Spherical>true</GSpherical:Spherical>");
    x.push_str("<GSpherical:Stitched>true</GSpherical:Stitched>");
    x.push_str(&format!(
        "<GSpherical:StitchingSoftware>{}</GSpherical:StitchingSoftware>",
        xml::escape(crate::v2::SOURCE)
    ));
    x.push_str("<GSpherical:ProjectionType>equirectangular</GSpherical:ProjectionType>");
    match stereo {
        StereoMode::Mono => {}
        StereoMode::TopBottom | StereoMode::LeftRight => x.push_str(&format!(
            "<GSpherical:StereoMode>{}</GSpherical:StereoMode>",
            stereo.describe()
        )),
        other => {
            return Err(Error::unfit(format!(
                "Spherical Video V1 has no stereo mode {}",
                other.describe()
            )))
        }
    }
    if *mapping != Mapping::FULL {
        let crop = Crop::of(mapping, w, h).expect("equirectangular");
        x.push_str(&crop.elements("GSpherical"));
    }
    x.push_str("</rdf:SphericalVideo>");
    Ok(x)
}

/// The `uuid` box holding `xml`.
pub fn node(xml: &str) -> Node {
    let mut p = UUID.to_vec();
    p.extend_from_slice(xml.as_bytes());
    Node::leaf(b"uuid", p)
}

/// Whether a `uuid` box's payload is V1's.
pub fn is_v1(payload: &[u8]) -> bool {
    payload.starts_with(&UUID)
}

/// What a V1 `uuid` payload says.
pub fn parse(payload: &[u8]) -> Result<V1, Error> {
    let text = String::from_utf8_lossy(payload.get(16..).unwrap_or_default());
    let get = |k: &str| xml::value(&text, k).map(str::to_string);
    let spherical = get("Spherical")
        .ok_or_else(|| Error::malformed("the GSpherical XML has no Spherical element"))?
        .eq_ignore_ascii_case("true");
    Ok(V1 {
        spherical,
        projection_type: get("ProjectionType").unwrap_or_default(),
        stereo_mode: get("StereoMode"),
        crop: Crop::parse(&text),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::Kind;

    #[test]
    fn xml_round_trips() {
        let x = xml(&Mapping::FULL, StereoMode::TopBottom, 64, 32).unwrap();
        // The spatial-media tool's own elements, in its order.
        assert!(x.contains(
            "<GSpherical:Spherical>true</GSpherical:Spherical>\
             <GSpherical:Stitched>true</GSpherical:Stitched>"
        ));
        let v = parse(&node(&x).to_bytes()[8..]).unwrap();
        assert_eq!(v.mapping(), Some(Mapping::FULL));
        assert_eq!(v.stereo(), Some(StereoMode::TopBottom));
        let vr180 = Kind::HalfEquirect.mapping();
        let x = xml(&vr180, StereoMode::LeftRight, 1024, 1024).unwrap();
        let v = parse(&node(&x).to_bytes()[8..]).unwrap();
        assert_eq!(v.mapping(), Some(vr180));
        assert_eq!(v.crop.unwrap().full_width, 2048);
        assert!(xml(&Mapping::Cube, StereoMode::Mono, 96, 64).is_err());
        assert!(is_v1(&node("").to_bytes()[8..]));
    }
}
