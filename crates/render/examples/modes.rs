//! Renders the side-by-side comparison of the indexing modes used in the README:
//! `cargo run --release -p mirrorball-render --example modes -- OUT.png [ENV.exr]`.
//!
//! Top row: a coarse sphere (12 segments) in a sphere map, modes 1–4. Bottom row: a quad
//! (one cell, two triangles) at a grazing angle, modes 1–4. The sphere map is made from
//! the lat-long environment as seen by the camera that renders it, attached to the eye (as
//! `GL_SPHERE_MAP` is); the objects are drawn over grey.

use glam::{Mat4, Vec3};
use mirrorball_core::{resample, Frame, Image, Projection, ResampleOptions, SphereMap};
use mirrorball_render::{
    mesh, render, tone, Attach, Camera, Environment, Indexing, Material, Object, Scene, Settings,
};
use std::path::PathBuf;
use std::sync::Arc;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(args.first().map_or("render-modes.png", |s| s.as_str()));
    let env_path = args.get(1).cloned().unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/env/venice.exr").to_string()
    });
    let loaded = mirrorball_io::read(std::path::Path::new(&env_path), &Default::default())
        .expect("read the environment");
    let ll = mirrorball_core::EnvMap::new(
        mirrorball_core::ProjectionKind::LatLong.default_projection(),
        loaded.layers,
    )
    .expect("a lat-long map");
    let sm = resample(
        &ll,
        Projection::Sphere(SphereMap::new(Frame::default())),
        256,
        &ResampleOptions::default(),
    );
    let size = 192;
    let mut tiles = Vec::new();
    let rows: [(Arc<mirrorball_render::Mesh>, Mat4, Camera); 2] = [
        (
            Arc::new(mesh::sphere(12)),
            Mat4::IDENTITY,
            Camera::perspective(Vec3::new(0.0, 0.0, 3.2), Vec3::ZERO, 45.0, size, size),
        ),
        (
            Arc::new(mesh::quad(1)),
            Mat4::from_rotation_y(68f32.to_radians()),
            Camera::perspective(Vec3::new(0.0, 0.0, 1.9), Vec3::ZERO, 62.0, size, size),
        ),
    ];
    for (m, model, cam) in rows.iter() {
        for mode in Indexing::ALL {
            let scene = Scene {
                objects: vec![Object {
                    mesh: m.clone(),
                    model: *model,
                    material: Material::mirror(),
                }],
                environment: Some(Environment {
                    attach: Attach::Eye,
                    ..Environment::new(sm.clone())
                }),
                background: false,
            };
            let f = render(
                &scene,
                cam,
                &Settings {
                    indexing: mode,
                    supersample: 3,
                    aovs: false,
                    motion_from: None,
                    cull_hidden_faces: true,
                },
            )
            .expect("render");
            // Over a neutral grey (colour is premultiplied by coverage).
            let mut c = f.color.clone();
            for px in c.data_mut().chunks_exact_mut(4) {
                for k in 0..3 {
                    px[k] += 0.18 * (1.0 - px[3]);
                }
            }
            tiles.push(tone::to_display(&c, 0.0, tone::Tone::Aces).with_channels(3));
        }
    }
    let gap = 4;
    let mut sheet = Image::new(4 * size + 3 * gap, 2 * size + gap, 3);
    for (i, t) in tiles.iter().enumerate() {
        let (cx, cy) = ((i % 4) as u32, (i / 4) as u32);
        sheet.paste(t, cx * (size + gap), cy * (size + gap));
    }
    mirrorball_io::write_image(&out, &sheet, &Default::default()).expect("write");
    println!("wrote {}", out.display());
}
