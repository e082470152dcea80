//! Square RGBA 8-bit PNG pictures in memory: the images Babylon.js's `.env` files and glTF's
//! `EXT_lights_image_based` hold (RGBD texels, four channels, no colour conversion: no
//! `sRGB`/`gAMA` chunk, so the browser hands the bytes over unchanged).

use crate::Error;
use std::path::Path;

/// One face of one level: `size × size` RGBA 8-bit texels, top row first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rgba8Face {
    /// The edge in texels.
    pub size: u32,
    /// `size² · 4` bytes, row by row, top row first.
    pub texels: Vec<u8>,
}

/// The PNG file of `face`; `path` names the file it goes into, for messages.
pub(crate) fn encode(path: &Path, face: &Rgba8Face) -> Result<Vec<u8>, Error> {
    let fail = |e: png::EncodingError| Error::input(path, e.to_string());
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, face.size, face.size);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().map_err(fail)?;
    wr.write_image_data(&face.texels).map_err(fail)?;
    wr.finish().map_err(fail)?;
    Ok(out)
}

/// Decodes `bytes` as a square RGBA 8-bit PNG of edge `size` (what `path` says it holds).
pub(crate) fn decode(path: &Path, bytes: &[u8], size: u32, what: &str) -> Result<Rgba8Face, Error> {
    let bad = |p: String| Error::input(path, format!("{what}: {p}"));
    let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .map_err(|e| bad(e.to_string()))?;
    let (w, h) = {
        let info = dec.info();
        (info.width, info.height)
    };
    if (w, h) != (size, size) {
        return Err(bad(format!("is {w}×{h}, expected {size}×{size}")));
    }
    let (color, depth) = dec.output_color_type();
    if color != png::ColorType::Rgba || depth != png::BitDepth::Eight {
        return Err(bad(format!("is {color:?} {depth:?}, expected RGBA 8-bit")));
    }
    let mut buf = vec![
        0;
        dec.output_buffer_size()
            .ok_or_else(|| bad("too large".into()))?
    ];
    let info = dec.next_frame(&mut buf).map_err(|e| bad(e.to_string()))?;
    buf.truncate(info.buffer_size());
    Ok(Rgba8Face { size, texels: buf })
}
