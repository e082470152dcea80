//! What a reader reads: a file, or bytes in memory. Every format has one decoder, which
//! takes an [`Input`]: [`crate::read`] opens the file, [`crate::read_bytes`] lends the
//! bytes, and the decoder asks the input for a buffered, seekable reader
//! ([`Input::reader`]), its length (the bound on what a header may declare, `bounds.rs`)
//! and positioned reads ([`Input::read_at`], for OpenEXR's blocks read on all cores).

use crate::Error;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// A file opened to read, or bytes in memory, with the name its errors give.
pub(crate) struct Input<'a> {
    name: PathBuf,
    len: u64,
    data: Data<'a>,
}

enum Data<'a> {
    File(File),
    Bytes(&'a [u8]),
}

impl Input<'static> {
    /// Opens `path` to read, refusing directories (which open fine on Unix but fail to
    /// read with an unhelpful system error).
    pub(crate) fn open(path: &Path) -> Result<Input<'static>, Error> {
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let meta = file.metadata().map_err(|e| Error::io(path, e))?;
        if meta.is_dir() {
            return Err(Error::input(
                path,
                "is a directory, not an image file".into(),
            ));
        }
        Ok(Input {
            name: path.to_path_buf(),
            len: meta.len(),
            data: Data::File(file),
        })
    }
}

impl<'a> Input<'a> {
    /// `bytes`, called `name` in messages.
    pub(crate) fn bytes(name: &Path, bytes: &'a [u8]) -> Input<'a> {
        Input {
            name: name.to_path_buf(),
            len: bytes.len() as u64,
            data: Data::Bytes(bytes),
        }
    }

    /// The name errors give: the file's path, or the name the bytes were given.
    pub(crate) fn path(&self) -> &Path {
        &self.name
    }

    /// The length in bytes (a file's, when it was opened).
    pub(crate) fn len(&self) -> u64 {
        self.len
    }

    /// A buffered reader from the first byte, `capacity` bytes of buffer for a file. Each
    /// reader keeps its own place (a file's is read with positioned reads), so several
    /// may read one input at once.
    pub(crate) fn reader_with_capacity(&self, capacity: usize) -> io::Result<Reader<'_>> {
        Ok(match &self.data {
            Data::File(file) => Reader::File(BufReader::with_capacity(
                capacity,
                At {
                    file,
                    pos: 0,
                    len: self.len,
                },
            )),
            Data::Bytes(b) => Reader::Bytes(Cursor::new(b)),
        })
    }

    /// A buffered reader from the first byte.
    pub(crate) fn reader(&self) -> io::Result<Reader<'_>> {
        self.reader_with_capacity(8 * 1024)
    }

    /// Fills `buf` from byte `at` without moving any reader (an error at the end).
    pub(crate) fn read_at(&self, buf: &mut [u8], at: u64) -> io::Result<()> {
        match &self.data {
            Data::File(f) => file_read_at(f, buf, at),
            Data::Bytes(b) => {
                let src = usize::try_from(at)
                    .ok()
                    .and_then(|at| b.get(at..)?.get(..buf.len()))
                    .ok_or_else(|| io::Error::from(io::ErrorKind::UnexpectedEof))?;
                buf.copy_from_slice(src);
                Ok(())
            }
        }
    }

    /// The whole input: borrowed when it is bytes, read when it is a file.
    pub(crate) fn all(&self) -> io::Result<std::borrow::Cow<'a, [u8]>> {
        match &self.data {
            Data::File(_) => {
                let mut bytes = Vec::with_capacity(self.len as usize);
                self.reader()?.read_to_end(&mut bytes)?;
                Ok(std::borrow::Cow::Owned(bytes))
            }
            Data::Bytes(b) => Ok(std::borrow::Cow::Borrowed(b)),
        }
    }
}

#[cfg(unix)]
fn file_read_at(file: &File, buf: &mut [u8], at: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, at)
}

#[cfg(not(unix))]
fn file_read_at(file: &File, mut buf: &mut [u8], mut at: u64) -> io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match file.seek_read(buf, at) {
            Ok(0) => return Err(io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => {
                buf = &mut buf[n..];
                at += n as u64;
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// A file read from a place of its own, with positioned reads (the file's shared cursor
/// is never moved).
pub(crate) struct At<'a> {
    file: &'a File,
    pos: u64,
    len: u64,
}

impl Read for At<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        #[cfg(unix)]
        let n = std::os::unix::fs::FileExt::read_at(self.file, buf, self.pos)?;
        #[cfg(not(unix))]
        let n = std::os::windows::fs::FileExt::seek_read(self.file, buf, self.pos)?;
        self.pos += n as u64;
        Ok(n)
    }
}

impl Seek for At<'_> {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let pos = match to {
            SeekFrom::Start(n) => Some(n),
            SeekFrom::End(d) => self.len.checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        self.pos = pos
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "seek before the start"))?;
        Ok(self.pos)
    }
}

/// A buffered, seekable reader of an [`Input`].
pub(crate) enum Reader<'a> {
    /// A file through a buffer.
    File(BufReader<At<'a>>),
    /// Bytes in memory.
    Bytes(Cursor<&'a [u8]>),
}

impl Reader<'_> {
    /// Skips `n` bytes forward or back, keeping what is buffered where it can.
    pub(crate) fn seek_relative(&mut self, n: i64) -> io::Result<()> {
        match self {
            Reader::File(r) => r.seek_relative(n),
            Reader::Bytes(r) => r.seek(SeekFrom::Current(n)).map(|_| ()),
        }
    }
}

impl Read for Reader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Reader::File(r) => r.read(buf),
            Reader::Bytes(r) => r.read(buf),
        }
    }
    fn read_exact(&mut self, buf: &mut [u8]) -> io::Result<()> {
        match self {
            Reader::File(r) => r.read_exact(buf),
            Reader::Bytes(r) => r.read_exact(buf),
        }
    }
}

impl BufRead for Reader<'_> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        match self {
            Reader::File(r) => r.fill_buf(),
            Reader::Bytes(r) => r.fill_buf(),
        }
    }
    fn consume(&mut self, n: usize) {
        match self {
            Reader::File(r) => r.consume(n),
            Reader::Bytes(r) => r.consume(n),
        }
    }
}

impl Seek for Reader<'_> {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        match self {
            Reader::File(r) => r.seek(to),
            Reader::Bytes(r) => r.seek(to),
        }
    }
}
