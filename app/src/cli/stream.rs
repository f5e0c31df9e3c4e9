//! Standard output and standard error for the command line, written so that
//! a full or closed stream is an error with a message, never a panic
//! (`eprintln!` and `println!` panic when the write fails) and never a
//! result lost.
//!
//! - What a command prints as its result goes through [`write_out`] (macro
//!   `out!`): a failed write is an error naming standard output.
//! - What it says on the way (progress, warnings, "wrote …") goes through
//!   [`write_err`] (macros `say!` and `say_part!`): a failed write is remembered
//!   and the command goes on, so the files it writes are still written;
//!   [`stderr_failure`] then makes the command end non-zero.
//!
//! A stream that was closed before the program started (`>&-`, `2>&-`)
//! looks like `/dev/null` to the program; [`guard`] tells them apart, so a
//! result written to a closed standard output is an error, not lost.

use std::fmt;
use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
static STDERR_CLOSED: AtomicBool = AtomicBool::new(false);
static STDERR_FAILURE: Mutex<Option<String>> = Mutex::new(None);

/// Finds which standard streams were closed when the program started and
/// remembers them. Call once, first thing.
///
/// The standard library's start-up puts `/dev/null`, opened for reading
/// and writing, in place of a closed standard stream (so no file lands on
/// its descriptor), and writes to it then vanish without an error; a shell's
/// `>/dev/null` opens it for writing only. On Linux that difference is
/// read from `/proc/self/fdinfo`; elsewhere a closed stream is not seen.
pub fn guard() {
    STDOUT_CLOSED.store(filled_at_start(1), Ordering::Relaxed);
    STDERR_CLOSED.store(filled_at_start(2), Ordering::Relaxed);
}

/// Whether descriptor `fd` is `/dev/null` opened for reading and writing
/// (what the runtime puts in place of a closed stream).
fn filled_at_start(fd: u32) -> bool {
    if !cfg!(target_os = "linux") {
        return false;
    }
    let is_null = std::fs::read_link(format!("/proc/self/fd/{fd}"))
        .is_ok_and(|target| target == std::path::Path::new("/dev/null"));
    if !is_null {
        return false;
    }
    let Ok(info) = std::fs::read_to_string(format!("/proc/self/fdinfo/{fd}")) else {
        return false;
    };
    info.lines()
        .find_map(|line| line.strip_prefix("flags:"))
        .and_then(|flags| u32::from_str_radix(flags.trim(), 8).ok())
        // O_ACCMODE is 3, O_RDWR 2.
        .is_some_and(|flags| flags & 3 == 2)
}

/// Writes a command's result to standard output; an error names standard
/// output ("cannot write to standard output: No space left on device").
pub fn write_out(args: fmt::Arguments<'_>) -> Result<()> {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        bail!(
            "cannot write to standard output: it is closed (give the command somewhere to write, \
             e.g. `> FILE`)"
        );
    }
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(args)
        .and_then(|()| stdout.flush())
        .context("cannot write to standard output")
}

/// Writes a message to standard error. A failed write does not stop the
/// command: the first failure is kept for [`stderr_failure`].
pub fn write_err(args: fmt::Arguments<'_>) {
    if STDERR_CLOSED.load(Ordering::Relaxed) {
        remember("cannot write to standard error: it is closed".to_owned());
        return;
    }
    let mut stderr = std::io::stderr().lock();
    if let Err(error) = stderr.write_fmt(args).and_then(|()| stderr.flush()) {
        remember(format!("cannot write to standard error: {error}"));
    }
}

fn remember(failure: String) {
    if let Ok(mut kept) = STDERR_FAILURE.lock() {
        kept.get_or_insert(failure);
    }
}

/// The first failed write to standard error, if any.
pub fn stderr_failure() -> Option<String> {
    STDERR_FAILURE.lock().ok().and_then(|kept| kept.clone())
}

/// Notes said once a command has succeeded (a project that states no
/// unit): a command that fails says only its error, in one line.
static NOTES_AT_END: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// Keeps `note` to say when the command has succeeded (`take_notes`).
pub fn note_at_end(note: String) {
    if let Ok(mut notes) = NOTES_AT_END.lock()
        && !notes.contains(&note)
    {
        notes.push(note);
    }
}

/// The notes kept by `note_at_end`, emptied.
pub fn take_notes() -> Vec<String> {
    NOTES_AT_END
        .lock()
        .map(|mut notes| std::mem::take(&mut *notes))
        .unwrap_or_default()
}

/// Whether standard output was closed when the program started.
pub fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

/// `println!` for a command's result: returns the error instead of
/// panicking.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::stream::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that never panics (see [`write_err`]).
macro_rules! say {
    () => {
        $crate::cli::stream::write_err(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::stream::write_err(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprint!` that never panics (progress on one line).
macro_rules! say_part {
    ($($arg:tt)*) => {
        $crate::cli::stream::write_err(format_args!($($arg)*))
    };
}

pub(crate) use {out, say, say_part};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_stderr_failure_is_kept() {
        remember("cannot write to standard error: first".to_owned());
        remember("cannot write to standard error: second".to_owned());
        assert_eq!(
            stderr_failure().as_deref(),
            Some("cannot write to standard error: first")
        );
    }
}
