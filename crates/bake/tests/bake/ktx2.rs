//! Plain KTX2: the cubes read back by the `ktx2` crate, the SH JSON's coefficients.

use crate::common::bake;
use mirrorball_bake::Engine;

#[test]
fn ktx2_files_are_cubes_with_the_chain_and_the_sh() {
    let dir = tempfile::tempdir().unwrap();
    let (baked, lighting, files) = bake(Engine::Ktx2, 16, None, dir.path());
    let names = crate::common::names(&files);
    assert_eq!(
        names,
        ["specular.ktx2", "diffuse.ktx2", "sh.json", "README.md"]
    );
    for (file, levels) in [(&files[0], 5), (&files[1], 1)] {
        let bytes = std::fs::read(file).unwrap();
        let r = ::ktx2::Reader::new(&bytes[..]).unwrap();
        let h = r.header();
        assert_eq!(h.face_count, 6);
        assert_eq!(h.level_count, levels);
        assert_eq!(h.format, Some(::ktx2::Format::R16G16B16A16_SFLOAT));
        assert_eq!(
            h.supercompression_scheme, None,
            "the library's default is none; the CLI asks for Zstandard"
        );
    }
    // Linear roughness in the level, unless asked otherwise.
    for (m, &(_, r)) in baked.spec.levels.iter().enumerate() {
        assert!((r - m as f64 / 4.0).abs() < 1e-12);
    }
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&files[2]).unwrap()).unwrap();
    let irr = lighting.sh9.lambert();
    for i in 0..9 {
        for c in 0..3 {
            let v = doc["irradiance_over_pi"][i][c].as_f64().unwrap();
            assert!((v - irr.coeffs[i][c]).abs() < 1e-12);
        }
    }
    // E/π of ½ + ½d is ½ + ⅓ n: the constant and each colour's own axis.
    let k0 = mirrorball_filter::sh::CONSTANTS[0];
    assert!((irr.coeffs[0][0] * k0 - 0.5).abs() < 1e-3);
    assert_eq!(doc["levels"].as_array().unwrap().len(), 5);
}
