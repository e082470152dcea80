//! Zimmons' one-dimensional measure against closed forms, and the claims table.
use crate::util::{close, proj};
use mirrorball_analysis::claims::{claims, Verdict};
use mirrorball_analysis::profile::profile;
use mirrorball_core::ProjectionKind as K;

#[test]
fn cube_sphere_and_paraboloid_pixel_angles() {
    let n = 512;
    let t = |k: usize| 2.0 * k as f64 / n as f64;
    type Theta = fn(f64) -> f64;
    let cases: [(K, Theta); 3] = [
        (K::Cube, |t: f64| t.atan()),
        (K::Sphere, |t: f64| 2.0 * t.asin()),
        (K::Paraboloid, |t: f64| 2.0 * t.atan()),
    ];
    for (k, theta) in cases {
        let p = profile(&proj(k), n);
        let h = &p.walks[0];
        assert_eq!(h.degrees.len(), n as usize / 2, "{}", k.name());
        for (i, d) in h.degrees.iter().enumerate() {
            let want = (theta(t(i + 1)) - theta(t(i))).to_degrees();
            close(*d, want, 1e-9, k.name());
        }
    }
    // The cube's diagonal: atan(√2 t).
    let p = profile(&proj(K::Cube), n);
    let d = &p.walks[2];
    for (i, a) in d.degrees.iter().enumerate() {
        let want = ((2f64.sqrt() * t(i + 1)).atan() - (2f64.sqrt() * t(i)).atan()).to_degrees();
        close(*a, want, 1e-9, "cube diagonal");
    }
    close(
        d.ratio,
        0.316_514_235_175_884_7 / 0.105_781_170_222_639_12,
        1e-9,
        "cube diagonal ratio",
    );
}

#[test]
fn zimmons_sphere_map_numbers() {
    let p = profile(&proj(K::Sphere), 512);
    let h = &p.walks[0];
    assert!((h.degrees[254] - 4.2014).abs() < 5e-5);
    assert!((h.degrees[255] - 10.13186).abs() < 5e-6);
    // The last pixel: 2 acos(1 − 2/n).
    close(
        h.degrees[255],
        (2.0 * (1.0 - 2.0 / 512.0f64).acos()).to_degrees(),
        1e-9,
        "rim pixel",
    );
    // Diagonal: cut by the rim after ⌊256/√2⌋ = 181 whole pixels.
    let d = &p.walks[2];
    assert_eq!(d.degrees.len(), 182);
    assert!(d.last_fraction > 0.0 && d.last_fraction < 1.0);
}

#[test]
fn claims_table_verdicts() {
    let c = claims();
    let verdict = |needle: &str| {
        c.iter()
            .find(|c| c.claim.contains(needle))
            .unwrap_or_else(|| panic!("no claim '{needle}'"))
            .verdict
    };
    assert_eq!(verdict("crossover radius"), Verdict::Confirmed);
    assert_eq!(verdict("wasted"), Verdict::Confirmed);
    assert_eq!(verdict("pixel 254 → 255"), Verdict::Confirmed);
    assert_eq!(verdict("outermost pixel 255 → 256"), Verdict::Confirmed);
    assert_eq!(
        verdict("cube 512²: angle of the outermost pixel along an axis"),
        Verdict::Contradicted
    );
    assert_eq!(
        verdict("centre / corner pixel angle along the diagonal"),
        Verdict::Contradicted
    );
    assert_eq!(verdict("cube 209²"), Verdict::Contradicted);
    assert_eq!(verdict("3√3"), Verdict::Confirmed);
    assert_eq!(
        verdict("paraboloid: two-dimensional distortion 4"),
        Verdict::Confirmed
    );
    assert_eq!(
        verdict("paraboloid 512²: centre / outermost"),
        Verdict::Confirmed
    );
    assert_eq!(verdict("viewer at (−8.3, 1, 0)"), Verdict::Contradicted);
    assert_eq!(verdict("6% of the world"), Verdict::Confirmed);
    assert_eq!(verdict("reflection cone"), Verdict::Confirmed);
    // Every claim has a source, values and a reason.
    for x in &c {
        assert!(
            !x.source.is_empty()
                && !x.document.is_empty()
                && !x.measured.is_empty()
                && !x.why.is_empty(),
            "{x:?}"
        );
    }
}
