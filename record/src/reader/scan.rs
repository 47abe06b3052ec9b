//! Linear scan of a recording from its start, one record at a time, tolerating files cut short.
//!
//! A file without summary or footer (a killed process) still yields every complete chunk.
//! Chunks are taken whole: their records are used only once the chunk has decompressed and
//! passed its CRC. A chunk whose bytes are damaged but whose record frame (opcode, length) is
//! sound is skipped ([`Layout::skipped`]) and the scan goes on with the next record, so that
//! the metadata and the chunks after it are still read; the channels and schemas it may have
//! defined are then taken from the summary section when the file has a valid one, and the
//! data-section CRC (which the damaged chunk breaks) is not checked. Otherwise the
//! data-section and summary CRCs are checked when the file has them. Only one record is in
//! memory at a time (records that are not needed are streamed through the CRC), and every
//! length is checked against the bytes left in the file and the reader's limits before
//! anything is read.

use super::chunk::{ReaderLimits, decompress, split_records};
use super::layout::{End, Layout, Unit};
use super::source::Source;
use super::summary;
use crate::RecordError;
use crate::parse::{Cursor, hex_prefix};
use mcap::records::op;
use std::io::{Read, Seek};
use std::path::Path;

/// Why the scan stopped before the footer.
enum Stop {
    /// The file ends early; the message says where.
    Truncated(String),
    /// A damaged or undecodable record, or an I/O error.
    Failed(RecordError),
    /// A chunk whose bytes are damaged, in a sound record frame (its offset, what is wrong):
    /// skipped.
    DamagedChunk(u64, String),
}

fn corrupt(offset: u64, detail: impl Into<String>) -> Stop {
    Stop::Failed(RecordError::Corrupt {
        offset,
        detail: detail.into(),
    })
}

/// Name of an MCAP record type, for messages.
pub(crate) fn kind(opcode: u8) -> String {
    let name = match opcode {
        op::HEADER => "header",
        op::FOOTER => "footer",
        op::SCHEMA => "schema",
        op::CHANNEL => "channel",
        op::MESSAGE => "message",
        op::CHUNK => "chunk",
        op::MESSAGE_INDEX => "message index",
        op::CHUNK_INDEX => "chunk index",
        op::ATTACHMENT => "attachment",
        op::ATTACHMENT_INDEX => "attachment index",
        op::STATISTICS => "statistics",
        op::METADATA => "metadata",
        op::METADATA_INDEX => "metadata index",
        op::SUMMARY_OFFSET => "summary offset",
        op::DATA_END => "data end",
        _ => return format!("private (opcode 0x{opcode:02x})"),
    };
    name.to_string()
}

/// Scans the whole file; the returned layout's `end` says how it ends.
pub(crate) fn scan<R: Read + Seek>(
    src: &mut Source<R>,
    path: &Path,
    limits: &ReaderLimits,
) -> Layout {
    let mut scan = Scan {
        src,
        path,
        limits,
        layout: Layout::default(),
        data_crc: crc32fast::Hasher::new(),
    };
    let end = match scan.run() {
        Ok(()) => End::Complete,
        Err(Stop::Truncated(msg)) => End::Truncated(msg),
        Err(Stop::Failed(e)) => End::Failed(e),
        Err(Stop::DamagedChunk(offset, detail)) => {
            End::Failed(RecordError::Corrupt { offset, detail })
        }
    };
    let mut layout = scan.layout;
    layout.end = end;
    layout
}

struct Scan<'a, R> {
    src: &'a mut Source<R>,
    path: &'a Path,
    limits: &'a ReaderLimits,
    layout: Layout,
    /// CRC of the data section so far.
    data_crc: crc32fast::Hasher,
}

impl<R: Read + Seek> Scan<'_, R> {
    fn truncated(&self, what: String) -> Stop {
        Stop::Truncated(format!(
            "file ends at byte {} {what}: {}",
            self.src.len,
            crate::complete_frames_read(self.layout.state_messages)
        ))
    }

    fn io(&self, source: std::io::Error) -> Stop {
        Stop::Failed(RecordError::Io {
            path: self.path.to_path_buf(),
            source,
        })
    }

    /// Reads `n` bytes at `offset` (within the file, checked by the caller).
    fn read(&mut self, offset: u64, n: u64) -> Result<Vec<u8>, Stop> {
        self.src.read_at(offset, n).map_err(|e| self.io(e))
    }

    fn run(&mut self) -> Result<(), Stop> {
        let len = self.src.len;
        let magic = mcap::MAGIC;
        let mlen = magic.len() as u64;
        let head = self.src.read_upto(0, mlen).map_err(|e| self.io(e))?;
        if len < mlen && magic.starts_with(&head) {
            return Err(self.truncated("inside the 8-byte MCAP magic (no footer)".into()));
        }
        if !head.starts_with(magic) {
            // The file's own bytes are never quoted: it may be any file (a scene naming
            // `/etc/passwd` as a recording must not reveal it).
            return Err(Stop::Failed(RecordError::NotMcap {
                detail: format!(
                    "the file does not start with the MCAP magic [{}]{}",
                    hex_prefix(magic),
                    if head
                        .iter()
                        .all(|b| b.is_ascii_graphic() || b.is_ascii_whitespace())
                    {
                        " (it starts with text)"
                    } else {
                        ""
                    }
                ),
            }));
        }
        self.data_crc.update(magic);
        // A file ending in the magic was finished: a record running past its end is damage.
        let finished = len >= 2 * mlen + 9
            && self
                .src
                .read_upto(len - mlen, mlen)
                .map_err(|e| self.io(e))?
                == magic;
        let mut pos = mlen;
        let mut in_summary = false;
        loop {
            let start = pos;
            if len - pos < 9 {
                let what = if pos == len && in_summary {
                    "after a complete record of the summary section (no footer)".into()
                } else if pos == len {
                    "after a complete record, before the summary section (no footer)".into()
                } else {
                    format!(
                        "inside the opcode and length of a record that starts at byte {pos} \
                         (no footer)"
                    )
                };
                return Err(self.truncated(what));
            }
            let header = self.read(pos, 9)?;
            let opcode = header[0];
            let mut rlen = [0u8; 8];
            rlen.copy_from_slice(&header[1..9]);
            let rlen = u64::from_le_bytes(rlen);
            if opcode == 0 || (op::DATA_END < opcode && opcode < 0x80) {
                return Err(corrupt(
                    start,
                    format!(
                        "opcode 0x{opcode:02x} is not an MCAP record type \
                         (expected 0x01..=0x0f, or >= 0x80 for a private record)"
                    ),
                ));
            }
            if (start == mlen) != (opcode == op::HEADER) {
                return Err(corrupt(
                    start,
                    format!(
                        "found a {} record; expected exactly one header record, \
                         right after the magic",
                        kind(opcode)
                    ),
                ));
            }
            let avail = len - pos - 9;
            if rlen > avail {
                return Err(self.overlong(start, opcode, rlen, avail, finished));
            }
            pos += 9 + rlen;
            let reads_body = matches!(opcode, op::FOOTER | op::DATA_END)
                || (!in_summary
                    && matches!(
                        opcode,
                        op::CHUNK | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA
                    ));
            if reads_body && rlen > self.limits.max_record_bytes {
                return Err(corrupt(
                    start,
                    format!(
                        "{} record declares {rlen} bytes, more than the reader's limit of {} \
                         bytes per record",
                        kind(opcode),
                        self.limits.max_record_bytes
                    ),
                ));
            }
            match opcode {
                op::FOOTER => {
                    let body = self.read(start + 9, rlen)?;
                    return self.footer(start, &body);
                }
                op::CHUNK if in_summary => {
                    return Err(corrupt(start, "chunk record in the summary section"));
                }
                op::CHUNK => {
                    let record = self.read(start, 9 + rlen)?;
                    self.data_crc.update(&record);
                    match self.chunk(start, &record[9..]) {
                        Ok(()) => self.layout.units.push(Unit::Chunk {
                            offset: start,
                            len: 9 + rlen,
                            channels: None,
                        }),
                        Err(Stop::DamagedChunk(at, detail)) => self.skip_chunk(at, detail),
                        Err(stop) => return Err(stop),
                    }
                }
                _ if in_summary => {} // Summary records repeat what the data section holds.
                op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA => {
                    let record = self.read(start, 9 + rlen)?;
                    self.data_crc.update(&record);
                    let body = &record[9..];
                    let result = match opcode {
                        op::SCHEMA => self.layout.schema(body),
                        op::CHANNEL => self.layout.channel(body),
                        op::MESSAGE => self.layout.message(body),
                        _ => self.layout.metadata_record(body),
                    };
                    let at = format!("the {} record at byte {start}", kind(opcode));
                    result.map_err(|e| Stop::Failed(e.at(start, &at)))?;
                    if opcode == op::MESSAGE {
                        self.layout.units.push(Unit::Message {
                            offset: start,
                            len: 9 + rlen,
                        });
                    }
                }
                op::DATA_END => {
                    let body = self.read(start + 9, rlen)?;
                    let saved = Cursor::new(&body)
                        .u32("data section CRC")
                        .map_err(|e| corrupt(start, format!("data end record: {e}")))?;
                    let computed = self.data_crc.clone().finalize();
                    // a skipped chunk accounts for a mismatch
                    if saved != 0 && saved != computed && self.layout.skipped.is_empty() {
                        return Err(corrupt(
                            start,
                            format!(
                                "data section CRC mismatch: the data end record stores \
                                 0x{saved:08x}, bytes 0..{start} give 0x{computed:08x}"
                            ),
                        ));
                    }
                    in_summary = true;
                }
                // Header, indexes, statistics, attachments, private records: streamed
                // through the data CRC.
                _ => {
                    let mut crc = std::mem::take(&mut self.data_crc);
                    let result = self.src.hash_range(start, pos, &mut crc);
                    self.data_crc = crc;
                    result.map_err(|e| self.io(e))?;
                }
            }
        }
    }

    /// The stop for a record at `start` declaring `rlen` bytes when only `avail` follow.
    fn overlong(&self, start: u64, opcode: u8, rlen: u64, avail: u64, finished: bool) -> Stop {
        let k = kind(opcode);
        if opcode == op::CHUNK && rlen == u64::MAX {
            return self.truncated(format!(
                "inside a chunk record that starts at byte {start} and was never \
                 completed (its length is still the writer's placeholder: the \
                 writing process stopped in the middle of a frame; no footer)"
            ));
        }
        if finished || rlen > self.limits.max_record_bytes {
            return corrupt(
                start,
                format!(
                    "{k} record declares a length of {rlen} bytes but only {avail} \
                     bytes follow; expected the record to end within the file"
                ),
            );
        }
        self.truncated(format!(
            "inside a {k} record that starts at byte {start} and \
             declares {rlen} bytes (no footer)"
        ))
    }

    /// Checks the footer at `start` (body `body`), the summary CRC and the closing magic.
    fn footer(&mut self, start: u64, body: &[u8]) -> Result<(), Stop> {
        let mut c = Cursor::new(body);
        let parsed = (|| {
            let summary_start = c.u64("summary start")?;
            c.u64("summary offset start")?;
            let crc = c.u32("summary CRC")?;
            Ok::<_, String>((summary_start, crc))
        })();
        let (summary_start, saved) =
            parsed.map_err(|e| corrupt(start, format!("footer record: {e}")))?;
        let crc_end = start + 9 + 16;
        if saved != 0 {
            let from = if summary_start == 0 {
                start
            } else {
                summary_start
            };
            if from > start {
                return Err(corrupt(
                    start,
                    format!("footer says the summary starts at byte {from}, after the footer"),
                ));
            }
            let mut hasher = crc32fast::Hasher::new();
            self.src
                .hash_range(from, crc_end, &mut hasher)
                .map_err(|e| self.io(e))?;
            let computed = hasher.finalize();
            if computed != saved {
                return Err(corrupt(
                    start,
                    format!(
                        "summary CRC mismatch: the footer stores 0x{saved:08x}, \
                         bytes {from}..{crc_end} give 0x{computed:08x}"
                    ),
                ));
            }
        }
        let end = start + 9 + body.len() as u64;
        let magic = mcap::MAGIC;
        let tail = self
            .src
            .read_upto(end, magic.len() as u64)
            .map_err(|e| self.io(e))?;
        if tail.len() < magic.len() && magic.starts_with(&tail) {
            return Err(self.truncated(format!(
                "inside the closing magic after the footer at byte {start} \
                 (all records present)"
            )));
        }
        if !tail.starts_with(magic) {
            return Err(corrupt(
                end,
                format!(
                    "the footer at byte {start} is not followed by the closing MCAP magic [{}]",
                    hex_prefix(magic)
                ),
            ));
        }
        let after = end + magic.len() as u64;
        if after < self.src.len {
            self.layout.trailing = Some((after, self.src.len - after));
        }
        Ok(())
    }

    /// Leaves out the damaged chunk at `offset`; at the first, takes the schemas and channels
    /// that the scan has not met yet from the summary section (they may be defined in the
    /// chunk).
    fn skip_chunk(&mut self, offset: u64, detail: String) {
        if self.layout.skipped.is_empty()
            && let Some(summary) = summary::indexed(self.src, self.limits)
        {
            for (id, schema) in summary.schemas {
                self.layout.schemas.entry(id).or_insert(schema);
            }
            for (id, mut channel) in summary.channels {
                channel.message_count = 0; // counted by the scan
                self.layout.channels.entry(id).or_insert(channel);
            }
        }
        self.layout.note_skipped(offset, detail);
    }

    /// Decompresses the chunk at byte `start` (record body `body`) and uses its records once
    /// the whole chunk has decompressed and passed its CRC.
    fn chunk(&mut self, start: u64, body: &[u8]) -> Result<(), Stop> {
        let damaged = |e: String| Stop::DamagedChunk(start, format!("chunk: {e}"));
        let data = decompress(body, self.limits).map_err(damaged)?;
        let records = split_records(&data).map_err(damaged)?;
        let state_before = self.layout.state_messages;
        for (k, (opcode, range)) in records.into_iter().enumerate() {
            let body = &data[range];
            let result = match opcode {
                op::SCHEMA => self.layout.schema(body),
                op::CHANNEL => self.layout.channel(body),
                op::MESSAGE => self.layout.message(body),
                op::METADATA => self.layout.metadata_record(body),
                _ => Ok(()),
            };
            if let Err(e) = result {
                self.layout.state_messages = state_before;
                let at = format!(
                    "the {} record #{k} in the chunk at byte {start}",
                    kind(opcode)
                );
                return Err(Stop::Failed(e.at(start, &at)));
            }
        }
        Ok(())
    }
}
