//! `tandem cmd` over iceoryx2: an instruction to an object of a running node of this machine,
//! its outcome, and with `--wait` its job followed to the end.

use crate::error::CliError;
use crate::live::{cli_node, load};
use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};
use tandem_config::Cell;
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::wire::{
    CommandReply, CommandRequest, Event, Text, EVENT_JOB, JOB_ABORTED, JOB_DONE, JOB_ERROR,
    JOB_REACHED, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID, OUTCOME_REJECTED,
};
use tandem_runtime::exec::Secs;
use tracing::{debug, info_span};

/// How long a node is given to answer a command (or the timeout, if shorter).
const REPLY_WITHIN: Duration = Duration::from_secs(5);

/// Who sends the commands of this process (docs/gateway.md, "Command rate"): `$TANDEM_SENDER`
/// if set, else `<user>@<machine>`. Not authenticated; over Zenoh with a certificate
/// (`--zenoh --cert`) the sender is the certificate's common name instead (docs/security.md,
/// "Commands with identity").
pub fn sender() -> String {
    if let Ok(s) = std::env::var("TANDEM_SENDER") {
        if !s.trim().is_empty() {
            return s;
        }
    }
    let user = std::env::var("USER").unwrap_or_else(|_| "unknown".to_string());
    let machine = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .unwrap_or_else(|_| "localhost".to_string());
    format!("{user}@{machine}")
}

/// What `tandem cmd` sends and how it waits.
#[derive(Debug, Clone)]
pub struct CmdRequest {
    /// `<node>/<object>`.
    pub target: String,
    /// The instruction as given (`MC_MoveAbsolute`, `MoveVelocity`, `gear_in`).
    pub instruction: String,
    /// `--param value` pairs, in order (the script's parameter names).
    pub params: Vec<(String, String)>,
    /// Follow the job until it is done, reached its goal, or failed.
    pub wait: bool,
    /// How long to wait for the job (and, at most, for the reply).
    pub timeout: Duration,
}

impl CmdRequest {
    /// The diagnostics span of one `tandem cmd` (its job is recorded once known).
    pub fn span(&self, node: &str, object: &str) -> tracing::Span {
        info_span!(
            "cmd",
            node,
            object,
            instruction = %self.instruction,
            job = tracing::field::Empty
        )
    }

    /// The node and the object of the target.
    pub fn node_object(&self) -> Result<(&str, &str), CliError> {
        self.target
            .split_once('/')
            .ok_or_else(|| CliError::Target(self.target.clone()))
    }

    /// The command line the node parses: `<instruction> --k v ...`.
    pub fn line(&self) -> String {
        let mut line = self.instruction.clone();
        for (k, v) in &self.params {
            line.push_str(&format!(" --{k} {v}"));
        }
        line
    }

    /// Checks the instruction and its parameters against the cell (for an error message
    /// without a round trip); returns the index of the object among the cell's objects.
    pub(crate) fn check(&self, cell: &Cell) -> Result<Option<usize>, CliError> {
        let (_, object) = self.node_object()?;
        let entry =
            tandem_config::script::parse_command(cell, object, &self.instruction, &self.params)
                .map_err(CliError::command)?;
        Ok(cell.object_names().iter().position(|x| *x == entry.axis))
    }
}

/// The iceoryx2 ports of `cmd` to one node: its command service and, with `--wait`, its events.
struct Ports {
    client: iceoryx2::port::client::Client<
        iceoryx2::prelude::ipc::Service,
        CommandRequest,
        (),
        CommandReply,
        (),
    >,
    events:
        Option<iceoryx2::port::subscriber::Subscriber<iceoryx2::prelude::ipc::Service, Event, ()>>,
}

impl Ports {
    /// Opens the command client of `node` (and its event subscriber when `wait`).
    fn open(iox: &IpcNode, cell: &Cell, node: &str, wait: bool) -> Result<Self, CliError> {
        // The events first, so that no event of the job is missed.
        let events = if wait {
            let svc = ipc::events(iox, &cell.name, node)?;
            Some(
                svc.subscriber_builder()
                    .buffer_size(1024)
                    .create()
                    .map_err(CliError::port(format!("events of {node}")))?,
            )
        } else {
            None
        };
        let svc = ipc::commands(iox, &cell.name, node)?;
        let client = svc
            .client_builder()
            .create()
            .map_err(CliError::port("command client"))?;
        Ok(Self { client, events })
    }

    /// Sends `text` and waits for the node's reply (at most [`REPLY_WITHIN`] or `timeout`).
    fn send(
        &self,
        text: &str,
        node: &str,
        cell_path: &Path,
        timeout: Duration,
    ) -> Result<CommandReply, CliError> {
        let pending = self
            .client
            .send_copy(CommandRequest {
                text: Text::new(text),
                sender: Text::new(&sender()),
            })
            .map_err(CliError::port("sending the command"))?;
        let within = REPLY_WITHIN.min(timeout);
        let deadline = Instant::now() + within;
        loop {
            match pending.receive() {
                Ok(Some(r)) => return Ok(*r.payload()),
                Ok(None) => {}
                Err(e) => return Err(CliError::port("receiving the reply")(e)),
            }
            if Instant::now() > deadline {
                return Err(if pending.number_of_server_connections() == 0 {
                    CliError::NodeNotRunning {
                        node: node.to_string(),
                        cell: cell_path.to_path_buf(),
                    }
                } else {
                    CliError::NoAnswer {
                        node: node.to_string(),
                        within,
                    }
                });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

/// `tandem cmd`: sends `<node>/<object> <instruction> [--param value]...` and prints the
/// outcome; with `wait`, follows the job until it is done, reached its goal, or failed.
pub fn cmd(cell_path: &Path, r: &CmdRequest, out: &mut impl Write) -> Result<(), CliError> {
    let cell = load(cell_path)?;
    let (node, object) = r.node_object()?;
    let span = r.span(node, object);
    let _entered = span.enter();
    let n = cell.node(node).ok_or_else(|| CliError::UnknownNode {
        node: node.to_string(),
        nodes: cell.nodes.iter().map(|x| x.name.clone()).collect(),
    })?;
    let object_index = r.check(&cell)?;
    let iox = cli_node(&cell, "cmd", &cell.hosts[cell.nodes[n].host])?;
    let ports = Ports::open(&iox, &cell, node, r.wait)?;
    let reply = ports.send(
        &format!("{object} {}", r.line()),
        node,
        cell_path,
        r.timeout,
    )?;
    span.record("job", reply.job);
    debug!(
        outcome = reply.outcome,
        error_id = reply.error_id,
        "the node replied"
    );
    report(r, &reply, out)?;
    match (ports.events, object_index) {
        (Some(events), Some(obj)) if reply.job != 0 => {
            follow(&events, obj, reply.job, r.timeout, out)
        }
        _ => Ok(()),
    }
}

/// The node's words on an accepted instruction (MC_ReadParameter's `Tag = value`), after a
/// colon; nothing when it said nothing.
pub(crate) struct Said<'a>(pub(crate) &'a str);

impl std::fmt::Display for Said<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_empty() {
            Ok(())
        } else {
            write!(f, ": {}", self.0)
        }
    }
}

/// Prints an accepted reply; any other is the error it stands for.
fn report(r: &CmdRequest, reply: &CommandReply, out: &mut impl Write) -> Result<(), CliError> {
    let (target, instruction) = (&r.target, &r.instruction);
    match reply.outcome {
        OUTCOME_ACCEPTED if reply.job == 0 => {
            outln!(
                out,
                "{target} {instruction}: accepted at t={}",
                Secs(reply.t_ns)
            );
            Ok(())
        }
        OUTCOME_ACCEPTED => {
            outln!(
                out,
                "{target} {instruction}: accepted, job {} at t={}{}",
                reply.job,
                Secs(reply.t_ns),
                Said(reply.message.as_str())
            );
            Ok(())
        }
        OUTCOME_REJECTED => Err(CliError::Rejected {
            target: target.clone(),
            instruction: instruction.clone(),
            error_id: reply.error_id,
            message: reply.message.as_str().to_string(),
        }),
        OUTCOME_INVALID => Err(CliError::Invalid(reply.message.as_str().to_string())),
        OUTCOME_BUSY => Err(CliError::Busy(reply.message.as_str().to_string())),
        other => Err(CliError::UnknownOutcome(other)),
    }
}

/// Prints the events of `job` of object `obj` until it is done or reached its goal (`Ok`),
/// failed (the error), or `timeout` passed.
fn follow(
    events: &iceoryx2::port::subscriber::Subscriber<iceoryx2::prelude::ipc::Service, Event, ()>,
    obj: usize,
    job: u32,
    timeout: Duration,
    out: &mut impl Write,
) -> Result<(), CliError> {
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        while let Ok(Some(s)) = events.receive() {
            let e = s.payload();
            if e.kind != EVENT_JOB || e.job != job || e.object as usize != obj {
                continue;
            }
            outln!(out, "t={} {}", Secs(e.t_ns), e.message.as_str());
            match e.code {
                JOB_DONE | JOB_REACHED => return Ok(()),
                JOB_ABORTED => return Err(CliError::JobAborted { job }),
                JOB_ERROR => {
                    return Err(CliError::JobError {
                        job,
                        error_id: e.error_id,
                    })
                }
                _ => {}
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Err(CliError::JobTimeout { job, timeout })
}
