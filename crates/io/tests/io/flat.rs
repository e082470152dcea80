//! Flat-image tests: OpenEXR, Radiance HDR, PNG, JPEG and WebP round trips, the bundled
//! assets, bad input, and writes that fail without leaving files behind.

use mirrorball_core::{Image, ProjectionKind};
use mirrorball_io::{
    read, write_image, Error, ExrCompression, Fault, Format, Limits, MapInfo, OutputSet, Precision,
    WriteOptions,
};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------
// Helpers.

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(name)
}

/// A deterministic pseudo-random generator (xorshift), in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// An HDR test picture: gradients, noise over several decades, a few exact zeros, a bright
/// spot, flat runs; alpha (if any) in [0, 1].
fn hdr_image(w: u32, h: u32, c: usize) -> Image {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ (w as u64 * 31 + h as u64 * 7 + c as u64));
    let mut img = Image::new(w, h, c);
    for y in 0..h {
        for x in 0..w {
            let v = if y % 5 == 4 {
                // A flat row segment (runs for RLE).
                [0.25, 0.5, 1.0, 0.5]
            } else if x == 3 && y == 2 {
                [5000.0, 3000.0, 1000.0, 1.0]
            } else if (x + y) % 17 == 0 {
                [0.0, 0.0, 0.0, 0.0]
            } else {
                let decade = 10f32.powf(rng.next() * 5.0 - 3.0);
                [
                    decade * rng.next(),
                    decade * rng.next(),
                    decade * rng.next(),
                    rng.next(),
                ]
            };
            img.set(x, y, &v);
        }
    }
    img
}

/// A display-range picture (linear values in [0, 1], alpha in [0, 1]).
fn ldr_image(w: u32, h: u32, c: usize) -> Image {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d ^ (w as u64 * 13 + h as u64 + c as u64));
    let mut img = Image::new(w, h, c);
    for px in img.data_mut().chunks_exact_mut(c) {
        for v in px.iter_mut() {
            *v = rng.next();
        }
    }
    img
}

fn write_err(path: &Path, img: &Image, opts: &WriteOptions) -> Error {
    match write_image(path, img, opts) {
        Ok(()) => panic!("writing {} should fail", path.display()),
        Err(e) => e,
    }
}

fn read_err(path: &Path) -> Error {
    read_err_with(path, &Limits::default())
}

fn read_err_with(path: &Path, limits: &Limits) -> Error {
    match read(path, limits) {
        Ok(l) => panic!(
            "reading {} should fail, got {}",
            path.display(),
            l.description
        ),
        Err(e) => e,
    }
}

fn read_one(path: &Path) -> (Image, mirrorball_io::Loaded) {
    let loaded = read(path, &Limits::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(loaded.layers.len(), 1);
    (loaded.layers[0].clone(), loaded)
}

/// Asserts an input error whose message names the file.
fn assert_input_error(e: &Error, path: &Path) {
    assert_eq!(e.fault(), Fault::Input, "{e}");
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(
        e.to_string().contains(&*name),
        "message should name the file: {e}"
    );
}

/// Asserts an input error that says the file is truncated.
fn assert_truncated(e: &Error, path: &Path) {
    assert_input_error(e, path);
    assert!(e.problem().contains("truncated"), "{e}");
}

/// The directory holds exactly `names` (no temporary files).
fn assert_dir_holds(dir: &Path, names: &[&str]) {
    let mut found: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut want: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(found, want);
}

fn half(v: f32) -> f32 {
    half::f16::from_f32(v).to_f32()
}

/// The exact sRGB encoding, in f64, for checking.
fn srgb(l: f32) -> f64 {
    let l = (l as f64).clamp(0.0, 1.0);
    if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

fn opts(precision: Option<Precision>) -> WriteOptions {
    WriteOptions {
        precision,
        ..WriteOptions::default()
    }
}

const COMPRESSIONS: [ExrCompression; 6] = [
    ExrCompression::None,
    ExrCompression::Rle,
    ExrCompression::Zips,
    ExrCompression::Zip,
    ExrCompression::Piz,
    ExrCompression::Pxr24,
];

fn compression_label(c: ExrCompression) -> &'static str {
    match c {
        ExrCompression::None => "uncompressed",
        ExrCompression::Rle => "RLE compression",
        ExrCompression::Zips => "ZIPS compression",
        ExrCompression::Zip => "ZIP compression",
        ExrCompression::Piz => "PIZ compression",
        ExrCompression::Pxr24 => "PXR24 compression",
    }
}

// ---------------------------------------------------------------------------------------
// OpenEXR.

#[test]
fn exr_half_round_trip_every_compression() {
    let dir = tempfile::tempdir().unwrap();
    for c in [3, 4] {
        // 45 rows: several ZIP (16) and PIZ (32) blocks, the last one partial.
        let img = hdr_image(37, 45, c);
        for comp in COMPRESSIONS {
            let path = dir.path().join(format!("half-{c}-{comp:?}.exr"));
            let o = WriteOptions {
                exr_compression: comp,
                ..WriteOptions::default()
            };
            write_image(&path, &img, &o).unwrap();
            let (back, loaded) = read_one(&path);
            assert_eq!(loaded.format, Format::Exr);
            assert_eq!(loaded.declared, None);
            assert_eq!((back.width(), back.height(), back.channels()), (37, 45, c));
            let want = format!(
                "OpenEXR, half, {}, {}",
                compression_label(comp),
                if c == 4 { "RGBA" } else { "RGB" }
            );
            assert_eq!(loaded.description, want);
            // Every compression is lossless for half data.
            for (i, (&a, &b)) in img.data().iter().zip(back.data()).enumerate() {
                assert_eq!(half(a), b, "{comp:?} sample {i}");
            }
        }
    }
}

#[test]
fn exr_float_round_trip_every_compression() {
    let dir = tempfile::tempdir().unwrap();
    for c in [3, 4] {
        let img = hdr_image(41, 35, c);
        for comp in COMPRESSIONS {
            let path = dir.path().join(format!("float-{c}-{comp:?}.exr"));
            let o = WriteOptions {
                exr_compression: comp,
                precision: Some(Precision::Float),
                ..WriteOptions::default()
            };
            write_image(&path, &img, &o).unwrap();
            let (back, loaded) = read_one(&path);
            assert_eq!((back.width(), back.height(), back.channels()), (41, 35, c));
            assert!(
                loaded.description.starts_with("OpenEXR, float, "),
                "{}",
                loaded.description
            );
            if comp == ExrCompression::Pxr24 {
                // 24-bit floats: 15 mantissa bits.
                for (&a, &b) in img.data().iter().zip(back.data()) {
                    assert!((a - b).abs() <= a.abs() * 3.1e-5, "{a} vs {b}");
                }
            } else {
                assert_eq!(img.data(), back.data(), "{comp:?} must be exact");
            }
        }
    }
}

/// The reader's count of NaN, infinite and negative values (`Loaded::invalid`), where it
/// counts (ZIP and ZIPS scan lines, half and float, RGB and RGBA), is the number of such
/// colour values in the decoded texels, counted here one by one; readers that do not count
/// say so (`None`), and formats that cannot hold such values say `Some(0)`.
#[test]
fn readers_count_invalid_values_where_they_can() {
    let dir = tempfile::tempdir().unwrap();
    let brute = |img: &Image| {
        let c = img.channels();
        img.data()
            .iter()
            .enumerate()
            .filter(|&(i, v)| {
                let alpha = c == 4 && i % 4 == 3;
                let valid = *v >= 0.0 && v.is_finite();
                !alpha && !valid
            })
            .count() as u64
    };
    for c in [3, 4] {
        let mut img = hdr_image(41, 35, c);
        // Scattered over blocks, lanes and the ragged end of the rows; alpha too, which does
        // not count.
        for (k, &v) in [f32::NAN, -1.0, f32::INFINITY, f32::NEG_INFINITY, -0.001]
            .iter()
            .enumerate()
        {
            let (x, y) = ((k as u32 * 17 + 3) % 41, (k as u32 * 11 + 1) % 35);
            let mut px = img.get(x, y).to_vec();
            px[k % 3] = v;
            if c == 4 {
                px[3] = -5.0;
            }
            img.set(x, y, &px);
        }
        img.set(40, 34, &[f32::NAN, 1.0, -2.0, 1.0][..c]);
        for precision in [Precision::Half, Precision::Float] {
            for comp in COMPRESSIONS {
                let path = dir
                    .path()
                    .join(format!("bad-{c}-{precision:?}-{comp:?}.exr"));
                let o = WriteOptions {
                    exr_compression: comp,
                    precision: Some(precision),
                    ..WriteOptions::default()
                };
                write_image(&path, &img, &o).unwrap();
                let (back, loaded) = read_one(&path);
                let expected = brute(&back);
                // (Half clamps +∞ to 65504, which is valid.)
                assert!(expected >= 6, "{c} {precision:?} {comp:?}: {expected}");
                // ZIP and ZIPS counted as decoded, the others after.
                assert_eq!(loaded.invalid(), expected, "{c} {precision:?} {comp:?}");
            }
        }
        // A clean map counts zero.
        let clean = hdr_image(41, 35, c);
        let path = dir.path().join(format!("clean-{c}.exr"));
        write_image(&path, &clean, &opts(Some(Precision::Float))).unwrap();
        assert_eq!(read_one(&path).1.invalid(), 0);
    }
    // RGBE and 8/16-bit PNG hold no such values.
    let hdr = dir.path().join("a.hdr");
    write_image(&hdr, &hdr_image(9, 5, 3), &opts(None)).unwrap();
    assert_eq!(read_one(&hdr).1.invalid(), 0);
    let png = dir.path().join("a.png");
    write_image(&png, &ldr_image(9, 5, 3), &opts(None)).unwrap();
    assert_eq!(read_one(&png).1.invalid(), 0);
}

/// What the `exr` crate's own writer makes of `img` uncompressed (half samples clamped to
/// the finite range, as mirrorball writes them), with the `envmap` attribute when `latlong`.
fn exr_crate_uncompressed(img: &Image, float: bool, latlong: bool) -> Vec<u8> {
    use exr::prelude::*;
    let st = if float {
        SampleType::F32
    } else {
        SampleType::F16
    };
    let (w, c) = (img.width() as usize, img.channels());
    let data = img.data();
    let fit = move |v: f32| if float { v } else { v.clamp(-65504.0, 65504.0) };
    // mirrorball records the projection as a string attribute (and writes no `envmap`).
    let mut attrs = LayerAttributes::default();
    if latlong {
        use exr::meta::attribute::{AttributeValue, Text};
        attrs.other.insert(
            Text::from("mirrorball:projection"),
            AttributeValue::Text(Text::from("latlong")),
        );
    }
    let enc = Encoding {
        compression: Compression::Uncompressed,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let size = Vec2(w, img.height() as usize);
    let d = |n: &str| ChannelDescription::named(n, st);
    let mut bytes = std::io::Cursor::new(Vec::new());
    if c == 4 {
        let px = move |p: Vec2<usize>| {
            let i = (p.y() * w + p.x()) * 4;
            (
                fit(data[i]),
                fit(data[i + 1]),
                fit(data[i + 2]),
                fit(data[i + 3]),
            )
        };
        let ch = SpecificChannels {
            channels: (d("R"), d("G"), d("B"), d("A")),
            pixels: px,
        };
        exr::image::Image::from_layer(Layer::new(size, attrs, enc, ch))
            .write()
            .to_buffered(&mut bytes)
            .unwrap();
    } else {
        let px = move |p: Vec2<usize>| {
            let i = (p.y() * w + p.x()) * 3;
            (fit(data[i]), fit(data[i + 1]), fit(data[i + 2]))
        };
        let ch = SpecificChannels {
            channels: (d("R"), d("G"), d("B")),
            pixels: px,
        };
        exr::image::Image::from_layer(Layer::new(size, attrs, enc, ch))
            .write()
            .to_buffered(&mut bytes)
            .unwrap();
    }
    bytes.into_inner()
}

#[test]
fn exr_uncompressed_files_are_byte_for_byte_what_the_exr_crate_writes() {
    // mirrorball writes uncompressed files itself (header by the `exr` crate, offset table
    // and lines packed here): the bytes must be the crate's own, for every sample type,
    // channel count, a one-line image, lines past one write batch, and the envmap attribute.
    let dir = tempfile::tempdir().unwrap();
    for (w, h) in [(37, 45), (5, 1), (3000, 200)] {
        for c in [3, 4] {
            let img = hdr_image(w, h, c);
            for float in [false, true] {
                for latlong in [false, true] {
                    let path = dir.path().join(format!("u-{w}-{c}-{float}-{latlong}.exr"));
                    let o = WriteOptions {
                        exr_compression: ExrCompression::None,
                        precision: Some(if float {
                            Precision::Float
                        } else {
                            Precision::Half
                        }),
                        declared: latlong.then_some(MapInfo {
                            projection: mirrorball_core::LatLong.into(),
                            layout: None,
                            stereo: Default::default(),
                        }),
                        ..WriteOptions::default()
                    };
                    write_image(&path, &img, &o).unwrap();
                    let ours = std::fs::read(&path).unwrap();
                    let theirs = exr_crate_uncompressed(&img, float, latlong);
                    assert_eq!(ours.len(), theirs.len(), "{w}x{h}x{c} float {float}");
                    assert!(
                        ours == theirs,
                        "{w}x{h}x{c} float {float} latlong {latlong}"
                    );
                }
            }
        }
    }
}

#[test]
fn exr_half_clamps_finite_values_to_the_largest_half_and_float_keeps_values() {
    let dir = tempfile::tempdir().unwrap();
    let mut img = Image::new(2, 1, 3);
    img.set(0, 0, &[1.0e6, -1.0e6, 70000.0]);
    img.set(1, 0, &[1.0e-3, f32::INFINITY, 0.5]);
    let path = dir.path().join("bright.exr");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let (back, _) = read_one(&path);
    assert_eq!(back.get(0, 0), &[65504.0, -65504.0, 65504.0]);
    // Half holds infinities: they stay (the caller decides whether one reaches a writer:
    // the CLI sets them to 0 unless --keep-invalid).
    assert_eq!(back.get(1, 0), &[half(1.0e-3), f32::INFINITY, 0.5]);

    write_image(&path, &img, &opts(Some(Precision::Float))).unwrap();
    let (back, _) = read_one(&path);
    assert_eq!(back.data(), img.data());
}

#[test]
fn exr_integer_precision_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.exr");
    let e = write_err(&path, &hdr_image(4, 4, 3), &opts(Some(Precision::U8)));
    assert_eq!(e.fault(), Fault::Request);
    assert!(e.problem().contains("half or float"), "{e}");
    assert_dir_holds(dir.path(), &[]);
}

#[test]
fn exr_reads_the_bundled_city() {
    let (img, loaded) = read_one(&asset("city.exr"));
    assert_eq!((img.width(), img.height(), img.channels()), (512, 256, 3));
    assert!(img.data().iter().all(|v| v.is_finite()));
    let mean = img.data().iter().map(|&v| v as f64).sum::<f64>() / img.data().len() as f64;
    assert!(mean > 0.1 && mean < 10.0, "mean {mean}");
    assert_eq!(loaded.declared, None, "city.exr has no envmap attribute");
    assert_eq!(loaded.description, "OpenEXR, half, ZIP compression, RGB");
}

/// The bundled DWAB file is city.exr before it was re-saved with ZIP: the `exr` crate
/// (1.74.1 and later) decodes DWAA/DWAB, and does so bit-exactly here.
#[test]
fn exr_reads_dwab_like_the_reference_decoder() {
    let (dwab, loaded) = read_one(&asset("city-dwab.exr"));
    let (zip, _) = read_one(&asset("city.exr"));
    assert_eq!(
        loaded.description,
        "OpenEXR, half, DWAB compression (lossy), RGB"
    );
    assert_eq!(dwab, zip);
}

/// Rewrites the value of the `compression` attribute of an EXR file in place.
fn patch_exr_compression(bytes: &mut [u8], code: u8) {
    let key = b"compression\0compression\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("compression attribute");
    let value = at + key.len() + 4; // after the i32 size
    bytes[value] = code;
}

#[test]
fn exr_undecodable_compression_says_how_to_resave() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("city-htj2k.exr");
    let mut bytes = std::fs::read(asset("city.exr")).unwrap();
    patch_exr_compression(&mut bytes, 10); // HTJ2K256
    std::fs::write(&path, &bytes).unwrap();
    let e = read_err(&path);
    assert_input_error(&e, &path);
    let msg = e.to_string();
    assert!(
        msg.contains("HTJ2K") && msg.contains("ZIP") && msg.contains("oiiotool"),
        "{msg}"
    );
}

#[test]
fn exr_reads_the_envmap_attribute() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    for (attr, want) in [
        (
            exr::meta::attribute::EnvironmentMap::LatitudeLongitude,
            ProjectionKind::LatLong,
        ),
        (
            exr::meta::attribute::EnvironmentMap::Cube,
            ProjectionKind::Cube,
        ),
    ] {
        let path = dir.path().join(format!("{want:?}.exr"));
        let attributes = LayerAttributes {
            environment_map: Some(attr),
            ..LayerAttributes::default()
        };
        let channels = SpecificChannels::rgb(|_: Vec2<usize>| (1.0f32, 0.5f32, 0.25f32));
        let layer = Layer::new((8, 6), attributes, Encoding::SMALL_LOSSLESS, channels);
        exr::image::Image::from_layer(layer)
            .write()
            .to_file(&path)
            .unwrap();
        let (img, loaded) = read_one(&path);
        assert_eq!(loaded.declared, Some(want));
        assert_eq!(img.get(7, 5), &[1.0, 0.5, 0.25]);
    }
}

#[test]
fn exr_reads_u32_and_mixed_channels() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mixed.exr");
    let channels = SpecificChannels::rgba(|Vec2(x, _y): Vec2<usize>| {
        (x as u32, f16::from_f32(0.5), 2.0f32, f16::from_f32(0.25))
    });
    exr::image::Image::from_channels((5, 3), channels)
        .write()
        .to_file(&path)
        .unwrap();
    let (img, loaded) = read_one(&path);
    assert_eq!(img.channels(), 4);
    assert_eq!(img.get(4, 2), &[4.0, 0.5, 2.0, 0.25]);
    assert!(
        loaded.description.contains("mixed"),
        "{}",
        loaded.description
    );
}

#[test]
fn exr_reads_the_first_rgb_layer_of_a_multi_part_tiled_file() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layers.exr");
    let (w, h) = (70usize, 40usize);
    let plane = |f: &dyn Fn(usize, usize) -> f32| {
        FlatSamples::F32((0..w * h).map(|i| f(i % w, i / w)).collect())
    };
    let layer = |name: &str, channels: Vec<AnyChannel<FlatSamples>>| {
        let channels = AnyChannels::sort(SmallVec::from_vec(channels));
        // 64×64 tiles, RLE.
        Layer::new(
            (w, h),
            LayerAttributes::named(name),
            Encoding::FAST_LOSSLESS,
            channels,
        )
    };
    let depth = layer("depth", vec![AnyChannel::new("Z", plane(&|_, _| 9.0))]);
    let beauty = layer(
        "beauty",
        vec![
            AnyChannel::new("R", plane(&|x, _| x as f32)),
            AnyChannel::new("G", plane(&|_, y| y as f32)),
            AnyChannel::new("B", plane(&|_, _| 0.5)),
        ],
    );
    let attributes = ImageAttributes::new(IntegerBounds::from_dimensions((w, h)));
    exr::image::Image::from_layers(attributes, SmallVec::from_vec(vec![depth, beauty]))
        .write()
        .to_file(&path)
        .unwrap();
    let (img, loaded) = read_one(&path);
    assert_eq!((img.width(), img.height(), img.channels()), (70, 40, 3));
    assert_eq!(img.get(69, 39), &[69.0, 39.0, 0.5]);
    assert_eq!(
        loaded.description,
        "OpenEXR, float, RLE compression, RGB, tiled, layer \"beauty\" of 2"
    );
}

#[test]
fn exr_without_rgb_is_an_input_error() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("depth.exr");
    let channels = SpecificChannels::build()
        .with_channel("Z")
        .with_pixel_fn(|_| (1.0f32,));
    exr::image::Image::from_channels((4, 4), channels)
        .write()
        .to_file(&path)
        .unwrap();
    let e = read_err(&path);
    assert_input_error(&e, &path);
    assert!(
        e.problem().contains("R, G and B") && e.problem().contains('Z'),
        "{e}"
    );
}

/// Sets an EXR header's box2i attribute `name` to (0, 0)–(w-1, h-1).
fn patch_exr_box(bytes: &mut [u8], name: &str, w: i32, h: i32) {
    let key = [name.as_bytes(), b"\0box2i\0"].concat();
    let at = bytes
        .windows(key.len())
        .position(|x| x == key.as_slice())
        .expect("box attribute");
    let v = at + key.len() + 4;
    for (i, n) in [0, 0, w - 1, h - 1].into_iter().enumerate() {
        bytes[v + 4 * i..v + 4 * i + 4].copy_from_slice(&i32::to_le_bytes(n));
    }
}

/// Sets an EXR header's `chunkCount` attribute, which the `exr` crate checks against the
/// data window (one chunk per scan line when uncompressed).
fn patch_exr_chunk_count(bytes: &mut [u8], count: i32) {
    let key = b"chunkCount\0int\0";
    let at = bytes
        .windows(key.len())
        .position(|x| x == key)
        .expect("chunkCount attribute");
    let v = at + key.len() + 4;
    bytes[v..v + 4].copy_from_slice(&count.to_le_bytes());
}

#[test]
fn exr_huge_declared_size_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small.exr");
    let o = WriteOptions {
        exr_compression: ExrCompression::None,
        ..WriteOptions::default()
    };
    write_image(&small, &Image::new(1, 1, 3), &o).unwrap();
    let mut bytes = std::fs::read(&small).unwrap();
    patch_exr_box(&mut bytes, "dataWindow", 60000, 60000);
    patch_exr_box(&mut bytes, "displayWindow", 60000, 60000);
    patch_exr_chunk_count(&mut bytes, 60000);
    let path = dir.path().join("huge.exr");
    std::fs::write(&path, &bytes).unwrap();
    let e = read_err(&path);
    assert_input_error(&e, &path);
    assert!(e.problem().contains("60000×60000"), "{e}");

    // Beyond the largest dimension, too.
    patch_exr_box(&mut bytes, "dataWindow", 70000, 2);
    patch_exr_box(&mut bytes, "displayWindow", 70000, 2);
    patch_exr_chunk_count(&mut bytes, 2);
    std::fs::write(&path, &bytes).unwrap();
    let e = read_err(&path);
    assert!(
        e.problem().contains("70000×2") && e.problem().contains("65536"),
        "{e}"
    );

    // And tighter limits refuse a real file.
    let tight = Limits {
        max_texels: 1000,
        ..Limits::default()
    };
    let e = read_err_with(&asset("city.exr"), &tight);
    assert_input_error(&e, &asset("city.exr"));
    assert!(e.problem().contains("512×256"), "{e}");
}

#[test]
fn exr_truncated_garbage_and_missing_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(asset("city.exr")).unwrap();
    for (name, cut) in [
        ("half.exr", bytes.len() / 2),
        ("header.exr", 100),
        ("magic.exr", 3),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes[..cut]).unwrap();
        assert_truncated(&read_err(&path), &path);
    }
    let path = dir.path().join("garbage.exr");
    std::fs::write(
        &path,
        b"this is not an OpenEXR file at all, just some text\n".repeat(50),
    )
    .unwrap();
    assert_input_error(&read_err(&path), &path);

    // The real magic number and version, then garbage.
    let mut fake = bytes[..8].to_vec();
    fake.extend((0..4000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8));
    std::fs::write(&path, &fake).unwrap();
    assert_input_error(&read_err(&path), &path);

    let path = dir.path().join("missing.exr");
    let e = read_err(&path);
    assert_input_error(&e, &path);
    assert!(e.problem().contains("no such file"), "{e}");

    // A directory with an image's name.
    for name in ["dir.exr", "dir.hdr", "dir.png", "dir.jpg"] {
        let path = dir.path().join(name);
        std::fs::create_dir(&path).unwrap();
        let e = read_err(&path);
        assert_input_error(&e, &path);
        assert!(e.problem().contains("directory"), "{e}");
    }
}

/// A ZIP EXR whose offset table or blocks were tampered with: each fault is an input error
/// that names the file and says what is wrong, never a panic, and a file whose blocks are
/// all in place still reads (the positioned reads of the ZIP path).
#[test]
fn exr_zip_blocks_out_of_place_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(40, 50, 3); // 4 blocks of 16 lines (the last one 2 lines)
    let path = dir.path().join("ok.exr");
    let opts = WriteOptions {
        precision: Some(Precision::Float),
        exr_compression: ExrCompression::Zip,
        ..WriteOptions::default()
    };
    write_image(&path, &img, &opts).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let u64_at = |b: &[u8], p: usize| u64::from_le_bytes(b[p..p + 8].try_into().unwrap());
    // The offset table: 4 entries, the first pointing just past the table.
    let table = (0..bytes.len() - 32)
        .find(|&p| u64_at(&bytes, p) == p as u64 + 32)
        .expect("offset table");
    let offsets: Vec<usize> = (0..4)
        .map(|i| u64_at(&bytes, table + 8 * i) as usize)
        .collect();
    assert_eq!(read_one(&path).0.data(), img.data());

    // (file name, what the message must say, how the bytes are tampered with)
    type Case<'a> = (&'a str, &'a str, Box<dyn Fn(&mut Vec<u8>) + 'a>);
    let cases: [Case; 6] = [
        (
            "same.exr",
            "two blocks claim",
            Box::new(|b| {
                let first = b[table..table + 8].to_vec();
                b[table + 8..table + 16].copy_from_slice(&first);
            }),
        ),
        (
            "past.exr",
            "truncated",
            Box::new(|b| {
                b[table + 16..table + 24].copy_from_slice(&(1u64 << 40).to_le_bytes());
            }),
        ),
        (
            "size.exr",
            "impossible size",
            Box::new(|b| {
                let at = offsets[1] + 4;
                b[at..at + 4].copy_from_slice(&(40 * 16 * 12 + 1i32).to_le_bytes());
            }),
        ),
        (
            "negative.exr",
            "impossible size",
            Box::new(|b| {
                let at = offsets[2] + 4;
                b[at..at + 4].copy_from_slice(&(-5i32).to_le_bytes());
            }),
        ),
        (
            "line.exr",
            "outside",
            Box::new(|b| {
                let at = offsets[3];
                b[at..at + 4].copy_from_slice(&7i32.to_le_bytes());
            }),
        ),
        (
            "inflate.exr",
            "inflate",
            Box::new(|b| {
                let at = offsets[0] + 8;
                for v in &mut b[at..at + 64] {
                    *v = !*v;
                }
            }),
        ),
    ];
    for (name, says, tamper) in cases {
        let mut b = bytes.clone();
        tamper(&mut b);
        let path = dir.path().join(name);
        std::fs::write(&path, &b).unwrap();
        let e = read_err(&path);
        assert_input_error(&e, &path);
        assert!(e.problem().contains(says), "{name}: {e}");
    }
}

// ---------------------------------------------------------------------------------------
// Radiance HDR.

/// RGBE keeps 8 mantissa bits relative to the texel's largest channel.
fn assert_rgbe_close(orig: &Image, back: &Image) {
    assert_eq!(
        (back.width(), back.height(), back.channels()),
        (orig.width(), orig.height(), 3)
    );
    for y in 0..orig.height() {
        for x in 0..orig.width() {
            let (a, b) = (orig.get(x, y), back.get(x, y));
            let max = a[0].max(a[1]).max(a[2]);
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= max * (0.5 / 128.0) + 1e-30,
                    "texel ({x}, {y}) channel {k}: {} vs {}",
                    a[k],
                    b[k]
                );
            }
            // The largest channel, well within 1%.
            if max > 1e-30 {
                let bmax = b[0].max(b[1]).max(b[2]);
                assert!((bmax - max).abs() <= max * 0.004, "{max} vs {bmax}");
            }
        }
    }
}

#[test]
fn hdr_round_trip_rle_and_flat() {
    let dir = tempfile::tempdir().unwrap();
    // Run-length encoded widths, a width past the 127-byte run limit, and flat widths.
    for (w, h) in [(64, 20), (300, 7), (8, 3), (7, 5), (1, 1)] {
        let img = hdr_image(w, h, 3);
        let path = dir.path().join(format!("rt-{w}x{h}.hdr"));
        write_image(&path, &img, &WriteOptions::default()).unwrap();
        let (back, loaded) = read_one(&path);
        assert_eq!(loaded.format, Format::Hdr);
        assert_eq!(loaded.description, "Radiance RGBE");
        assert_eq!(loaded.declared, None);
        assert_rgbe_close(&img, &back);
    }
    // The header is the standard one.
    let bytes = std::fs::read(dir.path().join("rt-64x20.hdr")).unwrap();
    assert!(bytes.starts_with(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 20 +X 64\n"));
}

#[test]
fn hdr_drops_alpha_and_clamps_what_rgbe_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(20, 4, 4);
    let path = dir.path().join("alpha.hdr");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let (back, _) = read_one(&path);
    assert_rgbe_close(&img.with_channels(3), &back);

    let mut odd = Image::new(9, 1, 3);
    odd.set(0, 0, &[-1.0, f32::NAN, 2.0]);
    odd.set(1, 0, &[f32::NEG_INFINITY, 0.0, -0.0]);
    odd.set(2, 0, &[f32::INFINITY, 1.0, 0.0]);
    odd.set(3, 0, &[1e-40, 1.0, 0.0]);
    let path = dir.path().join("odd.hdr");
    write_image(&path, &odd, &WriteOptions::default()).unwrap();
    let (back, _) = read_one(&path);
    assert_eq!(back.get(0, 0), &[0.0, 0.0, 2.0]);
    assert_eq!(back.get(1, 0), &[0.0, 0.0, 0.0]);
    let inf = back.get(2, 0);
    assert!(
        inf[0].is_finite() && inf[0] > 1e38 && inf[1] == 0.0,
        "{inf:?}"
    );
    assert_eq!(back.get(3, 0), &[0.0, 1.0, 0.0]);
    assert!(back.data().iter().all(|v| v.is_finite() && *v >= 0.0));
}

#[test]
fn hdr_reads_the_rgbe_signature_too() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(16, 4, 3);
    let path = dir.path().join("sig.hdr");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let rgbe = [b"#?RGBE".as_slice(), &bytes[b"#?RADIANCE".len()..]].concat();
    let path2 = dir.path().join("sig2.hdr");
    std::fs::write(&path2, rgbe).unwrap();
    let (back, _) = read_one(&path2);
    assert_rgbe_close(&img, &back);
}

#[test]
fn hdr_huge_declared_size_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    for (dims, needle) in [
        ("-Y 100000 +X 100000", "100000×100000"),
        ("-Y 60000 +X 60000", "60000×60000"),
    ] {
        let path = dir.path().join("huge.hdr");
        let text = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n{dims}\n");
        let mut bytes = text.into_bytes();
        bytes.extend_from_slice(&[2, 2, 0x86, 0xa0, 130, 0]);
        std::fs::write(&path, &bytes).unwrap();
        let e = read_err(&path);
        assert_input_error(&e, &path);
        assert!(e.problem().contains(needle), "{e}");
    }
}

#[test]
fn hdr_truncated_garbage_and_missing_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(64, 32, 3);
    let full = dir.path().join("full.hdr");
    write_image(&full, &img, &WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    for (name, cut) in [
        ("half.hdr", bytes.len() / 2),
        ("header.hdr", 20),
        ("dims.hdr", 40),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes[..cut]).unwrap();
        assert_truncated(&read_err(&path), &path);
    }
    let path = dir.path().join("garbage.hdr");
    std::fs::write(
        &path,
        b"GIF89a and more garbage bytes that are not radiance\n".repeat(20),
    )
    .unwrap();
    assert_input_error(&read_err(&path), &path);
    // The right signature, then nonsense.
    std::fs::write(
        &path,
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ten +X 20\n",
    )
    .unwrap();
    assert_input_error(&read_err(&path), &path);
    // Scan lines that overflow their width.
    let mut bad = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 16\n".to_vec();
    bad.extend_from_slice(&[2, 2, 0, 16, 255, 7, 255, 7]);
    std::fs::write(&path, &bad).unwrap();
    assert_input_error(&read_err(&path), &path);

    let path = dir.path().join("missing.hdr");
    assert_input_error(&read_err(&path), &path);
}

// ---------------------------------------------------------------------------------------
// PNG, JPEG, WebP.

/// The sRGB codes of `a` and `b` are within `tol` (in code units of `max`).
fn assert_srgb_close(a: &Image, b: &Image, max: f64, tol: f64) {
    assert_eq!(
        (a.width(), a.height(), a.channels()),
        (b.width(), b.height(), b.channels())
    );
    let c = a.channels();
    for (i, (&x, &y)) in a.data().iter().zip(b.data()).enumerate() {
        let (ex, ey) = if c == 4 && i % 4 == 3 {
            ((x as f64).clamp(0.0, 1.0) * max, y as f64 * max) // alpha is linear
        } else {
            (srgb(x) * max, srgb(y) * max)
        };
        assert!(
            (ex - ey).abs() <= tol,
            "sample {i}: {x} vs {y} ({ex} vs {ey} codes)"
        );
    }
}

#[test]
fn png_8_and_16_bit_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    for c in [3, 4] {
        let img = ldr_image(33, 21, c);
        for (precision, max, label) in [
            (None, 255.0, "8-bit"),
            (Some(Precision::U8), 255.0, "8-bit"),
            (Some(Precision::U16), 65535.0, "16-bit"),
        ] {
            let path = dir.path().join(format!("rt-{c}-{label}.png"));
            write_image(&path, &img, &opts(precision)).unwrap();
            let (back, loaded) = read_one(&path);
            assert_eq!(loaded.format, Format::Png);
            let layout = if c == 4 { "RGBA" } else { "RGB" };
            assert_eq!(loaded.description, format!("PNG, {label} sRGB, {layout}"));
            // Rounded to the nearest code: half a code, plus float slack.
            assert_srgb_close(&img, &back, max, 0.5 + 1e-3);
            // The decoded values are exactly representable: a second round trip is exact.
            write_image(&path, &back, &opts(precision)).unwrap();
            let (again, _) = read_one(&path);
            assert_eq!(again, back);
        }
    }
}

#[test]
fn png_clamps_out_of_range_values() {
    let dir = tempfile::tempdir().unwrap();
    let mut img = Image::new(3, 1, 4);
    img.set(0, 0, &[2.0, -1.0, f32::NAN, 1.5]);
    img.set(1, 0, &[f32::INFINITY, f32::NEG_INFINITY, 1.0, -0.5]);
    img.set(2, 0, &[0.0031308, 0.5, 1e-9, 0.5]);
    let path = dir.path().join("clamp.png");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let (back, _) = read_one(&path);
    assert_eq!(back.get(0, 0), &[1.0, 0.0, 0.0, 1.0]);
    assert_eq!(back.get(1, 0), &[1.0, 0.0, 1.0, 0.0]);
    assert!((back.get(2, 0)[1] - 0.5).abs() < 0.003);
    assert_eq!(back.get(2, 0)[3], 128.0 / 255.0);
}

#[test]
fn png_grey_is_expanded_to_rgb() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grey.png");
    let grey = image::GrayImage::from_fn(4, 3, |x, y| image::Luma([(x * 60 + y) as u8]));
    grey.save(&path).unwrap();
    let (img, loaded) = read_one(&path);
    assert_eq!(loaded.description, "PNG, 8-bit sRGB, grey");
    assert_eq!(img.channels(), 3);
    let v = img.get(3, 2);
    assert_eq!(v[0], v[1]);
    assert_eq!(v[1], v[2]);
    assert!((srgb(v[0]) * 255.0 - 182.0).abs() < 1e-3);
}

#[test]
fn jpeg_round_trip_is_close_and_drops_alpha() {
    let dir = tempfile::tempdir().unwrap();
    // A smooth picture: JPEG's home ground.
    let mut img = Image::new(64, 48, 4);
    for y in 0..48 {
        for x in 0..64 {
            let (u, v) = (x as f32 / 63.0, y as f32 / 47.0);
            img.set(x, y, &[u * u, v * v, 0.5 * u * v, 0.5]);
        }
    }
    for quality in [0, 95] {
        let path = dir.path().join(format!("q{quality}.jpg"));
        let o = WriteOptions {
            jpeg_quality: quality,
            ..WriteOptions::default()
        };
        write_image(&path, &img, &o).unwrap();
        let (back, loaded) = read_one(&path);
        assert_eq!(loaded.format, Format::Jpeg);
        assert_eq!(loaded.description, "JPEG, 8-bit sRGB, RGB");
        assert_eq!(back.channels(), 3);
        let mut err = 0.0;
        for (a, b) in img.data().chunks_exact(4).zip(back.data().chunks_exact(3)) {
            for k in 0..3 {
                err += (srgb(a[k]) - srgb(b[k])).abs();
            }
        }
        let mean = err / (64.0 * 48.0 * 3.0);
        assert!(mean < 0.01, "mean sRGB error {mean}");
    }
}

#[test]
fn webp_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lossless.webp");
    let rgba = image::RgbaImage::from_fn(5, 4, |x, y| {
        image::Rgba([x as u8 * 50, y as u8 * 60, 7, 200])
    });
    let file = std::fs::File::create(&path).unwrap();
    image::codecs::webp::WebPEncoder::new_lossless(file)
        .encode(rgba.as_raw(), 5, 4, image::ExtendedColorType::Rgba8)
        .unwrap();
    let (img, loaded) = read_one(&path);
    assert_eq!(loaded.format, Format::Webp);
    assert_eq!(loaded.description, "WebP, 8-bit sRGB, RGBA");
    let v = img.get(4, 3);
    assert!((srgb(v[0]) * 255.0 - 200.0).abs() < 1e-3 && (srgb(v[1]) * 255.0 - 180.0).abs() < 1e-3);
    assert_eq!(v[3], 200.0 / 255.0);
}

#[test]
fn float_precision_for_png_or_jpeg_is_refused_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let img = ldr_image(8, 8, 3);
    for (name, p) in [
        ("a.png", Precision::Float),
        ("b.png", Precision::Half),
        ("c.jpg", Precision::Float),
        ("d.jpg", Precision::U16),
    ] {
        let path = dir.path().join(name);
        let e = write_err(&path, &img, &opts(Some(p)));
        assert_eq!(e.fault(), Fault::Request, "{e}");
        assert!(e.to_string().contains(name), "{e}");
        assert!(e.problem().contains("8"), "{e}");
    }
    assert_dir_holds(dir.path(), &[]);
}

#[test]
fn failed_writes_leave_no_file_behind() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(8, 8, 3);
    for name in ["x.exr", "x.hdr", "x.png", "x.jpg"] {
        let path = dir.path().join("no-such-dir").join(name);
        let e = write_err(&path, &img, &WriteOptions::default());
        assert!(e.to_string().contains(name), "{e}");
        // A folder that is not there is the system's fault, not the request's or the
        // input's; so is one that is a file.
        assert_eq!(e.fault(), Fault::System, "{e}");
        assert_eq!(e.io_kind(), Some(std::io::ErrorKind::NotFound), "{e}");
        std::fs::write(dir.path().join("a-file"), b"x").unwrap();
        let e = write_err(
            &dir.path().join("a-file").join(name),
            &img,
            &WriteOptions::default(),
        );
        assert_eq!(e.fault(), Fault::System, "{e}");
        std::fs::remove_file(dir.path().join("a-file")).unwrap();
        // An empty image is refused as a request error.
        let path = dir.path().join(name);
        let e = write_err(&path, &Image::new(0, 0, 3), &WriteOptions::default());
        assert_eq!(e.fault(), Fault::Request, "{e}");
    }
    assert_dir_holds(dir.path(), &[]);

    // A failed write keeps the previous file as it was.
    let path = dir.path().join("keep.png");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let before = std::fs::read(&path).unwrap();
    write_err(&path, &img, &opts(Some(Precision::Float)));
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_dir_holds(dir.path(), &["keep.png"]);
}

#[test]
fn a_staged_write_lands_only_when_committed() {
    let dir = tempfile::tempdir().unwrap();
    let img = hdr_image(8, 8, 3);
    let path = dir.path().join("face.exr");
    write_image(&path, &img, &WriteOptions::default()).unwrap();
    let before = std::fs::read(&path).unwrap();
    let other = hdr_image(9, 8, 3);
    for name in ["face.exr", "face.hdr", "face.png"] {
        let target = dir.path().join(name);
        let existed = target.exists();
        let count = || std::fs::read_dir(dir.path()).unwrap().count();
        let before_count = count();
        // Pushed: the whole file is written beside the target, which is untouched.
        let mut set = OutputSet::new(&WriteOptions::default());
        set.push(&target, other.clone()).unwrap();
        assert_eq!(
            count(),
            before_count + 1,
            "a temporary file beside the target"
        );
        assert_eq!(target.exists(), existed);
        if name == "face.exr" {
            assert_eq!(
                std::fs::read(&path).unwrap(),
                before,
                "the old file is untouched"
            );
            // Dropped unfinished: the temporary file goes, the old file stays.
            drop(set);
            assert_dir_holds(dir.path(), &["face.exr"]);
            assert_eq!(std::fs::read(&path).unwrap(), before);
            let mut set = OutputSet::new(&WriteOptions::default());
            set.push(&target, other.clone()).unwrap();
            assert_eq!(set.finish().unwrap(), std::slice::from_ref(&target));
        } else {
            assert_eq!(set.finish().unwrap(), std::slice::from_ref(&target));
        }
        assert_eq!(
            read_one(&target).0.width(),
            9,
            "{name}: the new image is in place"
        );
    }
    assert_dir_holds(dir.path(), &["face.exr", "face.hdr", "face.png"]);
    // A rename that fails (the directory is gone) is an error naming the file, and leaves
    // nothing behind.
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let mut set = OutputSet::new(&WriteOptions::default());
    set.push(&sub.join("x.exr"), img.clone()).unwrap();
    std::fs::remove_dir_all(&sub).unwrap();
    let e = set.finish().unwrap_err();
    assert!(e.to_string().contains("x.exr"), "{e}");
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// A PNG whose IHDR declares `w`×`h` RGB8, with a tiny IDAT and IEND.
fn png_declaring(w: u32, h: u32) -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    png_chunk(&mut png, b"IHDR", &ihdr);
    // An empty stored zlib block: a valid but far too short stream.
    png_chunk(
        &mut png,
        b"IDAT",
        &[
            0x78, 0x01, 0x01, 0x00, 0x00, 0xff, 0xff, 0x00, 0x00, 0x00, 0x01,
        ],
    );
    png_chunk(&mut png, b"IEND", &[]);
    png
}

#[test]
fn png_huge_declared_size_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    // Sanity: the hand-made file is a valid PNG header (a 1×1 one gets past the header).
    let path = dir.path().join("tiny.png");
    std::fs::write(&path, png_declaring(1, 1)).unwrap();
    let e = read_err(&path);
    assert_input_error(&e, &path);
    assert!(!e.problem().contains("declares"), "{e}");

    for (w, h) in [(60000, 60000), (100000, 4)] {
        let path = dir.path().join(format!("huge-{w}.png"));
        std::fs::write(&path, png_declaring(w, h)).unwrap();
        let e = read_err(&path);
        assert_input_error(&e, &path);
        let p = e.problem();
        assert!(
            p.contains("larger than allowed") || p.contains(&format!("{w}×{h}")),
            "{e}"
        );
    }
}

#[test]
fn ldr_truncated_garbage_and_missing_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let img = ldr_image(64, 64, 3);
    for ext in ["png", "jpg"] {
        let full = dir.path().join(format!("full.{ext}"));
        write_image(&full, &img, &WriteOptions::default()).unwrap();
        let bytes = std::fs::read(&full).unwrap();
        for (i, cut) in [bytes.len() / 2, 40, 10].into_iter().enumerate() {
            let path = dir.path().join(format!("cut{i}.{ext}"));
            std::fs::write(&path, &bytes[..cut]).unwrap();
            assert_truncated(&read_err(&path), &path);
        }
        let path = dir.path().join(format!("garbage.{ext}"));
        std::fs::write(
            &path,
            b"not an image, only words and more words\n".repeat(30),
        )
        .unwrap();
        assert_input_error(&read_err(&path), &path);
        let path = dir.path().join(format!("missing.{ext}"));
        assert_input_error(&read_err(&path), &path);
    }
    let path = dir.path().join("garbage.webp");
    std::fs::write(&path, b"RIFF\x10\x00\x00\x00WEBPgarbage garbage").unwrap();
    assert_input_error(&read_err(&path), &path);
}

/// The block reader (R, G, B, A in half or float) gives what the `exr` crate's own image
/// reader gives, for scan lines and tiles, half and float, RGB and RGBA, and sizes that are
/// not multiples of the block size.
#[test]
fn exr_block_reader_matches_the_crates_reader() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let value = |x: usize, y: usize, c: usize| {
        ((x * 7 + y * 13 + c * 5) % 97) as f32 * 0.37 + (y as f32 * 0.01).sin()
    };
    let encodings = [
        ("lines-zip", Encoding::SMALL_LOSSLESS),
        ("lines-none", Encoding::UNCOMPRESSED),
        (
            "tiles-piz",
            Encoding {
                compression: Compression::PIZ,
                blocks: Blocks::Tiles(Vec2(16, 8)),
                line_order: LineOrder::Increasing,
            },
        ),
    ];
    for (name, encoding) in encodings {
        for (half_samples, alpha) in [(false, false), (true, true), (true, false), (false, true)] {
            let path = dir
                .path()
                .join(format!("{name}-{half_samples}-{alpha}.exr"));
            let size = (37, 21);
            let h = |v: f32| f16::from_f32(v);
            let layer_attrs = LayerAttributes::default();
            match (half_samples, alpha) {
                (false, false) => {
                    let ch = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                        (value(x, y, 0), value(x, y, 1), value(x, y, 2))
                    });
                    exr::image::Image::from_layer(Layer::new(size, layer_attrs, encoding, ch))
                        .write()
                        .to_file(&path)
                        .unwrap();
                }
                (true, true) => {
                    let ch = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
                        (
                            h(value(x, y, 0)),
                            h(value(x, y, 1)),
                            h(value(x, y, 2)),
                            h(value(x, y, 3)),
                        )
                    });
                    exr::image::Image::from_layer(Layer::new(size, layer_attrs, encoding, ch))
                        .write()
                        .to_file(&path)
                        .unwrap();
                }
                (true, false) => {
                    let ch = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                        (h(value(x, y, 0)), h(value(x, y, 1)), h(value(x, y, 2)))
                    });
                    exr::image::Image::from_layer(Layer::new(size, layer_attrs, encoding, ch))
                        .write()
                        .to_file(&path)
                        .unwrap();
                }
                (false, true) => {
                    let ch = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
                        (
                            value(x, y, 0),
                            value(x, y, 1),
                            value(x, y, 2),
                            value(x, y, 3),
                        )
                    });
                    exr::image::Image::from_layer(Layer::new(size, layer_attrs, encoding, ch))
                        .write()
                        .to_file(&path)
                        .unwrap();
                }
            }
            let (img, _) = read_one(&path);
            let reference = exr::prelude::read_first_rgba_layer_from_file(
                &path,
                |res, _| (res, vec![[0.0f32; 4]; res.area()]),
                |(res, px): &mut (Vec2<usize>, Vec<[f32; 4]>),
                 p: Vec2<usize>,
                 (r, g, b, a): (f32, f32, f32, f32)| {
                    px[p.y() * res.width() + p.x()] = [r, g, b, a]
                },
            )
            .unwrap();
            let (res, px) = &reference.layer_data.channel_data.pixels;
            assert_eq!(
                (img.width() as usize, img.height() as usize),
                (res.x(), res.y())
            );
            let n = img.channels();
            assert_eq!(n, if alpha { 4 } else { 3 }, "{name}");
            for y in 0..res.y() {
                for x in 0..res.x() {
                    let got = img.get(x as u32, y as u32);
                    assert_eq!(
                        got,
                        &px[y * res.x() + x][..n],
                        "{name} {half_samples} {alpha} at {x},{y}"
                    );
                }
            }
        }
    }
}

#[test]
fn exr_zip_blocks_agree_with_the_exr_crate_both_ways() {
    // mirrorball compresses and inflates ZIP/ZIPS blocks itself (libdeflate); the `exr`
    // crate does both its own way (miniz, zune-inflate). Each reads what the other wrote,
    // texel for texel: half and float, RGB and RGBA, a partial last block, NaN, ±∞,
    // negatives and values past the largest half.
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    for c in [3usize, 4] {
        // Smooth (so that the blocks really are deflated, not stored raw), with specials.
        let mut img = mirrorball_core::Image::new(37, 45, c);
        for y in 0..45 {
            for x in 0..37 {
                let t = (x + 2 * y) as f32;
                img.set(x, y, &[t * 0.25, 1.0 + y as f32, 100.0 - t, 0.5]);
            }
        }
        img.set(1, 0, &[f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.5]);
        img.set(2, 7, &[-3.5, 1e6, -0.0, 1.0]);
        for comp in [ExrCompression::Zip, ExrCompression::Zips] {
            for precision in [Precision::Half, Precision::Float] {
                let tag = format!("{c}-{comp:?}-{precision:?}");
                // Ours → the exr crate's reader.
                let ours = dir.path().join(format!("ours-{tag}.exr"));
                let o = WriteOptions {
                    exr_compression: comp,
                    precision: Some(precision),
                    ..WriteOptions::default()
                };
                write_image(&ours, &img, &o).unwrap();
                let raw_bytes = 37 * 45 * c * if precision == Precision::Half { 2 } else { 4 };
                let file_bytes = std::fs::metadata(&ours).unwrap().len() as usize;
                assert!(
                    file_bytes < raw_bytes / 2,
                    "{tag}: {file_bytes} bytes, deflated"
                );
                let theirs_read = read()
                    .no_deep_data()
                    .largest_resolution_level()
                    .all_channels()
                    .all_layers()
                    .all_attributes()
                    .from_file(&ours)
                    .unwrap();
                let layer = &theirs_read.layer_data[0];
                assert_eq!(
                    layer.encoding.compression,
                    match comp {
                        ExrCompression::Zip => Compression::ZIP16,
                        _ => Compression::ZIP1,
                    }
                );
                let (back, _) = read_one(&ours);
                for ch in &layer.channel_data.list {
                    let k = match ch.name.to_string().as_str() {
                        "R" => 0,
                        "G" => 1,
                        "B" => 2,
                        _ => 3,
                    };
                    let values: Vec<f32> = ch.sample_data.values_as_f32().collect();
                    assert_eq!(values.len(), 37 * 45);
                    for (i, v) in values.iter().enumerate() {
                        // What was written, as half where half was asked for (finite
                        // values clamped to the largest half, as mirrorball writes them;
                        // infinities, which half holds, kept).
                        let a = img.data()[i * c + k];
                        let want = if precision == Precision::Half && a.is_finite() {
                            half(a.clamp(-65504.0, 65504.0))
                        } else {
                            a
                        };
                        let ours_v = back.data()[i * c + k];
                        for got in [*v, ours_v] {
                            assert!(
                                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                                "{tag} channel {k} sample {i}: wrote {want}, exr crate reads {v}, \
                                 mirrorball {ours_v}"
                            );
                        }
                    }
                }
                // The exr crate's writer → ours.
                let theirs = dir.path().join(format!("theirs-{tag}.exr"));
                let st = if precision == Precision::Half {
                    SampleType::F16
                } else {
                    SampleType::F32
                };
                let desc = |n: &str| ChannelDescription::named(n, st);
                let w = img.width() as usize;
                let data = back.data().to_vec();
                let texel = move |p: Vec2<usize>, k: usize| data[(p.y() * w + p.x()) * c + k];
                let enc = Encoding {
                    compression: match comp {
                        ExrCompression::Zip => Compression::ZIP16,
                        _ => Compression::ZIP1,
                    },
                    ..Encoding::default()
                };
                let size = (img.width() as usize, img.height() as usize);
                if c == 4 {
                    let px = SpecificChannels {
                        channels: (desc("R"), desc("G"), desc("B"), desc("A")),
                        pixels: move |p: Vec2<usize>| {
                            (texel(p, 0), texel(p, 1), texel(p, 2), texel(p, 3))
                        },
                    };
                    let layer = Layer::new(size, LayerAttributes::default(), enc, px);
                    exr::image::Image::from_layer(layer)
                        .write()
                        .to_file(&theirs)
                        .unwrap();
                } else {
                    let px = SpecificChannels {
                        channels: (desc("R"), desc("G"), desc("B")),
                        pixels: move |p: Vec2<usize>| (texel(p, 0), texel(p, 1), texel(p, 2)),
                    };
                    let layer = Layer::new(size, LayerAttributes::default(), enc, px);
                    exr::image::Image::from_layer(layer)
                        .write()
                        .to_file(&theirs)
                        .unwrap();
                }
                let (again, _) = read_one(&theirs);
                for (i, (a, b)) in back.data().iter().zip(again.data()).enumerate() {
                    assert!(
                        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                        "{tag} sample {i}: {a} written by the exr crate, read back as {b}"
                    );
                }
            }
        }
    }
}

/// `read_codes` gives a PNG's or JPEG's samples as the file holds them: through io's sRGB
/// tables they are `read`'s floats, bit for bit (8-bit JPEG and PNG, 16-bit PNG, with a
/// JPEG's recorded projection); grey and alpha pictures are left to `read`.
#[test]
fn read_codes_are_read_s_floats() {
    use mirrorball_io::{read, read_codes, srgb16_to_linear, srgb8_to_linear, Precision};
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (37, 19);
    let mut img = Image::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            let k = (x * 5 + y * 11) as f32;
            img.set(x, y, &[(k * 0.3).sin().abs(), (k * 0.07).cos().abs(), 0.25]);
        }
    }
    let mut buf = vec![7u8; 3]; // reused: resized to the picture
    for (name, precision) in [
        ("a.png", Precision::U8),
        ("b.png", Precision::U16),
        ("c.jpg", Precision::U8),
    ] {
        let path = dir.path().join(name);
        let opts = WriteOptions {
            precision: Some(precision),
            declared: Some(MapInfo {
                projection: ProjectionKind::LatLong.default_projection(),
                layout: None,
                stereo: Default::default(),
            }),
            ..Default::default()
        };
        write_image(&path, &img, &opts).unwrap();
        let floats = read(&path, &Limits::default()).unwrap();
        let coded = read_codes(&path, &Limits::default(), &mut buf)
            .unwrap()
            .unwrap();
        assert_eq!((coded.width, coded.height), (w, h), "{name}");
        assert_eq!(coded.wide, precision == Precision::U16, "{name}");
        assert_eq!(coded.description, floats.description, "{name}");
        assert_eq!(
            coded.recorded.unwrap().unwrap().projection,
            floats.recorded.unwrap().unwrap().projection
        );
        let decoded: Vec<f32> = if coded.wide {
            buf.chunks_exact(2)
                .map(|b| srgb16_to_linear()[u16::from_le_bytes([b[0], b[1]]) as usize])
                .collect()
        } else {
            buf.iter().map(|&k| srgb8_to_linear()[k as usize]).collect()
        };
        assert!(decoded == floats.layers[0].data(), "{name}");
    }
    // A grey PNG and one with alpha: not codes of RGB, left to `read`.
    let grey = dir.path().join("grey.png");
    mirrorball_io::write_grey_png(&grey, (4, 2), &[9; 8]).unwrap();
    assert!(read_codes(&grey, &Limits::default(), &mut buf)
        .unwrap()
        .is_none());
    let missing = read_codes(&dir.path().join("none.jpg"), &Limits::default(), &mut buf);
    assert!(missing.is_err());
}
