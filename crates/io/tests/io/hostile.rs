//! Hostile files: the seed corpus (`tests/corpus/<format>/`, small files the tool wrote)
//! mutated many ways (cut at every few bytes, bits flipped, size fields set to 2³¹, 2³²−1
//! and 2⁴⁰), every result read back. Each read must end in a clear input error naming the
//! file or a valid image, quickly; a panic inside a decoder would be caught and reported
//! as an error by the reader, so those are counted and must be none. Files under
//! `tests/corpus/<format>/crashes/` are reproducers of past failures, replayed as they are.
//! The bolero targets (`fuzz_*`) mutate the same seeds from a fuzzer's input, and run as
//! ordinary tests on stable (see `docs/fuzzing.md`).

use crate::mutate::{apply_script, mutations};
use mirrorball_io::{read, Fault, Limits, Loaded};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The corpus folder.
pub fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// The files directly in `dir`, sorted (none if it does not exist).
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file())
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    files
}

/// The seeds of one format's folder.
fn seeds(format: &str) -> Vec<PathBuf> {
    files_in(&corpus().join(format))
}

/// How one read ended.
#[derive(Default, Debug)]
pub struct Tally {
    pub files: usize,
    pub valid: usize,
    pub errors: usize,
    /// Errors that came from a panic the reader caught.
    pub caught_panics: Vec<String>,
    pub slowest: Duration,
}

/// Reads `path` and checks the result: an input error whose message starts with the file's
/// name, or layers of a sane size with all their texels.
pub fn check_read(path: &Path, limits: &Limits, tally: &mut Tally) {
    let start = Instant::now();
    let result = read(path, limits);
    let took = start.elapsed();
    tally.slowest = tally.slowest.max(took);
    tally.files += 1;
    match result {
        Err(e) => {
            tally.errors += 1;
            assert_eq!(e.path(), path, "{e}");
            assert_eq!(e.fault(), Fault::Input, "{e}");
            assert!(
                e.to_string().starts_with(&path.display().to_string()) && !e.problem().is_empty(),
                "{e}"
            );
            if e.problem().contains("decoder failed") {
                // Tagged with the compression the file declares (a mutation can turn a
                // DWAB seed into a B44 file), for the known-panic rule of `assert_tally`.
                let b44 = if declares_b44(path) {
                    " [declares b44]"
                } else {
                    ""
                };
                tally.caught_panics.push(format!("{e}{b44}"));
            }
        }
        Ok(loaded) => {
            tally.valid += 1;
            check_loaded(path, &loaded, limits);
        }
    }
}

fn check_loaded(path: &Path, loaded: &Loaded, limits: &Limits) {
    assert!(!loaded.layers.is_empty(), "{}: no layers", path.display());
    for l in &loaded.layers {
        let texels = l.width() as u64 * l.height() as u64;
        assert!(
            texels >= 1 && texels <= limits.max_texels,
            "{}",
            path.display()
        );
        assert_eq!(
            l.data().len() as u64,
            texels * l.channels() as u64,
            "{}",
            path.display()
        );
    }
}

/// Every seed of `format` (which must read), every crash reproducer, and every mutation of
/// each seed, read back from `dir`.
fn replay_format(format: &str, dir: &Path) -> Tally {
    let limits = Limits::default();
    let mut tally = Tally::default();
    let found = seeds(format);
    assert!(
        !found.is_empty(),
        "no seeds in {}",
        corpus().join(format).display()
    );
    for crash in files_in(&corpus().join(format).join("crashes")) {
        check_read(&crash, &limits, &mut tally);
    }
    for (k, seed) in found.iter().enumerate() {
        let bytes = std::fs::read(seed).unwrap();
        let loaded = read(seed, &limits).unwrap_or_else(|e| panic!("seed {e}"));
        check_loaded(seed, &loaded, &limits);
        let name = seed.file_name().unwrap().to_string_lossy().into_owned();
        let mut all = mutations(&bytes, k as u64);
        if format == "png" {
            // Most mutations fail the chunks' CRCs: each again with the CRCs made right, so
            // the decoder itself sees them.
            let fixed: Vec<Vec<u8>> = all.iter().cloned().map(with_png_crcs).collect();
            all.extend(fixed);
        }
        for (i, m) in all.into_iter().enumerate() {
            let path = dir.join(format!("m{i}-{name}"));
            std::fs::write(&path, &m).unwrap();
            check_read(&path, &limits, &mut tally);
            std::fs::remove_file(&path).unwrap();
        }
    }
    tally
}

/// Whether `path` is an OpenEXR file whose first header declares B44 or B44A compression.
fn declares_b44(path: &Path) -> bool {
    use exr::meta::attribute::Compression;
    exr::meta::MetaData::read_from_file(path, false)
        .ok()
        .and_then(|m| m.headers.first().map(|h| h.compression))
        .is_some_and(|c| matches!(c, Compression::B44 | Compression::B44A))
}

fn assert_tally(format: &str, t: &Tally) {
    eprintln!(
        "{format}: {} files, {} valid, {} errors, slowest {:?}",
        t.files, t.valid, t.errors, t.slowest
    );
    // The `exr` crate's B44 decoder (`unpack14`) subtracts its bias from unsigned values
    // and relies on wrapping, as OpenEXR's C code does; with overflow checks on (test and
    // debug builds) a corrupt B44 block makes that a panic, which the reader catches and
    // reports. Release builds wrap and decode garbage texels, as the reference does.
    let known = |e: &String| cfg!(debug_assertions) && e.contains("b44");
    let unknown: Vec<&String> = t.caught_panics.iter().filter(|e| !known(e)).collect();
    assert!(
        unknown.is_empty(),
        "{format}: decoders panicked: {unknown:#?}"
    );
    assert!(
        t.slowest < Duration::from_secs(5),
        "{format}: a read took {:?}",
        t.slowest
    );
}

macro_rules! hostile_test {
    ($name:ident, $format:literal) => {
        #[test]
        fn $name() {
            let dir = tempfile::tempdir().unwrap();
            let t = replay_format($format, dir.path());
            assert_tally($format, &t);
            assert!(t.errors > 0, "mutations should be refused");
            // Nothing left behind by the reads.
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        }
    };
}

hostile_test!(hostile_exr, "exr");
hostile_test!(hostile_hdr, "hdr");
hostile_test!(hostile_png, "png");
hostile_test!(hostile_jpeg, "jpeg");
hostile_test!(hostile_webp, "webp");
hostile_test!(hostile_ktx2, "ktx2");
hostile_test!(hostile_dds, "dds");

// ---------------------------------------------------------------------------------------
// Fuzz targets: a seed picked and changed by the fuzzer's bytes ([`apply_script`]).

fn fuzz_format(format: &str) {
    let found = seeds(format);
    let seeds: Vec<(PathBuf, Vec<u8>)> = found
        .iter()
        .map(|p| (p.clone(), std::fs::read(p).unwrap()))
        .collect();
    // The inputs go to a fresh folder, or to $MIRRORBALL_FUZZ_KEEP, where the one that
    // failed is left (to be saved under `crashes/`).
    let dir = tempfile::tempdir().unwrap();
    let keep = std::env::var_os("MIRRORBALL_FUZZ_KEEP").map(PathBuf::from);
    let out = keep.unwrap_or_else(|| dir.path().to_path_buf());
    let limits = Limits::default();
    bolero::check!()
        .with_iterations(200)
        .for_each(|input: &[u8]| {
            let Some((&pick, script)) = input.split_first() else {
                return;
            };
            let (seed_path, seed) = &seeds[pick as usize % seeds.len()];
            let ext = seed_path.extension().unwrap().to_str().unwrap();
            let name = seed_path.file_stem().unwrap().to_str().unwrap();
            let path = out.join(format!("fuzz-{name}.{ext}"));
            let mut bytes = apply_script(seed, script);
            // PNG: half the inputs with their chunks' CRCs made right (see `replay_format`).
            if ext == "png" && pick & 0x80 != 0 {
                bytes = with_png_crcs(bytes);
            }
            std::fs::write(&path, bytes).unwrap();
            let mut tally = Tally::default();
            check_read(&path, &limits, &mut tally);
            let known = |e: &String| cfg!(debug_assertions) && e.contains("b44");
            assert!(
                tally.caught_panics.iter().all(known),
                "{:?}",
                tally.caught_panics
            );
        });
}

#[test]
fn fuzz_exr() {
    fuzz_format("exr");
}
#[test]
fn fuzz_hdr() {
    fuzz_format("hdr");
}
#[test]
fn fuzz_png() {
    fuzz_format("png");
}
#[test]
fn fuzz_jpeg() {
    fuzz_format("jpeg");
}
#[test]
fn fuzz_webp() {
    fuzz_format("webp");
}
#[test]
fn fuzz_ktx2() {
    fuzz_format("ktx2");
}
#[test]
fn fuzz_dds() {
    fuzz_format("dds");
}

// ---------------------------------------------------------------------------------------
// Declared sizes the file cannot hold.

/// A DWAA file of 64×32 smooth half RGB texels in one block, written by the `exr` crate,
/// and where that block's DWA counters start.
fn dwaa_file() -> (Vec<u8>, usize) {
    use exr::prelude::*;
    let (w, h) = (64usize, 32usize);
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let (x, y) = (p.x() as f32, p.y() as f32);
        (
            f16::from_f32(x / 64.0),
            f16::from_f32(y / 32.0),
            f16::from_f32(0.5),
        )
    });
    let encoding = Encoding {
        compression: Compression::DWAA(None),
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(Vec2(w, h), LayerAttributes::default(), encoding, channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .unwrap();
    let bytes = bytes.into_inner();
    // One block: the offset table's one entry points just past itself, to the block's y
    // and byte count, then its data.
    let table = (0..bytes.len() - 8)
        .find(|&p| u64::from_le_bytes(bytes[p..p + 8].try_into().unwrap()) == p as u64 + 8)
        .expect("offset table");
    let size = i32::from_le_bytes(bytes[table + 12..table + 16].try_into().unwrap()) as usize;
    assert_eq!(
        table + 16 + size,
        bytes.len(),
        "one block, last in the file"
    );
    assert!(
        size < w * h * 6,
        "the block is DWA-compressed, not stored raw"
    );
    (bytes, table + 16)
}

/// Found by the coverage-guided campaign: a 76-byte lossless WebP declaring 15120×14342
/// texels (a valid header; VP8L can code a picture in zero bits a texel) made the decoder
/// take 2.2 GB. WebP is held to a plausible density (`ldr_io::check_fits_file`).
#[test]
fn a_tiny_webp_declaring_a_huge_picture_is_refused_before_decoding() {
    let path = corpus().join("webp/crashes/vp8l-15120x14342-in-76-bytes.webp");
    let start = Instant::now();
    let e = read(&path, &Limits::default()).expect_err("refused");
    assert!(
        start.elapsed() < Duration::from_millis(200),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(e.fault(), Fault::Input, "{e}");
    assert!(
        e.to_string().contains("15120×14342") && e.to_string().contains("texels a byte"),
        "{e}"
    );
    // The seed, a real picture, still reads.
    read(&corpus().join("webp/lossless.webp"), &Limits::default()).unwrap();
}

#[test]
fn dwa_counters_beyond_the_block_are_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let (bytes, counters) = dwaa_file();
    let good = dir.path().join("good.exr");
    std::fs::write(&good, &bytes).unwrap();
    let loaded = read(&good, &Limits::default()).unwrap();
    assert!(
        loaded.description.contains("DWAA"),
        "{}",
        loaded.description
    );
    // totalAcUncompressedCount (counter 8), totalDcUncompressedCount (9),
    // unknownUncompressedSize (1), rleRawSize (7).
    for (index, name) in [
        (8, "totalAcUncompressedCount"),
        (9, "totalDcUncompressedCount"),
        (1, "unknownUncompressedSize"),
        (7, "rleRawSize"),
    ] {
        let mut m = bytes.clone();
        let at = counters + 8 * index;
        m[at..at + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
        let path = dir.path().join(format!("dwa-{index}.exr"));
        std::fs::write(&path, &m).unwrap();
        let start = Instant::now();
        let e = read(&path, &Limits::default()).expect_err("refused");
        assert!(start.elapsed() < Duration::from_secs(2));
        assert_eq!(e.fault(), Fault::Input);
        let text = e.to_string();
        assert!(text.starts_with(&path.display().to_string()), "{text}");
        assert!(
            text.contains(name) && text.contains("1099511627776"),
            "{text}"
        );
    }
}

/// CRC-32 (ISO-HDLC), for patching PNG chunks.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// `png` with each whole chunk's CRC recomputed (chunks walked from the signature by
/// their lengths; a chunk running past the end, and what follows, left as is).
fn with_png_crcs(mut png: Vec<u8>) -> Vec<u8> {
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        let Some(end) = (at + 8).checked_add(len).filter(|&e| e + 4 <= png.len()) else {
            break;
        };
        let crc = crc32(&png[at + 4..end]);
        png[end..end + 4].copy_from_slice(&crc.to_be_bytes());
        at = end + 4;
    }
    png
}

#[test]
fn a_small_file_declaring_a_large_image_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let limits = Limits::default();
    // A PNG seed with its IHDR saying 16384×16384 (within the limits), CRC fixed.
    let seed = std::fs::read(corpus().join("png/rgb8.png")).unwrap();
    let mut png = seed.clone();
    png[16..20].copy_from_slice(&16384u32.to_be_bytes());
    png[20..24].copy_from_slice(&16384u32.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    let path = dir.path().join("big.png");
    std::fs::write(&path, &png).unwrap();
    let e = read(&path, &limits).expect_err("refused");
    assert!(
        e.problem().contains("16384×16384")
            && e.problem().contains(&format!("{} bytes", png.len())),
        "{e}"
    );
    // The same header on a file long enough for it passes this check (and then fails on
    // the missing data, as a truncated file).
    let mut long = png.clone();
    long.resize(300_000, 0);
    let path = dir.path().join("long.png");
    std::fs::write(&path, &long).unwrap();
    let e = read(&path, &limits).expect_err("no image data");
    assert!(!e.problem().contains("holds at most"), "{e}");

    // A Radiance header declaring more scan lines than a short file has room for.
    let path = dir.path().join("tall.hdr");
    std::fs::write(
        &path,
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 16\n\x01\x02\x03\x04",
    )
    .unwrap();
    let e = read(&path, &limits).expect_err("refused");
    assert!(e.problem().contains("60000 scan lines"), "{e}");
    // Room for its 100 lines, not for 65536 texels in each.
    let mut wide = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100 +X 65536\n".to_vec();
    wide.resize(400, 1);
    let path = dir.path().join("wide.hdr");
    std::fs::write(&path, &wide).unwrap();
    let e = read(&path, &limits).expect_err("refused");
    assert!(
        e.problem().contains("65536×100") && e.problem().contains("400 bytes"),
        "{e}"
    );

    // An uncompressed EXR seed whose data window says 8192×8192.
    let seed = std::fs::read(corpus().join("exr/none.exr")).unwrap();
    let mut exr = seed.clone();
    let key = b"dataWindow\0box2i\0";
    let at = exr.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    exr[at + 8..at + 12].copy_from_slice(&8191i32.to_le_bytes());
    exr[at + 12..at + 16].copy_from_slice(&8191i32.to_le_bytes());
    // One line a block: the chunk count the header gives must agree.
    let key = b"chunkCount\0int\0";
    let at = exr.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    exr[at..at + 4].copy_from_slice(&8192i32.to_le_bytes());
    let path = dir.path().join("wide.exr");
    std::fs::write(&path, &exr).unwrap();
    let e = read(&path, &limits).expect_err("refused");
    assert!(e.problem().contains("bytes of samples"), "{e}");
}

// ---------------------------------------------------------------------------------------
// The seed corpus, as the tool writes it: `cargo test -p mirrorball-io --test io --
// --ignored make_seed_corpus` rewrites it (then check the files in).

#[test]
#[ignore]
fn make_seed_corpus() {
    use mirrorball_core::Image;
    use mirrorball_io::{write_cube, write_image, ExrCompression, Precision, WriteOptions};
    let root = corpus();
    let img = |w: u32, h: u32, c: usize| {
        let mut i = Image::new(w, h, c);
        for y in 0..h {
            for x in 0..w {
                let v = [
                    x as f32 / w as f32 * 4.0,
                    y as f32 / h as f32,
                    ((x * 7 + y * 3) % 11) as f32 / 11.0,
                    0.75,
                ];
                i.set(x, y, &v[..c]);
            }
        }
        i
    };
    let dir = |f: &str| {
        let d = root.join(f);
        std::fs::create_dir_all(&d).unwrap();
        d
    };
    let exr = dir("exr");
    for (c, name) in [
        (ExrCompression::None, "none"),
        (ExrCompression::Rle, "rle"),
        (ExrCompression::Zips, "zips"),
        (ExrCompression::Zip, "zip"),
        (ExrCompression::Piz, "piz"),
        (ExrCompression::Pxr24, "pxr24"),
    ] {
        let opts = WriteOptions {
            exr_compression: c,
            ..WriteOptions::default()
        };
        write_image(&exr.join(format!("{name}.exr")), &img(16, 8, 3), &opts).unwrap();
    }
    let float = WriteOptions {
        precision: Some(Precision::Float),
        ..WriteOptions::default()
    };
    write_image(&exr.join("zip-float-rgba.exr"), &img(8, 8, 4), &float).unwrap();
    {
        use exr::prelude::*;
        let write =
            |name: &str, compression: Compression, blocks: Blocks, (w, h): (usize, usize)| {
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    (
                        f16::from_f32(p.x() as f32 / w as f32),
                        f16::from_f32(p.y() as f32 / h as f32),
                        f16::from_f32(0.5),
                    )
                });
                let encoding = Encoding {
                    compression,
                    blocks,
                    line_order: LineOrder::Increasing,
                };
                let layer = Layer::new(Vec2(w, h), LayerAttributes::default(), encoding, channels);
                Image::from_layer(layer)
                    .write()
                    .to_file(exr.join(name))
                    .unwrap();
            };
        write("b44.exr", Compression::B44, Blocks::ScanLines, (16, 8));
        write("b44a.exr", Compression::B44A, Blocks::ScanLines, (16, 8));
        write(
            "dwaa.exr",
            Compression::DWAA(None),
            Blocks::ScanLines,
            (64, 32),
        );
        write(
            "dwab.exr",
            Compression::DWAB(None),
            Blocks::ScanLines,
            (32, 16),
        );
        let tiles = Blocks::Tiles(Vec2(8, 8));
        write("tiled-zip.exr", Compression::ZIP16, tiles, (16, 16));
    }
    write_image(
        &dir("hdr").join("rle.hdr"),
        &img(16, 8, 3),
        &WriteOptions::default(),
    )
    .unwrap();
    let png = dir("png");
    write_image(
        &png.join("rgb8.png"),
        &img(16, 8, 3),
        &WriteOptions::default(),
    )
    .unwrap();
    let u16 = WriteOptions {
        precision: Some(Precision::U16),
        ..WriteOptions::default()
    };
    write_image(&png.join("rgba16.png"), &img(8, 8, 4), &u16).unwrap();
    write_image(
        &dir("jpeg").join("rgb.jpg"),
        &img(16, 16, 3),
        &WriteOptions::default(),
    )
    .unwrap();
    {
        let mut bytes = Vec::new();
        let rgb: Vec<u8> = (0..16 * 8 * 3).map(|i| (i * 7 % 256) as u8).collect();
        image::codecs::webp::WebPEncoder::new_lossless(&mut bytes)
            .encode(&rgb, 16, 8, image::ExtendedColorType::Rgb8)
            .unwrap();
        std::fs::write(dir("webp").join("lossless.webp"), bytes).unwrap();
    }
    let cube = |size: u32| -> Vec<Vec<Image>> {
        let mut levels = Vec::new();
        let mut s = size;
        loop {
            levels.push((0..6).map(|_| img(s, s, 4)).collect());
            if s == 1 {
                break levels;
            }
            s /= 2;
        }
    };
    write_cube(
        &dir("ktx2").join("half.ktx2"),
        &cube(4),
        &WriteOptions::default(),
    )
    .unwrap();
    write_cube(&dir("ktx2").join("float.ktx2"), &cube(2), &float).unwrap();
    write_cube(
        &dir("dds").join("half.dds"),
        &cube(4),
        &WriteOptions::default(),
    )
    .unwrap();
    write_cube(&dir("dds").join("float.dds"), &cube(2), &float).unwrap();
}
