//! Prefiltered lighting for the page: a GGX chain as `mirrorball prefilter` makes it (a cube,
//! level `m` at half the edge of level `m − 1` down to 1×1, level `m` prefiltered with the
//! roughness `mapping.roughness(m, levels)`; `mirrorball_filter::chain_lobes` and
//! `Prefilterer::render_chain`, the CLI's `prefilter` calls), and the nine SH coefficients
//! of `E/π` (`mirrorball_filter::sh::project`, then `Sh9::lambert`, no window: the CLI's
//! default `--sh-window none`).
//!
//! The page's roughness slider moves in steps of `1/`[`ROUGHNESS_STEPS`]; for each step the
//! header carries the level `mapping.level(roughness, levels)` (the inverse of the mapping,
//! the rule `prefilter` writes into its SH JSON as `roughness_to_level`: the page computes
//! no level itself), which the page reads with `textureLod`, trilinear between the two
//! levels around it. The Lambert material is `Σ cᵢ Kᵢ mᵢ(n)`: the coefficients, the basis's
//! constants `Kᵢ` ([`sh::CONSTANTS`]) and its monomials `mᵢ` (`web/glsl/lighting.glsl`,
//! [`sh::basis`]'s order).
//!
//! The payload, little-endian: `b"MBLT"`, `u32` length of a JSON header, the header (padded
//! with spaces to a multiple of 4: `size`, `levels`, `mapping`, `roughness` per level,
//! `roughnessToLevel`, `levelOf` (the level of roughness `i/ROUGHNESS_STEPS`, `i` = 0 …
//! `ROUGHNESS_STEPS`), `sh9` as nine `[r, g, b]`, `shConstants`, `basis`, `irradiance`),
//! then each level's
//! six faces in OpenGL's order (+X −X +Y −Y +Z −Z), row 0 (`t = 0`) first, RGBA as IEEE half
//! floats: what `texImage2D(TEXTURE_CUBE_MAP_POSITIVE_X + f, m, RGBA16F, …, HALF_FLOAT)`
//! takes as it is.

use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_filter::{
    chain_lobes, chain_work, sh, LobeKind, PrefilterOptions, Prefilterer, RoughnessMapping, Sh9,
};
use serde_json::json;
use std::sync::atomic::AtomicU64;
use std::sync::Arc;

/// The smallest and largest level-0 face edge the page may ask for.
pub const SIZES: std::ops::RangeInclusive<u32> = 8..=512;

/// The page's roughness slider has this many steps from 0 to 1.
pub const ROUGHNESS_STEPS: u32 = 100;

/// A prefiltered chain and the irradiance's SH9.
pub struct Lighting {
    /// Level 0's face edge (a power of two).
    pub size: u32,
    /// The roughness-to-level rule.
    pub mapping: RoughnessMapping,
    /// Level `m`: a cube of edge `size >> m`.
    pub chain: Vec<EnvMap>,
    /// The roughness of each level.
    pub roughness: Vec<f64>,
    /// Coefficients of `E/π`.
    pub irradiance: Sh9,
}

/// Checks a request: `size` a power of two in [`SIZES`], `mapping` a name `prefilter
/// --mapping` takes (a list is refused: the chain's length is the page's business).
pub fn request(
    size: Option<u32>,
    mapping: Option<&str>,
) -> Result<(u32, RoughnessMapping), String> {
    let size = size.unwrap_or(128);
    if !SIZES.contains(&size) || !size.is_power_of_two() {
        return Err(format!(
            "size {size}: the chain's level 0 must be a power of two in {}..={}",
            SIZES.start(),
            SIZES.end()
        ));
    }
    let m = mapping.unwrap_or("linear");
    match RoughnessMapping::parse(m) {
        Some(RoughnessMapping::Custom(_)) | None => {
            Err(format!("mapping '{m}' is not linear, ue4 or filament"))
        }
        Some(r) => Ok((size, r)),
    }
}

/// The work [`prefilter`] reports through `progress` for `map` at level-0 edge `size`
/// (`mirrorball_filter::chain_work`'s units).
pub fn work(map: &EnvMap, size: u32, mapping: &RoughnessMapping) -> u64 {
    let cube = ProjectionKind::Cube.default_projection();
    let lobes = chain_lobes(LobeKind::Ggx, mapping, levels(size));
    chain_work(map, &lobes, cube, size, &PrefilterOptions::default())
}

/// The levels of a full chain from edge `size` down to 1.
pub fn levels(size: u32) -> usize {
    (u32::BITS - size.max(1).leading_zeros()) as usize
}

/// Prefilters `map` (any projection) to a GGX cube chain of level-0 edge `size` and the
/// irradiance's SH9, counting the work done in `progress` ([`work`]).
pub fn prefilter(
    map: &EnvMap,
    size: u32,
    mapping: RoughnessMapping,
    progress: Arc<AtomicU64>,
) -> Lighting {
    let cube = ProjectionKind::Cube.default_projection();
    let n = levels(size);
    let lobes = chain_lobes(LobeKind::Ggx, &mapping, n);
    let opts = PrefilterOptions {
        progress: Some(progress),
        ..PrefilterOptions::default()
    };
    let chain =
        Prefilterer::for_chain(map, &lobes, cube, size, opts).render_chain(&lobes, cube, size);
    Lighting {
        size,
        roughness: (0..n).map(|m| mapping.roughness(m, n)).collect(),
        mapping,
        chain,
        irradiance: sh::project(map).lambert(),
    }
}

/// The level the page reads at each step of its roughness slider: `mapping.level(i/STEPS)`.
pub fn level_table(mapping: &RoughnessMapping, levels: usize) -> Vec<f64> {
    (0..=ROUGHNESS_STEPS)
        .map(|i| mapping.level(f64::from(i) / f64::from(ROUGHNESS_STEPS), levels))
        .collect()
}

/// The payload described in the module's docs.
pub fn encode(l: &Lighting) -> Vec<u8> {
    let header = json!({
        "size": l.size,
        "levels": l.chain.len(),
        "mapping": l.mapping.name(),
        "roughness": l.roughness,
        "roughnessToLevel": l.mapping.level_formula(),
        "levelOf": level_table(&l.mapping, l.chain.len()),
        "sh9": l.irradiance.coeffs.to_vec(),
        "shConstants": sh::CONSTANTS,
        "basis": sh::BASIS_TEXT,
        "irradiance": sh::IRRADIANCE_TEXT,
    });
    let mut json = header.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let texels: usize = l
        .chain
        .iter()
        .map(|m| m.layers().len() * (m.width() * m.height()) as usize)
        .sum();
    let mut out = Vec::with_capacity(8 + json.len() + 8 * texels);
    out.extend_from_slice(b"MBLT");
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    for level in &l.chain {
        for face in level.layers() {
            let c = face.channels();
            for t in face.data().chunks_exact(c) {
                let rgba = [t[0], t[1], t[2], if c > 3 { t[3] } else { 1.0 }];
                for v in rgba {
                    out.extend_from_slice(&half::f16::from_f32(v).to_bits().to_le_bytes());
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::glam::DVec3;

    #[test]
    fn requests_name_what_is_wrong() {
        assert!(request(Some(100), None)
            .unwrap_err()
            .contains("power of two"));
        assert!(request(Some(1024), None).unwrap_err().contains("8..=512"));
        assert!(request(None, Some("steep"))
            .unwrap_err()
            .contains("'steep'"));
        assert!(request(None, Some("0,0.5,1")).is_err());
        assert_eq!(request(None, Some("ue4")).unwrap().0, 128);
    }

    #[test]
    fn the_chain_and_irradiance_of_a_linear_sky() {
        // L(d) = 1 + d.y: its E/π is 1 + (2/3) n.y (Ramamoorthi & Hanrahan's Â₁/π = 2/3),
        // and every GGX level of it is 1 + k·r.y for some 0 < k ≤ 1 at the texel's r.
        let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 128, 3, |d| {
            let v = 1.0 + d.y as f32;
            [v, v, v, 1.0]
        });
        let l = prefilter(&src, 16, RoughnessMapping::Linear, Arc::default());
        assert_eq!(l.chain.len(), 5);
        assert_eq!(l.chain[4].width(), 1);
        assert_eq!(l.roughness, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        for n in [DVec3::Y, DVec3::NEG_Y, DVec3::X, DVec3::new(0.6, 0.8, 0.0)] {
            let e = l.irradiance.eval(n);
            assert!((e[0] - (1.0 + 2.0 / 3.0 * n.y)).abs() < 2e-3, "{n}: {e:?}");
        }
        let bytes = encode(&l);
        assert_eq!(&bytes[..4], b"MBLT");
        let hl = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
        let h: serde_json::Value = serde_json::from_slice(&bytes[8..8 + hl]).unwrap();
        assert_eq!(h["levels"], 5);
        let table = h["levelOf"].as_array().unwrap();
        assert_eq!(table.len(), ROUGHNESS_STEPS as usize + 1);
        assert_eq!(table[50], 2.0);
        assert_eq!(table[100], 4.0);
        assert_eq!(h["shConstants"].as_array().unwrap().len(), 9);
        let texels: usize = (0..5).map(|m| 6 * (16usize >> m).pow(2)).sum();
        assert_eq!(bytes.len(), 8 + hl + 8 * texels);
        // Level 0 (a mirror) at +Y's face centre is the sky's top: 2.
        let top = 8 + hl + 8 * (2 * 256 + 8 * 16 + 8);
        let v = half::f16::from_bits(u16::from_le_bytes([bytes[top], bytes[top + 1]])).to_f32();
        assert!((v - 2.0).abs() < 0.02, "{v}");
    }
}
