//! ISO base media file format boxes (ISO/IEC 14496-12 §4.2, the same as QuickTime's
//! atoms): headers read with every declared size checked against the room its container
//! really has, and a tree of the boxes inside `moov` that can be changed and written again.
//!
//! A box is `size` (32 bits, big-endian), `type` (four bytes), and when `size` is 1 a 64-bit
//! `largesize` after the type; `size` 0 means "to the end of the container" (the file, at
//! the top level). Sizes count the header.

use crate::Error;

/// A box type.
pub type FourCC = [u8; 4];

/// Where a box is and how big: the header as read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// The box type.
    pub kind: FourCC,
    /// Offset of the box's first byte in its file or buffer.
    pub start: u64,
    /// Header bytes: 8, or 16 with a `largesize`.
    pub header_len: u64,
    /// Bytes in all, header included.
    pub size: u64,
}

impl Header {
    /// Offset just past the box.
    pub fn end(&self) -> u64 {
        self.start + self.size
    }

    /// Offset of the box's payload.
    pub fn payload_start(&self) -> u64 {
        self.start + self.header_len
    }
}

/// A four-character code for messages: `'moov'`, or its bytes in hex when not printable.
pub fn name(kind: &FourCC) -> String {
    if kind.iter().all(|b| (0x20..0x7f).contains(b)) {
        format!("'{}'", String::from_utf8_lossy(kind))
    } else {
        format!(
            "0x{:02x}{:02x}{:02x}{:02x}",
            kind[0], kind[1], kind[2], kind[3]
        )
    }
}

/// The header at `start`, of which `head` holds the first bytes (16, or fewer where the
/// container ends sooner), with `room` bytes left in the container from `start`. The
/// declared size must fit the room: a box that claims more than its container holds is a
/// truncated or corrupt file, said so here before anything is allocated for it.
pub fn parse_header(head: &[u8], start: u64, room: u64) -> Result<Header, Error> {
    if room < 8 || head.len() < 8 {
        return Err(Error::malformed(format!(
            "{room} stray bytes at offset {start}, too few for a box header"
        )));
    }
    let size32 = u32::from_be_bytes([head[0], head[1], head[2], head[3]]);
    let kind: FourCC = [head[4], head[5], head[6], head[7]];
    let (header_len, size) = match size32 {
        0 => (8, room),
        1 => {
            if room < 16 || head.len() < 16 {
                return Err(Error::malformed(format!(
                    "box {} at offset {start} declares a 64-bit size but is cut off",
                    name(&kind)
                )));
            }
            let large = u64::from_be_bytes(head[8..16].try_into().expect("eight bytes"));
            if large < 16 {
                return Err(Error::malformed(format!(
                    "box {} at offset {start} declares a 64-bit size of {large} bytes, less than its header",
                    name(&kind)
                )));
            }
            (16, large)
        }
        s if s < 8 => {
            return Err(Error::malformed(format!(
                "box {} at offset {start} declares {s} bytes, less than its header",
                name(&kind)
            )))
        }
        s => (8, u64::from(s)),
    };
    if size > room {
        return Err(Error::malformed(format!(
            "box {} at offset {start} declares {size} bytes, but only {room} remain (the file is truncated or corrupt)",
            name(&kind)
        )));
    }
    Ok(Header {
        kind,
        start,
        header_len,
        size,
    })
}

/// The boxes laid end to end in `bytes`, whose first byte is at offset `base` (for
/// messages). Fewer than 8 bytes left over at the end are returned as the tail (QuickTime
/// ends some lists with a 4-byte zero terminator).
pub fn headers_in(bytes: &[u8], base: u64) -> Result<(Vec<Header>, usize), Error> {
    let mut out = Vec::new();
    let mut at = 0usize;
    while bytes.len() - at >= 8 {
        let room = (bytes.len() - at) as u64;
        let head = &bytes[at..bytes.len().min(at + 16)];
        let h = parse_header(head, base + at as u64, room)?;
        at += h.size as usize;
        out.push(h);
    }
    Ok((out, bytes.len() - at))
}

/// A box held in memory: its type and either its payload as it is, or a head (the bytes
/// before its child boxes: a full box's version and flags, a sample entry's fields), its
/// children, and a tail of stray bytes after them.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// The box type.
    pub kind: FourCC,
    /// What it holds.
    pub body: Body,
}

/// A [`Node`]'s contents.
#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    /// The payload, kept as read.
    Leaf(Vec<u8>),
    /// A container: head bytes, child boxes, tail bytes.
    Tree {
        /// Bytes before the children.
        head: Vec<u8>,
        /// The child boxes, in order.
        children: Vec<Node>,
        /// Bytes after the children (fewer than a box header).
        tail: Vec<u8>,
    },
}

/// The boxes `moov` holds down to each track's sample descriptions, by type: how many head
/// bytes come before the children (`stsd`: version, flags and the entry count).
fn container_head(kind: &FourCC) -> Option<usize> {
    match kind {
        b"moov" | b"trak" | b"mdia" | b"minf" | b"stbl" => Some(0),
        b"stsd" => Some(8),
        _ => None,
    }
}

impl Node {
    /// A leaf box.
    pub fn leaf(kind: &FourCC, payload: Vec<u8>) -> Node {
        Node {
            kind: *kind,
            body: Body::Leaf(payload),
        }
    }

    /// A container of `children` with `head` bytes before them.
    pub fn tree(kind: &FourCC, head: Vec<u8>, children: Vec<Node>) -> Node {
        Node {
            kind: *kind,
            body: Body::Tree {
                head,
                children,
                tail: Vec::new(),
            },
        }
    }

    /// The box whose header is `h` in `bytes` (offsets as `h.start - base`): the containers
    /// on the way from `moov` to the sample descriptions opened, every other box a leaf.
    pub fn parse(bytes: &[u8], h: &Header, base: u64) -> Result<Node, Error> {
        let from = (h.payload_start() - base) as usize;
        let payload = &bytes[from..(h.end() - base) as usize];
        match container_head(&h.kind) {
            Some(n) => Node::open(&h.kind, payload, n, h.payload_start()),
            None => Ok(Node::leaf(&h.kind, payload.to_vec())),
        }
    }

    /// A container of type `kind` from its payload: `head_len` bytes of head, then boxes.
    pub fn open(kind: &FourCC, payload: &[u8], head_len: usize, at: u64) -> Result<Node, Error> {
        if payload.len() < head_len {
            return Err(Error::malformed(format!(
                "box {} (payload at offset {at}) holds {} bytes, fewer than the {head_len} its fields need",
                name(kind),
                payload.len()
            )));
        }
        let (head, rest) = payload.split_at(head_len);
        let base = at + head_len as u64;
        let (headers, tail) = headers_in(rest, base)?;
        let children = headers
            .iter()
            .map(|c| Node::parse(rest, c, base))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Node {
            kind: *kind,
            body: Body::Tree {
                head: head.to_vec(),
                children,
                tail: rest[rest.len() - tail..].to_vec(),
            },
        })
    }

    /// The payload bytes of a leaf; `None` for a container.
    pub fn payload(&self) -> Option<&[u8]> {
        match &self.body {
            Body::Leaf(p) => Some(p),
            Body::Tree { .. } => None,
        }
    }

    /// The children of a container (none for a leaf).
    pub fn children(&self) -> &[Node] {
        match &self.body {
            Body::Tree { children, .. } => children,
            Body::Leaf(_) => &[],
        }
    }

    /// The children of a container, to change; `None` for a leaf.
    pub fn children_mut(&mut self) -> Option<&mut Vec<Node>> {
        match &mut self.body {
            Body::Tree { children, .. } => Some(children),
            Body::Leaf(_) => None,
        }
    }

    /// The first child of type `kind`.
    pub fn child(&self, kind: &FourCC) -> Option<&Node> {
        self.children().iter().find(|c| &c.kind == kind)
    }

    /// Bytes of the payload (all but the header).
    fn payload_len(&self) -> u64 {
        match &self.body {
            Body::Leaf(p) => p.len() as u64,
            Body::Tree {
                head,
                children,
                tail,
            } => {
                let inner: u64 = children.iter().map(Node::size).sum();
                (head.len() + tail.len()) as u64 + inner
            }
        }
    }

    /// Bytes of the whole box as [`Node::write`] writes it: an 8-byte header, or 16 when the
    /// size needs 64 bits.
    pub fn size(&self) -> u64 {
        let p = self.payload_len();
        if p + 8 <= u64::from(u32::MAX) {
            p + 8
        } else {
            p + 16
        }
    }

    /// Appends the box to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        let size = self.size();
        if size <= u64::from(u32::MAX) {
            out.extend_from_slice(&(size as u32).to_be_bytes());
            out.extend_from_slice(&self.kind);
        } else {
            out.extend_from_slice(&1u32.to_be_bytes());
            out.extend_from_slice(&self.kind);
            out.extend_from_slice(&size.to_be_bytes());
        }
        match &self.body {
            Body::Leaf(p) => out.extend_from_slice(p),
            Body::Tree {
                head,
                children,
                tail,
            } => {
                out.extend_from_slice(head);
                for c in children {
                    c.write(out);
                }
                out.extend_from_slice(tail);
            }
        }
    }

    /// The box as bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.size() as usize);
        self.write(&mut out);
        out
    }
}

/// A full box's payload: version, flags (24 bits), then `body`.
pub fn full_box(version: u8, flags: u32, body: &[u8]) -> Vec<u8> {
    let mut p = Vec::with_capacity(4 + body.len());
    p.push(version);
    p.extend_from_slice(&flags.to_be_bytes()[1..]);
    p.extend_from_slice(body);
    p
}

/// A big-endian `u32` at `at` of `bytes`, if there.
pub fn be_u32(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_be_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
}

/// A big-endian `u64` at `at` of `bytes`, if there.
pub fn be_u64(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_be_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(size: u32, kind: &[u8; 4], large: Option<u64>) -> Vec<u8> {
        let mut b = size.to_be_bytes().to_vec();
        b.extend_from_slice(kind);
        if let Some(l) = large {
            b.extend_from_slice(&l.to_be_bytes());
        }
        b
    }

    #[test]
    fn sizes_32_64_and_to_the_end() {
        let h = parse_header(&header(24, b"free", None), 100, 1000).unwrap();
        assert_eq!((h.header_len, h.size, h.end()), (8, 24, 124));
        // A 64-bit size beyond 4 GiB, with the room for it.
        let big = (1u64 << 32) + 40;
        let h = parse_header(&header(1, b"mdat", Some(big)), 0, big).unwrap();
        assert_eq!((h.header_len, h.size, h.payload_start()), (16, big, 16));
        // Size 0: to the end of the container.
        let h = parse_header(&header(0, b"mdat", None), 8, 5000).unwrap();
        assert_eq!(h.size, 5000);
    }

    #[test]
    fn sizes_that_do_not_fit_are_refused() {
        let e = parse_header(&header(2000, b"moov", None), 40, 1000).unwrap_err();
        assert_eq!(e.fault(), mirrorball_core::Fault::Input);
        let e = e.to_string();
        assert!(
            e.contains("'moov'") && e.contains("2000") && e.contains("1000"),
            "{e}"
        );
        let e = parse_header(&header(1, b"mdat", Some(u64::MAX)), 0, 1 << 40)
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
        assert!(parse_header(&header(4, b"free", None), 0, 100).is_err());
        assert!(parse_header(&header(1, b"mdat", Some(8)), 0, 100).is_err());
        assert!(parse_header(&header(1, b"mdat", None), 0, 100).is_err());
        assert!(parse_header(b"abc", 0, 3).is_err());
    }

    #[test]
    fn a_tree_writes_back_byte_for_byte_and_grows_to_64_bits() {
        let mut stsd = full_box(0, 0, &1u32.to_be_bytes());
        stsd.extend_from_slice(&header(12, b"avc1", None));
        stsd.extend_from_slice(&[1, 2, 3, 4]);
        let mut stbl = header(8 + 8 + stsd.len() as u32, b"stbl", None);
        stbl.extend_from_slice(&header(8 + stsd.len() as u32, b"stsd", None));
        stbl.extend_from_slice(&stsd);
        let (hs, tail) = headers_in(&stbl, 0).unwrap();
        assert_eq!((hs.len(), tail), (1, 0));
        let node = Node::parse(&stbl, &hs[0], 0).unwrap();
        assert_eq!(node.to_bytes(), stbl);
        let stsd = node.child(b"stsd").unwrap();
        assert_eq!(stsd.children()[0].payload(), Some(&[1u8, 2, 3, 4][..]));
        // A payload past 4 GiB takes a 64-bit size (computed, not written here).
        let huge = Node::leaf(b"free", Vec::new());
        assert_eq!(huge.size(), 8);
        let mut out = Vec::new();
        Node::leaf(b"abcd", vec![7; 3]).write(&mut out);
        assert_eq!(out, [0, 0, 0, 11, b'a', b'b', b'c', b'd', 7, 7, 7]);
    }

    #[test]
    fn stray_bytes_end_a_list_as_its_tail() {
        let mut b = header(8, b"free", None);
        b.extend_from_slice(&[0, 0, 0, 0]);
        let (hs, tail) = headers_in(&b, 0).unwrap();
        assert_eq!((hs.len(), tail), (1, 4));
    }
}
