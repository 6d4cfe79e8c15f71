//! The command thread: receives commands on the node's request-response service, parses them
//! off the cyclic path, queues them for the cyclic thread and answers each with its result.
//! Each command runs in a `command` span (object, instruction, job).

use crate::audit::Audit;
use crate::error::NodeError;
use crate::owns;
use crate::parameters::{write_of, Retained};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError};
use std::sync::Arc;
use std::time::Duration;
use tandem_config::script::{split_command, ScriptEntry};
use tandem_config::Cell;
use tandem_protocol::ipc;
use tandem_protocol::json::error_id_text;
use tandem_protocol::names;
use tandem_protocol::rate::SenderRates;
use tandem_protocol::wire::{
    CommandReply, CommandRequest, Text, ANONYMOUS, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID,
};
use tandem_rt as rt;
use tandem_rt::retain::RetainStore;
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
    /// Where accepted MC_WriteParameter values are retained.
    pub(crate) parameters: Option<Arc<RetainStore>>,
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

/// A command queued for the cycle, waiting for its result.
struct Pending {
    id: u64,
    active: ActiveRequest,
    span: Span,
    request: CommandRequest,
    /// An MC_WriteParameter to retain once accepted.
    write: Option<(String, u16, f64)>,
}

/// The server side of one command request.
type ActiveRequest = iceoryx2::active_request::ActiveRequest<
    iceoryx2::prelude::ipc::Service,
    CommandRequest,
    (),
    CommandReply,
    (),
>;

/// The entry of command `text` of `sender` if it is within the sender's rate and understood;
/// otherwise it is answered (`busy` or `invalid`) and audited here.
fn admit(
    cell: &Cell,
    node: &str,
    (sender, text): (&str, &str),
    rates: &mut SenderRates,
    active: &ActiveRequest,
    audit: &mut Audit,
) -> Option<ScriptEntry> {
    let refused = if !rates.admit(sender, rt::now_ns()) {
        refusal(
            OUTCOME_BUSY,
            &format!(
                "busy: more than {} commands per second from `{sender}`; try again",
                cell.command_rate_hz
            ),
        )
    } else {
        match parse(cell, node, text) {
            Ok(entry) => return Some(entry),
            Err(m) => {
                info!(command = text, sender, "not understood: {m}");
                refusal(OUTCOME_INVALID, &m)
            }
        }
    };
    audit.record(sender, text, &refused);
    if active.send_copy(refused).is_err() {
        warn!(command = text, sender, "the reply could not be sent");
    }
    None
}

/// Sends the cycle's answer `d` to the request waiting for it, and audits it.
fn reply(pending: &mut Vec<Pending>, d: Done, audit: &mut Audit, retained: &mut Retained) {
    let Some(i) = pending.iter().position(|x| x.id == d.id) else {
        return;
    };
    let mut p = pending.swap_remove(i);
    if d.reply.outcome == OUTCOME_ACCEPTED {
        if let Some(w) = p.write.take() {
            // Retained before the reply leaves: a client that saw the reply finds the value
            // after a restart.
            retained.record(w);
        }
    }
    log_reply(&p.span, &d.reply);
    let sender = match p.request.sender.as_str() {
        "" => ANONYMOUS,
        s => s,
    };
    audit.record(sender, p.request.text.as_str(), &d.reply);
    if p.active.send_copy(d.reply).is_err() {
        let _in = p.span.enter();
        warn!("the reply could not be sent");
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
    let n = cell.node(node);
    let mut audit = Audit::open(n.and_then(|n| cell.node_retain_dir(n)));
    let mut retained = Retained::load(cell, n.unwrap_or(usize::MAX), links.parameters.clone());
    let mut rates = SenderRates::new(cell.command_rate_hz, cell.command_burst);
    let mut pending: Vec<Pending> = Vec::new();
    let mut id = 0u64;
    while !stop.load(Ordering::SeqCst) && !rt::termination_requested() {
        while let Ok(Some(active)) = server.receive() {
            id += 1;
            let req = *active.payload();
            let sender = match req.sender.as_str() {
                "" => ANONYMOUS,
                s => s,
            };
            let text = req.text.as_str();
            let Some(entry) = admit(cell, node, (sender, text), &mut rates, &active, &mut audit)
            else {
                continue;
            };
            let span = info_span!(
                "command",
                sender,
                object = %entry.axis,
                instruction = entry.instruction,
                job = tracing::field::Empty
            );
            let write = write_of(&entry.axis, &entry.action);
            match links.queue.try_send(Queued { id, entry }) {
                Ok(()) => pending.push(Pending {
                    id,
                    active,
                    span,
                    request: req,
                    write,
                }),
                Err(TrySendError::Full(_)) => {
                    let _in = span.enter();
                    let busy = refusal(OUTCOME_BUSY, "the node's command queue is full; try again");
                    audit.record(sender, text, &busy);
                    if active.send_copy(busy).is_err() {
                        warn!("the reply could not be sent");
                    }
                }
                Err(TrySendError::Disconnected(_)) => return Ok(()),
            }
        }
        // Wait for the cycle's answers (a reply leaves as soon as the cycle answered), then
        // look for new requests again: after 1 ms while a command is in flight, after 5 ms
        // while none is (200 wake-ups a second instead of 1,000 on an idle node; a new
        // command waits at most 5 ms to be picked up, docs/processes.md).
        let wait = if pending.is_empty() { 5 } else { 1 };
        let mut next = links.done.recv_timeout(Duration::from_millis(wait)).ok();
        while let Some(d) = next {
            reply(&mut pending, d, &mut audit, &mut retained);
            next = links.done.try_recv().ok();
        }
        audit.sync();
    }
    Ok(())
}
