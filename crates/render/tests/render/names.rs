//! Named choices read by their one table, and errors that say whose fault they are.

use glam::{Mat4, Vec3};
use mirrorball_core::{Choice, EnvMap, Fault, ProjectionKind};
use mirrorball_render::tone::Tone;
use mirrorball_render::{
    environment_filter, mesh, render, Attach, Builtin, Camera, Environment, Filter, Indexing,
    Material, MaterialKind, Object, Scene, Settings, ENVIRONMENT_FILTERS,
};
use std::sync::Arc;

fn round_trips<T: Choice + std::fmt::Debug + std::fmt::Display + std::str::FromStr>()
where
    T::Err: std::fmt::Debug,
{
    for (v, names) in T::NAMES {
        assert_eq!(v.to_string(), names[0]);
        for n in *names {
            assert_eq!(n.parse::<T>().unwrap(), *v, "{n}");
            assert_eq!(n.to_ascii_uppercase().parse::<T>().unwrap(), *v, "{n}");
        }
    }
}

#[test]
fn every_name_and_alias_parses_back_to_its_value() {
    round_trips::<Indexing>();
    round_trips::<Attach>();
    round_trips::<Tone>();
    round_trips::<Builtin>();
    round_trips::<Filter>();
    round_trips::<MaterialKind>();
    assert_eq!(Indexing::all().collect::<Vec<_>>(), Indexing::ALL);
    assert_eq!(Builtin::all().collect::<Vec<_>>(), Builtin::ALL);
    for (i, m) in Indexing::ALL.iter().enumerate() {
        assert_eq!(m.number(), i + 1);
        assert_eq!((i + 1).to_string().parse::<Indexing>().unwrap(), *m);
    }
    // The environment offers the four filters it always has; the error lists them.
    for f in ENVIRONMENT_FILTERS {
        assert_eq!(environment_filter(f.name()).unwrap(), f);
    }
    let e = environment_filter("sat").unwrap_err();
    assert_eq!(
        e.to_string(),
        "'sat' is not nearest, bilinear, trilinear or ewa"
    );
}

#[test]
fn render_errors_say_whose_fault_they_are() {
    let env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 16, 3, |_| {
        [1.0; 4]
    });
    let scene = |model: Mat4| Scene {
        objects: vec![Object {
            mesh: Arc::new(mesh::sphere(8)),
            model,
            material: Material::mirror(),
        }],
        environment: Some(Environment::new(env.clone())),
        background: true,
    };
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0, 8, 8);
    let settings = Settings::default();
    // What is asked: the settings, the camera.
    let e = render(
        &scene(Mat4::IDENTITY),
        &cam,
        &Settings {
            supersample: 0,
            ..settings
        },
    )
    .unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
    assert!(e.to_string().contains("supersampling 0"), "{e}");
    let mut looking_nowhere = cam;
    looking_nowhere.target = looking_nowhere.eye;
    let e = render(&scene(Mat4::IDENTITY), &looking_nowhere, &settings).unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
    // What is given: the scene's matrices.
    let e = render(&scene(Mat4::ZERO), &cam, &settings).unwrap_err();
    assert_eq!(e.fault(), Fault::Input, "{e}");
    assert!(e.message().contains("object 0"), "{e}");
}
