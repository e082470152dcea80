//! Lighting for plain OpenGL and Vulkan: KTX2 cubes exactly in the OpenGL convention
//! (ARCHITECTURE.md: faces +X −X +Y −Y +Z −Z, row 0 at t = 0, sampled with the world
//! direction), so nothing is turned; a specular chain to 1×1, a diffuse cube and the SH as
//! JSON.

use crate::{
    chain_by, cube_write, faces, names, write_text, BakeOptions, ChainSpec, Description, Lighting,
    Target,
};
use mirrorball_core::AxisMap;
use mirrorball_filter::{sh, RoughnessMapping};
use mirrorball_io::{Encoding, Error};
use serde_json::json;
use std::path::{Path, PathBuf};

const SPECULAR: &str = "specular.ktx2";
const DIFFUSE: &str = "diffuse.ktx2";
const SH: &str = "sh.json";
/// The diffuse cube's face edge: irradiance is smooth (SH9 describes it to about 1%).
const DIFFUSE_FACE: u32 = 32;

/// Plain OpenGL's and Vulkan's rules.
pub(crate) struct Ktx2;

impl Target for Ktx2 {
    /// The full chain, roughness linear in the level unless the user gives a mapping (the
    /// shader then picks `level = roughness · (levels − 1)`), and a 32² diffuse cube.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        ChainSpec {
            levels: chain_by(opts, &RoughnessMapping::Linear),
            diffuse_face: Some(DIFFUSE_FACE),
            background_face: None,
        }
    }

    fn describe(&self) -> Description {
        Description {
            files: "specular.ktx2 (GGX chain to 1x1), diffuse.ktx2 (irradiance/pi, 32²), sh.json",
            containers: "KTX2",
            encodings: &[
                Encoding::Rgba16F,
                Encoding::Rgba32F,
                Encoding::Rgb9E5,
                Encoding::B10G11R11,
                Encoding::Bc6hUnsigned,
                Encoding::Bc6hSigned,
                Encoding::Rgbd,
                Encoding::Rgbm,
            ],
            zstd: true,
            convention: "OpenGL's (4.6 §8.13) and Vulkan's cube, sampled with the world direction \
                     (right-handed, +Y up, -Z ahead); nothing turned",
            rule: "level = roughness * (levels - 1) (or --mapping's)",
            diffuse: "diffuse.ktx2 sampled at the normal; sh.json's irradiance_over_pi",
            background: None,
        }
    }

    /// The OpenGL convention is mirrorball's own.
    fn orientation(&self) -> AxisMap {
        AxisMap::IDENTITY
    }

    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        [SPECULAR, DIFFUSE, SH].map(String::from).to_vec()
    }

    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let specular = dir.join(SPECULAR);
        mirrorball_io::write_ktx2(&specular, &faces(&l.specular), &cube_write(opts, vec![]))?;
        let mut files = vec![specular];
        if let Some(d) = &l.diffuse {
            let diffuse = dir.join(DIFFUSE);
            mirrorball_io::write_ktx2(
                &diffuse,
                &faces(std::slice::from_ref(d)),
                &cube_write(opts, vec![]),
            )?;
            files.push(diffuse);
        }
        let sh_path = dir.join(SH);
        write_text(&sh_path, &sh_document(l, opts, &files))?;
        files.push(sh_path);
        Ok(files)
    }

    fn readme(&self, opts: &BakeOptions, _spec: &ChainSpec) -> String {
        let mapping = opts.mapping.clone().unwrap_or(RoughnessMapping::Linear);
        format!(
        "## Loading it\n\n\
         `{SPECULAR}` is a cube map with its whole mip chain; `{DIFFUSE}` one level of \
         irradiance divided by pi; `{SH}` the same as nine SH coefficients. Faces are in \
         OpenGL's order and orientation, so sample them with world directions, unflipped.\n\n\
         ```c\n\
         // libktx (KTX-Software)\n\
         ktxTexture2* tex;\n\
         ktxTexture2_CreateFromNamedFile(\"{SPECULAR}\", KTX_TEXTURE_CREATE_LOAD_IMAGE_DATA_BIT, &tex);\n\
         GLuint name = 0; GLenum target, err;\n\
         ktxTexture_GLUpload(ktxTexture(tex), &name, &target, &err); // target: GL_TEXTURE_CUBE_MAP\n\
         glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);\n\
         glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);\n\
         ```\n\n\
         ```glsl\n\
         // {}\n\
         vec3 specular = textureLod(specularMap, reflect(-v, n), roughness * float(textureQueryLevels(specularMap) - 1)).rgb;\n\
         vec3 diffuse = texture(diffuseMap, n).rgb; // E/pi: times the albedo\n\
         ```\n\n\
         Vulkan: `ktxTexture2_VkUploadEx` gives a `VK_IMAGE_VIEW_TYPE_CUBE` image. BC6H needs \
         `GL_ARB_texture_compression_bptc` (or `textureCompressionBC`); a supercompressed \
         file is inflated by libktx on load.\n",
        mapping.level_formula()
    )
    }
}

/// The SH JSON: the basis, the radiance's and the irradiance's coefficients, and the
/// levels' roughness, in prefilter's words.
fn sh_document(l: &Lighting, opts: &BakeOptions, files: &[PathBuf]) -> String {
    let coeffs = |s: &sh::Sh9| -> Vec<[f64; 3]> { s.coeffs.to_vec() };
    let mapping = opts.mapping.clone().unwrap_or(RoughnessMapping::Linear);
    let levels: Vec<_> = l
        .specular
        .iter()
        .zip(&l.roughness)
        .enumerate()
        .map(|(i, (m, r))| json!({"level": i, "width": m.width(), "lobe": "ggx", "roughness": r}))
        .collect();
    let doc = json!({
        "generator": format!("mirrorball {}", env!("CARGO_PKG_VERSION")),
        "source": opts.source,
        "output": names(files),
        "basis": sh::BASIS_TEXT,
        "radiance": coeffs(&l.sh9),
        "irradiance_over_pi": coeffs(&l.sh9.lambert()),
        "irradiance_note": sh::IRRADIANCE_TEXT,
        "roughness_mapping": mapping.name(),
        "roughness_to_level": mapping.level_formula(),
        "levels": levels,
    });
    serde_json::to_string_pretty(&doc).expect("JSON values serialise")
}
