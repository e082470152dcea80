//! What is rendered: objects with materials, the environment and how it is attached and
//! indexed.

use crate::lookup::{EnvCache, SpecularLobe};
use crate::mesh::Mesh;
use glam::Mat4;
use mirrorball_core::{Choice, EnvMap, UnknownName};
pub use mirrorball_filter::Filter;
use std::sync::Arc;

/// How the environment is indexed: the four ways environment mapping has been done. Their
/// differences are the point of the renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Indexing {
    /// **Mode 1**, fixed-function OpenGL texture-coordinate generation per vertex.
    /// `GL_SPHERE_MAP` for a sphere map: in eye space `u` = the unit vector from the eye to
    /// the vertex, `n` = the unit normal, `r = u − 2(n·u)n`, `m = 2√(rx² + ry² + (rz+1)²)`,
    /// `s = rx/m + ½`, `t = ry/m + ½` (OpenGL 4.6 compatibility profile §12.1.3, eq. 12.4–12.5);
    /// `s, t` are interpolated perspective-correctly and the sphere-map *texture* is read
    /// there, so chords cut across the map at grazing angles and triangles whose vertices
    /// straddle the rim sweep a "bow tie" through its centre (Zimmons, figures 21–22).
    /// `GL_REFLECTION_MAP` for cube maps (and for the other layered maps): `(s, t, r)` is the
    /// same `r`, interpolated, and the face is chosen per pixel. Other single-layer maps
    /// (lat-long, octahedral, …) get their own `(u, v)` per vertex, interpolated as a texgen
    /// with that formula would: the seams then show, as they would have.
    /// Note that `u` is the eye-to-vertex direction whatever the camera, exactly as the
    /// specification has it (texture generation knows nothing of the projection matrix).
    PerVertexTexgen,
    /// **Mode 2**, a reflected vector per vertex (true eye vector, so orthographic views
    /// use the view direction), interpolated perspective-correctly (unnormalised, as
    /// early cube-mapping hardware interpolated `(s, t, r)`) and looked up per pixel.
    PerVertexReflection,
    /// **Mode 3**, per pixel: the interpolated normal (renormalised) and the true eye vector
    /// at that pixel give the reflected direction, looked up per pixel.
    PerPixel,
    /// **Mode 4**, Greene (1986, §5–6): the reflected rays through a pixel's four corners
    /// bound a region of the world projection, and the region is filtered over the filter
    /// crate's solid-angle-weighted mip pyramid (EWA, or trilinear when the environment's
    /// filter is [`Filter::Trilinear`]), so highly curved surfaces do not alias.
    Cone,
}

impl Indexing {
    /// Every mode, in order.
    pub const ALL: [Indexing; 4] = [
        Indexing::PerVertexTexgen,
        Indexing::PerVertexReflection,
        Indexing::PerPixel,
        Indexing::Cone,
    ];

    /// The mode's number, 1 to 4.
    pub fn number(self) -> usize {
        Indexing::ALL.iter().position(|&m| m == self).unwrap_or(0) + 1
    }

    /// Canonical name.
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }
}

impl Choice for Indexing {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (
            Indexing::PerVertexTexgen,
            &["texgen", "1", "gl", "fixed-function", "per-vertex-texgen"],
        ),
        (
            Indexing::PerVertexReflection,
            &["vertex", "2", "per-vertex", "per-vertex-reflection"],
        ),
        (Indexing::PerPixel, &["pixel", "3", "per-pixel"]),
        (Indexing::Cone, &["cone", "4", "greene", "pixel-cone"]),
    ];
}
mirrorball_core::choice_traits!(Indexing);

/// What the environment is attached to (Zimmons, figure 18).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Attach {
    /// View-independent: a reflected direction is looked up as the world direction it is,
    /// so the reflection changes as the viewer moves around (a Christmas ornament).
    #[default]
    World,
    /// View-dependent: the direction is first expressed in eye coordinates and those are
    /// looked up as if they were world coordinates, so the map turns with the camera (as a
    /// plain `GL_SPHERE_MAP` does: the same picture from every side).
    Eye,
}

impl Choice for Attach {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Attach::World, &["world", "scene"]),
        (Attach::Eye, &["eye", "view", "camera"]),
    ];
}
mirrorball_core::choice_traits!(Attach);

/// The filters an [`Environment`] can be read with, in the order they are offered.
pub const ENVIRONMENT_FILTERS: [Filter; 4] = [
    Filter::Nearest,
    Filter::Bilinear,
    Filter::Trilinear,
    Filter::Ewa,
];

/// Parses the name of one of the [`ENVIRONMENT_FILTERS`]; the error lists them.
pub fn environment_filter(s: &str) -> Result<Filter, UnknownName> {
    Filter::from_name(s)
        .filter(|f| ENVIRONMENT_FILTERS.contains(f))
        .ok_or_else(|| UnknownName::among(s, ENVIRONMENT_FILTERS.map(Filter::name)))
}

/// The world projection the objects reflect, and how.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The map (any projection).
    pub map: Arc<EnvMap>,
    /// World- or eye-attached.
    pub attach: Attach,
    /// Filter of direct lookups (mode 4 and footprint-filtered backgrounds: see
    /// [`Filter`]).
    pub filter: Filter,
    /// Scale applied to every value read.
    pub intensity: f32,
    /// What is derived from `map` once and reused by every render (mip pyramids, Greene's
    /// prefiltered maps); shared by clones, rebuilt when `map` is replaced.
    pub cache: EnvCache,
}

impl Environment {
    /// A world-attached, bilinear environment.
    pub fn new(map: EnvMap) -> Environment {
        Environment {
            map: Arc::new(map),
            attach: Attach::World,
            filter: Filter::Bilinear,
            intensity: 1.0,
            cache: EnvCache::default(),
        }
    }
}

/// A 1-D colour ramp, evaluated piecewise linearly over evenly spaced stops.
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp(pub Vec<[f32; 3]>);

impl Ramp {
    /// Greene's "cheap chrome" ramp (§8): dark ground below the horizon, a bright band at
    /// the horizon, sky blue above, from straight down to straight up.
    pub fn chrome() -> Ramp {
        Ramp(vec![
            [0.10, 0.07, 0.05],
            [0.35, 0.25, 0.18],
            [0.55, 0.45, 0.35],
            [1.60, 1.55, 1.50],
            [0.45, 0.60, 0.90],
            [0.25, 0.40, 0.80],
            [0.15, 0.25, 0.65],
        ])
    }

    /// The colour at `t ∈ [0, 1]` (clamped).
    pub fn at(&self, t: f32) -> [f32; 3] {
        match self.0.len() {
            0 => [0.0; 3],
            1 => self.0[0],
            n => {
                let x = t.clamp(0.0, 1.0) * (n - 1) as f32;
                let i = (x.floor() as usize).min(n - 2);
                let f = x - i as f32;
                let (a, b) = (self.0[i], self.0[i + 1]);
                [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * f)
            }
        }
    }
}

/// How a surface turns the environment into colour.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// A perfect mirror: `tint × E(r)`.
    Mirror {
        /// Colour of the metal (1, 1, 1 for chrome).
        tint: [f32; 3],
    },
    /// A dielectric varnish over a flat colour: `F·E(r) + (1 − F)·base` with Schlick's
    /// `F = F₀ + (1 − F₀)(1 − cos θ)⁵`, θ between the normal and the direction to the eye.
    Fresnel {
        /// Reflectance at normal incidence (0.04 for glass and plastics).
        f0: f32,
        /// The colour under the varnish.
        base: [f32; 3],
    },
    /// Greene's "cheap chrome" (§8): no environment at all, a colour ramp indexed by the
    /// elevation of the reflected ray, `t = (r_y + 1)/2`.
    CheapChrome {
        /// The ramp, from straight down (t = 0) to straight up (t = 1).
        ramp: Ramp,
    },
    /// Lit simply, for scenes captured into world projections: `colour × (ambient +
    /// max(0, n·l))` with one light from `light` (world direction towards the light).
    Diffuse {
        /// Albedo.
        colour: [f32; 3],
        /// Towards the light.
        light: [f32; 3],
        /// Ambient term.
        ambient: f32,
    },
    /// Greene (1986, §7): `dc·D(n) + sc·S(r)`, with `D` the diffuse illumination map
    /// (Lambert, `E/π`) read at the surface normal and `S` the specular prefiltered map
    /// (a Phong or GGX lobe) read at the reflected vector of the indexing mode. Both are
    /// made from the environment by `mirrorball_filter::Prefilterer`, once per environment
    /// (see [`EnvCache`]), in the environment's own projection, so mode 1 reads `S` at its
    /// interpolated texture coordinates as the hardware would.
    Greene {
        /// Diffuse reflectance.
        dc: [f32; 3],
        /// Specular reflectance.
        sc: [f32; 3],
        /// The specular lobe.
        lobe: SpecularLobe,
    },
    /// Phong highlights from a sphere map of Phong intensities (Zimmons; see
    /// [`crate::maps::phong_sphere_map`]): `colour × (ambient + max(0, n·l)) + H(r)`, with
    /// `H` the eye-attached sphere map of `specular · max(0, r·l)^exponent` indexed by the
    /// mode's reflected vector in eye space (mode 1: `GL_SPHERE_MAP` texture coordinates per
    /// vertex, interpolated, with their chords and bow ties). `light` is in eye space
    /// (towards the light; it moves with the camera, as the map does). No environment is
    /// read.
    PhongMap {
        /// Diffuse colour.
        colour: [f32; 3],
        /// Highlight colour.
        specular: [f32; 3],
        /// Phong exponent.
        exponent: f32,
        /// Eye-space direction towards the light.
        light: [f32; 3],
        /// Ambient term.
        ambient: f32,
    },
}

impl Material {
    /// A chrome mirror.
    pub fn mirror() -> Material {
        Material::Mirror { tint: [1.0; 3] }
    }

    /// A simply lit diffuse colour (light from above and in front, ambient 0.25).
    pub fn diffuse(colour: [f32; 3]) -> Material {
        Material::Diffuse {
            colour,
            light: [0.3, 0.8, 0.5],
            ambient: 0.25,
        }
    }

    /// Which of the materials this is.
    ///
    /// ```
    /// use mirrorball_render::{Material, MaterialKind};
    /// assert_eq!(Material::mirror().kind(), MaterialKind::Mirror);
    /// assert_eq!("chrome".parse::<MaterialKind>().unwrap(), MaterialKind::Mirror);
    /// assert_eq!(MaterialKind::PhongMap.to_string(), "phong-map");
    /// ```
    pub fn kind(&self) -> MaterialKind {
        match self {
            Material::Mirror { .. } => MaterialKind::Mirror,
            Material::Fresnel { .. } => MaterialKind::Fresnel,
            Material::CheapChrome { .. } => MaterialKind::CheapChrome,
            Material::Diffuse { .. } => MaterialKind::Diffuse,
            Material::Greene { .. } => MaterialKind::Greene,
            Material::PhongMap { .. } => MaterialKind::PhongMap,
        }
    }

    /// Whether the material reads the environment.
    pub fn uses_environment(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. } | Material::Fresnel { .. } | Material::Greene { .. }
        )
    }
}

/// The materials by name, without their parameters: the one table of material names (a
/// [`Choice`], canonical name first), read by the CLI's `--material`, its help and the
/// scene file's `kind`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MaterialKind {
    /// [`Material::Mirror`].
    Mirror,
    /// [`Material::Fresnel`].
    Fresnel,
    /// [`Material::CheapChrome`].
    CheapChrome,
    /// [`Material::Diffuse`].
    Diffuse,
    /// [`Material::Greene`].
    Greene,
    /// [`Material::PhongMap`].
    PhongMap,
}

impl Choice for MaterialKind {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (MaterialKind::Mirror, &["mirror", "chrome"]),
        (MaterialKind::Fresnel, &["fresnel", "varnish", "plastic"]),
        (MaterialKind::CheapChrome, &["cheap-chrome", "ramp"]),
        (MaterialKind::Diffuse, &["diffuse", "matte"]),
        (MaterialKind::Greene, &["greene"]),
        (MaterialKind::PhongMap, &["phong-map", "phongmap"]),
    ];
}
mirrorball_core::choice_traits!(MaterialKind);

/// One object: a mesh, where it is, what it is made of.
#[derive(Clone, Debug)]
pub struct Object {
    /// The mesh in model space.
    pub mesh: Arc<Mesh>,
    /// Model to world.
    pub model: Mat4,
    /// Its material.
    pub material: Material,
}

/// Everything rendered.
///
/// ```
/// use glam::Vec3;
/// use mirrorball_core::{EnvMap, ProjectionKind};
/// use mirrorball_render::{render, Camera, Environment, Scene, Settings};
/// // No objects, the environment as background: every pixel shows the environment along
/// // its primary ray (here +Y is bright, −Y dark, and the camera looks up).
/// let latlong = ProjectionKind::LatLong.default_projection();
/// let env = EnvMap::from_fn(latlong, 64, 3, |d| [0.5 + 0.5 * d.y as f32, 0.0, 0.0, 1.0]);
/// let scene = Scene { objects: vec![], environment: Some(Environment::new(env)), background: true };
/// let mut cam = Camera::perspective(Vec3::ZERO, Vec3::Y, 30.0, 8, 8);
/// cam.up = Vec3::Z;
/// let frame = render(&scene, &cam, &Settings::default()).unwrap();
/// assert!(frame.color.get(4, 4)[0] > 0.98 && frame.color.get(4, 4)[3] == 1.0);
/// ```
#[derive(Clone, Debug)]
pub struct Scene {
    /// The objects.
    pub objects: Vec<Object>,
    /// The environment (reflected, and drawn behind the objects when `background`).
    pub environment: Option<Environment>,
    /// Draw the environment behind the objects (otherwise transparent black).
    pub background: bool,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Which indexing mode.
    pub indexing: Indexing,
    /// `n × n` samples per pixel, box-filtered (1 = one sample at the pixel centre).
    pub supersample: u32,
    /// Also produce the diagnostic channels.
    pub aovs: bool,
    /// Camera-rotation motion blur of the background (Greene §9): the camera of the
    /// previous frame. Each background pixel is filtered along the path its ray sweeps over
    /// the world projection between that camera and this one.
    pub motion_from: Option<crate::camera::Camera>,
    /// Leave out the back faces of meshes that are closed solids facing out
    /// ([`Mesh::is_closed_outward`](crate::Mesh::is_closed_outward)) and lie wholly beyond
    /// the near plane: their front faces hide them, so the picture is the same, made
    /// faster. `false` draws every triangle (to compare, or to measure the difference).
    pub cull_hidden_faces: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            indexing: Indexing::PerPixel,
            supersample: 1,
            aovs: false,
            motion_from: None,
            cull_hidden_faces: true,
        }
    }
}
