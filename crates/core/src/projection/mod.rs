//! World projections: every way of flattening the sphere of directions onto images.
//!
//! A world projection maps a unit direction (where the light comes *from*, in world space)
//! to a layer (cube face, paraboloid half) and texture coordinates `(u, v)` in `[0, 1]²`, and
//! back. `u` grows to the right and `v` grows downwards in the stored picture, so texel
//! `(x, y)` of a `w`×`h` layer covers `[x/w, (x+1)/w] × [y/h, (y+1)/h]` and its centre sits at
//! `((x + ½)/w, (y + ½)/h)`. The conventions are collected in `ARCHITECTURE.md`.
//!
//! Every projection also knows its exact area element ([`WorldProjection::density`], solid
//! angle per unit of `u·v` area) and the exact solid angle of any texel
//! ([`WorldProjection::texel_solid_angle`]), in closed form where one exists and by
//! high-order quadrature of an exact one-dimensional integral where it does not.

mod azimuthal;
mod continuous_cube;
mod cube;
mod cylindrical;
pub mod derivative;
mod dual_fisheye;
mod eac;
pub(crate) mod fastmath;
mod latlong;
mod octahedral;
mod overlap;
mod perspective;
mod pseudo;
pub mod quadrature;
mod range;
mod spec;
mod tetrahedron;

/// The projection types, one `pub use` each: the crate's root re-exports all of them.
pub mod types {
    pub use super::azimuthal::{
        AngularMap, DualParaboloid, Fisheye, Frame, Lens, RadialMap, SphereMap,
    };
    pub use super::continuous_cube::ContinuousCube;
    pub use super::cube::{CubeFace, CubeMap, FaceLanes};
    pub use super::cylindrical::{Cylinder, CylinderRule};
    pub use super::dual_fisheye::{DualFisheye, FisheyeLens, LensModel};
    pub use super::eac::Eac;
    pub use super::latlong::{LatLong, Mercator};
    pub use super::octahedral::{EqualAreaOctahedral, Octahedral};
    pub use super::perspective::View;
    pub use super::pseudo::{Hammer, Sinusoidal};
    pub use super::tetrahedron::Tetrahedron;
}
pub use overlap::OverlapBlend;
pub use range::Range;
pub use spec::{parse_dir, Bounded, ProjectionSpec};
pub use types::*;

use crate::{Choice, UnknownName};
use glam::{DVec2, DVec3};
use std::fmt;
use std::str::FromStr;

/// One source lookup of the conversion's texel loop, from [`WorldProjection::lookup_batch`]:
/// the layer (`u32::MAX` where the direction is not covered), the texture coordinates and the
/// density there.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)] // four 4-byte fields in this order: the resampler loads four at once
pub struct Lookup {
    /// Layer, or `u32::MAX` when not covered.
    pub layer: u32,
    /// Texture coordinate `u`.
    pub u: f32,
    /// Texture coordinate `v`.
    pub v: f32,
    /// Solid angle per unit `uv` area there.
    pub density: f32,
}

/// A run of texel directions and densities in `f32`, one array per component, as
/// [`WorldProjection::span_dirs_f32`] fills it. All four slices have the same length.
pub struct DirRun<'a> {
    /// x components of the unit directions.
    pub x: &'a mut [f32],
    /// y components.
    pub y: &'a mut [f32],
    /// z components.
    pub z: &'a mut [f32],
    /// The projection's density at each texel centre.
    pub density: &'a mut [f32],
}

impl<'a> DirRun<'a> {
    /// Each texel's `(x, y, z, density)`, to fill in order (as many as `x` has).
    pub fn texels(
        self,
    ) -> impl Iterator<Item = (&'a mut f32, &'a mut f32, &'a mut f32, &'a mut f32)> {
        let n = self.x.len();
        let (y, z, d) = (&mut self.y[..n], &mut self.z[..n], &mut self.density[..n]);
        self.x
            .iter_mut()
            .zip(y)
            .zip(z)
            .zip(d)
            .map(|(((x, y), z), d)| (x, y, z, d))
    }
}

/// [`WorldProjection::span_dirs_f32`]'s default: `p`'s `span_dirs`, 32 texels at a time,
/// converted (for projections that override it for some of their cases only).
pub(crate) fn span_dirs_f32_of<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    y: u32,
    (w, h): (u32, u32),
    x0: u32,
    out: DirRun,
) {
    const CHUNK: usize = 32;
    let mut buf = [None; CHUNK];
    let n = out.x.len();
    for start in (0..n).step_by(CHUNK) {
        let m = CHUNK.min(n - start);
        p.span_dirs(layer, y, w, h, x0 + start as u32, &mut buf[..m]);
        for (i, t) in buf[..m].iter().enumerate() {
            let (d, dens) = t.unwrap_or((DVec3::Z, -1.0));
            let k = start + i;
            (out.x[k], out.y[k], out.z[k], out.density[k]) =
                (d.x as f32, d.y as f32, d.z as f32, dens as f32);
        }
    }
}

/// The behaviour every world projection shares. All math is in `f64`.
pub trait WorldProjection {
    /// Number of layers: 6 for the cube types (OpenGL order +X −X +Y −Y +Z −Z), 2 for the
    /// dual paraboloid (front, back), 1 otherwise.
    fn layer_count(&self) -> usize;

    /// Width and height of one layer when the user asks for edge `size` (the face edge of a
    /// cube, the width of a lat-long or Mercator image, the diameter of a disk map).
    fn layer_extent(&self, size: u32) -> (u32, u32);

    /// The layer and texture coordinates of unit direction `dir`, or `None` where the
    /// projection does not cover `dir` (outside a fisheye's field of view, beyond Mercator's
    /// latitude limit).
    fn dir_to_uv(&self, dir: DVec3) -> Option<(usize, DVec2)>;

    /// The unit direction at texture coordinates `uv` of `layer`, or `None` outside the
    /// covered domain (the corners of a disk-shaped map).
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3>;

    /// Solid angle per unit `uv` area at `uv`: `|∂d/∂u × ∂d/∂v|`. Zero outside the domain.
    fn density(&self, layer: usize, uv: DVec2) -> f64;

    /// Exact solid angle, in steradians, of texel `(x, y)` of a `w`×`h` layer (only the part
    /// that lies inside the covered domain counts).
    fn texel_solid_angle(&self, layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64;

    /// [`density`](WorldProjection::density) at the texture coordinates of unit direction
    /// `dir` (0 where not covered). Projections with a cheaper form in terms of the direction
    /// override it; the resampler calls it once per texel.
    #[inline]
    fn density_of_dir(&self, dir: DVec3) -> f64 {
        self.dir_to_uv(dir)
            .map_or(0.0, |(l, uv)| self.density(l, uv))
    }

    /// The centre directions of texel row `y` of a `w`×`h` layer, with the density there:
    /// `out[x] = Some((dir, density))`, where texels outside the covered domain take the
    /// direction of the nearest covered point and density 0. (The row's first `w` texels;
    /// see [`span_dirs`](WorldProjection::span_dirs).)
    #[inline]
    fn row_dirs(&self, layer: usize, y: u32, w: u32, h: u32, out: &mut [Option<(DVec3, f64)>]) {
        let n = out.len().min(w as usize);
        self.span_dirs(layer, y, w, h, 0, &mut out[..n]);
    }

    /// [`row_dirs`](WorldProjection::row_dirs) for the texels `x0 .. x0 + out.len()` of the
    /// row only: `out[i]` is texel `x0 + i`. On a grid `n` times finer (`n·w`×`n·h`), the
    /// span of `n` texels from `n·x` in row `n·y + j` gives row `j` of an `n`×`n` grid of
    /// points spread evenly over texel `(x, y)`, which is how the resampler integrates.
    /// Projections override it to hoist per-row work out of the per-texel loop.
    fn span_dirs(
        &self,
        layer: usize,
        y: u32,
        w: u32,
        h: u32,
        x0: u32,
        out: &mut [Option<(DVec3, f64)>],
    ) {
        let v = (y as f64 + 0.5) / h as f64;
        for (i, o) in out.iter_mut().enumerate() {
            let x = x0 as usize + i;
            let uv0 = DVec2::new((x as f64 + 0.5) / w as f64, v);
            let uv = self.nearest_covered(layer, uv0);
            *o = self.uv_to_dir(layer, uv).map(|d| {
                (
                    d,
                    if uv == uv0 {
                        self.density(layer, uv)
                    } else {
                        0.0
                    },
                )
            });
        }
    }

    /// [`span_dirs`](WorldProjection::span_dirs) in `f32`, one array per component (the
    /// form the resampler's vector loops want), for the `out.x.len()` texels from `x0`: unit
    /// direction and density there (0 outside the covered domain, −1 where the projection has
    /// no direction at all, which none of mirrorball's has). The default converts
    /// [`span_dirs`](WorldProjection::span_dirs); the cube and the lat-long compute it
    /// directly.
    fn span_dirs_f32(&self, layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        span_dirs_f32_of(self, layer, y, (w, h), x0, out)
    }

    /// The solid angle the projection covers: 4π for all but those with a limit (fisheye,
    /// Mercator, the views and cylinders with a field of view).
    fn covered_solid_angle(&self) -> f64 {
        4.0 * std::f64::consts::PI
    }

    /// [`dir_to_uv`](WorldProjection::dir_to_uv) and
    /// [`density_of_dir`](WorldProjection::density_of_dir) for a batch of unit directions
    /// given as separate x, y, z arrays, in `f32`: the texel loop's fast path. Projections
    /// override it with branch-free code the compiler vectorises; their results agree with
    /// the `f64` methods to about 1e-6 in `uv` (tested), a two-hundredth of a texel on a 16k
    /// map. The default calls the `f64` methods one direction at a time.
    fn lookup_batch(&self, xs: &[f32], ys: &[f32], zs: &[f32], out: &mut [Lookup]) {
        for (i, o) in out.iter_mut().enumerate() {
            let d = DVec3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
            *o = match self.dir_to_uv(d) {
                Some((l, uv)) => Lookup {
                    layer: l as u32,
                    u: uv.x as f32,
                    v: uv.y as f32,
                    density: self.density_of_dir(d) as f32,
                },
                None => Lookup {
                    layer: u32::MAX,
                    ..Lookup::default()
                },
            };
        }
    }

    /// The closest coordinates to `uv` inside the covered domain. Texels outside a disk map's
    /// rim are filled from here, so that filtering near the rim never pulls in black.
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        uv
    }

    /// Where texel `(x, y)`, which may lie one or more texels outside `layer`, really is: the
    /// neighbouring texel across a cube edge, around the longitude wrap or over a pole. The
    /// default extends the projection's formula past the edge and maps the direction back,
    /// falling back to clamping.
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        if let Some((l, t)) = self.uv_to_dir(layer, uv).and_then(|d| self.dir_to_uv(d)) {
            let tx = ((t.x * w as f64).floor() as i64).clamp(0, w as i64 - 1);
            let ty = ((t.y * h as f64).floor() as i64).clamp(0, h as i64 - 1);
            return (l, tx as u32, ty as u32);
        }
        (
            layer,
            x.clamp(0, w as i64 - 1) as u32,
            y.clamp(0, h as i64 - 1) as u32,
        )
    }

    /// For reading maps of this projection with `layers` layers of `extent` texels as the
    /// source of a conversion: where two parts of the map see the same directions (a dual
    /// fisheye's overlap), the blend of those parts, planned once for that size and applied
    /// to each source map before its lookups, which then read the blend; `None` (the
    /// default: nothing seen twice) reads the maps as they are.
    fn overlap_blend(&self, _extent: (u32, u32), _layers: usize) -> Option<OverlapBlend> {
        None
    }

    /// Whether [`WorldProjection::overlap_blend`] changes maps of this projection (some
    /// direction is seen twice), so that its lookups cannot read a map as it is.
    fn blends_overlap(&self) -> bool {
        false
    }
}

/// The one registry of projections: each row is a kind's variant (its doc comment), its
/// names (canonical first, then aliases), a one-line description and its projection with
/// the documented default parameters. [`ProjectionKind`], [`ProjectionKind::ALL`], its
/// [`Choice`] table, [`ProjectionKind::about`], [`ProjectionKind::default_projection`] and
/// the CLI's help ([`ProjectionKind::help_list`]) all come from it; adding a projection is
/// one row here (and its module).
macro_rules! projections {
    ($($(#[$doc:meta])* $kind:ident: [$($name:literal),+ $(,)?], $about:literal, $default:expr;)+) => {
        /// The names of the projections, as the command line spells them.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum ProjectionKind {
            $($(#[$doc])* $kind,)+
        }

        impl ProjectionKind {
            /// Every kind, in the order the documentation lists them.
            pub const ALL: [ProjectionKind; [$(stringify!($kind)),+].len()] =
                [$(ProjectionKind::$kind),+];

            /// One line saying what the projection is, for help texts and tables.
            pub fn about(self) -> &'static str {
                match self {
                    $(ProjectionKind::$kind => $about,)+
                }
            }

            /// What an output's texels outside the covered domain hold unless asked
            /// otherwise: black for cameras' frames and pictures people look at (fisheye,
            /// dual fisheye, Hammer, sinusoidal: v360's rule), the rim's value for the maps
            /// a renderer samples (sphere, angular, paraboloid), which filtering near the
            /// rim must not darken. Projections covering their whole picture never have
            /// such texels.
            pub fn outside(self) -> crate::Outside {
                match self {
                    ProjectionKind::Fisheye
                    | ProjectionKind::DualFisheye
                    | ProjectionKind::Hammer
                    | ProjectionKind::Sinusoidal => crate::Outside::Black,
                    _ => crate::Outside::Rim,
                }
            }

            /// The projection with its documented default parameters.
            pub fn default_projection(self) -> Projection {
                match self {
                    $(ProjectionKind::$kind => $default,)+
                }
            }
        }

        impl Choice for ProjectionKind {
            const NAMES: &'static [(Self, &'static [&'static str])] =
                &[$((ProjectionKind::$kind, &[$($name),+]),)+];
        }
    };
}

projections! {
    /// Latitude-longitude (equirectangular).
    LatLong: ["latlong", "lat-long", "latlon", "equirect", "equirectangular", "longlat", "spherical"],
        "latitude-longitude (equirectangular), 2:1",
        Projection::LatLong(LatLong);
    /// OpenGL cube map.
    Cube: ["cube", "cubemap", "cube-map"],
        "six faces, OpenGL order and orientation",
        Projection::Cube(CubeMap);
    /// OpenGL sphere map.
    Sphere: ["sphere", "spheremap", "sphere-map", "matcap", "mirrorball", "mirror-ball"],
        "OpenGL's GL_SPHERE_MAP (mirror ball), taken looking along `look`",
        Projection::Sphere(SphereMap::default());
    /// Dual paraboloid.
    Paraboloid: ["paraboloid", "dual-paraboloid", "parabolic", "dp"],
        "dual paraboloid, front and back halves",
        Projection::Paraboloid(DualParaboloid::default());
    /// Continuous cube map.
    ContinuousCube: ["continuous-cube", "continuouscube", "ccube"],
        "the cube folded onto the sphere (Grimm & Niebruegge)",
        Projection::ContinuousCube(ContinuousCube);
    /// Mercator.
    Mercator: ["mercator"],
        "Mercator with a latitude limit (`max-lat`)",
        Projection::Mercator(Mercator::default());
    /// Angular map (light probe).
    Angular: ["angular", "angular-map", "lightprobe", "light-probe", "probe"],
        "Debevec's angular light-probe map",
        Projection::Angular(AngularMap::default());
    /// Fisheye.
    Fisheye: ["fisheye", "omnimax", "dome"],
        "fisheye of any field of view and lens",
        Projection::Fisheye(Fisheye::default());
    /// Octahedral.
    Octahedral: ["octahedral", "octahedron", "oct"],
        "the octahedron unfolded into a square",
        Projection::Octahedral(Octahedral);
    /// Equal-area octahedral.
    EqualAreaOctahedral: ["equal-area-octahedral", "eao", "clarberg", "equal-area-oct"],
        "Clarberg's octahedral map, every texel the same solid angle",
        Projection::EqualAreaOctahedral(EqualAreaOctahedral);
    /// Central cylindrical (`tan` latitude linear in `v`).
    Cylindrical: ["cylindrical", "central-cylindrical", "cylinder"],
        "central cylinder (`hfov`, `vfov`)",
        Projection::Cylinder(Cylinder::central());
    /// Lambert's cylindrical equal-area.
    CylindricalEqualArea: ["cylindrical-equal-area", "cylindricalea", "cea", "lambert-cylindrical"],
        "Lambert's cylindrical equal-area",
        Projection::Cylinder(Cylinder::equal_area());
    /// Half equirectangular (VR180): the front hemisphere.
    HalfEquirect: ["half-equirect", "hequirect", "half-equirectangular", "vr180"],
        "the front hemisphere, 1:1 (VR180)",
        Projection::Cylinder(Cylinder::half_equirect());
    /// Hammer's equal-area ellipse (Hammer–Aitoff).
    Hammer: ["hammer", "hammer-aitoff"],
        "Hammer's equal-area ellipse, 2:1",
        Projection::Hammer(Hammer::default());
    /// Sinusoidal (Sanson–Flamsteed).
    Sinusoidal: ["sinusoidal", "sanson-flamsteed"],
        "sinusoidal (Sanson-Flamsteed) equal-area map, 2:1",
        Projection::Sinusoidal(Sinusoidal);
    /// Rectilinear (perspective) view.
    Perspective: ["perspective", "rectilinear", "flat", "gnomonic"],
        "a rectilinear view (`hfov`, `vfov`, `yaw`, `pitch`, `roll`)",
        Projection::View(View::perspective(90.0, 90.0, 0.0, 0.0, 0.0).expect("valid"));
    /// Pannini view.
    Pannini: ["pannini", "panini"],
        "a Pannini view (`d`)",
        Projection::View(View::pannini(1.0, 120.0, 90.0, 0.0, 0.0, 0.0).expect("valid"));
    /// Equi-angular cube map (YouTube's EAC, v360's `eac`).
    Eac: ["eac", "equi-angular-cube", "equiangular-cube", "equi-angular-cubemap"],
        "equi-angular cube map (YouTube's EAC, v360's eac layout)",
        Projection::Eac(Eac);
    /// Dual fisheye: two lenses back to back in one 2:1 picture.
    DualFisheye: ["dual-fisheye", "dfisheye", "dualfisheye", "dual_fisheye"],
        "two lenses back to back in one 2:1 picture",
        Projection::DualFisheye(DualFisheye::default());
    /// FFmpeg v360's tetrahedron net.
    Tetrahedron: ["tetrahedron", "tetra"],
        "FFmpeg v360's tetrahedron unfolded, 2:1",
        Projection::Tetrahedron(Tetrahedron);
}

impl ProjectionKind {
    /// The canonical command-line name (the canonical name of [`Choice`]).
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }

    /// The aliases of the kind (its names after the canonical one).
    pub fn aliases(self) -> &'static [&'static str] {
        Self::NAMES
            .iter()
            .find(|(k, _)| *k == self)
            .map(|(_, n)| &n[1..])
            .expect("every kind is in the table")
    }

    /// Every kind, one a line: `  name  description (also: aliases)`, for a command
    /// line's help.
    pub fn help_list() -> String {
        let width = Self::ALL.iter().map(|k| k.name().len()).max().unwrap_or(0);
        let mut out = String::new();
        for k in Self::ALL {
            let also = k
                .aliases()
                .iter()
                .filter(|a| !a.contains('_'))
                .copied()
                .collect::<Vec<_>>();
            out.push_str(&format!("  {:width$}  {}", k.name(), k.about()));
            if !also.is_empty() {
                out.push_str(&format!(" (also: {})", also.join(", ")));
            }
            out.push('\n');
        }
        out
    }
}

impl fmt::Display for ProjectionKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A projection name that is not known; the message lists the known ones.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownProjection(pub String);

impl fmt::Display for UnknownProjection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let known = UnknownName::new::<ProjectionKind>(&self.0);
        write!(
            f,
            "unknown projection '{}' (known: {})",
            self.0,
            known.list()
        )
    }
}

impl std::error::Error for UnknownProjection {}

impl FromStr for ProjectionKind {
    type Err = UnknownProjection;
    /// Accepts the canonical names and common aliases, case-insensitively.
    ///
    /// ```
    /// use mirrorball_core::ProjectionKind;
    /// assert_eq!("equirect".parse::<ProjectionKind>().unwrap(), ProjectionKind::LatLong);
    /// assert_eq!("cubemap".parse::<ProjectionKind>().unwrap(), ProjectionKind::Cube);
    /// assert!("banana".parse::<ProjectionKind>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ProjectionKind::from_name(s).ok_or_else(|| UnknownProjection(s.to_string()))
    }
}

/// The one list of projection types: each row is a variant of [`Projection`] and the type
/// it holds, and the kind of a value of it where the variant is not itself a kind's name
/// (a [`Cylinder`] is one of three kinds, a [`View`] one of two). The enum, its
/// [`WorldProjection`] delegation, [`Projection::kind`] and the `From` conversions come
/// from it.
macro_rules! projection_types {
    ($($(#[$doc:meta])* $v:ident($t:ty) $(, |$c:ident| $kind:expr)?;)+) => {
        /// Any world projection, with its parameters. Implements [`WorldProjection`] by
        /// delegating to the named type inside.
        // The dual fisheye (two lenses, each with its frame) is the largest variant, a few
        // hundred bytes: `Projection` stays `Copy` and is passed by reference in the loops.
        #[allow(clippy::large_enum_variant)]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum Projection {
            $($(#[$doc])* $v($t),)+
        }

        /// `$e` with `$p` bound to the projection type inside `$self`.
        macro_rules! delegate {
            ($self_:ident, $p_:ident => $e_:expr) => {
                match $self_ {
                    $(Projection::$v($p_) => $e_,)+
                }
            };
        }

        impl Projection {
            /// Which kind of projection this is.
            pub fn kind(&self) -> ProjectionKind {
                match self {
                    $(Projection::$v(_p) => projection_types!(@kind _p, $v $(, |$c| $kind)?),)+
                }
            }
        }

        $(
            impl From<$t> for Projection {
                fn from(p: $t) -> Projection {
                    Projection::$v(p)
                }
            }
        )+
    };
    (@kind $p:ident, $v:ident) => { ProjectionKind::$v };
    (@kind $p:ident, $v:ident, |$c:ident| $kind:expr) => {{
        let $c = $p;
        $kind
    }};
}

projection_types! {
    /// See [`LatLong`].
    LatLong(LatLong);
    /// See [`CubeMap`].
    Cube(CubeMap);
    /// See [`SphereMap`].
    Sphere(SphereMap);
    /// See [`DualParaboloid`].
    Paraboloid(DualParaboloid);
    /// See [`ContinuousCube`].
    ContinuousCube(ContinuousCube);
    /// See [`Mercator`].
    Mercator(Mercator);
    /// See [`AngularMap`].
    Angular(AngularMap);
    /// See [`Fisheye`].
    Fisheye(Fisheye);
    /// See [`Octahedral`].
    Octahedral(Octahedral);
    /// See [`EqualAreaOctahedral`].
    EqualAreaOctahedral(EqualAreaOctahedral);
    /// See [`Cylinder`]: cylindrical, cylindrical equal-area or half equirectangular, by
    /// its [`CylinderRule`].
    Cylinder(Cylinder), |c| match c.rule() {
        CylinderRule::Central => ProjectionKind::Cylindrical,
        CylinderRule::EqualArea => ProjectionKind::CylindricalEqualArea,
        CylinderRule::Equidistant => ProjectionKind::HalfEquirect,
    };
    /// See [`Hammer`].
    Hammer(Hammer);
    /// See [`Sinusoidal`].
    Sinusoidal(Sinusoidal);
    /// See [`View`]: perspective or Pannini.
    View(View), |v| if v.is_pannini() {
        ProjectionKind::Pannini
    } else {
        ProjectionKind::Perspective
    };
    /// See [`Eac`].
    Eac(Eac);
    /// See [`DualFisheye`].
    DualFisheye(DualFisheye);
    /// See [`Tetrahedron`].
    Tetrahedron(Tetrahedron);
}

impl Projection {
    /// The canonical name of this projection's kind.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }
}

impl WorldProjection for Projection {
    #[inline]
    fn layer_count(&self) -> usize {
        delegate!(self, p => p.layer_count())
    }
    #[inline]
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        delegate!(self, p => p.layer_extent(size))
    }
    #[inline]
    fn dir_to_uv(&self, dir: DVec3) -> Option<(usize, DVec2)> {
        delegate!(self, p => p.dir_to_uv(dir))
    }
    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        delegate!(self, p => p.uv_to_dir(layer, uv))
    }
    #[inline]
    fn density(&self, layer: usize, uv: DVec2) -> f64 {
        delegate!(self, p => p.density(layer, uv))
    }
    fn texel_solid_angle(&self, layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        delegate!(self, p => p.texel_solid_angle(layer, x, y, w, h))
    }
    fn covered_solid_angle(&self) -> f64 {
        delegate!(self, p => p.covered_solid_angle())
    }
    #[inline]
    fn density_of_dir(&self, dir: DVec3) -> f64 {
        delegate!(self, p => p.density_of_dir(dir))
    }
    fn span_dirs(
        &self,
        layer: usize,
        y: u32,
        w: u32,
        h: u32,
        x0: u32,
        out: &mut [Option<(DVec3, f64)>],
    ) {
        delegate!(self, p => p.span_dirs(layer, y, w, h, x0, out))
    }
    fn span_dirs_f32(&self, layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        delegate!(self, p => p.span_dirs_f32(layer, y, w, h, x0, out))
    }
    fn lookup_batch(&self, xs: &[f32], ys: &[f32], zs: &[f32], out: &mut [Lookup]) {
        delegate!(self, p => p.lookup_batch(xs, ys, zs, out))
    }
    #[inline]
    fn nearest_covered(&self, layer: usize, uv: DVec2) -> DVec2 {
        delegate!(self, p => p.nearest_covered(layer, uv))
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        delegate!(self, p => p.wrap_texel(layer, x, y, w, h))
    }
    fn overlap_blend(&self, extent: (u32, u32), layers: usize) -> Option<OverlapBlend> {
        delegate!(self, p => p.overlap_blend(extent, layers))
    }
    fn blends_overlap(&self) -> bool {
        delegate!(self, p => p.blends_overlap())
    }
}

/// The `[lo, hi]` range in `uv` of texel index `i` of `n`.
#[inline]
pub(crate) fn texel_range(i: u32, n: u32) -> (f64, f64) {
    (i as f64 / n as f64, (i as f64 + 1.0) / n as f64)
}
