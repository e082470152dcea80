//! PNG text chunks (PNG specification, 3rd edition, §11.3.3): `tEXt` chunks written right
//! after `IHDR` as the encoder streams the file out, and `tEXt` and uncompressed `iTXt`
//! chunks found anywhere in a file read back.

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

/// CRC-32 as PNG computes it (ISO 3309, reflected polynomial 0xEDB88320), over the chunk
/// type and data.
fn crc32(bytes: &[u8]) -> u32 {
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
