//! `mirrorball demo`: the bundled HDR environment in every projection, with previews and the
//! round-trip quality of each, in a folder a person can open (`index.html`).

use crate::error::CliError;
use crate::progress::with_progress;
use crate::save::{self, SaveOptions};
use crate::{load, DemoArgs};
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::{resample, Image, ProjectionKind, ResampleOptions, WorldProjection};
use mirrorball_io::{Precision, WriteOptions};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// Poly Haven's "city" environment (CC0), 512×256 half-float lat-long, bundled.
const CITY_EXR: &[u8] = include_bytes!("../../../../assets/env/city.exr");

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

pub fn run(a: DemoArgs) -> Result<(), CliError> {
    let size = size_bound().check("--size", a.size)?;
    let dir = Path::new(&a.out);
    let mut files = crate::guard::Files::new();
    files
        .making(mirrorball_io::Folders::MakeAll)
        .output("--out", dir.join("index.html"));
    files.check()?;
    files.room(output_bytes(size))?;
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::system(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    let src_path = dir.join("source-city.exr");
    std::fs::write(&src_path, CITY_EXR)
        .map_err(|e| CliError::system(format!("{}: {e}", src_path.display())))?;
    let t0 = Instant::now();
    let src_str = src_path.display().to_string();
    let mut src = load::load(&src_str, None, None, &mirrorball_io::Limits::default())?;
    src.env.sanitize();
    let src = src.env;
    eprintln!(
        "source: {src_str} (lat-long {}x{}); writing every projection to {}",
        src.width(),
        src.height(),
        dir.display()
    );

    let preview = WriteOptions {
        precision: Some(Precision::U8),
        ..Default::default()
    };
    let exr = WriteOptions::default();
    let opts = ResampleOptions::default();
    let bright = ResampleOptions {
        exposure: a.exposure,
        ..Default::default()
    };
    let mut rows = Vec::new();
    let mut sheet_cells: Vec<Image> = Vec::new();
    with_progress(
        "demo",
        ProjectionKind::ALL.len() as u64,
        false,
        |done| -> Result<(), CliError> {
            for kind in ProjectionKind::ALL {
                let proj = kind.default_projection();
                let size = edge(kind, size);
                let t = Instant::now();
                let out = resample(&src, proj, size, &opts);
                let secs = t.elapsed().as_secs_f64();
                let name = kind.name();
                let layout = mirrorball_core::Layout::default_for(proj.kind());
                let save_opts = |w: WriteOptions| SaveOptions {
                    layout: Some(layout),
                    write: w,
                    mips: false,
                    keep_invalid: false,
                };
                save::save(
                    &out,
                    &dir.join(format!("{name}.exr")).display().to_string(),
                    &save_opts(exr),
                )?;
                let shown = if a.exposure != 0.0 {
                    resample(&src, proj, size, &bright)
                } else {
                    out.clone()
                };
                save::save(
                    &shown,
                    &dir.join(format!("{name}.png")).display().to_string(),
                    &save_opts(preview),
                )?;
                if let Some(packed) = layout.pack(&shown) {
                    sheet_cells.push(fit(&packed, SHEET_CELL));
                }
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
                let psnr = log_psnr_where(&src, &back, |d| proj.dir_to_uv(d).is_some())
                    .unwrap_or(f64::NAN);
                let (w, h) = (out.width(), out.height());
                rows.push((name, layout, w, h, out.layers().len(), secs, psnr, covered));
                done.fetch_add(1, Ordering::Relaxed);
            }
            Ok(())
        },
    )?;

    // A contact sheet of every projection, in the order of the table, five to a row.
    let cols = 5u32;
    let rows_n = (sheet_cells.len() as u32).div_ceil(cols);
    let mut sheet = Image::new(cols * SHEET_CELL, rows_n * SHEET_CELL, 3);
    for (i, cell) in sheet_cells.iter().enumerate() {
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
    mirrorball_io::write_image(&dir.join("sheet.png"), &sheet, &preview)?;

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
    eprintln!(
        "{:<24} {:<8} {:>14} {:>7} {:>9} {:>10}",
        "projection", "layout", "size", "covers", "time (s)", "log-PSNR"
    );
    for (name, layout, w, h, n, secs, psnr, covered) in &rows {
        let line = format!(
            "{:<24} {:<8} {:>14} {:>6.1}% {:>9.3} {:>10.2}",
            name,
            layout.to_string(),
            format!("{n}x{w}x{h}"),
            covered * 100.0,
            secs,
            psnr
        );
        eprintln!("{line}");
        let _ = writeln!(table, "{line}");
        let _ = write!(html, "<tr><td>{name}</td><td>{layout}</td><td>{n}×{w}×{h}</td><td>{:.1}%</td><td>{secs:.3}</td><td>{psnr:.2}</td></tr>", covered * 100.0);
    }
    html.push_str("</table><p><img src=\"sheet.png\" style=\"max-width:100%\"></p>");
    for (name, layout, ..) in &rows {
        let _ = write!(
            html,
            "<figure><img src=\"{name}.png\"><figcaption>{name} ({layout})</figcaption></figure>"
        );
    }
    html.push_str("<p>cube.ktx2 and cube.dds hold the cube with its full mip chain, faces in OpenGL/Vulkan/Direct3D order.</p>");
    let index = dir.join("index.html");
    std::fs::write(&index, html)
        .map_err(|e| CliError::system(format!("{}: {e}", index.display())))?;
    std::fs::write(dir.join("summary.txt"), table)
        .map_err(|e| CliError::system(format!("{}: {e}", dir.display())))?;
    eprintln!(
        "done in {:.1}s: open {}",
        t0.elapsed().as_secs_f64(),
        index.display()
    );
    Ok(())
}
