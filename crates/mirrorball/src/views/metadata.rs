//! The EXIF a panorama's views keep: when it was taken (`DateTimeOriginal`, with
//! `OffsetTimeOriginal` and `SubSecTimeOriginal`) and where (the GPS IFD), read with
//! `kamadak-exif` from a JPEG (or PNG, WebP) source. JPEG views carry them in an `APP1`
//! segment; every container's views have them recorded in `transforms.json`.

use exif::{Context, Field, In, Tag, Value};
use std::path::Path;

/// The fields a panorama's views keep.
#[derive(Clone, Debug)]
pub struct Carried {
    fields: Vec<Field>,
}

/// Whether a field is kept: the capture time's, or the GPS IFD's.
fn kept(f: &Field) -> bool {
    f.ifd_num == In::PRIMARY
        && (matches!(
            f.tag,
            Tag::DateTimeOriginal | Tag::OffsetTimeOriginal | Tag::SubSecTimeOriginal
        ) || (f.tag.context() == Context::Gps && f.tag != Tag::GPSInfoIFDPointer))
}

/// The fields of `path` the views keep; `None` when it has no EXIF, none of them, or EXIF
/// that cannot be read (the views are made all the same).
pub fn read(path: &Path) -> Option<Carried> {
    let file = std::fs::File::open(path).ok()?;
    let mut reader = std::io::BufReader::new(file);
    let exif = exif::Reader::new().read_from_container(&mut reader).ok()?;
    let fields: Vec<Field> = exif.fields().filter(|f| kept(f)).cloned().collect();
    (!fields.is_empty()).then_some(Carried { fields })
}

/// Degrees of a GPS latitude or longitude (degrees, minutes, seconds), negative towards
/// `negative` (`S`, `W`).
fn degrees(c: &Carried, value: Tag, sign: Tag, negative: u8) -> Option<f64> {
    let v = c.fields.iter().find(|f| f.tag == value)?;
    let Value::Rational(r) = &v.value else {
        return None;
    };
    let d = r
        .iter()
        .zip([1.0, 60.0, 3600.0])
        .map(|(r, k)| r.to_f64() / k)
        .sum::<f64>();
    let s = c.fields.iter().find(|f| f.tag == sign);
    let neg = s.is_some_and(|s| matches!(&s.value, Value::Ascii(a) if a.first().and_then(|a| a.first()) == Some(&negative)));
    d.is_finite().then_some(if neg { -d } else { d })
}

impl Carried {
    /// The fields as JSON: each by its EXIF name (text as written, others as
    /// `kamadak-exif` shows them), and `latitude`, `longitude` (degrees, north and east
    /// positive) and `altitude` (metres) where the GPS fields give them.
    pub fn json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for f in &self.fields {
            let text = match &f.value {
                Value::Ascii(a) => a
                    .iter()
                    .map(|s| String::from_utf8_lossy(s).into_owned())
                    .collect::<Vec<_>>()
                    .join(" "),
                _ => f.display_value().with_unit(f).to_string(),
            };
            m.insert(f.tag.to_string(), text.into());
        }
        if let Some(lat) = degrees(self, Tag::GPSLatitude, Tag::GPSLatitudeRef, b'S') {
            m.insert("latitude".into(), lat.into());
        }
        if let Some(lon) = degrees(self, Tag::GPSLongitude, Tag::GPSLongitudeRef, b'W') {
            m.insert("longitude".into(), lon.into());
        }
        let alt = self.fields.iter().find(|f| f.tag == Tag::GPSAltitude);
        if let Some(Value::Rational(r)) = alt.map(|f| &f.value) {
            let below = self.fields.iter().any(|f| {
                f.tag == Tag::GPSAltitudeRef
                    && matches!(&f.value, Value::Byte(b) if b.first() == Some(&1))
            });
            if let Some(a) = r.first().map(|r| r.to_f64()).filter(|a| a.is_finite()) {
                m.insert("altitude".into(), (if below { -a } else { a }).into());
            }
        }
        serde_json::Value::Object(m)
    }

    /// The fields as a JPEG `APP1` EXIF segment (marker, length, `Exif\0\0`, TIFF data);
    /// `None` when they do not fit in one segment or cannot be encoded.
    pub fn app1(&self) -> Option<Vec<u8>> {
        let mut w = exif::experimental::Writer::new();
        for f in &self.fields {
            w.push_field(f);
        }
        let mut tiff = std::io::Cursor::new(Vec::new());
        w.write(&mut tiff, false).ok()?;
        let tiff = tiff.into_inner();
        let len = u16::try_from(2 + 6 + tiff.len()).ok()?;
        let mut seg = vec![0xFF, 0xE1];
        seg.extend_from_slice(&len.to_be_bytes());
        seg.extend_from_slice(b"Exif\0\0");
        seg.extend_from_slice(&tiff);
        Some(seg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use exif::Rational;

    #[test]
    fn carried_fields_round_trip_through_app1() {
        let c = Carried {
            fields: vec![
                Field {
                    tag: Tag::DateTimeOriginal,
                    ifd_num: In::PRIMARY,
                    value: Value::Ascii(vec![b"2024:05:01 12:34:56".to_vec()]),
                },
                Field {
                    tag: Tag::GPSLatitudeRef,
                    ifd_num: In::PRIMARY,
                    value: Value::Ascii(vec![b"S".to_vec()]),
                },
                Field {
                    tag: Tag::GPSLatitude,
                    ifd_num: In::PRIMARY,
                    value: Value::Rational(vec![
                        Rational::from((33, 1)),
                        Rational::from((30, 1)),
                        Rational::from((0, 1)),
                    ]),
                },
            ],
        };
        let j = c.json();
        assert_eq!(j["DateTimeOriginal"], "2024:05:01 12:34:56");
        assert_eq!(j["latitude"], -33.5);
        let seg = c.app1().unwrap();
        let back = exif::Reader::new().read_raw(seg[10..].to_vec()).unwrap();
        let date = back.get_field(Tag::DateTimeOriginal, In::PRIMARY).unwrap();
        assert_eq!(date.display_value().to_string(), "2024-05-01 12:34:56");
        assert!(back.get_field(Tag::GPSLatitude, In::PRIMARY).is_some());
    }
}
