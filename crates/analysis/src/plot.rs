//! Plain SVG plots, written as text: line charts with axes, ticks, labels and a legend;
//! raster heat maps with a colour bar; grids of panels. No dependencies, no I/O.
//!
//! Every function returns SVG markup. [`LineChart::draw`] and [`heat_panel`] draw into a
//! rectangle of a larger picture (a `<g>` fragment), and [`document`] wraps fragments into a
//! standalone `<svg>` with a white background, so figures can be composed as small multiples.

use crate::png;
use std::fmt::Write as _;

/// Escapes text for XML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A standalone SVG document of `w×h` px around `body`.
pub fn document(w: f64, h: f64, body: &str) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" \
         viewBox=\"0 0 {w:.0} {h:.0}\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" \
         font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n{body}</svg>\n"
    )
}

/// A text label.
pub fn text(x: f64, y: f64, s: &str, size: f64, anchor: &str, extra: &str) -> String {
    format!(
        "<text x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"{size}\" text-anchor=\"{anchor}\" {extra}>{}</text>\n",
        esc(s)
    )
}

/// Colours for series, distinguishable in print (Okabe & Ito's palette).
pub const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
];

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// Points `[x, y]`; non-finite ones break the line.
    pub points: Vec<[f64; 2]>,
    /// Stroke colour.
    pub color: String,
    /// Dashed stroke.
    pub dashed: bool,
}

impl Series {
    /// A solid series in palette colour `i`.
    pub fn new(name: &str, points: Vec<[f64; 2]>, i: usize) -> Series {
        Series {
            name: name.to_string(),
            points,
            color: PALETTE[i % PALETTE.len()].to_string(),
            dashed: false,
        }
    }
    /// The same, dashed.
    pub fn dashed(mut self) -> Series {
        self.dashed = true;
        self
    }
}

/// A marked point with a label.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Position in data units.
    pub at: [f64; 2],
    /// Label.
    pub label: String,
}

/// A line chart.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LineChart {
    /// Title above the plot.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Fixed x range (else from the data).
    pub x_range: Option<[f64; 2]>,
    /// Fixed y range (else from the data; a linear axis starts at 0 when all data are ≥ 0).
    pub y_range: Option<[f64; 2]>,
    /// Labelled points.
    pub markers: Vec<Marker>,
    /// Where the legend goes.
    pub legend: Legend,
    /// A second line under the title (smaller).
    pub subtitle: String,
}

/// Where a chart's legend goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Legend {
    /// Inside the plot, top right.
    #[default]
    TopRight,
    /// Inside the plot, top left.
    TopLeft,
    /// Inside the plot, bottom right.
    BottomRight,
    /// No legend.
    None,
}

/// "Nice" tick positions covering `[lo, hi]`, about `n` of them.
pub fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater)
        || !lo.is_finite()
        || !hi.is_finite()
    {
        return vec![lo];
    }
    let raw = (hi - lo) / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).ceil() * step;
    let mut t = Vec::new();
    let mut v = start;
    while v <= hi + step * 1e-9 {
        t.push(if v.abs() < step * 1e-9 { 0.0 } else { v });
        v += step;
    }
    t
}

/// Formats a tick value compactly.
pub fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        if (m.abs() - 1.0).abs() < 1e-9 {
            return format!("{}1e{}", if v < 0.0 { "-" } else { "" }, e as i32);
        }
        return format!("{m:.1}e{}", e as i32);
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

impl LineChart {
    fn ranges(&self) -> ([f64; 2], [f64; 2]) {
        let pts = self
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| p[0].is_finite() && p[1].is_finite() && (!self.log_y || p[1] > 0.0));
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in pts {
            x0 = x0.min(p[0]);
            x1 = x1.max(p[0]);
            y0 = y0.min(p[1]);
            y1 = y1.max(p[1]);
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        if x1 <= x0 {
            x1 = x0 + 1.0;
        }
        let xr = self.x_range.unwrap_or([x0, x1]);
        let yr = self.y_range.unwrap_or_else(|| {
            if self.log_y {
                let (a, b) = (
                    10f64.powf(y0.log10().floor()),
                    10f64.powf(y1.log10().ceil()),
                );
                [a, if b > a { b } else { a * 10.0 }]
            } else {
                let lo = if y0 >= 0.0 { 0.0 } else { y0 };
                let hi = if y1 > lo {
                    y1 + 0.05 * (y1 - lo)
                } else {
                    lo + 1.0
                };
                [lo, hi]
            }
        });
        (xr, yr)
    }

    /// Draws the chart into the rectangle `(x, y, w, h)` (axes, labels and all).
    pub fn draw(&self, x: f64, y: f64, w: f64, h: f64) -> String {
        let mut s = String::new();
        let mt = if self.subtitle.is_empty() { 26.0 } else { 40.0 };
        let (ml, mr, mb) = (62.0, 14.0, 42.0);
        let (px, py, pw, ph) = (x + ml, y + mt, w - ml - mr, h - mt - mb);
        let (xr, yr) = self.ranges();
        let area = PlotArea {
            px,
            py,
            pw,
            ph,
            xr,
            yr,
            log_y: self.log_y,
        };
        self.draw_titles(&mut s, x, y, w);
        self.draw_grid(&mut s, &area);
        self.draw_axis_labels(&mut s, &area, x, y, h);
        // The clip path's id, from the rectangle: unique per chart of a figure.
        let clip = format!("clip{}", (x * 7919.0 + y * 104729.0 + w * 13.0 + h) as u64);
        self.draw_lines(&mut s, &area, &clip);
        self.draw_legend(&mut s, &area);
        s
    }

    /// The title, centred at the top of the rectangle `(x, y, w, …)`, and the subtitle
    /// under it when there is one.
    fn draw_titles(&self, s: &mut String, x: f64, y: f64, w: f64) {
        *s += &text(
            x + w / 2.0,
            y + 16.0,
            &self.title,
            13.0,
            "middle",
            "font-weight=\"bold\"",
        );
        if !self.subtitle.is_empty() {
            *s += &text(
                x + w / 2.0,
                y + 31.0,
                &self.subtitle,
                11.0,
                "middle",
                "fill=\"#444\"",
            );
        }
    }

    /// The grid lines and tick labels of both axes, then the plot rectangle's frame.
    fn draw_grid(&self, s: &mut String, area: &PlotArea) {
        let (xr, yr) = (area.xr, area.yr);
        let (px, py, pw, ph) = (area.px, area.py, area.pw, area.ph);
        let (fx, fy) = (|v| area.fx(v), |v| area.fy(v));
        // Grid and ticks.
        let xt = nice_ticks(xr[0], xr[1], ((pw / 70.0) as usize).max(2));
        for t in &xt {
            let tx = fx(*t);
            let _ = writeln!(
                s,
                "<line x1=\"{tx:.1}\" y1=\"{py:.1}\" x2=\"{tx:.1}\" y2=\"{:.1}\" stroke=\"#e3e3e3\"/>",
                py + ph
            );
            *s += &text(tx, py + ph + 14.0, &fmt_tick(*t), 11.0, "middle", "");
        }
        let yt: Vec<f64> = if self.log_y {
            let (a, b) = (yr[0].log10().floor() as i32, yr[1].log10().ceil() as i32);
            let every = (((b - a) as f64) / 6.0).ceil().max(1.0) as i32;
            (a..=b)
                .filter(|e| (e - a) % every == 0)
                .map(|e| 10f64.powi(e))
                .filter(|v| *v >= yr[0] * 0.999 && *v <= yr[1] * 1.001)
                .collect()
        } else {
            nice_ticks(yr[0], yr[1], ((ph / 40.0) as usize).max(2))
        };
        for t in &yt {
            let ty = fy(*t);
            let _ = writeln!(
                s,
                "<line x1=\"{px:.1}\" y1=\"{ty:.1}\" x2=\"{:.1}\" y2=\"{ty:.1}\" stroke=\"#e3e3e3\"/>",
                px + pw
            );
            *s += &text(px - 5.0, ty + 4.0, &fmt_tick(*t), 11.0, "end", "");
        }
        let _ = writeln!(
                s,
                "<rect x=\"{px:.1}\" y=\"{py:.1}\" width=\"{pw:.1}\" height=\"{ph:.1}\" fill=\"none\" stroke=\"#444\"/>"
        );
    }

    /// The x label under the plot and the y label, rotated, left of it (the chart's
    /// rectangle is `(x, y, …, h)`).
    fn draw_axis_labels(&self, s: &mut String, area: &PlotArea, x: f64, y: f64, h: f64) {
        let (px, py, pw, ph) = (area.px, area.py, area.pw, area.ph);
        *s += &text(
            px + pw / 2.0,
            y + h - 8.0,
            &self.x_label,
            12.0,
            "middle",
            "",
        );
        let (lx, ly) = (x + 14.0, py + ph / 2.0);
        *s += &text(
            lx,
            ly,
            &self.y_label,
            12.0,
            "middle",
            &format!("transform=\"rotate(-90 {lx:.1} {ly:.1})\""),
        );
    }

    /// The series as paths (a dot for a single point), clipped to the plot rectangle by the
    /// clip path `clip`, then the markers with their labels.
    fn draw_lines(&self, s: &mut String, area: &PlotArea, clip: &str) {
        let (px, py, pw, ph) = (area.px, area.py, area.pw, area.ph);
        let (fx, fy) = (|v| area.fx(v), |v| area.fy(v));
        // Lines, clipped to the plot rectangle.
        let _ = writeln!(
                s,
                "<clipPath id=\"{clip}\"><rect x=\"{px:.1}\" y=\"{py:.1}\" width=\"{pw:.1}\" height=\"{ph:.1}\"/></clipPath>\n<g clip-path=\"url(#{clip})\">"
        );
        for se in &self.series {
            let mut d = String::new();
            let mut pen = false;
            for p in &se.points {
                let ok = p[0].is_finite() && p[1].is_finite() && (!self.log_y || p[1] > 0.0);
                if !ok {
                    pen = false;
                    continue;
                }
                let _ = write!(
                    d,
                    "{}{:.2},{:.2} ",
                    if pen { "L" } else { "M" },
                    fx(p[0]),
                    fy(p[1])
                );
                pen = true;
            }
            let dash = if se.dashed {
                " stroke-dasharray=\"6 3\""
            } else {
                ""
            };
            let _ = writeln!(
                s,
                "<path d=\"{d}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.6\"{dash}/>",
                se.color
            );
            if se.points.len() == 1 {
                let p = se.points[0];
                let _ = writeln!(
                    s,
                    "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{}\"/>",
                    fx(p[0]),
                    fy(p[1]),
                    se.color
                );
            }
        }
        *s += "</g>\n";
        for m in &self.markers {
            let (tx, ty) = (fx(m.at[0]), fy(m.at[1]));
            let _ = writeln!(s, "<circle cx=\"{tx:.1}\" cy=\"{ty:.1}\" r=\"3.5\" fill=\"none\" stroke=\"#000\" stroke-width=\"1.2\"/>");
            let anchor = if tx > px + pw * 0.6 { "end" } else { "start" };
            let dx = if anchor == "end" { -6.0 } else { 6.0 };
            *s += &text(tx + dx, ty - 6.0, &m.label, 11.0, anchor, "");
        }
    }

    /// The legend, when it is wanted and a series has a name: a box in the corner
    /// [`LineChart::legend`] names, a line and the name of each series.
    fn draw_legend(&self, s: &mut String, area: &PlotArea) {
        let (px, py, pw, ph) = (area.px, area.py, area.pw, area.ph);
        // Legend.
        let show = self.legend != Legend::None && self.series.iter().any(|s| !s.name.is_empty());
        if show {
            let lw = self
                .series
                .iter()
                .map(|s| s.name.chars().count())
                .max()
                .unwrap_or(0) as f64
                * 6.4
                + 34.0;
            let lh = 16.0 * self.series.len() as f64 + 6.0;
            let lx = if self.legend == Legend::TopLeft {
                px + 6.0
            } else {
                px + pw - lw - 6.0
            };
            let ly = if self.legend == Legend::BottomRight {
                py + ph - lh - 6.0
            } else {
                py + 6.0
            };
            let _ = writeln!(
                s,
                "<rect x=\"{lx:.1}\" y=\"{ly:.1}\" width=\"{lw:.1}\" height=\"{lh:.1}\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#bbb\"/>"
            );
            for (i, se) in self.series.iter().enumerate() {
                let yy = ly + 14.0 + 16.0 * i as f64;
                let dash = if se.dashed {
                    " stroke-dasharray=\"6 3\""
                } else {
                    ""
                };
                let _ = writeln!(
                    s,
                    "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"2\"{dash}/>",
                    lx + 6.0,
                    yy - 4.0,
                    lx + 26.0,
                    yy - 4.0,
                    se.color
                );
                *s += &text(lx + 30.0, yy, &se.name, 11.0, "start", "");
            }
        }
    }

    /// The chart as a standalone SVG of `w×h` px.
    pub fn svg(&self, w: f64, h: f64) -> String {
        document(w, h, &self.draw(0.0, 0.0, w, h))
    }
}

/// Where a [`LineChart`] plots: the rectangle `(px, py, pw, ph)` inside its margins and the
/// ranges `xr`, `yr` it spans (`yr` logarithmically when `log_y`).
struct PlotArea {
    px: f64,
    py: f64,
    pw: f64,
    ph: f64,
    xr: [f64; 2],
    yr: [f64; 2],
    log_y: bool,
}

impl PlotArea {
    /// The x coordinate of the value `v`.
    #[inline]
    fn fx(&self, v: f64) -> f64 {
        let (px, pw, xr) = (self.px, self.pw, self.xr);
        px + pw * (v - xr[0]) / (xr[1] - xr[0])
    }

    /// The y coordinate of the value `v` (upwards; logarithmic when `log_y`).
    #[inline]
    fn fy(&self, v: f64) -> f64 {
        let (py, ph, yr) = (self.py, self.ph, self.yr);
        let t = if self.log_y {
            (v.log10() - yr[0].log10()) / (yr[1].log10() - yr[0].log10())
        } else {
            (v - yr[0]) / (yr[1] - yr[0])
        };
        py + ph * (1.0 - t)
    }
}

/// A colour scale: values in `[lo, hi]` (logarithmic if `log`) to viridis.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorScale {
    /// Lowest value (its colour also below).
    pub lo: f64,
    /// Highest value (its colour also above).
    pub hi: f64,
    /// Logarithmic.
    pub log: bool,
    /// Label of the colour bar.
    pub label: String,
}

/// Viridis (matplotlib's), sampled at 9 stops and interpolated linearly in sRGB.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Viridis at `t ∈ [0, 1]`.
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = t * (VIRIDIS.len() - 1) as f64;
    let i = (f.floor() as usize).min(VIRIDIS.len() - 2);
    let a = f - i as f64;
    let c = |k: usize| (VIRIDIS[i][k] * (1.0 - a) + VIRIDIS[i + 1][k] * a).round() as u8;
    [c(0), c(1), c(2)]
}

impl ColorScale {
    /// Position of `v` on the scale, 0..1 (clamped).
    pub fn t(&self, v: f64) -> f64 {
        let t = if self.log {
            (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        };
        t.clamp(0.0, 1.0)
    }
    /// The colour of `v`.
    pub fn color(&self, v: f64) -> [u8; 3] {
        viridis(self.t(v))
    }
    /// Tick values for the bar.
    pub fn ticks(&self) -> Vec<f64> {
        if self.log {
            let (a, b) = (self.lo.log2().ceil() as i32, self.hi.log2().floor() as i32);
            let every = (((b - a) as f64) / 8.0).ceil().max(1.0) as i32;
            (a..=b)
                .filter(|e| (e - a) % every == 0)
                .map(|e| 2f64.powi(e))
                .collect()
        } else {
            nice_ticks(self.lo, self.hi, 6)
        }
    }
}

/// A horizontal colour bar of `len×12` px at `(x, y)`, ticks and label below.
pub fn colorbar(x: f64, y: f64, len: f64, scale: &ColorScale) -> String {
    let n = 256;
    let mut rgba = Vec::with_capacity(n * 4);
    for i in 0..n {
        let c = viridis(i as f64 / (n - 1) as f64);
        rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
    }
    let mut s = format!(
        "<image x=\"{x:.1}\" y=\"{y:.1}\" width=\"{len:.1}\" height=\"12\" preserveAspectRatio=\"none\" \
         style=\"image-rendering:pixelated\" href=\"{}\"/>\n<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{len:.1}\" height=\"12\" fill=\"none\" stroke=\"#444\"/>\n",
        png::data_uri(n as u32, 1, &rgba)
    );
    for t in scale.ticks() {
        let tx = x + len * scale.t(t);
        let _ = writeln!(
            s,
            "<line x1=\"{tx:.1}\" y1=\"{:.1}\" x2=\"{tx:.1}\" y2=\"{:.1}\" stroke=\"#444\"/>",
            y + 12.0,
            y + 16.0
        );
        let lab = if scale.log && t < 1.0 {
            format!("1/{}", fmt_tick(1.0 / t))
        } else {
            fmt_tick(t)
        };
        s += &text(tx, y + 28.0, &lab, 10.5, "middle", "");
    }
    s += &text(x + len / 2.0, y + 44.0, &scale.label, 12.0, "middle", "");
    s
}

/// An RGBA raster drawn into the box `(x, y, w, h)` (aspect kept, centred), with a title
/// (a second line after `\n`, if any, is drawn smaller).
#[allow(clippy::too_many_arguments)]
pub fn heat_panel(
    x: f64,
    y: f64,
    w: f64,
    h: f64,
    title: &str,
    iw: u32,
    ih: u32,
    rgba: &[u8],
) -> String {
    let (first, second) = title.split_once('\n').unwrap_or((title, ""));
    let th = if second.is_empty() { 18.0 } else { 32.0 };
    let k = (w / iw as f64).min((h - th) / ih as f64);
    let (dw, dh) = (iw as f64 * k, ih as f64 * k);
    let (ox, oy) = (x + (w - dw) / 2.0, y + th + (h - th - dh) / 2.0);
    let mut s = text(
        x + w / 2.0,
        y + 13.0,
        first,
        12.0,
        "middle",
        "font-weight=\"bold\"",
    );
    if !second.is_empty() {
        s += &text(
            x + w / 2.0,
            y + 27.0,
            second,
            11.0,
            "middle",
            "fill=\"#444\"",
        );
    }
    let _ = writeln!(
        s,
        "<image x=\"{ox:.1}\" y=\"{oy:.1}\" width=\"{dw:.1}\" height=\"{dh:.1}\" preserveAspectRatio=\"none\" \
         style=\"image-rendering:pixelated\" href=\"{}\"/>",
        png::data_uri(iw, ih, rgba)
    );
    s
}
