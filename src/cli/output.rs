//! Outputs of the CLI: output paths checked before any computation, and standard output
//! written without panicking.
//!
//! **Output files** (`run --record`, `replay --resume --record`, `field --out`) are checked
//! before the scene is run or the recording read in full ([`check_file`]):
//!
//! * the path must not be a directory, a device, a FIFO or a dangling symbolic link;
//! * it must not be the same file as any input: the scene file, the recording being resumed,
//!   the points CSV, a recording the scene names (`[[fibre_packings]] recording`). Files are
//!   compared by device and inode on Unix (so hard links and symbolic links are caught) and by
//!   canonical path elsewhere. `--force` never allows this;
//! * an existing file is refused unless `--force` is given;
//! * the file (if it exists) or its directory (if not) must be writable: a directory that
//!   does not exist is not created.
//!
//! **Output directories** (`chart --out`) are checked by [`check_dir`]: an existing path must
//! be a writable directory (the chart files in it are replaced), a missing one is created by
//! the chart, so its nearest existing ancestor must be a writable directory.
//!
//! Every failed check is bad input (exit 2) and touches nothing.
//!
//! **Standard output** is written by [`print`], which returns an error instead of panicking:
//! a closed pipe (`magsep info f.mcap | head -1`) ends the command quietly with exit 1 (no
//! message; the reader has what it wanted), any other write error (`> /dev/full`) with exit 1
//! and a message. A run's recording is finished before its summary is printed, so it is
//! complete either way.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::CliError;

/// An input file an output must not overwrite: what it is (e.g. `scene`) and its path.
pub struct Input {
    /// What the input is, for messages.
    pub what: &'static str,
    /// Its path.
    pub path: PathBuf,
}

impl Input {
    /// The input `what` at `path`.
    pub fn new(what: &'static str, path: impl Into<PathBuf>) -> Self {
        Self {
            what,
            path: path.into(),
        }
    }
}

/// Whether `a` and `b` are the same existing file (same device and inode on Unix, same
/// canonical path elsewhere). `false` if either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(ca), Ok(cb)) => ca == cb,
        _ => false,
    }
}

/// Checks that `dir` accepts new files, by creating and removing an empty probe file.
fn probe_dir(flag: &str, out: &Path, dir: &Path) -> Result<(), CliError> {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let probe = dir.join(format!(
        ".magsep-write-check-{}-{nanos}",
        std::process::id()
    ));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(CliError::input(format!(
            "{flag} {}: cannot create files in {}: {e}",
            out.display(),
            dir.display()
        ))),
    }
}

/// The directory `path` would be created in (`.` for a bare file name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Checks the output file `path` of option `flag` against the rules of the module header.
///
/// # Errors
/// Bad input (exit 2) naming the option, the path and the rule.
pub fn check_file(flag: &str, path: &Path, inputs: &[Input], force: bool) -> Result<(), CliError> {
    let bad = |what: String| CliError::input(format!("{flag} {}: {what}", path.display()));
    if path.as_os_str().is_empty() {
        return Err(CliError::input(format!("{flag}: empty path")));
    }
    match std::fs::symlink_metadata(path) {
        Ok(_) => {
            let meta = std::fs::metadata(path).map_err(|e| {
                bad(format!(
                    "a symbolic link whose target cannot be used ({e}); remove it or name \
                     another file"
                ))
            })?;
            if meta.is_dir() {
                return Err(bad("is a directory; name a file".into()));
            }
            if !meta.is_file() {
                return Err(bad(
                    "is not a regular file (a device, FIFO or socket)".into()
                ));
            }
            if let Some(input) = inputs.iter().find(|i| same_file(path, &i.path)) {
                return Err(bad(format!(
                    "is the same file as the {} {}: writing it would destroy the input \
                     (--force does not apply)",
                    input.what,
                    input.path.display()
                )));
            }
            if !force {
                return Err(bad("exists; pass --force to overwrite it".into()));
            }
            std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map(drop)
                .map_err(|e| bad(format!("cannot be written: {e}")))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let dir = parent_of(path);
            match std::fs::metadata(dir) {
                Ok(m) if m.is_dir() => probe_dir(flag, path, dir),
                Ok(_) => Err(bad(format!("{} is not a directory", dir.display()))),
                Err(e) => Err(bad(format!(
                    "its directory {} does not exist or cannot be read ({e})",
                    dir.display()
                ))),
            }
        }
        Err(e) => Err(bad(format!("cannot be used: {e}"))),
    }
}

/// Checks the output directory `path` of option `flag` (see the module header).
///
/// # Errors
/// Bad input (exit 2) naming the option, the path and the rule.
pub fn check_dir(flag: &str, path: &Path) -> Result<(), CliError> {
    let bad = |what: String| CliError::input(format!("{flag} {}: {what}", path.display()));
    if path.as_os_str().is_empty() {
        return Err(CliError::input(format!("{flag}: empty path")));
    }
    // the path itself or its nearest existing ancestor
    let mut dir = path;
    loop {
        match std::fs::metadata(dir) {
            Ok(m) if m.is_dir() => return probe_dir(flag, path, dir),
            Ok(_) if dir == path => return Err(bad("exists and is not a directory".into())),
            Ok(_) => return Err(bad(format!("{} is not a directory", dir.display()))),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let up = parent_of(dir);
                if up == dir {
                    return Err(bad(format!("cannot be created ({e})")));
                }
                dir = up;
            }
            Err(e) => return Err(bad(format!("cannot be used: {e}"))),
        }
    }
}

/// The CLI error of a failed write to standard output: a closed pipe ends quietly (exit 1,
/// no message), anything else is a runtime failure with a message (exit 1).
pub fn stdout_error(e: std::io::Error) -> CliError {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        CliError::runtime(String::new())
    } else {
        CliError::runtime(format!("cannot write to standard output: {e}"))
    }
}

/// Writes `text` and a newline to standard output and flushes it.
///
/// # Errors
/// [`stdout_error`] of a failed write (never a panic).
pub fn print(text: impl std::fmt::Display) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}")
        .and_then(|()| out.flush())
        .map_err(stdout_error)
}

/// Writes `message` to standard error, ignoring failures (a closed stderr must not panic).
pub fn eprint(message: impl std::fmt::Display) {
    let _ = writeln!(std::io::stderr().lock(), "{message}");
}
