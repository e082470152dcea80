//! The split-sum BRDF table against an independent quadrature of the BRDF.
use mirrorball_filter::brdf_lut::integrate;
use mirrorball_filter::{BrdfLut, Visibility};
use std::f64::consts::PI;

/// `(A, B)` by a plain midpoint rule over the hemisphere of `l`: `∫ f (n·l) dl` with
/// `f = D G F / (4 (n·l)(n·v))`, `F = F₀ + (1 − F₀)(1 − v·h)⁵`.
fn quadrature(nv: f64, r: f64, vis: Visibility) -> [f64; 2] {
    let a = r * r;
    let a2 = a * a;
    let v = [(1.0 - nv * nv).sqrt(), 0.0, nv];
    let (nt, np) = (1200, 600);
    let (mut sa, mut sb) = (0.0, 0.0);
    for i in 0..nt {
        let th = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
            let l = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let hv = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
            let hn = (hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2]).sqrt();
            let h = [hv[0] / hn, hv[1] / hn, hv[2] / hn];
            let nh = h[2];
            let vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
            let nl = l[2];
            let q = nh * nh * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * q * q);
            let g = match vis {
                Visibility::SchlickUe4 => {
                    let k = a / 2.0;
                    (nv / (nv * (1.0 - k) + k)) * (nl / (nl * (1.0 - k) + k))
                }
                Visibility::HeightCorrelated => {
                    let vv = 0.5
                        / (nl * (nv * nv * (1.0 - a2) + a2).sqrt()
                            + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
                    4.0 * nl * nv * vv
                }
            };
            let f = d * g / (4.0 * nl * nv) * nl;
            let fc = (1.0 - vh).powi(5);
            let dw = th.sin() * (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64);
            sa += (1.0 - fc) * f * dw;
            sb += fc * f * dw;
        }
    }
    [sa, sb]
}

#[test]
fn table_matches_quadrature() {
    for vis in [Visibility::SchlickUe4, Visibility::HeightCorrelated] {
        for (nv, r) in [(0.9, 0.5), (0.5, 0.5), (0.3, 0.8), (0.7, 1.0), (0.2, 0.4)] {
            let is = integrate(nv, r, 4096, vis);
            let q = quadrature(nv, r, vis);
            for k in 0..2 {
                let e = (is[k] - q[k]).abs();
                assert!(
                    e < 0.01 * (q[0] + q[1]),
                    "{vis:?} nv={nv} r={r}: {is:?} vs {q:?}"
                );
            }
        }
    }
}

#[test]
fn table_properties() {
    let lut = BrdfLut::new(32, 512, Visibility::SchlickUe4);
    assert_eq!(lut.data.len(), 32 * 32);
    for v in &lut.data {
        assert!(
            v[0] >= 0.0 && v[1] >= 0.0 && v[0] + v[1] <= 1.0 + 1e-3,
            "{v:?}"
        );
    }
    // Smooth and head-on: everything reflected, no Fresnel gain.
    let s = lut.get(1.0, 0.0);
    assert!(s[0] > 0.95 && s[1] < 0.02, "{s:?}");
    // Grazing: Fresnel grows.
    assert!(lut.get(0.05, 0.2)[1] > lut.get(0.9, 0.2)[1]);
    let img = lut.to_image();
    assert_eq!((img.width(), img.height()), (32, 32));
}
