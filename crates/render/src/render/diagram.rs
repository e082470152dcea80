//! Pictures about a frame rather than of it: mode 1's per-vertex sphere-map coordinates,
//! and Zimmons' texture-space diagram of what a frame read.

use super::texgen::Texgen;
use super::{RenderError, Rendered};
use crate::camera::Camera;
use crate::scene::{Indexing, Scene, Settings};
use glam::{Mat3, Mat4, Vec2};
use mirrorball_core::{Image, SphereMap};

/// Per-vertex GL texgen `(s, t)` of mode 1 for a sphere map, for tests and the diagnostic
/// plot: for each vertex of `mesh` placed by `model` and seen by `cam`, the `GL_SPHERE_MAP`
/// coordinates in eye space, as `(s, t)` (OpenGL's `t` upwards).
pub fn sphere_map_texcoords(mesh: &crate::mesh::Mesh, model: Mat4, cam: &Camera) -> Vec<Vec2> {
    let view = cam.view();
    let mv = view * model;
    let nm = Mat3::from_mat4(mv).inverse().transpose();
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .map(|(&q, &n)| {
            let u = mv.transform_point3(q).normalize_or_zero();
            let ne = (nm * n).normalize_or_zero();
            let r = u - 2.0 * ne.dot(u) * ne;
            let st = SphereMap::gl_st(r.as_dvec3());
            Vec2::new(st.x as f32, st.y as f32)
        })
        .collect()
}

/// Zimmons' simulators as a picture: the environment map (its layers side by side, each in
/// a `cell`-pixel-wide panel, dimmed) with, drawn over it, the texels the frame read
/// (magenta: every pixel's `(u, v, layer)` from the diagnostic channels), and the per-vertex
/// texture coordinates of the objects' camera-facing triangles with their edges (yellow
/// edges, cyan vertices) — for mode 1 the texgen output itself, for the other modes the
/// coordinates of the per-vertex reflected vector. Straight edges in this plot are what
/// per-vertex interpolation does; where they cut across the map (a grazing quad's chord,
/// a rim-straddling triangle's bow tie) the picture goes wrong. Triangles spanning two
/// layers are not drawn; meshes over 50 000 triangles get vertices only.
///
/// `frame` must have been rendered with `aovs` on, with the same scene, camera and settings.
pub fn texture_space_diagram(
    scene: &Scene,
    cam: &Camera,
    settings: &Settings,
    frame: &Rendered,
    cell: u32,
) -> Result<Image, RenderError> {
    let env = scene
        .environment
        .as_ref()
        .ok_or_else(|| RenderError::request("the diagram needs an environment"))?;
    let aovs = frame
        .aovs
        .as_ref()
        .ok_or_else(|| RenderError::request("the diagram needs a frame rendered with aovs"))?;
    let map = &env.map;
    let layers = map.layers().len() as u32;
    let cw = cell.max(8);
    let ch = ((cw as f64 * map.height() as f64 / map.width() as f64).round() as u32).max(1);
    let mut out = Image::new(cw * layers, ch, 3);
    let panels = Panels { layers, cw, ch };
    draw_dimmed_map(&mut out, map, &panels);
    draw_read_texels(&mut out, &aovs.st_face, &panels);
    // Per-vertex coordinates and edges.
    let p = super::prepare(scene, cam, settings);
    let coords = vertex_coords(&p, cam, settings, map);
    let facing = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| p.pos[i as usize]);
        let n = (b - a).cross(c - a);
        let v = if cam.is_perspective() {
            a - cam.eye
        } else {
            p.forward
        };
        n.dot(v) < 0.0
    };
    if p.tris.len() <= 50_000 {
        draw_edges(
            &mut out,
            p.tris.iter().filter(|t| facing(t)),
            &coords,
            &panels,
        );
    }
    let used: std::collections::HashSet<u32> = p
        .tris
        .iter()
        .filter(|t| facing(t))
        .flat_map(|t| t.iter().copied())
        .collect();
    draw_vertices(&mut out, used, &coords, &panels);
    Ok(out)
}

/// The panels of [`texture_space_diagram`]: `layers` panels of `cw`×`ch` pixels side by
/// side, one per layer of the map.
struct Panels {
    layers: u32,
    cw: u32,
    ch: u32,
}

impl Panels {
    /// Sets the pixel of `(u, v)` (clamped into the panel) in layer `layer`'s panel to
    /// `c`; nothing for non-finite coordinates or a layer the map does not have.
    fn plot(&self, out: &mut Image, layer: u32, u: f32, v: f32, c: [f32; 3]) {
        let (layers, cw, ch) = (self.layers, self.cw, self.ch);
        if !(u.is_finite() && v.is_finite()) || layer >= layers {
            return;
        }
        let x = (u.clamp(0.0, 0.9999) * cw as f32) as u32 + layer * cw;
        let y = (v.clamp(0.0, 0.9999) * ch as f32) as u32;
        out.set(x, y, &c);
    }
}

/// The map's layers in their panels, dimmed and tone-mapped, nearest texel per plot pixel.
fn draw_dimmed_map(out: &mut Image, map: &mirrorball_core::EnvMap, panels: &Panels) {
    let (layers, cw, ch) = (panels.layers, panels.cw, panels.ch);
    for l in 0..layers {
        let img = &map.layers()[l as usize];
        for y in 0..ch {
            for x in 0..cw {
                let tx = (x * img.width() / cw).min(img.width() - 1);
                let ty = (y * img.height() / ch).min(img.height() - 1);
                let t = img.get(tx, ty);
                let c = [0, 1, 2].map(|k| 0.35 * crate::tone::Tone::Aces.apply(t[k]));
                out.set(l * cw + x, y, &c);
            }
        }
    }
}

/// The texels read by the objects, in magenta: each pixel of the `st` diagnostic channel
/// (`u`, `v`, layer) with a layer ≥ 0 (the background is −2).
fn draw_read_texels(out: &mut Image, st: &Image, panels: &Panels) {
    for y in 0..st.height() {
        for x in 0..st.width() {
            let p = st.get(x, y);
            if p[2] >= 0.0 {
                panels.plot(out, p[2] as u32, p[0], p[1], [1.0, 0.1, 0.9]);
            }
        }
    }
}

/// Each vertex's `(layer, u, v)` in `map`: for mode 1 the texgen output itself (sphere-map
/// `st` and `uv` in layer 0, a direction looked up), for the other modes the coordinates of
/// the per-vertex reflected vector; `None` where a direction has none.
fn vertex_coords(
    p: &super::Prepared,
    cam: &Camera,
    settings: &Settings,
    map: &mirrorball_core::EnvMap,
) -> Vec<Option<(u32, f32, f32)>> {
    (0..p.pos.len())
        .map(|i| match (settings.indexing, p.texgen_kind) {
            (Indexing::PerVertexTexgen, Texgen::SphereSt | Texgen::Uv) => {
                let g = p.texgen[i];
                Some((0, g.x, g.y))
            }
            (Indexing::PerVertexTexgen, Texgen::Vector) => {
                crate::fast::dir_to_uv(map, p.texgen[i]).map(|(l, u, v)| (l as u32, u, v))
            }
            _ => {
                let v = if cam.is_perspective() {
                    (p.pos[i] - cam.eye).normalize_or_zero()
                } else {
                    p.forward
                };
                let n = p.nrm[i];
                let r = v - 2.0 * n.dot(v) * n;
                crate::fast::dir_to_uv(map, p.attach(r).as_vec3()).map(|(l, u, v)| (l as u32, u, v))
            }
        })
        .collect()
}

/// The edges of `tris` in yellow, each a straight line in texture space as per-vertex
/// interpolation makes it (a point per plot pixel of its length, at most `4·(cw + ch)`);
/// triangles with a vertex without coordinates or spanning two layers are skipped.
fn draw_edges<'t>(
    out: &mut Image,
    tris: impl Iterator<Item = &'t [u32; 3]>,
    coords: &[Option<(u32, f32, f32)>],
    panels: &Panels,
) {
    let (cw, ch) = (panels.cw, panels.ch);
    for t in tris {
        let c = t.map(|i| coords[i as usize]);
        let (Some(a), Some(b), Some(cc)) = (c[0], c[1], c[2]) else {
            continue;
        };
        if a.0 != b.0 || b.0 != cc.0 {
            continue;
        }
        for (s, e) in [(a, b), (b, cc), (cc, a)] {
            let len = ((e.1 - s.1) * cw as f32).hypot((e.2 - s.2) * ch as f32);
            let n = (len.ceil() as u32).clamp(1, 4 * (cw + ch));
            for k in 0..=n {
                let f = k as f32 / n as f32;
                panels.plot(
                    out,
                    s.0,
                    s.1 + (e.1 - s.1) * f,
                    s.2 + (e.2 - s.2) * f,
                    [1.0, 0.9, 0.1],
                );
            }
        }
    }
}

/// The `used` vertices that have coordinates, each as a cyan 3×3-pixel square.
fn draw_vertices(
    out: &mut Image,
    used: impl IntoIterator<Item = u32>,
    coords: &[Option<(u32, f32, f32)>],
    panels: &Panels,
) {
    let (cw, ch) = (panels.cw, panels.ch);
    for i in used {
        if let Some((l, u, v)) = coords[i as usize] {
            let cx = u * cw as f32;
            let cy = v * ch as f32;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    panels.plot(
                        out,
                        l,
                        (cx + dx as f32) / cw as f32,
                        (cy + dy as f32) / ch as f32,
                        [0.1, 0.9, 1.0],
                    );
                }
            }
        }
    }
}
