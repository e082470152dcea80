//! Text in 8-bit image files: PNG text chunks (PNG specification, 3rd edition, §11.3.3),
//! `tEXt` written right after `IHDR` as the encoder streams the file out and `tEXt` and
//! uncompressed `iTXt` read back from anywhere in the file; and a JPEG comment segment (`COM`,
//! ITU T.81 §B.2.4.5) of `key=value` lines, written after `SOI` and the JFIF `APP0` segment
//! and read back from before the first scan.

use mirrorball_spherical::crc32;
use std::io::{self, Read, Seek, SeekFrom, Write};

/// Bytes before the first chunk after `IHDR`: the 8-byte signature and the 25-byte `IHDR`
/// chunk (length, type, 13 bytes of data, CRC), which the specification puts first.
const AFTER_IHDR: usize = 8 + 25;

/// Largest text chunk read back; longer ones are skipped.
const MAX_TEXT: u32 = 1 << 16;

/// A `tEXt` chunk: `keyword NUL text`, with its length and CRC. The keyword and text must be
/// Latin-1 (ours are ASCII).
pub(crate) fn text_chunk(keyword: &str, text: &str) -> Vec<u8> {
    let mut body = b"tEXt".to_vec();
    body.extend_from_slice(keyword.as_bytes());
    body.push(0);
    body.extend_from_slice(text.as_bytes());
    let mut chunk = ((body.len() - 4) as u32).to_be_bytes().to_vec();
    chunk.extend_from_slice(&body);
    chunk.extend_from_slice(&crc32(&body).to_be_bytes());
    chunk
}

/// An uncompressed `iTXt` chunk (§11.3.3.4): `keyword NUL 0 0 NUL NUL text`, no language
/// tag or translated keyword, the text UTF-8. An XMP packet goes in one keyed
/// `XML:com.adobe.xmp` (XMP Specification Part 3, §1.1.5).
pub(crate) fn itxt_chunk(keyword: &str, text: &str) -> Vec<u8> {
    let mut body = b"iTXt".to_vec();
    body.extend_from_slice(keyword.as_bytes());
    body.extend_from_slice(&[0, 0, 0, 0, 0]);
    body.extend_from_slice(text.as_bytes());
    let mut chunk = ((body.len() - 4) as u32).to_be_bytes().to_vec();
    chunk.extend_from_slice(&body);
    chunk.extend_from_slice(&crc32(&body).to_be_bytes());
    chunk
}

/// A writer that passes a PNG stream through, putting `chunks` in right after `IHDR`.
pub(crate) struct WithText<W: Write> {
    inner: W,
    chunks: Vec<u8>,
    written: usize,
}

impl<W: Write> WithText<W> {
    /// Passes the PNG written into it on to `inner` with `chunks` (from [`text_chunk`]) added.
    pub(crate) fn new(inner: W, chunks: Vec<u8>) -> WithText<W> {
        WithText {
            inner,
            chunks,
            written: 0,
        }
    }
}

impl<W: Write> Write for WithText<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if !self.chunks.is_empty() && self.written + buf.len() >= AFTER_IHDR {
            let k = AFTER_IHDR - self.written;
            self.inner.write_all(&buf[..k])?;
            self.inner.write_all(&std::mem::take(&mut self.chunks))?;
            self.inner.write_all(&buf[k..])?;
        } else {
            self.inner.write_all(buf)?;
        }
        self.written += buf.len();
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// The `(keyword, text)` pairs of a PNG's `tEXt` and uncompressed `iTXt` chunks, walking the
/// chunks from the start of `r` to `IEND` (skipping the others' data) and leaving `r` at
/// its start. A malformed or cut-off stream ends the walk: the decoder reports it.
pub(crate) fn read_texts<R: Read + Seek>(r: &mut R) -> io::Result<Vec<(String, String)>> {
    let mut texts = Vec::new();
    let mut sig = [0u8; 8];
    if r.read_exact(&mut sig).is_ok() && sig == *b"\x89PNG\r\n\x1a\n" {
        let mut head = [0u8; 8];
        while r.read_exact(&mut head).is_ok() {
            let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]);
            let kind = &head[4..8];
            if kind == b"IEND" {
                break;
            }
            if (kind == b"tEXt" || kind == b"iTXt") && len <= MAX_TEXT {
                let mut data = vec![0u8; len as usize];
                if r.read_exact(&mut data).is_err() {
                    break;
                }
                if let Some(t) = parse_text(kind == b"iTXt", &data) {
                    texts.push(t);
                }
                r.seek(SeekFrom::Current(4))?;
            } else {
                r.seek(SeekFrom::Current(i64::from(len) + 4))?;
            }
        }
    }
    r.seek(SeekFrom::Start(0))?;
    Ok(texts)
}

/// A text chunk's keyword and text: `tEXt` is `keyword NUL text` in Latin-1; `iTXt` is
/// `keyword NUL flag method language NUL translated NUL text` in UTF-8 (compressed ones,
/// flag 1, are not read).
fn parse_text(international: bool, data: &[u8]) -> Option<(String, String)> {
    let nul = data.iter().position(|&b| b == 0)?;
    let latin1 = |b: &[u8]| b.iter().map(|&c| c as char).collect::<String>();
    let keyword = latin1(&data[..nul]);
    let rest = &data[nul + 1..];
    if !international {
        return Some((keyword, latin1(rest)));
    }
    let (&flag, rest) = rest.split_first()?;
    let rest = rest.get(1..)?; // compression method
    if flag != 0 {
        return None;
    }
    let lang_end = rest.iter().position(|&b| b == 0)?;
    let rest = &rest[lang_end + 1..];
    let trans_end = rest.iter().position(|&b| b == 0)?;
    let text = std::str::from_utf8(&rest[trans_end + 1..]).ok()?;
    Some((keyword, text.to_string()))
}

/// JPEG markers: start of image, the JFIF application segment, comment, start of scan, end
/// of image.
const SOI: u8 = 0xD8;
const APP0: u8 = 0xE0;
const COM: u8 = 0xFE;
const SOS: u8 = 0xDA;
const EOI: u8 = 0xD9;

/// JPEG's application segment 1, which holds Exif and XMP.
const APP1: u8 = 0xE1;

/// `jpeg` (a whole file) with a comment segment holding `pairs` as `key=value` lines, put
/// after `SOI` and, when there is one, the `APP0` segment (JFIF wants `APP0` first).
pub(crate) fn with_jpeg_comment(jpeg: Vec<u8>, pairs: &[(&str, String)]) -> Vec<u8> {
    let text: Vec<String> = pairs.iter().map(|(k, v)| format!("{k}={v}")).collect();
    with_jpeg_segment(jpeg, COM, text.join("\n").as_bytes())
}

/// `jpeg` with an `APP1` segment holding the XMP packet `xmp` after the XMP signature
/// (XMP Specification Part 3, §1.1.3), put where [`with_jpeg_comment`] puts its segment.
pub(crate) fn with_jpeg_xmp(jpeg: Vec<u8>, xmp: &str) -> Vec<u8> {
    let mut body = mirrorball_spherical::gpano::JPEG_SIGNATURE.to_vec();
    body.extend_from_slice(xmp.as_bytes());
    with_jpeg_segment(jpeg, APP1, &body)
}

/// `jpeg` with a segment of `marker` holding `body` after `SOI` and any `APP0`; unchanged
/// when `body` is empty or longer than a segment holds.
fn with_jpeg_segment(jpeg: Vec<u8>, marker: u8, body: &[u8]) -> Vec<u8> {
    if body.is_empty() || body.len() > 65533 || jpeg.len() < 2 || jpeg[..2] != [0xFF, SOI] {
        return jpeg;
    }
    let mut at = 2;
    if jpeg.len() >= 6 && jpeg[2] == 0xFF && jpeg[3] == APP0 {
        at = (4 + usize::from(u16::from_be_bytes([jpeg[4], jpeg[5]]))).min(jpeg.len());
    }
    let mut out = Vec::with_capacity(jpeg.len() + body.len() + 4);
    out.extend_from_slice(&jpeg[..at]);
    out.extend_from_slice(&[0xFF, marker]);
    out.extend_from_slice(&((body.len() + 2) as u16).to_be_bytes());
    out.extend_from_slice(body);
    out.extend_from_slice(&jpeg[at..]);
    out
}

/// The `key=value` lines of a JPEG's comment segments before its first scan (other lines
/// are skipped). A malformed stream ends the walk: the decoder reports it.
pub(crate) fn jpeg_comments(jpeg: &[u8]) -> Vec<(String, String)> {
    let mut pairs = Vec::new();
    for body in jpeg_segments(jpeg, COM) {
        let text = String::from_utf8_lossy(body);
        for line in text.lines() {
            if let Some((k, v)) = line.split_once('=') {
                pairs.push((k.to_string(), v.to_string()));
            }
        }
    }
    pairs
}

/// The bodies of a JPEG's segments of `marker` before its first scan. A malformed stream
/// ends the walk.
fn jpeg_segments(jpeg: &[u8], want: u8) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut i = 2;
    while i + 4 <= jpeg.len() && jpeg[i] == 0xFF {
        let marker = jpeg[i + 1];
        if marker == 0xFF {
            i += 1; // fill byte
            continue;
        }
        if marker == SOS || marker == EOI {
            break;
        }
        let len = usize::from(u16::from_be_bytes([jpeg[i + 2], jpeg[i + 3]]));
        let Some(body) = jpeg.get(i + 4..i + 2 + len).filter(|_| len >= 2) else {
            break;
        };
        if marker == want {
            out.push(body);
        }
        i += 2 + len;
    }
    out
}

/// The XMP packet of a PNG (an `iTXt` chunk keyed `XML:com.adobe.xmp`) or a JPEG (an `APP1`
/// segment after the XMP signature), if the file has one; other files have none.
pub fn read_xmp(path: &std::path::Path) -> Result<Option<String>, crate::Error> {
    use mirrorball_spherical::gpano::{JPEG_SIGNATURE, PNG_KEYWORD};
    let err = |e| crate::Error::io(path, e);
    let mut file = io::BufReader::new(std::fs::File::open(path).map_err(err)?);
    let mut magic = [0u8; 2];
    let n = file.read(&mut magic).map_err(err)?;
    file.seek(SeekFrom::Start(0)).map_err(err)?;
    if magic[..n] == [0xFF, SOI] {
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(err)?;
        let xmp = jpeg_segments(&bytes, APP1)
            .into_iter()
            .find_map(|b| b.strip_prefix(JPEG_SIGNATURE))
            .map(|b| String::from_utf8_lossy(b).into_owned());
        return Ok(xmp);
    }
    let texts = read_texts(&mut file).map_err(err)?;
    Ok(texts
        .into_iter()
        .find(|(k, _)| k == PNG_KEYWORD)
        .map(|(_, v)| v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_matches_the_specification_check_value() {
        // The CRC-32 check value (ISO 3309 / ITU-T V.42) of "123456789".
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        // The IEND chunk every PNG ends with: its CRC is AE 42 60 82.
        assert_eq!(crc32(b"IEND"), 0xAE42_6082);
    }

    #[test]
    fn itxt_is_read() {
        let data = b"mirrorball:projection\0\0\0en\0\0sphere:look=0,0,-1";
        assert_eq!(
            parse_text(true, data),
            Some((
                "mirrorball:projection".to_string(),
                "sphere:look=0,0,-1".to_string()
            ))
        );
        // Compressed iTXt is skipped.
        assert_eq!(parse_text(true, b"k\0\x01\0\0\0x"), None);
    }
}
