//! The audit trail of a node's commands (docs/gateway.md, "Audit trail"): one line per command
//! with its sender, text and outcome, appended to `<retain dir>/<cell>/<node>/audit.log` by
//! the command thread (never the cyclic thread) and synced to the disk once per batch.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::PathBuf;
use tandem_protocol::json::error_id_text;
use tandem_protocol::wire::{
    CommandReply, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID, OUTCOME_REJECTED,
};
use tracing::{info, warn};

/// The audit file of one node; lines that could not be written are counted.
#[derive(Debug)]
pub(crate) struct Audit {
    path: Option<PathBuf>,
    file: Option<File>,
    /// Lines written since the last sync.
    unsynced: usize,
    /// Lines that could not be written.
    pub(crate) lost: u64,
}

/// The word of a reply's outcome.
pub(crate) fn outcome_word(outcome: u32) -> &'static str {
    match outcome {
        OUTCOME_ACCEPTED => "accepted",
        OUTCOME_REJECTED => "rejected",
        OUTCOME_INVALID => "invalid",
        OUTCOME_BUSY => "busy",
        _ => "unknown",
    }
}

impl Audit {
    /// The audit file in directory `dir` (created if needed); `None`: no file, log only.
    pub(crate) fn open(dir: Option<PathBuf>) -> Self {
        let path = dir.map(|d| d.join("audit.log"));
        let file = path.as_ref().and_then(|p| {
            let made = p.parent().map_or(Ok(()), std::fs::create_dir_all);
            let f = made.and_then(|()| OpenOptions::new().create(true).append(true).open(p));
            match f {
                Ok(f) => Some(f),
                Err(e) => {
                    warn!(path = %p.display(), error = %e, "the audit file cannot be opened; commands are logged only");
                    None
                }
            }
        });
        Self {
            path,
            file,
            unsynced: 0,
            lost: 0,
        }
    }

    /// Records command `text` of `sender` with its reply: a log line and a line of the file.
    pub(crate) fn record(&mut self, sender: &str, text: &str, reply: &CommandReply) {
        let outcome = outcome_word(reply.outcome);
        let error_id = if reply.outcome == OUTCOME_REJECTED {
            error_id_text(reply.error_id)
        } else {
            String::new()
        };
        info!(
            target: "tandem::audit",
            sender,
            command = text,
            outcome,
            job = reply.job,
            error_id = %error_id,
            t_ns = reply.t_ns,
            "command"
        );
        let Some(f) = self.file.as_mut() else {
            return;
        };
        let wall_ns = tandem_rt::now_ns();
        let line = format!(
            "wall_ns={wall_ns} sender={sender:?} command={text:?} outcome={outcome} job={} error_id={error_id:?} t_ns={}\n",
            reply.job, reply.t_ns
        );
        if f.write_all(line.as_bytes()).is_ok() {
            self.unsynced += 1;
        } else {
            self.lost += 1;
        }
    }

    /// Syncs the lines written since the last call to the disk.
    pub(crate) fn sync(&mut self) {
        if self.unsynced == 0 {
            return;
        }
        let n = self.unsynced;
        self.unsynced = 0;
        if let Some(f) = self.file.as_mut() {
            if let Err(e) = f.flush().and_then(|()| f.sync_data()) {
                self.lost += n as u64;
                warn!(path = ?self.path, error = %e, "the audit file could not be synced");
            }
        }
    }
}
