//! The environment seen behind the objects: along each pixel's primary ray, filtered over
//! the pixel's cone of rays with a footprint sampler, or swept across a camera pan
//! ([`super::blur`]).

use super::prepare::{Prepared, Shaded};

impl Prepared<'_> {
    /// The environment seen along the primary ray of a sample that hits nothing.
    pub(super) fn background(&self, fx: f32, fy: f32) -> Shaded {
        if !self.scene.background && !self.settings.aovs {
            return Shaded::default();
        }
        let (x, y) = self.ndc(fx, fy);
        let (_, dir) = self.rays.ray(x, y);
        let mut out = Shaded {
            r: dir,
            win_depth: 1.0,
            st: [0.0, 0.0, -2.0],
            ..Default::default()
        };
        if !self.scene.background {
            return out;
        }
        let d = self.attach(dir);
        let (c, st) = match (&self.sampler, self.settings.indexing, &self.prev_rays) {
            (_, _, Some(prev)) => {
                // Greene §9: the path the pixel's ray sweeps between the two frames, sampled
                // about once per texel along its length (at most 64 samples) and averaged.
                let d0 = self.attach(prev.ray(x, y).1);
                let (_, st) = self.read_dir(d);
                (self.sweep(d0, d), st)
            }
            (Some(_), _, None) => {
                // A footprint filter: the pixel's cone of camera rays.
                let h = 0.5;
                let corners = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(dx, dy)| {
                    let (cx, cy) = self.ndc(fx + dx, fy + dy);
                    self.attach(self.rays.ray(cx, cy).1)
                });
                let (_, st) = self.read_dir(d);
                (self.cone_read(d, &corners), st)
            }
            _ => self.read_dir(d),
        };
        out.color = c;
        out.st = [st[0], st[1], -2.0];
        out
    }
}
