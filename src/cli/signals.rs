//! SIGINT and SIGTERM during `magsep run` and `magsep sweep` (the handlers are installed by the
//! CLI only; the library's side is the [`StopFlag`]; a sweep stops as described in
//! `studies::sweep::run`).
//!
//! The first signal sets the run's stop flag: the current step ends, the final frame is
//! recorded, the recording is closed with its footer and a `magsep.interrupted` record, the
//! summary of what ran is printed on stdout marked `"interrupted": true` and
//! `"interrupted_by": "SIGINT"` (or `"SIGTERM"`), and the process exits with 128 + the signal
//! number: [`EXIT_SIGINT`] (130) or [`EXIT_SIGTERM`] (143), the shell's convention. A second
//! signal exits at once, with its own code, leaving the recording as a truncated file whose
//! finished frames stay readable; but a repeat of the first signal within
//! [`REPEAT_IGNORED`] of it is ignored: `timeout -s TERM` (without `--foreground`) and a
//! terminal's Ctrl-C to a process group can deliver one request twice, which is not a second
//! request.
//!
//! SIGXFSZ (a write past the process's file-size limit, `ulimit -f`) would kill the process by
//! default, with no summary and no word on why; [`survive_file_size_limit`] replaces that
//! action, so the write fails with EFBIG ("File too large") and the run ends as for any write
//! failure: its summary with `run_error`, exit code 1.

use crate::sim::StopFlag;

/// Exit code of a run stopped by SIGINT (128 + 2).
pub const EXIT_SIGINT: i32 = 130;
/// Exit code of a run stopped by SIGTERM (128 + 15).
pub const EXIT_SIGTERM: i32 = 143;

/// How soon after the first signal a repeat of the same signal is taken as the same request
/// (ignored) rather than a second one (exit at once).
pub const REPEAT_IGNORED: std::time::Duration = std::time::Duration::from_secs(1);

pub use imp::{SignalGuard, install, survive_file_size_limit};

#[cfg(unix)]
mod imp {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicI32, Ordering};
    use std::thread::JoinHandle;

    use signal_hook::consts::{SIGINT, SIGTERM};
    use signal_hook::iterator::{Handle, Signals};

    use super::StopFlag;
    use crate::cli::output::eprint;

    /// The installed handlers: a thread that receives the signals (so nothing runs in signal
    /// context). Dropping it stops that thread.
    pub struct SignalGuard {
        handle: Handle,
        thread: Option<JoinHandle<()>>,
        received: Arc<AtomicI32>,
    }

    fn name(signal: i32) -> &'static str {
        match signal {
            SIGINT => "SIGINT",
            SIGTERM => "SIGTERM",
            _ => "signal",
        }
    }

    /// Handle SIGINT and SIGTERM: the first sets `stop` (reason `SIGINT` or `SIGTERM`), the
    /// second exits the process at once with 128 + its number (a repeat of the first within
    /// [`super::REPEAT_IGNORED`] is ignored).
    ///
    /// # Errors
    /// The OS error when the handlers or their thread cannot be set up.
    pub fn install(stop: &StopFlag) -> std::io::Result<SignalGuard> {
        let mut signals = Signals::new([SIGINT, SIGTERM])?;
        let handle = signals.handle();
        let received = Arc::new(AtomicI32::new(0));
        let seen = received.clone();
        let stop = stop.clone();
        let thread = std::thread::Builder::new()
            .name("magsep-signals".into())
            .spawn(move || {
                let mut first_at: Option<std::time::Instant> = None;
                for signal in signals.forever() {
                    let first = seen
                        .compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst)
                        .is_ok();
                    if !first {
                        let echo = seen.load(Ordering::SeqCst) == signal
                            && first_at.is_some_and(|t| t.elapsed() < super::REPEAT_IGNORED);
                        if echo {
                            // e.g. `timeout`, which signals the process and then its group
                            continue;
                        }
                        let first = seen.load(Ordering::SeqCst);
                        let what = if first == signal {
                            format!("{} again", name(signal))
                        } else {
                            format!("{} after {}", name(signal), name(first))
                        };
                        eprint(format!("\nmagsep: {what}: exiting at once"));
                        std::process::exit(128 + signal);
                    }
                    first_at = Some(std::time::Instant::now());
                    eprint(format!(
                        "\nmagsep: {} received: ending the current step and closing the recording \
                         (send it again to exit at once)",
                        name(signal)
                    ));
                    stop.request_stop(name(signal));
                }
            })?;
        Ok(SignalGuard {
            handle,
            thread: Some(thread),
            received,
        })
    }

    /// Let writes past the file-size limit fail (EFBIG) instead of killing the process with
    /// SIGXFSZ (see the module docs). Best effort: if the action cannot be set, the OS default
    /// stays.
    pub fn survive_file_size_limit() {
        let seen = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, seen);
    }

    impl SignalGuard {
        /// The exit code of the first signal received (130, 143), if one was.
        pub fn exit_code(&self) -> Option<i32> {
            match self.received.load(Ordering::SeqCst) {
                0 => None,
                s => Some(128 + s),
            }
        }
    }

    impl Drop for SignalGuard {
        fn drop(&mut self) {
            self.handle.close();
            if let Some(t) = self.thread.take() {
                let _ = t.join();
            }
        }
    }
}

#[cfg(not(unix))]
mod imp {
    use super::StopFlag;

    /// No signal handling on this platform (the process ends as the OS decides).
    pub struct SignalGuard;

    /// Nothing to install on this platform.
    ///
    /// # Errors
    /// Never.
    pub fn install(_stop: &StopFlag) -> std::io::Result<SignalGuard> {
        Ok(SignalGuard)
    }

    /// Nothing to change on this platform.
    pub fn survive_file_size_limit() {}

    impl SignalGuard {
        /// Always `None`.
        pub fn exit_code(&self) -> Option<i32> {
            None
        }
    }
}
