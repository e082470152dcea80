//! What `bake --for bevy` writes, read by Bevy's own KTX2 loader (`bevy_image`'s
//! `ktx2_buffer_to_image`, the function its asset loader calls) and looked up the way Bevy's
//! WGSL looks it up: a direction-coded world (colour = ½ + ½·d) must come back as the
//! direction Bevy asks for.
//!
//! The lookup, from bevy at 4805ca7, `crates/bevy_pbr/src/light_probe/environment_map.wesl`:
//! the reflected direction R has its z negated (`:272`, `radiance_sample_dir.z =
//! -radiance_sample_dir.z`) and samples the specular cube at level `perceptual_roughness ×
//! (mip count − 1)` (`:242`, `:273-277`); the normal N likewise samples the diffuse cube at
//! level 0 (`:259-264`). wgpu samples cubes with the Vulkan/OpenGL face selection (Vulkan
//! §16.5.4 "Cube Map Face Selection", OpenGL 4.6 table 8.19), written here from the table.
//! Texels are decoded here from the bytes Bevy hands the GPU (`Image::data`, mip-major:
//! level by level, the six faces in each), by each wgpu format's definition, not by
//! mirrorball's decoders.

use bevy_image::{ktx2_buffer_to_image, CompressedImageFormats};
use glam::DVec3;
use half::f16;
use mirrorball_bake::{Bake, BakeOptions, Engine, Lighting};
use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_io::Encoding;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use wgpu_types::{TextureDimension, TextureFormat, TextureViewDimension};

/// Level 0's face edge in these tests.
const SIZE: u32 = 64;
/// The rough level checked: 16², perceptual roughness 2/6.
const ROUGH: usize = 2;

/// The direction-coded world.
fn code(d: DVec3) -> DVec3 {
    DVec3::splat(0.5) + 0.5 * d
}

/// The direction-coded world as a lat-long map, prefiltered once for Bevy's chain.
fn lighting() -> &'static Lighting {
    static L: OnceLock<Lighting> = OnceLock::new();
    L.get_or_init(|| {
        let env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 512, 3, |d| {
            let c = code(d);
            [c.x as f32, c.y as f32, c.z as f32, 1.0]
        });
        let spec = Engine::Bevy.chain_spec(&options(None, None));
        Lighting::from_env(&env, &spec, Default::default())
    })
}

fn options(encoding: Option<Encoding>, zstd: Option<i32>) -> BakeOptions {
    BakeOptions {
        size: SIZE,
        encoding,
        zstd,
        source: "direction-coded".into(),
        ..Default::default()
    }
}

/// Bakes for Bevy into a fresh folder through the library; the folder and the files.
fn bake(encoding: Option<Encoding>, zstd: Option<i32>) -> (tempfile::TempDir, Vec<PathBuf>) {
    let bake = Bake::new(Engine::Bevy, options(encoding, zstd)).expect("a request Bevy takes");
    let dir = tempfile::tempdir().unwrap();
    let turned = lighting().clone().oriented(&Engine::Bevy.orientation());
    let files = bake.write(&turned, dir.path()).expect("the bake");
    (dir, files)
}

fn file<'a>(files: &'a [PathBuf], name: &str) -> &'a Path {
    files
        .iter()
        .find(|f| f.file_name().unwrap() == name)
        .unwrap_or_else(|| panic!("{name} among {files:?}"))
}

/// A cube as Bevy hands it to the GPU, decoded: `levels[m][face]` is the face's texels,
/// RGB, top row first.
struct Cube {
    format: TextureFormat,
    levels: Vec<[Vec<[f32; 3]>; 6]>,
}

impl Cube {
    fn edge(&self, level: usize) -> usize {
        (self.levels[level][0].len() as f64).sqrt() as usize
    }

    /// `textureSampleLevel(cube, s, dir, level)` at an integer level, nearest texel: the
    /// face and (s, t) from the major axis (Vulkan §16.5.4 / OpenGL table 8.19).
    fn sample(&self, dir: DVec3, level: usize) -> DVec3 {
        let (x, y, z) = (dir.x, dir.y, dir.z);
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        let (face, sc, tc, ma) = if ax >= ay && ax >= az {
            if x > 0.0 {
                (0, -z, -y, ax)
            } else {
                (1, z, -y, ax)
            }
        } else if ay >= az {
            if y > 0.0 {
                (2, x, z, ay)
            } else {
                (3, x, -z, ay)
            }
        } else if z > 0.0 {
            (4, x, -y, az)
        } else {
            (5, -x, -y, az)
        };
        let (s, t) = (0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
        let n = self.edge(level);
        let i = ((s * n as f64) as usize).min(n - 1);
        let j = ((t * n as f64) as usize).min(n - 1);
        let v = self.levels[level][face][j * n + i];
        DVec3::new(v[0].into(), v[1].into(), v[2].into())
    }
}

/// Loads `path` with Bevy's loader (every compressed format supported) and checks it is a
/// cube of `format` with `mips` levels of edge `edge`, its data as long as wgpu needs.
fn load(path: &Path, format: TextureFormat, edge: u32, mips: u32) -> Cube {
    let bytes = std::fs::read(path).unwrap();
    let image = ktx2_buffer_to_image(&bytes, CompressedImageFormats::all(), false)
        .unwrap_or_else(|e| panic!("{}: Bevy refuses it: {e:?}", path.display()));
    let d = &image.texture_descriptor;
    assert_eq!(d.format, format, "{}", path.display());
    assert_eq!(
        (d.size.width, d.size.height, d.size.depth_or_array_layers),
        (edge, edge, 6),
        "{}: six layers of {edge}²",
        path.display()
    );
    assert_eq!(d.mip_level_count, mips, "{}", path.display());
    assert_eq!(d.dimension, TextureDimension::D2);
    let view = image.texture_view_descriptor.as_ref().expect("a view");
    assert_eq!(
        view.dimension,
        Some(TextureViewDimension::Cube),
        "{}",
        path.display()
    );
    let data = image.data.as_ref().expect("texels");
    let (bw, bh) = format.block_dimensions();
    let block_bytes = format.block_copy_size(None).unwrap() as usize;
    let mut at = 0;
    let mut levels = Vec::new();
    for m in 0..mips {
        let n = (edge >> m).max(1) as usize;
        let face_bytes = n.div_ceil(bw as usize) * n.div_ceil(bh as usize) * block_bytes;
        let faces = std::array::from_fn(|_| {
            let face = decode(format, &data[at..at + face_bytes], n);
            at += face_bytes;
            face
        });
        levels.push(faces);
    }
    assert_eq!(
        at,
        data.len(),
        "{}: level data as wgpu lays it",
        path.display()
    );
    Cube { format, levels }
}

/// One `n`×`n` face of `format`, decoded by the format's definition.
fn decode(format: TextureFormat, bytes: &[u8], n: usize) -> Vec<[f32; 3]> {
    let words = || {
        bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    match format {
        TextureFormat::Rgba16Float => bytes
            .chunks_exact(8)
            .map(|b| {
                let h = |k: usize| f16::from_le_bytes([b[2 * k], b[2 * k + 1]]).to_f32();
                [h(0), h(1), h(2)]
            })
            .collect(),
        // E5B9G9R9_UFLOAT_PACK32: 9-bit R, G, B mantissas from bit 0, a 5-bit exponent at
        // bit 27; value = mantissa · 2^(e − 15 − 9) (EXT_texture_shared_exponent).
        TextureFormat::Rgb9e5Ufloat => words()
            .map(|w| {
                let scale = 2f32.powi((w >> 27) as i32 - 24);
                [0, 9, 18].map(|s| ((w >> s) & 0x1ff) as f32 * scale)
            })
            .collect(),
        // B10G11R11_UFLOAT_PACK32: R in bits 0–10 and G in 11–21 (5-bit exponent, 6-bit
        // mantissa), B in 22–31 (5-bit exponent, 5-bit mantissa), no sign, bias 15.
        TextureFormat::Rg11b10Ufloat => words()
            .map(|w| {
                let small = |bits: u32, mantissa_bits: u32| {
                    let m = (bits & ((1 << mantissa_bits) - 1)) as f32;
                    let e = (bits >> mantissa_bits) as i32;
                    let one = (1u32 << mantissa_bits) as f32;
                    if e == 0 {
                        m / one * 2f32.powi(-14)
                    } else {
                        (1.0 + m / one) * 2f32.powi(e - 15)
                    }
                };
                [
                    small(w & 0x7ff, 6),
                    small((w >> 11) & 0x7ff, 6),
                    small(w >> 22, 5),
                ]
            })
            .collect(),
        TextureFormat::Bc6hRgbUfloat | TextureFormat::Bc6hRgbFloat => {
            let signed = format == TextureFormat::Bc6hRgbFloat;
            let blocks = n.div_ceil(4);
            let mut out = vec![[0.0; 3]; n * n];
            for (k, block) in bytes.chunks_exact(16).enumerate() {
                let mut texels = [0f32; 48];
                bcdec_rs::bc6h_float(block, &mut texels, 12, signed);
                let (bx, by) = (k % blocks * 4, k / blocks * 4);
                for j in 0..4.min(n - by) {
                    for i in 0..4.min(n - bx) {
                        let t = &texels[(j * 4 + i) * 3..][..3];
                        out[(by + j) * n + bx + i] = [t[0], t[1], t[2]];
                    }
                }
            }
            out
        }
        f => panic!("no decoder for {f:?}"),
    }
}

/// 10⁴ directions spread evenly over the sphere (a Fibonacci lattice).
fn directions() -> impl Iterator<Item = DVec3> {
    const N: usize = 10_000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..N).map(move |i| {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / N as f64;
        let r = (1.0 - y * y).sqrt();
        let phi = golden * i as f64;
        DVec3::new(r * phi.cos(), y, r * phi.sin())
    })
}

/// Bevy's sample direction for a world direction (environment_map.wesl:259, :272).
fn bevy_dir(world: DVec3) -> DVec3 {
    DVec3::new(world.x, world.y, -world.z)
}

/// How far a texel of edge `n` reaches: its diagonal in tangent units, 2√2/n, bounds the
/// angle between a direction and the centre of the texel it falls in (at most half that,
/// doubled to allow one texel of disagreement at face edges).
fn texel(n: usize) -> f64 {
    2.0 * 2f64.sqrt() / n as f64
}

/// The largest error `encoding` adds to `level` as Bevy gets it: the level mirrored in z
/// here, from its definition (each texel centre's value at (x, y, −z), exact at texel
/// centres), encoded and decoded by mirrorball's encoder (deterministic, so these are the
/// bytes of the bake) and compared. BC6H's error is the block's, up to ~0.1 on a 4×4 block
/// of this world at 16² (one region cannot hold a 2-D gradient); the others' is rounding.
fn encoding_error(level: &EnvMap, encoding: Encoding) -> f64 {
    let cube = ProjectionKind::Cube.default_projection();
    let mirrored = EnvMap::from_fn(cube, level.width(), 3, |d| {
        level.sample(DVec3::new(d.x, d.y, -d.z))
    });
    let mut bytes = Vec::new();
    let mut worst = 0f64;
    for face in mirrored.layers() {
        encoding.encode_with(face, Default::default(), &mut bytes);
        let back = encoding.decode(&bytes, face.width(), face.height());
        for (a, b) in face
            .data()
            .chunks_exact(3)
            .zip(back.data().chunks_exact(back.channels()))
        {
            for k in 0..3 {
                worst = worst.max(f64::from((a[k] - b[k]).abs()));
            }
        }
    }
    worst
}

/// Level 0 is the mirror: Bevy's lookup of R shows R's colour within one texel.
fn check_mirror(cube: &Cube, lighting: &Lighting, encoding: Encoding) {
    let tol = 0.5 * texel(cube.edge(0)) + encoding_error(&lighting.specular[0], encoding);
    let mut worst = 0f64;
    for r in directions() {
        let got = cube.sample(bevy_dir(r), 0);
        let err = (got - code(r)).abs().max_element();
        assert!(
            err <= tol,
            "{:?} level 0 at R = {r:.3}: {got:.3}, want {:.3}",
            cube.format,
            code(r)
        );
        worst = worst.max(err);
    }
    eprintln!(
        "{:?} level 0: worst error {worst:.4} (≤ {tol:.4})",
        cube.format
    );
}

/// A rough level of the direction-coded world is ½ + ½·k·R for one k in (0, 1): a lobe
/// symmetric about R averages the linear world to a shorter R. So the value minus ½ points
/// along R (within a texel), with one length everywhere; and it agrees with the library's
/// own level looked up at R in mirrorball's axes.
fn check_rough(cube: &Cube, lighting: &Lighting, encoding: Encoding) {
    let n = cube.edge(ROUGH);
    let ours = &lighting.specular[ROUGH];
    let k_at = |r: DVec3| 2.0 * (cube.sample(bevy_dir(r), ROUGH) - DVec3::splat(0.5)).dot(r);
    let k = k_at(DVec3::Y);
    assert!(
        k > 0.2 && k < 0.999,
        "{:?}: k = {k} at roughness {}",
        cube.format,
        lighting.roughness[ROUGH]
    );
    let tol = 0.5 * k * texel(n) + encoding_error(ours, encoding);
    for r in directions() {
        let got = cube.sample(bevy_dir(r), ROUGH);
        let want = DVec3::splat(0.5) + 0.5 * k * r;
        assert!(
            (got - want).abs().max_element() <= tol,
            "{:?} level {ROUGH} at R = {r:.3}: {got:.3}, want {want:.3} (k {k:.3})",
            cube.format
        );
        let lib = ours.sample(r);
        let lib = DVec3::new(lib[0].into(), lib[1].into(), lib[2].into());
        assert!(
            (got - lib).abs().max_element() <= tol,
            "{:?} level {ROUGH} at R = {r:.3}: {got:.3}, the library's {lib:.3}",
            cube.format
        );
    }
}

/// The diffuse cube at N is the library's irradiance/π at N, and, for this world, the
/// cosine-weighted mean of ½ + ½·d over N's hemisphere: ½ + ⅓·N.
fn check_diffuse(cube: &Cube, lighting: &Lighting, encoding: Encoding) {
    let n = cube.edge(0);
    let ours = lighting.diffuse.as_ref().unwrap();
    let tol = 0.5 * (2.0 / 3.0) * texel(n) + encoding_error(ours, encoding);
    for normal in directions() {
        let got = cube.sample(bevy_dir(normal), 0);
        let exact = DVec3::splat(0.5) + normal / 3.0;
        assert!(
            // 0.005 more for the lat-long source's own texels
            (got - exact).abs().max_element() <= tol + 0.005,
            "{:?} diffuse at N = {normal:.3}: {got:.3}, want {exact:.3}",
            cube.format
        );
        let lib = ours.sample(normal);
        let lib = DVec3::new(lib[0].into(), lib[1].into(), lib[2].into());
        assert!(
            (got - lib).abs().max_element() <= tol,
            "{:?} diffuse at N = {normal:.3}: {got:.3}, the library's {lib:.3}",
            cube.format
        );
    }
}

/// Every encoding Bevy takes, with and without Zstandard: each file a cube of the format
/// and mip count Bevy expects, the world the right way round.
#[test]
fn bevy_loads_every_output_the_right_way_round() {
    let levels = SIZE.ilog2() + 1;
    for (encoding, zstd, format) in [
        (None, None, TextureFormat::Rgb9e5Ufloat),
        (None, Some(3), TextureFormat::Rgb9e5Ufloat),
        (Some(Encoding::Rgba16F), None, TextureFormat::Rgba16Float),
        (
            Some(Encoding::B10G11R11),
            Some(3),
            TextureFormat::Rg11b10Ufloat,
        ),
        (
            Some(Encoding::Bc6hUnsigned),
            Some(3),
            TextureFormat::Bc6hRgbUfloat,
        ),
        (
            Some(Encoding::Bc6hSigned),
            None,
            TextureFormat::Bc6hRgbFloat,
        ),
    ] {
        let (_dir, files) = bake(encoding, zstd);
        eprintln!("{encoding:?}, zstd {zstd:?}:");
        let specular = load(file(&files, "specular.ktx2"), format, SIZE, levels);
        let diffuse = load(file(&files, "diffuse.ktx2"), format, 32, 1);
        let encoding = encoding.unwrap_or(Encoding::Rgb9E5);
        check_mirror(&specular, lighting(), encoding);
        check_rough(&specular, lighting(), encoding);
        check_diffuse(&diffuse, lighting(), encoding);
    }
}

/// BC6H is refused by Bevy's loader on a GPU without BC formats, which is why RGB9E5 is the
/// default: the default loads with no compressed format at all.
#[test]
fn the_default_loads_without_compressed_formats() {
    let (_dir, files) = bake(None, Some(3));
    for f in &files[..2] {
        let bytes = std::fs::read(f).unwrap();
        ktx2_buffer_to_image(&bytes, CompressedImageFormats::NONE, false)
            .unwrap_or_else(|e| panic!("{}: {e:?}", f.display()));
    }
    let (_dir, files) = bake(Some(Encoding::Bc6hUnsigned), None);
    let bytes = std::fs::read(file(&files, "specular.ktx2")).unwrap();
    assert!(ktx2_buffer_to_image(&bytes, CompressedImageFormats::NONE, false).is_err());
}

/// Each cube records who wrote it, its orientation as KTX2 defines it, and what it holds
/// (Bevy reads none of it: `ktx2_buffer_to_image` ignores key/value data).
#[test]
fn the_cubes_record_their_writer_and_content() {
    let (_dir, files) = bake(None, Some(3));
    for (name, content) in [("specular.ktx2", "GGX"), ("diffuse.ktx2", "Lambert")] {
        let bytes = std::fs::read(file(&files, name)).unwrap();
        let reader = ktx2::Reader::new(&bytes[..]).unwrap();
        let kv: std::collections::HashMap<&str, String> = reader
            .key_value_data()
            .map(|(k, v)| (k, String::from_utf8_lossy(v).trim_end_matches('\0').into()))
            .collect();
        assert!(kv["KTXwriter"].starts_with("mirrorball "), "{name}: {kv:?}");
        assert_eq!(kv["KTXorientation"], "rd", "{name}");
        assert_eq!(kv["mirrorball:engine"], "bevy", "{name}");
        assert!(kv["mirrorball:content"].contains(content), "{name}: {kv:?}");
        assert!(
            kv["mirrorball:content"].contains("z mirrored"),
            "{name}: {kv:?}"
        );
    }
}

/// The note says how to load the files in Bevy.
#[test]
fn the_note_names_the_files_and_the_component() {
    let (_dir, files) = bake(None, None);
    let note = std::fs::read_to_string(file(&files, "README.md")).unwrap();
    for needle in [
        "EnvironmentMapLight",
        "specular.ktx2",
        "diffuse.ktx2",
        "RGB9E5",
    ] {
        assert!(note.contains(needle), "{needle} in\n{note}");
    }
}

/// Requests Bevy cannot load are refused before any work, in words.
#[test]
fn bad_requests_are_refused_up_front() {
    for (encoding, size) in [
        (Some(Encoding::Rgba32F), 64),
        (Some(Encoding::Rgbd), 64),
        (None, 48),
        (Some(Encoding::Bc6hUnsigned), 2),
    ] {
        let opts = BakeOptions {
            size,
            encoding,
            ..Default::default()
        };
        let e = Bake::new(Engine::Bevy, opts).unwrap_err();
        assert_eq!(e.fault, mirrorball_core::Fault::Request);
        assert!(
            e.message.contains(&size.to_string()) || e.message.contains("rgb"),
            "{e}"
        );
    }
}
