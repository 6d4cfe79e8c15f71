//! tandem-gateway: one per host, the bridge between the host's iceoryx2 domain and Zenoh (the
//! keys and payloads are listed in docs/gateway.md).
//!
//! - **Leading values out**: for each leader of this host that a follower on another host
//!   follows, every sample its node publishes is put on `tandem/<cell>/lv/<leader>` (binary,
//!   `Priority::RealTime`, express, drop on congestion). The gateway wakes on the node's
//!   "published" event, so a sample leaves within microseconds of its cycle.
//! - **Leading values in**: for each leader on another host that a follower here follows, the
//!   Zenoh samples are published into this host's iceoryx2 leading-value service, so the
//!   follower's node reads a remote leader exactly as a local one. The sample keeps its own
//!   timestamp.
//! - **Commands**: a queryable per node (`tandem/<cell>/<node>/*/cmd/*`, the last chunk the
//!   sender, bound to the certificate by the access control in an mTLS cell) forwards each
//!   query to the node's command service with that sender, replies with the job id or the
//!   ErrorID (JSON), and publishes a `command` event (who, what, outcome) on the object's
//!   events key. A plain cell also serves `tandem/<cell>/<node>/*/cmd` (the sender as claimed).
//! - **Telemetry**: per axis state as JSON at `cell.telemetry_hz`, node health, job events and
//!   log lines as they happen, a liveliness token per host, and the gateway's own counters.
//! - **Clock watch**: a queryable answers with this host's clock; the gateway asks the others
//!   and warns when an offset exceeds `cell.clock_warning_fraction` of the smallest delay of a
//!   coupling between the two hosts.
//!
//! A malformed payload on any key is dropped and counted; it never stops the gateway.
//!
//! Diagnostics go through `tracing` (the binary installs `tandem_rt::diag`): a span `gateway`
//! (host, cell) with one span per thread (`task`) and one per command query (`command`: node,
//! object, instruction, job); failures are [`GatewayError`]s with their exit code.
//!
//! ```no_run
//! // The gateway of host `h1` for ten seconds, as `tandem-gateway cell.toml --host h1` runs it.
//! let o = tandem_gateway::Options {
//!     cell: "cell.toml".into(),
//!     host: Some("h1".into()),
//!     duration_s: Some(10.0),
//! };
//! match tandem_gateway::run(&o) {
//!     Ok(counters) => println!("{counters:?}"),
//!     Err(e) => {
//!         eprintln!("{e}");
//!         std::process::exit(e.exit_code().into());
//!     }
//! }
//! ```

pub mod acl;
mod error;

pub use error::GatewayError;

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicI64, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tandem_config::{Cell, Coupling, Leader, SecurityMode};
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::json::{self, AxisState, EventJson, Health, ReplyJson};
use tandem_protocol::keys;
use tandem_protocol::rate::SenderRates;
use tandem_protocol::wire::{CommandRequest, Text, ANONYMOUS, EVENT_JOB, EVENT_LOG};
use tandem_rt as rt;
use tracing::{debug, error, info, warn};
use zenoh::qos::{CongestionControl, Priority};
use zenoh::sample::Locality;
use zenoh::Wait;

/// How a gateway is started.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// The cell file.
    pub cell: PathBuf,
    /// This host (default: the cell's only host).
    pub host: Option<String>,
    /// Stop after this many seconds (default: on SIGINT/SIGTERM).
    pub duration_s: Option<f64>,
}

/// The gateway's counters, published on `tandem/<cell>/gateway/<host>`.
#[derive(Debug, Default)]
pub struct Counters {
    /// Leading values put on Zenoh.
    pub lv_out: AtomicU64,
    /// Leading values from Zenoh published into iceoryx2.
    pub lv_in: AtomicU64,
    /// Payloads dropped because they could not be decoded (any key).
    pub malformed: AtomicU64,
    /// Command queries answered.
    pub commands: AtomicU64,
    /// Command queries answered `busy` because their sender exceeded its rate.
    pub commands_busy: AtomicU64,
    /// Zenoh samples on the key of a leader this host publishes (a forged copy): dropped.
    pub lv_forged: AtomicU64,
    /// Largest clock offset to another host seen in the last round (ns, absolute).
    pub clock_offset_ns: AtomicI64,
    /// Clock offsets above the warning threshold.
    pub clock_warnings: AtomicU64,
}

/// What the gateway bridges, from the cell.
#[derive(Debug, Default)]
struct Plan {
    /// Leaders of this host followed on another host: (leader, coupling, node).
    out: Vec<(Leader, Coupling, usize)>,
    /// Leaders of another host followed here: (leader, coupling).
    inn: Vec<(Leader, Coupling)>,
    /// This host's nodes.
    nodes: Vec<usize>,
    /// Per other host: the smallest delay of a coupling between the two hosts (ns).
    min_delay: HashMap<usize, i64>,
}

/// What every thread of the gateway shares.
#[derive(Clone)]
struct Ctx {
    cell: Arc<Cell>,
    host: String,
    h: usize,
    plan: Arc<Plan>,
    session: zenoh::Session,
    counters: Arc<Counters>,
    stop: Arc<AtomicBool>,
}

impl Ctx {
    /// What a thread works with: cell, host, plan, session, counters, stop flag.
    fn parts(&self) -> (&Cell, &str, &Plan, &zenoh::Session, &Counters, &AtomicBool) {
        (
            &self.cell,
            &self.host,
            &self.plan,
            &self.session,
            &self.counters,
            &self.stop,
        )
    }
}

fn plan(cell: &Cell, h: usize) -> Plan {
    let mut p = Plan {
        nodes: (0..cell.nodes.len())
            .filter(|n| cell.nodes[*n].host == h)
            .collect(),
        ..Plan::default()
    };
    for f in &cell.axes {
        let f_host = cell.nodes[f.node].host;
        for (l, c) in f.leaders.iter().flatten() {
            let c = if l.is_encoder() {
                Coupling::Setpoint
            } else {
                *c
            };
            let Some(ln) = cell.leader_node(*l) else {
                continue;
            };
            let l_host = cell.nodes[ln].host;
            if l_host == f_host {
                continue;
            }
            let d = cell.leading(*l).delay_ns;
            let other = if l_host == h { f_host } else { l_host };
            if l_host == h || f_host == h {
                let e = p.min_delay.entry(other).or_insert(d);
                *e = (*e).min(d);
            }
            if l_host == h && !p.out.iter().any(|(x, y, _)| x == l && *y == c) {
                p.out.push((*l, c, ln));
            }
            if f_host == h && !p.inn.iter().any(|(x, y)| x == l && *y == c) {
                p.inn.push((*l, c));
            }
        }
    }
    p
}

/// Sets Zenoh configuration `key` to `value` (JSON5).
fn set(c: &mut zenoh::Config, key: &'static str, value: String) -> Result<(), GatewayError> {
    c.insert_json5(key, &value)
        .map_err(|source| GatewayError::ZenohConfig { key, value, source })
}

/// The Zenoh configuration of host `h` (docs/security.md): peer mode; listening exactly on the
/// host's endpoints (none: on nothing) and connecting to the other hosts'; multicast scouting
/// only when `[security] multicast_scouting` asks for it. In mTLS mode: TLS links only, this
/// host's certificate on both ends of every link, the client's certificate required, and the
/// cell's access control ([`acl::access_control`]).
pub fn zenoh_config(cell: &Cell, h: usize) -> Result<zenoh::Config, GatewayError> {
    let mut c = zenoh::Config::default();
    set(&mut c, "mode", "\"peer\"".into())?;
    let listen = cell.host_listen.get(h).cloned().unwrap_or_default();
    let connect: Vec<String> = cell
        .host_listen
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != h)
        .flat_map(|(_, l)| l.clone())
        .collect();
    let json = |v: &[String]| serde_json::to_string(v).unwrap_or_else(|_| "[]".into());
    // Explicit, even when empty: Zenoh's default for a peer is every interface.
    set(&mut c, "listen/endpoints", json(&listen))?;
    if !connect.is_empty() {
        set(&mut c, "connect/endpoints", json(&connect))?;
        // Keep trying: the other hosts' gateways may start later.
        set(&mut c, "connect/timeout_ms", "-1".into())?;
    }
    let scouting = cell.security.multicast_scouting;
    set(&mut c, "scouting/multicast/enabled", scouting.to_string())?;
    if cell.security.mode == SecurityMode::Mtls {
        set(&mut c, "scouting/gossip/enabled", scouting.to_string())?;
        mtls(&mut c, cell, h)?;
    }
    Ok(c)
}

/// The mTLS part of host `h`'s configuration: TLS links only, its certificate and key as
/// both listener and connector, the cell's CA as the only issuer of clients, and the ACL.
fn mtls(c: &mut zenoh::Config, cell: &Cell, h: usize) -> Result<(), GatewayError> {
    let host = cell.hosts.get(h).map(String::as_str).unwrap_or_default();
    let s = &cell.security;
    let files = [
        ("CA certificate", s.ca.clone()),
        ("host certificate", s.host_certificate(host)),
        ("host private key", s.host_private_key(host)),
    ];
    for (what, path) in &files {
        if let Err(source) = std::fs::File::open(path) {
            return Err(GatewayError::Certificate {
                what,
                path: path.clone(),
                source,
            });
        }
    }
    let [(_, ca), (_, cert), (_, key)] = &files;
    let file = |p: &std::path::Path| {
        serde_json::to_string(&p.to_string_lossy()).unwrap_or_else(|_| "\"\"".into())
    };
    set(c, "transport/link/tls/root_ca_certificate", file(ca))?;
    set(c, "transport/link/tls/listen_certificate", file(cert))?;
    set(c, "transport/link/tls/listen_private_key", file(key))?;
    set(c, "transport/link/tls/connect_certificate", file(cert))?;
    set(c, "transport/link/tls/connect_private_key", file(key))?;
    set(c, "transport/link/tls/enable_mtls", "true".into())?;
    set(
        c,
        "transport/link/tls/verify_name_on_connect",
        "true".into(),
    )?;
    set(
        c,
        "transport/link/tls/close_link_on_expiration",
        "true".into(),
    )?;
    set(c, "transport/link/protocols", "[\"tls\"]".into())?;
    set(c, "access_control", acl::access_control(cell).to_string())?;
    Ok(())
}

/// Runs the gateway until SIGINT/SIGTERM or the end of its duration.
pub fn run(o: &Options) -> Result<Arc<Counters>, GatewayError> {
    let cell = Arc::new(tandem_config::load(&o.cell)?);
    let h = select_host(&cell, o)?;
    let host = cell.hosts[h].clone();
    let span = tracing::info_span!("gateway", host = %host, cell = %cell.name);
    let _entered = span.enter();
    rt::install_termination_handler();
    let removed = ipc::cleanup_dead_nodes(&host);
    if removed > 0 {
        info!(
            removed,
            "removed the iceoryx2 resources of crashed processes"
        );
    }
    let plan = Arc::new(plan(&cell, h));
    if cell.security.mode == SecurityMode::Plain {
        warn!(
            mode = "plain",
            "plain, unauthenticated Zenoh: anyone who reaches {:?} may observe, command and publish leading values (docs/security.md)",
            cell.host_listen.get(h).cloned().unwrap_or_default()
        );
    }
    let session = zenoh::open(zenoh_config(&cell, h)?)
        .wait()
        .map_err(GatewayError::zenoh("opening the Zenoh session"))?;
    let _token = session
        .liveliness()
        .declare_token(keys::alive(&cell.name, &host))
        .wait()
        .map_err(GatewayError::zenoh("liveliness token"))?;
    info!(
        zenoh_id = %session.zid(),
        "cell `{}`, {} node(s); {} leader(s) out, {} in; Zenoh id {}",
        cell.name,
        plan.nodes.len(),
        plan.out.len(),
        plan.inn.len(),
        session.zid()
    );
    let ctx = Ctx {
        cell: Arc::clone(&cell),
        host: host.clone(),
        h,
        plan,
        session: session.clone(),
        counters: Arc::new(Counters::default()),
        stop: Arc::new(AtomicBool::new(false)),
    };
    let threads = start_tasks(&ctx, &span)?;
    wait_for_stop(o.duration_s);
    ctx.stop.store(true, Ordering::SeqCst);
    for (name, t) in threads {
        if t.join().is_err() {
            error!(task = name, "the {name} thread panicked");
        }
    }
    let c = &ctx.counters;
    info!(
        lv_out = c.lv_out.load(Ordering::Relaxed),
        lv_in = c.lv_in.load(Ordering::Relaxed),
        malformed = c.malformed.load(Ordering::Relaxed),
        commands = c.commands.load(Ordering::Relaxed),
        "stopped; leading values out {}, in {}, malformed payloads {}, commands {}",
        c.lv_out.load(Ordering::Relaxed),
        c.lv_in.load(Ordering::Relaxed),
        c.malformed.load(Ordering::Relaxed),
        c.commands.load(Ordering::Relaxed)
    );
    if let Err(e) = session.close().wait() {
        // The process ends next: the peers see the liveliness token go either way.
        debug!(error = %e, "closing the Zenoh session");
    }
    Ok(Arc::clone(&ctx.counters))
}

/// The index of this gateway's host: `--host`, else the cell's only host.
fn select_host(cell: &Cell, o: &Options) -> Result<usize, GatewayError> {
    match &o.host {
        Some(name) => {
            cell.hosts
                .iter()
                .position(|x| x == name)
                .ok_or_else(|| GatewayError::UnknownHost {
                    cell: o.cell.clone(),
                    host: name.clone(),
                    hosts: cell.hosts.clone(),
                })
        }
        None if cell.hosts.len() == 1 => Ok(0),
        None => Err(GatewayError::HostRequired {
            cell: o.cell.clone(),
            hosts: cell.hosts.clone(),
        }),
    }
}

/// A thread of the gateway: runs until the stop flag is set.
type Task = fn(&Ctx) -> Result<(), GatewayError>;

/// Starts the gateway's threads (leading values out and in, commands, telemetry, clock), each in
/// a span named after it under `parent`. A thread that fails logs its error and ends; the
/// others go on.
fn start_tasks(
    ctx: &Ctx,
    parent: &tracing::Span,
) -> Result<Vec<(&'static str, std::thread::JoinHandle<()>)>, GatewayError> {
    let tasks: [(&'static str, Task); 5] = [
        ("lv-out", lv_out),
        ("lv-in", lv_in),
        ("commands", commands),
        ("telemetry", telemetry),
        ("clock", clock),
    ];
    let mut threads = Vec::new();
    for (name, task) in tasks {
        let x = ctx.clone();
        let span = tracing::info_span!(parent: parent, "task", name);
        let spawned = std::thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                let _entered = span.enter();
                if let Err(e) = task(&x) {
                    error!(task = name, error = %e, "{name}: {e}");
                }
            });
        match spawned {
            Ok(t) => threads.push((name, t)),
            Err(source) => {
                ctx.stop.store(true, Ordering::SeqCst);
                return Err(GatewayError::Thread { name, source });
            }
        }
    }
    Ok(threads)
}

/// Returns on SIGINT/SIGTERM or when `duration_s` has passed.
fn wait_for_stop(duration_s: Option<f64>) {
    let started = Instant::now();
    while !rt::termination_requested()
        && duration_s.is_none_or(|d| started.elapsed().as_secs_f64() < d)
    {
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn iox(cell: &Cell, host: &str, what: &str) -> Result<IpcNode, GatewayError> {
    Ok(ipc::node(
        &format!("tandem/{}/gateway-{what}", cell.name),
        host,
    )?)
}

/// iceoryx2 to Zenoh: wakes on each publishing node's event and forwards every new sample.
fn lv_out(x: &Ctx) -> Result<(), GatewayError> {
    let (cell, host, plan, session, c, stop) = x.parts();
    if plan.out.is_empty() {
        return Ok(());
    }
    rt::no_timer_slack();
    let node = iox(cell, host, "lv-out")?;
    let mut listeners = Vec::new();
    for n in plan
        .out
        .iter()
        .map(|(_, _, n)| *n)
        .collect::<std::collections::BTreeSet<_>>()
    {
        let svc = ipc::published(&node, &cell.name, &cell.nodes[n].name)?;
        listeners.push(
            svc.listener_builder()
                .create()
                .map_err(GatewayError::port("listener"))?,
        );
    }
    let mut routes = Vec::new();
    for (l, cp, _) in &plan.out {
        let actual = *cp == Coupling::Actual;
        let svc = ipc::leading_values(
            &node,
            &cell.name,
            cell.leader_name(*l),
            actual,
            cell.leading_history(*l),
        )?;
        let sub = svc
            .subscriber_builder()
            .buffer_size(cell.leading_history(*l))
            .create()
            .map_err(GatewayError::port("subscriber"))?;
        let key = keys::leading_value(&cell.name, cell.leader_name(*l), actual);
        // Block, not Drop: an express message takes a whole batch of the link's real-time queue
        // (two batches), so with Drop a stall of the link's task longer than 1 ms lost samples,
        // which the follower then bridged by interpolation, off by up to jerk·Δt³ where the
        // leader's jerk changed. A sample late by less than the delay D is still exact; this
        // thread waits for the link instead, the iceoryx2 subscriber's buffer holds what
        // arrives meanwhile, and the node never waits (docs/gateway.md).
        let publisher = session
            .declare_publisher(key.clone())
            .priority(Priority::RealTime)
            .express(true)
            .congestion_control(CongestionControl::Block)
            .allowed_destination(Locality::Remote)
            .wait()
            .map_err(GatewayError::zenoh(format!("publisher {key}")))?;
        routes.push((sub, publisher));
    }
    let each = Duration::from_millis(5) / listeners.len().max(1) as u32;
    while !stop.load(Ordering::SeqCst) {
        for l in &listeners {
            // Woken or timed out, the routes are drained the same; a failed wait is a timeout.
            let _ = l.timed_wait(|_| {}, each);
            for (sub, publisher) in &routes {
                while let Ok(Some(s)) = sub.receive() {
                    if publisher
                        .put(json::encode_leading_value(s.payload()))
                        .wait()
                        .is_ok()
                    {
                        c.lv_out.fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
        }
    }
    Ok(())
}

/// Zenoh to iceoryx2: every sample of a remote leader followed here goes into this host's
/// leading-value service, timestamp unchanged.
fn lv_in(x: &Ctx) -> Result<(), GatewayError> {
    let (cell, host, plan, session, c, stop) = x.parts();
    let node = iox(cell, host, "lv-in")?;
    // (leader name, actual, leader index, publisher): looked up by &str, no allocation per sample.
    let mut publishers = Vec::new();
    for (l, cp) in &plan.inn {
        let actual = *cp == Coupling::Actual;
        let svc = ipc::leading_values(
            &node,
            &cell.name,
            cell.leader_name(*l),
            actual,
            cell.leading_history(*l),
        )?;
        let p = svc
            .publisher_builder()
            .create()
            .map_err(GatewayError::port("publisher"))?;
        publishers.push((cell.leader_name(*l), actual, *l, p));
    }
    // The leaders this host publishes: a sample of one from another host is forged.
    let local: Vec<(&str, bool)> = plan
        .out
        .iter()
        .map(|(l, cp, _)| (cell.leader_name(*l), *cp == Coupling::Actual))
        .collect();
    // Every leading value of the cell, so that a malformed one on any lv key is counted.
    let sub = session
        .declare_subscriber(keys::leading_values(&cell.name))
        .allowed_origin(Locality::Remote)
        .wait()
        .map_err(GatewayError::zenoh("subscriber"))?;
    while !stop.load(Ordering::SeqCst) {
        let Ok(Some(sample)) = sub.recv_timeout(Duration::from_millis(50)) else {
            continue;
        };
        let key = sample.key_expr().as_str();
        let Some((leader, actual)) = keys::parse_leading_value(&cell.name, key) else {
            c.malformed.fetch_add(1, Ordering::Relaxed);
            debug!(key, "not a leading-value key: dropped");
            continue;
        };
        let decoded = json::decode_leading_value(&sample.payload().to_bytes());
        let Some((_, _, l, p)) = publishers
            .iter()
            .find(|(n, a, _, _)| *n == leader && *a == actual)
        else {
            if local.iter().any(|(n, a)| *n == leader && *a == actual) {
                // A remote copy of a leader this host publishes: forged, never bridged.
                c.lv_forged.fetch_add(1, Ordering::Relaxed);
                debug!(key, "a leader of this host, from another: dropped");
                continue;
            }
            // A leader nobody here follows: not ours to forward (but still checked).
            if decoded.is_err() {
                c.malformed.fetch_add(1, Ordering::Relaxed);
                debug!(key, "malformed leading value: dropped");
            }
            continue;
        };
        match decoded {
            Ok(s) if s.leader == cell.leader_id(*l) => {
                if p.send_copy(s).is_ok() {
                    c.lv_in.fetch_add(1, Ordering::Relaxed);
                }
            }
            _ => {
                c.malformed.fetch_add(1, Ordering::Relaxed);
                debug!(key, "malformed leading value: dropped");
            }
        }
    }
    Ok(())
}

/// The iceoryx2 command client of one node.
type CommandClient = iceoryx2::port::client::Client<
    iceoryx2::prelude::ipc::Service,
    CommandRequest,
    (),
    tandem_protocol::wire::CommandReply,
    (),
>;

/// What the queryables of the command keys share: the command thread's queue, the senders'
/// rates, the cell's name and rate (for the `busy` message) and the counters.
#[derive(Clone)]
struct CommandGate {
    tx: mpsc::SyncSender<(zenoh::query::Query, String)>,
    rates: Arc<std::sync::Mutex<SenderRates>>,
    cell: Arc<Cell>,
    counters: Arc<Counters>,
}

/// A queryable on `expr` that answers a sender beyond its rate `busy` at once, on Zenoh's
/// thread, and hands every other query (with its sender) to the command thread: a flood's
/// excess never waits in the queue ahead of another sender's commands.
fn command_queryable(
    session: &zenoh::Session,
    expr: String,
    gate: CommandGate,
) -> Result<zenoh::query::Queryable<()>, GatewayError> {
    session
        .declare_queryable(expr)
        .callback(move |q| {
            let c = &gate.counters;
            c.commands.fetch_add(1, Ordering::Relaxed);
            let sender = query_sender(&gate.cell.name, &q);
            // A poisoned lock (a panic elsewhere while admitting) admits: the command thread
            // still answers every command.
            let admitted = gate
                .rates
                .lock()
                .map_or(true, |mut r| r.admit(&sender, tandem_rt::now_ns()));
            if !admitted {
                c.commands_busy.fetch_add(1, Ordering::Relaxed);
                reply_json(
                    &q,
                    &ReplyJson::failed(
                        "busy",
                        format!(
                            "busy: more than {} commands per second from `{sender}`; try again",
                            gate.cell.command_rate_hz
                        ),
                    ),
                );
                return;
            }
            // Never dropped unanswered: a full queue answers `busy` at once.
            if let Err(mpsc::TrySendError::Full((q, _))) = gate.tx.try_send((q, sender)) {
                reply_json(
                    &q,
                    &ReplyJson::failed(
                        "busy",
                        "the gateway's command queue is full; try again".to_string(),
                    ),
                );
            }
        })
        .wait()
        .map_err(GatewayError::zenoh("queryable"))
}

/// Zenoh queries to the nodes' command services and back.
fn commands(x: &Ctx) -> Result<(), GatewayError> {
    let (cell, host, plan, session, c, stop) = x.parts();
    let node = iox(cell, host, "commands")?;
    let (tx, rx) = mpsc::sync_channel(COMMAND_QUEUE);
    let gate = CommandGate {
        tx,
        rates: Arc::new(std::sync::Mutex::new(SenderRates::new(
            cell.command_rate_hz,
            cell.command_burst,
        ))),
        cell: x.cell.clone(),
        counters: x.counters.clone(),
    };
    let mut queryables = Vec::new();
    let mut clients: HashMap<String, CommandClient> = HashMap::new();
    for n in &plan.nodes {
        let name = &cell.nodes[*n].name;
        // The sender-bound key always; the key without a sender only in a plain cell (in an
        // mTLS cell the sender must be the one the access control checked).
        let mut exprs = vec![keys::commands(&cell.name, name)];
        if cell.security.mode == SecurityMode::Plain {
            exprs.push(keys::commands_unbound(&cell.name, name));
        }
        for expr in exprs {
            queryables.push(command_queryable(session, expr, gate.clone())?);
        }
        let svc = ipc::commands(&node, &cell.name, name)?;
        clients.insert(
            name.clone(),
            svc.client_builder()
                .create()
                .map_err(GatewayError::port("command client"))?,
        );
    }
    let mut flight = InFlight::default();
    while !stop.load(Ordering::SeqCst) {
        // Block for the next query only when no reply is awaited; otherwise look every ms.
        let wait = if flight.is_empty() { 50 } else { 1 };
        if let Ok(first) = rx.recv_timeout(Duration::from_millis(wait)) {
            flight.waiting.push_back(first);
            while let Ok(more) = rx.try_recv() {
                flight.waiting.push_back(more);
            }
        }
        flight.start(&clients, (cell, host, session), c);
        flight.finish((cell, session));
    }
    flight.abandon();
    drop(queryables);
    // The queryables' callbacks may still hold the queue's sender: answer what is left.
    while let Ok((q, _)) = rx.try_recv() {
        reply_json(
            &q,
            &ReplyJson::failed("busy", "the gateway is stopping; try again".to_string()),
        );
    }
    Ok(())
}

/// Queries waiting for the command thread; more are answered `busy` at once.
const COMMAND_QUEUE: usize = 4096;

/// Sends `reply` to query `q` (a failure is logged: the querier times out).
fn reply_json(q: &zenoh::query::Query, reply: &ReplyJson) {
    let body = serde_json::to_string(reply).unwrap_or_default();
    if let Err(e) = q.reply(q.key_expr().clone(), body).wait() {
        warn!(key = q.key_expr().as_str(), error = %e, "the reply to a command query could not be sent");
    }
}

/// Who sends query `q`: the sender its key names (`…/cmd/<sender>`, docs/security.md
/// "Commands with identity": in an mTLS cell the access control let the query through only if
/// that is the common name of the querier's certificate), whatever its payload claims; for a
/// key without a sender (plain cells only) its attachment `sender=<name>`, else the `sender` of
/// its JSON payload, else `anonymous` (docs/gateway.md, "Command rate").
fn query_sender(cell: &str, q: &zenoh::query::Query) -> String {
    let claimed = claimed_sender(q);
    match keys::parse_command(cell, q.key_expr().as_str()).and_then(|k| k.sender) {
        Some(bound) => {
            if let Some(c) = claimed.filter(|c| c != bound) {
                info!(
                    sender = bound,
                    claimed = %c,
                    "the command's payload claims another sender: the key's is used"
                );
            }
            bound.to_string()
        }
        None => claimed.unwrap_or_else(|| ANONYMOUS.to_string()),
    }
}

/// The sender query `q` claims: its attachment `sender=<name>`, else the `sender` of its JSON
/// payload (not authenticated).
fn claimed_sender(q: &zenoh::query::Query) -> Option<String> {
    let from_attachment = q.attachment().and_then(|a| {
        a.try_to_string()
            .ok()
            .and_then(|t| t.strip_prefix("sender=").map(|s| s.trim().to_string()))
    });
    let from_json = || {
        q.payload()
            .and_then(|p| p.try_to_string().ok().map(|t| t.to_string()))
            .filter(|t| t.trim_start().starts_with('{'))
            .and_then(|t| serde_json::from_str::<json::CommandJson>(&t).ok())
            .and_then(|c| c.sender)
    };
    from_attachment.or_else(from_json).filter(|s| !s.is_empty())
}

/// Commands forwarded to a node at most at once per node (each node's command thread queues
/// them for its cycle, which applies all it has each cycle; at most
/// [`ipc::COMMANDS_IN_FLIGHT`]): a command waits behind at most this many others to the same
/// node (docs/gateway.md, "Command rate").
const IN_FLIGHT_PER_NODE: usize = 8;

/// A command forwarded to a node, waiting for its reply.
struct Forwarded {
    query: zenoh::query::Query,
    node: String,
    object: String,
    line: String,
    sender: String,
    pending: iceoryx2::pending_response::PendingResponse<
        iceoryx2::prelude::ipc::Service,
        CommandRequest,
        (),
        tandem_protocol::wire::CommandReply,
        (),
    >,
    deadline: Instant,
    span: tracing::Span,
}

/// The command thread's queries: waiting to be forwarded (first come, first served), and
/// forwarded, waiting for their node's reply.
#[derive(Default)]
struct InFlight {
    waiting: std::collections::VecDeque<(zenoh::query::Query, String)>,
    forwarded: Vec<Forwarded>,
}

impl InFlight {
    /// Nothing forwarded and nothing waiting.
    fn is_empty(&self) -> bool {
        self.waiting.is_empty() && self.forwarded.is_empty()
    }

    /// Forwards the waiting queries in their order, as long as their node has fewer than
    /// [`IN_FLIGHT_PER_NODE`] in flight; those that cannot be forwarded are answered.
    fn start(
        &mut self,
        clients: &HashMap<String, CommandClient>,
        at: (&Cell, &str, &zenoh::Session),
        c: &Counters,
    ) {
        let mut kept = std::collections::VecDeque::new();
        while let Some((q, sender)) = self.waiting.pop_front() {
            let node = keys::parse_command(&at.0.name, q.key_expr().as_str()).map(|k| k.node);
            let busy = |n: &str| self.forwarded.iter().filter(|f| f.node == n).count();
            if node.is_some_and(|n| busy(n) >= IN_FLIGHT_PER_NODE) {
                kept.push_back((q, sender));
                continue;
            }
            match forward_start(&q, at, sender, clients, c) {
                Ok(f) => self.forwarded.push(f),
                Err(reply) => reply_json(&q, &reply),
            }
        }
        self.waiting = kept;
    }

    /// Answers every forwarded query whose node replied, or whose 5 s are over.
    fn finish(&mut self, at: (&Cell, &zenoh::Session)) {
        let now = Instant::now();
        let mut i = 0;
        while let Some(f) = self.forwarded.get(i) {
            let reply = match f.pending.receive() {
                Ok(Some(r)) => ReplyJson::from_reply(r.payload()),
                Ok(None) if now < f.deadline => {
                    i += 1;
                    continue;
                }
                Ok(None) => ReplyJson::failed(
                    "unreachable",
                    if f.pending.number_of_server_connections() == 0 {
                        "the node is not running".to_string()
                    } else {
                        "the node did not answer within 5 s".to_string()
                    },
                ),
                Err(e) => ReplyJson::failed("unreachable", format!("{e}")),
            };
            let f = self.forwarded.swap_remove(i);
            forward_end(&f, at, &reply);
            reply_json(&f.query, &reply);
        }
    }

    /// Answers what is left when the gateway stops.
    fn abandon(&mut self) {
        let stopping =
            || ReplyJson::failed("busy", "the gateway is stopping; try again".to_string());
        for (q, _) in self.waiting.drain(..) {
            reply_json(&q, &stopping());
        }
        for f in self.forwarded.drain(..) {
            reply_json(&f.query, &stopping());
        }
    }
}

/// Forwards command query `q` to its node, in a `command` span (node, object, instruction,
/// job); or the reply saying why it was not forwarded.
fn forward_start(
    q: &zenoh::query::Query,
    (cell, host, _): (&Cell, &str, &zenoh::Session),
    sender: String,
    clients: &HashMap<String, CommandClient>,
    c: &Counters,
) -> Result<Forwarded, ReplyJson> {
    let key = q.key_expr().as_str().to_string();
    let Some(keys::CommandKey {
        node: node_name,
        object,
        ..
    }) = keys::parse_command(&cell.name, &key)
    else {
        debug!(key, "not a command key");
        return Err(ReplyJson::failed(
            "invalid",
            format!("`{key}` is not a command key"),
        ));
    };
    let span = tracing::info_span!(
        "command",
        sender,
        node = node_name,
        object,
        instruction = tracing::field::Empty,
        job = tracing::field::Empty
    );
    let line = command_line(q);
    if let Ok(l) = &line {
        span.record("instruction", l.split_whitespace().next().unwrap_or(""));
    }
    let failed = |reply: ReplyJson| {
        let _in = span.enter();
        debug!(outcome = %reply.outcome, message = %reply.message, "command answered");
        Err(reply)
    };
    let (line, client) = match (line, clients.get(node_name)) {
        (Err(m), _) => {
            c.malformed.fetch_add(1, Ordering::Relaxed);
            return failed(ReplyJson::failed("invalid", m));
        }
        (Ok(_), None) => {
            let m = format!("node `{node_name}` is not on host `{host}`");
            return failed(ReplyJson::failed("invalid", m));
        }
        (Ok(line), Some(client)) => (line, client),
    };
    let pending = match client.send_copy(CommandRequest {
        text: Text::new(&format!("{object} {line}")),
        sender: Text::new(&sender),
    }) {
        Ok(p) => p,
        Err(e) => {
            let m = format!("sending to the node: {e}");
            return failed(ReplyJson::failed("unreachable", m));
        }
    };
    Ok(Forwarded {
        node: node_name.to_string(),
        object: object.to_string(),
        line,
        sender,
        pending,
        deadline: Instant::now() + Duration::from_secs(5),
        span: span.clone(),
        query: q.clone(),
    })
}

/// Publishes who commanded what with what outcome, for every observer (the node's audit file
/// has the same record), and logs the outcome in the command's span.
fn forward_end(f: &Forwarded, (cell, session): (&Cell, &zenoh::Session), reply: &ReplyJson) {
    let event = EventJson::command(&f.object, &f.sender, &f.line, reply);
    put(
        session,
        keys::events(&cell.name, &f.node, &f.object),
        serde_json::to_string(&event).unwrap_or_default(),
    );
    f.span.record("job", reply.job);
    let _in = f.span.enter();
    debug!(
        outcome = %reply.outcome,
        error_id = %reply.error_id,
        message = %reply.message,
        "command answered"
    );
}

/// The command line of a query's payload: text as it is, or the JSON form turned into text.
fn command_line(q: &zenoh::query::Query) -> Result<String, String> {
    let text = q
        .payload()
        .map(|p| p.try_to_string().map(|s| s.to_string()))
        .unwrap_or(Ok(String::new()));
    match text {
        Err(_) => Err("the payload is not UTF-8".to_string()),
        Ok(t) if t.trim_start().starts_with('{') => serde_json::from_str::<json::CommandJson>(&t)
            .map_err(|e| format!("the JSON command is malformed: {e}"))
            .and_then(|c| c.to_line().map_err(|e| e.to_string())),
        Ok(t) => Ok(t),
    }
}

/// The telemetry and event subscribers of one node.
struct NodeFeeds<'a> {
    name: &'a str,
    telemetry: iceoryx2::port::subscriber::Subscriber<
        iceoryx2::prelude::ipc::Service,
        [tandem_protocol::wire::AxisTelemetry],
        tandem_protocol::wire::NodeHealth,
    >,
    events: iceoryx2::port::subscriber::Subscriber<
        iceoryx2::prelude::ipc::Service,
        tandem_protocol::wire::Event,
        (),
    >,
    /// The node's signal edges, if it has signals.
    signals: Option<
        iceoryx2::port::subscriber::Subscriber<
            iceoryx2::prelude::ipc::Service,
            tandem_protocol::wire::SignalEvent,
            (),
        >,
    >,
}

/// Puts `value` on `key`; a failed put is counted by Zenoh's own statistics and the next
/// telemetry period puts a newer value, so it is only logged at debug level.
fn put(session: &zenoh::Session, key: String, value: String) {
    if let Err(e) = session.put(key.as_str(), value).wait() {
        debug!(key = %key, error = %e, "put failed");
    }
}

/// Per-axis state and node health at the telemetry rate, events and log lines as they happen.
fn telemetry(x: &Ctx) -> Result<(), GatewayError> {
    let (cell, host, plan, session, c, stop) = x.parts();
    let node = iox(cell, host, "telemetry")?;
    let names = cell.object_names();
    let mut feeds = Vec::new();
    for n in &plan.nodes {
        let name = &cell.nodes[*n].name;
        let has_signals = cell
            .signals
            .iter()
            .any(|s| cell.devices.get(s.device.0).is_some_and(|d| d.node == *n));
        let signals = if has_signals {
            Some(
                ipc::signals(&node, &cell.name, name)?
                    .subscriber_builder()
                    .buffer_size(1024)
                    .create()
                    .map_err(GatewayError::port("signal subscriber"))?,
            )
        } else {
            None
        };
        feeds.push(NodeFeeds {
            signals,
            name,
            telemetry: ipc::telemetry(&node, &cell.name, name)?
                .subscriber_builder()
                .buffer_size(4)
                .create()
                .map_err(GatewayError::port("telemetry subscriber"))?,
            events: ipc::events(&node, &cell.name, name)?
                .subscriber_builder()
                .buffer_size(1024)
                .create()
                .map_err(GatewayError::port("event subscriber"))?,
        });
    }
    let period = Duration::from_secs_f64(1.0 / cell.telemetry_hz);
    let mut next = Instant::now();
    while !stop.load(Ordering::SeqCst) {
        next += period;
        for f in &feeds {
            put_state(session, cell, &names, f);
            put_events(session, cell, &names, f);
            put_signals(session, cell, f);
        }
        put_counters(session, cell, host, c);
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now;
        }
    }
    Ok(())
}

/// The newest telemetry of one node: each axis' state and the node's health.
fn put_state(session: &zenoh::Session, cell: &Cell, names: &[&str], f: &NodeFeeds) {
    let mut newest = None;
    while let Ok(Some(s)) = f.telemetry.receive() {
        newest = Some((*s.user_header(), s.payload().to_vec()));
    }
    let Some((h, axes)) = newest else {
        return;
    };
    for a in &axes {
        let axis = names.get(a.axis as usize).copied().unwrap_or("?");
        let state = AxisState::new(&h, f.name, axis, a);
        put(
            session,
            keys::state(&cell.name, f.name, axis),
            serde_json::to_string(&state).unwrap_or_default(),
        );
    }
    put(
        session,
        keys::health(&cell.name, f.name),
        serde_json::to_string(&Health::new(f.name, &h)).unwrap_or_default(),
    );
}

/// The job events and log lines of one node since the last call.
fn put_events(session: &zenoh::Session, cell: &Cell, names: &[&str], f: &NodeFeeds) {
    while let Ok(Some(s)) = f.events.receive() {
        let ev = s.payload();
        let object = if ev.kind == EVENT_JOB {
            names.get(ev.object as usize).copied().unwrap_or("?")
        } else {
            ""
        };
        let body = serde_json::to_string(&EventJson::new(ev, object)).unwrap_or_default();
        match ev.kind {
            EVENT_JOB => put(session, keys::events(&cell.name, f.name, object), body),
            EVENT_LOG => put(session, keys::log(&cell.name, f.name), body),
            _ => {}
        }
    }
}

/// Each signal edge of one node since the last call, on its signal's key (docs/processes.md,
/// "Zenoh keys").
fn put_signals(session: &zenoh::Session, cell: &Cell, f: &NodeFeeds) {
    use tandem_protocol::wire::{
        SIGNAL_FLOAT, SIGNAL_INPUT, SIGNAL_INTEGER, SIGNAL_LATE, SIGNAL_TIMESTAMPED,
    };
    let Some(sub) = &f.signals else {
        return;
    };
    while let Ok(Some(s)) = sub.receive() {
        let e = s.payload();
        let Some(signal) = cell.signals.get(e.signal as usize) else {
            continue;
        };
        let input = e.flags & SIGNAL_INPUT != 0;
        let body = if e.flags & (SIGNAL_INTEGER | SIGNAL_FLOAT) != 0 {
            // A new reading of an integer or float signal: the edge fields it shares, and
            // its value and type.
            let (ty, value) = if e.flags & SIGNAL_INTEGER != 0 {
                ("integer", serde_json::json!(e.value as i64))
            } else {
                ("float", serde_json::json!(e.value))
            };
            serde_json::json!({
                "signal": signal.name,
                "node": f.name,
                "direction": if input { "input" } else { "output" },
                "type": ty,
                "value": value,
                "level": e.level != 0,
                "time_ns": e.t_ns,
                "sampled_ns": e.ref_ns,
                "timestamped": false,
            })
        } else if input {
            serde_json::json!({
                "signal": signal.name,
                "node": f.name,
                "direction": "input",
                "level": e.level != 0,
                "time_ns": e.t_ns,
                "sampled_ns": e.ref_ns,
                "timestamped": e.flags & SIGNAL_TIMESTAMPED != 0,
            })
        } else {
            serde_json::json!({
                "signal": signal.name,
                "node": f.name,
                "direction": "output",
                "level": e.level != 0,
                "time_ns": e.t_ns,
                "edge_ns": e.ref_ns,
                "timestamped": e.flags & SIGNAL_TIMESTAMPED != 0,
                "late": e.flags & SIGNAL_LATE != 0,
            })
        };
        put(
            session,
            keys::signal(&cell.name, f.name, &signal.name),
            body.to_string(),
        );
    }
}

/// The gateway's own counters.
fn put_counters(session: &zenoh::Session, cell: &Cell, host: &str, c: &Counters) {
    let own = serde_json::json!({
        "host": host,
        "lv_out": c.lv_out.load(Ordering::Relaxed),
        "lv_in": c.lv_in.load(Ordering::Relaxed),
        "malformed": c.malformed.load(Ordering::Relaxed),
        "commands": c.commands.load(Ordering::Relaxed),
        "commands_busy": c.commands_busy.load(Ordering::Relaxed),
        "lv_forged": c.lv_forged.load(Ordering::Relaxed),
        "clock_offset_us": c.clock_offset_ns.load(Ordering::Relaxed) as f64 * 1e-3,
        "clock_warnings": c.clock_warnings.load(Ordering::Relaxed),
    });
    put(session, keys::gateway(&cell.name, host), own.to_string());
}

/// Answers clock queries and measures the offset to the other hosts' gateways once a second:
/// `offset = t_remote - (t_sent + t_received) / 2`, from the round trip with the smallest delay
/// of five.
fn clock(x: &Ctx) -> Result<(), GatewayError> {
    let (cell, host, plan, session, c, stop) = x.parts();
    let h = x.h;
    let _q = session
        .declare_queryable(keys::clock(&cell.name, host))
        .callback(|q| {
            // An asker whose reply is lost retries on its next round.
            let _ = q
                .reply(q.key_expr().clone(), rt::now_ns().to_string())
                .wait();
        })
        .wait()
        .map_err(GatewayError::zenoh("clock queryable"))?;
    let others: Vec<usize> = (0..cell.hosts.len()).filter(|x| *x != h).collect();
    let mut warned: HashMap<usize, bool> = HashMap::new();
    while !stop.load(Ordering::SeqCst) {
        let mut worst = 0i64;
        for o in &others {
            let Some((rtt, offset)) = clock_offset(session, cell, *o, c) else {
                continue;
            };
            worst = worst.max(offset.abs());
            if let Some(d) = plan.min_delay.get(o) {
                let limit = (*d as f64 * cell.clock_warning_fraction) as i64;
                let over = offset.abs() > limit;
                if over && !warned.get(o).copied().unwrap_or(false) {
                    c.clock_warnings.fetch_add(1, Ordering::Relaxed);
                    warn!(
                        other = %cell.hosts[*o],
                        offset_us = offset as f64 * 1e-3,
                        round_trip_us = rtt as f64 * 1e-3,
                        "the clock of host `{}` is {:.1} µs off (round trip {:.1} µs), more than {:.0} % of the {:.1} ms leading-value delay between the hosts: synchronize the clocks (PTP)",
                        cell.hosts[*o],
                        offset as f64 * 1e-3,
                        rtt as f64 * 1e-3,
                        cell.clock_warning_fraction * 100.0,
                        *d as f64 * 1e-6
                    );
                }
                warned.insert(*o, over);
            }
        }
        c.clock_offset_ns.store(worst, Ordering::Relaxed);
        let until = Instant::now() + Duration::from_secs(1);
        while Instant::now() < until && !stop.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    Ok(())
}

/// The clock offset to host `o` (ns) with the round trip it was measured over: the best of
/// five queries, or `None` when none was answered.
fn clock_offset(
    session: &zenoh::Session,
    cell: &Cell,
    o: usize,
    c: &Counters,
) -> Option<(i64, i64)> {
    let mut best: Option<(i64, i64)> = None;
    for _ in 0..5 {
        let t0 = rt::now_ns();
        let Ok(replies) = session
            .get(keys::clock(&cell.name, &cell.hosts[o]))
            .timeout(Duration::from_millis(500))
            .wait()
        else {
            continue;
        };
        let Ok(r) = replies.recv() else {
            continue;
        };
        let t1 = rt::now_ns();
        let remote = r
            .result()
            .ok()
            .and_then(|s| s.payload().try_to_string().ok().map(|x| x.to_string()))
            .and_then(|x| x.parse::<i64>().ok());
        match remote {
            Some(tr) => {
                let rtt = t1 - t0;
                if best.is_none_or(|(b, _)| rtt < b) {
                    best = Some((rtt, tr - (t0 + t1) / 2));
                }
            }
            None => {
                c.malformed.fetch_add(1, Ordering::Relaxed);
                debug!(other = %cell.hosts[o], "malformed clock reply");
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    const CELL: &str = r#"
[cell]
name = "c"

SECURITY

[[hosts]]
name = "h1"
listen = ["PROTO/10.0.0.1:7447"]

[[hosts]]
name = "h2"
listen = ["PROTO/10.0.0.2:7447"]

[[nodes]]
name = "n"
cycle_us = 1000
host = "h1"
"#;

    fn get(c: &zenoh::Config, key: &str) -> serde_json::Value {
        serde_json::from_str(&c.get_json(key).unwrap()).unwrap()
    }

    #[test]
    fn mtls_listens_where_named_on_tls_only_with_both_certificates_and_the_acl() {
        let dir = std::env::temp_dir().join(format!("tandem-gw-cfg-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("pki")).unwrap();
        for f in ["ca.pem", "host-h1.pem", "host-h1.key"] {
            std::fs::write(dir.join("pki").join(f), "x").unwrap();
        }
        let src = CELL
            .replace("PROTO", "tls")
            .replace("SECURITY", "[security]\nobservers = [\"hmi\"]");
        std::fs::write(dir.join("c.toml"), &src).unwrap();
        let cell = tandem_config::load(&dir.join("c.toml")).unwrap();
        let c = zenoh_config(&cell, 0).unwrap();
        assert_eq!(
            get(&c, "listen/endpoints"),
            serde_json::json!(["tls/10.0.0.1:7447"])
        );
        assert_eq!(
            get(&c, "connect/endpoints"),
            serde_json::json!(["tls/10.0.0.2:7447"])
        );
        assert_eq!(get(&c, "scouting/multicast/enabled"), false);
        assert_eq!(get(&c, "scouting/gossip/enabled"), false);
        assert_eq!(
            get(&c, "transport/link/protocols"),
            serde_json::json!(["tls"])
        );
        assert_eq!(get(&c, "transport/link/tls/enable_mtls"), true);
        let pki = dir.join("pki");
        assert_eq!(
            get(&c, "transport/link/tls/connect_certificate"),
            pki.join("host-h1.pem").to_string_lossy().as_ref()
        );
        assert_eq!(
            get(&c, "transport/link/tls/root_ca_certificate"),
            pki.join("ca.pem").to_string_lossy().as_ref()
        );
        assert_eq!(get(&c, "access_control/default_permission"), "deny");
        assert_eq!(get(&c, "access_control/enabled"), true);
        // Host h2's key is missing: refused by name before Zenoh opens anything.
        let e = zenoh_config(&cell, 1).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("host-h2.pem"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn plain_without_endpoints_listens_nowhere_and_does_not_scout() {
        let src = "[cell]\nname = \"c\"\n\n[[nodes]]\nname = \"n\"\ncycle_us = 1000\n";
        let cell = tandem_config::parse("c.toml", src).unwrap();
        let c = zenoh_config(&cell, 0).unwrap();
        assert_eq!(get(&c, "listen/endpoints"), serde_json::json!([]));
        assert_eq!(get(&c, "scouting/multicast/enabled"), false);
        assert_ne!(get(&c, "access_control/enabled"), true);
        let src = CELL.replace("PROTO", "tcp").replace(
            "SECURITY",
            "[security]\nmode = \"plain\"\nmulticast_scouting = true",
        );
        let cell = tandem_config::parse("c.toml", &src).unwrap();
        let c = zenoh_config(&cell, 1).unwrap();
        assert_eq!(
            get(&c, "listen/endpoints"),
            serde_json::json!(["tcp/10.0.0.2:7447"])
        );
        assert_eq!(get(&c, "scouting/multicast/enabled"), true);
        assert_ne!(get(&c, "transport/link/tls/enable_mtls"), true);
        assert_ne!(get(&c, "access_control/enabled"), true);
    }
}
