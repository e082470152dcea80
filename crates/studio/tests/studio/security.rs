//! Only the studio's own page, with the printed token, may drive it.

use crate::host::{own, request, start};

#[test]
fn the_url_is_on_loopback_with_a_token() {
    let r = start(&[]);
    assert_eq!(
        r.url,
        format!("http://127.0.0.1:{}/?token={}", r.port, r.token)
    );
    assert_eq!(r.token.len(), 32);
    // The page, by the printed URL (the token in the query).
    let host = format!("127.0.0.1:{}", r.port);
    let page = request(
        r.port,
        "GET",
        &format!("/?token={}", r.token),
        &[("Host", &host)],
        b"",
    );
    assert_eq!(page.status, 200);
    assert!(page.text().contains("mirrorball studio"));
    assert_eq!(page.header("cache-control"), Some("no-store"));
    r.stop();
}

#[test]
fn a_good_request_is_served() {
    let r = start(&[]);
    let a = own(&r, "GET", "/api/state", b"");
    assert_eq!(a.status, 200, "{}", a.text());
    let v: serde_json::Value = serde_json::from_slice(&a.body).unwrap();
    assert_eq!(v["scene"]["name"], "a mirror sphere");
    // The same with the server's own origin, and by the name localhost.
    let host = format!("localhost:{}", r.port);
    let origin = format!("http://localhost:{}", r.port);
    let a = request(
        r.port,
        "GET",
        "/api/state",
        &[
            ("Host", &host),
            ("Origin", &origin),
            ("X-Mirrorball-Token", &r.token),
        ],
        b"",
    );
    assert_eq!(a.status, 200, "{}", a.text());
    r.stop();
}

#[test]
fn a_request_without_the_token_is_refused() {
    let r = start(&[]);
    let host = format!("127.0.0.1:{}", r.port);
    for target in [
        "/",
        "/api/state",
        "/web/studio.js",
        "/web/glsl/cube.glsl",
        "/api/export?what=map&format=exr",
    ] {
        let a = request(r.port, "GET", target, &[("Host", &host)], b"");
        assert_eq!(a.status, 401, "{target}: {}", a.text());
        assert!(!a.text().contains("envUv"), "{target} gave the shader away");
    }
    let wrong = format!("/api/state?token={}", "0".repeat(32));
    assert_eq!(
        request(r.port, "GET", &wrong, &[("Host", &host)], b"").status,
        401
    );
    let a = request(
        r.port,
        "POST",
        "/api/upload?name=x.exr",
        &[("Host", &host)],
        b"abc",
    );
    assert_eq!(a.status, 401);
    r.stop();
}

#[test]
fn a_wrong_host_is_refused() {
    // DNS rebinding: a page at evil.example whose name now resolves to 127.0.0.1 sends
    // its own host name, even if it had learnt the token.
    let r = start(&[]);
    for host in [
        "evil.example",
        &format!("evil.example:{}", r.port),
        &format!("127.0.0.1:{}", r.port + 1),
    ] {
        let a = request(
            r.port,
            "GET",
            "/api/state",
            &[("Host", host), ("X-Mirrorball-Token", &r.token)],
            b"",
        );
        assert_eq!(a.status, 403, "Host {host}: {}", a.text());
    }
    r.stop();
}

#[test]
fn a_forged_origin_is_refused() {
    let r = start(&[]);
    let host = format!("127.0.0.1:{}", r.port);
    for origin in [
        "http://evil.example",
        "null",
        &format!("http://127.0.0.1:{}", r.port + 1),
        &format!("https://127.0.0.1:{}", r.port),
    ] {
        let a = request(
            r.port,
            "POST",
            "/api/upload?name=x.exr",
            &[
                ("Host", &host),
                ("Origin", origin),
                ("X-Mirrorball-Token", &r.token),
            ],
            b"abc",
        );
        assert_eq!(a.status, 403, "Origin {origin}: {}", a.text());
    }
    let a = request(
        r.port,
        "GET",
        "/api/state",
        &[
            ("Host", &host),
            ("Sec-Fetch-Site", "cross-site"),
            ("X-Mirrorball-Token", &r.token),
        ],
        b"",
    );
    assert_eq!(a.status, 403);
    r.stop();
}
