//! The frame loop: one thread reads (and decodes) frame k+1 while another converts frame k
//! with the planned `Remap` and a third writes frame k−1. The stages are joined by channels
//! that hold one frame each, and buffers go back to the stage that fills them, so at most
//! three source frames and three outputs exist whatever the number of frames (their memory
//! is [`FRAMES_IN_FLIGHT`] of each), and a long run allocates nothing after its first
//! frames. Each stage's heavy loops are parallel (rayon), so the two cores share whichever
//! stages have work.
//!
//! A frame is one map per eye ([`Eyes`]): one for `2d`, two for a stereo pair. An output is
//! whatever the converter makes for the writer: the output eyes ([`convert_eyes`], written
//! to files or packed), or a raw frame's bytes already encoded (each row encoded as the
//! `Remap` makes it, so the frame never exists as floats).

use crate::error::Error;
use mirrorball_core::{EnvMap, Remap, RemapError, Stereo};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender};

/// Source maps (and output maps) alive at once: one being filled, one waiting in a
/// channel, one being read.
pub const FRAMES_IN_FLIGHT: u64 = 3;

/// What a stage knows about a frame besides its texels.
#[derive(Clone, Debug)]
pub struct Meta {
    /// The frame's number (its output's, for patterns).
    pub number: u64,
    /// Where it came from, for messages and the log.
    pub input: String,
}

/// A frame's maps, one per eye, the left first.
pub type Eyes = Vec<EnvMap>;

/// Reads the next frame (maps, [`Eyes`], or whatever source the converter takes), given a
/// source frame that has come back for reuse (when one has); `None` at the end.
pub type Next<'a, S = Eyes> = dyn FnMut(Option<S>) -> Option<Result<(Meta, S), Error>> + Send + 'a;
/// Converts a source frame into an output of the writer's kind, reusing its memory.
pub type Convert<'a, O, S = Eyes> = dyn Fn(&Meta, &S, &mut O) -> Result<(), Error> + Sync + 'a;
/// Writes a converted frame.
pub type Put<'a, O> = dyn FnMut(&Meta, &O) -> Result<(), Error> + Send + 'a;

/// Runs the loop until `next` ends or a stage fails; `done` counts the frames written.
/// `fresh_output` makes an output for the converter to fill (at most
/// [`FRAMES_IN_FLIGHT`] are made; `next` is given a source back to fill once as many
/// sources are in flight).
/// The first error of the reader, the converter or the writer (in that order: a failing
/// stage makes the others stop without one) is returned after every frame before it was
/// written.
pub fn run<S: Send, O: Send>(
    next: &mut Next<'_, S>,
    convert: &Convert<'_, O, S>,
    fresh_output: &(dyn Fn() -> O + Sync),
    put: &mut Put<'_, O>,
    done: &AtomicU64,
) -> Result<(), Error> {
    let (src_tx, src_rx) = sync_channel::<(Meta, S)>(1);
    let (out_tx, out_rx) = sync_channel::<(Meta, O)>(1);
    let (src_back_tx, src_back_rx) = channel::<S>();
    let (out_back_tx, out_back_rx) = channel::<O>();
    std::thread::scope(|s| {
        let reader = s.spawn(move || read_stage(next, src_tx, src_back_rx));
        let writer = s.spawn(move || write_stage(put, out_rx, out_back_tx, done));
        let converted = convert_stage(
            convert,
            fresh_output,
            src_rx,
            out_tx,
            src_back_tx,
            out_back_rx,
        );
        let read = reader.join().expect("the reader does not panic");
        let written = writer.join().expect("the writer does not panic");
        read.and(converted).and(written)
    })
}

fn read_stage<S>(
    next: &mut Next<'_, S>,
    tx: std::sync::mpsc::SyncSender<(Meta, S)>,
    back: Receiver<S>,
) -> Result<(), Error> {
    let mut made = 0;
    loop {
        let spare = match back.try_recv() {
            Ok(s) => Some(s),
            Err(_) if made < FRAMES_IN_FLIGHT => {
                made += 1;
                None
            }
            // Every source is in flight: the next to come back is filled (a fresh one each
            // time would be a frame's memory allocated and faulted in again).
            Err(_) => match back.recv() {
                Ok(s) => Some(s),
                Err(_) => return Ok(()), // the converter stopped: its error is the one to say
            },
        };
        match next(spare) {
            None => return Ok(()),
            Some(Err(e)) => return Err(e),
            Some(Ok(frame)) => {
                if tx.send(frame).is_err() {
                    return Ok(()); // the converter stopped: its error is the one to say
                }
            }
        }
    }
}

/// The error of a frame the plan was not made for.
pub fn misfit(meta: &Meta, err: RemapError) -> Error {
    Error::input(format!(
        "{}: {err} (every frame must have the first's projection and size)",
        meta.input
    ))
}

/// Makes every output eye of `out` from source frame `src` (arranged as `from`) with
/// `remap`: each from its `Stereo::source_eye`, an eye made from the same source eye as the
/// one before it copied.
pub fn convert_eyes(
    (remap, from): (&Remap, Stereo),
    meta: &Meta,
    src: &Eyes,
    out: &mut Eyes,
) -> Result<(), Error> {
    for e in 0..out.len() {
        let eye = from.source_eye(e);
        if e > 0 && from.source_eye(e - 1) == eye {
            let (made, rest) = out.split_at_mut(e);
            for (to, from) in rest[0].layers_mut().iter_mut().zip(made[e - 1].layers()) {
                to.data_mut().copy_from_slice(from.data());
            }
            continue;
        }
        let src_eye = src.get(eye).ok_or_else(|| {
            Error::input(format!(
                "{}: {} eye(s), where the first frame had {}",
                meta.input,
                src.len(),
                from.eyes()
            ))
        })?;
        remap
            .apply_into(src_eye, &mut out[e])
            .map_err(|err| misfit(meta, err))?;
    }
    Ok(())
}

fn convert_stage<S, O>(
    convert: &Convert<'_, O, S>,
    fresh_output: &(dyn Fn() -> O + Sync),
    rx: Receiver<(Meta, S)>,
    tx: std::sync::mpsc::SyncSender<(Meta, O)>,
    src_back: Sender<S>,
    out_back: Receiver<O>,
) -> Result<(), Error> {
    let mut made = 0;
    for (meta, src) in rx {
        let mut out = match out_back.try_recv() {
            Ok(o) => o,
            Err(_) if made < FRAMES_IN_FLIGHT => {
                made += 1;
                fresh_output()
            }
            Err(_) => match out_back.recv() {
                Ok(o) => o,
                Err(_) => return Ok(()), // the writer stopped
            },
        };
        convert(&meta, &src, &mut out)?;
        let _ = src_back.send(src);
        if tx.send((meta, out)).is_err() {
            return Ok(());
        }
    }
    Ok(())
}

fn write_stage<O>(
    put: &mut Put<'_, O>,
    rx: Receiver<(Meta, O)>,
    back: Sender<O>,
    done: &AtomicU64,
) -> Result<(), Error> {
    for (meta, out) in rx {
        put(&meta, &out)?;
        done.fetch_add(1, Ordering::Relaxed);
        let _ = back.send(out);
    }
    Ok(())
}
