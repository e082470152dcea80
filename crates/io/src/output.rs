//! A set of image files written one after another and landing together.

use crate::atomic::{commit_all, Staged};
use crate::exr_io::WriteBuffers;
use crate::{stage_image, Error, WriteOptions};
use mirrorball_core::Image;
use std::path::{Path, PathBuf};

/// Flat image files (EXR, HDR, PNG, JPEG) that belong together, such as the six faces of a
/// cube written one file a face: each image is written as it is pushed, to a temporary file
/// beside its destination, and [`finish`](Self::finish) renames the whole set into place.
/// Until then every destination keeps its old file; dropped unfinished (an error, a panic)
/// the set removes its temporary files, and an interrupt ([`crate::interrupted`]) either
/// lets a set that is being renamed land whole or keeps it from landing at all.
///
/// A pushed image's buffer comes back from [`spare`](Self::spare), so that a caller making
/// image after image of one size fills the same memory again rather than fresh pages; the
/// encoders' own buffers are kept from file to file too.
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read, Limits, OutputSet, WriteOptions};
/// let dir = tempfile::tempdir().unwrap();
/// let mut set = OutputSet::new(&WriteOptions::default());
/// for (i, name) in ["front.exr", "back.exr"].iter().enumerate() {
///     let mut img = set.spare().unwrap_or_else(|| Image::new(4, 4, 3));
///     img.data_mut().fill(i as f32);
///     set.push(&dir.path().join(name), img).unwrap();
/// }
/// assert!(!dir.path().join("front.exr").exists()); // written beside, not yet in place
/// let files = set.finish().unwrap();
/// assert_eq!(files, [dir.path().join("front.exr"), dir.path().join("back.exr")]);
/// let back = read(&files[1], &Limits::default()).unwrap();
/// assert_eq!(back.layers[0].get(3, 3), &[1.0, 1.0, 1.0]);
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2); // no temporary left
/// ```
#[derive(Debug)]
pub struct OutputSet {
    opts: WriteOptions,
    staged: Vec<Staged>,
    buffers: WriteBuffers,
    spare: Option<Image>,
}

impl OutputSet {
    /// An empty set whose files are written with `opts`.
    pub fn new(opts: &WriteOptions) -> OutputSet {
        OutputSet {
            opts: *opts,
            staged: Vec::new(),
            buffers: WriteBuffers::default(),
            spare: None,
        }
    }

    /// Writes `image` to a temporary file beside `path` (the container chosen by `path`'s
    /// extension), renamed into place by [`finish`](Self::finish). On an error nothing of
    /// this file is left, and the files pushed before stay pending.
    pub fn push(&mut self, path: &Path, image: Image) -> Result<(), Error> {
        let staged = stage_image(path, &image, &self.opts, &mut self.buffers)?;
        self.staged.push(staged);
        self.spare = Some(image);
        Ok(())
    }

    /// Writes `images[i]` to `paths[i]` as [`push`](Self::push) does, the files in
    /// parallel (PNG, JPEG and Radiance encoders each run on one core). On an error none of
    /// these files is left.
    ///
    /// # Panics
    /// If `paths` and `images` differ in length.
    pub fn push_all(&mut self, paths: &[PathBuf], images: &[Image]) -> Result<(), Error> {
        use rayon::prelude::*;
        assert_eq!(paths.len(), images.len(), "a path for each image");
        let opts = self.opts;
        let staged = paths
            .par_iter()
            .zip(images)
            .map(|(p, img)| stage_image(p, img, &opts, &mut WriteBuffers::default()))
            .collect::<Result<Vec<_>, _>>()?;
        self.staged.extend(staged);
        Ok(())
    }

    /// The buffer of an image already written, to be filled with the next one (`None` when
    /// none is free). Its size and texels are those of the image it held.
    pub fn spare(&mut self) -> Option<Image> {
        self.spare.take()
    }

    /// Renames every file into place, together (see [`OutputSet`]), and returns their
    /// paths in the order they were pushed. Every file is tried; the first error is
    /// returned, and the files that failed to land are removed.
    pub fn finish(self) -> Result<Vec<PathBuf>, Error> {
        let paths = self.staged.iter().map(|s| s.path().to_path_buf()).collect();
        commit_all(self.staged)?;
        Ok(paths)
    }
}
