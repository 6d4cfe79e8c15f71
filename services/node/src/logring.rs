//! The cyclic thread's diagnostics: the log ring its step writes lines into, and the
//! fixed-size records it hands to the recorder thread, which emits them through `tracing`
//! (and stores the changed retained data, [`crate::retain`]). Nothing here formats for
//! `tracing` or allocates on the cyclic thread.

use std::collections::VecDeque;
use std::io::{self, Write};
use tandem_protocol::wire::{Event, Text};

/// Lines the log ring holds between two cycles.
pub(crate) const LOG_LINES: usize = 128;

/// Records the channel to the recorder thread holds (about 20 cycles of a full log
/// ring; the cyclic thread wakes the recorder when it handed over a quarter of it,
/// `recorder::Wake`).
pub(crate) const DIAG_RECORDS: usize = 4096;

/// The cyclic thread's log: lines formatted into fixed buffers, published after the step.
pub(crate) struct LogRing {
    line: Vec<u8>,
    /// The complete lines of this cycle.
    pub(crate) lines: VecDeque<Text>,
    /// Lines dropped because more than [`LOG_LINES`] came in one cycle.
    pub(crate) dropped: u64,
}

impl LogRing {
    /// An empty ring, its buffers allocated once.
    pub(crate) fn new() -> Self {
        Self {
            line: Vec::with_capacity(tandem_protocol::wire::TEXT_LEN * 2),
            lines: VecDeque::with_capacity(LOG_LINES),
            dropped: 0,
        }
    }
}

impl Write for LogRing {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            if b == b'\n' {
                if self.lines.len() < LOG_LINES {
                    let text = core::str::from_utf8(&self.line).unwrap_or("(not UTF-8)");
                    self.lines.push_back(Text::new(text));
                } else {
                    self.dropped += 1;
                }
                self.line.clear();
            } else if self.line.len() < self.line.capacity() {
                self.line.push(b);
            }
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// What the cyclic thread hands to the recorder thread, through one bounded channel.
// The records are the channel's fixed slots: boxing the large variant would allocate on the
// cyclic thread; a retained-data record costs a diagnostic record's slot, as before.
#[allow(clippy::large_enum_variant)]
#[derive(Copy, Clone, Debug)]
pub(crate) enum Record {
    /// A log line or a job event, to emit (and write to the log file).
    Diag(DiagRecord),
    /// An axis's retained data changed: to store.
    Retain(tandem_runtime::exec::AdjustmentChange),
}

/// One diagnostic record of the cyclic thread: a log line or a job event as published, with
/// the pending alarm of the event's axis (0 for none).
#[derive(Copy, Clone, Debug)]
pub(crate) struct DiagRecord {
    /// The event as the node published it.
    pub(crate) event: Event,
    /// `ErrorDetail.Number` of the object's axis at the event, 0 for none.
    pub(crate) alarm: u16,
}

/// Formats into a [`Text`] without allocating (cut at its capacity).
pub(crate) struct TextWriter<'a>(pub(crate) &'a mut Text);

impl core::fmt::Write for TextWriter<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        self.0.push(s);
        Ok(())
    }
}
