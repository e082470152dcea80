//! Planar YUV frames converted as they are: each plane (Y, then U and V at their own,
//! subsampled size) is one channel of codes, converted by a [`Remap`] planned for that
//! plane's extent, as FFmpeg's `v360` converts planes; never through RGB. Codes stay codes
//! (a 10-bit frame is converted and written 10-bit), with the plan's antialiasing.
//!
//! A plane's codes are read as floats less a neutral value (black for Y, no colour for U
//! and V), so that what no layer covers (a cross's empty cells, a view's uncovered texels)
//! comes out black and grey instead of green; the plan's weights sum to one, so the
//! neutral value added back leaves every covered texel as the codes' own weighted mean.

use mirrorball::load;
use mirrorball::{Error, ProjSpec};
use mirrorball_core::{
    EnvMap, Image, Layout, Projection, Remap, ResampleOptions, Stereo, WorldProjection,
};
use rayon::prelude::*;

/// How a planar YUV pixel format holds a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlaneFormat {
    /// FFmpeg's name (`-pix_fmt`).
    pub name: &'static str,
    /// Bits a code (8, 10, 12 or 16); codes over 8 bits take two bytes, little-endian.
    pub depth: u32,
    /// Chroma subsampling as shifts: 4:2:0 is (1, 1), 4:2:2 (1, 0), 4:4:4 (0, 0).
    pub shift: (u32, u32),
}

/// The planar YUV formats converted natively, by FFmpeg's names.
pub const FORMATS: &[PlaneFormat] = &[
    PlaneFormat::new("yuv420p", 8, (1, 1)),
    PlaneFormat::new("yuvj420p", 8, (1, 1)),
    PlaneFormat::new("yuv422p", 8, (1, 0)),
    PlaneFormat::new("yuvj422p", 8, (1, 0)),
    PlaneFormat::new("yuv444p", 8, (0, 0)),
    PlaneFormat::new("yuvj444p", 8, (0, 0)),
    PlaneFormat::new("yuv420p10le", 10, (1, 1)),
    PlaneFormat::new("yuv422p10le", 10, (1, 0)),
    PlaneFormat::new("yuv444p10le", 10, (0, 0)),
    PlaneFormat::new("yuv420p12le", 12, (1, 1)),
    PlaneFormat::new("yuv444p12le", 12, (0, 0)),
    PlaneFormat::new("yuv420p16le", 16, (1, 1)),
    PlaneFormat::new("yuv444p16le", 16, (0, 0)),
];

impl PlaneFormat {
    const fn new(name: &'static str, depth: u32, shift: (u32, u32)) -> PlaneFormat {
        PlaneFormat { name, depth, shift }
    }

    /// The format FFmpeg calls `name`, if converted natively.
    pub fn named(name: &str) -> Option<PlaneFormat> {
        FORMATS.iter().copied().find(|f| f.name == name)
    }

    /// Bytes a code takes.
    pub fn bytes(&self) -> usize {
        if self.depth > 8 {
            2
        } else {
            1
        }
    }

    /// The largest code.
    pub fn max_code(&self) -> f32 {
        ((1u32 << self.depth) - 1) as f32
    }

    /// Plane `k`'s extent in a `w`×`h` frame, or `None` if the subsampling does not divide
    /// the frame (an odd-sized 4:2:0 frame).
    pub fn plane_extent(&self, k: usize, (w, h): (u32, u32)) -> Option<(u32, u32)> {
        if k == 0 {
            return Some((w, h));
        }
        let (sx, sy) = self.shift;
        (w % (1 << sx) == 0 && h % (1 << sy) == 0).then_some((w >> sx, h >> sy))
    }

    /// The code of "nothing" in plane `k`: black for Y (16 scaled to the depth; 0 for the
    /// full-range `yuvj` formats), no colour for U and V.
    fn neutral(&self, k: usize) -> f32 {
        let scale = (1u32 << (self.depth - 8)) as f32;
        match k {
            0 if self.name.starts_with("yuvj") => 0.0,
            0 => 16.0 * scale,
            _ => 128.0 * scale,
        }
    }
}

/// One frame's three planes, each `width × height` codes, rows packed (no padding).
#[derive(Clone, Debug, Default)]
pub struct Planes {
    /// Y, U, V.
    pub data: [Vec<u8>; 3],
    /// Each plane's width and height.
    pub extent: [(u32, u32); 3],
}

/// How the frames' pictures are read: what `convert` decides from its flags, the file's
/// metadata, or the picture's shape (the first frame's decision holds for every frame).
#[derive(Clone, Debug)]
pub struct Reading {
    /// The input's name, for messages.
    pub input: String,
    /// The projection (`None`: guessed from the picture's shape).
    pub from: Option<ProjSpec>,
    /// The layers' layout in the picture.
    pub layout: Option<Layout>,
    /// How the picture holds its eyes, and how many are read.
    pub stereo: (Stereo, usize),
}

impl Reading {
    /// Plane `img` read as the frame's picture: the eyes read, each a map.
    fn eyes(&self, img: Image) -> Result<(Vec<EnvMap>, String), Error> {
        let (left, right, said) = load::interpret_eyes(
            &self.input,
            img,
            self.stereo,
            self.from.as_ref(),
            self.layout,
            None,
            None,
            |_| String::new(),
        )?;
        Ok((std::iter::once(left).chain(right).collect(), said))
    }
}

/// One plane's plan: the conversion of each eye's layers.
struct PlanePlan {
    remap: Remap,
    neutral: f32,
}

/// The conversion of every frame: a plan for Y and one for U and V (their extent), the
/// output's layout and stereo arrangement.
pub struct Converter {
    format: PlaneFormat,
    reading: Reading,
    plans: [PlanePlan; 2],
    layout: Layout,
    stereo: Stereo,
    /// The output frame's width and height.
    pub out_extent: (u32, u32),
    /// How much U and V as made are reduced (2×2 means for 4:2:0) to their planes' size:
    /// none where the layout halves with them.
    chroma_shift: (u32, u32),
    /// What was decided about the input (its projection, layout and eyes), for people.
    pub said: String,
}

/// What the output is: its projection, size (`None`: the input's natural size, made even),
/// layout and eyes, and the resampler's settings.
pub struct Target {
    /// The output projection.
    pub dst: Projection,
    /// The output's size as `--size` gives it.
    pub size: Option<u32>,
    /// The layers' layout in the output picture.
    pub layout: Layout,
    /// How the output picture holds its eyes.
    pub stereo: Stereo,
    /// Rotation, samples.
    pub resample: ResampleOptions,
}

fn packed_extent(layout: Layout, layers: usize, (w, h): (u32, u32)) -> (u32, u32) {
    if layers == 1 {
        (w, h)
    } else {
        layout.extent(layers, w, h)
    }
}

impl Converter {
    /// Plans the conversion of `format` frames of `extent` to `target`.
    pub fn new(
        format: PlaneFormat,
        extent: (u32, u32),
        reading: Reading,
        target: &Target,
    ) -> Result<Converter, Error> {
        let input = &reading.input;
        let chroma = format.plane_extent(1, extent).ok_or_else(|| {
            Error::input(format!(
                "{input}: its {}x{} {} frames have an odd size, which their half-size colour \
                 planes cannot hold",
                extent.0, extent.1, format.name
            ))
        })?;
        let (luma, said) = reading.eyes(Image::new(extent.0, extent.1, 1))?;
        let (chroma_eyes, _) = reading.eyes(Image::new(chroma.0, chroma.1, 1))?;
        let (src, csrc) = (&luma[0], &chroma_eyes[0]);
        let dst = target.dst;
        let layers = dst.layer_count();
        let (sx, sy) = format.shift;
        let even = |n: u32, s: u32| n >> s << s == n;
        let layer = match target.size {
            Some(size) => dst.layer_extent(size),
            None => {
                // The natural size, made smaller until the subsampling divides each layer.
                let mut size = src.natural_size(dst.kind()).max(2);
                loop {
                    let (w, h) = dst.layer_extent(size);
                    if (even(w, sx) && even(h, sy)) || size <= 2 {
                        break (w, h);
                    }
                    size -= 1;
                }
            }
        };
        if !(even(layer.0, sx) && even(layer.1, sy)) {
            return Err(Error::request(format!(
                "--size: layers of {}x{} cannot be halved for the {} colour planes: give an \
                 even size",
                layer.0, layer.1, format.name
            )));
        }
        let packed = packed_extent(target.layout, layers, layer);
        let picture = target.stereo.extent(packed.0, packed.1);
        if !(even(picture.0, sx) && even(picture.1, sy)) {
            return Err(Error::request(format!(
                "--size: a {}x{} picture does not hold {} with even sizes: give another --size",
                picture.0, picture.1, format.name
            )));
        }
        // The colour planes' layers at their own size where the layout halves with them;
        // else (EAC's fixed border) made at the picture's size and halved.
        let mut clayer = (layer.0 >> sx, layer.1 >> sy);
        let cpacked = packed_extent(target.layout, layers, clayer);
        let halves =
            target.stereo.extent(cpacked.0, cpacked.1) == (picture.0 >> sx, picture.1 >> sy);
        let chroma_shift = if halves {
            (0, 0)
        } else {
            clayer = layer;
            (sx, sy)
        };
        let plan = |src: &EnvMap, out: (u32, u32), k: usize| PlanePlan {
            remap: Remap::with_extent(
                *src.projection(),
                (src.width(), src.height()),
                src.layers().len(),
                dst,
                out,
                &target.resample,
            ),
            neutral: format.neutral(k),
        };
        let plans = [plan(src, layer, 0), plan(csrc, clayer, 1)];
        // From here every frame is read as the first was: the projection decided.
        let reading = Reading {
            from: Some(
                ProjSpec::parse(&src.projection().to_string())
                    .map_err(|e| Error::input(format!("{input}: {e}")))?,
            ),
            ..reading
        };
        Ok(Converter {
            format,
            reading,
            plans,
            layout: target.layout,
            stereo: target.stereo,
            out_extent: picture,
            chroma_shift,
            said,
        })
    }

    /// The pixel format of the frames, in and out.
    pub fn format(&self) -> PlaneFormat {
        self.format
    }

    /// Converts one frame, plane by plane.
    pub fn convert(&self, frame: &Planes) -> Result<Planes, Error> {
        let mut out = Planes::default();
        for k in 0..3 {
            let plan = &self.plans[k.min(1)];
            let (w, h) = frame.extent[k];
            let img = self.read_plane(&frame.data[k], (w, h), plan.neutral);
            let (eyes, _) = self.reading.eyes(img)?;
            let mut pictures = Vec::with_capacity(eyes.len());
            for eye in &eyes {
                let made = plan
                    .remap
                    .apply(eye)
                    .map_err(|e| Error::input(format!("{}: {e}", self.reading.input)))?;
                pictures.push(if made.layers().len() == 1 {
                    made.layers()[0].clone()
                } else {
                    self.layout.pack(&made).ok_or_else(|| {
                        Error::request(format!("--layout {} does not fit", self.layout.name()))
                    })?
                });
            }
            // An output of two eyes from one read eye shows it to both.
            if self.stereo.eyes() == 2 && pictures.len() == 1 {
                pictures.push(pictures[0].clone());
            }
            let picture = if self.stereo.eyes() == 1 {
                pictures.swap_remove(0)
            } else {
                self.stereo
                    .join(pictures)
                    .ok_or_else(|| Error::input("the eyes differ in size"))?
            };
            let picture = match (k, self.chroma_shift) {
                (0, _) | (_, (0, 0)) => picture,
                (_, shift) => reduce(&picture, shift),
            };
            out.extent[k] = (picture.width(), picture.height());
            out.data[k] = self.write_plane(&picture, plan.neutral);
        }
        Ok(out)
    }

    /// A plane's codes as floats less `neutral`.
    fn read_plane(&self, bytes: &[u8], (w, h): (u32, u32), neutral: f32) -> Image {
        let mut img = Image::new(w, h, 1);
        let data = img.data_mut();
        if self.format.bytes() == 1 {
            data.par_iter_mut()
                .zip(bytes.par_iter())
                .for_each(|(v, &b)| *v = b as f32 - neutral);
        } else {
            data.par_iter_mut()
                .zip(bytes.par_chunks_exact(2))
                .for_each(|(v, b)| *v = u16::from_le_bytes([b[0], b[1]]) as f32 - neutral);
        }
        img
    }

    /// A converted plane as codes: the neutral value added back, rounded, clamped.
    fn write_plane(&self, img: &Image, neutral: f32) -> Vec<u8> {
        let max = self.format.max_code();
        let code = |v: f32| (v + neutral).round().clamp(0.0, max);
        let data = img.data();
        let mut out = vec![0u8; data.len() * self.format.bytes()];
        if self.format.bytes() == 1 {
            out.par_iter_mut()
                .zip(data.par_iter())
                .for_each(|(o, &v)| *o = code(v) as u8);
        } else {
            out.par_chunks_exact_mut(2)
                .zip(data.par_iter())
                .for_each(|(o, &v)| o.copy_from_slice(&(code(v) as u16).to_le_bytes()));
        }
        out
    }
}

/// A one-channel picture reduced by `(sx, sy)` halvings: each texel the mean of its block.
fn reduce(img: &Image, (sx, sy): (u32, u32)) -> Image {
    let (w, h) = (img.width() >> sx, img.height() >> sy);
    let (bw, bh) = (1usize << sx, 1usize << sy);
    let src = img.data();
    let sw = img.width() as usize;
    let mut out = Image::new(w, h, 1);
    let k = 1.0 / (bw * bh) as f32;
    out.data_mut()
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for dy in 0..bh {
                    let r = &src[(y * bh + dy) * sw + x * bw..][..bw];
                    sum += r.iter().sum::<f32>();
                }
                *o = sum * k;
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_frames_have_no_half_size_planes() {
        let f = PlaneFormat::named("yuv420p").unwrap();
        assert_eq!(f.plane_extent(1, (256, 128)), Some((128, 64)));
        assert_eq!(f.plane_extent(1, (255, 128)), None);
        let f = PlaneFormat::named("yuv444p").unwrap();
        assert_eq!(f.plane_extent(2, (255, 127)), Some((255, 127)));
        assert_eq!(
            PlaneFormat::named("yuv420p10le").unwrap().max_code(),
            1023.0
        );
    }
}
