//! Greene's material, footprint filters (trilinear, EWA) for objects and backgrounds, the
//! per-environment cache, and Phong highlights from a sphere map.
use crate::util::*;
use glam::{DVec3, Mat4, Vec3};
use mirrorball_core::{EnvMap, Image, ProjectionKind};
use mirrorball_render::{
    mesh, render, Attach, Camera, Filter, Indexing, Material, Scene, Settings, SpecularLobe,
};

fn constant(_: DVec3) -> [f32; 3] {
    [0.7, 0.7, 0.7]
}

fn sky(d: DVec3) -> [f32; 3] {
    let v = (1.0 + d.y) as f32;
    [v, v, v]
}

/// A fine black-and-white checker in longitude and latitude (48 × 24 cells).
fn checker(d: DVec3) -> [f32; 3] {
    let lon = d.x.atan2(-d.z);
    let lat = d.y.asin();
    let v = if ((lon * 24.0).sin() * (lat * 24.0).sin()) > 0.0 {
        1.0
    } else {
        0.0
    };
    [v, v, v]
}

/// Root-mean-square difference of the colours over pixels both cover fully.
fn rms(a: &Image, b: &Image) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (p, q) in a.data().chunks_exact(4).zip(b.data().chunks_exact(4)) {
        if p[3] > 0.999 && q[3] > 0.999 {
            s += (0..3).map(|i| ((p[i] - q[i]) as f64).powi(2)).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    assert!(n > 0, "no pixels compared");
    (s / n as f64).sqrt()
}

fn greene_scene(env: EnvMap, dc: [f32; 3], sc: [f32; 3], lobe: SpecularLobe) -> Scene {
    let mut s = scene_with(mesh::sphere(48), Mat4::IDENTITY, env, Attach::World, false);
    s.objects[0].material = Material::Greene { dc, sc, lobe };
    s
}

#[test]
fn greene_on_a_constant_environment_is_dc_plus_sc_times_it_in_every_mode() {
    let (dc, sc) = ([0.3, 0.2, 0.1], [0.5, 0.6, 0.7]);
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 32, 32);
    for lobe in [
        SpecularLobe::Phong { exponent: 20.0 },
        SpecularLobe::Ggx { roughness: 0.4 },
    ] {
        for kind in [
            ProjectionKind::LatLong,
            ProjectionKind::Cube,
            ProjectionKind::Sphere,
        ] {
            let s = greene_scene(env_of(kind, 64, constant), dc, sc, lobe);
            for mode in Indexing::ALL {
                let f = draw(&s, &cam, mode, 1, false);
                let mut n = 0;
                for y in 0..32 {
                    for x in 0..32 {
                        if f.color.get(x, y)[3] < 1.0 {
                            continue;
                        }
                        n += 1;
                        let c = px(&f.color, x, y);
                        for k in 0..3 {
                            let want = (dc[k] + sc[k]) * 0.7;
                            assert!(
                                (c[k] - want).abs() < 0.01 * want,
                                "{lobe:?} {kind:?} {mode:?} ({x},{y}) channel {k}: {} vs {want}",
                                c[k]
                            );
                        }
                    }
                }
                assert!(n > 300, "{n} pixels");
            }
        }
    }
}

#[test]
fn greene_diffuse_term_is_the_lambert_irradiance_of_the_sky() {
    // A quad facing up (+Y), seen from above: D(up) = E/π of the sky 1 + y = 1 + 2/3; a
    // quad facing down sees 1 − 2/3.
    let cam = Camera {
        up: Vec3::NEG_Z,
        ..Camera::orthographic(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, 0.5, 8, 8)
    };
    let up = Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let down = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let cam_down = Camera {
        eye: Vec3::new(0.0, -5.0, 0.0),
        ..cam
    };
    for (model, camera, want) in [(up, cam, 5.0 / 3.0), (down, cam_down, 1.0 / 3.0)] {
        let mut s = scene_with(
            mesh::quad(2),
            model,
            env_of(ProjectionKind::LatLong, 64, sky),
            Attach::World,
            false,
        );
        s.objects[0].material = Material::Greene {
            dc: [1.0; 3],
            sc: [0.0; 3],
            lobe: SpecularLobe::Phong { exponent: 10.0 },
        };
        let f = draw(&s, &camera, Indexing::PerPixel, 1, true);
        let n = f.aovs.as_ref().unwrap().normal.get(4, 4)[1];
        assert!((n.abs() - 1.0).abs() < 1e-4, "normal {n}");
        let d = f.color.get(4, 4)[0];
        assert!(
            (d - want).abs() < 0.02 * want,
            "D at normal {n}: {d}, want {want}"
        );
    }
}

#[test]
fn greene_specular_term_follows_the_reflected_vector() {
    // sc only, a sharp Phong lobe in the sky 1 + y: a mirror-like sphere seen from the front
    // shows ≈ 1 + r_y (slightly pulled towards the mean by the lobe), so its top is brighter
    // than its bottom, and the top pixel agrees with a lobe evaluated by brute force.
    let cam = ortho_front(32);
    let s = greene_scene(
        env_of(ProjectionKind::Cube, 32, sky),
        [0.0; 3],
        [1.0; 3],
        SpecularLobe::Phong { exponent: 200.0 },
    );
    let f = draw(&s, &cam, Indexing::PerPixel, 1, true);
    let r = &f.aovs.as_ref().unwrap().reflected;
    let mut worst = 0.0f32;
    for y in 0..32 {
        for x in 0..32 {
            if f.color.get(x, y)[3] < 1.0 {
                continue;
            }
            // The Phong lobe of exponent s on 1 + y gives 1 + r_y·(s+1)/(s+2) exactly.
            let want = 1.0 + r.get(x, y)[1] * 201.0 / 202.0;
            worst = worst.max((f.color.get(x, y)[0] - want).abs());
        }
    }
    assert!(worst < 0.03, "worst {worst}");
}

#[test]
fn prefiltered_maps_and_pyramids_are_built_once_per_environment() {
    let s = {
        let mut s = greene_scene(
            env_of(ProjectionKind::LatLong, 64, sky),
            [0.5; 3],
            [0.5; 3],
            SpecularLobe::Ggx { roughness: 0.5 },
        );
        s.background = true;
        s
    };
    let cache = s.environment.as_ref().unwrap().cache.clone();
    assert_eq!(cache.builds(), 0);
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 16, 16);
    draw(&s, &cam, Indexing::Cone, 1, false);
    let after_first = cache.builds();
    // Diffuse map, specular map, EWA pyramid.
    assert_eq!(after_first, 3);
    for i in 1..4 {
        let c = cam.orbited(i as f32 * 0.5);
        draw(&s.clone(), &c, Indexing::Cone, 1, false);
    }
    assert_eq!(cache.builds(), after_first, "later frames built again");
    // A new map starts again.
    let mut t = s.clone();
    t.environment.as_mut().unwrap().map =
        std::sync::Arc::new(env_of(ProjectionKind::LatLong, 64, constant));
    draw(&t, &cam, Indexing::Cone, 1, false);
    assert_eq!(cache.builds(), after_first + 3);
}

/// A small far mirror sphere in the fine checker: per-pixel point sampling aliases.
fn aliasing_setup() -> (Scene, Camera) {
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, 14.0, 40, 40);
    let env = env_of(ProjectionKind::LatLong, 1024, checker);
    let s = scene_with(mesh::sphere(128), Mat4::IDENTITY, env, Attach::World, false);
    (s, cam)
}

#[test]
fn cone_mode_with_ewa_aliases_far_less_than_point_sampling() {
    let (s, cam) = aliasing_setup();
    let reference = draw(&s, &cam, Indexing::PerPixel, 16, false);
    let point = draw(&s, &cam, Indexing::PerPixel, 1, false);
    let ewa = draw(&s, &cam, Indexing::Cone, 1, false);
    let mut tri = s.clone();
    tri.environment.as_mut().unwrap().filter = Filter::Trilinear;
    let trilinear = draw(&tri, &cam, Indexing::Cone, 1, false);
    let (e_point, e_ewa, e_tri) = (
        rms(&point.color, &reference.color),
        rms(&ewa.color, &reference.color),
        rms(&trilinear.color, &reference.color),
    );
    eprintln!("rms error: point {e_point:.4}, cone+EWA {e_ewa:.4}, cone+trilinear {e_tri:.4}");
    assert!(e_point > 0.2, "the setup does not alias: {e_point}");
    assert!(e_ewa < 0.35 * e_point, "EWA {e_ewa} vs point {e_point}");
    assert!(
        e_tri < 0.6 * e_point,
        "trilinear {e_tri} vs point {e_point}"
    );
}

#[test]
fn every_mode_with_a_footprint_filter_also_filters() {
    // Modes 1–3 with the EWA filter use the pixel's reflected corner rays as the footprint
    // around their own direction; on a cube map (mode 1: GL_REFLECTION_MAP) and on a
    // lat-long map (mode 1: the map's own u, v per vertex).
    for kind in [ProjectionKind::Cube, ProjectionKind::LatLong] {
        let (mut s, cam) = aliasing_setup();
        let size = if kind == ProjectionKind::Cube {
            256
        } else {
            1024
        };
        s.environment.as_mut().unwrap().map = std::sync::Arc::new(env_of(kind, size, checker));
        let reference = draw(&s, &cam, Indexing::PerPixel, 16, false);
        for mode in [
            Indexing::PerVertexTexgen,
            Indexing::PerVertexReflection,
            Indexing::PerPixel,
        ] {
            s.environment.as_mut().unwrap().filter = Filter::Bilinear;
            let point = draw(&s, &cam, mode, 1, false);
            s.environment.as_mut().unwrap().filter = Filter::Ewa;
            let ewa = draw(&s, &cam, mode, 1, false);
            let (e_point, e_ewa) = (
                rms(&point.color, &reference.color),
                rms(&ewa.color, &reference.color),
            );
            eprintln!("{kind:?} {mode:?}: point {e_point:.4}, EWA {e_ewa:.4}");
            assert!(
                e_ewa < 0.4 * e_point,
                "{kind:?} {mode:?}: EWA {e_ewa} vs point {e_point}"
            );
        }
    }
}

#[test]
fn background_is_filtered_for_the_pixel_footprint_in_every_mode() {
    // No objects, a wide field of view over the fine checker (about 2.5 cells per pixel at
    // the image's edges): one bilinear sample per pixel aliases, footprint filters are close
    // to the supersampled reference.
    let env = env_of(ProjectionKind::LatLong, 1024, checker);
    let mut s = scene_with(mesh::sphere(8), Mat4::IDENTITY, env, Attach::World, true);
    s.objects.clear();
    let cam = Camera::perspective(Vec3::ZERO, Vec3::new(0.3, 0.2, -1.0), 120.0, 48, 48);
    let reference = draw(&s, &cam, Indexing::PerPixel, 16, false);
    let bilinear = draw(&s, &cam, Indexing::PerPixel, 1, false);
    let e_bilinear = rms(&bilinear.color, &reference.color);
    assert!(e_bilinear > 0.15, "the setup does not alias: {e_bilinear}");
    for filter in [Filter::Ewa, Filter::Trilinear] {
        s.environment.as_mut().unwrap().filter = filter;
        for mode in Indexing::ALL {
            let f = draw(&s, &cam, mode, 1, false);
            let e = rms(&f.color, &reference.color);
            eprintln!("background {filter:?} {mode:?}: {e:.4} (bilinear {e_bilinear:.4})");
            // Trilinear is isotropic (the level of the footprint's major axis), so where
            // the wide lens stretches the footprint it blurs what the reference resolves
            // along the minor axis: less gain than EWA (0.063 vs 0.148 here, bilinear 0.198).
            let bound = if filter == Filter::Ewa { 0.4 } else { 0.85 };
            assert!(
                e < bound * e_bilinear,
                "{filter:?} {mode:?}: {e} vs bilinear {e_bilinear}"
            );
        }
    }
    // Mode 4 filters the background even with the bilinear setting (EWA).
    s.environment.as_mut().unwrap().filter = Filter::Bilinear;
    let f = draw(&s, &cam, Indexing::Cone, 1, false);
    assert!(rms(&f.color, &reference.color) < 0.35 * e_bilinear);
}

#[test]
fn footprint_filters_keep_a_smooth_environment_as_it_is() {
    // Filtering must not shift or darken a smooth map: EWA and trilinear agree with
    // bilinear on a mirror sphere in the smooth environment to a few percent.
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 32, 32);
    let mut s = scene_with(
        mesh::sphere(64),
        Mat4::IDENTITY,
        env_of(ProjectionKind::Cube, 64, smooth),
        Attach::World,
        true,
    );
    let base = draw(&s, &cam, Indexing::PerPixel, 1, false);
    for filter in [Filter::Ewa, Filter::Trilinear] {
        s.environment.as_mut().unwrap().filter = filter;
        let f = draw(&s, &cam, Indexing::PerPixel, 1, false);
        let e = rms(&f.color, &base.color);
        assert!(e < 0.03, "{filter:?}: {e}");
    }
}

fn phong_scene(tess: u32) -> Scene {
    let mut s = scene_with(
        mesh::sphere(tess),
        Mat4::IDENTITY,
        env_of(ProjectionKind::LatLong, 8, constant),
        Attach::World,
        false,
    );
    s.environment = None;
    s.objects[0].material = Material::PhongMap {
        colour: [0.2, 0.1, 0.05],
        specular: [1.0, 1.0, 1.0],
        exponent: 50.0,
        light: [0.0, 0.0, 1.0],
        ambient: 0.1,
    };
    s
}

#[test]
fn phong_map_highlight_sits_where_the_mirror_direction_meets_the_light() {
    // Headlight along +Z (eye space) on a sphere seen orthographically from the front: the
    // reflected vector meets the light at the sphere's centre, where the colour is
    // colour × (ambient + 1) + specular; near the limb the highlight is gone.
    let s = phong_scene(96);
    let cam = ortho_front(33);
    let f = render(
        &s,
        &cam,
        &Settings {
            indexing: Indexing::PerPixel,
            ..Settings::default()
        },
    )
    .unwrap();
    let c = px(&f.color, 16, 16);
    let want = [0.2 * 1.1 + 1.0, 0.1 * 1.1 + 1.0, 0.05 * 1.1 + 1.0];
    assert!(max_diff(c, want) < 0.02, "{c:?} vs {want:?}");
    let limb = px(&f.color, 16, 2);
    assert!(limb[0] < 0.2 * 1.1 * 0.6 + 0.01, "{limb:?}");
    // Mode 1 reads the map at GL_SPHERE_MAP coordinates interpolated per vertex: coarse
    // tessellation misplaces the highlight (chords), fine tessellation converges to mode 3.
    // (Perspective: texgen's eye vector is the direction from the eye to the vertex.)
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 48, 48);
    let pixel = draw(&phong_scene(256), &cam, Indexing::PerPixel, 1, false);
    let coarse = draw(&phong_scene(6), &cam, Indexing::PerVertexTexgen, 1, false);
    let fine = draw(&phong_scene(128), &cam, Indexing::PerVertexTexgen, 1, false);
    let e_coarse = rms(&coarse.color, &pixel.color);
    let e_fine = rms(&fine.color, &pixel.color);
    eprintln!("phong map, texgen vs per pixel: coarse {e_coarse:.4}, fine {e_fine:.4}");
    assert!(e_fine < 0.02, "fine texgen vs per pixel: {e_fine}");
    assert!(
        e_coarse > 3.0 * e_fine,
        "coarse {e_coarse} vs fine {e_fine}"
    );
}

/// Rendering into a reused frame gives exactly what a fresh render gives, whatever the frame
/// held before: a frame full of background, reused for a scene without one, is cleared to
/// transparent black where nothing is drawn; a frame of another size is replaced.
#[test]
fn render_into_a_reused_frame_equals_a_fresh_render() {
    use mirrorball_render::render_into;
    let env = env_of(ProjectionKind::Cube, 16, checker);
    let with_bg = scene_with(
        mesh::sphere(24),
        Mat4::IDENTITY,
        env.clone(),
        Attach::World,
        true,
    );
    let without = scene_with(mesh::sphere(24), Mat4::IDENTITY, env, Attach::World, false);
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 40, 30);
    for ss in [1, 2] {
        for indexing in [Indexing::PerPixel, Indexing::Cone] {
            let settings = Settings {
                indexing,
                supersample: ss,
                ..Settings::default()
            };
            let mut frame = render(&with_bg, &cam, &settings).unwrap();
            assert!(frame.color.data().chunks_exact(4).all(|p| p[3] == 1.0));
            render_into(&without, &cam, &settings, &mut frame).unwrap();
            let fresh = render(&without, &cam, &settings).unwrap();
            assert_eq!(
                frame.color.data(),
                fresh.color.data(),
                "ss {ss} {indexing:?}"
            );
            assert!(frame.color.data().chunks_exact(4).any(|p| p == [0.0; 4]));
        }
    }
    let small = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 8, 6);
    let mut frame = render(&with_bg, &cam, &Settings::default()).unwrap();
    render_into(&with_bg, &small, &Settings::default(), &mut frame).unwrap();
    assert_eq!((frame.color.width(), frame.color.height()), (8, 6));
}

#[test]
fn the_vectorised_mirror_gives_the_portable_pictures_to_the_bit() {
    // The per-pixel (and mode 2) mirror's AVX2 rows (where the processor has them) against the portable
    // path, on scenes that reach every branch: two objects (a tinted mirror teapot and a
    // Fresnel torus, which the fast rows hand back), perspective and orthographic cameras,
    // an environment attached to the world or the eye, three and four channels, seams and
    // corners of a small cube; and both against the full shader (diagnostic channels on),
    // which normalises instead, to within rounding.
    use mirrorball_render::{set_portable, Object};
    use std::sync::Arc;
    let mut runs = 0;
    for channels in [3, 4] {
        let mut env = env_of(ProjectionKind::Cube, 8, checker);
        if channels == 4 {
            let layers = env.layers().iter().map(|l| l.with_channels(4)).collect();
            env = EnvMap::new(*env.projection(), layers).unwrap();
        }
        for attach in [Attach::World, Attach::Eye] {
            let mut scene = scene_with(
                mirrorball_render::Builtin::Teapot.mesh(3),
                Mat4::from_translation(Vec3::new(-0.4, -0.3, 0.0)),
                env.clone(),
                attach,
                false,
            );
            scene.objects[0].material = Material::Mirror {
                tint: [0.9, 0.7, 0.5],
            };
            scene.objects.push(Object {
                mesh: Arc::new(mesh::torus(0.6, 0.2, 24)),
                model: Mat4::from_translation(Vec3::new(0.8, 0.4, -0.5)),
                material: Material::Fresnel {
                    f0: 0.04,
                    base: [0.2, 0.3, 0.4],
                },
            });
            for cam in [
                Camera::perspective(Vec3::new(0.3, 0.8, 3.5), Vec3::ZERO, 45.0, 61, 37),
                Camera::orthographic(Vec3::new(0.3, 0.8, 3.5), Vec3::ZERO, 3.0, 61, 37),
            ] {
                for indexing in [Indexing::PerPixel, Indexing::PerVertexReflection] {
                    let settings = Settings {
                        indexing,
                        ..Settings::default()
                    };
                    set_portable(true);
                    let portable = render(&scene, &cam, &settings).unwrap();
                    set_portable(false);
                    let fast = render(&scene, &cam, &settings).unwrap();
                    assert_eq!(
                        portable
                            .color
                            .data()
                            .iter()
                            .map(|v| v.to_bits())
                            .collect::<Vec<_>>(),
                        fast.color
                            .data()
                            .iter()
                            .map(|v| v.to_bits())
                            .collect::<Vec<_>>(),
                        "{channels} channels, {attach:?}"
                    );
                    let full = render(
                        &scene,
                        &cam,
                        &Settings {
                            aovs: true,
                            ..settings
                        },
                    )
                    .unwrap();
                    let worst = fast
                        .color
                        .data()
                        .iter()
                        .zip(full.color.data())
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0f32, f32::max);
                    assert!(worst < 1e-3, "{channels} channels, {attach:?}: {worst}");
                    runs += 1;
                }
            }
        }
    }
    assert_eq!(runs, 16);
}

#[test]
fn leaving_out_hidden_back_faces_changes_no_picture() {
    // Closed solids (a bunny, a sphere, a torus, a mirrored cube) in front of and behind
    // each other, in every indexing mode, through perspective and orthographic cameras,
    // and with the camera so close that the near plane cuts the sphere (no culling there,
    // and the inside shows): the same picture with and without culling, to the bit.
    use mirrorball_render::{load_mesh, Object};
    use std::sync::Arc;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bunny = load_mesh(&root.join("assets/meshes/bunny.obj")).unwrap();
    let fit = bunny.normalizing_transform();
    let env = env_of(ProjectionKind::Cube, 16, checker);
    let mut scene = scene_with(bunny, fit, env, Attach::World, true);
    let extra = [
        (
            mesh::sphere(20),
            Mat4::from_translation(Vec3::new(0.9, 0.2, -0.6)) * Mat4::from_scale(Vec3::splat(0.5)),
        ),
        (
            mesh::torus(0.6, 0.2, 24),
            Mat4::from_translation(Vec3::new(-0.7, 0.5, 0.6)) * Mat4::from_rotation_x(0.7),
        ),
        // Mirrored: a negative determinant turns which winding faces the viewer.
        (
            mesh::cube(2),
            Mat4::from_translation(Vec3::new(0.2, -0.8, 0.5))
                * Mat4::from_scale(Vec3::new(-0.3, 0.3, 0.3)),
        ),
    ];
    for (m, model) in extra {
        scene.objects.push(Object {
            mesh: Arc::new(m),
            model,
            material: Material::Fresnel {
                f0: 0.04,
                base: [0.2, 0.3, 0.4],
            },
        });
    }
    let mut runs = 0;
    for cam in [
        Camera::perspective(Vec3::new(0.3, 0.8, 3.5), Vec3::ZERO, 45.0, 61, 37),
        Camera::perspective(Vec3::new(-2.0, -1.0, -2.5), Vec3::ZERO, 60.0, 53, 41),
        Camera::orthographic(Vec3::new(0.3, 0.8, 3.5), Vec3::ZERO, 1.5, 61, 37),
        // Inside the near plane's reach of the sphere.
        Camera::perspective(
            Vec3::new(0.9, 0.2, -0.12),
            Vec3::new(0.9, 0.2, -0.6),
            70.0,
            40,
            30,
        ),
    ] {
        for indexing in [
            Indexing::PerVertexTexgen,
            Indexing::PerVertexReflection,
            Indexing::PerPixel,
            Indexing::Cone,
        ] {
            let with = |cull: bool| {
                render(
                    &scene,
                    &cam,
                    &Settings {
                        indexing,
                        aovs: true,
                        cull_hidden_faces: cull,
                        ..Settings::default()
                    },
                )
                .unwrap()
            };
            let (culled, all) = (with(true), with(false));
            let bits = |i: &Image| i.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&culled.color),
                bits(&all.color),
                "{indexing:?}, camera at {}",
                cam.eye
            );
            runs += 1;
        }
    }
    assert_eq!(runs, 16);
}
