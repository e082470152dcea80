//! The diagnostic channels: recorded per band at the sample nearest each pixel's centre,
//! then put together into four images.

use super::prepare::Shaded;
use mirrorball_core::Image;

/// Diagnostic channels ("arbitrary output variables"), taken at the sample nearest each
/// pixel's centre.
#[derive(Clone, Debug)]
pub struct Aovs {
    /// `(u, v, layer)` actually read from the environment (for mode 1 with a sphere map, the
    /// interpolated GL `(s, 1 − t)`); layer −1 where the object reads no environment, −2 on
    /// the background (whose own coordinates are still given).
    pub st_face: Image,
    /// The reflected direction used, in world space (the view ray on the background).
    pub reflected: Image,
    /// The unit world-space normal (0 on the background).
    pub normal: Image,
    /// R: eye-space depth (distance along the view axis), G: window depth in `[0, 1]` as
    /// OpenGL's depth buffer holds it, B: coverage of the pixel by objects. 0, 1, 0 on the
    /// background.
    pub depth: Image,
}

/// One band's diagnostic channels as they are recorded: `(u, v, layer)`, reflected
/// direction, normal, and (eye depth, window depth, coverage), three floats a pixel each.
pub(super) struct AovBand([Vec<f32>; 4]);

impl AovBand {
    /// Zeroed channels for `pixels` pixels.
    pub(super) fn new(pixels: usize) -> AovBand {
        AovBand(std::array::from_fn(|_| vec![0.0f32; pixels * 3]))
    }

    /// What pixel `k` of the band shows, from its centre sample `sh`.
    pub(super) fn record(&mut self, k: usize, sh: &Shaded) {
        let k = k * 3;
        let [st, r, n, depth] = &mut self.0;
        st[k..k + 3].copy_from_slice(&sh.st);
        r[k..k + 3].copy_from_slice(&sh.r.to_array());
        n[k..k + 3].copy_from_slice(&sh.n.to_array());
        depth[k] = sh.eye_depth;
        depth[k + 1] = sh.win_depth;
    }

    /// The fraction of pixel `k` covered by objects.
    pub(super) fn coverage(&mut self, k: usize, cov: f32) {
        self.0[3][k * 3 + 2] = cov;
    }
}

/// The bands' channels, top band first, as `w×h` images.
pub(super) fn assemble<'a>(bands: impl Iterator<Item = &'a AovBand>, w: u32, h: u32) -> Aovs {
    let mut imgs: [Image; 4] = std::array::from_fn(|_| Image::new(w, h, 3));
    let mut offset = 0usize;
    for band in bands {
        let n = band.0[0].len();
        for (img, r) in imgs.iter_mut().zip(band.0.iter()) {
            img.data_mut()[offset..offset + n].copy_from_slice(r);
        }
        offset += n;
    }
    let [st_face, reflected, normal, depth] = imgs;
    Aovs {
        st_face,
        reflected,
        normal,
        depth,
    }
}
