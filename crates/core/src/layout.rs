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

use crate::projection::{Projection, ProjectionKind, WorldProjection};
use crate::{Choice, EnvMap, Image};
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
        }
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
        }
    }

    /// The cell of layer `i`: `(column, row, turned 180°)`.
    fn cell(self, i: usize) -> (u32, u32, bool) {
        match self {
            Layout::Separate => (0, 0, false),
            Layout::HorizontalCross => HCROSS[i],
            Layout::VerticalCross => VCROSS[i],
            Layout::HorizontalStrip => (i as u32, 0, false),
            Layout::VerticalStrip => (0, i as u32, false),
        }
    }

    /// The layout for a single picture of `w`×`h` holding `layers` layers, judged by its
    /// aspect ratio alone, with the cell size. `None` if no layout fits.
    pub fn from_extent(w: u32, h: u32, layers: usize) -> Option<(Layout, u32, u32)> {
        if layers == 1 {
            return Some((Layout::Separate, w, h));
        }
        for l in [
            Layout::HorizontalCross,
            Layout::VerticalCross,
            Layout::HorizontalStrip,
            Layout::VerticalStrip,
        ] {
            if !l.fits(layers) {
                continue;
            }
            let (c, r) = l.grid(layers);
            if w.is_multiple_of(c) && h.is_multiple_of(r) && w / c == h / r && w / c > 0 {
                return Some((l, w / c, h / r));
            }
        }
        None
    }

    /// Packs the layers of `env` into one picture (unused cross cells are black with zero
    /// alpha). For [`Layout::Separate`] the map must have a single layer.
    pub fn pack(self, env: &EnvMap) -> Option<Image> {
        let n = env.layers().len();
        if !self.fits(n) || (self == Layout::Separate && n != 1) {
            return None;
        }
        let (cw, ch) = (env.width(), env.height());
        let (gc, gr) = self.grid(n);
        let mut out = Image::new(cw * gc, ch * gr, env.channels());
        for (i, layer) in env.layers().iter().enumerate() {
            let (col, row, turned) = self.cell(i);
            if turned {
                out.paste(&layer.rotated_180(), col * cw, row * ch);
            } else {
                out.paste(layer, col * cw, row * ch);
            }
        }
        Some(out)
    }

    /// [`Layout::unpack`], taking the picture: a one-layer map (or a separate layout) keeps
    /// its texels where they are instead of copying them (100 MB for a 4096×2048 float
    /// lat-long).
    pub fn unpack_owned(self, image: Image, projection: Projection) -> Result<EnvMap, String> {
        if self == Layout::Separate {
            return EnvMap::new(projection, vec![image]).map_err(|e| e.to_string());
        }
        self.unpack(&image, projection)
    }

    /// Cuts a picture laid out this way into the layers of `projection`.
    pub fn unpack(self, image: &Image, projection: Projection) -> Result<EnvMap, String> {
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
    ];
}

impl Layout {
    /// The command-line name (the canonical name of [`Choice`]).
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }
}

impl fmt::Display for Layout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Layout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Layout::parse_name(s).map_err(|e| format!("unknown layout '{s}' (known: {})", e.list()))
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

/// Guesses projection and layout of a `w`×`h` picture: 2:1 is lat-long, 4:3 and 3:4 are cube
/// crosses, 6:1 and 1:6 cube strips, 1:1 a sphere map; a declared kind wins when its layout
/// fits. `None` when nothing fits.
pub fn guess(w: u32, h: u32, declared: Option<ProjectionKind>) -> Option<Guess> {
    if let Some(kind) = declared {
        let n = kind.default_projection().layer_count();
        if let Some((layout, _, _)) = Layout::from_extent(w, h, n) {
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
        return g(
            ProjectionKind::Cube,
            layout,
            &format!("the shape of a cube {layout}"),
        );
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
