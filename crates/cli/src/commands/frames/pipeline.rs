//! The frame loop: one thread reads (and decodes) frame k+1 while another converts frame k
//! with the planned `Remap` and a third writes (and encodes) frame k−1. The stages are
//! joined by channels that hold one frame each, and buffers go back to the stage that fills
//! them, so at most three source maps and three output maps exist whatever the number of
//! frames (their memory is [`FRAMES_IN_FLIGHT`] of each), and a long run allocates nothing
//! after its first frames. Each stage's heavy loops are parallel (rayon), so the two cores
//! share whichever stages have work.
//!
//! A frame is one map per eye ([`Eyes`]): one for `2d`, two for a stereo pair. Each output
//! eye is made by the one `Remap` from its `Stereo::source_eye`; an eye made from the same
//! source eye as the one before it is copied.

use crate::error::CliError;
use mirrorball_core::{EnvMap, Remap, Stereo};
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

/// Reads the next frame, given source maps that have come back for reuse (when they have);
/// `None` at the end.
pub type Next<'a> = dyn FnMut(Option<Eyes>) -> Option<Result<(Meta, Eyes), CliError>> + Send + 'a;
/// Writes a converted frame.
pub type Put<'a> = dyn FnMut(&Meta, &[EnvMap]) -> Result<(), CliError> + Send + 'a;

/// Runs the loop until `next` ends or a stage fails; `done` counts the frames written.
/// Source frames are arranged as `from`; `fresh_output` makes a frame of output eyes.
/// The first error of the reader, the converter or the writer (in that order: a failing
/// stage makes the others stop without one) is returned after every frame before it was
/// written.
pub fn run(
    next: &mut Next<'_>,
    (remap, from): (&Remap, Stereo),
    fresh_output: &(dyn Fn() -> Eyes + Sync),
    put: &mut Put<'_>,
    done: &AtomicU64,
) -> Result<(), CliError> {
    let (src_tx, src_rx) = sync_channel::<(Meta, Eyes)>(1);
    let (out_tx, out_rx) = sync_channel::<(Meta, Eyes)>(1);
    let (src_back_tx, src_back_rx) = channel::<Eyes>();
    let (out_back_tx, out_back_rx) = channel::<Eyes>();
    std::thread::scope(|s| {
        let reader = s.spawn(move || read_stage(next, src_tx, src_back_rx));
        let writer = s.spawn(move || write_stage(put, out_rx, out_back_tx, done));
        let converted = convert_stage(
            (remap, from),
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

fn read_stage(
    next: &mut Next<'_>,
    tx: std::sync::mpsc::SyncSender<(Meta, Eyes)>,
    back: Receiver<Eyes>,
) -> Result<(), CliError> {
    loop {
        let spare = back.try_recv().ok();
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

fn convert_stage(
    (remap, from): (&Remap, Stereo),
    fresh_output: &(dyn Fn() -> Eyes + Sync),
    rx: Receiver<(Meta, Eyes)>,
    tx: std::sync::mpsc::SyncSender<(Meta, Eyes)>,
    src_back: Sender<Eyes>,
    out_back: Receiver<Eyes>,
) -> Result<(), CliError> {
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
                CliError::input(format!(
                    "{}: {} eye(s), where the first frame had {}",
                    meta.input,
                    src.len(),
                    from.eyes()
                ))
            })?;
            remap.apply_into(src_eye, &mut out[e]).map_err(|err| {
                CliError::input(format!(
                    "{}: {err} (every frame must have the first's projection and size)",
                    meta.input
                ))
            })?;
        }
        let _ = src_back.send(src);
        if tx.send((meta, out)).is_err() {
            return Ok(());
        }
    }
    Ok(())
}

fn write_stage(
    put: &mut Put<'_>,
    rx: Receiver<(Meta, Eyes)>,
    back: Sender<Eyes>,
    done: &AtomicU64,
) -> Result<(), CliError> {
    for (meta, out) in rx {
        put(&meta, &out)?;
        done.fetch_add(1, Ordering::Relaxed);
        let _ = back.send(out);
    }
    Ok(())
}
