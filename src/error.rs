//! The error types of scenes, runs and replays (a leaf module: every other module of the crate
//! may use it, it uses none of them).

use std::fmt;

use magsep_plugins::record::RecordError;

/// One problem in a scene: where (a key path such as `particles[2].shape.radius`) and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Key path, `(syntax)` for TOML syntax errors, `(file)` for I/O.
    pub path: String,
    /// What is wrong, with the offending value.
    pub message: String,
}

/// Longest message kept in full \[characters\]; a longer one (e.g. echoing a huge string
/// value) is cut in the middle.
pub const MAX_MESSAGE_CHARS: usize = 1000;

impl SceneError {
    /// A new error at `path`. Long numbers (`1e300` printed by `{}` has 301 digits) are
    /// rewritten in scientific notation, and a message longer than
    /// [`MAX_MESSAGE_CHARS`] is cut, so no value floods the terminal.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: cut(&path.into(), MAX_MESSAGE_CHARS / 2),
            message: cut(&compact_numbers(&message.into()), MAX_MESSAGE_CHARS),
        }
    }
}

/// `text` with long numbers in scientific notation: more than 20 digits, more than 12 with a
/// decimal point, decimals below 1e-4 (`0.000000075` -> `7.5e-8`), and round integers from
/// 1e7 (`20000000` -> `2e7`); other integers (counts) stay exact.
pub fn compact_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let starts_number = b[i].is_ascii_digit() && (i == 0 || !is_word(b[i - 1]));
        if !starts_number {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
            continue;
        }
        let mut j = i;
        let mut digits = 0;
        let mut dot = false;
        while j < b.len() && (b[j].is_ascii_digit() || (b[j] == b'.' && !dot)) {
            if b[j] == b'.' {
                // a dot followed by no digit ends the sentence, not the number
                if !b.get(j + 1).is_some_and(u8::is_ascii_digit) {
                    break;
                }
                dot = true;
            } else {
                digits += 1;
            }
            j += 1;
        }
        let number = &text[i..j];
        let followed_by_word = j < b.len() && is_word(b[j]);
        match number.parse::<f64>() {
            Ok(v)
                if !followed_by_word
                    && (digits > 20
                        || (dot && (digits > 12 || (v != 0.0 && v < 1e-4)))
                        || (!dot && digits >= 8 && number.ends_with("000000"))) =>
            {
                out.push_str(&format!("{v:e}"))
            }
            _ => out.push_str(number),
        }
        i = j;
    }
    out
}

fn is_word(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// `text` cut to about `max` characters, with the number of characters left out.
fn cut(text: &str, max: usize) -> String {
    let n = text.chars().count();
    if n <= max {
        return text.to_string();
    }
    let head: String = text.chars().take(max * 3 / 4).collect();
    let tail: String = text.chars().skip(n - max / 4).collect();
    format!(
        "{head} [... {} characters cut ...] {tail}",
        n - max * 3 / 4 - max / 4
    )
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

/// All problems found in a scene (never empty when returned as an error).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneErrors(pub Vec<SceneError>);

impl fmt::Display for SceneErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneErrors {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_become_scientific_and_short_ones_stay() {
        let huge = format!("got {}", 1e300);
        assert_eq!(compact_numbers(&huge), "got 1e300");
        assert_eq!(compact_numbers("got 0.000000000000001."), "got 1e-15.");
        assert_eq!(
            compact_numbers("in (0, 0.3], got 12.5"),
            "in (0, 0.3], got 12.5"
        );
        assert_eq!(compact_numbers("particles[12].x"), "particles[12].x");
        assert_eq!(compact_numbers("got -0.000000001"), "got -1e-9");
        assert_eq!(compact_numbers("radius 0.000000075 m"), "radius 7.5e-8 m");
        assert_eq!(compact_numbers("got 0.0005, 20000000"), "got 0.0005, 2e7");
        assert_eq!(compact_numbers("12345678 particles"), "12345678 particles");
        // digits inside a word (a hash, a name) are left alone
        assert_eq!(
            compact_numbers("id a12345678901234567"),
            "id a12345678901234567"
        );
    }

    #[test]
    fn a_huge_value_is_cut_and_the_cut_is_counted() {
        let e = SceneError::new(
            "a.b",
            format!("unknown value \"{}\"", "x".repeat(10_000_000)),
        );
        assert!(
            e.message.len() < MAX_MESSAGE_CHARS + 80,
            "{}",
            e.message.len()
        );
        assert!(e.message.contains("characters cut"));
        assert!(e.message.starts_with("unknown value \"xxx"));
    }
}

/// Why spawning failed (after validation only run-time failures remain).
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    /// Random insertion could not place a particle.
    #[error(transparent)]
    Insertion(#[from] magsep_systems::packing::insert::InsertionError),
    /// A pipeline or a plugin kind failed.
    #[error("{0}")]
    Other(String),
    /// The run's stop flag was set while spawning (`magsep run` exits 130 or 143); the reason
    /// given to the flag (e.g. `SIGINT`).
    #[error("interrupted by {0} while spawning the scene (nothing ran)")]
    Interrupted(String),
}

/// Errors while building or running a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scene could not be spawned (e.g. random insertion failed).
    #[error("spawning the scene failed: {0}")]
    Spawn(#[from] SpawnError),
    /// The schedule could not be built (ambiguity, cycle, a force no plugin consumes).
    #[error("building the schedule failed: {0}")]
    Schedule(String),
    /// The recording could not be written.
    #[error("recording failed: {0}")]
    Record(#[from] RecordError),
    /// Writing the recording failed during the run (the message names the file and the OS
    /// error); the run stopped at once.
    #[error("recording failed: {0}")]
    RecordWrite(String),
    /// The scene has no `[simulation]` (a field-only scene: use `magsep field`).
    #[error("the scene has no [simulation] to run (a field-only scene: use `magsep field`)")]
    NothingToRun,
    /// The frame to resume from does not fit the scene.
    #[error("cannot resume: {0}")]
    Resume(String),
    /// A numerical failure was reported.
    #[error("numerical failure: {0}")]
    Health(String),
    /// The run stopped on `error` (e.g. a recording write failure); `summary` is the summary
    /// of what ran, with the error's message as `"run_error"` (and `"interrupted": true` when
    /// the run ended before its end).
    #[error("{error}")]
    Partial {
        /// Why the run stopped.
        error: Box<SimError>,
        /// The summary of the steps that ran.
        summary: Box<serde_json::Value>,
    },
}

impl SimError {
    /// The summary of what ran before the error, when the run got that far.
    pub fn partial_summary(&self) -> Option<&serde_json::Value> {
        match self {
            Self::Partial { summary, .. } => Some(summary),
            _ => None,
        }
    }

    /// The error itself, without its partial summary.
    pub fn cause(&self) -> &SimError {
        match self {
            Self::Partial { error, .. } => error.cause(),
            e => e,
        }
    }

    /// The error without its partial summary.
    pub fn into_cause(self) -> SimError {
        match self {
            Self::Partial { error, .. } => error.into_cause(),
            e => e,
        }
    }
}

/// Why a replay or a resume failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The recording could not be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The recording has no `magsep` metadata record.
    #[error(
        "the recording has no `magsep` metadata record (scene text, seed): not written by magsep run"
    )]
    NoMetadata,
    /// The file ends before its `magsep` metadata record (a run killed at its start).
    #[error(
        "the recording ends before its `magsep` metadata record (scene text, seed), so there is \
         nothing to replay: {0}"
    )]
    TruncatedBeforeMetadata(String),
    /// The recorded scene does not parse with this program.
    #[error("the recorded scene is invalid:\n{0}")]
    Scene(#[from] SceneErrors),
    /// The recording holds no frame.
    #[error("the recording holds no frame{0}")]
    NoFrames(String),
    /// A frame is inconsistent.
    #[error("frame at step {step} is inconsistent: {detail}")]
    BadFrame {
        /// Step of the frame.
        step: u64,
        /// What is wrong.
        detail: String,
    },
    /// The recorded run used plugins this program does not have.
    #[error(
        "the recording was made with plugins this program lacks: {0}; continuing without them would silently change the run (build a binary with them, e.g. through magsep::cli::main_with)"
    )]
    MissingPlugins(String),
    /// The recorded run's forces differ from this program's (another kernel, a contribution
    /// more or less).
    #[error(
        "the recording's forces differ from this program's: recorded {recorded}, here {here}; continuing would silently change the run (resume with the program and plugins that made it)"
    )]
    ForcesDiffer {
        /// The recorded forces (JSON).
        recorded: String,
        /// This program's (JSON).
        here: String,
    },
    /// The pipeline cannot do this (e.g. resume), or the frame does not fit it or a plugin.
    #[error("{0}")]
    Unsupported(String),
    /// The continued run failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}
