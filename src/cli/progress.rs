//! Progress on stderr for long commands (`run`, `replay --resume`, `sweep`).
//!
//! On a terminal it is an `indicatif` bar redrawn in place. When stderr is not a terminal (a
//! log file, CI, `nohup`), `indicatif` draws nothing, so a plain line is written instead every
//! [`log_interval`] seconds (10 s by default; `MAGSEP_PROGRESS_INTERVAL` sets it, in seconds):
//! `[elapsed] done/total steps (pct %) message`. A run shorter than the interval writes none.
//! `--quiet` writes neither.

use std::io::{IsTerminal, Write};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::ProgressBar;

use crate::scene::Progress;

/// The environment variable that sets the interval of the plain progress lines \[s\].
pub const INTERVAL_ENV: &str = "MAGSEP_PROGRESS_INTERVAL";

/// Interval of the plain progress lines: `MAGSEP_PROGRESS_INTERVAL` seconds when it is a
/// positive number (clamped to 0.05 s..1 day), else 10 s; any other value is warned about on
/// stderr (once per process) and the default used.
pub fn log_interval() -> Duration {
    let value = std::env::var(INTERVAL_ENV).ok();
    parse_interval(value.as_deref()).unwrap_or_else(|why| {
        static WARNED: std::sync::Once = std::sync::Once::new();
        WARNED.call_once(|| eprintln!("warning: {why}"));
        DEFAULT_INTERVAL
    })
}

/// The progress-line interval when `MAGSEP_PROGRESS_INTERVAL` is unset or not usable.
pub const DEFAULT_INTERVAL: Duration = Duration::from_secs(10);

/// The interval that a value of `MAGSEP_PROGRESS_INTERVAL` sets (`None`: unset, the default),
/// or why the value is not usable.
///
/// # Errors
/// A message naming the variable and its value, when it is not a positive number of seconds.
pub fn parse_interval(value: Option<&str>) -> Result<Duration, String> {
    let Some(value) = value else {
        return Ok(DEFAULT_INTERVAL);
    };
    match value.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(Duration::from_secs_f64(s.clamp(0.05, 86_400.0))),
        _ => Err(format!(
            "{INTERVAL_ENV}={value:?} is not a positive number of seconds: progress lines \
             every {} s",
            DEFAULT_INTERVAL.as_secs()
        )),
    }
}

/// A progress display on stderr: a bar on a terminal, plain lines otherwise (see the module).
pub struct StderrProgress {
    bar: ProgressBar,
    lines: Option<(Sender<()>, JoinHandle<()>)>,
}

impl StderrProgress {
    /// `unit` names what the bar counts ("steps", "points"). Hidden when `quiet`.
    pub fn new(quiet: bool, unit: &'static str) -> Self {
        if quiet {
            return Self {
                bar: ProgressBar::hidden(),
                lines: None,
            };
        }
        if std::io::stderr().is_terminal() {
            return Self {
                bar: ProgressBar::new_spinner(),
                lines: None,
            };
        }
        // hidden bars still count: the line writer reads their state
        let bar = ProgressBar::hidden();
        let (tx, rx) = mpsc::channel::<()>();
        let every = log_interval();
        let state = bar.clone();
        let spawned = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                while let Err(RecvTimeoutError::Timeout) = rx.recv_timeout(every) {
                    let _ = writeln!(std::io::stderr(), "{}", line(&state, unit));
                }
            });
        Self {
            lines: spawned.ok().map(|h| (tx, h)),
            bar,
        }
    }

    /// The bar (for styles and counts).
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }
}

/// One plain progress line of `bar`'s state.
fn line(bar: &ProgressBar, unit: &str) -> String {
    let secs = bar.elapsed().as_secs();
    let clock = format!("{:02}:{:02}:{:02}", secs / 3600, secs / 60 % 60, secs % 60);
    let done = bar.position();
    let count = match bar.length() {
        Some(total) if total > 0 => format!(
            "{done}/{total} {unit} ({:.0} %)",
            100.0 * done as f64 / total as f64
        ),
        _ => format!("{done} {unit}"),
    };
    let msg = bar.message();
    if msg.is_empty() {
        format!("[{clock}] {count}")
    } else {
        format!("[{clock}] {count} {msg}")
    }
}

impl Drop for StderrProgress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
        if let Some((tx, handle)) = self.lines.take() {
            let _ = tx.send(());
            let _ = handle.join();
        }
    }
}

impl Progress for StderrProgress {
    fn set_total(&self, steps: u64) {
        self.bar.set_length(steps);
        self.bar.set_style(
            indicatif::ProgressStyle::with_template(
                "[{elapsed_precise}] {bar:40} {pos}/{len} steps ({eta} left) {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    }
    fn advance(&self, steps: u64) {
        self.bar.inc(steps);
    }
    fn message(&self, text: String) {
        self.bar.set_message(text);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_values() {
        assert_eq!(parse_interval(None), Ok(DEFAULT_INTERVAL));
        assert_eq!(
            parse_interval(Some(" 2.5 ")),
            Ok(Duration::from_millis(2500))
        );
        assert_eq!(parse_interval(Some("1e-9")), Ok(Duration::from_millis(50)));
        for bad in ["abc", "", "0", "-1", "inf", "NaN"] {
            let e = parse_interval(Some(bad)).unwrap_err();
            assert!(
                e.contains(INTERVAL_ENV) && e.contains(&format!("{bad:?}")),
                "{e}"
            );
        }
    }

    #[test]
    fn a_line_shows_counts_share_and_message() {
        let bar = ProgressBar::hidden();
        bar.set_length(200);
        bar.inc(50);
        bar.set_message("phi 0.41");
        let l = line(&bar, "steps");
        assert!(l.ends_with("50/200 steps (25 %) phi 0.41"), "{l}");
        assert!(l.starts_with("[00:00:0"), "{l}");
        let open = ProgressBar::hidden();
        open.inc(7);
        assert!(line(&open, "points").ends_with("] 7 points"));
    }
}
