//! User output: what a command prints for its user, on the writers given to [`crate::run`].

use std::io::Write;

/// Writes `args` to `out`. A failed write (stdout closed: `tandem status | head`) is dropped:
/// it must not turn into another error or hide the command's exit code.
pub(crate) fn write(out: &mut dyn Write, args: std::fmt::Arguments) {
    // Dropped on purpose, see above.
    let _ = out.write_fmt(args);
}

/// Flushes `out` (the live views), dropping a failure like [`write`].
pub(crate) fn flush(out: &mut dyn Write) {
    // Dropped on purpose, see `write`.
    let _ = out.flush();
}
