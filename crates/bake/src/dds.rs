//! Lighting for Unity and Unreal: DDS cubes (BC6H by default), each turned into its
//! engine's world. Direct3D samples a cube with the same face table and row order as
//! OpenGL (ARCHITECTURE.md's cube convention), so the only difference is the world's axes:
//!
//! - **Unity**: left-handed, +Y up, +Z forward, +X right. Mirrorball's forward is −Z, so a
//!   Unity direction `e` is mirrorball's `(e.x, e.y, −e.z)`: mirror z. Unity's shaders
//!   sample reflection probes with the world reflected vector
//!   (`UNITY_SAMPLE_TEXCUBE_LOD(unity_SpecCube0, reflUVW, mip)`), unflipped.
//! - **Unreal**: left-handed, Z up, X forward, Y right. Mirrorball's forward, right and up
//!   are −Z, +X, +Y, so an Unreal direction `e = (forward, right, up)` is mirrorball's
//!   `(e.y, e.z, −e.x)`; Unreal's shaders sample with the world reflection vector
//!   (`TextureCubeSampleLevel(…, ReflectionVector, Mip)`, ReflectionEnvironmentShared.ush).
//!
//! Roughness: Unity's `PerceptualRoughnessToMipmapLevel` (the render pipelines' core
//! ImageBasedLighting.hlsl): `mip = r(1.7 − 0.7r) · UNITY_SPECCUBE_LOD_STEPS`, the steps
//! being 6 ("the last mip index, we generate 7 mips of convolution"), so level `m` holds
//! `r = (1.7 − √(2.89 − 2.8·m/6))/1.4`, and levels past 6 hold r = 1 ([`unity_roughness`]).
//! Unreal: `ComputeReflectionCaptureMipFromRoughness` (ReflectionEnvironmentShared.ush):
//! `RoughnessMapping::Ue4`.

use crate::{chain_by, cube_write, faces, BakeOptions, ChainSpec, Description, Lighting, Target};
use mirrorball_core::{Axis, AxisMap};
use mirrorball_filter::RoughnessMapping;
use mirrorball_io::{Encoding, Error};
use std::path::{Path, PathBuf};

/// Unity's `UNITY_SPECCUBE_LOD_STEPS`: the last mip level its shaders read.
const UNITY_LOD_STEPS: f64 = 6.0;
/// The diffuse cube's face edge.
const DIFFUSE_FACE: u32 = 32;

/// The perceptual roughness Unity reads from level `m`: the inverse of
/// `mip = r(1.7 − 0.7r) · 6`, clamped to 1 past level 6.
pub(crate) fn unity_roughness(m: usize) -> f64 {
    let t = m as f64 / UNITY_LOD_STEPS;
    if t >= 1.0 {
        return 1.0;
    }
    (1.7 - (2.89 - 2.8 * t).sqrt()) / 1.4
}

/// The two engines that take DDS cubes: the same files, each in its own world and with its
/// own roughness rule.
pub(crate) enum Dds {
    /// Unity.
    Unity,
    /// Unreal Engine.
    Unreal,
}

impl Dds {
    /// The engine's roughness per level.
    fn mapping(&self, levels: usize) -> RoughnessMapping {
        match self {
            Dds::Unity => RoughnessMapping::Custom((0..levels).map(unity_roughness).collect()),
            Dds::Unreal => RoughnessMapping::Ue4,
        }
    }
}

const ENCODINGS: &[Encoding] = &[
    Encoding::Bc6hUnsigned,
    Encoding::Bc6hSigned,
    Encoding::Rgba16F,
    Encoding::Rgba32F,
];

/// The specular chain's file.
const SPECULAR: &str = "specular.dds";
/// The diffuse cube's file.
const DIFFUSE: &str = "diffuse.dds";

impl Target for Dds {
    /// The full chain at the engine's roughness rule, and a 32² diffuse cube.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        let n = (32 - opts.size.max(1).leading_zeros()) as usize;
        ChainSpec {
            levels: chain_by(opts, &self.mapping(n)),
            diffuse_face: Some(DIFFUSE_FACE),
            background_face: None,
        }
    }

    fn describe(&self) -> Description {
        match self {
            Dds::Unity => Description {
                files: "specular.dds (GGX chain to 1x1), diffuse.dds (irradiance/pi, 32²)",
                containers: "DDS (DX10 header)",
                encodings: ENCODINGS,
                zstd: false,
                convention: "left-handed, +Y up, +Z forward: z mirrored, (x, y, -z)",
                rule: "mip = 6 * r * (1.7 - 0.7 r) (ImageBasedLighting.hlsl \
                   PerceptualRoughnessToMipmapLevel; levels past 6 hold r = 1)",
                diffuse: "diffuse.dds sampled at the normal (Unity makes its own SH from a probe)",
                background: None,
            },
            Dds::Unreal => Description {
                files: "specular.dds (GGX chain to 1x1), diffuse.dds (irradiance/pi, 32²)",
                containers: "DDS (DX10 header)",
                encodings: ENCODINGS,
                zstd: false,
                convention: "left-handed, Z up, X forward, Y right: (y, z, -x)",
                rule: "mip = levels - 2 + 1.2 log2(r) (ReflectionEnvironmentShared.ush \
                   ComputeReflectionCaptureMipFromRoughness)",
                diffuse: "diffuse.dds sampled at the normal (a Sky Light makes its own SH)",
                background: None,
            },
        }
    }

    /// The engine's axes (see the module documentation).
    fn orientation(&self) -> AxisMap {
        match self {
            Dds::Unity => AxisMap::mirror(Axis::Z),
            Dds::Unreal => AxisMap::new([(Axis::Y, 1), (Axis::Z, 1), (Axis::X, -1)])
                .expect("a signed permutation"),
        }
    }

    /// `specular.dds`, `diffuse.dds`.
    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        vec![SPECULAR.into(), DIFFUSE.into()]
    }

    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let specular = dir.join(SPECULAR);
        mirrorball_io::write_dds(&specular, &faces(&l.specular), &cube_write(opts, vec![]))?;
        let mut files = vec![specular];
        if let Some(d) = &l.diffuse {
            let diffuse = dir.join(DIFFUSE);
            mirrorball_io::write_dds(
                &diffuse,
                &faces(std::slice::from_ref(d)),
                &cube_write(opts, vec![]),
            )?;
            files.push(diffuse);
        }
        Ok(files)
    }

    /// The note's body: where to put the files and the lines that load them.
    fn readme(&self, _opts: &BakeOptions, _spec: &ChainSpec) -> String {
        match self {
        Dds::Unity => format!(
            "## Loading it\n\n\
             Put `{SPECULAR}` and `{DIFFUSE}` under `Assets/Resources/` (any folder of that \
             name). In the texture importer: Texture Shape Cube, Mapping Auto, Convolution \
             Type None (the mips are already convolved), sRGB off. The faces are already in \
             Unity's left-handed world.\n\n\
             ```csharp\n\
             // The assets the two files became: Resources.Load takes the name without its extension.\n\
             Cubemap specularCubemap = Resources.Load<Cubemap>(\"specular\"); // {SPECULAR}\n\
             Cubemap diffuseCubemap = Resources.Load<Cubemap>(\"diffuse\");   // {DIFFUSE}\n\
             var probe = GetComponent<ReflectionProbe>();\n\
             probe.mode = UnityEngine.Rendering.ReflectionProbeMode.Custom;\n\
             probe.customBakedTexture = specularCubemap;\n\
             // or, for the sky: RenderSettings.defaultReflectionMode = DefaultReflectionMode.Custom;\n\
             //                  RenderSettings.customReflectionTexture = specularCubemap;\n\
             // or, for a shader of your own (below):\n\
             material.SetTexture(\"_Specular\", specularCubemap);\n\
             material.SetTexture(\"_Diffuse\", diffuseCubemap);\n\
             ```\n\n\
             ```hlsl\n\
             TEXTURECUBE(_Specular); SAMPLER(sampler_Specular); // {SPECULAR}\n\
             TEXTURECUBE(_Diffuse);  SAMPLER(sampler_Diffuse);  // {DIFFUSE}\n\
             half mip = PerceptualRoughnessToMipmapLevel(perceptualRoughness); // 6 r (1.7 - 0.7 r)\n\
             half3 spec = SAMPLE_TEXTURECUBE_LOD(_Specular, sampler_Specular, reflectDir, mip).rgb;\n\
             half3 diff = SAMPLE_TEXTURECUBE(_Diffuse, sampler_Diffuse, normalWS).rgb; // E/pi\n\
             ```\n"
        ),
        Dds::Unreal => format!(
            "## Loading it\n\n\
             Import `{SPECULAR}` and `{DIFFUSE}` into the Content folder (Import, or drag them \
             in): each becomes a TextureCube asset of the same name; set Compression Settings \
             HDR Compressed (BC6H) or HDR and keep its mips. The faces are already in \
             Unreal's Z-up world.\n\n\
             ```cpp\n\
             // The asset the import of {SPECULAR} made, at Content/specular.\n\
             UTextureCube* SpecularCube = LoadObject<UTextureCube>(nullptr, TEXT(\"/Game/specular.specular\"));\n\
             // SkyLight: the level's ASkyLight.\n\
             USkyLightComponent* Sky = SkyLight->GetLightComponent();\n\
             Sky->SourceType = ESkyLightSourceType::SLS_SpecifiedCubemap;\n\
             Sky->SetCubemap(SpecularCube);\n\
             Sky->RecaptureSky();\n\
             ```\n\n\
             A Sky Light filters the cubemap again; a material that reads the chain as it is \
             samples it with TextureSampleParameterCube at MipLevel = \
             ComputeReflectionCaptureMipFromRoughness(Roughness, MipCount - 1).\n"
        ),
    }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unity picks level `6 r (1.7 − 0.7 r)`: each level's roughness lands on its level.
    #[test]
    fn unity_roughness_inverts_its_level_rule() {
        for m in 0..=6 {
            let r = unity_roughness(m);
            let level = UNITY_LOD_STEPS * r * (1.7 - 0.7 * r);
            assert!((level - m as f64).abs() < 1e-12, "{m}: r = {r}");
        }
        assert_eq!(unity_roughness(9), 1.0);
    }
}
