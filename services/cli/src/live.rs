//! The commands that work on a running cell over iceoryx2: `up` (start and supervise a host's
//! nodes), `status`, `watch` and `cmd`.

use std::collections::VecDeque;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tandem_config::Cell;
use tandem_motion::error_id::ErrorId;
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::wire::{
    AxisTelemetry, CommandRequest, Event, NodeHealth, Text, EVENT_JOB, EVENT_LOG, JOB_ABORTED,
    JOB_DONE, JOB_ERROR, JOB_REACHED, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID,
    OUTCOME_REJECTED,
};
use tandem_rt as rt;

type TelemetrySub = iceoryx2::port::subscriber::Subscriber<
    iceoryx2::prelude::ipc::Service,
    [AxisTelemetry],
    NodeHealth,
>;
type EventSub = iceoryx2::port::subscriber::Subscriber<iceoryx2::prelude::ipc::Service, Event, ()>;

/// A failure with its exit code: 1 the command failed, 2 the input is wrong, 3 the cell is not
/// reachable (not running, timeout), 4 an iceoryx2 error.
#[derive(Debug)]
pub struct Fail(pub u8, pub String);

impl From<ipc::IpcError> for Fail {
    fn from(e: ipc::IpcError) -> Self {
        Fail(4, e.to_string())
    }
}

fn load(path: &Path) -> Result<Cell, Fail> {
    tandem_config::load(path).map_err(|e| Fail(2, e.to_string()))
}

/// The cell file of `status`, `watch` and `cmd`: `--cell`, else `$TANDEM_CELL`.
pub fn cell_path(given: Option<&PathBuf>) -> Result<PathBuf, Fail> {
    given
        .cloned()
        .or_else(|| std::env::var_os("TANDEM_CELL").map(PathBuf::from))
        .ok_or_else(|| {
            Fail(
                2,
                "which cell? give --cell <cell.toml> or set TANDEM_CELL".into(),
            )
        })
}

/// The nodes of `host` (by name; the only host when `None`).
fn host_nodes(cell: &Cell, host: Option<&str>) -> Result<(String, Vec<usize>), Fail> {
    let h = match host {
        Some(h) => cell.hosts.iter().position(|x| x == h).ok_or_else(|| {
            Fail(
                2,
                format!(
                    "no host `{h}` in cell `{}`; it has: {}",
                    cell.name,
                    cell.hosts.join(", ")
                ),
            )
        })?,
        None if cell.hosts.len() == 1 => 0,
        None => {
            return Err(Fail(
                2,
                format!(
                    "cell `{}` has several hosts ({}): say which with --host",
                    cell.name,
                    cell.hosts.join(", ")
                ),
            ))
        }
    };
    let nodes = (0..cell.nodes.len())
        .filter(|n| cell.nodes[*n].host == h)
        .collect();
    Ok((cell.hosts[h].clone(), nodes))
}

/// An iceoryx2 node of this command in the domain of `host`.
fn cli_node(cell: &Cell, what: &str, host: &str) -> Result<IpcNode, Fail> {
    Ok(ipc::node(
        &format!("tandem/{}/{what}-{}", cell.name, std::process::id()),
        host,
    )?)
}

/// What an observer holds of the cell's nodes.
struct Observer {
    telemetry: Vec<(usize, TelemetrySub)>,
    events: Vec<(usize, EventSub)>,
    last: Vec<Option<(NodeHealth, Vec<AxisTelemetry>, Instant)>>,
}

impl Observer {
    fn new(iox: &IpcNode, cell: &Cell, nodes: &[usize], events: bool) -> Result<Self, Fail> {
        let mut telemetry = Vec::new();
        let mut ev = Vec::new();
        for n in nodes {
            let name = &cell.nodes[*n].name;
            let svc = ipc::telemetry(iox, &cell.name, name)?;
            let sub = svc
                .subscriber_builder()
                .buffer_size(4)
                .create()
                .map_err(|e| Fail(4, format!("telemetry of {name}: {e}")))?;
            telemetry.push((*n, sub));
            if events {
                let svc = ipc::events(iox, &cell.name, name)?;
                let sub = svc
                    .subscriber_builder()
                    .buffer_size(1024)
                    .create()
                    .map_err(|e| Fail(4, format!("events of {name}: {e}")))?;
                ev.push((*n, sub));
            }
        }
        Ok(Self {
            telemetry,
            events: ev,
            last: vec![None; cell.nodes.len()],
        })
    }

    /// Takes the newest snapshot of each node.
    fn poll(&mut self) {
        for (n, sub) in &self.telemetry {
            while let Ok(Some(s)) = sub.receive() {
                self.last[*n] = Some((*s.user_header(), s.payload().to_vec(), Instant::now()));
            }
        }
    }

    /// Log lines and job events since the last call: (node, event).
    fn events(&mut self) -> Vec<(usize, Event)> {
        let mut out = Vec::new();
        for (n, sub) in &self.events {
            while let Ok(Some(s)) = sub.receive() {
                out.push((*n, *s.payload()));
            }
        }
        out
    }

    /// Whether node `n` published within the last second.
    fn alive(&self, n: usize) -> bool {
        self.last[n]
            .as_ref()
            .is_some_and(|(_, _, at)| at.elapsed() < Duration::from_secs(1))
    }
}

/// The header of the axis table of `status`, `watch` and `up`.
const HEADER: &str = "node         axis           state                    position    velocity sync      alarm  job";

/// One row of the axis table.
fn table_row(
    node: &str,
    axis: &str,
    state: &str,
    (position, velocity): (f64, f64),
    sync: &str,
    alarm: u32,
    job: u32,
) -> String {
    let alarm = if alarm == 0 {
        "-".to_string()
    } else {
        alarm.to_string()
    };
    format!("{node:<12} {axis:<14} {state:<19} {position:>13.4} {velocity:>11.4} {sync:<9} {alarm:>5} {job:>4}")
}

fn sync_name(code: u32) -> &'static str {
    match code {
        1 => "GearIn",
        2 => "GearInPos",
        3 => "CamIn",
        _ => "-",
    }
}

/// The table of axes (and a health line per node) for `nodes`, axes filtered by `pattern`.
fn render(cell: &Cell, obs: &Observer, nodes: &[usize], pattern: Option<&str>) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "{HEADER}");
    for n in nodes {
        let name = &cell.nodes[*n].name;
        match (&obs.last[*n], obs.alive(*n)) {
            (Some((_, axes, _)), true) => {
                for a in axes {
                    let axis = cell
                        .axes
                        .get(a.axis as usize)
                        .map_or("?", |x| x.name.as_str());
                    if pattern.is_some_and(|p| !format!("{name}/{axis}").contains(p)) {
                        continue;
                    }
                    let _ = writeln!(
                        s,
                        "{}",
                        table_row(
                            name,
                            axis,
                            a.state_name(),
                            (a.position, a.velocity),
                            sync_name(a.sync_function),
                            a.alarm,
                            a.job
                        )
                    );
                }
            }
            _ => {
                let _ = writeln!(s, "{name:<12} (not running)");
            }
        }
    }
    for n in nodes {
        if let (Some((h, _, _)), true) = (&obs.last[*n], obs.alive(*n)) {
            let _ = writeln!(
                s,
                "{:<12} pid {:<7} t={:<14} cycle {} µs, compute {} µs (max {}), lateness {} µs (max {}), overruns {}",
                cell.nodes[*n].name,
                h.pid,
                tandem_runtime::exec::Secs(h.t_ns),
                h.cycle_ns / 1000,
                h.compute_ns / 1000,
                h.max_compute_ns / 1000,
                h.lateness_ns / 1000,
                h.max_lateness_ns / 1000,
                h.overruns
            );
        }
    }
    s
}

/// `tandem status`: one snapshot of the host's nodes. Exit 0 when every node runs, 3 if not.
pub fn status(cell_path: &Path, host: Option<&str>, out: &mut impl Write) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, host)?;
    let iox = cli_node(&cell, "status", &host)?;
    let mut obs = Observer::new(&iox, &cell, &nodes, false)?;
    let deadline = Instant::now() + Duration::from_millis(1500);
    while Instant::now() < deadline && !nodes.iter().all(|n| obs.alive(*n)) {
        obs.poll();
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = write!(out, "{}", render(&cell, &obs, &nodes, None));
    let down: Vec<&str> = nodes
        .iter()
        .filter(|n| !obs.alive(**n))
        .map(|n| cell.nodes[*n].name.as_str())
        .collect();
    if down.is_empty() {
        Ok(())
    } else {
        Err(Fail(
            3,
            format!(
                "not running: {} (start them with `tandem up {}`)",
                down.join(", "),
                cell_path.display()
            ),
        ))
    }
}

/// `tandem watch`: the live table until Ctrl-C (or `count` refreshes).
pub fn watch(
    cell_path: &Path,
    host: Option<&str>,
    pattern: Option<&str>,
    count: Option<u64>,
    out: &mut impl Write,
) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, host)?;
    let iox = cli_node(&cell, "watch", &host)?;
    let mut obs = Observer::new(&iox, &cell, &nodes, false)?;
    rt::install_termination_handler();
    let mut shown = 0u64;
    let tty = std::io::IsTerminal::is_terminal(&std::io::stdout());
    while !rt::termination_requested() && count.is_none_or(|c| shown < c) {
        let until = Instant::now() + Duration::from_millis(250);
        while Instant::now() < until {
            obs.poll();
            std::thread::sleep(Duration::from_millis(10));
        }
        if tty {
            let _ = write!(out, "\x1b[H\x1b[2J");
        }
        let _ = writeln!(out, "{}", render(&cell, &obs, &nodes, pattern));
        let _ = out.flush();
        shown += 1;
    }
    Ok(())
}

/// `tandem cmd`: sends `<node>/<object> <instruction> [--param value]...` and prints the
/// outcome; with `wait`, follows the job until it is done, reached its goal, or failed.
pub fn cmd(
    cell_path: &Path,
    target: &str,
    instruction: &str,
    params: &[(String, String)],
    wait: bool,
    timeout: Duration,
    out: &mut impl Write,
) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    let (node, object) = target.split_once('/').ok_or_else(|| {
        Fail(
            2,
            format!("`{target}`: address an object as <node>/<object>, e.g. followers/feed"),
        )
    })?;
    let n = cell.node(node).ok_or_else(|| {
        let names: Vec<&str> = cell.nodes.iter().map(|x| x.name.as_str()).collect();
        Fail(
            2,
            format!("no node `{node}`; the cell has: {}", names.join(", ")),
        )
    })?;
    // Check it here first, for an error message without a round trip.
    let entry = tandem_config::script::parse_command(&cell, object, instruction, params)
        .map_err(|m| Fail(2, m))?;
    let object_index = cell.object_names().iter().position(|x| *x == entry.axis);
    let mut text = format!("{object} {instruction}");
    for (k, v) in params {
        text.push_str(&format!(" --{k} {v}"));
    }
    let iox = cli_node(&cell, "cmd", &cell.hosts[cell.nodes[n].host])?;
    let events = if wait {
        let svc = ipc::events(&iox, &cell.name, node)?;
        Some(
            svc.subscriber_builder()
                .buffer_size(1024)
                .create()
                .map_err(|e| Fail(4, format!("events of {node}: {e}")))?,
        )
    } else {
        None
    };
    let svc = ipc::commands(&iox, &cell.name, node)?;
    let client = svc
        .client_builder()
        .create()
        .map_err(|e| Fail(4, format!("command client: {e}")))?;
    let not_running = || {
        Fail(
            3,
            format!(
                "node `{node}` is not running (no command server); start it with `tandem up {}`",
                cell_path.display()
            ),
        )
    };
    let pending = client
        .send_copy(CommandRequest {
            text: Text::new(&text),
        })
        .map_err(|e| Fail(4, format!("sending the command: {e}")))?;
    let deadline = Instant::now() + Duration::from_secs(5).min(timeout);
    let reply = loop {
        match pending.receive() {
            Ok(Some(r)) => break *r.payload(),
            Ok(None) => {}
            Err(e) => return Err(Fail(4, format!("receiving the reply: {e}"))),
        }
        if Instant::now() > deadline {
            return Err(if pending.number_of_server_connections() == 0 {
                not_running()
            } else {
                Fail(
                    3,
                    format!(
                        "node `{}` did not answer within {:?}",
                        cell.nodes[n].name,
                        Duration::from_secs(5).min(timeout)
                    ),
                )
            });
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    match reply.outcome {
        OUTCOME_ACCEPTED => {
            if reply.job == 0 {
                let _ = writeln!(
                    out,
                    "{target} {instruction}: accepted at t={}",
                    tandem_runtime::exec::Secs(reply.t_ns)
                );
                return Ok(());
            }
            let _ = writeln!(
                out,
                "{target} {instruction}: accepted, job {} at t={}",
                reply.job,
                tandem_runtime::exec::Secs(reply.t_ns)
            );
        }
        OUTCOME_REJECTED => {
            let id = u16::try_from(reply.error_id)
                .ok()
                .and_then(ErrorId::from_code)
                .map_or(format!("16#{:04X}", reply.error_id), |e| e.to_string());
            return Err(Fail(
                1,
                format!(
                    "{target} {instruction}: rejected with {id}: {}; the running job goes on",
                    reply.message.as_str()
                ),
            ));
        }
        OUTCOME_INVALID => return Err(Fail(2, reply.message.as_str().to_string())),
        OUTCOME_BUSY => return Err(Fail(3, reply.message.as_str().to_string())),
        other => return Err(Fail(4, format!("unknown reply outcome {other}"))),
    }
    let (Some(events), Some(obj)) = (events, object_index) else {
        return Ok(());
    };
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        while let Ok(Some(s)) = events.receive() {
            let e = s.payload();
            if e.kind != EVENT_JOB || e.job != reply.job || e.object as usize != obj {
                continue;
            }
            let _ = writeln!(
                out,
                "t={} {}",
                tandem_runtime::exec::Secs(e.t_ns),
                e.message.as_str()
            );
            match e.code {
                JOB_DONE | JOB_REACHED => return Ok(()),
                JOB_ABORTED => return Err(Fail(1, format!("job {} was aborted", reply.job))),
                JOB_ERROR => {
                    let id = u16::try_from(e.error_id)
                        .ok()
                        .and_then(ErrorId::from_code)
                        .map_or(format!("16#{:04X}", e.error_id), |x| x.to_string());
                    return Err(Fail(1, format!("job {} ended with {id}", reply.job)));
                }
                _ => {}
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Err(Fail(
        3,
        format!("job {} did not end within {timeout:?}", reply.job),
    ))
}

/// A process of `up` (a node, or the host's gateway), with its restart state.
struct Slot {
    /// The node, or `None` for the gateway.
    node: Option<usize>,
    /// What `up` calls it in its messages.
    name: String,
    child: Option<Child>,
    restarts: u32,
    backoff: Duration,
    start_at: Option<Instant>,
    started: Instant,
    finished: bool,
}

/// Where a tandem program (`tandem-node`, `tandem-gateway`) is: beside this executable, else on
/// PATH.
fn binary(name: &str) -> PathBuf {
    std::env::current_exe()
        .ok()
        .and_then(|p| p.parent().map(|d| d.join(name)))
        .filter(|p| p.exists())
        .unwrap_or_else(|| PathBuf::from(name))
}

/// How `up` runs.
#[derive(Debug, Clone, Default)]
pub struct UpOptions {
    /// The host whose nodes to start.
    pub host: Option<String>,
    /// A script for the nodes.
    pub script: Option<PathBuf>,
    /// Write each node's trace and log into this directory.
    pub record: Option<PathBuf>,
    /// Show the live table (else: print events as they happen).
    pub view: bool,
    /// Stop after this many seconds of engine time.
    pub duration_s: Option<f64>,
    /// Start the host's gateway (Zenoh) too.
    pub gateway: bool,
    /// The cell clock's time of cycle 0 (ns). Every host of a cell must use the same; default:
    /// the next whole second plus one.
    pub epoch_ns: Option<i64>,
}

fn spawn(
    cell_path: &Path,
    cell: &Cell,
    slot: &Slot,
    (host, epoch): (&str, i64),
    o: &UpOptions,
    lines: &mpsc::Sender<(String, String)>,
) -> std::io::Result<Child> {
    let name = &slot.name;
    let Some(node) = slot.node else {
        let mut c = std::process::Command::new(binary("tandem-gateway"));
        c.arg(cell_path).arg("--host").arg(host);
        return start(c, name, lines);
    };
    let mut c = std::process::Command::new(binary("tandem-node"));
    c.arg(cell_path)
        .arg("--node")
        .arg(&cell.nodes[node].name)
        .arg("--epoch-ns")
        .arg(epoch.to_string());
    if let Some(s) = &o.script {
        c.arg("--script").arg(s);
    }
    if let Some(d) = o.duration_s {
        c.arg("--duration").arg(d.to_string());
    }
    if let Some(dir) = &o.record {
        let suffix = if slot.restarts == 0 {
            String::new()
        } else {
            format!(".{}", slot.restarts)
        };
        c.arg("--trace")
            .arg(dir.join(format!("{name}{suffix}.csv")))
            .arg("--log")
            .arg(dir.join(format!("{name}{suffix}.log")));
    }
    start(c, name, lines)
}

/// Starts a program of the set, its stderr lines going to `lines` under `name`.
fn start(
    mut c: std::process::Command,
    name: &str,
    lines: &mpsc::Sender<(String, String)>,
) -> std::io::Result<Child> {
    c.stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let mut child = c.spawn()?;
    if let Some(stderr) = child.stderr.take() {
        let (tx, n) = (lines.clone(), name.to_string());
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(stderr)
                .lines()
                .map_while(Result::ok)
            {
                if tx.send((n.clone(), line)).is_err() {
                    break;
                }
            }
        });
    }
    Ok(child)
}

fn describe_exit(s: std::process::ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (s.code(), s.signal()) {
        (Some(c), _) => format!("exit code {c}"),
        (None, Some(sig)) => format!("signal {sig}"),
        _ => "unknown status".into(),
    }
}

/// `tandem up`: starts the host's nodes, restarts a crashed one with backoff, stops all on
/// SIGINT/SIGTERM, and shows the live table or the events.
pub fn up(cell_path: &Path, o: &UpOptions, out: &mut impl Write) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, o.host.as_deref())?;
    if nodes.is_empty() {
        return Err(Fail(2, "this host has no nodes".into()));
    }
    if let Some(s) = &o.script {
        let src = std::fs::read_to_string(s)
            .map_err(|e| Fail(2, format!("{}: cannot read: {e}", s.display())))?;
        tandem_config::script::parse_cell(&s.display().to_string(), &src, &cell)
            .map_err(|e| Fail(2, e.to_string()))?;
    }
    if let Some(d) = &o.record {
        std::fs::create_dir_all(d).map_err(|e| Fail(2, format!("{}: {e}", d.display())))?;
    }
    rt::install_termination_handler();
    let removed = ipc::cleanup_dead_nodes(&host);
    let iox = cli_node(&cell, "up", &host)?;
    let mut obs = Observer::new(&iox, &cell, &nodes, true)?;
    // Cycle 0 of every node at the next whole second plus one: all start on one grid.
    let epoch = o
        .epoch_ns
        .unwrap_or((rt::now_ns() / 1_000_000_000 + 2) * 1_000_000_000);
    let (tx, rx) = mpsc::channel::<(String, String)>();
    let mut slots: Vec<Slot> = nodes
        .iter()
        .map(|n| Slot {
            node: Some(*n),
            name: cell.nodes[*n].name.clone(),
            child: None,
            restarts: 0,
            backoff: Duration::from_millis(500),
            start_at: Some(Instant::now()),
            started: Instant::now(),
            finished: false,
        })
        .collect();
    if o.gateway {
        slots.push(Slot {
            node: None,
            name: format!("gateway {host}"),
            child: None,
            restarts: 0,
            backoff: Duration::from_millis(500),
            start_at: Some(Instant::now()),
            started: Instant::now(),
            finished: false,
        });
    }
    let _ = writeln!(
        out,
        "tandem up: cell `{}`, {} node(s) on this host: {}{}",
        cell.name,
        nodes.len(),
        nodes
            .iter()
            .map(|n| cell.nodes[*n].name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        if removed > 0 {
            format!("; removed the resources of {removed} crashed process(es)")
        } else {
            String::new()
        }
    );
    let mut messages: VecDeque<String> = VecDeque::new();
    let say = |messages: &mut VecDeque<String>, out: &mut dyn Write, view: bool, line: String| {
        if view {
            messages.push_back(line);
            if messages.len() > 12 {
                messages.pop_front();
            }
        } else {
            let _ = writeln!(out, "{line}");
        }
    };
    let mut last_draw = Instant::now();
    let mut fatal: Option<Fail> = None;
    loop {
        if rt::termination_requested() || fatal.is_some() {
            break;
        }
        for slot in slots.iter_mut() {
            let name = slot.name.clone();
            if let Some(child) = slot.child.as_mut() {
                if let Ok(Some(status)) = child.try_wait() {
                    slot.child = None;
                    if status.success() {
                        slot.finished = true;
                        say(&mut messages, out, o.view, format!("[{name}] finished"));
                    } else if status.code() == Some(2) {
                        fatal = Some(Fail(
                            2,
                            format!(
                                "`{name}` refused its configuration ({})",
                                describe_exit(status)
                            ),
                        ));
                    } else {
                        if slot.started.elapsed() > Duration::from_secs(10) {
                            slot.backoff = Duration::from_millis(500);
                        }
                        say(
                            &mut messages,
                            out,
                            o.view,
                            format!(
                                "[{name}] crashed ({}); restarting in {:.1} s",
                                describe_exit(status),
                                slot.backoff.as_secs_f64()
                            ),
                        );
                        slot.start_at = Some(Instant::now() + slot.backoff);
                        slot.backoff = (slot.backoff * 2).min(Duration::from_secs(10));
                        slot.restarts += 1;
                    }
                }
            } else if let Some(at) = slot.start_at.filter(|at| Instant::now() >= *at) {
                let _ = at;
                slot.start_at = None;
                match spawn(cell_path, &cell, slot, (&host, epoch), o, &tx) {
                    Ok(c) => {
                        say(
                            &mut messages,
                            out,
                            o.view,
                            format!(
                                "[{name}] started, pid {}{}",
                                c.id(),
                                if slot.restarts > 0 {
                                    format!(" (restart {})", slot.restarts)
                                } else {
                                    String::new()
                                }
                            ),
                        );
                        slot.child = Some(c);
                        slot.started = Instant::now();
                    }
                    Err(e) => {
                        let program = if slot.node.is_some() {
                            "tandem-node"
                        } else {
                            "tandem-gateway"
                        };
                        fatal = Some(Fail(
                            4,
                            format!(
                                "cannot start {name} ({}): {e}; build it beside tandem \
                                 (cargo build --release --bins){}",
                                binary(program).display(),
                                if slot.node.is_some() {
                                    ""
                                } else {
                                    ", or run without it: --no-gateway"
                                }
                            ),
                        ));
                    }
                }
            }
        }
        while let Ok((n, line)) = rx.try_recv() {
            say(&mut messages, out, o.view, format!("[{n}] {line}"));
        }
        for (n, e) in obs.events() {
            if e.kind == EVENT_LOG {
                say(
                    &mut messages,
                    out,
                    o.view,
                    format!("[{}] {}", cell.nodes[n].name, e.message.as_str()),
                );
            }
        }
        obs.poll();
        if o.view && last_draw.elapsed() > Duration::from_millis(250) {
            last_draw = Instant::now();
            let _ = write!(out, "\x1b[H\x1b[2J{}", render(&cell, &obs, &nodes, None));
            let _ = writeln!(out, "\nCtrl-C stops the cell. Recent messages:");
            for m in &messages {
                let _ = writeln!(out, "  {m}");
            }
            let _ = out.flush();
        }
        // Done when every node finished (its script or duration ended); the gateway serves them.
        if slots
            .iter()
            .filter(|s| s.node.is_some())
            .all(|s| s.finished)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    // Stop: SIGTERM, then SIGKILL for a node that does not end within 5 s.
    for slot in &slots {
        if let Some(c) = &slot.child {
            let _ = rt::send_signal(c.id(), libc::SIGTERM);
        }
    }
    let deadline = Instant::now() + Duration::from_secs(5);
    for slot in slots.iter_mut() {
        if let Some(c) = slot.child.as_mut() {
            loop {
                match c.try_wait() {
                    Ok(Some(_)) => break,
                    Ok(None) if Instant::now() < deadline => {
                        std::thread::sleep(Duration::from_millis(10))
                    }
                    _ => {
                        let _ = c.kill();
                        let _ = c.wait();
                        break;
                    }
                }
            }
        }
    }
    std::thread::sleep(Duration::from_millis(50));
    while let Ok((n, line)) = rx.try_recv() {
        let _ = writeln!(out, "[{n}] {line}");
    }
    let _ = writeln!(out, "tandem up: all nodes stopped");
    match fatal {
        Some(f) => Err(f),
        None => Ok(()),
    }
}

/// The given endpoints plus every host's listen endpoints from the cell file (with none given
/// and none in the cell: multicast scouting).
fn with_cell_endpoints(cell: &Cell, given: &[String]) -> Vec<String> {
    let mut all: Vec<String> = given.to_vec();
    for e in cell.host_listen.iter().flatten() {
        if !all.contains(e) {
            all.push(e.clone());
        }
    }
    all
}

fn runtime() -> Result<tokio::runtime::Runtime, Fail> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| Fail(4, format!("cannot start the async runtime: {e}")))
}

fn client_fail(e: tandem_client::ClientError) -> Fail {
    use tandem_client::ClientError as E;
    let code = match &e {
        E::Rejected { .. } | E::JobFailed { .. } => 1,
        E::Invalid(_) => 2,
        E::Timeout { .. } | E::Unreachable(_) => 3,
        E::Zenoh(_) | E::Malformed(_) => 4,
    };
    Fail(code, e.to_string())
}

/// `tandem cmd --zenoh`: the same over Zenoh, through the cell's gateways, from any machine.
#[allow(clippy::too_many_arguments)]
pub fn cmd_zenoh(
    cell_path: &Path,
    endpoints: &[String],
    target: &str,
    instruction: &str,
    params: &[(String, String)],
    wait: bool,
    timeout: Duration,
    out: &mut impl Write,
) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    let (node, object) = target.split_once('/').ok_or_else(|| {
        Fail(
            2,
            format!("`{target}`: address an object as <node>/<object>"),
        )
    })?;
    // Check it here first, for an error message without a round trip.
    tandem_config::script::parse_command(&cell, object, instruction, params)
        .map_err(|m| Fail(2, m))?;
    let mut line = instruction.to_string();
    for (k, v) in params {
        line.push_str(&format!(" --{k} {v}"));
    }
    runtime()?.block_on(async {
        let c = tandem_client::Client::connect(&cell.name, &with_cell_endpoints(&cell, endpoints))
            .await
            .map_err(client_fail)?;
        let result = if wait {
            c.execute(node, object, &line, timeout).await.map(|o| {
                let _ = writeln!(out, "{target} {instruction}: accepted, job {}", o.job);
                for e in &o.events {
                    let _ = writeln!(
                        out,
                        "t={} {}",
                        tandem_runtime::exec::Secs(e.t_ns),
                        e.message
                    );
                }
            })
        } else {
            c.command(node, object, &line, timeout).await.map(|a| {
                let _ = writeln!(
                    out,
                    "{target} {instruction}: accepted, job {} at t={}",
                    a.job,
                    tandem_runtime::exec::Secs(a.t_ns)
                );
            })
        };
        let _ = c.close().await;
        result.map_err(client_fail)
    })
}

/// `tandem status --zenoh`: every axis of every host, from the gateways' telemetry.
pub fn status_zenoh(
    cell_path: &Path,
    endpoints: &[String],
    out: &mut impl Write,
) -> Result<(), Fail> {
    let cell = load(cell_path)?;
    runtime()?.block_on(async {
        let c = tandem_client::Client::connect(&cell.name, &with_cell_endpoints(&cell, endpoints))
            .await
            .map_err(client_fail)?;
        let window = Duration::from_secs_f64((3.0 / cell.telemetry_hz).max(0.3));
        let states = c.states(window).await.map_err(client_fail)?;
        let hosts = c
            .alive_hosts(Duration::from_secs(2))
            .await
            .map_err(client_fail)?;
        let _ = c.close().await;
        let _ = writeln!(
            out,
            "hosts alive: {}",
            if hosts.is_empty() {
                "none".to_string()
            } else {
                hosts.join(", ")
            }
        );
        let _ = writeln!(out, "{HEADER}");
        for a in &states {
            let sync = if a.sync == "none" {
                "-"
            } else {
                a.sync.as_str()
            };
            let row = table_row(
                &a.node,
                &a.axis,
                &a.state,
                (a.position, a.velocity),
                sync,
                a.alarm,
                a.job,
            );
            let _ = writeln!(out, "{row}");
        }
        let missing: Vec<&str> = cell
            .hosts
            .iter()
            .filter(|h| !hosts.contains(h))
            .map(String::as_str)
            .collect();
        if missing.is_empty() {
            Ok(())
        } else {
            Err(Fail(
                3,
                format!("hosts not reachable: {}", missing.join(", ")),
            ))
        }
    })
}
