//! The command thread: receives commands on the node's request-response service, parses them
//! off the cyclic path, queues them for the cyclic thread and answers each with its result.
//! Each command runs in a `command` span (object, instruction, job).

use crate::error::NodeError;
use crate::owns;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError};
use std::time::Duration;
use tandem_config::script::{split_command, ScriptEntry};
use tandem_config::Cell;
use tandem_protocol::ipc;
use tandem_protocol::json::error_id_text;
use tandem_protocol::names;
use tandem_protocol::wire::{CommandReply, Text, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID};
use tandem_rt as rt;
use tracing::{debug, info, info_span, warn, Span};

/// A command from the command thread: its id, what to apply.
#[derive(Debug)]
pub(crate) struct Queued {
    /// The command's id.
    pub(crate) id: u64,
    /// What to apply.
    pub(crate) entry: ScriptEntry,
}

/// The result for command `id`.
#[derive(Debug)]
pub(crate) struct Done {
    /// The command's id.
    pub(crate) id: u64,
    /// Its reply.
    pub(crate) reply: CommandReply,
}

/// The command thread's links to the cyclic thread.
#[derive(Debug)]
pub(crate) struct CommandLinks {
    /// Commands to apply.
    pub(crate) queue: SyncSender<Queued>,
    /// Their results.
    pub(crate) done: Receiver<Done>,
}

/// Serves node `node`'s commands until `stop` or a termination signal.
pub(crate) fn command_thread(cell: &Cell, node: &str, stop: &AtomicBool, links: &CommandLinks) {
    if let Err(e) = serve(cell, node, stop, links) {
        warn!(error = %e, "commands unavailable");
    }
}

/// A reply refusing a command before it reached the cycle.
fn refusal(outcome: u32, message: &str) -> CommandReply {
    CommandReply {
        outcome,
        job: 0,
        error_id: 0,
        t_ns: 0,
        message: Text::new(message),
    }
}

/// Parses command line `text` for node `node`: the entry to apply, or why not.
fn parse(cell: &Cell, node: &str, text: &str) -> Result<ScriptEntry, String> {
    let c = split_command(text).map_err(|e| e.to_string())?;
    let object = match c.object.split_once('/') {
        Some((nn, o)) if nn == node => o.to_string(),
        Some((nn, _)) => return Err(format!("this is node `{node}`, not `{nn}`")),
        None => c.object,
    };
    let e = tandem_config::script::parse_command(cell, &object, &c.instruction, &c.params)
        .map_err(|e| e.to_string())?;
    if cell
        .node(node)
        .is_some_and(|n| owns(cell, n, &e.axis, &e.action))
    {
        Ok(e)
    } else {
        Err(format!("`{}` is not an object of node `{node}`", e.axis))
    }
}

/// Logs the outcome of a command in its span.
fn log_reply(span: &Span, reply: &CommandReply) {
    span.record("job", reply.job);
    let _in = span.enter();
    if reply.outcome == OUTCOME_ACCEPTED {
        debug!(t_ns = reply.t_ns, "accepted");
    } else {
        warn!(
            error_id = %error_id_text(reply.error_id),
            t_ns = reply.t_ns,
            "rejected: {}",
            reply.message.as_str()
        );
    }
}

/// The command loop.
fn serve(
    cell: &Cell,
    node: &str,
    stop: &AtomicBool,
    links: &CommandLinks,
) -> Result<(), NodeError> {
    let host = cell
        .node(node)
        .map_or("local", |n| cell.hosts[cell.nodes[n].host].as_str());
    let port = "command server";
    let iox = ipc::node(&format!("{}/commands", names::node(&cell.name, node)), host)
        .map_err(|e| NodeError::port(port, e))?;
    let service = ipc::commands(&iox, &cell.name, node).map_err(|e| NodeError::port(port, e))?;
    let server = ipc::ctx(
        service.server_builder().create(),
        ipc::IpcOp::CreatePort,
        port,
    )
    .map_err(|e| NodeError::port(port, e))?;
    let mut pending = Vec::new();
    let mut id = 0u64;
    while !stop.load(Ordering::SeqCst) && !rt::termination_requested() {
        while let Ok(Some(active)) = server.receive() {
            id += 1;
            let text = active.payload().text;
            let text = text.as_str();
            let entry = match parse(cell, node, text) {
                Ok(entry) => entry,
                Err(m) => {
                    info!(command = text, "not understood: {m}");
                    if active.send_copy(refusal(OUTCOME_INVALID, &m)).is_err() {
                        warn!(command = text, "the reply could not be sent");
                    }
                    continue;
                }
            };
            let span = info_span!(
                "command",
                object = %entry.axis,
                instruction = entry.instruction,
                job = tracing::field::Empty
            );
            match links.queue.try_send(Queued { id, entry }) {
                Ok(()) => pending.push((id, active, span)),
                Err(TrySendError::Full(_)) => {
                    let _in = span.enter();
                    warn!("the command queue is full");
                    let busy = refusal(OUTCOME_BUSY, "the node's command queue is full; try again");
                    if active.send_copy(busy).is_err() {
                        warn!("the reply could not be sent");
                    }
                }
                Err(TrySendError::Disconnected(_)) => return Ok(()),
            }
        }
        while let Ok(d) = links.done.try_recv() {
            if let Some(i) = pending.iter().position(|(x, _, _)| *x == d.id) {
                let (_, active, span) = pending.swap_remove(i);
                log_reply(&span, &d.reply);
                if active.send_copy(d.reply).is_err() {
                    let _in = span.enter();
                    warn!("the reply could not be sent");
                }
            }
        }
        // Commands are for people and supervisors: 5 ms is well below what they notice
        // and costs a fraction of a per cent of a core.
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(())
}
