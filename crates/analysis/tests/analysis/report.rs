//! The whole analysis at a small size: numbers, JSON, SVG and HTML.
use mirrorball_analysis::{analyze, html, json, Config, Sizing};

#[test]
fn small_analysis_serialises_and_draws() {
    let cfg = Config {
        sizing: Sizing::Budget(6 * 16 * 16),
        drawing_budget: 6 * 8 * 8,
        ..Default::default()
    };
    let a = analyze(&cfg);
    let kinds = mirrorball_core::ProjectionKind::ALL.len();
    assert_eq!(a.report.projections.len(), kinds);
    let v: serde_json::Value = serde_json::from_str(&json(&a.report)).expect("valid JSON");
    assert_eq!(v["projections"].as_array().unwrap().len(), kinds);
    assert!(v["claims"].as_array().unwrap().len() > 20);
    let ids: Vec<&str> = a.figures.iter().map(|f| f.id.as_str()).collect();
    for id in [
        "analysis-solid-angle-heatmaps",
        "analysis-anisotropy-heatmaps",
        "analysis-zimmons-1d",
        "analysis-reflection-cone",
        "analysis-indexing-line",
        "analysis-indexing-meshes",
        "analysis-rims",
    ] {
        assert!(ids.contains(&id), "{id}");
    }
    for f in &a.figures {
        assert!(
            f.svg.starts_with("<svg") && f.svg.trim_end().ends_with("</svg>"),
            "{}",
            f.id
        );
    }
    let page = html(&a);
    assert!(page.contains("<svg") && page.contains("contradicted"));
}

/// Every number of `v` (a projection's entry as JSON, where a NaN or an infinity becomes
/// `null`) is finite: the paths of the ones that are not. `None` options are named in
/// `optional`.
fn non_finite(v: &serde_json::Value, path: &str, optional: &[&str], out: &mut Vec<String>) {
    match v {
        serde_json::Value::Null if !optional.iter().any(|o| path.ends_with(o)) => {
            out.push(path.to_string())
        }
        serde_json::Value::Number(n) if !n.as_f64().is_some_and(f64::is_finite) => {
            out.push(path.to_string())
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                non_finite(x, &format!("{path}[{i}]"), optional, out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                non_finite(x, &format!("{path}.{k}"), optional, out);
            }
        }
        _ => {}
    }
}

/// Every projection of core's table gets finite numbers in every row of its analysis
/// (texel statistics, each of Zimmons' walks, the cone), and each walk measures pixels.
#[test]
fn every_projection_in_the_table_gets_finite_numbers_in_every_row() {
    use mirrorball_analysis::analyze_projection;
    use mirrorball_core::ProjectionKind;
    let mut bad = Vec::new();
    for kind in ProjectionKind::ALL {
        let p = kind.default_projection();
        let (entry, figures) = analyze_projection(&p, 64, 6 * 16 * 16);
        let v = serde_json::to_value(&entry).unwrap();
        non_finite(&v, kind.name(), &[".crossover"], &mut bad);
        for w in &entry.profile.walks {
            assert!(
                !w.degrees.is_empty() && w.degrees.iter().all(|d| d.is_finite() && *d > 0.0),
                "{kind} {}: {:?}",
                w.name,
                w.degrees
            );
            assert!(w.min <= w.max && w.ratio >= 1.0, "{kind} {}: {w:?}", w.name);
        }
        for f in &figures {
            // The text of the drawing, its embedded pictures' base64 left out.
            let mut text = String::new();
            for (i, part) in f.svg.split("base64,").enumerate() {
                let part = if i == 0 {
                    part
                } else {
                    part.split_once('"').map_or("", |p| p.1)
                };
                text.push_str(part);
            }
            for word in ["NaN", "inf"] {
                if let Some(at) = text.find(word) {
                    let near = &text[at.saturating_sub(80)..(at + 20).min(text.len())];
                    bad.push(format!("{kind}: {word} in {}: …{near}…", f.id));
                }
            }
        }
    }
    assert!(bad.is_empty(), "not finite: {bad:?}");
}
