//! A plain linear-light raster: the pixels of one layer (face) of an environment map.

/// A rectangular raster of linear-light `f32` texels, RGB or RGBA, interleaved, stored
/// top row first (row 0 is the top of the picture as a person looks at the file).
///
/// ```
/// use mirrorball_core::Image;
/// let mut img = Image::new(4, 2, 3);
/// img.set(1, 0, &[1.0, 0.5, 0.25]);
/// assert_eq!(img.get(1, 0), &[1.0, 0.5, 0.25]);
/// assert_eq!(img.data().len(), 4 * 2 * 3);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    channels: usize,
    data: Vec<f32>,
}

impl Image {
    /// A black image. `channels` must be 3 (RGB) or 4 (RGBA), or 1 for one plane of a
    /// planar picture (a YUV frame's Y, U or V), which [`Remap`](crate::Remap), layouts and
    /// stereo pairs convert and arrange alone.
    ///
    /// # Panics
    /// If `channels` is not 1, 3 or 4. Callers validating user input use
    /// [`Image::from_vec`].
    pub fn new(width: u32, height: u32, channels: usize) -> Image {
        assert!(matches!(channels, 1 | 3 | 4), "channels must be 1, 3 or 4");
        let len = width as usize * height as usize * channels;
        Image {
            width,
            height,
            channels,
            data: vec![0.0; len],
        }
    }

    /// Wraps interleaved texels, checking that the length matches.
    pub fn from_vec(width: u32, height: u32, channels: usize, data: Vec<f32>) -> Option<Image> {
        let ok = (channels == 3 || channels == 4)
            && data.len() == width as usize * height as usize * channels;
        ok.then_some(Image {
            width,
            height,
            channels,
            data,
        })
    }

    /// Width in texels.
    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in texels.
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }
    /// 3 for RGB, 4 for RGBA.
    #[inline]
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// The interleaved texels, top row first.
    #[inline]
    pub fn data(&self) -> &[f32] {
        &self.data
    }
    /// The interleaved texels, mutably.
    #[inline]
    pub fn data_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }
    /// Gives up the texel buffer.
    pub fn into_vec(self) -> Vec<f32> {
        self.data
    }
    /// Row `y` as interleaved texels.
    #[inline]
    pub fn row(&self, y: u32) -> &[f32] {
        let n = self.width as usize * self.channels;
        &self.data[y as usize * n..(y as usize + 1) * n]
    }
    /// The texel at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> &[f32] {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        &self.data[i..i + self.channels]
    }
    /// Sets the texel at column `x`, row `y` (extra channels in `v` are ignored; missing ones
    /// are left as they were).
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, v: &[f32]) {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        let n = self.channels.min(v.len());
        self.data[i..i + n].copy_from_slice(&v[..n]);
    }

    /// Copies a `w`×`h` block with its top-left corner at (`x`, `y`) into a new image.
    /// Returns `None` if the block does not fit.
    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> Option<Image> {
        if x.checked_add(w)? > self.width || y.checked_add(h)? > self.height {
            return None;
        }
        let c = self.channels;
        let mut out = Image::new(w, h, c);
        for row in 0..h {
            let src = &self.row(y + row)[x as usize * c..(x + w) as usize * c];
            let dst = (row as usize * w as usize) * c;
            out.data[dst..dst + src.len()].copy_from_slice(src);
        }
        Some(out)
    }

    /// Pastes `src` with its top-left corner at (`x`, `y`). Parts outside are clipped.
    pub fn paste(&mut self, src: &Image, x: u32, y: u32) {
        if x >= self.width {
            return;
        }
        // The part of each source row that lands inside, copied a row at a time.
        let cols = src.width.min(self.width - x) as usize;
        let (c, sc, dc) = (self.channels.min(src.channels), src.channels, self.channels);
        for row in 0..src.height {
            let ty = y as usize + row as usize;
            if ty >= self.height as usize {
                break;
            }
            let s = &src.data[row as usize * src.width as usize * sc..][..cols * sc];
            let at = (ty * self.width as usize + x as usize) * dc;
            let d = &mut self.data[at..at + cols * dc];
            if sc == dc {
                d.copy_from_slice(s);
            } else {
                for (d, s) in d.chunks_exact_mut(dc).zip(s.chunks_exact(sc)) {
                    d[..c].copy_from_slice(&s[..c]);
                }
            }
        }
    }

    /// The same picture rotated by 180 degrees.
    pub fn rotated_180(&self) -> Image {
        let mut out = self.clone();
        let c = self.channels;
        let n = self.data.len() / c;
        for i in 0..n {
            let j = n - 1 - i;
            out.data[i * c..i * c + c].copy_from_slice(&self.data[j * c..j * c + c]);
        }
        out
    }

    /// The texel at picture position `(x, y)` (texel centres at integers), bilinearly
    /// between the four texels around it, the position clamped to the columns `0..width`
    /// and the rows `rows.0..rows.1`: `channels()` values written to `out`.
    pub fn bilinear_clamped(&self, (x, y): (f64, f64), rows: (u32, u32), out: &mut [f32]) {
        let split = |v: f64, lo: u32, hi: u32| {
            let f = v.clamp(lo as f64, (hi - 1) as f64);
            let i = (f.floor() as u32).min(hi.saturating_sub(2).max(lo));
            let t = (f - i as f64) as f32;
            (i, (i + 1).min(hi - 1), t)
        };
        let (xa, xb, tx) = split(x, 0, self.width);
        let (ya, yb, ty) = split(y, rows.0, rows.1);
        let (a, b) = (self.get(xa, ya), self.get(xb, ya));
        let (c, d) = (self.get(xa, yb), self.get(xb, yb));
        for k in 0..self.channels {
            let top = a[k] + (b[k] - a[k]) * tx;
            let bottom = c[k] + (d[k] - c[k]) * tx;
            out[k] = top + (bottom - top) * ty;
        }
    }

    /// The same picture mirrored left to right (`horizontal`) or top to bottom.
    pub fn flipped(&self, horizontal: bool) -> Image {
        let mut out = self.clone();
        let (w, h) = (self.width, self.height);
        for y in 0..h {
            for x in 0..w {
                let (sx, sy) = if horizontal {
                    (w - 1 - x, y)
                } else {
                    (x, h - 1 - y)
                };
                out.set(x, y, self.get(sx, sy));
            }
        }
        out
    }

    /// The same texels with `channels` channels: dropping alpha, or adding alpha = 1.
    pub fn with_channels(&self, channels: usize) -> Image {
        if channels == self.channels {
            return self.clone();
        }
        let mut out = Image::new(self.width, self.height, channels);
        for (d, s) in out
            .data
            .chunks_exact_mut(channels)
            .zip(self.data.chunks_exact(self.channels))
        {
            d[..3].copy_from_slice(&s[..3]);
            if channels == 4 {
                d[3] = 1.0;
            }
        }
        out
    }

    /// Multiplies the colour channels (not alpha) by `k`.
    pub fn scale(&mut self, k: f32) {
        let c = self.channels;
        for px in self.data.chunks_exact_mut(c) {
            for v in &mut px[..3] {
                *v *= k;
            }
        }
    }
}

impl Image {
    /// An image whose rows `f(y, row)` fills, in parallel; each row is zero when `f` gets it.
    ///
    /// Rows are zeroed by the thread that fills them, right before, rather than all at once
    /// by the allocator on one thread: a large output so costs one pass over memory, not two.
    pub(crate) fn par_rows<F>(width: u32, height: u32, channels: usize, f: F) -> Image
    where
        F: Fn(usize, &mut [f32]) + Sync + Send,
    {
        use rayon::prelude::*;
        use std::mem::MaybeUninit;
        assert!(matches!(channels, 1 | 3 | 4), "channels must be 1, 3 or 4");
        let row_len = width as usize * channels;
        let len = row_len * height as usize;
        let mut data: Vec<f32> = Vec::with_capacity(len);
        if row_len > 0 {
            data.spare_capacity_mut()[..len]
                .par_chunks_mut(row_len)
                .enumerate()
                .for_each(|(y, row)| {
                    for v in row.iter_mut() {
                        v.write(0.0);
                    }
                    // SAFETY: every element of `row` was initialised just above, and
                    // `MaybeUninit<f32>` has the layout of `f32`.
                    let row = unsafe { &mut *(row as *mut [MaybeUninit<f32>] as *mut [f32]) };
                    f(y, row);
                });
        }
        // SAFETY: all `len` elements were initialised by the loop above (each row once).
        unsafe { data.set_len(len) };
        Image {
            width,
            height,
            channels,
            data,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Image;

    /// `paste` as a texel-by-texel copy: every texel inside, its first `min(channels)`
    /// values, the rest of the destination untouched.
    fn paste_reference(dst: &mut Image, src: &Image, x: u32, y: u32) {
        for row in 0..src.height() {
            for col in 0..src.width() {
                let (tx, ty) = (x + col, y + row);
                if tx < dst.width() && ty < dst.height() {
                    let v = src.get(col, row).to_vec();
                    dst.set(tx, ty, &v);
                }
            }
        }
    }

    #[test]
    fn paste_copies_each_texel_inside_and_clips_the_rest() {
        let numbered = |w: u32, h: u32, c: usize, base: f32| {
            let data = (0..w as usize * h as usize * c)
                .map(|i| base + i as f32)
                .collect();
            Image::from_vec(w, h, c, data).unwrap()
        };
        for (dc, sc) in [(3, 3), (4, 4), (4, 3), (3, 4)] {
            for (x, y) in [(0, 0), (2, 1), (5, 3), (6, 0), (0, 4), (9, 9)] {
                let src = numbered(4, 3, sc, 1000.0);
                let mut a = numbered(7, 5, dc, 0.0);
                let mut b = a.clone();
                a.paste(&src, x, y);
                paste_reference(&mut b, &src, x, y);
                assert_eq!(a.data(), b.data(), "{sc} into {dc} channels at ({x}, {y})");
            }
        }
    }
}
