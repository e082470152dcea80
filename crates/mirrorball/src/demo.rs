//! The demo (`mirrorball demo`): the bundled HDR environment in every projection, with
//! previews and the round-trip quality of each, in a folder a person can open
//! (`index.html`).

use crate::error::Error;
use crate::hooks::Hooks;
use crate::load;
use crate::save::{self, SaveOptions};
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::EnvMap;
use mirrorball_core::{resample, Image, Layout, ProjectionKind, ResampleOptions, WorldProjection};
use mirrorball_io::{Precision, WriteOptions};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

/// Poly Haven's "city" environment (CC0), 512×256 half-float lat-long, bundled.
const CITY_EXR: &[u8] = include_bytes!("../../../assets/env/city.exr");

/// Edge of one contact-sheet cell, in pixels.
const SHEET_CELL: u32 = 240;

/// `img` scaled (box filter) to fit a `cell`×`cell` square, keeping its aspect ratio.
fn fit(img: &Image, cell: u32) -> Image {
    let k = (cell as f64 / img.width() as f64).min(cell as f64 / img.height() as f64);
    let (w, h) = (
        ((img.width() as f64 * k) as u32).max(1),
        ((img.height() as f64 * k) as u32).max(1),
    );
    let c = img.channels();
    let mut out = Image::new(w, h, c);
    for y in 0..h {
        let (y0, y1) = (
            (y as f64 / k) as u32,
            (((y + 1) as f64 / k) as u32).clamp(1, img.height()),
        );
        for x in 0..w {
            let (x0, x1) = (
                (x as f64 / k) as u32,
                (((x + 1) as f64 / k) as u32).clamp(1, img.width()),
            );
            let mut acc = [0.0f32; 4];
            let mut n = 0.0;
            for sy in y0..y1.max(y0 + 1) {
                for sx in x0..x1.max(x0 + 1) {
                    for (a, v) in acc
                        .iter_mut()
                        .zip(img.get(sx.min(img.width() - 1), sy.min(img.height() - 1)))
                    {
                        *a += v;
                    }
                    n += 1.0;
                }
            }
            let px: Vec<f32> = acc[..c].iter().map(|a| a / n).collect();
            out.set(x, y, &px);
        }
    }
    out
}

/// The edge each projection gets for a lat-long of width `size`: about equal texel budgets.
fn edge(kind: ProjectionKind, size: u32) -> u32 {
    match kind {
        ProjectionKind::LatLong | ProjectionKind::Mercator => size,
        ProjectionKind::Cube | ProjectionKind::ContinuousCube => (size / 4).max(1),
        _ => (size / 2).max(1),
    }
}

/// The demo's sizes: at least 8 (the smallest maps stay maps), at most what every file it
/// writes holds and mirrorball reads back (each projection's EXR, the cube's KTX2 and DDS).
fn size_bound() -> crate::size::Bound {
    let smallest = crate::size::Bound {
        min: 8,
        max: u32::MAX,
        why: String::new(),
    };
    ProjectionKind::ALL.iter().fold(smallest, |b, &kind| {
        let p = kind.default_projection();
        let layout = mirrorball_core::Layout::default_for(kind);
        let picture = |s: u32| {
            let (w, h) = p.layer_extent(edge(kind, s));
            let (pw, ph) = layout.extent(p.layer_count(), w, h);
            (pw as u64, ph as u64)
        };
        let name = format!("{}.exr", kind.name());
        let b = b.and(crate::size::pictures(
            mirrorball_io::Format::Exr,
            &name,
            picture,
        ));
        match kind {
            ProjectionKind::Cube => b.and(crate::size::pictures(
                mirrorball_io::Format::Ktx2,
                "cube.ktx2's face",
                |s| (edge(kind, s) as u64, edge(kind, s) as u64),
            )),
            _ => b,
        }
    })
}

/// About how many bytes the demo writes at `size`: every projection as a half-float EXR
/// and an 8-bit PNG, uncompressed, the cube twice more with its mips as RGBA16F (KTX2 and
/// DDS), the source and the sheet.
fn output_bytes(size: u32) -> u64 {
    let texels = |p: mirrorball_core::Projection, s: u32| {
        let (w, h) = p.layer_extent(s);
        w as u64 * h as u64 * p.layer_count() as u64
    };
    let maps: u64 = ProjectionKind::ALL
        .iter()
        .map(|&k| texels(k.default_projection(), edge(k, size)) * (6 + 3))
        .sum();
    let cube = ProjectionKind::Cube.default_projection();
    let chains = 2 * texels(cube, edge(ProjectionKind::Cube, size)) * 8 * 4 / 3;
    maps + chains + CITY_EXR.len() as u64 + 5 * SHEET_CELL as u64 * SHEET_CELL as u64 * 4 * 3
}

/// What the demo makes: its folder, the lat-long width of the largest outputs (others
/// scale to match) and the previews' exposure in stops.
#[derive(Clone, Debug)]
pub struct DemoRequest {
    pub out: String,
    pub size: i64,
    pub exposure: f32,
}

impl Default for DemoRequest {
    fn default() -> DemoRequest {
        DemoRequest {
            out: "mirrorball-demo".into(),
            size: 1024,
            exposure: 0.0,
        }
    }
}

/// One projection's line of the report: its name, layout, layer extent and count, the
/// conversion's seconds, the round trip's log-PSNR and the share of the sphere it covers.
type Row = (&'static str, Layout, u32, u32, usize, f64, f64, f64);

/// Makes the demo's folder as `a` asks, saying what it does through `hooks`.
pub fn run(a: &DemoRequest, hooks: &dyn Hooks) -> Result<(), Error> {
    let size = size_bound().check("--size", a.size)?;
    let dir = Path::new(&a.out);
    let mut files = crate::guard::Files::new();
    files
        .making(mirrorball_io::Folders::MakeAll)
        .output("--out", dir.join("index.html"));
    files.check()?;
    files.room(output_bytes(size))?;
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::system(format!("{}: cannot create the folder: {e}", dir.display())))?;
    let src_path = dir.join("source-city.exr");
    std::fs::write(&src_path, CITY_EXR)
        .map_err(|e| Error::system(format!("{}: {e}", src_path.display())))?;
    let t0 = Instant::now();
    let src_str = src_path.display().to_string();
    let mut src = load::load(&src_str, None, None, &mirrorball_io::Limits::default())?;
    src.env.sanitize();
    let src = src.env;
    hooks.note(&format!(
        "source: {src_str} (lat-long {}x{}); writing every projection to {}",
        src.width(),
        src.height(),
        dir.display()
    ));
    let mut rows = Vec::new();
    let mut sheet_cells: Vec<Image> = Vec::new();
    let mut result: Result<(), Error> = Ok(());
    hooks.progress("demo", ProjectionKind::ALL.len() as u64, &mut |done| {
        result = ProjectionKind::ALL.iter().try_for_each(|&kind| {
            let (row, cell) = every_projection(&src, kind, (dir, size, a.exposure))?;
            rows.push(row);
            sheet_cells.extend(cell);
            done.fetch_add(1, Ordering::Relaxed);
            Ok(())
        });
    });
    result?;
    write_sheet(&dir.join("sheet.png"), &sheet_cells)?;
    let index = write_report(dir, &rows, hooks)?;
    hooks.note(&format!(
        "done in {:.1}s: open {}",
        t0.elapsed().as_secs_f64(),
        index.display()
    ));
    Ok(())
}

/// The 8-bit previews' write options.
fn preview() -> WriteOptions {
    WriteOptions {
        precision: Some(Precision::U8),
        ..Default::default()
    }
}

/// `src` in `kind`'s projection at the demo's `size` (as [`edge`] scales it), written into
/// `dir` as an EXR and a PNG preview (exposed by `exposure` stops; the cube also as KTX2
/// and DDS with mips), and converted back to measure the round trip: the report's row, and
/// the contact sheet's cell.
fn every_projection(
    src: &EnvMap,
    kind: ProjectionKind,
    (dir, size, exposure): (&Path, u32, f32),
) -> Result<(Row, Option<Image>), Error> {
    let exr = WriteOptions::default();
    let opts = ResampleOptions::default();
    let proj = kind.default_projection();
    let size = edge(kind, size);
    let t = Instant::now();
    let out = resample(src, proj, size, &opts);
    let secs = t.elapsed().as_secs_f64();
    let name = kind.name();
    let layout = Layout::default_for(proj.kind());
    let save_opts = |w: WriteOptions| SaveOptions {
        layout: Some(layout),
        write: w,
        mips: false,
        keep_invalid: false,
    };
    let path = |ext: &str| dir.join(format!("{name}.{ext}")).display().to_string();
    save::save(&out, &path("exr"), &save_opts(exr))?;
    let shown = match exposure {
        0.0 => out.clone(),
        e => {
            let bright = ResampleOptions {
                exposure: e,
                ..Default::default()
            };
            resample(src, proj, size, &bright)
        }
    };
    save::save(&shown, &path("png"), &save_opts(preview()))?;
    let cell = layout.pack(&shown).map(|packed| fit(&packed, SHEET_CELL));
    if kind == ProjectionKind::Cube {
        let m = SaveOptions {
            layout: None,
            write: exr,
            mips: true,
            keep_invalid: false,
        };
        save::save(&out, &dir.join("cube.ktx2").display().to_string(), &m)?;
        save::save(&out, &dir.join("cube.dds").display().to_string(), &m)?;
    }
    // Round trip back to the source's projection and size.
    let back = resample(&out, *src.projection(), src.width(), &opts);
    let covered = proj.covered_solid_angle() / (4.0 * std::f64::consts::PI);
    let psnr = log_psnr_where(src, &back, |d| proj.dir_to_uv(d).is_some()).unwrap_or(f64::NAN);
    let (w, h) = (out.width(), out.height());
    let row = (name, layout, w, h, out.layers().len(), secs, psnr, covered);
    Ok((row, cell))
}

/// A contact sheet of every projection, in the order of the table, five to a row.
fn write_sheet(path: &Path, cells: &[Image]) -> Result<(), Error> {
    let cols = 5u32;
    let rows_n = (cells.len() as u32).div_ceil(cols);
    let mut sheet = Image::new(cols * SHEET_CELL, rows_n * SHEET_CELL, 3);
    for (i, cell) in cells.iter().enumerate() {
        let (cx, cy) = (
            (i as u32 % cols) * SHEET_CELL,
            (i as u32 / cols) * SHEET_CELL,
        );
        let (ox, oy) = (
            (SHEET_CELL - cell.width()) / 2,
            (SHEET_CELL - cell.height()) / 2,
        );
        sheet.paste(&cell.with_channels(3), cx + ox, cy + oy);
    }
    mirrorball_io::write_image(path, &sheet, &preview())?;
    Ok(())
}

/// `index.html` and `summary.txt` in `dir`, the table also said through `hooks`; the
/// index's path.
fn write_report(dir: &Path, rows: &[Row], hooks: &dyn Hooks) -> Result<PathBuf, Error> {
    let mut table = String::new();
    let mut html = String::from(
        "<!doctype html><meta charset=utf-8><title>mirrorball demo</title>\
         <style>body{font:14px sans-serif;background:#222;color:#ddd;margin:2em}\
         figure{display:inline-block;margin:1em;vertical-align:top}img{max-width:512px;max-height:384px;background:#000}\
         td,th{padding:2px 10px;text-align:right}</style>\
         <h1>mirrorball demo</h1><p>The bundled <code>city</code> environment (Poly Haven, CC0) in every world projection. \
         PNGs are previews (clamped, sRGB); the EXR files beside them hold the linear values.</p>\
         <table><tr><th>projection</th><th>layout</th><th>layers × size</th><th>covers</th><th>convert (s)</th><th>round-trip log-PSNR (dB), over what it covers</th></tr>",
    );
    hooks.note(&format!(
        "{:<24} {:<8} {:>14} {:>7} {:>9} {:>10}",
        "projection", "layout", "size", "covers", "time (s)", "log-PSNR"
    ));
    for (name, layout, w, h, n, secs, psnr, covered) in rows {
        let line = format!(
            "{:<24} {:<8} {:>14} {:>6.1}% {:>9.3} {:>10.2}",
            name,
            layout.to_string(),
            format!("{n}x{w}x{h}"),
            covered * 100.0,
            secs,
            psnr
        );
        hooks.note(&line);
        let _ = writeln!(table, "{line}");
        let _ = write!(html, "<tr><td>{name}</td><td>{layout}</td><td>{n}×{w}×{h}</td><td>{:.1}%</td><td>{secs:.3}</td><td>{psnr:.2}</td></tr>", covered * 100.0);
    }
    html.push_str("</table><p><img src=\"sheet.png\" style=\"max-width:100%\"></p>");
    for (name, layout, ..) in rows {
        let _ = write!(
            html,
            "<figure><img src=\"{name}.png\"><figcaption>{name} ({layout})</figcaption></figure>"
        );
    }
    html.push_str("<p>cube.ktx2 and cube.dds hold the cube with its full mip chain, faces in OpenGL/Vulkan/Direct3D order.</p>");
    let index = dir.join("index.html");
    std::fs::write(&index, html).map_err(|e| Error::system(format!("{}: {e}", index.display())))?;
    std::fs::write(dir.join("summary.txt"), table)
        .map_err(|e| Error::system(format!("{}: {e}", dir.display())))?;
    Ok(index)
}
