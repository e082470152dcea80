//! `mirrorball tag`: 360° metadata added to, replaced in or removed from an MP4/MOV without
//! re-encoding (mirrorball-spherical rewrites the movie box and copies the media data
//! through); the file is replaced through io's atomic writes, so it is either whole and
//! new or untouched. Also what `info` says of a video.

use crate::choice::{names, parse_flag};
use crate::error::CliError;
use clap::Args;
use mirrorball_core::Stereo;
use mirrorball_spherical::{Change, Kind, Reading, StereoMode, VideoTrack};
use std::path::Path;

#[derive(Args, Debug)]
pub struct TagArgs {
    /// The MP4 or MOV file, changed in place (written beside it, then renamed over it).
    file: String,
    /// The projection of its pictures: equirect (the whole sphere, 2:1), half-equirect
    /// (VR180, 1:1), cube (v360's c3x2), eac (v360's eac).
    #[arg(long, value_name = "PROJECTION", value_parser = names::<Kind>(),
          required_unless_present = "remove")]
    projection: Option<String>,
    /// How its pictures hold the eyes, as v360's in_stereo: 2d (mono), tb (left eye on
    /// top), sbs (left eye on the left). --projection is each eye's.
    #[arg(long, value_name = "MODE", value_parser = names::<Stereo>(), default_value = "2d")]
    stereo: String,
    /// Also write Spherical Video V1's XML (equirectangular only) for services that read
    /// only V1.
    #[arg(long)]
    v1: bool,
    /// Remove the spherical metadata (V2 and V1) instead.
    #[arg(long, conflicts_with_all = ["projection", "stereo", "v1"])]
    remove: bool,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(a: TagArgs) -> Result<(), CliError> {
    let path = Path::new(&a.file);
    let (change, what) = if a.remove {
        (Change::Remove, "spherical metadata removed".to_string())
    } else {
        let kind: Kind = parse_flag("--projection", a.projection.as_deref().unwrap_or(""))?;
        let stereo: Stereo = parse_flag("--stereo", &a.stereo)?;
        let what = format!(
            "{kind} {}: Spherical Video V2{}",
            StereoMode::of(stereo).describe(),
            if a.v1 { " and V1" } else { "" }
        );
        let change = Change::Set {
            mapping: kind.mapping(),
            stereo,
            v1: a.v1,
        };
        (change, what)
    };
    let tagging = mirrorball_spherical::plan(path, &change)?;
    let s = &tagging.summary;
    if s.unchanged {
        if !a.quiet {
            println!("{}: {what} already; left as it is", a.file);
        }
        return Ok(());
    }
    let permissions = std::fs::metadata(path)
        .map_err(|e| mirrorball_io::Error::io(path, e))?
        .permissions();
    mirrorball_io::atomic_write(path, |w| {
        let io = |e| mirrorball_io::Error::io(path, e);
        w.get_ref().set_permissions(permissions).map_err(io)?;
        tagging.write_to(w).map_err(io)
    })?;
    if !a.quiet {
        let mut moved = String::new();
        if s.tables_moved > 0 {
            moved = format!(
                "; {} chunk offset table(s) moved by {} bytes",
                s.tables_moved, s.shift
            );
            if s.promoted > 0 {
                moved.push_str(&format!(", {} made 64-bit", s.promoted));
            }
        }
        println!(
            "{}: {what} in {} video track(s); movie box {} → {} bytes{moved}",
            a.file, s.tracks, s.moov.0, s.moov.1
        );
    }
    Ok(())
}

/// Whether `info` should read `input` as a video (by its extension).
pub fn is_movie(input: &str) -> bool {
    matches!(
        mirrorball::info::extension(input).as_deref(),
        Some("mp4" | "mov" | "m4v")
    )
}

/// `info` of a video: each video track's spherical metadata and how mirrorball reads it.
pub fn info(input: &str, json: bool) -> Result<(), CliError> {
    let tracks = mirrorball_spherical::read(Path::new(input))?;
    let described: Vec<(String, Result<Option<Reading>, mirrorball_spherical::Error>)> =
        tracks.iter().map(|t| (boxes(t), t.reading())).collect();
    if json {
        let list: Vec<serde_json::Value> = tracks
            .iter()
            .zip(&described)
            .map(|(t, (b, r))| track_json(t, b, r))
            .collect();
        let v = serde_json::json!({ "file": input, "video_tracks": list });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).expect("serialisable")
        );
        return Ok(());
    }
    println!("file:        {input}");
    for (i, (t, (b, r))) in tracks.iter().zip(&described).enumerate() {
        println!(
            "video {}:     {} {}x{}; spherical metadata: {b}",
            i + 1,
            t.codec,
            t.size.0,
            t.size.1
        );
        match r {
            Ok(Some(r)) => println!(
                "projection:  {} ({}, from {}): read its frames with {} --in-stereo {}",
                r.mapping.projection(),
                r.stereo,
                r.from,
                r.mapping.flags(),
                r.stereo
            ),
            Ok(None) => println!("projection:  none recorded"),
            Err(e) => println!("projection:  not one mirrorball reads: {e}"),
        }
    }
    Ok(())
}

/// Which spherical boxes a track has, for people.
fn boxes(t: &VideoTrack) -> String {
    let mut parts = Vec::new();
    if let Some(m) = t.stereo {
        parts.push(format!("st3d {}", m.describe()));
    }
    match &t.sv3d {
        Some(Ok(s)) => parts.push(format!("sv3d by '{}'", s.source)),
        Some(Err(_)) => parts.push("sv3d (unreadable)".into()),
        None => {}
    }
    match &t.v1 {
        Some(Ok(_)) => parts.push("V1 XML".into()),
        Some(Err(_)) => parts.push("V1 XML (unreadable)".into()),
        None => {}
    }
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

fn track_json(
    t: &VideoTrack,
    b: &str,
    r: &Result<Option<Reading>, mirrorball_spherical::Error>,
) -> serde_json::Value {
    let (projection, layout, stereo, from, problem) = match r {
        Ok(Some(r)) => (
            Some(r.mapping.projection().to_string()),
            r.mapping.layout().map(|l| l.to_string()),
            Some(r.stereo.to_string()),
            Some(r.from),
            None,
        ),
        Ok(None) => (None, None, None, None, None),
        Err(e) => (None, None, None, None, Some(e.to_string())),
    };
    serde_json::json!({
        "codec": t.codec,
        "width": t.size.0,
        "height": t.size.1,
        "metadata": b,
        "projection": projection,
        "layout": layout,
        "stereo": stereo,
        "from": from,
        "problem": problem,
    })
}
