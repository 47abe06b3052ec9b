//! A recording written on a thread of its own ([`RecordingWriter::create_background`]): the
//! calling thread (the simulation's) only hands each call, with the data it needs (a frame
//! moves, a message is copied), to a bounded queue that wakes the writer thread only now and
//! then (`writer/mailbox.rs`); a writer thread makes the calls on a
//! plain [`RecordingWriter`] in the same order, so the file's records are the same. The
//! writer thread does the MCAP header, schemas and metadata record, the encoding, the zstd
//! compression and the writes, and the summary section at the end. On two or more cores the
//! run's wall time then barely changes when it records.
//!
//! Errors: the first error of the writer thread is kept and the thread stops (dropping its
//! writer, which closes the file best-effort, so what was written stays readable); the next
//! call returns it (the same error as a plain writer's call would have returned, one call
//! later), and every call after that an error saying the recording stopped. Memory is bounded:
//! at most [`BACKGROUND_CALLS`] calls and [`BACKGROUND_BYTES`] of their data wait in the queue,
//! the caller blocks when it is full.

use super::mailbox::{Receiver, Sender, mailbox};
use super::{RecordingSink, RecordingWriter};
use crate::{ParticleFrame, RecordError, RecordingMetadata};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Most calls waiting for the writer thread (each one frame at most); a caller that gets
/// this far ahead waits (back-pressure).
pub const BACKGROUND_CALLS: usize = 256;

/// Most bytes (as estimated by each call's weight) waiting for the writer thread; a caller
/// that gets this far ahead waits.
pub const BACKGROUND_BYTES: usize = 32 << 20;

/// The weight of a call whose data is not counted (a few hundred bytes at most).
const SMALL_CALL: usize = 256;

/// One call to make on the writer thread's [`RecordingWriter`].
pub(super) type Call = Box<dyn FnOnce(&mut RecordingWriter) -> Result<(), RecordError> + Send>;

/// What the writer thread is sent.
enum Job {
    Call(Call),
    /// Finish the file (`true`: and sync it), send the result, then end the thread.
    Finish(bool, SyncSender<Result<(), RecordError>>),
}

/// The caller's side of a background writer.
pub(super) struct Background {
    /// `None` once finished (or dropped).
    sender: Option<Sender<Job>>,
    thread: Option<JoinHandle<Result<(), RecordError>>>,
    /// The writer thread's first error, until a call returns it.
    error: Arc<Mutex<Option<RecordError>>>,
    /// Whether an error was returned already (later calls return [`stopped`]).
    failed: bool,
    path: PathBuf,
}

/// The error of every call after the one that returned the writer thread's error.
fn stopped(path: &Path) -> RecordError {
    RecordError::InvalidInput {
        detail: format!(
            "the recording {} stopped at an earlier write error",
            path.display()
        ),
    }
}

impl RecordingWriter {
    /// As [`create`](Self::create), with everything after creating the file done on a writer
    /// thread of its own (see `writer/background.rs`): the header, schemas, channels and
    /// metadata record, then every later call in order. The file is created before this
    /// returns, so a bad path fails here; any later error (writing the header included) is
    /// returned by the first call after the writer thread met it, or by
    /// [`finish`](Self::finish). The file's records are those of [`create`](Self::create)
    /// with the same calls.
    pub fn create_background(path: &Path, meta: &RecordingMetadata) -> Result<Self, RecordError> {
        let file = File::create(path).map_err(|source| RecordError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::background_from_sink(path, Box::new(file), meta)
    }

    /// As [`create_background`](Self::create_background), writing to `sink` (see
    /// [`from_sink`](Self::from_sink)).
    pub fn background_from_sink(
        path: &Path,
        sink: Box<dyn RecordingSink>,
        meta: &RecordingMetadata,
    ) -> Result<Self, RecordError> {
        let (sender, receiver) = mailbox(BACKGROUND_CALLS, BACKGROUND_BYTES);
        let error = Arc::new(Mutex::new(None));
        let shared = error.clone();
        let owned_path = path.to_path_buf();
        let meta = meta.clone();
        let thread = std::thread::Builder::new()
            .name("magsep-record".into())
            .spawn(move || {
                let writer = RecordingWriter::from_sink(&owned_path, sink, &meta);
                serve(writer, &receiver, &shared)
            })
            .map_err(|source| RecordError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        let mut writer = Self::unopened(path);
        writer.background = Some(Background {
            sender: Some(sender),
            thread: Some(thread),
            error,
            failed: false,
            path: path.to_path_buf(),
        });
        Ok(writer)
    }
}

/// The writer thread: make the calls in order until the channel closes or a finish comes.
fn serve(
    writer: Result<RecordingWriter, RecordError>,
    receiver: &Receiver<Job>,
    error: &Mutex<Option<RecordError>>,
) -> Result<(), RecordError> {
    let keep = |e: RecordError| {
        if let Ok(mut slot) = error.lock() {
            slot.get_or_insert(e);
        }
    };
    let mut writer = match writer {
        Ok(w) => w,
        Err(e) => {
            keep(e);
            return Ok(());
        }
    };
    while let Some(job) = receiver.recv() {
        match job {
            Job::Call(call) => {
                if let Err(e) = call(&mut writer) {
                    // dropping the writer closes the file best-effort
                    keep(e);
                    return Ok(());
                }
            }
            Job::Finish(sync, done) => {
                // the caller waits for this, not for the thread's end (a thread's exit, its
                // stack and allocator caches given back, cost the caller ~0.2 ms more on this machine)
                let _ = done.send(writer.finish_inner(sync));
                return Ok(());
            }
        }
    }
    Ok(())
}

impl Background {
    /// The writer thread's error, if it met one (returned once; then [`stopped`]).
    fn take_error(&mut self) -> Result<(), RecordError> {
        if self.failed {
            return Err(stopped(&self.path));
        }
        let kept = self.error.lock().ok().and_then(|mut slot| slot.take());
        match kept {
            Some(e) => {
                self.failed = true;
                Err(e)
            }
            None => Ok(()),
        }
    }

    /// Hand `call` to the writer thread; returns the thread's earlier error, if any.
    /// `weight`: the call's data in bytes, roughly ([`SMALL_CALL`] if it carries little).
    pub(super) fn send(&mut self, call: Call, weight: usize) -> Result<(), RecordError> {
        self.send_as(call, weight.max(SMALL_CALL), false)
    }

    /// Hand a frame to the writer thread, weighed by what it holds: 14 words per particle
    /// (16 with colours) and its status.
    pub(super) fn send_frame(
        &mut self,
        frame: ParticleFrame,
        colours: Option<Vec<[f32; 4]>>,
    ) -> Result<(), RecordError> {
        let per_particle = if colours.is_some() { 128 } else { 112 };
        let weight = frame.ids.len() * per_particle + frame.status_json.len();
        self.send(
            Box::new(move |w| w.write_frame_owned(frame, colours)),
            weight,
        )
    }

    /// [`send`](Self::send); `urgent`: wake the writer thread now (someone waits for the
    /// call), else it takes the call when its queue is three quarters full or at its next poll.
    fn send_as(&mut self, call: Call, weight: usize, urgent: bool) -> Result<(), RecordError> {
        self.take_error()?;
        if self.push(call, weight, urgent) {
            return Ok(());
        }
        // the thread ended: it met an error (or the writer is finished)
        self.sender = None;
        self.join_thread()?;
        self.take_error()?;
        Err(stopped(&self.path))
    }

    /// Hand a call that cannot fail to the writer thread; an error of the thread is left for
    /// the next fallible call.
    pub(super) fn send_unit(&mut self, call: impl FnOnce(&mut RecordingWriter) + Send + 'static) {
        if !self.failed {
            // not sent: the thread ended at an error, which stays for the next call
            self.push(
                Box::new(move |w| {
                    call(w);
                    Ok(())
                }),
                SMALL_CALL,
                false,
            );
        }
    }

    /// Hand `call` to the writer thread; whether it is still there to take it.
    fn push(&mut self, call: Call, weight: usize, urgent: bool) -> bool {
        match &self.sender {
            Some(s) => s.send(Job::Call(call), weight, urgent).is_ok(),
            None => false,
        }
    }

    /// Make `call` on the writer thread and wait for its result (calls that return a value).
    pub(super) fn call<T: Send + 'static>(
        &mut self,
        call: impl FnOnce(&mut RecordingWriter) -> Result<T, RecordError> + Send + 'static,
    ) -> Result<T, RecordError> {
        let (reply, answer) = sync_channel(1);
        self.send_as(
            Box::new(move |w| {
                // the caller gets the call's error and decides, as with a plain writer
                let _ = reply.send(call(w));
                Ok(())
            }),
            SMALL_CALL,
            true,
        )?;
        match answer.recv() {
            Ok(Ok(value)) => Ok(value),
            Ok(Err(e)) => Err(e),
            Err(_) => {
                self.sender = None;
                self.join_thread()?;
                self.take_error()?;
                Err(stopped(&self.path))
            }
        }
    }

    /// Finish the file on the writer thread (`sync`: and sync it) and wait until it is
    /// closed; the thread then ends by itself.
    pub(super) fn finish(&mut self, sync: bool) -> Result<(), RecordError> {
        self.take_error()?;
        let (done, result) = sync_channel(1);
        let sent = self
            .sender
            .take()
            .is_some_and(|s| s.send(Job::Finish(sync, done), 0, true).is_ok());
        if sent && let Ok(finished) = result.recv() {
            // the file is complete: let the thread end without waiting for it
            self.thread = None;
            if let Err(e) = finished {
                self.failed = true;
                return Err(e);
            }
            return self.take_error();
        }
        // the thread ended before finishing (an error, or a panic)
        self.join_thread()?;
        self.take_error()
    }

    /// Wait for the writer thread to end; its result (a panic is reported as an error).
    fn join_thread(&mut self) -> Result<(), RecordError> {
        match self.thread.take().map(JoinHandle::join) {
            None | Some(Ok(Ok(()))) => Ok(()),
            Some(Ok(Err(e))) => {
                self.failed = true;
                Err(e)
            }
            Some(Err(_)) => {
                self.failed = true;
                Err(RecordError::InvalidInput {
                    detail: format!("the writer thread of {} panicked", self.path.display()),
                })
            }
        }
    }
}

impl Drop for Background {
    /// Closes the channel and waits for the writer thread, which finishes the file
    /// best-effort (as dropping a plain writer does).
    fn drop(&mut self) {
        self.sender = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
