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
