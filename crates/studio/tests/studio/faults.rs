//! Answers by cause: the page's request is a 400, the file it sent a 422, the machine's
//! failure a 500, a full disk a 507 (never a 422, as if the file were bad).

use crate::host::{latlong_exr, own, start, FULL_DISK};
use mirrorball_core::Fault;
use mirrorball_studio::Error;
use std::io::ErrorKind;

#[test]
fn each_fault_has_its_status() {
    assert_eq!(Error::request("a setting").status(), 400);
    assert_eq!(Error::input("a file").status(), 422);
    assert_eq!(Error::system("a thread").status(), 500);
    let full = std::io::Error::from(ErrorKind::StorageFull);
    let e = Error::io("writing", &full);
    assert_eq!((e.fault, e.status().as_u16()), (Fault::System, 507));
    let denied = std::io::Error::from(ErrorKind::PermissionDenied);
    assert_eq!(Error::io("writing", &denied).status(), 500);
    // A file that is not there, or ends early, is the input's.
    let eof = std::io::Error::from(ErrorKind::UnexpectedEof);
    assert_eq!(Error::io("reading", &eof).status(), 422);
    // Context keeps the fault and the kind.
    assert_eq!(Error::io("writing", &full).context("x.exr").status(), 507);
}

#[test]
fn uploads_are_answered_by_the_faults_cause() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(latlong_exr(dir.path())).unwrap();
    let r = start(&[]);
    // The disk is full: the system's fault, not the file's.
    let a = own(&r, "POST", &format!("/api/upload?name={FULL_DISK}"), &good);
    assert_eq!(a.status, 507, "{}", a.text());
    // A file cut short: the input's.
    let a = own(&r, "POST", "/api/upload?name=cut.exr", &good[..100]);
    assert_eq!(a.status, 422, "{}", a.text());
    // A name of no container: the request's.
    let a = own(&r, "POST", "/api/upload?name=notes.txt", b"hello");
    assert_eq!(a.status, 400, "{}", a.text());
    // The same bytes under any name of the container are read from memory.
    let a = own(&r, "POST", "/api/upload?name=upload.exr", &good);
    assert_eq!(a.status, 200, "{}", a.text());
    r.stop();
}

#[test]
fn an_export_the_container_cannot_hold_is_the_requests_fault() {
    let dir = tempfile::tempdir().unwrap();
    let r = start(&[latlong_exr(dir.path())]);
    // A lat-long is no cube: KTX2 cannot hold it.
    let a = own(&r, "GET", "/api/export?what=map&format=ktx2", b"");
    assert_eq!(a.status, 400, "{}", a.text());
    r.stop();
}
