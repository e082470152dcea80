//! The whole analysis in one call, [`analyze`], and its report: the numbers as a
//! serialisable [`Report`] (written as JSON) and the drawings as SVG [`Figure`]s, assembled
//! into one HTML page by [`html`]. Nothing here touches files; the CLI writes the strings.
//!
//! Sizes: with [`Sizing::Budget`] every projection gets the edge at which all its layers
//! together hold about the same number of texels (a 512² sphere map against six 209² cube
//! faces: Zimmons' fair comparison); with [`Sizing::Size`] every projection gets the same
//! edge. Heat maps and cone drawings are computed at a smaller drawing budget (their values
//! are solid angles relative to an equal share, so they hardly depend on the size), and say
//! so in their captions.

use crate::claims::{claims, Claim};
use crate::cone::{class, cone_region, greene_cone, Cone, ConeRegion};
use crate::frustum::{frustum_share, Frustum, FrustumShare};
use crate::indexing::{
    LineStudy, MapSpec, QuadStudy, SphereStudy, VertexIndexing, ViewResult, Worst,
};
use crate::jacobian;
use crate::plot::{self, esc, heat_panel, ColorScale, Legend, LineChart, Marker, Series};
use crate::profile::{profile, Profile};
use crate::texels::{equal_share, scan, size_for_budget, texel_count, LayerField, TexelStats};
use glam::DVec2;
use mirrorball_core::{EnvMap, Image, Layout, Projection, ProjectionKind, WorldProjection};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt::Write as _;
use std::time::Instant;

/// How big each projection is analysed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "mode", content = "value")]
pub enum Sizing {
    /// The same edge for every projection.
    Size(u32),
    /// About this many texels (all layers together) for every projection.
    Budget(u64),
}

impl Sizing {
    /// The edge for `p`.
    pub fn size_for(&self, p: &Projection) -> u32 {
        match *self {
            Sizing::Size(n) => n,
            Sizing::Budget(b) => size_for_budget(p, b),
        }
    }
}

/// What to analyse.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// The projections (all of them by default).
    pub projections: Vec<Projection>,
    /// Their size.
    pub sizing: Sizing,
    /// Texel budget of the heat maps and cone drawings.
    pub drawing_budget: u64,
    /// The reflection cone drawn on every projection.
    pub cone: Cone,
    /// The camera frustum measured.
    pub frustum: Frustum,
    /// Zimmons' mirror line.
    pub line: LineStudy,
    /// The viewer of his figure 35.
    pub line_viewer: f64,
    /// The mirror quad.
    pub quad: QuadStudy,
    /// The tessellated sphere.
    pub sphere: SphereStudy,
}

impl Default for Config {
    /// Every projection at a budget of 6×512² texels; Greene's cone and frustum; Zimmons'
    /// line; a 20×20 quad seen from one unit above; an 8×16 UV sphere seen from 3 radii.
    fn default() -> Self {
        Config {
            projections: ProjectionKind::ALL
                .iter()
                .map(|k| k.default_projection())
                .collect(),
            sizing: Sizing::Budget(6 * 512 * 512),
            drawing_budget: 6 * 128 * 128,
            cone: greene_cone(),
            frustum: Frustum::GREENE,
            line: LineStudy::ZIMMONS,
            line_viewer: -8.3,
            quad: QuadStudy {
                half: 10.0,
                cells: 1,
                height: 1.0,
                samples: 24,
            },
            sphere: SphereStudy {
                stacks: 8,
                slices: 16,
                distance: 3.0,
                azimuth_deg: 11.25,
                samples: 12,
            },
        }
    }
}

/// One projection's numbers.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProjectionEntry {
    /// Texel statistics at the analysed size.
    pub stats: TexelStats,
    /// Zimmons' one-dimensional measure at the analysed size.
    pub profile: Profile,
    /// The reflection cone on it, at the drawing size.
    pub cone: ConeRegion,
}

/// The reflection cone, described.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConeInfo {
    /// Its axis.
    pub axis: [f64; 3],
    /// Its corners.
    pub corners: Vec<[f64; 3]>,
    /// Exact solid angle, sr.
    pub solid_angle: f64,
    /// Share of the sphere.
    pub share: f64,
    /// Angle from the axis to a corner, degrees.
    pub corner_radius_deg: f64,
}

/// One worst case of the line study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepPoint {
    /// Viewer x.
    pub viewer: f64,
    /// The worst error for that viewer and where.
    pub worst: Worst,
}

/// The line study cut into a number of segments.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LineRun {
    /// Segments.
    pub segments: u32,
    /// Error along the line for the figure-35 viewer, `[x, degrees]`.
    pub errors: Vec<[f64; 2]>,
    /// The worst for that viewer.
    pub worst: Worst,
    /// Worst error for each viewer position.
    pub sweep: Vec<SweepPoint>,
    /// The worst over all viewers.
    pub worst_viewer: SweepPoint,
}

/// The three indexing studies.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IndexingReport {
    /// The line set-up.
    pub line: LineStudy,
    /// Figure 35's viewer.
    pub line_viewer: f64,
    /// Runs with 1 (Zimmons), 4, 16 and 27 segments.
    pub line_runs: Vec<LineRun>,
    /// The quad set-up.
    pub quad: QuadStudy,
    /// Per viewer x.
    pub quad_results: Vec<ViewResult>,
    /// Largest error per 1° bin of incidence angle, over all quad viewers.
    pub quad_worst_by_incidence: Vec<f64>,
    /// The sphere set-up.
    pub sphere: SphereStudy,
    /// Per viewer elevation.
    pub sphere_results: Vec<ViewResult>,
    /// Largest error per 1° bin of incidence angle, over all sphere viewers.
    pub sphere_worst_by_incidence: Vec<f64>,
}

/// The sphere map's rim and the paraboloid's, size by size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RimRow {
    /// Edge size.
    pub size: u32,
    /// Centre pixel's angle, degrees.
    pub first_deg: f64,
    /// Outermost pixel's angle, degrees.
    pub last_deg: f64,
    /// Largest / smallest over the axis.
    pub ratio: f64,
    /// Anisotropy at the centre of the outermost texel of the centre row.
    pub outermost_anisotropy: f64,
}

/// Rim behaviour of the sphere map and the paraboloid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Singularities {
    /// The sphere map.
    pub sphere: Vec<RimRow>,
    /// One paraboloid half.
    pub paraboloid: Vec<RimRow>,
    /// The cube, for comparison.
    pub cube: Vec<RimRow>,
}

/// Everything measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The tool.
    pub generator: String,
    /// How the projections were sized.
    pub sizing: Sizing,
    /// Budget of the drawings.
    pub drawing_budget: u64,
    /// Per projection.
    pub projections: Vec<ProjectionEntry>,
    /// The frustum.
    pub frustum: FrustumShare,
    /// The cone.
    pub cone: ConeInfo,
    /// The indexing studies.
    pub indexing: IndexingReport,
    /// Rim singularities.
    pub singularities: Singularities,
    /// The documents' claims.
    pub claims: Vec<Claim>,
    /// Seconds the analysis took.
    pub seconds: f64,
    /// Seconds per stage.
    pub stages: Vec<(String, f64)>,
}

/// A drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// File stem (`analysis-…`).
    pub id: String,
    /// Title.
    pub title: String,
    /// Caption: what is drawn and how.
    pub caption: String,
    /// The SVG document.
    pub svg: String,
}

/// The report and its drawings.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// The numbers.
    pub report: Report,
    /// The drawings.
    pub figures: Vec<Figure>,
}

fn rim_rows(p: &Projection, sizes: &[u32]) -> Vec<RimRow> {
    sizes
        .iter()
        .map(|&n| {
            let pr = profile(p, n);
            let w = &pr.walks[0];
            let (lw, lh) = p.layer_extent(n);
            let uv = DVec2::new(
                (lw as f64 - 0.5) / lw as f64,
                ((lh / 2) as f64 + 0.5) / lh as f64,
            );
            RimRow {
                size: n,
                first_deg: w.first,
                last_deg: w.last,
                ratio: w.ratio,
                outermost_anisotropy: jacobian::anisotropy(p, pr.layer, uv, lw, lh)
                    .unwrap_or(f64::NAN),
            }
        })
        .collect()
}

/// The three per-vertex indexing studies of `cfg`.
fn indexing_studies(cfg: &Config) -> IndexingReport {
    let line_viewers: Vec<f64> = (0..=200).map(|i| -10.0 + 0.05 * i as f64).collect();
    let line_runs: Vec<LineRun> = [1u32, 4, 16, 27]
        .par_iter()
        .map(|&segments| {
            let l = LineStudy {
                segments,
                ..cfg.line
            };
            let sweep: Vec<SweepPoint> = l
                .sweep(&line_viewers)
                .into_iter()
                .map(|(viewer, worst)| SweepPoint { viewer, worst })
                .collect();
            let worst_viewer = sweep
                .iter()
                .max_by(|a, b| a.worst.degrees.total_cmp(&b.worst.degrees))
                .cloned()
                .expect("viewers");
            LineRun {
                segments,
                errors: l.errors(cfg.line_viewer, 800),
                worst: l.worst(cfg.line_viewer),
                sweep,
                worst_viewer,
            }
        })
        .collect();
    let size_of = |k: ProjectionKind| {
        let p = k.default_projection();
        (p, cfg.sizing.size_for(&p))
    };
    let mut maps = Vec::new();
    for (k, ix) in [
        (ProjectionKind::Sphere, VertexIndexing::Texgen),
        (ProjectionKind::Cube, VertexIndexing::Vector),
        (ProjectionKind::Paraboloid, VertexIndexing::Vector),
        (ProjectionKind::LatLong, VertexIndexing::Texgen),
    ] {
        let (projection, size) = size_of(k);
        maps.push(MapSpec {
            projection,
            size,
            indexing: ix,
        });
    }
    let quad_viewers: Vec<f64> = (0..=40).map(|i| -10.0 + 0.5 * i as f64).collect();
    let (quad_results, quad_worst_by_incidence) = cfg.quad.run(&quad_viewers, &maps);
    let elevations: Vec<f64> = (0..=18).map(|i| 5.0 * i as f64).collect();
    let (sphere_results, sphere_worst_by_incidence) = cfg.sphere.run(&elevations, &maps);
    IndexingReport {
        line: cfg.line,
        line_viewer: cfg.line_viewer,
        line_runs,
        quad: cfg.quad,
        quad_results,
        quad_worst_by_incidence,
        sphere: cfg.sphere,
        sphere_results,
        sphere_worst_by_incidence,
    }
}

/// Runs the whole analysis.
pub fn analyze(cfg: &Config) -> Analysis {
    let t0 = Instant::now();
    let sized: Vec<(Projection, u32)> = cfg
        .projections
        .iter()
        .map(|p| (*p, cfg.sizing.size_for(p)))
        .collect();
    let mut stages = Vec::new();
    let mut lap = {
        let mut t = Instant::now();
        move |name: &str, stages: &mut Vec<(String, f64)>| {
            stages.push((name.to_string(), t.elapsed().as_secs_f64()));
            t = Instant::now();
        }
    };
    // The projections one after another, each in parallel over its rows, while the studies
    // that do not depend on them (indexing, rims, claims) run beside them.
    let ((entries, fields, frustum), (indexing, singularities, claims)) = rayon::join(
        || {
            let per: Vec<(ProjectionEntry, (Projection, Vec<LayerField>))> = sized
                .iter()
                .map(|(p, n)| measure(p, *n, cfg.drawing_budget, &cfg.cone))
                .collect();
            let (entries, fields): (Vec<_>, Vec<_>) = per.into_iter().unzip();
            // Brute force at no more than 6×256² texels a projection: it converges like 1/n,
            // and the closed form is the reference.
            let frustum_sizes: Vec<(Projection, u32)> = sized
                .iter()
                .map(|(p, n)| {
                    (
                        *p,
                        size_for_budget(p, texel_count(p, *n).min(6 * 256 * 256)),
                    )
                })
                .collect();
            (entries, fields, frustum_share(cfg.frustum, &frustum_sizes))
        },
        || {
            let indexing = indexing_studies(cfg);
            let rim_sizes = [32, 64, 128, 256, 512, 1024, 2048, 4096];
            let singularities = Singularities {
                sphere: rim_rows(&ProjectionKind::Sphere.default_projection(), &rim_sizes),
                paraboloid: rim_rows(&ProjectionKind::Paraboloid.default_projection(), &rim_sizes),
                cube: rim_rows(&ProjectionKind::Cube.default_projection(), &rim_sizes),
            };
            (indexing, singularities, claims())
        },
    );
    lap("measurements", &mut stages);

    let cone = ConeInfo {
        axis: cfg.cone.axis.to_array(),
        corners: cfg.cone.corners.iter().map(|c| c.to_array()).collect(),
        solid_angle: cfg.cone.solid_angle(),
        share: cfg.cone.solid_angle() / (4.0 * std::f64::consts::PI),
        corner_radius_deg: cfg.cone.corner_radius().to_degrees(),
    };
    let mut report = Report {
        generator: format!("mirrorball-analysis {}", env!("CARGO_PKG_VERSION")),
        sizing: cfg.sizing,
        drawing_budget: cfg.drawing_budget,
        projections: entries,
        frustum,
        cone,
        indexing,
        singularities,
        claims,
        seconds: 0.0,
        stages: Vec::new(),
    };
    let figures = figures(&report, &fields);
    lap("figures", &mut stages);
    report.seconds = t0.elapsed().as_secs_f64();
    report.stages = stages;
    Analysis { report, figures }
}

/// One projection's numbers at edge `n` and its fields at the drawing budget (no more texels
/// than at `n`).
fn measure(
    p: &Projection,
    n: u32,
    drawing_budget: u64,
    cone: &Cone,
) -> (ProjectionEntry, (Projection, Vec<LayerField>)) {
    let (stats, _) = scan(p, n, false);
    let ds = size_for_budget(p, drawing_budget.min(texel_count(p, n)));
    let (_, f) = scan(p, ds, true);
    let entry = ProjectionEntry {
        stats,
        profile: profile(p, n),
        cone: cone_region(p, ds, cone),
    };
    (entry, (*p, f.expect("kept")))
}

/// One projection measured and drawn as [`analyze`] measures and draws each of its own (a
/// [`Config`] with `p` alone, sized `size`, the default cone): its numbers, and the
/// report's solid-angle, anisotropy and Zimmons figures of it alone, the same documents
/// `mirrorball analyze --projection P --size N` writes (tested). For the studio's analysis
/// panel: no indexing studies, rims or claims.
pub fn analyze_projection(
    p: &Projection,
    size: u32,
    drawing_budget: u64,
) -> (ProjectionEntry, Vec<Figure>) {
    let (entry, fields) = measure(p, size, drawing_budget, &greene_cone());
    let entries = std::slice::from_ref(&entry);
    let fields = std::slice::from_ref(&fields);
    let figures = vec![
        solid_angle_figure(entries, drawing_budget, fields),
        anisotropy_figure(entries, fields),
        zimmons_figure(entries),
    ];
    (entry, figures)
}

/// The report as pretty-printed JSON. Non-finite numbers become `null`.
pub fn json(report: &Report) -> String {
    serde_json::to_string_pretty(report).expect("a report serialises")
}

/// The layout a projection's layers are drawn in.
fn layout_for(p: &Projection) -> Layout {
    match p.layer_count() {
        6 => Layout::HorizontalCross,
        1 => Layout::Separate,
        _ => Layout::HorizontalStrip,
    }
}

/// Packs per-layer RGBA colours (`f32` in 0..1) with the projection's layout, to bytes.
fn pack(p: &Projection, layers: Vec<Image>) -> (u32, u32, Vec<u8>) {
    let env = EnvMap::new(*p, layers).expect("layers fit the projection");
    let img = layout_for(p).pack(&env).expect("layout fits");
    let bytes = img
        .data()
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    (img.width(), img.height(), bytes)
}

const UNUSED_RGBA: [f32; 4] = [0.85, 0.85, 0.85, 1.0];

fn field_image(f: &LayerField, color: impl Fn(usize) -> Option<[u8; 3]>) -> Image {
    let mut img = Image::new(f.width, f.height, 4);
    for (i, px) in img.data_mut().chunks_mut(4).enumerate() {
        match color(i) {
            Some(c) => px.copy_from_slice(&[
                c[0] as f32 / 255.0,
                c[1] as f32 / 255.0,
                c[2] as f32 / 255.0,
                1.0,
            ]),
            None => px.copy_from_slice(&UNUSED_RGBA),
        }
    }
    img
}

/// A grid of drawings, one per projection, with a colour bar under it.
fn grid(title: &str, panels: &[(String, u32, u32, Vec<u8>)], scale: Option<&ColorScale>) -> String {
    let cols = 5usize.min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols);
    let (pw, ph) = (270.0, 230.0);
    let top = 30.0;
    let bar = if scale.is_some() { 70.0 } else { 10.0 };
    // Wide enough for the title and the colour bar (one projection alone: the studio's
    // panel, `analyze --projection P`), the panels centred.
    let w = (cols as f64 * pw + 20.0).max(560.0);
    let left = (w - cols as f64 * pw) / 2.0;
    let h = top + rows as f64 * ph + bar;
    let mut body = plot::text(w / 2.0, 20.0, title, 15.0, "middle", "font-weight=\"bold\"");
    for (i, (name, iw, ih, rgba)) in panels.iter().enumerate() {
        let (c, r) = (i % cols, i / cols);
        body += &heat_panel(
            left + c as f64 * pw,
            top + r as f64 * ph,
            pw - 10.0,
            ph - 8.0,
            name,
            *iw,
            *ih,
            rgba,
        );
    }
    if let Some(s) = scale {
        body += &plot::colorbar(w / 2.0 - 250.0, top + rows as f64 * ph + 4.0, 500.0, s);
    }
    plot::document(w, h, &body)
}

fn figures(r: &Report, fields: &[(Projection, Vec<LayerField>)]) -> Vec<Figure> {
    vec![
        solid_angle_figure(&r.projections, r.drawing_budget, fields),
        anisotropy_figure(&r.projections, fields),
        zimmons_figure(&r.projections),
        cone_figure(r, fields),
        indexing_line_figure(r),
        indexing_quad_sphere_figure(r),
        singularities_figure(r),
    ]
}

/// "4×512²", or "1×1024×512" where the layers are not square.
fn size_label(t: &TexelStats) -> String {
    if t.width == t.height {
        format!("{}×{}²", t.layers, t.width)
    } else {
        format!("{}×{}×{}", t.layers, t.width, t.height)
    }
}

/// Solid angle per texel.
fn solid_angle_figure(
    entries: &[ProjectionEntry],
    drawing_budget: u64,
    fields: &[(Projection, Vec<LayerField>)],
) -> Figure {
    let sa = ColorScale {
        lo: 1.0 / 64.0,
        hi: 8.0,
        log: true,
        label: "solid angle per texel ÷ equal share 4π/texels (log scale; grey: unused)".into(),
    };
    let panels: Vec<_> = fields
        .iter()
        .enumerate()
        .map(|(i, (p, f))| {
            let t = &entries[i].stats;
            let total: u64 = f.iter().map(|l| (l.width * l.height) as u64).sum();
            let share = equal_share(total);
            let layers = f
                .iter()
                .map(|l| {
                    field_image(l, |i| {
                        (l.solid_angle[i] > 0.0).then(|| sa.color(l.solid_angle[i] / share))
                    })
                })
                .collect();
            let (w, h, px) = pack(p, layers);
            let title = format!(
                "{}\nmax/min {:.4} at {}",
                p.name(),
                t.full.ratio,
                size_label(t)
            );
            (title, w, h, px)
        })
        .collect();
    Figure {
        id: "analysis-solid-angle-heatmaps".into(),
        title: "Solid angle per texel".into(),
        caption: format!(
            "Exact solid angle of every texel (WorldProjection::texel_solid_angle; rim texels \
             count only their covered part) divided by 4π/texels, the share an ideal equal-area \
             map with no waste would give each texel: 1 is fair, above 1 a texel sees more than \
             its share. Drawn at a budget of {} texels per projection (the numbers under each \
             name are at the analysed size); cubes as a horizontal cross, the paraboloid \
             front | back.",
            drawing_budget
        ),
        svg: grid(
            "Solid angle per texel, relative to an equal share",
            &panels,
            Some(&sa),
        ),
    }
}

/// Anisotropy.
fn anisotropy_figure(
    entries: &[ProjectionEntry],
    fields: &[(Projection, Vec<LayerField>)],
) -> Figure {
    let an = ColorScale {
        lo: 1.0,
        hi: 16.0,
        log: true,
        label: "anisotropy σ₁/σ₂ of the Jacobian at the texel centre (log scale)".into(),
    };
    let panels: Vec<_> = fields
        .iter()
        .enumerate()
        .map(|(k, (p, f))| {
            let t = &entries[k].stats;
            let layers = f
                .iter()
                .map(|l| {
                    field_image(l, |i| {
                        l.anisotropy[i]
                            .is_finite()
                            .then(|| an.color(l.anisotropy[i]))
                    })
                })
                .collect();
            let (w, h, px) = pack(p, layers);
            let title = format!(
                "{}\nmax {:.4}, mean {:.4} at {}",
                p.name(),
                t.anisotropy_max.value,
                t.anisotropy_mean,
                size_label(t)
            );
            (title, w, h, px)
        })
        .collect();
    Figure {
        id: "analysis-anisotropy-heatmaps".into(),
        title: "Anisotropy".into(),
        caption: "Ratio of the largest to the smallest angle one pixel step subtends (singular \
                  values of the Jacobian of uv_to_dir in pixel coordinates, by central \
                  differences on the projection's own code). 1 (dark) is isotropic: the \
                  paraboloid and the Mercator are conformal, the sphere map's and the angular \
                  map's rims are singular. Drawn at the same budget as the solid angles; the \
                  numbers under each name are at the analysed size."
            .into(),
        svg: grid("Anisotropy of each texel", &panels, Some(&an)),
    }
}

/// Zimmons' one-dimensional measure.
fn zimmons_figure(entries: &[ProjectionEntry]) -> Figure {
    let n = entries.len();
    let cols = 5usize.min(n.max(1));
    let rows = n.div_ceil(cols);
    let (pw, ph) = (300.0, 240.0);
    // Wide enough for the title and the legend, the charts centred.
    let w = (cols as f64 * pw).max(760.0);
    let left = (w - cols as f64 * pw) / 2.0;
    let h = 36.0 + rows as f64 * ph;
    let h = h + 22.0;
    let mut body = plot::text(
        w / 2.0,
        22.0,
        "Angle subtended by each pixel, from the layer centre outwards (Zimmons' figs. 13, 30, 48)",
        15.0,
        "middle",
        "font-weight=\"bold\"",
    );
    // One legend for all panels.
    for (k, name) in ["horizontal axis (h)", "vertical axis (v)", "diagonal (d)"]
        .iter()
        .enumerate()
    {
        let lx = w / 2.0 - 270.0 + 190.0 * k as f64;
        let dash = if k == 1 {
            " stroke-dasharray=\"6 3\""
        } else {
            ""
        };
        let _ = writeln!(
            body,
            "<line x1=\"{lx:.1}\" y1=\"40\" x2=\"{:.1}\" y2=\"40\" stroke=\"{}\" stroke-width=\"2\"{dash}/>",
            lx + 24.0,
            plot::PALETTE[k]
        );
        body += &plot::text(lx + 30.0, 44.0, name, 12.0, "start", "");
    }
    for (i, e) in entries.iter().enumerate() {
        let (c, row) = (i % cols, i / cols);
        let pr = &e.profile;
        let series = pr
            .walks
            .iter()
            .enumerate()
            .map(|(k, wk)| {
                // A last step cut short by the rim or an odd edge is not a whole pixel.
                let full = if wk.last_fraction < 1.0 {
                    wk.degrees.len() - 1
                } else {
                    wk.degrees.len()
                };
                let pts = wk.degrees[..full]
                    .iter()
                    .enumerate()
                    .map(|(j, d)| [j as f64, *d])
                    .collect();
                let s = Series::new(&wk.name, pts, k);
                if k == 1 {
                    s.dashed()
                } else {
                    s
                }
            })
            .collect();
        let ratios: Vec<String> = pr
            .walks
            .iter()
            .map(|w| format!("{} {:.3}", &w.name[..1], w.ratio))
            .collect();
        let chart = LineChart {
            title: if e.stats.layers > 1 {
                format!(
                    "{} (layer {}, {}×{})",
                    pr.projection, pr.layer, pr.width, pr.height
                )
            } else {
                format!("{} ({}×{})", pr.projection, pr.width, pr.height)
            },
            subtitle: format!("max/min: {}", ratios.join(", ")),
            x_label: "pixel from the centre".into(),
            y_label: "degrees per pixel".into(),
            series,
            legend: Legend::None,
            ..Default::default()
        };
        body += &chart.draw(left + c as f64 * pw, 58.0 + row as f64 * ph, pw, ph);
    }
    Figure {
        id: "analysis-zimmons-1d".into(),
        title: "Zimmons' one-dimensional measure".into(),
        caption: "For each projection at the analysed size: the angle between the directions \
                  at the two ends of each pixel, walking from the centre of the layer that \
                  looks along −Z to its edge, along the horizontal axis, the vertical axis \
                  (dashed) and the diagonal (one pixel in each direction per step). A \
                  rising curve (sphere map, angular map) means texels see more of the world \
                  towards the edge; the sphere map's last pixel is its rim singularity."
            .into(),
        svg: plot::document(w, h, &body),
    }
}

/// The reflection cone.
fn cone_figure(r: &Report, fields: &[(Projection, Vec<LayerField>)]) -> Figure {
    let panels: Vec<_> = r
        .projections
        .iter()
        .zip(fields)
        .map(|(e, (p, _))| {
            let c = &e.cone;
            let layers = c
                .mask
                .iter()
                .map(|m| {
                    let mut img = Image::new(c.width, c.height, 4);
                    for (px, &k) in img.data_mut().chunks_mut(4).zip(m) {
                        let col: [f32; 4] = match k {
                            class::UNUSED => UNUSED_RGBA,
                            class::OUTSIDE => [0.97, 0.97, 0.97, 1.0],
                            class::INSIDE => [0.84, 0.37, 0.0, 1.0],
                            _ => [0.0, 0.2, 0.5, 1.0],
                        };
                        px.copy_from_slice(&col);
                    }
                    img
                })
                .collect();
            let (w, h, px) = pack(p, layers);
            (
                format!(
                    "{}\n{} piece{}, edges bend {:.1} texels",
                    c.projection,
                    c.pieces,
                    if c.pieces == 1 { "" } else { "s" },
                    c.max_edge_bend_texels
                ),
                w,
                h,
                px,
            )
        })
        .collect();
    Figure {
        id: "analysis-reflection-cone".into(),
        title: "One reflection cone on every projection (Greene's fig. 2)".into(),
        caption: format!(
            "A reflection cone of {:.1}% of the sphere (a spherical quadrilateral, its four \
             corners {:.1}° from its axis) drawn on every projection at a budget of {} texels: \
             orange texels have their centre inside, blue ones are crossed by its edges. \
             'pieces' counts the separate regions a filter must handle; 'bend' is how far \
             (texels) a mapped edge strays from a straight line: 0 on the cube, whose regions \
             are polygons.",
            100.0 * r.cone.share,
            r.cone.corner_radius_deg,
            r.drawing_budget
        ),
        svg: grid(
            "The same reflection cone (3/8 of the world) on every projection",
            &panels,
            None,
        ),
    }
}

/// Indexing: the line.
fn indexing_line_figure(r: &Report) -> Figure {
    let ix = &r.indexing;
    let (w, h) = (1100.0, 380.0);
    let s35: Vec<Series> = ix
        .line_runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            Series::new(
                &format!(
                    "{} segment{}",
                    run.segments,
                    if run.segments == 1 { "" } else { "s" }
                ),
                run.errors.clone(),
                i,
            )
        })
        .collect();
    let c35 = LineChart {
        title: format!(
            "Fig. 35 set-up: viewer at ({}, {}, 0)",
            ix.line_viewer, ix.line.height
        ),
        x_label: "x on the mirror".into(),
        y_label: "interpolated vs exact reflection (°)".into(),
        series: s35,
        log_y: true,
        y_range: Some([1e-3, 300.0]),
        markers: vec![Marker {
            at: [-4.5, 2.61],
            label: "Zimmons: 2.61° at −4.5".into(),
        }],
        ..Default::default()
    };
    let s36: Vec<Series> = ix
        .line_runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            Series::new(
                &format!(
                    "{} seg.: worst {:.2}° (viewer {:.2})",
                    run.segments, run.worst_viewer.worst.degrees, run.worst_viewer.viewer
                ),
                run.sweep
                    .iter()
                    .map(|s| [s.viewer, s.worst.degrees])
                    .collect(),
                i,
            )
        })
        .collect();
    let c36 = LineChart {
        title: "Fig. 36 set-up: worst error for each viewer position".into(),
        x_label: "viewer x (one unit above the mirror)".into(),
        y_label: "largest error along the mirror (°)".into(),
        series: s36,
        log_y: true,
        y_range: Some([1e-1, 300.0]),
        markers: vec![Marker {
            at: [-8.3, 2.60751],
            label: "Zimmons: 2.60751° at −8.3".into(),
        }],
        ..Default::default()
    };
    let body = c35.draw(0.0, 0.0, w / 2.0, h) + &c36.draw(w / 2.0, 0.0, w / 2.0, h);
    Figure {
        id: "analysis-indexing-line".into(),
        title: "Per-vertex reflection on a mirror line (Zimmons' figs. 34–36)".into(),
        caption: "A flat mirror along x from −10 to 10 (normal +y), the viewer one unit \
                  above it. Reflected vectors are computed exactly at the segment ends and \
                  interpolated linearly in between (object space, i.e. perspective-correct) \
                  and compared with the exact reflection at each point. One segment is \
                  Zimmons' stated set-up; the circles mark his printed values, which no \
                  segment count reproduces."
            .into(),
        svg: plot::document(w, h, &body),
    }
}

/// Indexing: quad and sphere.
fn indexing_quad_sphere_figure(r: &Report) -> Figure {
    let ix = &r.indexing;
    let (w, h) = (1260.0, 720.0);
    let (cw, chh) = (w / 3.0, h / 2.0);
    let mut body = String::new();
    let map_series = |res: &[ViewResult]| -> Vec<Series> {
        (0..res.first().map_or(0, |v| v.maps.len()))
            .map(|k| {
                let m = &res[0].maps[k];
                Series::new(
                    &format!(
                        "{} {} ({}²)",
                        m.projection,
                        m.indexing.to_lowercase(),
                        m.size
                    ),
                    res.iter()
                        .map(|v| [v.viewer, v.maps[k].max_texels])
                        .collect(),
                    k + 1,
                )
            })
            .collect()
    };
    let angle_series = |res: &[ViewResult]| {
        vec![
            Series::new(
                "worst, vector interpolation",
                res.iter().map(|v| [v.viewer, v.worst.degrees]).collect(),
                0,
            ),
            Series::new(
                "mean, vector interpolation",
                res.iter().map(|v| [v.viewer, v.mean_degrees]).collect(),
                0,
            )
            .dashed(),
            Series::new(
                "worst, sphere-map texgen (looked-up direction)",
                res.iter()
                    .map(|v| [v.viewer, v.maps[0].max_degrees])
                    .collect(),
                1,
            ),
        ]
    };
    let by_inc = |bins: &[f64]| -> Vec<[f64; 2]> {
        bins.iter()
            .enumerate()
            .map(|(i, e)| [i as f64 + 0.5, if *e > 0.0 { *e } else { f64::NAN }])
            .collect()
    };
    type Row<'a> = (&'a str, String, &'a str, &'a [ViewResult], &'a [f64]);
    let rows: [Row; 2] = [
        (
            "Mirror quad",
            format!(
                "[−{0},{0}]² at y = 0, {1}×{1} cell(s) of 2 triangles, viewer at (x, {2}, 0)",
                ix.quad.half, ix.quad.cells, ix.quad.height
            ),
            "viewer x",
            &ix.quad_results,
            &ix.quad_worst_by_incidence,
        ),
        (
            "UV sphere",
            format!(
                "{} stacks × {} slices, radius 1, viewer {} radii from the centre",
                ix.sphere.stacks, ix.sphere.slices, ix.sphere.distance
            ),
            "viewer elevation (°)",
            &ix.sphere_results,
            &ix.sphere_worst_by_incidence,
        ),
    ];
    for (i, (title, sub, xl, res, bins)) in rows.iter().enumerate() {
        let y = i as f64 * chh;
        let a = LineChart {
            title: format!("{title}: reflected-vector error"),
            subtitle: sub.clone(),
            x_label: xl.to_string(),
            y_label: "degrees".into(),
            series: angle_series(res),
            ..Default::default()
        };
        body += &a.draw(0.0, y, cw, chh);
        let t = LineChart {
            title: format!("{title}: worst texture-coordinate error"),
            subtitle: "each map at its analysed size".into(),
            x_label: xl.to_string(),
            y_label: "texels".into(),
            series: map_series(res),
            log_y: true,
            y_range: Some([1e-2, 1e3]),
            legend: Legend::BottomRight,
            ..Default::default()
        };
        body += &t.draw(cw, y, cw, chh);
        let b = LineChart {
            title: format!("{title}: worst vector error by incidence"),
            subtitle: "all viewer positions together".into(),
            x_label: "angle between view ray and normal (°)".into(),
            y_label: "degrees".into(),
            series: vec![Series::new("", by_inc(bins), 2)],
            x_range: Some([0.0, 90.0]),
            legend: Legend::None,
            ..Default::default()
        };
        body += &b.draw(2.0 * cw, y, cw, chh);
    }
    Figure {
        id: "analysis-indexing-meshes".into(),
        title: "Per-vertex indexing on a mirror quad and a tessellated sphere".into(),
        caption: "Exact per-point reflection (interpolated normal, exact view ray) against \
                  reflected vectors computed at the vertices and interpolated. Vector \
                  indexing (cube, paraboloid) looks the interpolated vector up per pixel; \
                  texgen indexing (GL_SPHERE_MAP in the camera's eye space, lat-long) \
                  interpolates per-vertex texture coordinates. Texel errors are measured on \
                  each map at the analysed size; samples whose two lookups fall on \
                  different faces (or across the lat-long seam) are left out of the texel \
                  error and counted in the JSON."
            .into(),
        svg: plot::document(w, h, &body),
    }
}

/// Singularities.
fn singularities_figure(r: &Report) -> Figure {
    let s = &r.singularities;
    let (w, h) = (1100.0, 360.0);
    let lg = |rows: &[RimRow], f: fn(&RimRow) -> f64| -> Vec<[f64; 2]> {
        rows.iter()
            .map(|r| [(r.size as f64).log2(), f(r)])
            .collect()
    };
    let a = LineChart {
        title: "Largest / smallest pixel angle along the axis".into(),
        x_label: "log₂ of the edge size".into(),
        y_label: "ratio".into(),
        series: vec![
            Series::new("sphere map", lg(&s.sphere, |r| r.ratio), 0),
            Series::new("paraboloid half", lg(&s.paraboloid, |r| r.ratio), 1),
            Series::new("cube face", lg(&s.cube, |r| r.ratio), 2),
        ],
        log_y: true,
        legend: Legend::TopLeft,
        ..Default::default()
    };
    let b = LineChart {
        title: "Anisotropy of the outermost texel of the centre row".into(),
        x_label: "log₂ of the edge size".into(),
        y_label: "σ₁/σ₂".into(),
        series: vec![
            Series::new("sphere map", lg(&s.sphere, |r| r.outermost_anisotropy), 0),
            Series::new(
                "paraboloid half",
                lg(&s.paraboloid, |r| r.outermost_anisotropy),
                1,
            ),
            Series::new("cube face", lg(&s.cube, |r| r.outermost_anisotropy), 2),
        ],
        log_y: true,
        legend: Legend::TopLeft,
        ..Default::default()
    };
    let body = a.draw(0.0, 0.0, w / 2.0, h) + &b.draw(w / 2.0, 0.0, w / 2.0, h);
    Figure {
        id: "analysis-rims".into(),
        title: "The sphere map's rim singularity and the paraboloid's rim".into(),
        caption: "As the map grows the sphere map's one-dimensional ratio grows like √n \
                  (its rim is a single direction) and its rim texels become arbitrarily \
                  anisotropic (1/(1 − ρ²)), although every full texel has the same solid \
                  angle. The paraboloid's ratio tends to 2 and it stays isotropic; the \
                  cube's tends to 2 along an axis (the two curves coincide: both are atan \
                  maps), with anisotropy √2 at an edge midpoint."
            .into(),
        svg: plot::document(w, h, &body),
    }
}

fn pct(x: f64) -> String {
    format!("{:.2}%", 100.0 * x)
}

fn sci(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    format!("{x:.4e}")
}

/// The report as one HTML page with the figures inline.
pub fn html(a: &Analysis) -> String {
    let r = &a.report;
    let mut s = html_head(r);
    html_texels(&mut s, r);
    html_figure(&mut s, a, "analysis-solid-angle-heatmaps");
    html_figure(&mut s, a, "analysis-anisotropy-heatmaps");
    html_zimmons(&mut s, r);
    html_figure(&mut s, a, "analysis-zimmons-1d");
    html_cone(&mut s, r);
    html_figure(&mut s, a, "analysis-reflection-cone");
    html_frustum(&mut s, r);
    html_indexing_line(&mut s, r);
    html_figure(&mut s, a, "analysis-indexing-line");
    html_indexing_worst(&mut s, r);
    html_figure(&mut s, a, "analysis-indexing-meshes");
    html_singularities(&mut s, r);
    html_figure(&mut s, a, "analysis-rims");
    html_claims(&mut s, r);
    s += "</table>\n</html>\n";
    s
}

/// The page's head, style sheet and title, and the paragraph on the generator, the sizing
/// and the time taken.
fn html_head(r: &Report) -> String {
    let mut s = String::from(
        "<!doctype html>\n<html lang=\"en\"><meta charset=\"utf-8\"><title>mirrorball analyze</title>\n<style>\
         body{font:14px/1.45 system-ui,sans-serif;margin:2em auto;max-width:1320px;color:#222}\
         table{border-collapse:collapse;margin:1em 0;font-size:13px}td,th{border:1px solid #ccc;padding:3px 7px;vertical-align:top}\
         th{background:#f3f3f3}td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\
         figure{margin:1.5em 0}figcaption{max-width:1100px;color:#444}svg{max-width:100%;height:auto}\
         .confirmed{background:#e6f4ea}.contradicted{background:#fde7e7}.off-in-the-last-digits{background:#fff6dd}.partly{background:#eef}\
         code{background:#f4f4f4;padding:0 3px}</style>\n<h1>Distortion and error of world projections</h1>\n",
    );
    let sizing = match r.sizing {
        Sizing::Size(n) => format!("every projection at edge size {n}"),
        Sizing::Budget(b) => {
            format!("every projection at a budget of about {b} texels (all layers together)")
        }
    };
    let _ = writeln!(
        s,
        "<p>{} — {sizing}. Every number comes from the projection code the converter uses \
         (<code>mirrorball_core::WorldProjection</code>); the same numbers are in <code>report.json</code>. \
         Analysis took {:.2} s.</p>",
        esc(&r.generator),
        r.seconds
    );
    s
}

/// The figure `id` of `a` (its SVG, title and caption), if `a` has it.
fn html_figure(s: &mut String, a: &Analysis, id: &str) {
    if let Some(f) = a.figures.iter().find(|f| f.id == id) {
        let _ = writeln!(
            s,
            "<figure id=\"{}\">{}<figcaption><b>{}.</b> {}</figcaption></figure>",
            f.id,
            f.svg.trim_start_matches(|c| c != '<'),
            esc(&f.title),
            esc(&f.caption)
        );
    }
}

/// The texel table: sizes, used area, full and rim texels, solid angle per texel and its
/// ratios, anisotropy, front/back shares and the crossover radius of each projection.
fn html_texels(s: &mut String, r: &Report) {
    *s += "<h2>Texels</h2>\n<table><tr><th>projection</th><th>layers × w × h</th><th>texels</th><th>used (exact area)</th>\
          <th>full / partial texels</th><th>solid angle per texel, full: min … max (sr)</th><th>max/min full</th><th>max/min with rim texels</th>\
          <th>anisotropy max</th><th>mean (per texel)</th><th>mean (over the sphere)</th><th>front / back / unused texels</th><th>crossover radius (uv)</th></tr>\n";
    for e in &r.projections {
        let t = &e.stats;
        let cross = t.crossover.map_or("—".to_string(), |c| {
            format!(
                "{:.10}{}",
                c.radius_uv,
                if c.at_rim { " (rim)" } else { "" }
            )
        });
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=n>{}×{}×{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{} / {}</td>\
             <td class=n>{} … {}</td><td class=n>{:.6}</td><td class=n>{}</td><td class=n>{:.4} <small>@{} ({},{})</small></td><td class=n>{:.4}</td><td class=n>{:.4}</td>\
             <td class=n>{} / {} / {}</td><td class=n>{}</td></tr>",
            t.projection,
            t.layers,
            t.width,
            t.height,
            t.texels,
            pct(t.used_area_fraction),
            t.full_texels,
            t.partial_texels,
            sci(t.full.min.value),
            sci(t.full.max.value),
            t.full.ratio,
            sci(t.with_partial.ratio),
            t.anisotropy_max.value,
            t.anisotropy_max.layer,
            t.anisotropy_max.x,
            t.anisotropy_max.y,
            t.anisotropy_mean,
            t.anisotropy_mean_sphere,
            pct(t.front_share),
            pct(t.back_share),
            pct(t.unused_share),
            cross
        );
    }
    *s += "</table>\n<p>Full texels lie wholly inside the covered domain; rim texels count only their covered part, so their ratio \
          is unbounded. Front is the hemisphere the default camera looks at (−Z), judged at the texel centre. The crossover \
          is where front meets back, when that is a circle about a layer's centre.</p>\n";
}

/// The table of Zimmons' one-dimensional measure: each projection's walks.
fn html_zimmons(s: &mut String, r: &Report) {
    *s += "<h2>Zimmons' one-dimensional measure</h2>\n<table><tr><th>projection</th><th>walk</th><th>pixels</th><th>first (°)</th><th>last full (°)</th><th>min</th><th>max</th><th>max/min</th></tr>\n";
    for e in &r.projections {
        for w in &e.profile.walks {
            let _ = writeln!(
                s,
                "<tr><td>{}</td><td>{}</td><td class=n>{}{}</td><td class=n>{:.7}</td><td class=n>{:.7}</td><td class=n>{:.7}</td><td class=n>{:.7}</td><td class=n>{:.5}</td></tr>",
                e.profile.projection,
                w.name,
                w.degrees.len(),
                if w.last_fraction < 1.0 { format!(" (last cut at {:.3})", w.last_fraction) } else { String::new() },
                w.first,
                w.last,
                w.min,
                w.max,
                w.ratio
            );
        }
    }
    *s += "</table>\n";
}

/// Greene's reflection cone: its paragraph and the table of each projection's drawing of it.
fn html_cone(s: &mut String, r: &Report) {
    *s += "<h2>Greene: a reflection cone and a camera frustum</h2>\n";
    let _ = writeln!(
        s,
        "<p>Reflection cone: {:.4} sr ({}), corners {:.2}° from the axis ({:.3}, {:.3}, {:.3}).</p>\n<table><tr><th>projection</th><th>drawn at</th><th>pieces</th><th>layers</th><th>texels inside</th><th>their solid angle / exact</th><th>edge bend (texels)</th><th>all edges mapped</th></tr>",
        r.cone.solid_angle,
        pct(r.cone.share),
        r.cone.corner_radius_deg,
        r.cone.axis[0],
        r.cone.axis[1],
        r.cone.axis[2]
    );
    for e in &r.projections {
        let c = &e.cone;
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{:.5}</td><td class=n>{:.2e}</td><td>{}</td></tr>",
            c.projection,
            c.size,
            c.pieces,
            c.layers_touched,
            c.texels,
            c.solid_angle / c.exact_solid_angle,
            c.max_edge_bend_texels,
            if c.fully_covered { "yes" } else { "no" }
        );
    }
    *s += "</table>\n";
}

/// Greene's camera frustum: its paragraph and the brute-force table, then the heading of
/// the per-vertex indexing section.
fn html_frustum(s: &mut String, r: &Report) {
    let f = &r.frustum;
    let _ = writeln!(
        s,
        "<p>Camera frustum, aspect {:.4} (width/height), {}° vertical × {:.3}° horizontal: \
         4 asin(sin α sin β) = {:.10} sr; as a spherical polygon {:.10} sr; <b>{} of the sphere</b> \
         (Greene: \"about six percent\").</p>\n<table><tr><th>brute force on</th><th>size</th><th>texels inside</th><th>Σ solid angle (sr)</th><th>relative error</th></tr>",
        f.frustum.aspect,
        f.frustum.vertical_fov_deg,
        f.horizontal_fov_deg,
        f.closed_form,
        f.polygon,
        pct(f.share)
    );
    for b in &f.brute_force {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{:.8}</td><td class=n>{:.2e}</td></tr>",
            b.projection, b.size, b.texels, b.solid_angle, b.relative_error
        );
    }
    *s += "</table>\n<h2>Per-vertex indexing</h2>\n";
}

/// The per-vertex indexing set-up and the table of Zimmons' line, by segment count.
fn html_indexing_line(s: &mut String, r: &Report) {
    let ix = &r.indexing;
    let _ = writeln!(
        s,
        "<p><b>Set-up measured.</b> Reflection <code>r = i − 2(i·n)n</code>, <code>i</code> the unit ray from \
         the eye. Exact: at every sample point, the exact ray and the normalised interpolated normal. Per vertex: \
         exact <code>r</code> at the vertices, interpolated with the point's barycentric coordinates \
         (perspective-correct). (1) Zimmons' line: a mirror from x = {} to {}, normal +y, the viewer at \
         (x<sub>e</sub>, {}, 0), cut into 1 (his set-up), 4, 16 or 27 equal segments. (2) A square mirror \
         [−{h}, {h}]² at y = 0, {c}×{c} cell(s) of two triangles, the viewer at (x, {qh}, 0) looking at its centre, \
         {qs} subdivisions per triangle edge. (3) A UV sphere of {st} stacks × {sl} slices, radius 1, the viewer {d} \
         radii from its centre at azimuth {az}°, elevation 0–90°, looking at the centre, {ss} subdivisions per \
         triangle edge. Maps for texel errors: sphere map (texgen, eye space), cube and paraboloid (vector), \
         lat-long (texgen), each at its analysed size.</p>\n<table><tr><th>line segments</th>\
         <th>viewer {}: worst (°)</th><th>at x</th><th>worst viewer</th><th>its worst (°)</th><th>at x</th></tr>",
        ix.line.x0,
        ix.line.x1,
        ix.line.height,
        ix.line_viewer,
        h = ix.quad.half,
        c = ix.quad.cells,
        qh = ix.quad.height,
        qs = ix.quad.samples,
        st = ix.sphere.stacks,
        sl = ix.sphere.slices,
        d = ix.sphere.distance,
        az = ix.sphere.azimuth_deg,
        ss = ix.sphere.samples,
    );
    for run in &ix.line_runs {
        let _ = writeln!(
            s,
            "<tr><td class=n>{}</td><td class=n>{:.4}</td><td class=n>{:.3}</td><td class=n>{:.2}</td><td class=n>{:.4}</td><td class=n>{:.3}</td></tr>",
            run.segments,
            run.worst.degrees,
            run.worst.at[0],
            run.worst_viewer.viewer,
            run.worst_viewer.worst.degrees,
            run.worst_viewer.worst.at[0]
        );
    }
    *s += "</table>\n";
}

/// The paragraph on the worst vector errors of the quad and the sphere.
fn html_indexing_worst(s: &mut String, r: &Report) {
    let ix = &r.indexing;
    let worst_of = |res: &[ViewResult]| {
        res.iter()
            .max_by(|a, b| a.worst.degrees.total_cmp(&b.worst.degrees))
            .cloned()
            .unwrap_or_default()
    };
    let (wq, ws) = (worst_of(&ix.quad_results), worst_of(&ix.sphere_results));
    let _ = writeln!(
        s,
        "<p>Quad: the worst vector error, {:.3}°, is for the viewer at x = {:.2}, at ({:.2}, {:.2}) on the mirror \
         (incidence {:.1}°). Sphere: the worst, {:.3}°, is for the viewer at elevation {:.0}°, at latitude {:.1}°, \
         longitude {:.1}° (incidence {:.1}°).</p>",
        wq.worst.degrees,
        wq.viewer,
        wq.worst.at[0],
        wq.worst.at[1],
        wq.worst.incidence_deg,
        ws.worst.degrees,
        ws.viewer,
        ws.worst.at[0],
        ws.worst.at[1],
        ws.worst.incidence_deg
    );
}

/// The table of the sphere map's singularity, the paraboloid's rim and the cube's ratios,
/// by edge size.
fn html_singularities(s: &mut String, r: &Report) {
    *s += "<h2>The sphere map's singularity and the paraboloid's rim</h2>\n<table><tr><th>edge</th><th>sphere: first / last (°)</th><th>ratio</th><th>outermost anisotropy</th>\
          <th>paraboloid: first / last (°)</th><th>ratio</th><th>outermost anisotropy</th><th>cube: ratio</th><th>outermost anisotropy</th></tr>\n";
    let sg = &r.singularities;
    for i in 0..sg.sphere.len() {
        let (a, b, c) = (&sg.sphere[i], &sg.paraboloid[i], &sg.cube[i]);
        let _ = writeln!(
            s,
            "<tr><td class=n>{}</td><td class=n>{:.5} / {:.5}</td><td class=n>{:.3}</td><td class=n>{:.1}</td><td class=n>{:.5} / {:.5}</td><td class=n>{:.5}</td><td class=n>{:.6}</td><td class=n>{:.5}</td><td class=n>{:.5}</td></tr>",
            a.size, a.first_deg, a.last_deg, a.ratio, a.outermost_anisotropy, b.first_deg, b.last_deg, b.ratio, b.outermost_anisotropy, c.ratio, c.outermost_anisotropy
        );
    }
    *s += "</table>\n";
}

/// The claims table: each claim of the documents, measured, with its verdict (the table is
/// left open).
fn html_claims(s: &mut String, r: &Report) {
    *s += "<h2>The documents' claims</h2>\n<p>Verdicts by the numbers: <i>confirmed</i> within half a unit of the last printed digit; \
          <i>off in the last digits</i> within ten units of it; <i>contradicted</i> beyond.</p>\n<table><tr><th>source</th><th>claim</th><th>document</th>\
          <th>measured</th><th>verdict</th><th>why</th></tr>\n";
    for c in &r.claims {
        let v = c.verdict.label();
        let _ = writeln!(
            s,
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td class=n>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            v.replace(' ', "-"),
            esc(&c.source),
            esc(&c.claim),
            esc(&c.document),
            esc(&c.measured),
            v,
            esc(&c.why)
        );
    }
}
