//! How the layers of a projection are arranged in one picture: cube crosses and strips, the
//! dual paraboloid side by side. Pure pixel rearrangement.
//!
//! Cells are face-sized. The crosses put the faces where they join up without mirroring
//! (OpenGL's face orientation makes this work with no rotation, except the vertical cross's
//! −Z, which hangs below −Y turned half a turn):
//!
//! ```text
//! horizontal cross     vertical cross     strips
//!     +Y                   +Y              +X −X +Y −Y +Z −Z (left to right,
//! −X  +Z  +X  −Z       −X  +Z  +X          or top to bottom)
//!     −Y                   −Y
//!                          −Z (rotated 180°)
//! ```
//!
//! FFmpeg `v360`'s cube arrangements are [`Layout::Cells`] ([`CubeCells`]): `c3x2`, `c6x1`,
//! `c1x6` with v360's face order and rotation strings, and `eac`, v360's equi-angular
//! arrangement with its padding. See [`CubeCells`] for how v360's cells relate to OpenGL's
//! faces.

use crate::projection::{CubeFace, Eac, Projection, ProjectionKind, WorldProjection};
use crate::{Choice, EnvMap, Image};
use glam::DVec3;
use std::fmt;
use std::str::FromStr;

/// An arrangement of a projection's layers in one picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layout {
    /// One layer per picture (the only layout for single-layer projections; for cubes and
    /// paraboloids, one file per layer).
    Separate,
    /// Six faces in a 4×3 cross.
    HorizontalCross,
    /// Six faces in a 3×4 cross.
    VerticalCross,
    /// All layers in a row, in layer order (a paraboloid's "side by side": front | back).
    HorizontalStrip,
    /// All layers in a column, in layer order.
    VerticalStrip,
    /// Six cube faces in FFmpeg `v360`'s cells: its `c3x2`, `c6x1`, `c1x6` and `eac`.
    Cells(CubeCells),
}

/// The grid of a [`CubeCells`] layout, in cells `(columns, rows)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CellGrid {
    /// Three across, two down (`c3x2`, `eac`).
    C3x2,
    /// Six across.
    C6x1,
    /// Six down.
    C1x6,
}

impl CellGrid {
    fn dims(self) -> (u32, u32) {
        match self {
            CellGrid::C3x2 => (3, 2),
            CellGrid::C6x1 => (6, 1),
            CellGrid::C1x6 => (1, 6),
        }
    }
    fn name(self) -> &'static str {
        match self {
            CellGrid::C3x2 => "c3x2",
            CellGrid::C6x1 => "c6x1",
            CellGrid::C1x6 => "c1x6",
        }
    }
}

/// FFmpeg `v360`'s cube layouts (`libavfilter/vf_v360.c`: `cube_to_xyz`, `xyz_to_cube`,
/// `rotate_cube_face`, `prepare_eac_in/out`, `eac_to_xyz`).
///
/// Cells are numbered left to right, top to bottom. Cell `i` shows the face of letter `i` of
/// v360's `forder` (`r l u d f b`: right, left, up, down, front, back; ours +X −X +Y −Y −Z
/// +Z, since v360's `(x, y, z)` is our `(x, −y, −z)`), turned by digit `i` of `frot`
/// (quarter turns clockwise as seen: v360's `ROT_90` for `1`). Derived from `cube_to_xyz`:
/// with cell coordinates `(c, d)` ∈ `[−1, 1]²` (right, down), v360 first undoes the turn,
/// `(c, d)` → `(d, −c)`, `(−c, −d)`, `(−d, c)` for `1`, `2`, `3`, giving `(c′, d′)`; then a
/// side face (r l f b) shows OpenGL's `(s, t) = (−c′, d′)` and the up and down faces show
/// `(c′, −d′)`: v360's cells are OpenGL's faces mirrored, read as a panorama reads. These are
/// signed permutations of the coordinates, so pixel centres land on pixel centres and
/// packing is an exact rearrangement.
///
/// `eac` is `c3x2` with `forder=lfrdbu`, `frot=000313` (v360 spells the same table out in
/// `eac_to_xyz`) and v360's fixed padding: the picture of faces of `n` texels is
/// `(3n + 4)×(2n + 8)`, two texels of border at the picture's left and right edges and above
/// and below each row of faces. v360 fills a border texel by continuing the face coordinate
/// linearly past the edge (`uf = 2·uf` where `|uf| > ½`: face coordinate `±(1 + δ)` at
/// distance `δ` past the edge in the face's `[−1, 1]`, not the tangent); [`Layout::pack`]
/// looks the map up in that texel's direction, bilinearly. Reading ignores the border.
///
/// v360 draws `eac` at any picture size `W`×`H` (its default from a lat-long is
/// `W`×`9H/8`, YouTube's 3840×2160): the faces lie between two texels of border at the left
/// and right and two above and below each row, `(W − 4)/3` texels wide and `H/2 − 4` high,
/// not square and not whole in general (`eac_to_xyz`, `xyz_to_eac`: each face's texels span
/// its angles in x and y apart). Such a picture is [`CubeCells::eac_frame`]: packed by
/// looking every texel up in the direction v360 gives its centre, and read by sampling it
/// bilinearly where v360 puts each face texel's centre (square faces of the finer of the two
/// spacings).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CubeCells {
    /// The grid.
    pub grid: CellGrid,
    /// The OpenGL face in each cell.
    pub faces: [CubeFace; 6],
    /// Quarter turns (clockwise as seen) of each cell, v360's `frot` digits.
    pub turns: [u8; 6],
    /// v360's `eac` padding: two texels of border (see above).
    pub eac_pad: bool,
    /// v360's `eac` picture at a size its square faces do not give (see above): its
    /// `(width, height)`.
    pub frame: Option<(u32, u32)>,
}

/// v360's face letters and the OpenGL face of each.
const LETTERS: [(char, CubeFace); 6] = [
    ('r', CubeFace::PosX),
    ('l', CubeFace::NegX),
    ('u', CubeFace::PosY),
    ('d', CubeFace::NegY),
    ('f', CubeFace::NegZ),
    ('b', CubeFace::PosZ),
];
const RLUDFB: [CubeFace; 6] = [
    CubeFace::PosX,
    CubeFace::NegX,
    CubeFace::PosY,
    CubeFace::NegY,
    CubeFace::NegZ,
    CubeFace::PosZ,
];

impl CubeCells {
    /// v360's defaults for a grid: `forder=rludfb`, `frot=000000`, no padding.
    pub const fn v360(grid: CellGrid) -> CubeCells {
        CubeCells {
            grid,
            faces: RLUDFB,
            turns: [0; 6],
            eac_pad: false,
            frame: None,
        }
    }

    /// v360's `eac`: `c3x2:forder=lfrdbu:frot=000313` with its two-texel padding.
    pub const EAC: CubeCells = CubeCells {
        grid: CellGrid::C3x2,
        faces: [
            CubeFace::NegX,
            CubeFace::NegZ,
            CubeFace::PosX,
            CubeFace::NegY,
            CubeFace::PosZ,
            CubeFace::PosY,
        ],
        turns: [0, 0, 0, 3, 1, 3],
        eac_pad: true,
        frame: None,
    };

    /// v360's `eac` as a `w`×`h` picture, and the edge of the square faces a map is made
    /// at to fill it (the finer of the faces' two spacings, `(w − 4)/3` and `h/2 − 4`,
    /// rounded up to an even edge, which video's half-size colour planes halve); the plain
    /// [`CubeCells::EAC`] where square faces give that size. `None` for a picture too small
    /// to hold a texel of each face.
    pub fn eac_frame(w: u32, h: u32) -> Option<(CubeCells, u32)> {
        if let Some(n) = CubeCells::EAC.face_size(w, h) {
            return Some((CubeCells::EAC, n));
        }
        let (fw, fh) = ((w as f64 - 4.0) / 3.0, h as f64 / 2.0 - 4.0);
        if fw < 1.0 || fh < 1.0 {
            return None;
        }
        let cells = CubeCells {
            frame: Some((w, h)),
            ..CubeCells::EAC
        };
        let n = fw.max(fh).ceil() as u32;
        Some((cells, n + n % 2))
    }

    /// Whether the picture is v360's `eac` at a size of its own ([`CubeCells::eac_frame`]),
    /// not the one faces of `n` texels give.
    fn continuous(&self, n: u32) -> bool {
        self.frame.is_some_and(|f| f != self.with_faces(n))
    }

    /// The picture size that faces of `n` texels give.
    fn with_faces(&self, n: u32) -> (u32, u32) {
        let (c, r) = self.grid.dims();
        if self.eac_pad {
            (c * n + 4, r * (n + 4))
        } else {
            (c * n, r * n)
        }
    }

    /// The picture size for faces of `n` texels: the frame's own, for v360's `eac` at a
    /// size of its own.
    pub fn extent(&self, n: u32) -> (u32, u32) {
        self.frame.unwrap_or_else(|| self.with_faces(n))
    }

    /// The face size of a `w`×`h` picture in this layout, if it is one.
    pub fn face_size(&self, w: u32, h: u32) -> Option<u32> {
        let (c, _) = self.grid.dims();
        let n = if self.eac_pad {
            w.checked_sub(4)? / c
        } else {
            w / c
        };
        (n > 0 && self.with_faces(n) == (w, h)).then_some(n)
    }

    /// The top-left texel of cell `i`'s face, for faces of `n` texels.
    pub fn origin(&self, i: usize, n: u32) -> (u32, u32) {
        let (c, _) = self.grid.dims();
        let (col, row) = (i as u32 % c, i as u32 / c);
        if self.eac_pad {
            (2 + col * n, 2 + row * (n + 4))
        } else {
            (col * n, row * n)
        }
    }

    /// The face coordinates `(s, t)` shown at cell coordinates `(c, d)` of cell `i`, as
    /// doubled integers (`2x + 1 − n` for texel `x` of `n`) or as reals: a signed
    /// permutation (see the type's documentation).
    pub fn face_coords<T: Copy + std::ops::Neg<Output = T>>(&self, i: usize, c: T, d: T) -> (T, T) {
        let (c, d) = match self.turns[i] & 3 {
            0 => (c, d),
            1 => (d, -c),
            2 => (-c, -d),
            _ => (-d, c),
        };
        match self.faces[i] {
            CubeFace::PosY | CubeFace::NegY => (c, -d),
            _ => (-c, d),
        }
    }

    /// For each texel `(x, y)` of each cell's face (faces of `n` texels), the face texel it
    /// shows: `f(cell, picture x, picture y, face texel x, face texel y)`, the face being
    /// `faces[cell]`; cell by cell, each cell's rows top first, each row left to right. None
    /// for v360's `eac` at a size of its own, whose texels are all looked up.
    pub fn each_texel(&self, n: u32, mut f: impl FnMut(usize, u32, u32, u32, u32)) {
        if self.continuous(n) {
            return;
        }
        let n2 = n as i64;
        for i in 0..6 {
            let (ox, oy) = self.origin(i, n);
            for y in 0..n {
                for x in 0..n {
                    let (c, d) = (2 * x as i64 + 1 - n2, 2 * y as i64 + 1 - n2);
                    let (s, t) = self.face_coords(i, c, d);
                    f(
                        i,
                        ox + x,
                        oy + y,
                        ((s + n2 - 1) / 2) as u32,
                        ((t + n2 - 1) / 2) as u32,
                    );
                }
            }
        }
    }

    /// The direction v360 gives texel `(px, py)` of its `eac` picture of `w`×`h` texels, for
    /// a map of projection `p` (`eac_to_xyz`: faces `(w − 4)/3` wide and `h/2 − 4` high
    /// between two-texel borders; EAC's faces are equi-angular inside the edge; past it both
    /// EAC and the cube continue the gnomonic coordinate linearly).
    fn frame_dir(&self, p: &Projection, (w, h): (u32, u32), px: u32, py: u32) -> DVec3 {
        let (cols, rows) = self.grid.dims();
        let (fw, row_h) = ((w as f64 - 4.0) / cols as f64, h as f64 / rows as f64);
        let fh = row_h - 4.0;
        // Position in face widths from the left edge of the faces, and the cell.
        let fx = (px as f64 + 0.5 - 2.0) / fw;
        let col = (fx.floor().max(0.0) as u32).min(cols - 1);
        let row = (((py as f64 + 0.5) / row_h).floor() as u32).min(rows - 1);
        let fy = (py as f64 + 0.5 - 2.0 - row as f64 * row_h) / fh;
        let (c, d) = (2.0 * (fx - col as f64) - 1.0, 2.0 * fy - 1.0);
        let i = (row * cols + col) as usize;
        let (s, t) = self.face_coords(i, c, d);
        let warp = |a: f64| {
            if a.abs() > 1.0 {
                a
            } else if p.kind() == ProjectionKind::Eac {
                Eac::unwarp(a)
            } else {
                a
            }
        };
        self.faces[i].point(warp(s), warp(t)).normalize()
    }

    /// Where v360's `eac` picture of `w`×`h` texels shows face texel `(x, y)` of the face in
    /// cell `i` (faces of `n` texels): the picture position of its centre, in texels from the
    /// picture's top-left corner (`xyz_to_eac`).
    fn frame_position(&self, (w, h): (u32, u32), i: usize, n: u32, x: u32, y: u32) -> (f64, f64) {
        let (s, t) = (
            2.0 * (x as f64 + 0.5) / n as f64 - 1.0,
            2.0 * (y as f64 + 0.5) / n as f64 - 1.0,
        );
        // face_coords is a signed permutation: its inverse is its transpose.
        let (a, b) = (self.face_coords(i, 1.0, 0.0), self.face_coords(i, 0.0, 1.0));
        self.eac_point((w, h), i, a.0 * s + a.1 * t, b.0 * s + b.1 * t)
    }

    /// Where v360's `eac` picture of `w`×`h` texels shows cell coordinates `(c, d)` ∈
    /// `[−1, 1]²` (right, down) of cell `i`, in texels from the picture's top-left corner:
    /// the cell's face `(w − 4)/3` wide and `h/2 − 4` high inside its two-texel borders
    /// (`xyz_to_eac`; with square faces of `n`, [`CubeCells::origin`] plus `(c + 1)/2·n`).
    pub fn eac_point(&self, (w, h): (u32, u32), i: usize, c: f64, d: f64) -> (f64, f64) {
        let (cols, rows) = self.grid.dims();
        let (fw, row_h) = ((w as f64 - 4.0) / cols as f64, h as f64 / rows as f64);
        let (col, row) = (i as u32 % cols, i as u32 / cols);
        (
            2.0 + (col as f64 + 0.5 * (c + 1.0)) * fw,
            2.0 + row as f64 * row_h + 0.5 * (d + 1.0) * (row_h - 4.0),
        )
    }

    fn parse(grid: CellGrid, opts: &str) -> Result<CubeCells, String> {
        let mut cells = CubeCells::v360(grid);
        for opt in opts.split(':').filter(|o| !o.is_empty()) {
            let (key, value) = opt
                .split_once('=')
                .ok_or_else(|| format!("'{opt}' is not KEY=VALUE (forder, frot, pad)"))?;
            match key.trim().to_ascii_lowercase().as_str() {
                "forder" => {
                    let letters: Vec<char> = value.trim().to_ascii_lowercase().chars().collect();
                    if letters.len() != 6 {
                        return Err(format!(
                            "forder={value}: needs six face letters, one per cell (r l u d f b)"
                        ));
                    }
                    for (i, ch) in letters.iter().enumerate() {
                        let face = LETTERS
                            .iter()
                            .find(|(l, _)| l == ch)
                            .map(|(_, f)| *f)
                            .ok_or_else(|| {
                                format!("forder={value}: '{ch}' is not a face letter (r l u d f b)")
                            })?;
                        if letters[..i].contains(ch) {
                            return Err(format!(
                                "forder={value}: face '{ch}' appears twice; each face once"
                            ));
                        }
                        cells.faces[i] = face;
                    }
                }
                "frot" => {
                    let digits: Vec<char> = value.trim().chars().collect();
                    if digits.len() != 6 || digits.iter().any(|d| !('0'..='3').contains(d)) {
                        return Err(format!(
                            "frot={value}: needs six digits 0-3 (quarter turns), one per cell"
                        ));
                    }
                    for (i, d) in digits.iter().enumerate() {
                        cells.turns[i] = *d as u8 - b'0';
                    }
                }
                "pad" => {
                    let p: f64 = value.trim().parse().map_err(|_| {
                        format!("pad={value}: not a number (a fraction of the cell, 0 to 0.1)")
                    })?;
                    if !(0.0..=0.1).contains(&p) {
                        return Err(format!(
                            "pad={value}: outside 0 to 0.1 (the fraction of each cell left as a border, v360's range)"
                        ));
                    }
                    if p != 0.0 {
                        return Err(format!(
                            "pad={value}: only pad=0 is supported for c3x2, c6x1 and c1x6 (eac has its own padding)"
                        ));
                    }
                }
                other => return Err(format!("unknown option '{other}' (forder, frot, pad)")),
            }
        }
        Ok(cells)
    }
}

impl fmt::Display for CubeCells {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.eac_pad {
            return f.write_str("eac");
        }
        f.write_str(self.grid.name())?;
        if *self != CubeCells::v360(self.grid) {
            let letters: String = self
                .faces
                .iter()
                .map(|face| LETTERS.iter().find(|(_, f)| f == face).map_or('?', |l| l.0))
                .collect();
            let turns: String = self.turns.iter().map(|t| (b'0' + t) as char).collect();
            write!(f, ":forder={letters}:frot={turns}")?;
        }
        Ok(())
    }
}

/// Cell `(column, row)` of each cube face (OpenGL order) and whether it is turned 180°.
const HCROSS: [(u32, u32, bool); 6] = [
    (2, 1, false),
    (0, 1, false),
    (1, 0, false),
    (1, 2, false),
    (1, 1, false),
    (3, 1, false),
];
const VCROSS: [(u32, u32, bool); 6] = [
    (2, 1, false),
    (0, 1, false),
    (1, 0, false),
    (1, 2, false),
    (1, 1, false),
    (1, 3, true),
];

impl Layout {
    /// Every layout.
    pub const ALL: [Layout; 5] = [
        Layout::Separate,
        Layout::HorizontalCross,
        Layout::VerticalCross,
        Layout::HorizontalStrip,
        Layout::VerticalStrip,
    ];

    /// Whether a projection with `layers` layers can use this layout packed in one picture.
    pub fn fits(self, layers: usize) -> bool {
        match self {
            Layout::Separate => true,
            Layout::HorizontalCross | Layout::VerticalCross => layers == 6,
            Layout::HorizontalStrip | Layout::VerticalStrip => true,
            Layout::Cells(_) => layers == 6,
        }
    }

    /// Whether this layout can hold a map of `kind`: the table of which layouts each
    /// projection takes. One picture a layer holds any projection; the strips hold the
    /// projections of several layers (a strip of one layer would not be read back as one:
    /// its cells are square); the crosses and v360's unpadded cells hold six faces (the
    /// cube, the continuous cube and EAC); v360's padded `eac` holds EAC only (its border is
    /// continued in equi-angular face coordinates, so that plain cube faces in it are read
    /// wrong by every EAC reader).
    pub fn holds(self, kind: ProjectionKind) -> bool {
        let layers = kind.default_projection().layer_count();
        match self {
            Layout::Separate => true,
            Layout::HorizontalStrip | Layout::VerticalStrip => layers > 1,
            Layout::Cells(c) if c.eac_pad => kind == ProjectionKind::Eac,
            Layout::HorizontalCross | Layout::VerticalCross | Layout::Cells(_) => layers == 6,
        }
    }

    /// Why this layout cannot hold a map of `kind`, naming the projections it holds: `eac
    /// holds v360's padded equi-angular faces, not a cube map: use --to eac (or another
    /// layout)`; `None` when it can ([`Layout::holds`]). `flag` is the flag that names the
    /// projection (`--to`, `--from`); the caller puts its layout flag before the message.
    pub fn refusal(self, kind: ProjectionKind, flag: &str) -> Option<String> {
        if self.holds(kind) {
            return None;
        }
        let takes: Vec<String> = ProjectionKind::ALL
            .into_iter()
            .filter(|&k| self.holds(k))
            .map(|k| format!("{flag} {k}"))
            .collect();
        let why = match self {
            Layout::Cells(c) if c.eac_pad => {
                format!("v360's padded equi-angular faces, not a {kind} map")
            }
            Layout::HorizontalStrip | Layout::VerticalStrip => format!(
                "several layers, and a {kind} map has {}",
                crate::count(kind.default_projection().layer_count() as u64, "layer")
            ),
            _ => format!(
                "six faces, and a {kind} map has {}",
                crate::count(kind.default_projection().layer_count() as u64, "layer")
            ),
        };
        let one_of = UnknownNameList(&takes);
        Some(format!(
            "{} holds {why}: use {one_of} (or another layout)",
            self.name()
        ))
    }

    /// v360's `eac` arrangement (see [`CubeCells`]): the default layout of an EAC map.
    pub const fn eac() -> Layout {
        Layout::Cells(CubeCells::EAC)
    }

    /// The layout a map of `kind` gets when none is named: v360's `eac` for EAC, a
    /// horizontal cross for the cubes, side by side for the paraboloid, else separate.
    pub fn default_for(kind: ProjectionKind) -> Layout {
        match kind.default_projection().layer_count() {
            _ if kind == ProjectionKind::Eac => Layout::eac(),
            6 => Layout::HorizontalCross,
            2 => Layout::HorizontalStrip,
            _ => Layout::Separate,
        }
    }

    /// The picture size of this layout for layers of `w`×`h` texels.
    pub fn extent(self, layers: usize, w: u32, h: u32) -> (u32, u32) {
        if let Layout::Cells(c) = self {
            return c.extent(w);
        }
        let (gc, gr) = self.grid(layers);
        (gc * w, gr * h)
    }

    /// Grid size in cells `(columns, rows)` for `layers` layers.
    pub fn grid(self, layers: usize) -> (u32, u32) {
        let n = layers as u32;
        match self {
            Layout::Separate => (1, 1),
            Layout::HorizontalCross => (4, 3),
            Layout::VerticalCross => (3, 4),
            Layout::HorizontalStrip => (n, 1),
            Layout::VerticalStrip => (1, n),
            Layout::Cells(c) => c.grid.dims(),
        }
    }

    /// Where [`Layout::pack`] puts layer `i` of `layers` whole: its cell `(column, row,
    /// turned 180°)` in the [`Layout::grid`]; `None` for v360's cells (packed texel by
    /// texel, EAC's with looked-up borders) and for a layer the layout does not hold.
    pub fn grid_cell(self, i: usize, layers: usize) -> Option<(u32, u32, bool)> {
        let whole = !matches!(self, Layout::Cells(_)) && self.fits(layers) && i < layers;
        whole.then(|| self.cell(i))
    }

    /// The cell of layer `i`: `(column, row, turned 180°)`.
    fn cell(self, i: usize) -> (u32, u32, bool) {
        match self {
            Layout::Separate => (0, 0, false),
            Layout::HorizontalCross => HCROSS[i],
            Layout::VerticalCross => VCROSS[i],
            Layout::HorizontalStrip => (i as u32, 0, false),
            Layout::VerticalStrip => (0, i as u32, false),
            Layout::Cells(_) => unreachable!("cells are packed texel by texel"),
        }
    }

    /// The layout for a single picture of `w`×`h` holding `layers` layers, judged by its
    /// aspect ratio alone, with the cell size. `None` if no layout fits.
    pub fn from_extent(w: u32, h: u32, layers: usize) -> Option<(Layout, u32, u32)> {
        Layout::from_extent_where(w, h, layers, |_| true)
    }

    /// [`Layout::from_extent`] among the layouts that hold a map of `kind`
    /// ([`Layout::holds`]): a cube is never read from v360's padded `eac`. An EAC picture of any other size is v360's `eac` at that size
    /// ([`CubeCells::eac_frame`]).
    pub fn from_extent_of(w: u32, h: u32, kind: ProjectionKind) -> Option<(Layout, u32, u32)> {
        let layers = kind.default_projection().layer_count();
        Layout::from_extent_where(w, h, layers, |l| l.holds(kind)).or_else(|| {
            let (cells, n) = CubeCells::eac_frame(w, h).filter(|_| kind == ProjectionKind::Eac)?;
            Some((Layout::Cells(cells), n, n))
        })
    }

    fn from_extent_where(
        w: u32,
        h: u32,
        layers: usize,
        accept: impl Fn(Layout) -> bool,
    ) -> Option<(Layout, u32, u32)> {
        if layers == 1 {
            return Some((Layout::Separate, w, h));
        }
        for l in [
            Layout::HorizontalCross,
            Layout::VerticalCross,
            Layout::HorizontalStrip,
            Layout::VerticalStrip,
        ] {
            if !l.fits(layers) || !accept(l) {
                continue;
            }
            let (c, r) = l.grid(layers);
            if w.is_multiple_of(c) && h.is_multiple_of(r) && w / c == h / r && w / c > 0 {
                return Some((l, w / c, h / r));
            }
        }
        if layers == 6 {
            for cells in [CubeCells::EAC, CubeCells::v360(CellGrid::C3x2)] {
                if !accept(Layout::Cells(cells)) {
                    continue;
                }
                if let Some(n) = cells.face_size(w, h) {
                    return Some((Layout::Cells(cells), n, n));
                }
            }
        }
        None
    }

    /// The texels of [`Layout::pack`]'s picture of a map of projection `p` with layers of
    /// `n`×`n` texels that are looked up in a direction rather than copied from a layer
    /// texel, as `(x, y, direction)` row by row: EAC's two-texel border (`pack` reads each
    /// with [`EnvMap::sample`]); none for every other layout.
    pub fn looked_up_texels(self, p: &Projection, n: u32) -> Vec<(u32, u32, DVec3)> {
        match self {
            Layout::Cells(cells) => cells.looked_up(p, n),
            _ => Vec::new(),
        }
    }

    /// Packs the layers of `env` into one picture (unused cross cells are black with zero
    /// alpha). For [`Layout::Separate`] the map must have a single layer.
    pub fn pack(self, env: &EnvMap) -> Option<Image> {
        let n = env.layers().len();
        if !self.fits(n) || (self == Layout::Separate && n != 1) {
            return None;
        }
        let (cw, ch) = (env.width(), env.height());
        // Each layer's copy counted for progress bars as it lands (`work::PACK`).
        let layer_work = crate::work::PACK * cw as u64 * ch as u64;
        if let Layout::Cells(cells) = self {
            let out = pack_cells(&cells, env);
            crate::work::add(layer_work * n as u64);
            return Some(out);
        }
        let (gc, gr) = self.grid(n);
        let mut out = Image::new(cw * gc, ch * gr, env.channels());
        for (i, layer) in env.layers().iter().enumerate() {
            let (col, row, turned) = self.cell(i);
            if turned {
                out.paste(&layer.rotated_180(), col * cw, row * ch);
            } else {
                out.paste(layer, col * cw, row * ch);
            }
            crate::work::add(layer_work);
        }
        Some(out)
    }

    /// [`Layout::unpack`], taking the picture: a one-layer map (or a separate layout) keeps
    /// its texels where they are instead of copying them (100 MB for a 4096×2048 float
    /// lat-long).
    pub fn unpack_owned(
        self,
        image: Image,
        projection: Projection,
    ) -> Result<EnvMap, crate::Error> {
        if self == Layout::Separate {
            return EnvMap::new(projection, vec![image])
                .map_err(|e| crate::Error::request(e.to_string()));
        }
        self.unpack(&image, projection)
    }

    /// Cuts a picture laid out this way into the layers of `projection`; a picture it
    /// does not fit is the request's fault (the caller named the layout and projection).
    pub fn unpack(self, image: &Image, projection: Projection) -> Result<EnvMap, crate::Error> {
        self.unpack_text(image, projection)
            .map_err(crate::Error::request)
    }

    fn unpack_text(self, image: &Image, projection: Projection) -> Result<EnvMap, String> {
        let n = projection.layer_count();
        if self == Layout::Separate {
            return EnvMap::new(projection, vec![image.clone()]).map_err(|e| e.to_string());
        }
        if !self.fits(n) {
            return Err(format!(
                "layout {} needs 6 layers; {} has {}",
                self,
                projection.name(),
                n
            ));
        }
        let (gc, gr) = self.grid(n);
        let (w, h) = (image.width(), image.height());
        if let Layout::Cells(cells) = self {
            return unpack_cells(&cells, image, projection);
        }
        if w % gc != 0 || h % gr != 0 || w / gc != h / gr {
            return Err(format!(
                "a {} layout of {} layers needs a {}:{} picture of square cells; {}x{} is not",
                self, n, gc, gr, w, h
            ));
        }
        let cell = w / gc;
        let layers = (0..n)
            .map(|i| {
                let (col, row, turned) = self.cell(i);
                let img = image
                    .crop(col * cell, row * cell, cell, cell)
                    .expect("in range");
                if turned {
                    img.rotated_180()
                } else {
                    img
                }
            })
            .collect();
        EnvMap::new(projection, layers).map_err(|e| e.to_string())
    }
}

impl Choice for Layout {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Layout::Separate, &["separate", "faces", "files"]),
        (
            Layout::HorizontalCross,
            &["hcross", "horizontal-cross", "cross"],
        ),
        (Layout::VerticalCross, &["vcross", "vertical-cross"]),
        (
            Layout::HorizontalStrip,
            &[
                "hstrip",
                "horizontal-strip",
                "strip",
                "side-by-side",
                "sidebyside",
            ],
        ),
        (Layout::VerticalStrip, &["vstrip", "vertical-strip"]),
        (
            Layout::Cells(CubeCells::v360(CellGrid::C3x2)),
            &["c3x2", "cube3x2"],
        ),
        (
            Layout::Cells(CubeCells::v360(CellGrid::C6x1)),
            &["c6x1", "cube6x1"],
        ),
        (
            Layout::Cells(CubeCells::v360(CellGrid::C1x6)),
            &["c1x6", "cube1x6"],
        ),
        (Layout::Cells(CubeCells::EAC), &["eac"]),
    ];
}

impl Layout {
    /// The command-line name (the canonical name of [`Choice`]).
    /// For [`Layout::Cells`], the grid's name (`Display` adds v360's strings).
    pub fn name(self) -> &'static str {
        match self {
            Layout::Cells(c) if c.eac_pad => "eac",
            Layout::Cells(c) => c.grid.name(),
            _ => Choice::name(self),
        }
    }
}

impl fmt::Display for Layout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Layout::Cells(c) => c.fmt(f),
            _ => f.write_str(self.name()),
        }
    }
}

impl FromStr for Layout {
    type Err = String;
    /// A layout's name; v360's `c3x2`, `c6x1` and `c1x6` take v360's strings after it:
    /// `c3x2:forder=lfrdbu:frot=000313` (`pad=0` is accepted; no other padding yet).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (head, opts) = s.split_once(':').unwrap_or((s, ""));
        let layout = Layout::parse_name(head)
            .map_err(|e| format!("unknown layout '{head}' (known: {})", e.list()))?;
        match layout {
            _ if opts.is_empty() => Ok(layout),
            Layout::Cells(c) if c != CubeCells::EAC => CubeCells::parse(c.grid, opts)
                .map(Layout::Cells)
                .map_err(|e| format!("layout '{s}': {e}")),
            _ => Err(format!(
                "layout '{s}': {head} takes no options (forder, frot and pad are for c3x2, c6x1, c1x6)"
            )),
        }
    }
}

/// [`Layout::pack`] for v360's cells: each face texel moved to its cell, then (for `eac`)
/// the border looked up.
fn pack_cells(cells: &CubeCells, env: &EnvMap) -> Image {
    let n = env.width();
    let (w, h) = cells.extent(n);
    let ch = env.channels();
    let mut out = Image::new(w, h, ch);
    let layers = env.layers();
    cells.each_texel(n, |i, px, py, fx, fy| {
        out.set(px, py, layers[cells.faces[i] as usize].get(fx, fy));
    });
    for (px, py, d) in cells.looked_up(env.projection(), n) {
        let v = env.sample(d);
        out.set(px, py, &v[..ch]);
    }
    out
}

impl CubeCells {
    /// The texels of the picture (faces of `n` texels, a map of projection `p`) that show
    /// no face texel but are looked up in a direction: EAC's two-texel border, each in
    /// [`CubeCells::frame_dir`]'s direction (every texel of v360's `eac` at a size of its own);
    /// none without the padding. Row by row.
    fn looked_up(&self, p: &Projection, n: u32) -> Vec<(u32, u32, DVec3)> {
        if !self.eac_pad {
            return Vec::new();
        }
        let (w, h) = self.extent(n);
        if self.continuous(n) {
            return (0..h)
                .flat_map(|py| (0..w).map(move |px| (px, py)))
                .map(|(px, py)| (px, py, self.frame_dir(p, (w, h), px, py)))
                .collect();
        }
        let mut inside = vec![false; (w * h) as usize];
        self.each_texel(n, |_, px, py, _, _| inside[(py * w + px) as usize] = true);
        (0..h)
            .flat_map(|py| (0..w).map(move |px| (px, py)))
            .filter(|&(px, py)| !inside[(py * w + px) as usize])
            .map(|(px, py)| (px, py, self.frame_dir(p, (w, h), px, py)))
            .collect()
    }
}

/// [`Layout::unpack`] for v360's cells.
fn unpack_cells(
    cells: &CubeCells,
    image: &Image,
    projection: Projection,
) -> Result<EnvMap, String> {
    let (w, h) = (image.width(), image.height());
    if cells.eac_pad && cells.face_size(w, h).is_none() {
        return unpack_frame(cells, image, projection);
    }
    let n = cells.face_size(w, h).ok_or_else(|| {
        let (a, b) = cells.extent(1);
        format!("a {cells} layout needs a picture of {a}n x {b}n; {w}x{h} is not")
    })?;
    let mut faces = vec![Image::new(n, n, image.channels()); 6];
    cells.each_texel(n, |i, px, py, fx, fy| {
        faces[cells.faces[i] as usize].set(fx, fy, image.get(px, py));
    });
    EnvMap::new(projection, faces).map_err(|e| e.to_string())
}

/// [`Layout::unpack`] for v360's `eac` at a size of its own ([`CubeCells::eac_frame`]):
/// square faces of the finer spacing, each texel read bilinearly where v360 puts its centre.
fn unpack_frame(
    cells: &CubeCells,
    image: &Image,
    projection: Projection,
) -> Result<EnvMap, String> {
    let (w, h) = (image.width(), image.height());
    let (_, n) = CubeCells::eac_frame(w, h).ok_or_else(|| {
        format!("an eac picture of {w}x{h} is too small to hold its six faces and their borders")
    })?;
    let ch = image.channels();
    let mut faces = vec![Image::new(n, n, ch); 6];
    let mut texel = [0.0f32; 4];
    for (i, face) in cells.faces.iter().enumerate() {
        let layer = &mut faces[*face as usize];
        for y in 0..n {
            for x in 0..n {
                let (px, py) = cells.frame_position((w, h), i, n, x, y);
                image.bilinear_clamped((px - 0.5, py - 0.5), (0, h), &mut texel[..ch]);
                layer.set(x, y, &texel[..ch]);
            }
        }
    }
    EnvMap::new(projection, faces).map_err(|e| e.to_string())
}

/// How one picture holds a stereo pair: FFmpeg `v360`'s `in_stereo`/`out_stereo`
/// (`libavfilter/vf_v360.c`, `config_output` and the remap slices).
///
/// `2d` is one picture, one eye; `sbs` the left eye in the left half and the right eye in
/// the right half; `tb` the left eye on top, the right below. Each eye is a whole picture of
/// the projection in its layout, so a pair is split before the layout unpacks an eye and
/// joined after it packs one; no padding between the eyes. v360 halves an odd width or
/// height by integer division and leaves the last column or row unread; [`Stereo::split`]
/// refuses it instead.
///
/// Converting from one arrangement to another, output eye `e` is made from input eye
/// [`Stereo::source_eye`] of the input: the left eye of a pair for a `2d` output (v360 converts only its
/// first eye then), the one eye of a `2d` input for both eyes of a pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Stereo {
    /// One eye (`2d`).
    #[default]
    Mono,
    /// Left | right (`sbs`).
    SideBySide,
    /// Left above right (`tb`).
    TopBottom,
}

impl Choice for Stereo {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Stereo::Mono, &["2d", "mono"]),
        (Stereo::SideBySide, &["sbs", "side-by-side"]),
        (Stereo::TopBottom, &["tb", "top-bottom", "over-under"]),
    ];
}
crate::choice_traits!(Stereo);

impl Stereo {
    /// How many eyes the picture holds: 1 or 2.
    pub fn eyes(self) -> usize {
        match self {
            Stereo::Mono => 1,
            _ => 2,
        }
    }

    /// The picture of eyes of `w`×`h` texels.
    pub fn extent(self, w: u32, h: u32) -> (u32, u32) {
        match self {
            Stereo::Mono => (w, h),
            Stereo::SideBySide => (2 * w, h),
            Stereo::TopBottom => (w, 2 * h),
        }
    }

    /// The size of each eye of a `w`×`h` picture; an error when the width (`sbs`) or the
    /// height (`tb`) does not halve evenly (the request's fault).
    pub fn eye_extent(self, w: u32, h: u32) -> Result<(u32, u32), crate::Error> {
        let (n, what) = match self {
            Stereo::Mono => return Ok((w, h)),
            Stereo::SideBySide => (w, "width"),
            Stereo::TopBottom => (h, "height"),
        };
        if n % 2 != 0 || n == 0 {
            return Err(crate::Error::request(format!(
                "a {self} stereo pair needs an even {what}, one half per eye; {w}x{h} has {what} {n}"
            )));
        }
        Ok(match self {
            Stereo::SideBySide => (w / 2, h),
            _ => (w, h / 2),
        })
    }

    /// The top-left texel of eye `e` for eyes of `w`×`h`.
    fn origin(self, e: usize, w: u32, h: u32) -> (u32, u32) {
        match self {
            Stereo::SideBySide => (e as u32 * w, 0),
            Stereo::TopBottom => (0, e as u32 * h),
            Stereo::Mono => (0, 0),
        }
    }

    /// The first `eyes` eyes of `picture` (left first), at most [`Stereo::eyes`]: a `2d`
    /// picture is its one eye, kept as it is.
    pub fn split(self, picture: Image, eyes: usize) -> Result<Vec<Image>, crate::Error> {
        if self == Stereo::Mono {
            return Ok(vec![picture]);
        }
        let (w, h) = self.eye_extent(picture.width(), picture.height())?;
        Ok((0..eyes.min(2))
            .map(|e| {
                let (x, y) = self.origin(e, w, h);
                picture
                    .crop(x, y, w, h)
                    .expect("an eye lies inside the picture")
            })
            .collect())
    }

    /// The picture holding `eyes` (left first, each of one size): the one eye for `2d`.
    /// `None` when the count is not [`Stereo::eyes`] or the sizes differ.
    pub fn join(self, mut eyes: Vec<Image>) -> Option<Image> {
        if eyes.len() != self.eyes() {
            return None;
        }
        if self == Stereo::Mono {
            return eyes.pop();
        }
        let (w, h, c) = (eyes[0].width(), eyes[0].height(), eyes[0].channels());
        if eyes
            .iter()
            .any(|e| (e.width(), e.height(), e.channels()) != (w, h, c))
        {
            return None;
        }
        let (pw, ph) = self.extent(w, h);
        let mut out = Image::new(pw, ph, c);
        for (e, eye) in eyes.iter().enumerate() {
            let (x, y) = self.origin(e, w, h);
            out.paste(eye, x, y);
        }
        Some(out)
    }

    /// The eye of a picture arranged as `self` (the input) that output eye `e` is made
    /// from: the same eye, or for a `2d` input its one eye. A `2d` output's one eye is eye
    /// 0, the left.
    pub fn source_eye(self, e: usize) -> usize {
        e.min(self.eyes() - 1)
    }

    /// How many eyes of a picture arranged as `self` a conversion to `output` reads: the
    /// left eye alone for a `2d` output.
    pub fn eyes_read(self, output: Stereo) -> usize {
        self.eyes().min(output.eyes())
    }
}

/// A guess at projection and layout from a picture's size (and a declared projection, such
/// as OpenEXR's `envmap` attribute), with the reason, for [`guess`].
#[derive(Clone, Debug, PartialEq)]
pub struct Guess {
    /// The projection kind.
    pub kind: ProjectionKind,
    /// The layout of its layers in the picture.
    pub layout: Layout,
    /// Why: shown to the user, who can override it.
    pub reason: String,
}

/// `a`, `a or b`, `a, b or c`.
struct UnknownNameList<'a>(&'a [String]);

impl fmt::Display for UnknownNameList<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.split_last() {
            None => Ok(()),
            Some((last, [])) => f.write_str(last),
            Some((last, rest)) => write!(f, "{} or {last}", rest.join(", ")),
        }
    }
}

/// Guesses projection and layout of a `w`×`h` picture: 2:1 is lat-long, 4:3 and 3:4 are cube
/// crosses, 6:1 and 1:6 cube strips, 1:1 a sphere map; a declared kind wins when its layout
/// fits. `None` when nothing fits.
pub fn guess(w: u32, h: u32, declared: Option<ProjectionKind>) -> Option<Guess> {
    if let Some(kind) = declared {
        if let Some((layout, _, _)) = Layout::from_extent_of(w, h, kind) {
            let reason = format!("the file declares a {kind} map; {w}x{h} fits {layout}");
            return Some(Guess {
                kind,
                layout,
                reason,
            });
        }
    }
    let g = |kind, layout, why: &str| {
        Some(Guess {
            kind,
            layout,
            reason: format!("{w}x{h} is {why}"),
        })
    };
    if w == 2 * h {
        return g(
            ProjectionKind::LatLong,
            Layout::Separate,
            "2:1, the lat-long shape",
        );
    }
    if let Some((layout, _, _)) = Layout::from_extent(w, h, 6) {
        // v360's padded `eac` holds EAC only: a picture of its shape is an EAC frame.
        let kind = std::iter::once(ProjectionKind::Cube)
            .chain(ProjectionKind::ALL)
            .find(|&k| layout.holds(k))
            .unwrap_or(ProjectionKind::Cube);
        return g(kind, layout, &format!("the shape of a {kind} {layout}"));
    }
    if w == h {
        return g(
            ProjectionKind::Sphere,
            Layout::Separate,
            "square, taken as a sphere map (mirror ball)",
        );
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::CubeMap;

    /// A cube whose every texel holds its own (face, x, y), so any misplacement shows.
    fn labelled(n: u32) -> EnvMap {
        let faces = (0..6)
            .map(|f| {
                let mut img = Image::new(n, n, 3);
                for y in 0..n {
                    for x in 0..n {
                        img.set(x, y, &[f as f32, x as f32, y as f32]);
                    }
                }
                img
            })
            .collect();
        EnvMap::new(Projection::Cube(CubeMap), faces).unwrap()
    }

    #[test]
    fn cells_pack_and_unpack_with_every_turn_and_order() {
        let env = labelled(5);
        for grid in [CellGrid::C3x2, CellGrid::C6x1, CellGrid::C1x6] {
            for turn in 0..4u8 {
                let mut cells = CubeCells::v360(grid);
                cells.turns = [turn, (turn + 1) % 4, (turn + 2) % 4, turn, 3 - turn, 1];
                cells.faces.rotate_left(turn as usize);
                let layout = Layout::Cells(cells);
                let img = layout.pack(&env).unwrap();
                assert_eq!((img.width(), img.height()), cells.extent(5));
                assert_eq!(
                    Layout::from_extent(img.width(), img.height(), 6).map(|l| l.1),
                    Some(5)
                );
                assert_eq!(layout.unpack(&img, *env.projection()).unwrap(), env);
                // The text reads back as the same layout.
                assert_eq!(layout.to_string().parse::<Layout>().unwrap(), layout);
            }
        }
        let img = Layout::eac().pack(&env).unwrap();
        assert_eq!((img.width(), img.height()), (3 * 5 + 4, 2 * 5 + 8));
        assert_eq!(Layout::eac().unpack(&img, *env.projection()).unwrap(), env);
    }

    #[test]
    fn a_turned_cell_shows_its_face_turned_clockwise() {
        // v360's ROT_90 (`frot` 1) in `cube_to_xyz`: cell (c, d) shows face (d, −c) before
        // the mirror, so the face's top row lands in the cell's right column.
        let env = labelled(4);
        let mut cells = CubeCells::v360(CellGrid::C6x1);
        cells.turns[4] = 1; // cell 4 holds front, −Z
        let img = Layout::Cells(cells).pack(&env).unwrap();
        // Unturned, −Z's cell is mirrored left to right: cell x shows face x' = 3 − x.
        let plain = Layout::Cells(CubeCells::v360(CellGrid::C6x1))
            .pack(&env)
            .unwrap();
        assert_eq!(plain.get(16, 1), &[5.0, 3.0, 1.0]);
        // Turned: the mirrored face's top row (t = 0) runs down the cell's right column.
        for y in 0..4 {
            let px = img.get(16 + 3, y);
            assert_eq!((px[0], px[2]), (5.0, 0.0), "row {y}");
        }
    }

    #[test]
    fn bad_cell_strings_are_refused_by_name() {
        for (s, says) in [
            ("c3x2:forder=rludfx", "'x' is not a face letter"),
            ("c3x2:forder=rrudfb", "appears twice"),
            ("c3x2:forder=rlud", "six face letters"),
            ("c6x1:frot=0005", "six digits 0-3"),
            ("c6x1:frot=000004", "six digits 0-3"),
            ("c1x6:pad=0.9", "outside 0 to 0.1"),
            ("c1x6:pad=NaN", "outside 0 to 0.1"),
            ("c1x6:pad=x", "not a number"),
            ("c3x2:spin=1", "unknown option 'spin'"),
            ("eac:frot=000000", "takes no options"),
            ("hcross:frot=000000", "takes no options"),
        ] {
            let e = s.parse::<Layout>().unwrap_err();
            assert!(e.contains(says), "{s}: {e}");
        }
        assert_eq!(
            "c3x2:forder=rludfb:frot=000000:pad=0"
                .parse::<Layout>()
                .unwrap(),
            Layout::Cells(CubeCells::v360(CellGrid::C3x2))
        );
        assert_eq!("eac".parse::<Layout>().unwrap().to_string(), "eac");
    }

    #[test]
    fn stereo_split_and_join_are_inverse_and_put_the_left_eye_first() {
        let mut pic = Image::new(6, 4, 3);
        for y in 0..4 {
            for x in 0..6 {
                pic.set(x, y, &[x as f32, y as f32, 0.0]);
            }
        }
        let sbs = Stereo::SideBySide.split(pic.clone(), 2).unwrap();
        assert_eq!((sbs[0].width(), sbs[0].height()), (3, 4));
        assert_eq!(sbs[0].get(0, 0), &[0.0, 0.0, 0.0]);
        assert_eq!(sbs[1].get(0, 0), &[3.0, 0.0, 0.0]);
        assert_eq!(Stereo::SideBySide.join(sbs).unwrap(), pic);
        let tb = Stereo::TopBottom.split(pic.clone(), 2).unwrap();
        assert_eq!((tb[1].width(), tb[1].height()), (6, 2));
        assert_eq!(tb[1].get(5, 0), &[5.0, 2.0, 0.0]);
        assert_eq!(Stereo::TopBottom.join(tb).unwrap(), pic);
        // The left eye alone; a 2d picture is its one eye.
        assert_eq!(Stereo::SideBySide.split(pic.clone(), 1).unwrap().len(), 1);
        assert_eq!(
            Stereo::Mono.split(pic.clone(), 2).unwrap(),
            vec![pic.clone()]
        );
        assert!(Stereo::SideBySide.join(vec![pic.clone()]).is_none());
        // Odd halves are refused by name.
        let e = Stereo::TopBottom
            .split(Image::new(4, 5, 3), 2)
            .unwrap_err()
            .message;
        assert!(e.contains("even height") && e.contains("4x5"), "{e}");
        assert!(Stereo::SideBySide.eye_extent(7, 4).is_err());
        // v360's eye rule.
        assert_eq!(Stereo::SideBySide.eyes_read(Stereo::Mono), 1);
        assert_eq!(Stereo::Mono.source_eye(1), 0);
        assert_eq!(Stereo::TopBottom.source_eye(1), 1);
        assert_eq!("SBS".parse::<Stereo>().unwrap(), Stereo::SideBySide);
        assert_eq!(Stereo::Mono.to_string(), "2d");
    }
}
