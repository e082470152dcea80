//! What the studio has loaded, and what the page is told about it.

use mirrorball_core::glam::Mat4;
use mirrorball_core::glam::{DVec3, Mat3};
use mirrorball_core::{
    Choice, CylinderRule, EnvMap, Frame, Layout, Lens, Projection, ProjectionKind, RadialMap,
    WorldProjection,
};
use mirrorball_render::tone::Tone;
use mirrorball_render::{
    Attach, Builtin, Camera, CameraLens, Environment, Indexing, Material, Mesh, Object, Scene,
    Settings,
};
use serde_json::{json, Value};
use std::sync::Arc;

/// A scene as `mirrorball render` would draw it: objects, environment, camera, the
/// settings, and the display's exposure and tone curve.
#[derive(Clone)]
pub struct SceneView {
    /// What it was read from (a file's name).
    pub name: String,
    pub scene: Scene,
    pub camera: Camera,
    pub settings: Settings,
    pub exposure: f32,
    pub tone: Tone,
    /// The scene file as JSON whose paths are absolute (`docs/render-scene.md`), which the
    /// page exports with its own camera and mode; `None` when the scene came from no file
    /// or its environment was replaced (the file would name the wrong one).
    pub source: Option<Value>,
    /// Per object, the built-in mesh and tessellation it was made from (`None`: a mesh
    /// file), so that the page may ask for it tessellated otherwise (`/api/mesh/I?tessellation=N`).
    pub builtins: Vec<Option<(Builtin, u32)>>,
}

/// What a file held.
pub enum Opened {
    /// A scene file: replaces the scene.
    Scene(Box<SceneView>),
    /// An environment map: replaces the scene's environment (world-attached, bilinear,
    /// intensity 1 if the scene had none).
    Environment { name: String, map: Box<EnvMap> },
    /// A mesh file: shown in place of the scene's objects, as a mirror of unit size
    /// (`Mesh::normalizing_transform`, as `render` frames mesh files).
    Mesh { name: String, mesh: Box<Mesh> },
}

/// What the page may show in place of the scene's objects (`POST /api/object`).
pub enum ObjectChoice {
    /// The scene's own objects again.
    Scene,
    /// One built-in at the origin, at a tessellation.
    Builtin(Builtin, u32),
    /// One mesh (a file uploaded, or one the embedding program bundles), called `name`.
    Mesh { name: String, mesh: Arc<Mesh> },
    /// The mesh file opened last ([`State::base_object`]) again, else the scene's own.
    Opened,
}

/// The scene's own objects, kept while another is shown: the objects, their built-ins and
/// the scene file.
#[derive(Clone)]
struct SceneObjects {
    objects: Vec<Object>,
    builtins: Vec<Option<(Builtin, u32)>>,
    source: Option<Value>,
}

/// Everything loaded.
pub struct State {
    pub view: SceneView,
    /// Messages for the page (the newest last): files that could not be read.
    pub errors: Vec<String>,
    /// Bumped on every change, so that the page knows to fetch again.
    pub generation: u64,
    /// What is shown in place of the scene's objects (`None`: the scene's own), and the
    /// scene's objects kept meanwhile.
    shown: Option<(String, SceneObjects)>,
    /// The meshes the embedding program bundles ([`crate::Host::bundled_meshes`]).
    pub bundled: &'static [&'static str],
    /// The mesh file opened last (named on the command line, picked or dropped) since the
    /// scene was: what a link that names no object shows ([`State::base_object`]).
    opened: Option<(String, Arc<Mesh>)>,
}

/// The most triangles the page may ask a built-in to be tessellated into.
pub const MAX_TRIANGLES: u64 = 1 << 21;

/// The most messages kept for the page.
const MAX_ERRORS: usize = 20;

impl State {
    pub fn new(view: SceneView) -> State {
        State {
            view,
            errors: Vec::new(),
            generation: 1,
            shown: None,
            bundled: &[],
            opened: None,
        }
    }

    /// Takes in what a file held. The messages of what was refused before are let go: the
    /// page shows what went wrong since the last thing that loaded.
    pub fn apply(&mut self, opened: Opened) {
        self.errors.clear();
        match opened {
            Opened::Scene(v) => {
                self.view = *v;
                self.shown = None;
                self.opened = None;
            }
            Opened::Mesh { name, mesh } => {
                let mesh: Arc<Mesh> = Arc::from(mesh);
                self.opened = Some((name.clone(), mesh.clone()));
                self.show_object(ObjectChoice::Mesh { name, mesh });
                return;
            }
            Opened::Environment { name, map } => {
                let env = match self.view.scene.environment.take() {
                    Some(e) => Environment {
                        map: Arc::new(*map),
                        cache: Default::default(),
                        ..e
                    },
                    None => Environment {
                        map: Arc::new(*map),
                        attach: Attach::World,
                        filter: mirrorball_render::Filter::Bilinear,
                        intensity: 1.0,
                        cache: Default::default(),
                    },
                };
                self.view.scene.environment = Some(env);
                self.view.source = None;
                if let Some((_, kept)) = &mut self.shown {
                    kept.source = None;
                }
                self.view.name = format!("{} with {name}", self.view.name);
            }
        }
        self.generation += 1;
    }

    /// Shows `choice` in place of the scene's objects: one mirror, with the scene's camera,
    /// environment and settings. A built-in stays in the scene file the page exports
    /// (`meshes` becomes that built-in); a mesh has no path a scene file could name, so the
    /// page cannot export the scene while it is shown.
    pub fn show_object(&mut self, choice: ObjectChoice) {
        self.errors.clear();
        let v = &mut self.view;
        let kept = || SceneObjects {
            objects: v.scene.objects.clone(),
            builtins: v.builtins.clone(),
            source: v.source.clone(),
        };
        let kept = match self.shown.take() {
            Some((_, k)) => k,
            None => kept(),
        };
        let choice = match choice {
            ObjectChoice::Opened => match &self.opened {
                Some((name, mesh)) => ObjectChoice::Mesh {
                    name: name.clone(),
                    mesh: mesh.clone(),
                },
                None => ObjectChoice::Scene,
            },
            c => c,
        };
        let (name, object, builtin, source) = match choice {
            ObjectChoice::Opened | ObjectChoice::Scene => {
                v.scene.objects = kept.objects;
                v.builtins = kept.builtins;
                v.source = kept.source;
                self.generation += 1;
                return;
            }
            ObjectChoice::Builtin(b, level) => {
                let object = Object {
                    mesh: Arc::new(b.mesh(level)),
                    model: Mat4::IDENTITY,
                    material: Material::mirror(),
                };
                let source = kept.source.clone().map(|mut s| {
                    s["meshes"] = json!([{
                        "mesh": b.name(),
                        "tessellation": level,
                        "material": {"kind": "mirror"},
                    }]);
                    s
                });
                (b.name().to_string(), object, Some((b, level)), source)
            }
            ObjectChoice::Mesh { name, mesh } => {
                let object = Object {
                    model: mesh.normalizing_transform(),
                    mesh,
                    material: Material::mirror(),
                };
                (name, object, None, None)
            }
        };
        v.scene.objects = vec![object];
        v.builtins = vec![builtin];
        v.source = source;
        self.shown = Some((name, kept));
        self.generation += 1;
    }

    /// The name of what is shown in place of the scene's objects, or `None`.
    pub fn shown_object(&self) -> Option<&str> {
        self.shown.as_ref().map(|(n, _)| n.as_str())
    }

    /// What a link that names no object shows: the mesh file opened last, or `scene` (the
    /// scene's own objects). An object another link or the menu chose is not kept: a link
    /// decides the whole view.
    pub fn base_object(&self) -> &str {
        self.opened.as_ref().map_or("scene", |(n, _)| n.as_str())
    }

    /// The name of the mesh file opened last, if any ([`ObjectChoice::Opened`]).
    pub fn opened_object(&self) -> Option<&str> {
        self.opened.as_ref().map(|(n, _)| n.as_str())
    }

    /// Records a message for the page, kept until something loads or is shown.
    pub fn error(&mut self, message: String) {
        self.errors.push(message);
        if self.errors.len() > MAX_ERRORS {
            self.errors.remove(0);
        }
        self.generation += 1;
    }

    /// What `POST /api/object` may show: `scene`, the built-ins, the bundled meshes and
    /// the mesh file opened last.
    pub fn object_choices(&self) -> Vec<&str> {
        let mut names: Vec<&str> = (["scene"].into_iter())
            .chain(Builtin::ALL.iter().map(|b| b.name()))
            .chain(self.bundled.iter().copied())
            .collect();
        if let Some(n) = self.opened_object().filter(|n| !names.contains(n)) {
            names.push(n);
        }
        names
    }

    /// The page's description of everything loaded.
    pub fn describe(&self) -> Value {
        json!({
            "generation": self.generation,
            "scene": describe_scene(&self.view),
            "object": self.shown_object(),
            "baseObject": self.base_object(),
            "objectChoices": self.object_choices(),
            "errors": self.errors,
            "projections": projections(),
        })
    }
}

/// A column-major 4×4 matrix as 16 numbers.
fn mat(m: mirrorball_core::glam::Mat4) -> Vec<f32> {
    m.to_cols_array().to_vec()
}

fn describe_scene(v: &SceneView) -> Value {
    let c = &v.camera;
    let (fov, ortho) = match c.lens {
        CameraLens::Perspective { fov_y_deg } => (Some(fov_y_deg), None),
        CameraLens::Orthographic { half_height } => (None, Some(half_height)),
    };
    let mut notes = Vec::new();
    let objects: Vec<Value> = (v.scene.objects.iter().enumerate())
        .map(|(i, o)| {
            let material = match &o.material {
                Material::Mirror { tint } => json!({"kind": "mirror", "tint": tint}),
                m => {
                    notes.push(format!(
                        "object {i}: the viewport draws the {} material as a mirror",
                        m.kind().name()
                    ));
                    json!({"kind": "mirror", "tint": [1.0, 1.0, 1.0]})
                }
            };
            let builtin = v.builtins.get(i).copied().flatten();
            json!({
                "mesh": i,
                "vertices": o.mesh.positions.len(),
                "triangles": o.mesh.triangles.len(),
                "material": material,
                "builtin": builtin.map(|(b, _)| b.name()),
                "tessellation": builtin.map(|(_, l)| l),
                "maxTessellation": builtin.map(|(b, _)| b.max_tessellation(MAX_TRIANGLES)),
            })
        })
        .collect();
    let cone = v.settings.indexing == Indexing::Cone;
    if cone {
        let asked = v.scene.environment.as_ref().map(|e| e.filter);
        if asked != Some(mirrorball_render::Filter::Trilinear) {
            notes.push(
                "mode 4: the viewport approximates the renderer's EWA by anisotropic taps (a trilinear environment it draws exactly)"
                    .into(),
            );
        }
    }
    if v.settings.supersample != 1 {
        notes.push(format!(
            "the viewport draws 1 sample a pixel (the scene asks for {0}×{0})",
            v.settings.supersample
        ));
    }
    let environment = v.scene.environment.as_ref().map(|e| {
        if !cone && e.filter != mirrorball_render::Filter::Bilinear {
            notes.push(format!(
                "the viewport reads the environment bilinearly (the scene asks for {})",
                e.filter.name()
            ));
        }
        let mut d = describe_map(&e.map);
        d["attach"] = json!(e.attach.name());
        d["filter"] = json!(e.filter.name());
        d["intensity"] = json!(e.intensity);
        d
    });
    json!({
        "name": v.name,
        "camera": {
            "eye": c.eye.to_array(), "target": c.target.to_array(), "up": c.up.to_array(),
            "fov": fov, "orthoHalfHeight": ortho, "near": c.near, "far": c.far,
            "width": c.width, "height": c.height,
            "view": mat(c.view()), "projection": mat(c.projection()),
        },
        "indexing": v.settings.indexing.name(),
        "mode": v.settings.indexing.number(),
        "background": v.scene.background,
        "source": v.source,
        "exposure": v.exposure,
        "tone": v.tone.name(),
        "objects": objects,
        "environment": environment,
        "notes": notes,
    })
}

/// An environment map's projection, its frame and its size, for the page.
pub fn describe_map(map: &EnvMap) -> Value {
    let p = map.projection();
    json!({
        "projection": p.name(),
        "spec": p.to_string(),
        "gpu": gpu_kind(p).is_some(),
        "frame": frame_of(p).map(|m| m.to_cols_array().to_vec()),
        "params": params_of(p),
        "layers": map.layers().len(),
        "width": map.width(),
        "height": map.height(),
        "layout": layout_of(map.layers().len()),
    })
}

/// Every projection of the core's table, for the page's menu and the tests: its name, what
/// it is, whether the viewport has its shader (else the page is sent its lat-long
/// conversion), its layers and the simulator's layout of them.
pub fn projections() -> Value {
    let rows: Vec<Value> = ProjectionKind::ALL
        .into_iter()
        .map(|k| {
            let p = k.default_projection();
            json!({
                "name": k.name(),
                "about": k.about(),
                "gpu": gpu_kind(&p).is_some(),
                "layers": p.layer_count(),
                "layout": layout_of(p.layer_count()),
            })
        })
        .collect();
    Value::Array(rows)
}

/// The simulator's picture of a map of `layers` layers, from the core's layouts: six as
/// its horizontal cross, two side by side, else one cell; `grid` (columns, rows) and each
/// layer's `[column, row]` (`Layout::grid_cell`).
pub fn layout_of(layers: usize) -> Value {
    let layout = match layers {
        6 => Layout::HorizontalCross,
        1 => Layout::Separate,
        _ => Layout::HorizontalStrip,
    };
    let (c, r) = layout.grid(layers);
    let cells: Vec<[u32; 2]> = (0..layers)
        .map(|i| {
            let (x, y, _) = layout
                .grid_cell(i, layers)
                .expect("the layout holds every layer");
            [x, y]
        })
        .collect();
    json!({ "name": layout.name(), "grid": [c, r], "cells": cells })
}

/// The name the page loads projection `p`'s shader under, where the viewport has one:
/// `web/glsl/projections/NAME.glsl`, NAME the core's name for its kind (`gl.js`
/// `projectionSource`). A projection without one (the dual fisheye: two lenses with their own
/// centres, rolls and distortion) is sent to the page as its lat-long conversion
/// (server.rs `texture`).
pub fn gpu_kind(p: &Projection) -> Option<&'static str> {
    crate::web::projection_shader(p.name()).map(|_| p.name())
}

/// The frame the shader measures a map's directions in, as the columns (right, up, axis):
/// a sphere map's centre looks against its camera's view (core `SphereMap::new`), a
/// paraboloid's front half, an angular map's or a fisheye's centre along its `look`, a
/// view's centre along its forward axis (`View::frame_of`).
pub fn frame_of(p: &Projection) -> Option<Mat3> {
    let cols =
        |r: DVec3, u: DVec3, f: DVec3| Mat3::from_cols(r.as_vec3(), u.as_vec3(), f.as_vec3());
    let radial = |f: &Frame| cols(f.right, f.up, f.forward);
    match p {
        Projection::Sphere(s) => {
            let e = s.eye();
            Some(cols(e.right, e.up, -e.forward))
        }
        Projection::Paraboloid(d) => Some(radial(d.frame())),
        Projection::Angular(a) => Some(radial(a.radial().frame())),
        Projection::Fisheye(f) => Some(radial(f.radial().frame())),
        Projection::View(v) => Some(radial(v.frame())),
        _ => None,
    }
}

/// The shader's `uParams` for a map with parameters beyond its frame (zeros otherwise):
///
/// | projection | `uParams` |
/// | --- | --- |
/// | Mercator | `Y_max`, `tanh Y_max` (= sin φ_max) |
/// | angular, fisheye | lens (0 equidistant, 1 equisolid, 2 stereographic, 3 orthographic), `k = f(θ_max)`, `cos θ_max` |
/// | cylinders | rule (0 central, 1 equal-area, 2 equidistant), `2/H`, `1/g(V/2)` |
/// | views | Pannini's `d`, `1/X_max`, `1/Y_max`, `cos(hfov/2)` |
pub fn params_of(p: &Projection) -> [f32; 4] {
    let lens = |m: &RadialMap| {
        let l = match m.lens() {
            Lens::Equidistant => 0.0,
            Lens::Equisolid => 1.0,
            Lens::Stereographic => 2.0,
            Lens::Orthographic => 3.0,
        };
        [l, m.lens_constant(), m.theta_max().cos(), 0.0]
    };
    let v = match p {
        Projection::Mercator(m) => {
            let y = m.ordinate_limit();
            [y, y.tanh(), 0.0, 0.0]
        }
        Projection::Angular(a) => lens(a.radial()),
        Projection::Fisheye(f) => lens(f.radial()),
        Projection::Cylinder(c) => {
            let rule = match c.rule() {
                CylinderRule::Central => 0.0,
                CylinderRule::EqualArea => 1.0,
                CylinderRule::Equidistant => 2.0,
            };
            [
                rule,
                2.0 / c.hfov_deg().to_radians(),
                1.0 / c.height_scale(),
                0.0,
            ]
        }
        Projection::View(v) => {
            let (x, y) = v.plane_extent();
            [v.distance(), 1.0 / x, 1.0 / y, v.cos_half_hfov()]
        }
        _ => [0.0; 4],
    };
    v.map(|x| x as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::glam::Vec3;

    fn view() -> SceneView {
        SceneView {
            name: "scene.json".into(),
            scene: Scene {
                objects: vec![Object {
                    mesh: Arc::new(Builtin::Sphere.mesh(12)),
                    model: Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0)),
                    material: Material::Mirror {
                        tint: [1.0, 0.5, 0.5],
                    },
                }],
                environment: None,
                background: true,
            },
            camera: Camera::perspective(Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO, 40.0, 64, 48),
            settings: Settings::default(),
            exposure: 0.0,
            tone: Tone::Clamp,
            source: Some(
                json!({"meshes": [{"mesh": "sphere", "tessellation": 12}], "indexing": "pixel"}),
            ),
            builtins: vec![Some((Builtin::Sphere, 12))],
        }
    }

    fn triangles(s: &State) -> Vec<usize> {
        let objects = &s.view.scene.objects;
        objects.iter().map(|o| o.mesh.triangles.len()).collect()
    }

    #[test]
    fn an_object_shown_in_place_of_the_scenes_and_the_scenes_again() {
        let mut s = State::new(view());
        let own = (
            triangles(&s),
            s.view.builtins.clone(),
            s.view.source.clone(),
        );
        s.show_object(ObjectChoice::Builtin(Builtin::Teapot, 2));
        assert_eq!(s.shown_object(), Some("teapot"));
        assert_eq!(triangles(&s), vec![Builtin::Teapot.mesh(2).triangles.len()]);
        assert_eq!(s.view.scene.objects[0].model, Mat4::IDENTITY);
        assert_eq!(s.view.builtins, vec![Some((Builtin::Teapot, 2))]);
        // The scene file names the built-in, and keeps the rest.
        let src = s.view.source.clone().unwrap();
        assert_eq!(
            src["meshes"],
            json!([{"mesh": "teapot", "tessellation": 2, "material": {"kind": "mirror"}}])
        );
        assert_eq!(src["indexing"], "pixel");
        // Another object replaces it; the scene's own come back whole.
        s.show_object(ObjectChoice::Builtin(Builtin::Torus, 8));
        s.show_object(ObjectChoice::Scene);
        assert_eq!(s.shown_object(), None);
        assert_eq!(
            (
                triangles(&s),
                s.view.builtins.clone(),
                s.view.source.clone()
            ),
            own
        );
        assert_eq!(
            s.view.scene.objects[0].model,
            Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0))
        );
        let described = s.describe();
        assert_eq!(described["object"], Value::Null);
        assert_eq!(described["objectChoices"][0], "scene");
    }

    #[test]
    fn a_mesh_has_no_scene_file_and_a_new_environment_leaves_none_to_restore() {
        let mut s = State::new(view());
        // A mesh 10 units across, framed to unit size at the origin as render frames files.
        let mut big = Builtin::Cube
            .mesh(1)
            .transformed(Mat4::from_scale(Vec3::splat(5.0)));
        big.compute_normals();
        s.apply(Opened::Mesh {
            name: "big.obj".into(),
            mesh: Box::new(big),
        });
        assert_eq!(s.shown_object(), Some("big.obj"));
        assert_eq!(s.view.source, None);
        assert_eq!(s.view.builtins, vec![None]);
        let o = &s.view.scene.objects[0];
        let (lo, hi) = o.mesh.transformed(o.model).bounds().unwrap();
        assert!((hi - Vec3::ONE).abs().max_element() < 1e-5, "{hi}");
        assert!((lo + Vec3::ONE).abs().max_element() < 1e-5, "{lo}");
        // The environment replaced meanwhile: the scene's objects come back without a file.
        let img = mirrorball_core::Image::new(8, 4, 3);
        let map = EnvMap::new(
            mirrorball_core::ProjectionKind::LatLong.default_projection(),
            vec![img],
        )
        .unwrap();
        s.apply(Opened::Environment {
            name: "sky.exr".into(),
            map: Box::new(map),
        });
        s.show_object(ObjectChoice::Scene);
        assert_eq!(
            triangles(&s),
            vec![Builtin::Sphere.mesh(12).triangles.len()]
        );
        assert_eq!(s.view.source, None);
        // A scene opened forgets what was shown.
        s.show_object(ObjectChoice::Builtin(Builtin::Quad, 1));
        s.apply(Opened::Scene(Box::new(view())));
        assert_eq!(s.shown_object(), None);
        assert_eq!(
            triangles(&s),
            vec![Builtin::Sphere.mesh(12).triangles.len()]
        );
    }

    /// The page's projection menu and the simulator's layouts come from the core's table:
    /// every kind, each layer in a cell of its own inside the grid.
    #[test]
    fn every_projection_of_the_table_is_listed_with_a_cell_for_each_layer() {
        let listed = projections();
        let rows = listed.as_array().unwrap();
        assert_eq!(rows.len(), ProjectionKind::ALL.len());
        for (row, kind) in rows.iter().zip(ProjectionKind::ALL) {
            assert_eq!(row["name"], kind.name());
            assert_eq!(row["about"], kind.about());
            let layers = kind.default_projection().layer_count();
            assert_eq!(row["layers"], layers);
            let cells = row["layout"]["cells"].as_array().unwrap();
            assert_eq!(cells.len(), layers, "{kind}");
            let grid = &row["layout"]["grid"];
            let mut seen = std::collections::HashSet::new();
            for c in cells {
                let (x, y) = (c[0].as_u64().unwrap(), c[1].as_u64().unwrap());
                assert!(x < grid[0].as_u64().unwrap() && y < grid[1].as_u64().unwrap());
                assert!(seen.insert((x, y)), "{kind}: two layers in one cell");
            }
        }
    }
}
