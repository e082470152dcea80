//! What the server gives the page, and how it takes bad files.

use crate::host::{latlong_exr, own, start};
use mirrorball_studio::Running;

fn json(a: &crate::host::Answer) -> serde_json::Value {
    serde_json::from_slice(&a.body).unwrap_or_else(|_| panic!("not JSON: {}", a.text()))
}

#[test]
fn a_truncated_exr_upload_is_refused_with_the_readers_message_and_serving_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(latlong_exr(dir.path())).unwrap();
    let r = start(&[]);
    let a = own(
        &r,
        "POST",
        "/api/upload?name=cut.exr",
        &good[..good.len() / 2],
    );
    assert_eq!(a.status, 422, "{}", a.text());
    let message = json(&a)["error"].as_str().unwrap().to_string();
    // The reader's own message, under the upload's name.
    assert!(message.starts_with("cut.exr"), "{message}");
    let s = json(&own(&r, "GET", "/api/state", b""));
    assert_eq!(s["errors"][0], message.as_str());
    assert!(s["scene"]["environment"].is_null());
    // Still serving: the whole file is taken.
    let a = own(&r, "POST", "/api/upload?name=map.exr", &good);
    assert_eq!(a.status, 200, "{}", a.text());
    let s = json(&a);
    assert_eq!(s["scene"]["environment"]["projection"], "latlong");
    assert_eq!(s["scene"]["environment"]["width"], 16);
    // What went wrong before the map loaded is no longer said.
    let s = json(&own(&r, "GET", "/api/state", b""));
    assert_eq!(s["errors"].as_array().map(Vec::len), Some(0), "{s}");
    r.stop();
}

#[test]
fn an_upload_over_the_limit_is_refused_and_serving_goes_on() {
    let r = start(&[]);
    let a = own(
        &r,
        "POST",
        "/api/upload?name=big.exr",
        &vec![0u8; (1 << 20) + 1],
    );
    assert_eq!(a.status, 413, "{}", a.text());
    let message = json(&a)["error"].as_str().unwrap().to_string();
    assert_eq!(
        message,
        "big.exr: larger than the upload limit of 1 MiB (mirrorball studio --max-upload)"
    );
    let s = own(&r, "GET", "/api/state", b"");
    assert_eq!(s.status, 200);
    assert_eq!(json(&s)["errors"][0], message.as_str());
    r.stop();
}

#[test]
fn a_bad_file_on_the_command_line_is_an_error_before_serving() {
    let dir = tempfile::tempdir().unwrap();
    let cut = dir.path().join("cut.exr");
    let good = std::fs::read(latlong_exr(dir.path())).unwrap();
    std::fs::write(&cut, &good[..100]).unwrap();
    let e = mirrorball_studio::Studio::default()
        .start(
            std::sync::Arc::new(crate::host::TestHost),
            std::slice::from_ref(&cut),
        )
        .err()
        .expect("refused");
    assert!(e.message.starts_with(&cut.display().to_string()), "{e}");
}

/// `GET query` of the environment, answered 200: the payload's JSON header, its length, and
/// the body.
fn environment(r: &Running, query: &str) -> (serde_json::Value, usize, Vec<u8>) {
    let a = own(r, "GET", &format!("/api/environment?{query}"), b"");
    assert_eq!(a.status, 200, "{query}: {}", a.text());
    assert_eq!(&a.body[..4], b"MBTX");
    let n = u32::from_le_bytes(a.body[4..8].try_into().unwrap()) as usize;
    let h = serde_json::from_slice(&a.body[8..8 + n]).unwrap();
    (h, n, a.body)
}

#[test]
fn the_environment_comes_padded_in_its_own_and_other_projections() {
    let dir = tempfile::tempdir().unwrap();
    let r = start(&[latlong_exr(dir.path())]);
    let (h, n, body) = environment(&r, "projection=native&precision=float");
    assert_eq!(
        (h["texelWidth"].as_u64(), h["texelHeight"].as_u64()),
        (Some(18), Some(10))
    );
    assert_eq!(body.len(), 8 + n + 18 * 10 * 16);
    // Texel (0, 0) of the map is at (1, 1) of the padded layer; (−1, 0) wraps to (15, 0).
    let f = |x: usize, y: usize, c: usize| {
        let i = 8 + n + ((y * 18 + x) * 4 + c) * 4;
        f32::from_le_bytes(body[i..i + 4].try_into().unwrap())
    };
    assert_eq!((f(1, 1, 0), f(1, 1, 1)), (0.0, 0.0));
    assert_eq!((f(0, 1, 0), f(0, 1, 1)), (15.0 / 16.0, 0.0));
    let (h, n, body) = environment(&r, "projection=cube&size=8&precision=half");
    assert_eq!(
        (h["projection"].as_str(), h["layers"].as_u64()),
        (Some("cube"), Some(6))
    );
    assert_eq!(body.len(), 8 + n + 6 * 10 * 10 * 8);
    // With the mip chain: 8², 4², 2², 1² faces, each padded, in one atlas a face.
    let (h, n, body) = environment(&r, "projection=cube&size=8&precision=half&mips=1");
    assert_eq!(
        h["levels"],
        serde_json::json!([[0, 0, 8, 8], [10, 0, 4, 4], [10, 6, 2, 2], [10, 10, 1, 1]])
    );
    let (w, ht) = (
        h["texelWidth"].as_u64().unwrap(),
        h["texelHeight"].as_u64().unwrap(),
    );
    assert_eq!((w, ht), (16, 13));
    assert_eq!(body.len(), 8 + n + 6 * (w * ht) as usize * 8);
    // A projection without a shader (the dual fisheye) comes as the lat-long conversion of
    // that map, its header saying so, so that the page draws it.
    let (h, _, _) = environment(&r, "projection=dual-fisheye&size=16");
    assert_eq!(h["projection"], "latlong");
    assert_eq!(h["layout"]["cells"], serde_json::json!([[0, 0]]));
    for bad in [
        "projection=cube&size=0",
        "projection=nonsense",
        "precision=double",
        "mips=2",
    ] {
        let a = own(&r, "GET", &format!("/api/environment?{bad}"), b"");
        assert!(
            a.status == 400 || a.status == 422,
            "{bad}: {} {}",
            a.status,
            a.text()
        );
        assert!(json(&a)["error"].is_string());
    }
    r.stop();
}

#[test]
fn meshes_come_in_world_space() {
    let r = start(&[]);
    let a = own(&r, "GET", "/api/mesh/0", b"");
    assert_eq!(a.status, 200);
    let u = |i: usize| u32::from_le_bytes(a.body[4 * i..4 * i + 4].try_into().unwrap());
    let f = |i: usize| f32::from_le_bytes(a.body[4 * i..4 * i + 4].try_into().unwrap());
    let (n, t) = (u(0) as usize, u(1) as usize);
    assert_eq!(a.body.len(), 8 + 24 * n + 12 * t);
    // The sphere of radius 1 moved up by 0.5: every vertex at distance 1 from (0, 0.5, 0),
    // its normal pointing away from there.
    for i in 0..n {
        let p = [f(2 + 3 * i), f(3 + 3 * i) - 0.5, f(4 + 3 * i)];
        let q = [
            f(2 + 3 * n + 3 * i),
            f(3 + 3 * n + 3 * i),
            f(4 + 3 * n + 3 * i),
        ];
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!((r - 1.0).abs() < 1e-5, "vertex {i} at radius {r}");
        assert!(
            p.iter().zip(q).all(|(a, b)| (a / r - b).abs() < 1e-3),
            "normal {i}"
        );
    }
    assert_eq!(own(&r, "GET", "/api/mesh/1", b"").status, 404);
    // The built-in sphere tessellated otherwise: the render crate's mesh at that level.
    let a = own(&r, "GET", "/api/mesh/0?tessellation=32", b"");
    assert_eq!(a.status, 200, "{}", a.text());
    let want = mirrorball_render::Builtin::Sphere.mesh(32);
    let counts = [0, 4].map(|o| u32::from_le_bytes(a.body[o..o + 4].try_into().unwrap()));
    assert_eq!(
        counts,
        [want.positions.len() as u32, want.triangles.len() as u32]
    );
    for bad in ["tessellation=0", "tessellation=100000", "tessellation=x"] {
        let a = own(&r, "GET", &format!("/api/mesh/0?{bad}"), b"");
        assert_eq!(a.status, 400, "{bad}: {}", a.text());
    }
    r.stop();
}

#[test]
fn the_grid_holds_the_cores_answers() {
    let r = start(&[]);
    let a = own(&r, "GET", "/api/grid?projection=cube&n=8", b"");
    assert_eq!(a.status, 200);
    let count = u32::from_le_bytes(a.body[..4].try_into().unwrap()) as usize;
    assert_eq!(count, 6 * 81);
    // Count, the frame (9 floats), the parameters (4), then nine floats a direction.
    assert_eq!(a.body.len(), 56 + 36 * count);
    assert_eq!(
        own(&r, "GET", "/api/grid?projection=cube&n=100000", b"").status,
        400
    );
    r.stop();
}

#[test]
fn exports_are_the_hosts_files_and_bad_requests_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let r = start(&[latlong_exr(dir.path())]);
    // The map as loaded: an EXR the io crate reads back with the loaded texels.
    let a = own(&r, "GET", "/api/export?what=map&format=exr", b"");
    assert_eq!(a.status, 200, "{}", a.text());
    assert_eq!(
        a.header("content-disposition"),
        Some("attachment; filename=\"environment-native.exr\"")
    );
    let file = dir.path().join("back.exr");
    std::fs::write(&file, &a.body).unwrap();
    let back = mirrorball_io::read(&file, &mirrorball_io::Limits::default()).unwrap();
    assert_eq!((back.layers[0].width(), back.layers[0].height()), (16, 8));
    // Converted as the page asks: a cube into KTX2.
    let a = own(
        &r,
        "GET",
        "/api/export?what=map&format=ktx2&projection=cube&size=8",
        b"",
    );
    assert_eq!(a.status, 200, "{}", a.text());
    assert_eq!(&a.body[1..7], b"KTX 20");
    for (target, status, says) in [
        (
            "/api/export?what=map&format=bmp",
            400,
            "'bmp' is not one of",
        ),
        (
            "/api/export?what=scene&format=exr",
            400,
            "'scene' is not map or chain",
        ),
        ("/api/export?what=chain&format=exr", 400, "ktx2 or dds"),
        (
            "/api/export?what=chain&format=ktx2",
            404,
            "no prefiltered chain",
        ),
        (
            "/api/export?what=map&format=exr&projection=nonsense",
            400,
            "projection",
        ),
    ] {
        let a = own(&r, "GET", target, b"");
        assert_eq!(a.status, status, "{target}: {}", a.text());
        let m = json(&a)["error"].as_str().unwrap().to_string();
        assert!(m.contains(says), "{target}: {m}");
    }
    // Once the page is lit, its chain: every level in one KTX2.
    let a = own(&r, "GET", "/api/lighting?size=8", b"");
    assert_eq!(a.status, 200, "{}", a.text());
    let a = own(&r, "GET", "/api/export?what=chain&format=ktx2", b"");
    assert_eq!(a.status, 200, "{}", a.text());
    let levels = u32::from_le_bytes(a.body[40..44].try_into().unwrap());
    assert_eq!(levels, 4);
    r.stop();
}

#[test]
fn files_held_for_a_scene_are_listed_bounded_together_and_let_go_by_the_next_upload() {
    let r = start(&[]);
    let half = vec![0u8; 600 << 10];
    let a = own(&r, "POST", "/api/upload?name=a.exr&alongside=1", &half);
    assert_eq!(a.status, 200, "{}", a.text());
    assert_eq!(json(&a)["held"], serde_json::json!(["a.exr"]));
    // Held, not read: nothing is loaded yet.
    let s = json(&own(&r, "GET", "/api/state", b""));
    assert!(s["scene"]["environment"].is_null());
    assert_eq!(s["errors"].as_array().map(Vec::len), Some(0));
    // Each alone is under the 1 MiB limit, the two together over it.
    let b = own(&r, "POST", "/api/upload?name=b.obj&alongside=1", &half);
    assert_eq!(b.status, 413, "{}", b.text());
    assert_eq!(
        json(&b)["error"],
        "b.obj: the files picked together are larger than the upload limit of 1 MiB (mirrorball studio --max-upload)"
    );
    // Refused, the held files are let go: the next one is held alone.
    let c = own(&r, "POST", "/api/upload?name=c.exr&alongside=1", b"x");
    assert_eq!(json(&c)["held"], serde_json::json!(["c.exr"]));
    // An ordinary upload takes them (here a bad one); the next is held alone again.
    let d = own(&r, "POST", "/api/upload?name=d.exr", b"not an exr");
    assert_eq!(d.status, 422, "{}", d.text());
    let e = own(&r, "POST", "/api/upload?name=e.exr&alongside=1", b"x");
    assert_eq!(json(&e)["held"], serde_json::json!(["e.exr"]));
    r.stop();
}
