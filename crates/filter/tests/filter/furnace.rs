//! The furnace test: a constant environment comes out constant, for every lobe, every
//! level of every chain, every output projection.
use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_filter::{
    chain_lobes, Lobe, LobeKind, PrefilterOptions, Prefilterer, RoughnessMapping,
};

const C: [f32; 3] = [1.0, 0.5, 2.0];

fn check(env: &EnvMap, what: &str) {
    for (layer, img) in env.layers().iter().enumerate() {
        for px in img.data().chunks_exact(img.channels()) {
            for k in 0..3 {
                let e = (px[k] - C[k]).abs() / C[k];
                assert!(
                    e < 2e-5,
                    "{what}: layer {layer} channel {k}: {} vs {}",
                    px[k],
                    C[k]
                );
            }
        }
    }
}

#[test]
fn constant_in_constant_out() {
    for src_kind in [ProjectionKind::Cube, ProjectionKind::LatLong] {
        let size = if src_kind == ProjectionKind::Cube {
            16
        } else {
            64
        };
        let src = EnvMap::from_fn(src_kind.default_projection(), size, 3, |_| {
            [C[0], C[1], C[2], 1.0]
        });
        let pf = Prefilterer::new(&src, PrefilterOptions::default());
        let mut lobes = vec![
            Lobe::Lambert,
            Lobe::Phong { exponent: 1.0 },
            Lobe::Phong { exponent: 1000.0 },
            Lobe::Phong {
                exponent: f64::INFINITY,
            },
            Lobe::Ggx { roughness: 0.0 },
            Lobe::Ggx { roughness: 0.05 },
        ];
        for kind in [LobeKind::Lambert, LobeKind::Phong, LobeKind::Ggx] {
            for m in [
                RoughnessMapping::Linear,
                RoughnessMapping::Ue4,
                RoughnessMapping::Filament,
            ] {
                lobes.extend(chain_lobes(kind, &m, 5));
            }
        }
        for out in [
            ProjectionKind::Cube,
            ProjectionKind::LatLong,
            ProjectionKind::Sphere,
            ProjectionKind::Octahedral,
        ] {
            for lobe in &lobes {
                let m = pf.render(lobe, out.default_projection(), 8);
                check(&m, &format!("{src_kind} → {out} {lobe:?}"));
            }
        }
        // A whole chain, level by level.
        let chain = pf.render_chain(
            &chain_lobes(LobeKind::Ggx, &RoughnessMapping::Linear, 5),
            ProjectionKind::Cube.default_projection(),
            16,
        );
        assert_eq!(chain.len(), 5);
        for (i, level) in chain.iter().enumerate() {
            assert_eq!(level.width(), 16 >> i);
            check(level, &format!("chain level {i}"));
        }
    }
}
