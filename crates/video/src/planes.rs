//! Planar YUV frames converted as they are: each plane (Y, then U and V at their own,
//! subsampled size) is one channel of codes, converted by a [`Remap`] planned for that
//! plane's extent, as FFmpeg's `v360` converts planes; never through RGB. Codes stay codes
//! (a 10-bit frame is converted and written 10-bit), with the plan's antialiasing.
//!
//! A plane's codes are read as floats less a neutral value (black for Y, no colour for U
//! and V), so that what no layer covers (a cross's empty cells, a view's uncovered texels)
//! comes out black and grey instead of green; the plan's weights sum to one, so the
//! neutral value added back leaves every covered texel as the codes' own weighted mean.

use mirrorball::frames::packing::{Packing, Picture, PlaneCodes};
use mirrorball::load;
use mirrorball::{Error, ProjSpec};
use mirrorball_core::{
    EnvMap, Image, Layout, Plane, Projection, Remap, ResampleOptions, Stereo, WorldProjection,
};
use rayon::prelude::*;
use std::sync::Mutex;

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

/// One plane's plan: the conversion of each eye's layers, and where one eye becomes one
/// picture, how its rows are encoded as they are made.
struct PlanePlan {
    remap: Remap,
    neutral: f32,
    packed: Option<Packed>,
}

/// A plane made and encoded row by row, with no map of the layers and no packed float
/// picture: the packing's rows from the plan's rows (strips, crosses, one layer), or turned
/// cells (EAC, v360's cells) from the plan laid out as the picture
/// ([`Packing::lay_out`]).
struct Packed {
    packing: Packing,
    laid: Option<(Remap, Picture)>,
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
    /// Each plane's floats of the last frame, filled again by the next.
    scratch: Mutex<[Option<Image>; 3]>,
    /// Planes read by the plans as their codes ([`Remap::rows_plane`]), with no float copy:
    /// where each plane, read as the picture, is its one eye's one layer as it is, and the
    /// plans take codes.
    direct: bool,
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
        Converter::planned(format, extent, reading, target, true)
    }

    /// [`Converter::new`]; `by_rows`: planes of one eye made and encoded row by row
    /// ([`Packed`]) where the layout allows, else always as maps, packed and written.
    fn planned(
        format: PlaneFormat,
        extent: (u32, u32),
        reading: Reading,
        target: &Target,
        by_rows: bool,
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
        // One eye in and out: each plane's rows encoded as they are made ([`Packed`]).
        let mono = by_rows && target.stereo.eyes() == 1 && luma.len() == 1;
        let packing = |l: (u32, u32)| mono.then(|| Packing::new(target.layout, dst, l)).flatten();
        let luma_packing = packing(layer);
        // The colour planes' layers at their own size where the layout halves with them;
        // where it does not (EAC's fixed border), at their own size still where the
        // packing halves (4:2:0 of v360's cells: each colour texel shows its block's
        // first face texel, halved); else made at the picture's size and halved.
        let mut clayer = (layer.0 >> sx, layer.1 >> sy);
        let cpacked = packed_extent(target.layout, layers, clayer);
        let halves =
            target.stereo.extent(cpacked.0, cpacked.1) == (picture.0 >> sx, picture.1 >> sy);
        let chroma_packing = if halves {
            packing(clayer)
        } else if sx == sy {
            luma_packing.as_ref().and_then(|p| p.halved(sx))
        } else {
            None
        };
        let chroma_shift = if halves || chroma_packing.is_some() {
            (0, 0)
        } else {
            clayer = layer;
            (sx, sy)
        };
        let plan = |src: &EnvMap, out: (u32, u32), k: usize, packing: Option<Packing>| {
            let remap = Remap::with_extent(
                *src.projection(),
                (src.width(), src.height()),
                src.layers().len(),
                dst,
                out,
                &target.resample,
            );
            let packed = packing.map(|packing| Packed {
                laid: (!packing.along_rows()).then(|| packing.lay_out(&remap, &dst)),
                packing,
            });
            PlanePlan {
                remap,
                neutral: format.neutral(k),
                packed,
            }
        };
        let plans = [
            plan(src, layer, 0, luma_packing),
            plan(csrc, clayer, 1, chroma_packing),
        ];
        // From here every frame is read as the first was: the projection decided.
        let reading = Reading {
            from: Some(
                ProjSpec::parse(&src.projection().to_string())
                    .map_err(|e| Error::input(format!("{input}: {e}")))?,
            ),
            ..reading
        };
        // A plane read as the picture is its eye's one layer as it is (moved, not cut or
        // copied) where the picture is one eye and one layer laid out alone.
        let whole = |ext: (u32, u32)| {
            reading.stereo.0 == Stereo::Mono
                && load::decide(
                    &reading.input,
                    ext,
                    reading.from.as_ref(),
                    reading.layout,
                    None,
                    None,
                    |_| String::new(),
                )
                .is_ok_and(|(p, l, _)| l == Layout::Separate && p.layer_count() == 1)
        };
        let direct = mono
            && plans
                .iter()
                .all(|p| p.packed.is_some() && p.remap.takes_codes())
            && whole(extent)
            && whole(chroma);
        Ok(Converter {
            direct,
            format,
            reading,
            plans,
            layout: target.layout,
            stereo: target.stereo,
            out_extent: picture,
            chroma_shift,
            said,
            scratch: Mutex::new(Default::default()),
        })
    }

    /// The pixel format of the frames, in and out.
    pub fn format(&self) -> PlaneFormat {
        self.format
    }

    /// Converts one frame, plane by plane.
    pub fn convert(&self, frame: &Planes) -> Result<Planes, Error> {
        let mut out = Planes::default();
        self.convert_into(frame, &mut out)?;
        Ok(out)
    }

    /// Converts one frame, plane by plane, into `out` (its memory reused where the planes
    /// are made row by row).
    pub fn convert_into(&self, frame: &Planes, out: &mut Planes) -> Result<(), Error> {
        let mut scratch = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let failed =
            |e: mirrorball_core::RemapError| Error::input(format!("{}: {e}", self.reading.input));
        for k in 0..3 {
            let plan = &self.plans[k.min(1)];
            let (w, h) = frame.extent[k];
            if let (true, Some(packed)) = (self.direct, &plan.packed) {
                let bytes = &frame.data[k];
                let plane = match self.format.bytes() {
                    1 => Plane::u8(bytes, plan.neutral, (w, h)),
                    _ => Plane::u16le(bytes, plan.neutral, (w, h)),
                }
                .map_err(|e| Error::input(format!("{}: {e}", self.reading.input)))?;
                let codes = self.plane_codes(plan.neutral);
                match &packed.laid {
                    Some((laid, picture)) => {
                        let rows = laid.rows_plane(plane).map_err(failed)?;
                        picture.encode_rows(codes, &rows, &mut out.data[k]);
                    }
                    None => {
                        let rows = plan.remap.rows_plane(plane).map_err(failed)?;
                        packed.packing.encode_rows(codes, &rows, &mut out.data[k]);
                    }
                }
                out.extent[k] = packed.packing.extent();
                continue;
            }
            let img = scratch[k].take();
            let img = self.read_plane(&frame.data[k], (w, h), plan.neutral, img);
            let (mut eyes, _) = self.reading.eyes(img)?;
            if let (Some(packed), 1) = (&plan.packed, eyes.len()) {
                let codes = self.plane_codes(plan.neutral);
                let eye = &eyes[0];
                match &packed.laid {
                    Some((laid, picture)) => {
                        let rows = laid.rows(eye).map_err(failed)?;
                        picture.encode_rows(codes, &rows, &mut out.data[k]);
                    }
                    None => {
                        let rows = plan.remap.rows(eye).map_err(failed)?;
                        packed.packing.encode_rows(codes, &rows, &mut out.data[k]);
                    }
                }
                out.extent[k] = packed.packing.extent();
                let mut layers = eyes.swap_remove(0).into_layers();
                if layers.len() == 1 {
                    scratch[k] = Some(layers.swap_remove(0));
                }
                continue;
            }
            let mut pictures = Vec::with_capacity(eyes.len());
            for eye in &eyes {
                let made = plan.remap.apply(eye).map_err(failed)?;
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
        Ok(())
    }

    /// How plane values with `neutral` become this format's codes.
    fn plane_codes(&self, neutral: f32) -> PlaneCodes {
        PlaneCodes {
            bytes: self.format.bytes(),
            neutral,
            max: self.format.max_code(),
        }
    }

    /// A plane's codes as floats less `neutral`, into `img`'s memory where it fits.
    fn read_plane(
        &self,
        bytes: &[u8],
        (w, h): (u32, u32),
        neutral: f32,
        img: Option<Image>,
    ) -> Image {
        let mut img = img
            .filter(|i| (i.width(), i.height(), i.channels()) == (w, h, 1))
            .unwrap_or_else(|| Image::new(w, h, 1));
        let data = img.data_mut();
        if self.format.bytes() == 1 {
            data.par_chunks_mut(1 << 16)
                .zip(bytes.par_chunks(1 << 16))
                .for_each(|(v, b)| {
                    for (v, &b) in v.iter_mut().zip(b) {
                        *v = b as f32 - neutral;
                    }
                });
        } else {
            data.par_chunks_mut(1 << 16)
                .zip(bytes.par_chunks(2 << 16))
                .for_each(|(v, b)| {
                    for (v, b) in v.iter_mut().zip(b.chunks_exact(2)) {
                        *v = u16::from_le_bytes([b[0], b[1]]) as f32 - neutral;
                    }
                });
        }
        img
    }

    /// A converted plane as codes: the neutral value added back, rounded, clamped.
    fn write_plane(&self, img: &Image, neutral: f32) -> Vec<u8> {
        let codes = self.plane_codes(neutral);
        let data = img.data();
        let mut out = vec![0u8; data.len() * codes.bytes];
        out.par_chunks_mut(codes.bytes << 16)
            .zip(data.par_chunks(1 << 16))
            .for_each(|(o, v)| codes.encode(v, o));
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

    /// A frame of codes, each plane its own smooth pattern over the whole range.
    fn frame(fmt: PlaneFormat, (w, h): (u32, u32)) -> Planes {
        let mut f = Planes::default();
        for k in 0..3 {
            let (pw, ph) = fmt.plane_extent(k, (w, h)).unwrap();
            let max = fmt.max_code();
            let codes = (0..pw * ph).map(|i| {
                let (x, y) = ((i % pw) as f32 / pw as f32, (i / pw) as f32 / ph as f32);
                let t = (6.0 * x + k as f32).sin() * (5.0 * y).cos();
                ((0.5 + 0.45 * t) * max).round() as u32
            });
            f.data[k] = if fmt.bytes() == 1 {
                codes.map(|c| c as u8).collect()
            } else {
                codes.flat_map(|c| (c as u16).to_le_bytes()).collect()
            };
            f.extent[k] = (pw, ph);
        }
        f
    }

    /// Planes made and encoded row by row (one eye) are the bytes the general path makes:
    /// each plane's layers made as a map, packed by `Layout::pack`, written as codes. EAC's
    /// 4:2:0 colour planes, made at their own size through the halved packing, are within
    /// a code or two of the general path's (the picture's made at full size, then each
    /// 2×2 block averaged).
    #[test]
    fn planes_encoded_as_rows_are_made_are_the_packed_maps_codes() {
        let ll = ProjSpec::parse("latlong").unwrap();
        for fmt in ["yuv420p", "yuv444p", "yuv420p10le"] {
            let fmt = PlaneFormat::named(fmt).unwrap();
            for (to, layout) in [
                ("cube", "c3x2"),
                ("cube", "hstrip"),
                ("eac", "eac"),
                ("latlong", "c3x2"),
            ] {
                let target = Target {
                    dst: ProjSpec::parse(to).unwrap().build(None).unwrap(),
                    size: Some(if to == "latlong" { 64 } else { 24 }),
                    layout: layout.parse().unwrap(),
                    stereo: Stereo::Mono,
                    resample: ResampleOptions::default(),
                };
                let reading = || Reading {
                    input: "test".into(),
                    from: Some(ll.clone()),
                    layout: None,
                    stereo: (Stereo::Mono, 1),
                };
                let extent = (96, 48);
                let fast = Converter::new(fmt, extent, reading(), &target).unwrap();
                let general = Converter::planned(fmt, extent, reading(), &target, false).unwrap();
                let what = format!("{} {to} {layout}", fmt.name);
                assert!(fast.plans[0].packed.is_some(), "{what}");
                assert!(
                    fast.direct && !general.direct,
                    "{what}: planes read as codes"
                );
                let f = frame(fmt, extent);
                // Twice: the second frame reads into the first one's memory.
                for _ in 0..2 {
                    let (a, b) = (fast.convert(&f).unwrap(), general.convert(&f).unwrap());
                    assert_eq!(a.extent, b.extent, "{what}");
                    for k in 0..3 {
                        let (a, b) = (&a.data[k], &b.data[k]);
                        assert_eq!(a.len(), b.len(), "{what}");
                        let halved = k > 0 && to == "eac" && fmt.shift == (1, 1);
                        if !halved {
                            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
                            assert_eq!(differ, 0, "{what}: plane {k}, {differ} bytes differ");
                            continue;
                        }
                        let codes = |v: &[u8]| -> Vec<f64> {
                            match fmt.bytes() {
                                1 => v.iter().map(|&c| c as f64).collect(),
                                _ => v
                                    .chunks_exact(2)
                                    .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64)
                                    .collect(),
                            }
                        };
                        let (a, b) = (codes(a), codes(b));
                        let scale = fmt.max_code() as f64 / 255.0;
                        let diff: Vec<f64> = a
                            .iter()
                            .zip(&b)
                            .map(|(x, y)| (x - y).abs() / scale)
                            .collect();
                        let mean = diff.iter().sum::<f64>() / diff.len() as f64;
                        // The border (one colour texel: a block of v360's two) is looked up in
                        // its first luma texel's direction, not averaged over four.
                        let (cw, ch) = (
                            fast.out_extent.0 as usize / 2,
                            fast.out_extent.1 as usize / 2,
                        );
                        let border = |i: usize| {
                            let (x, y) = (i % cw, i / cw);
                            x == 0 || x == cw - 1 || [0, ch / 2 - 1, ch / 2, ch - 1].contains(&y)
                        };
                        let worst = |edge: bool| {
                            let mut w = 0.0f64;
                            for (i, d) in diff.iter().enumerate() {
                                if border(i) == edge {
                                    w = w.max(*d);
                                }
                            }
                            w
                        };
                        let (inner, edge) = (worst(false), worst(true));
                        assert!(
                            mean < 0.75 && inner <= 4.0 && edge <= 8.0,
                            "{what}: plane {k}, mean {mean}, worst {inner} inside, {edge} on \
                             the border (8-bit codes)"
                        );
                    }
                }
            }
        }
    }
}
