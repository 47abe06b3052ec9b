//! [`RecordingWriter`]: writes a run to an MCAP file, frame by frame, and the channels and
//! metadata records that plugins add.

mod background;
mod channels;
mod mailbox;
mod queue;

pub use background::{BACKGROUND_BYTES, BACKGROUND_CALLS};
pub use queue::FrameBuffering;

pub use channels::ChannelHandle;

use crate::frame::{BackdropCube, FibreShape, WallShape};
use crate::meta::metadata_entries;
use crate::proto::{encode_state, particle_count, state_schema};
use crate::reader::MAX_CHUNK_BYTES;
use crate::scene::{SceneCache, SceneDecor, encode_scene_update};
use crate::{
    INTERRUPTED_METADATA_NAME, METADATA_NAME, ParticleFrame, RecordError, RecordingMetadata,
    SCENE_TOPIC, STATE_TOPIC, SUMMARY_METADATA_NAME,
};
use background::Background;
use channels::AddedChannel;
use foxglove::Encode;
use foxglove::messages::SceneUpdate;
use glam::DVec3;
use mcap::records::{MessageHeader, Metadata};
use queue::QueuedFrame;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where a recording's bytes go: a [`File`], or any seekable sink (an in-memory buffer, or in
/// tests one that fails like a full disk), see [`RecordingWriter::from_sink`].
pub trait RecordingSink: Write + Seek + Send + Sync {
    /// Make what was written durable (a file: `sync_all`); called by
    /// [`RecordingWriter::finish_synced`]. The default does nothing.
    fn sync(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl RecordingSink for File {
    fn sync(&mut self) -> std::io::Result<()> {
        self.sync_all()
    }
}

impl RecordingSink for std::io::Cursor<Vec<u8>> {}

type McapWriter = mcap::Writer<BufWriter<Box<dyn RecordingSink>>>;

// The writer lives in a bevy_ecs `Resource`, which must be `Send + Sync`. With mcap's
// zstd-only build `mcap::Writer<BufWriter<Box<dyn RecordingSink>>>` is both (the sink trait
// requires it); fail the build if that changes.
const _: fn() = || {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<McapWriter>();
    assert_send_sync::<RecordingWriter>();
};

/// MCAP log time (ns) of `frame`: `frame.step` when `frame.time == 0.0` (packing has no
/// physical time, so steps serve as the clock), else `round(frame.time * 1e9)` (negative or
/// NaN times give 0, times beyond `u64::MAX` ns saturate).
///
/// [`RecordingWriter::write_frame`] additionally clamps each log time to be at least the
/// previous one, so log times never decrease within a recording.
pub fn log_time_ns(frame: &ParticleFrame) -> u64 {
    if frame.time == 0.0 {
        frame.step
    } else {
        // `as` saturates (and maps NaN to 0), which is the intent here.
        (frame.time * 1e9).round() as u64
    }
}

/// zstd level of the chunks. Level 1 (zstd's fastest positive level, `ZSTD_fast`) instead
/// of the default 3 (`ZSTD_dfast`): its stream context takes ~0.7 MB instead of ~3 MB (a
/// 512 KiB window instead of 2 MiB; hash tables of 32 KiB instead of 768 KiB, which zstd
/// zeroes when the context is created), and it compresses a frame in about half the
/// instructions. The data (mostly f64 words) compresses nearly as well; readers decompress
/// any level.
pub const COMPRESSION_LEVEL: u32 = 1;

/// Writes a recording: MCAP with zstd-compressed chunks, channels [`STATE_TOPIC`] and
/// [`SCENE_TOPIC`], metadata records [`METADATA_NAME`] and [`SUMMARY_METADATA_NAME`], plus the
/// channels ([`add_channel`](Self::add_channel)) and metadata records
/// ([`add_metadata`](Self::add_metadata)) that plugins add.
///
/// Every call that writes data (a frame, a message or a batch of messages, a metadata record,
/// a channel) ends the current chunk and flushes the file (frames may instead share chunks for
/// up to a bounded time, see [`buffer_frames`](Self::buffer_frames)), so a process killed at any point
/// leaves a file whose finished frames and messages [`read_recording`](crate::read_recording)
/// and [`RecordingReader`](crate::RecordingReader) recover. [`finish`](Self::finish) writes the summary section and footer; dropping an
/// unfinished writer does the same on a best-effort basis (errors are ignored, nothing panics).
///
/// The writer is `Send + Sync` (checked at compile time) so that it can live in a bevy_ecs
/// `Resource`.
pub struct RecordingWriter {
    /// `None` only once finished.
    mcap: Option<McapWriter>,
    path: PathBuf,
    state_channel: u16,
    scene_channel: u16,
    frames_written: u64,
    last_log_time: Option<u64>,
    /// Reused message encoding buffer.
    buf: Vec<u8>,
    /// Reused encoding buffer of the scene updates.
    scene_buf: Vec<u8>,
    /// Fibres, walls and particle shapes drawn in every scene update.
    decor: SceneDecor,
    /// The encoded entities that frames reuse (backdrop, fibres; box outline, walls).
    scene_cache: SceneCache,
    /// Channels added by plugins, in the order added.
    channels: Vec<AddedChannel>,
    /// Largest chunk a frame may take ([`MAX_CHUNK_BYTES`]; smaller in tests).
    pub(crate) max_chunk: u64,
    /// Frame buffering ([`RecordingWriter::buffer_frames`]); `None`: every frame ends its chunk.
    buffering: Option<FrameBuffering>,
    /// Message bytes written since the last flush.
    pending: u64,
    /// When the last flush happened.
    last_flush: Instant,
    /// When the last frame was written.
    last_frame: Option<Instant>,
    /// Small frames not yet encoded (buffered writers only; see `queue.rs`).
    queued: Vec<QueuedFrame>,
    /// Particles in `queued`.
    queued_particles: usize,
    /// An error met while encoding queued frames in a call that cannot return it (the
    /// `set_*` methods); the next fallible call returns it.
    deferred_error: Option<RecordError>,
    /// The writer thread of [`create_background`](Self::create_background), which makes
    /// every call on a plain writer of its own; `None`: calls are made here.
    background: Option<Background>,
}

impl RecordingWriter {
    /// Creates (or truncates) the file at `path`, writes the MCAP header, the schemas and
    /// channels, and the metadata record [`METADATA_NAME`] with keys `scene_text` (verbatim),
    /// `seed` (decimal), `version`, `pipeline`, `dt` (seconds, shortest round-trip decimal),
    /// `schedule` (JSON object: set name -> system names), `plugins` (JSON array of
    /// `{"name", "params"}`) and `extra` (JSON object of strings), then flushes the file.
    pub fn create(path: &Path, meta: &RecordingMetadata) -> Result<Self, RecordError> {
        let file = File::create(path).map_err(|source| RecordError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_sink(path, Box::new(file), meta)
    }

    /// As [`create`](Self::create), writing to `sink` instead of a file created at `path`
    /// (`path` names the output in errors). Every write error of the sink is returned by the
    /// call that hit it, naming `path` and the OS error.
    pub fn from_sink(
        path: &Path,
        sink: Box<dyn RecordingSink>,
        meta: &RecordingMetadata,
    ) -> Result<Self, RecordError> {
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .library(format!("magsep-record/{}", env!("CARGO_PKG_VERSION")))
            // Chunks end at every flush: once per frame, or per batch of buffered frames.
            .chunk_size(None)
            // Compress on the calling thread: the crate's default (a zstd worker per physical
            // core) hands every chunk to a worker and waits for it, which cost a one-particle
            // frame ~100 µs of thread wake-ups, more than the compression itself.
            .compression_threads(0)
            .compression_level(COMPRESSION_LEVEL);
        let mut writer = Self::unopened(path);
        let mut mcap = options
            .create(BufWriter::new(sink))
            .map_err(|e| writer.write_error(e))?;

        let (name, encoding, data) = state_schema()?;
        let state_schema = mcap
            .add_schema(&name, &encoding, &data)
            .map_err(|e| writer.write_error(e))?;
        let scene =
            <SceneUpdate as Encode>::get_schema().ok_or_else(|| RecordError::InvalidInput {
                detail: "foxglove provides no schema for SceneUpdate".into(),
            })?;
        let scene_schema = mcap
            .add_schema(&scene.name, &scene.encoding, &scene.data)
            .map_err(|e| writer.write_error(e))?;
        let no_meta = BTreeMap::new();
        let encoding = <SceneUpdate as Encode>::get_message_encoding();
        writer.state_channel = mcap
            .add_channel(state_schema, STATE_TOPIC, &encoding, &no_meta)
            .map_err(|e| writer.write_error(e))?;
        writer.scene_channel = mcap
            .add_channel(scene_schema, SCENE_TOPIC, &encoding, &no_meta)
            .map_err(|e| writer.write_error(e))?;
        writer.mcap = Some(mcap);

        let entries = metadata_entries(meta)?;
        writer.write_metadata(METADATA_NAME, entries)?;
        Ok(writer)
    }

    /// A writer of `path` with no MCAP writer yet (nothing open, nothing written).
    fn unopened(path: &Path) -> Self {
        Self {
            mcap: None,
            path: path.to_path_buf(),
            state_channel: 0,
            scene_channel: 0,
            frames_written: 0,
            last_log_time: None,
            buf: Vec::new(),
            scene_buf: Vec::new(),
            decor: SceneDecor::default(),
            scene_cache: SceneCache::default(),
            channels: Vec::new(),
            max_chunk: MAX_CHUNK_BYTES,
            buffering: None,
            pending: 0,
            last_flush: Instant::now(),
            last_frame: None,
            queued: Vec::new(),
            queued_particles: 0,
            deferred_error: None,
            background: None,
        }
    }

    /// Let frames that arrive fast share chunks: [`write_frame`](Self::write_frame) then ends
    /// the chunk (one zstd frame and one write to the file) only once `policy.max_bytes` of
    /// messages are pending, `policy.max_wait` has passed since the last flush, or the frame
    /// came `policy.max_wait` or more after the previous one (the first frame and slow frames
    /// are written at once), instead of at every frame. Small frames (a few particles) then
    /// cost a fraction of the time. Every other write (metadata, channels,
    /// [`finish`](Self::finish), dropping the writer) still flushes at once, the pending frames
    /// included; a process killed without finishing loses only frames that came less than
    /// `max_wait` after the last flush. Small frames are also encoded in batches (see
    /// `writer/queue.rs`; the file's bytes do not change), so an encoding error can be returned
    /// by a later call than the frame's. `None` restores one chunk per frame (the default).
    pub fn buffer_frames(&mut self, policy: Option<FrameBuffering>) {
        if let Some(bg) = &mut self.background {
            // an error of the writer thread is returned by the next fallible call
            bg.send_unit(move |w| w.buffer_frames(policy));
            return;
        }
        self.buffering = policy;
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of frames written so far (those still queued for encoding included).
    pub fn frames_written(&self) -> u64 {
        self.frames_written + self.queued.len() as u64
    }

    /// Writes `frame` as one message on [`STATE_TOPIC`] and one on [`SCENE_TOPIC`], both with log
    /// and publish time [`log_time_ns`] (clamped to be non-decreasing), then ends the chunk and
    /// flushes the file (unless frames are buffered, see [`buffer_frames`](Self::buffer_frames)).
    ///
    /// `colours` gives each particle's RGBA colour (components in 0..1) in the scene, in the
    /// frame's particle order; `None` uses a default colour. Fails with
    /// [`RecordError::InvalidInput`] if the frame's arrays (or `colours`) differ in length, or
    /// if the frame's chunk would exceed [`MAX_CHUNK_BYTES`] (1 GiB, the readers' default
    /// limit; about two million particles), before anything is written.
    pub fn write_frame(
        &mut self,
        frame: &ParticleFrame,
        colours: Option<&[[f32; 4]]>,
    ) -> Result<(), RecordError> {
        self.write_frame_cow(Cow::Borrowed(frame), colours.map(Cow::Borrowed))
    }

    /// As [`write_frame`](Self::write_frame), taking the frame and its colours: a small frame
    /// of a buffered writer is then queued as it is instead of copied (see
    /// [`buffer_frames`](Self::buffer_frames)). The file's bytes are the same.
    pub fn write_frame_owned(
        &mut self,
        frame: ParticleFrame,
        colours: Option<Vec<[f32; 4]>>,
    ) -> Result<(), RecordError> {
        self.write_frame_cow(Cow::Owned(frame), colours.map(Cow::Owned))
    }

    fn write_frame_cow(
        &mut self,
        frame: Cow<'_, ParticleFrame>,
        colours: Option<Cow<'_, [[f32; 4]]>>,
    ) -> Result<(), RecordError> {
        let n = particle_count(&frame)?;
        if let Some(c) = &colours
            && c.len() != n
        {
            return Err(RecordError::InvalidInput {
                detail: format!(
                    "frame at step {}: {} colours for {n} particles",
                    frame.step,
                    c.len()
                ),
            });
        }
        if let Some(bg) = &mut self.background {
            self.frames_written += 1;
            let (frame, colours) = (frame.into_owned(), colours.map(Cow::into_owned));
            return bg.send_frame(frame, colours);
        }
        if let Some(e) = self.deferred_error.take() {
            return Err(e);
        }
        if self.queues(n) {
            self.queue_frame(frame.into_owned(), colours.map(Cow::into_owned), n);
            return self.after_frame();
        }
        self.drain_queue()?;
        self.encode_frame(&frame, colours.as_deref())?;
        self.after_frame()
    }

    /// Encode `frame` and write its two messages into the open chunk (ending the chunk first
    /// if the frame would make it larger than readers accept); no flush.
    fn encode_frame(
        &mut self,
        frame: &ParticleFrame,
        colours: Option<&[[f32; 4]]>,
    ) -> Result<(), RecordError> {
        let n = frame.ids.len();
        let log_time = log_time_ns(frame).max(self.last_log_time.unwrap_or(0));
        // MCAP sequence numbers are u32; wrapping after 2^32 frames is harmless.
        let sequence = self.frames_written as u32;

        // both message buffers are kept between frames (a small frame's scene update is a
        // few kB, which a new buffer reaches through several reallocations)
        let mut scene = std::mem::take(&mut self.scene_buf);
        encode_scene_update(
            frame,
            colours,
            &self.decor,
            log_time,
            &mut self.scene_cache,
            &mut scene,
        );
        self.buf.clear();
        encode_state(frame, &mut self.buf);
        // The frame's chunk holds both messages (record and message headers: 31 bytes each).
        let chunk = (self.buf.len() + scene.len() + 62) as u64;
        if chunk > self.max_chunk {
            self.scene_buf = scene;
            return Err(RecordError::InvalidInput {
                detail: format!(
                    "frame at step {} of {n} particles takes {chunk} bytes, more than the \
                     {} bytes per chunk that readers accept",
                    frame.step, self.max_chunk
                ),
            });
        }
        let result = self.write_frame_messages(&scene, chunk, sequence, log_time);
        self.scene_buf = scene;
        result?;
        self.pending += chunk;
        self.last_log_time = Some(log_time);
        self.frames_written += 1;
        Ok(())
    }

    /// Write a frame's messages: `self.buf` on [`STATE_TOPIC`], `scene` on [`SCENE_TOPIC`]
    /// (flushing the pending frames first if the frame's `chunk` bytes would make the open
    /// chunk larger than readers accept); no flush.
    fn write_frame_messages(
        &mut self,
        scene: &[u8],
        chunk: u64,
        sequence: u32,
        time: u64,
    ) -> Result<(), RecordError> {
        // a chunk never grows past what readers accept: flush the frames pending first
        if self.pending > 0 && self.pending + chunk > self.max_chunk {
            self.flush()?;
        }
        self.write_buf(self.state_channel, sequence, time)?;
        let header = MessageHeader {
            channel_id: self.scene_channel,
            sequence,
            log_time: time,
            publish_time: time,
        };
        let result = self.mcap().write_to_known_channel(&header, scene);
        result.map_err(|e| self.write_error(e))
    }

    /// Fibres to draw (as cylinders, entity `fibres`) in every following scene update.
    pub fn set_fibres(&mut self, fibres: Vec<FibreShape>) {
        if let Some(bg) = &mut self.background {
            bg.send_unit(move |w| w.set_fibres(fibres));
            return;
        }
        self.drain_before_decor();
        self.decor.fibres = fibres;
        self.scene_cache.clear_statics();
    }

    /// Hard walls to draw (entity `walls`, sized from each frame's box edges) in every
    /// following scene update: a [`WallShape`], or any value that serialises like one (e.g.
    /// `magsep_components::container::Walls`, whose serde form is the same; this keeps the codec
    /// free of ECS types). A value of another form draws no walls.
    pub fn set_walls<W: serde::Serialize>(&mut self, walls: Option<W>) {
        if let Some(bg) = &mut self.background {
            let walls = walls.and_then(|w| WallShape::from_serialize(&w));
            bg.send_unit(move |w| w.set_walls(walls));
            return;
        }
        self.drain_before_decor();
        self.decor.walls = walls.and_then(|w| WallShape::from_serialize(&w));
    }

    /// Boxes to draw behind the particles (entity `backdrop`) in every following scene update.
    pub fn set_backdrop(&mut self, cubes: Vec<BackdropCube>) {
        if let Some(bg) = &mut self.background {
            bg.send_unit(move |w| w.set_backdrop(cubes));
            return;
        }
        self.drain_before_decor();
        self.decor.backdrop = cubes;
        self.scene_cache.clear_statics();
    }

    /// Superquadric semi-axes per particle (frame order; zero for spheres and rods): such
    /// particles are drawn as ellipsoids of these semi-axes.
    pub fn set_semi_axes(&mut self, semi_axes: Vec<DVec3>) {
        if let Some(bg) = &mut self.background {
            bg.send_unit(move |w| w.set_semi_axes(semi_axes));
            return;
        }
        self.drain_before_decor();
        self.decor.semi_axes = semi_axes;
    }

    /// Writes the metadata record [`SUMMARY_METADATA_NAME`] with key `summary` = `summary_json`
    /// (which must be valid JSON, normally an object), then flushes. May be called more than
    /// once; readers keep the last one.
    pub fn write_summary(&mut self, summary_json: &str) -> Result<(), RecordError> {
        serde_json::from_str::<serde_json::Value>(summary_json).map_err(|e| {
            RecordError::InvalidInput {
                detail: format!("summary is not valid JSON: {e}"),
            }
        })?;
        let entries = BTreeMap::from([("summary".to_string(), summary_json.to_string())]);
        self.write_metadata(SUMMARY_METADATA_NAME, entries)
    }

    /// As [`write_summary`](Self::write_summary) with the JSON text of `summary` (which, being
    /// a `serde_json::Value`, needs no check: a run's summary of a few thousand numbers took
    /// longer to parse again than to write).
    pub fn write_summary_value(&mut self, summary: &serde_json::Value) -> Result<(), RecordError> {
        if let Some(bg) = &mut self.background {
            // a copy is cheaper than its JSON text (formatting the numbers): leave that to
            // the writer thread
            let summary = summary.clone();
            return bg.send(Box::new(move |w| w.write_summary_value(&summary)), 0);
        }
        let entries = BTreeMap::from([("summary".to_string(), summary.to_string())]);
        self.write_metadata(SUMMARY_METADATA_NAME, entries)
    }

    /// Writes the metadata record [`INTERRUPTED_METADATA_NAME`] with key `reason` (e.g.
    /// `SIGINT`): the run was stopped before its end, its last frame is where it stopped.
    /// Then flushes.
    pub fn write_interrupted(&mut self, reason: &str) -> Result<(), RecordError> {
        let entries = BTreeMap::from([("reason".to_string(), reason.to_string())]);
        self.write_metadata(INTERRUPTED_METADATA_NAME, entries)
    }

    /// Writes the summary section (schemas, channels, statistics, indexes) and the footer and
    /// flushes the file to the operating system. It does not wait for the disk (an `fsync`
    /// costs ~20 ms, more than a short run; a file cut by a power failure is still read up to
    /// its last complete chunk): use [`finish_synced`](Self::finish_synced) for that.
    pub fn finish(self) -> Result<(), RecordError> {
        self.finish_inner(false)
    }

    /// As [`finish`](Self::finish), then syncs the file to disk ([`RecordingSink::sync`]).
    pub fn finish_synced(self) -> Result<(), RecordError> {
        self.finish_inner(true)
    }

    fn finish_inner(mut self, sync: bool) -> Result<(), RecordError> {
        if let Some(mut bg) = self.background.take() {
            return bg.finish(sync);
        }
        self.drain_queue()?;
        let Some(mut mcap) = self.mcap.take() else {
            return Ok(());
        };
        mcap.finish().map_err(|e| self.write_error(e))?;
        let mut sink = mcap
            .into_inner()
            .into_inner()
            .map_err(|e| self.io_error(e.into_error()))?;
        if sync {
            sink.sync().map_err(|e| self.io_error(e))?;
        }
        Ok(())
    }

    pub(crate) fn mcap(&mut self) -> &mut McapWriter {
        self.mcap
            .as_mut()
            .expect("RecordingWriter holds its MCAP writer until finish() consumes it")
    }

    /// Writes `self.buf` as one message (no flush).
    fn write_buf(&mut self, channel: u16, sequence: u32, time: u64) -> Result<(), RecordError> {
        let header = MessageHeader {
            channel_id: channel,
            sequence,
            log_time: time,
            publish_time: time,
        };
        let buf = std::mem::take(&mut self.buf);
        let result = self.mcap().write_to_known_channel(&header, &buf);
        self.buf = buf;
        result.map_err(|e| self.write_error(e))
    }

    pub(crate) fn write_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), RecordError> {
        if let Some(bg) = &mut self.background {
            let name = name.to_string();
            return bg.send(Box::new(move |w| w.write_metadata(&name, entries)), 0);
        }
        self.drain_queue()?;
        let metadata = Metadata {
            name: name.into(),
            metadata: entries,
        };
        let result = self.mcap().write_metadata(&metadata);
        result.map_err(|e| self.write_error(e))?;
        self.flush()
    }

    /// Ends the current chunk and flushes the `BufWriter` to the file (see `mcap::Writer::flush`).
    pub(crate) fn flush(&mut self) -> Result<(), RecordError> {
        self.pending = 0;
        self.last_flush = Instant::now();
        let result = self.mcap().flush();
        result.map_err(|e| self.write_error(e))
    }

    /// The error of a failed write; an I/O error is reported as such, so that its message
    /// names the OS error (e.g. `No space left on device (os error 28)`).
    pub(crate) fn write_error(&self, source: mcap::McapError) -> RecordError {
        match source {
            mcap::McapError::Io(e) => self.io_error(e),
            source => RecordError::Write {
                path: self.path.clone(),
                source,
            },
        }
    }

    fn io_error(&self, source: std::io::Error) -> RecordError {
        RecordError::Io {
            path: self.path.clone(),
            source,
        }
    }
}

impl Drop for RecordingWriter {
    /// Finishes the file best-effort if [`finish`](Self::finish) was not called; errors are
    /// ignored and nothing panics (the underlying `mcap::Writer` also finishes on drop).
    fn drop(&mut self) {
        if self.mcap.is_some() {
            let _ = self.drain_queue();
        }
        if let Some(mut mcap) = self.mcap.take() {
            let _ = mcap.finish();
            // Dropping the BufWriter flushes it, ignoring errors.
        }
    }
}

impl std::fmt::Debug for RecordingWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordingWriter")
            .field("path", &self.path)
            .field("frames_written", &self.frames_written)
            .field("channels", &self.channels.len())
            .field("finished", &self.mcap.is_none())
            .finish()
    }
}
