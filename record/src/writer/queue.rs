//! Frames queued for encoding. A buffered writer ([`RecordingWriter::buffer_frames`]) keeps
//! small frames (at most [`QUEUE_PARTICLES`] particles) as they are and encodes them in a
//! batch: up to [`QUEUE_FRAMES`] frames, or [`QUEUE_PARTICLES`] particles, or whenever a flush
//! is due (the first frame, a slow frame, the buffering's byte or time limit), and before any
//! other write. The file's bytes are those of encoding each frame when it came (same
//! messages, sequence numbers and log times, in the same order); only when the work is done
//! changes. Why: a frame of a one-particle scene every 100 steps of ~5 µs cost ~30 µs
//! encoded on its own (protobuf, the scene update, zstd's stream: code and tables that the
//! steps in between evict from the caches), and a small fraction of that in a batch.

use super::RecordingWriter;
use crate::{ParticleFrame, RecordError};
use std::time::{Duration, Instant};

/// How long frames may wait in the open chunk (see [`RecordingWriter::buffer_frames`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameBuffering {
    /// Flush once the open chunk holds this many message bytes (uncompressed).
    pub max_bytes: u64,
    /// Flush at the first frame written this long after the last flush.
    pub max_wait: Duration,
}

impl Default for FrameBuffering {
    /// 1 MiB or 1 s, whichever comes first.
    fn default() -> Self {
        Self {
            max_bytes: 1 << 20,
            max_wait: Duration::from_secs(1),
        }
    }
}

/// Most frames queued before they are encoded.
pub const QUEUE_FRAMES: usize = 64;
/// Most particles queued before the frames are encoded; larger frames are never queued
/// (with [`QUEUE_FRAMES`], this bounds the queue's memory to about 1 MiB).
pub const QUEUE_PARTICLES: usize = 4096;

/// A frame waiting to be encoded, with its colours.
pub(super) struct QueuedFrame {
    frame: ParticleFrame,
    colours: Option<Vec<[f32; 4]>>,
}

impl RecordingWriter {
    /// Whether a frame of `n` particles is queued: the writer buffers frames and the frame
    /// is small.
    pub(super) fn queues(&self, n: usize) -> bool {
        self.buffering.is_some() && n <= QUEUE_PARTICLES
    }

    /// Queue `frame` (of `n` particles) with its colours.
    pub(super) fn queue_frame(
        &mut self,
        frame: ParticleFrame,
        colours: Option<Vec<[f32; 4]>>,
        n: usize,
    ) {
        self.queued.push(QueuedFrame { frame, colours });
        self.queued_particles += n;
    }

    /// After a frame was queued or written: encode the queue when it is full or a flush is
    /// due, and flush when due (see [`RecordingWriter::buffer_frames`]).
    pub(super) fn after_frame(&mut self) -> Result<(), RecordError> {
        let now = Instant::now();
        let slow = self.last_frame.is_none_or(|t| {
            now.duration_since(t) >= self.buffering.map_or(Duration::ZERO, |b| b.max_wait)
        });
        self.last_frame = Some(now);
        // the queued frames' messages take at least their headers and 24 bytes (a position)
        // per particle: enough to honour a small byte limit at once
        let late = |w: &Self| {
            let queued = (62 * w.queued.len() + 24 * w.queued_particles) as u64;
            w.buffering.is_none_or(|b| {
                slow || w.pending + queued >= b.max_bytes
                    || now.duration_since(w.last_flush) >= b.max_wait
            })
        };
        let full = self.queued.len() >= QUEUE_FRAMES || self.queued_particles >= QUEUE_PARTICLES;
        if full || late(self) {
            self.drain_queue()?;
        }
        if late(self) {
            self.flush()?;
        }
        Ok(())
    }

    /// Encode the queued frames, in order, into the open chunk (no flush); returns the error
    /// a `set_*` call met first, if any.
    pub(crate) fn drain_queue(&mut self) -> Result<(), RecordError> {
        if let Some(e) = self.deferred_error.take() {
            self.queued.clear();
            self.queued_particles = 0;
            return Err(e);
        }
        if self.queued.is_empty() {
            return Ok(());
        }
        let mut queued = std::mem::take(&mut self.queued);
        self.queued_particles = 0;
        let mut result = Ok(());
        for q in &queued {
            result = self.encode_frame(&q.frame, q.colours.as_deref());
            if result.is_err() {
                break;
            }
        }
        queued.clear();
        self.queued = queued;
        result
    }

    /// Before the scene's decoration changes, encode the queued frames with the old one (an
    /// error is kept for the next fallible call).
    pub(super) fn drain_before_decor(&mut self) {
        if self.mcap.is_some()
            && let Err(e) = self.drain_queue()
            && self.deferred_error.is_none()
        {
            self.deferred_error = Some(e);
        }
    }
}
