//! Lighting for Filament, as `cmgen --deploy` writes it, less the source's name in front
//! (the folder is the bake's): `ibl.ktx` (the specular chain, KTX1, the SH under the key
//! `sh`), `skybox.ktx` (the source as a cube, at the background's size) and `sh.txt`.
//!
//! - **Axes.** Filament's world is mirrorball's (right-handed, +Y up) and its shaders look
//!   the cube up with the world reflected vector, unflipped: `textureLod(sampler0_iblSpecular,
//!   r, lod)` (shaders/src/surface_light_indirect.fs, `prefilteredRadiance`); its IBL
//!   library addresses faces with OpenGL's table (libs/ibl/src/Cubemap.cpp,
//!   `Cubemap::getAddressFor`: +X sc = −z, tc = −y; … the same as OpenGL 4.6 table 8.19).
//!   So nothing is turned. cmgen's default mirror (`CubemapUtils::mirrorCubemap`, which
//!   samples the source at (−x, y, z); `--no-mirror` skips it) undoes its own reading of
//!   a panorama (`equirectangularToCubemap`: longitude `atan2(x, z)`, increasing to the
//!   right, which seen from inside runs from +Z towards +X, to the left): mirrorball reads
//!   panoramas the right way round already. cmgen's panorama centre lands at +Z and
//!   mirrorball's at −Z (a half turn about +Y, not a mirror).
//! - **Roughness.** `perceptualRoughnessToLod`: `lod = iblRoughnessOneLevel · r(2 − r)`
//!   (surface_light_indirect.fs), `iblRoughnessOneLevel` = levels − 1; so level `m` holds
//!   `r = 1 − √(1 − m/(L − 1))`: `RoughnessMapping::Filament`.
//! - **SH.** `Irradiance_SphericalHarmonics` (surface_light_indirect.fs) sums
//!   `iblSH[i] · Pᵢ(n)` with the bare polynomials 1, y, z, x, yx, yz, 3z² − 1, zx, x² − y²,
//!   and uses the sum as E(n)/π (the diffuse BRDF's 1/π baked in). cmgen's `--deploy`
//!   writes exactly that, "pre-scaled" (libs/ibl/src/CubemapSH.cpp,
//!   `computeIrradianceSH3Bands`: Aᵢ = Kᵢ² · Âₗ/π): coefficient `i` is the basis constant
//!   Kᵢ times mirrorball's E/π coefficient ([`prescaled`]).

use crate::{
    chain_by, cube_write, faces, write_text, BakeOptions, ChainSpec, Description, Lighting, Target,
};
use mirrorball_core::AxisMap;
use mirrorball_filter::sh::{self, Sh9};
use mirrorball_filter::RoughnessMapping;
use mirrorball_io::{Encoding, Error};
use std::path::{Path, PathBuf};

/// The specular chain's file.
const IBL: &str = "ibl.ktx";
/// The sky's file.
const SKYBOX: &str = "skybox.ktx";
/// The SH as text.
const SH_TXT: &str = "sh.txt";

/// Filament's rules.
pub(crate) struct Filament;

impl Target for Filament {
    /// The full chain at Filament's roughness rule; diffuse light is SH only; the skybox.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        ChainSpec {
            levels: chain_by(opts, &RoughnessMapping::Filament),
            diffuse_face: None,
            background_face: Some(opts.background_face()),
        }
    }

    fn describe(&self) -> Description {
        Description {
        files: "ibl.ktx (GGX chain to 1x1, SH under the key sh), skybox.ktx, sh.txt",
        containers: "KTX1 (Filament's Ktx1Reader)",
        encodings: &[Encoding::B10G11R11, Encoding::Rgba16F, Encoding::Rgba32F],
        zstd: false,
        convention: "Filament's world is ours and its shaders sample r unflipped \
                     (surface_light_indirect.fs prefilteredRadiance); nothing turned",
        rule:
            "lod = (levels - 1) * r * (2 - r) (surface_light_indirect.fs perceptualRoughnessToLod)",
        diffuse: "SH9 pre-scaled as cmgen --deploy writes it (CubemapSH.cpp \
                  computeIrradianceSH3Bands), in sh.txt and the ibl file's sh key",
        background: Some("skybox.ktx, the source as a cube, one level (Skybox::Builder)"),
    }
    }

    /// Filament's axes and cube lookups are mirrorball's (see the module documentation).
    fn orientation(&self) -> AxisMap {
        AxisMap::IDENTITY
    }

    /// `ibl.ktx`, `skybox.ktx`, `sh.txt`: cmgen's names without the source's in front.
    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        [IBL, SKYBOX, SH_TXT].map(String::from).to_vec()
    }

    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let [ibl, skybox, txt] = [IBL, SKYBOX, SH_TXT].map(|n| dir.join(n));
        let Some(sky) = &l.background else {
            return Err(Error::request(
                dir,
                "Filament's skybox is the background; this lighting has none: make it from \
             Engine::Filament.chain_spec"
                    .into(),
            ));
        };
        let sh = prescaled(&l.sh9);
        let sh32: Vec<[f32; 3]> = sh.iter().map(|c| c.map(|v| v as f32)).collect();
        let with_sh = cube_write(
            opts,
            vec![("sh".into(), mirrorball_io::filament_sh_text(&sh32))],
        );
        mirrorball_io::write_ktx1(&ibl, &faces(&l.specular), &with_sh)?;
        mirrorball_io::write_ktx1(
            &skybox,
            &faces(std::slice::from_ref(sky)),
            &cube_write(opts, vec![]),
        )?;
        write_text(&txt, &sh_txt(&sh))?;
        Ok(vec![ibl, skybox, txt])
    }

    fn readme(&self, _opts: &BakeOptions, spec: &ChainSpec) -> String {
        let sky = spec.background_face.unwrap_or(spec.levels[0].0);
        format!(
            "## Loading it\n\n\
         As the files `cmgen --deploy` writes (without the source's name in front): `{IBL}` \
         the specular cube with its mip chain (the SH under the key `sh`), `{SKYBOX}` the \
         source itself for the sky ({sky}² faces), `{SH_TXT}` the nine pre-scaled irradiance \
         coefficients.\n\n\
         ```cpp\n\
         #include <ktxreader/Ktx1Reader.h>\n\
         #include <fstream>\n\
         #include <vector>\n\
         using namespace filament;\n\
         auto read = [](const char* name) {{\n\
         \x20   std::ifstream in(name, std::ios::binary);\n\
         \x20   return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {{}});\n\
         }};\n\
         std::vector<uint8_t> iblData = read(\"{IBL}\"), skyData = read(\"{SKYBOX}\");\n\
         auto* iblBundle = new image::Ktx1Bundle(iblData.data(), iblData.size());\n\
         math::float3 sh[9];\n\
         iblBundle->getSphericalHarmonics(sh);\n\
         Texture* ibl = ktxreader::Ktx1Reader::createTexture(engine, iblBundle, false);\n\
         auto* skyBundle = new image::Ktx1Bundle(skyData.data(), skyData.size());\n\
         Texture* sky = ktxreader::Ktx1Reader::createTexture(engine, skyBundle, false);\n\
         IndirectLight* light = IndirectLight::Builder()\n\
         \x20       .reflections(ibl)\n\
         \x20       .irradiance(3, sh)\n\
         \x20       .intensity(30000.0f)\n\
         \x20       .build(*engine);\n\
         Skybox* skybox = Skybox::Builder().environment(sky).build(*engine);\n\
         scene->setIndirectLight(light);\n\
         scene->setSkybox(skybox);\n\
         ```\n\n\
         Nothing is mirrored: Filament samples world directions as mirrorball stores them \
         (cmgen mirrors only to undo its own reading of panoramas). Where cmgen puts a \
         panorama's centre at +Z, mirrorball puts it at -Z, ahead of the default camera: \
         `IndirectLight::setRotation` with a half turn about +Y matches cmgen's.\n"
        )
    }
}

/// The nine coefficients Filament's `IndirectLight::Builder::irradiance(3, sh)` takes: for
/// each, the basis constant Kᵢ times the coefficient of E/π (cmgen's pre-scaled SH), so
/// that `Σ shᵢ Pᵢ(n)` is E(n)/π.
pub(crate) fn prescaled(sh9: &Sh9) -> [[f64; 3]; 9] {
    let lambert = sh9.lambert();
    let mut out = [[0.0; 3]; 9];
    for (i, o) in out.iter_mut().enumerate() {
        *o = lambert.coeffs[i].map(|c| c * sh::CONSTANTS[i]);
    }
    out
}

/// `sh.txt` as cmgen writes it (`outputSh`): one line per coefficient, band l then m from
/// −l to l, `(r, g, b); // Llm, irradiance, pre-scaled base`, fifteen decimals, each number
/// 18 wide; Filament's samples read it back with `sscanf("(%f,%f,%f)")`.
pub(crate) fn sh_txt(sh: &[[f64; 3]; 9]) -> String {
    let mut out = String::new();
    let mut i = 0;
    for l in 0..3i32 {
        for m in -l..=l {
            let c = sh[i];
            out += &format!(
                "({:18.15}, {:18.15}, {:18.15}); // L{l}{m}, irradiance, pre-scaled base\n",
                c[0], c[1], c[2]
            );
            i += 1;
        }
    }
    out
}
