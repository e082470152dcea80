//! Pictures for the report: 8-bit RGBA encoded as PNG in memory, through the `png` crate
//! (no file is written here; the CLI writes the report), and Base64, so that heat maps can
//! be embedded in SVG as `data:` URIs.

/// Encodes `rgba` (`w·h·4` bytes, top row first) as a PNG file's bytes.
///
/// # Panics
/// If `rgba.len() != w·h·4`.
pub fn encode_rgba(w: u32, h: u32, rgba: &[u8]) -> Vec<u8> {
    assert_eq!(rgba.len(), (w as usize) * (h as usize) * 4, "rgba size");
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    // Writing into a Vec cannot fail, and the header matches the data (checked above).
    let mut wr = enc.write_header().expect("PNG header");
    wr.write_image_data(rgba).expect("PNG data");
    wr.finish().expect("PNG end");
    out
}

/// Standard Base64 (RFC 4648 §4) with padding.
pub fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(data.len().div_ceil(3) * 4);
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        s.push(A[(n >> 18) as usize & 63] as char);
        s.push(A[(n >> 12) as usize & 63] as char);
        s.push(if c.len() > 1 {
            A[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        s.push(if c.len() > 2 {
            A[n as usize & 63] as char
        } else {
            '='
        });
    }
    s
}

/// A PNG as a `data:` URI.
pub fn data_uri(w: u32, h: u32, rgba: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(&encode_rgba(w, h, rgba)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648() {
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"f"), "Zg==");
    }

    #[test]
    fn pngs_decode_to_the_pixels_given() {
        // A heat-map-like picture (flat runs) and noise, odd sizes.
        let (w, h) = (37u32, 11u32);
        let mut rgba = Vec::new();
        let mut x = 12345u32;
        for i in 0..w * h {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            let v = if i < w * h / 2 {
                (i / 7) as u8
            } else {
                (x >> 16) as u8
            };
            rgba.extend_from_slice(&[v, v.wrapping_mul(3), 255 - v, (x >> 24) as u8]);
        }
        let bytes = encode_rgba(w, h, &rgba);
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; dec.output_buffer_size().unwrap()];
        let info = dec.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (w, h));
        assert_eq!(info.color_type, png::ColorType::Rgba);
        assert_eq!(&buf[..info.buffer_size()], &rgba[..]);
    }
}
