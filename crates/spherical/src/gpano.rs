//! Photo Sphere XMP (Google's `GPano` namespace, `http://ns.google.com/photos/1.0/panorama/`)
//! for 360° photos: an equirectangular picture, whole or cropped from a full panorama
//! (VR180: the middle half of one twice as wide). The packet is what an XMP reader finds in
//! a JPEG's `APP1` segment after `http://ns.adobe.com/xap/1.0/\0` or in a PNG's `iTXt`
//! chunk `XML:com.adobe.xmp` (mirrorball-io puts it there).

use crate::mapping::{Crop, Mapping};
use crate::xml;
use crate::Error;
use mirrorball_core::{Layout, Projection, Stereo};

/// The PNG `iTXt` keyword that holds an XMP packet (XMP Specification Part 3, §1.1.5).
pub const PNG_KEYWORD: &str = "XML:com.adobe.xmp";

/// What starts a JPEG `APP1` segment holding an XMP packet (Part 3, §1.1.3).
pub const JPEG_SIGNATURE: &[u8] = b"http://ns.adobe.com/xap/1.0/\0";

/// The namespace.
pub const NAMESPACE: &str = "http://ns.google.com/photos/1.0/panorama/";

/// The packet for a `w`×`h` picture of projection `p` laid out as `layout` with `stereo`,
/// if it is a single equirectangular panorama (mirrorball's `latlong`, or a
/// `half-equirect` cropped from one); stereo pairs and other projections get none.
pub fn for_picture(
    p: &Projection,
    layout: Option<Layout>,
    stereo: Stereo,
    w: u32,
    h: u32,
) -> Option<String> {
    if stereo != Stereo::Mono {
        return None;
    }
    let crop = Crop::of(&Mapping::of(p, layout)?, w, h)?;
    Some(packet(&crop))
}

/// The XMP packet stating `crop` of an equirectangular panorama.
pub fn packet(crop: &Crop) -> String {
    format!(
        "<?xpacket begin=\"\u{feff}\" id=\"W5M0MpCehiHzreSzNTczkc9d\"?>\n\
         <x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n\
         <rdf:RDF xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n\
         <rdf:Description rdf:about=\"\" xmlns:GPano=\"{NAMESPACE}\">\n\
         <GPano:ProjectionType>equirectangular</GPano:ProjectionType>\n\
         <GPano:UsePanoramaViewer>True</GPano:UsePanoramaViewer>\n\
         <GPano:StitchingSoftware>{}</GPano:StitchingSoftware>\n\
         {}\n\
         </rdf:Description>\n\
         </rdf:RDF>\n\
         </x:xmpmeta>\n\
         <?xpacket end=\"w\"?>",
        xml::escape(crate::v2::SOURCE),
        crop.elements("GPano").replace("><GPano:", ">\n<GPano:"),
    )
}

/// What a packet's GPano properties say: `None` when it has none (no `ProjectionType`);
/// else the crop for an equirectangular one (the picture's own size, `w`×`h`, when the crop
/// fields are absent: a whole panorama), or why it is not one mirrorball reads.
pub fn parse(xmp: &str, w: u32, h: u32) -> Option<Result<Crop, Error>> {
    if !xmp.contains(NAMESPACE) {
        return None;
    }
    let projection = xml::value(xmp, "ProjectionType")?;
    if projection != "equirectangular" {
        return Some(Err(Error::malformed(format!(
            "GPano:ProjectionType is '{projection}', not equirectangular"
        ))));
    }
    Some(Ok(Crop::parse(xmp).unwrap_or(Crop {
        full_width: w,
        full_height: h,
        width: w,
        height: h,
        left: 0,
        top: 0,
    })))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    #[test]
    fn lat_long_and_vr180_round_trip() {
        let ll = ProjectionKind::LatLong.default_projection();
        let x = for_picture(&ll, None, Stereo::Mono, 4096, 2048).unwrap();
        let c = parse(&x, 4096, 2048).unwrap().unwrap();
        assert_eq!(c.mapping(), Some(Mapping::FULL));
        assert_eq!((c.full_width, c.left), (4096, 0));
        let half = ProjectionKind::HalfEquirect.default_projection();
        let x = for_picture(&half, None, Stereo::Mono, 2048, 2048).unwrap();
        let c = parse(&x, 2048, 2048).unwrap().unwrap();
        assert_eq!(
            (c.full_width, c.full_height, c.left, c.top),
            (4096, 2048, 1024, 0)
        );
        assert_eq!(Mapping::of(&half, None), c.mapping());
        // No GPano for a pair, a cube or a sphere map.
        assert_eq!(for_picture(&ll, None, Stereo::SideBySide, 64, 32), None);
        let sphere = ProjectionKind::Sphere.default_projection();
        assert_eq!(for_picture(&sphere, None, Stereo::Mono, 64, 64), None);
        assert_eq!(parse("<x/>", 1, 1), None);
    }

    #[test]
    fn packets_from_other_tools_are_read() {
        // ExifTool's form (as in Google's sample), attributes and elements mixed.
        let x = "<x:xmpmeta xmlns:x='adobe:ns:meta/'><rdf:RDF xmlns:rdf='http://www.w3.org/1999/02/22-rdf-syntax-ns#'>\
            <rdf:Description rdf:about='' xmlns:GPano='http://ns.google.com/photos/1.0/panorama/' \
             GPano:ProjectionType='equirectangular' GPano:FullPanoWidthPixels='8000'>\
            <GPano:FullPanoHeightPixels>4000</GPano:FullPanoHeightPixels>\
            <GPano:CroppedAreaImageWidthPixels>8000</GPano:CroppedAreaImageWidthPixels>\
            <GPano:CroppedAreaImageHeightPixels>2000</GPano:CroppedAreaImageHeightPixels>\
            <GPano:CroppedAreaLeftPixels>0</GPano:CroppedAreaLeftPixels>\
            <GPano:CroppedAreaTopPixels>1000</GPano:CroppedAreaTopPixels>\
            </rdf:Description></rdf:RDF></x:xmpmeta>";
        let c = parse(x, 8000, 2000).unwrap().unwrap();
        assert_eq!(
            c.mapping(),
            Some(Mapping::Equirect {
                hfov: 360.0,
                vfov: 90.0
            })
        );
        let cyl = x.replace("'equirectangular'", "'cylindrical'");
        assert!(parse(&cyl, 1, 1).unwrap().is_err());
        // Whole panoramas may leave the crop out.
        let bare = format!("<d xmlns:GPano='{NAMESPACE}' GPano:ProjectionType='equirectangular'/>");
        assert_eq!(
            parse(&bare, 64, 32).unwrap().unwrap().mapping(),
            Some(Mapping::FULL)
        );
    }
}
