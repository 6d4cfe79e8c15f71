//! `tandem up`: starts this host's nodes (and its gateway) of a cell, restarts a crashed one
//! with backoff, stops them all on SIGINT/SIGTERM, and shows the live table or the events.
//!
//! Its stages: `prepare` loads and checks the cell, script and recording directory; a
//! `Supervisor` starts the processes, watches them and restarts a crashed one (doubling its
//! backoff up to 10 s, back to 0.5 s after 10 s of running), relays their output, and stops
//! them (SIGTERM, then SIGKILL after 5 s). What the supervision does is a `tracing` event (in
//! the span `up` with the cell and host, and `node` per process); the live view also lists it.

use crate::error::{describe_exit, CliError};
use crate::live::{cli_node, host_nodes, load, render, Observer};
use std::collections::VecDeque;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tandem_config::Cell;
use tandem_protocol::ipc;
use tandem_protocol::wire::EVENT_LOG;
use tandem_rt as rt;
use tandem_rt::diag::LogFormat;
use tracing::{info, info_span, warn};

/// The first restart delay of a crashed process, and the delay again after it ran 10 s.
const FIRST_BACKOFF: Duration = Duration::from_millis(500);
/// The longest restart delay.
const MAX_BACKOFF: Duration = Duration::from_secs(10);
/// How many messages the live view lists.
const VIEW_MESSAGES: usize = 12;

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
    /// The diagnostics format, passed on to the gateway.
    pub log_format: LogFormat,
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
    /// The watchdog reported this process stalled (once per stall).
    stall_reported: bool,
    /// The watchdog killed it (kill -9) to restart it.
    watchdog_killed: bool,
    /// The gateway: the cell clock time it was last seen not stopped.
    gateway_alive_ns: i64,
}

impl Slot {
    fn new(node: Option<usize>, name: String) -> Self {
        Self {
            node,
            name,
            child: None,
            restarts: 0,
            backoff: FIRST_BACKOFF,
            start_at: Some(Instant::now()),
            started: Instant::now(),
            finished: false,
            stall_reported: false,
            watchdog_killed: false,
            gateway_alive_ns: rt::now_ns(),
        }
    }
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

/// What every process of the set is started with.
struct Launch<'a> {
    cell_path: &'a Path,
    cell: &'a Cell,
    host: &'a str,
    /// The cell clock's time of cycle 0 (ns).
    epoch: i64,
    o: &'a UpOptions,
}

impl Launch<'_> {
    /// Passes `up`'s `--log-format json` on to a node or the gateway (text is their default).
    fn log_format(&self, c: &mut std::process::Command) {
        if self.o.log_format == LogFormat::Json {
            c.arg("--log-format").arg("json");
        }
    }

    /// The command line of `slot`'s program.
    fn command(&self, slot: &Slot) -> std::process::Command {
        let Some(node) = slot.node else {
            let mut c = std::process::Command::new(binary("tandem-gateway"));
            c.arg(self.cell_path).arg("--host").arg(self.host);
            self.log_format(&mut c);
            return c;
        };
        let mut c = std::process::Command::new(binary("tandem-node"));
        self.log_format(&mut c);
        c.arg(self.cell_path)
            .arg("--node")
            .arg(&self.cell.nodes[node].name)
            .arg("--epoch-ns")
            .arg(self.epoch.to_string());
        if let Some(s) = &self.o.script {
            c.arg("--script").arg(s);
        }
        if let Some(d) = self.o.duration_s {
            c.arg("--duration").arg(d.to_string());
        }
        if let Some(dir) = &self.o.record {
            let name = &slot.name;
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
        c
    }
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
    // When `up` dies (even by kill -9) its processes get SIGTERM and stop: no unsupervised set
    // is left to run beside the next `up`'s. `up` spawns from its main thread, which lives as
    // long as the supervision.
    rt::die_with_parent(&mut c);
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

/// Loads the cell and checks what `up` is given before anything starts: the host has nodes,
/// the script parses, the recording directory exists. Returns the cell, the host's name and
/// its nodes.
fn prepare(cell_path: &Path, o: &UpOptions) -> Result<(Cell, String, Vec<usize>), CliError> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, o.host.as_deref())?;
    if nodes.is_empty() {
        return Err(CliError::NoNodesHere);
    }
    if let Some(s) = &o.script {
        tandem_config::script::load(s, &cell)?;
    }
    if let Some(d) = &o.record {
        std::fs::create_dir_all(d).map_err(|source| CliError::RecordDir {
            path: d.clone(),
            source,
        })?;
    }
    Ok((cell, host, nodes))
}

/// `tandem up`: starts the host's nodes, restarts a crashed one with backoff, stops all on
/// SIGINT/SIGTERM, and shows the live table or the events.
pub fn up(cell_path: &Path, o: &UpOptions, out: &mut impl Write) -> Result<(), CliError> {
    let (cell, host, nodes) = prepare(cell_path, o)?;
    let span = info_span!("up", cell = %cell.name, host = %host);
    let _entered = span.enter();
    // One supervisor per cell and host, for as long as this `up` runs.
    let _lock = lock(&cell, &host)?;
    rt::install_termination_handler();
    warn_if_shm_small(out);
    let removed = ipc::cleanup_dead_nodes(&host);
    let iox = cli_node(&cell, "up", &host)?;
    let obs = Observer::new(&iox, &cell, &nodes, true)?;
    // Cycle 0 of every node at the next whole second plus one: all start on one grid.
    let epoch = o
        .epoch_ns
        .unwrap_or((rt::now_ns() / 1_000_000_000 + 2) * 1_000_000_000);
    outln!(
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
    if o.gateway {
        warn_if_plain(&cell, &host, out);
    }
    let launch = Launch {
        cell_path,
        cell: &cell,
        host: &host,
        epoch,
        o,
    };
    let mut s = Supervisor::new(launch, &nodes, obs);
    let result = s.supervise(out);
    s.stop(out);
    outln!(out, "tandem up: all nodes stopped");
    result
}

/// The lock file of the supervisor of `cell` on `host`: `<retain_dir>/<cell>/<host>.up.lock`.
pub fn lock_path(cell: &Cell, host: &str) -> PathBuf {
    cell.retain_dir
        .join(&cell.name)
        .join(format!("{host}.up.lock"))
}

/// Takes the supervisor's lock of `cell` on `host` (held until it is dropped or `up` ends, also
/// by kill -9), or the error naming the `up` that holds it.
fn lock(cell: &Cell, host: &str) -> Result<rt::RunLock, CliError> {
    let path = lock_path(cell, host);
    rt::RunLock::acquire(&path).map_err(|e| match e {
        rt::LockError::Held { pid } => CliError::AlreadySupervised {
            cell: cell.name.clone(),
            host: host.to_string(),
            path: path.clone(),
            pid,
        },
        rt::LockError::Io { .. } => CliError::Lock {
            path: path.clone(),
            source: e,
        },
    })
}

/// Where iceoryx2 keeps its shared memory.
const SHM: &str = "/dev/shm";

/// The free space of /dev/shm below which `up` warns at start: 16 MiB. Measured: the three
/// nodes of the bundled line cell and `up` map 11.5 MB of iceoryx2 segments there (sparse
/// files; 0.8 MB of pages touched after a few seconds), and a node dies of SIGBUS when it
/// touches a page the file system cannot give (docs/processes.md, "Shared memory").
const SHM_WARN_BYTES: u64 = 16 << 20;

/// The free space of /dev/shm in MB, for messages ("?" when it cannot be read).
fn shm_free_mb() -> String {
    rt::free_bytes(Path::new(SHM)).map_or("?".into(), |b| format!("{:.1}", b as f64 / 1e6))
}

/// Warns when /dev/shm has less free space than [`SHM_WARN_BYTES`]: iceoryx2's shared memory
/// then fails to be created, or a process dies of SIGBUS when it first touches a page.
fn warn_if_shm_small(out: &mut impl Write) {
    let Some(free) = rt::free_bytes(Path::new(SHM)) else {
        return;
    };
    if free < SHM_WARN_BYTES {
        let line = format!(
            "WARNING: {SHM} has only {:.1} MB free (at least {} MB recommended): iceoryx2's \
             shared memory may not fit, and a node then dies of SIGBUS (docs/processes.md, \
             \"Shared memory\")",
            free as f64 / 1e6,
            SHM_WARN_BYTES >> 20
        );
        warn!("{line}");
        outln!(out, "{line}");
    }
}

/// Warns (on stdout and as a `tracing` warning) when the cell's Zenoh is plain,
/// unauthenticated: on every start, so it is never forgotten (docs/security.md).
fn warn_if_plain(cell: &Cell, host: &str, out: &mut impl Write) {
    if cell.security.mode != tandem_config::SecurityMode::Plain {
        return;
    }
    let h = cell.hosts.iter().position(|x| x == host).unwrap_or(0);
    let listen = cell.host_listen.get(h).cloned().unwrap_or_default();
    let why = if cell.security.declared {
        "[security] mode = \"plain\""
    } else {
        "no [security] in the cell file"
    };
    let reach = if listen.is_empty() {
        "it listens on no endpoint".to_string()
    } else {
        format!(
            "anyone who reaches {} may observe, command and publish leading values",
            listen.join(", ")
        )
    };
    warn!(
        mode = "plain",
        "plain, unauthenticated Zenoh ({why}): {reach}; see docs/security.md for mTLS"
    );
    outln!(
        out,
        "WARNING: the gateway of host `{host}` runs plain, unauthenticated Zenoh ({why}): {reach}. Use [security] mode = \"mtls\" (docs/security.md)"
    );
}

/// The processes of `up` and what it shows of them.
struct Supervisor<'a> {
    launch: Launch<'a>,
    nodes: &'a [usize],
    slots: Vec<Slot>,
    obs: Observer,
    /// The processes' stderr lines: (name, line).
    tx: mpsc::Sender<(String, String)>,
    rx: mpsc::Receiver<(String, String)>,
    /// The live view's recent messages.
    messages: VecDeque<String>,

    last_draw: Instant,
}

impl<'a> Supervisor<'a> {
    /// A slot per node of the host, and one for the gateway unless `--no-gateway`.
    fn new(launch: Launch<'a>, nodes: &'a [usize], obs: Observer) -> Self {
        let mut slots: Vec<Slot> = nodes
            .iter()
            .map(|n| Slot::new(Some(*n), launch.cell.nodes[*n].name.clone()))
            .collect();
        if launch.o.gateway {
            slots.push(Slot::new(None, format!("gateway {}", launch.host)));
        }
        let (tx, rx) = mpsc::channel();
        Self {
            launch,
            nodes,
            slots,
            obs,
            tx,
            rx,
            messages: VecDeque::new(),
            last_draw: Instant::now(),
        }
    }

    /// Starts, watches and restarts the processes until SIGINT/SIGTERM, until every node
    /// finished (its script or duration ended; the gateway serves them), or until one refused
    /// its configuration or could not be started (the error).
    fn supervise(&mut self, out: &mut impl Write) -> Result<(), CliError> {
        while !rt::termination_requested() {
            self.obs.poll();
            for i in 0..self.slots.len() {
                self.tend(i)?;
            }
            self.relay(out);
            if self.launch.o.view && self.last_draw.elapsed() > Duration::from_millis(250) {
                self.last_draw = Instant::now();
                self.draw(out);
            }
            if self
                .slots
                .iter()
                .filter(|s| s.node.is_some())
                .all(|s| s.finished)
            {
                break;
            }
            std::thread::sleep(self.next_look());
        }
        Ok(())
    }

    /// How long to sleep before looking again: 20 ms, or less when a watchdog deadline comes
    /// sooner (so that a stall is reported within a few ms of the watchdog time).
    fn next_look(&self) -> Duration {
        let cell = self.launch.cell;
        let now = rt::now_ns();
        let soonest = (0..self.slots.len())
            .filter_map(|i| {
                let slot = self.slots.get(i)?;
                let last = self.last_cycle(i)?;
                let after = if !slot.stall_reported {
                    cell.watchdog_ns
                } else if !slot.watchdog_killed {
                    cell.watchdog_restart_ns
                } else {
                    return None;
                };
                Some(last.saturating_add(after).saturating_sub(now))
            })
            .min()
            .unwrap_or(i64::MAX);
        Duration::from_nanos(soonest.clamp(1_000_000, 20_000_000) as u64)
    }

    /// The cell clock time process `i` was last seen alive: for a node, its last cycle
    /// published (if it published since it was started); for the gateway, which publishes no
    /// cycle on iceoryx2, the last time its process was not stopped (`/proc/<pid>/stat`).
    fn last_cycle(&self, i: usize) -> Option<i64> {
        let slot = self.slots.get(i)?;
        let pid = slot.child.as_ref()?.id();
        let Some(node) = slot.node else {
            return Some(slot.gateway_alive_ns);
        };
        let h = self.obs.health(node).filter(|h| h.pid == pid)?;
        Some(h.epoch_ns.saturating_add(h.t_ns))
    }

    /// The watchdog of process `i`: reports it stalled once its last cycle is
    /// `[cell] watchdog_ms` old, kills it (kill -9, to be restarted as a crashed one) once it is
    /// `watchdog_restart_ms` old, and reports it cycling again when it resumed before.
    fn watch(&mut self, i: usize) {
        if let Some(slot) = self.slots.get_mut(i).filter(|s| s.node.is_none()) {
            let pid = slot.child.as_ref().map(Child::id);
            if pid.is_some_and(|p| !stopped(p)) {
                slot.gateway_alive_ns = rt::now_ns();
            }
        }
        let Some(last) = self.last_cycle(i) else {
            return;
        };
        let cell = self.launch.cell;
        let silent = rt::now_ns().saturating_sub(last);
        let t = last.saturating_sub(self.launch.epoch);
        let slot = &mut self.slots[i];
        let name = slot.name.clone();
        let ms = |ns: i64| ns as f64 / 1e6;
        let mut lines = Vec::new();
        if silent > cell.watchdog_ns && !slot.stall_reported {
            slot.stall_reported = true;
            let what = if slot.node.is_some() {
                "no cycle"
            } else {
                "stopped"
            };
            let line = format!(
                "[{name}] stalled: {what} since t={} ({:.1} ms ago; watchdog {:.0} ms)",
                tandem_runtime::exec::Secs(t),
                ms(silent),
                ms(cell.watchdog_ns)
            );
            warn!(silent_ms = ms(silent), "{line}");
            lines.push(line);
        }
        if silent > cell.watchdog_restart_ns && !slot.watchdog_killed {
            slot.watchdog_killed = true;
            let line = format!(
                "[{name}] silent for {:.1} ms (watchdog_restart_ms {:.0}): killing it (kill -9) to restart it",
                ms(silent),
                ms(cell.watchdog_restart_ns)
            );
            warn!("{line}");
            if let Some(c) = slot.child.as_mut() {
                if let Err(e) = c.kill() {
                    // It ended meanwhile: `tend` collects it and restarts it.
                    tracing::debug!(node = %name, error = %e, "SIGKILL");
                }
            }
            lines.push(line);
        }
        if silent <= cell.watchdog_ns && slot.stall_reported && !slot.watchdog_killed {
            slot.stall_reported = false;
            let line = format!(
                "[{name}] {} again at t={}",
                if slot.node.is_some() {
                    "cycling"
                } else {
                    "running"
                },
                tandem_runtime::exec::Secs(t)
            );
            info!("{line}");
            lines.push(line);
        }
        for line in lines {
            self.note(line);
        }
    }

    /// Lists `line` in the live view (a supervision event, already given to `tracing`).
    fn note(&mut self, line: String) {
        if self.launch.o.view {
            self.messages.push_back(line);
            if self.messages.len() > VIEW_MESSAGES {
                self.messages.pop_front();
            }
        }
    }

    /// Shows `line` of a process or node: in the live view, else as a line of output.
    fn say(&mut self, out: &mut impl Write, line: String) {
        if self.launch.o.view {
            self.note(line);
        } else {
            outln!(out, "{line}");
        }
    }

    /// Looks after process `i`: notes how a running one ended, starts one that is due.
    fn tend(&mut self, i: usize) -> Result<(), CliError> {
        let span = info_span!("node", node = %self.slots[i].name);
        let _entered = span.enter();
        let slot = &mut self.slots[i];
        if let Some(child) = slot.child.as_mut() {
            if let Ok(Some(status)) = child.try_wait() {
                slot.child = None;
                return self.ended(i, status);
            }
            self.watch(i);
        } else if slot.start_at.is_some_and(|at| Instant::now() >= at) {
            slot.start_at = None;
            return self.spawn(i);
        }
        Ok(())
    }

    /// Process `i` ended with `status`: finished, refused its configuration (exit code 2: the
    /// error), or crashed (restarted after its backoff).
    fn ended(&mut self, i: usize, status: std::process::ExitStatus) -> Result<(), CliError> {
        let slot = &mut self.slots[i];
        let name = slot.name.clone();
        if status.success() {
            slot.finished = true;
            let line = format!("[{name}] finished");
            info!("{line}");
            self.note(line);
            return Ok(());
        }
        if status.code() == Some(2) {
            return Err(CliError::Refused { name, status });
        }
        if slot.started.elapsed() > MAX_BACKOFF {
            slot.backoff = FIRST_BACKOFF;
        }
        let reason = if slot.watchdog_killed {
            "killed by the watchdog after a stall".to_string()
        } else if std::os::unix::process::ExitStatusExt::signal(&status) == Some(libc::SIGBUS) {
            format!(
                "SIGBUS: {SHM} is probably too small (free {} MB)",
                shm_free_mb()
            )
        } else {
            describe_exit(status)
        };
        let line = format!(
            "[{name}] crashed ({reason}); restarting in {:.1} s",
            slot.backoff.as_secs_f64()
        );
        warn!(reason = %reason, restarts = slot.restarts, "{line}");
        slot.start_at = Some(Instant::now() + slot.backoff);
        slot.backoff = (slot.backoff * 2).min(MAX_BACKOFF);
        slot.restarts += 1;
        self.note(line);
        Ok(())
    }

    /// Starts process `i`.
    fn spawn(&mut self, i: usize) -> Result<(), CliError> {
        let slot = &self.slots[i];
        let command = self.launch.command(slot);
        let program = PathBuf::from(command.get_program());
        let child =
            start(command, &slot.name, &self.tx).map_err(|source| CliError::CannotStart {
                name: slot.name.clone(),
                program,
                gateway: slot.node.is_none(),
                source,
            })?;
        let line = format!(
            "[{}] started, pid {}{}",
            slot.name,
            child.id(),
            if slot.restarts > 0 {
                format!(" (restart {})", slot.restarts)
            } else {
                String::new()
            }
        );
        info!(pid = child.id(), restarts = slot.restarts, "{line}");
        let slot = &mut self.slots[i];
        slot.child = Some(child);
        slot.started = Instant::now();
        slot.stall_reported = false;
        slot.watchdog_killed = false;
        slot.gateway_alive_ns = rt::now_ns();
        self.note(line);
        Ok(())
    }

    /// Shows the processes' stderr lines and the nodes' log lines since the last call.
    fn relay(&mut self, out: &mut impl Write) {
        while let Ok((n, line)) = self.rx.try_recv() {
            self.say(out, format!("[{n}] {line}"));
        }
        for (n, e) in self.obs.events() {
            if e.kind == EVENT_LOG {
                let line = format!(
                    "[{}] {}",
                    self.launch.cell.nodes[n].name,
                    e.message.as_str()
                );
                self.say(out, line);
            }
        }
    }

    /// Draws the live view: the axis table and the recent messages.
    fn draw(&self, out: &mut impl Write) {
        out!(
            out,
            "\x1b[H\x1b[2J{}",
            render(self.launch.cell, &self.obs, self.nodes, None)
        );
        outln!(out, "\nCtrl-C stops the cell. Recent messages:");
        for m in &self.messages {
            outln!(out, "  {m}");
        }
        crate::output::flush(out);
    }

    /// Stops every process: SIGTERM, then SIGKILL for one that does not end within 5 s; then
    /// prints their last lines.
    fn stop(&mut self, out: &mut impl Write) {
        for slot in &self.slots {
            if let Some(c) = &slot.child {
                if let Err(e) = rt::send_signal(c.id(), libc::SIGTERM) {
                    // It ended on its own meanwhile; the wait below collects it.
                    tracing::debug!(node = %slot.name, error = %e, "SIGTERM");
                }
            }
        }
        let deadline = Instant::now() + Duration::from_secs(5);
        for slot in self.slots.iter_mut() {
            if let Some(c) = slot.child.as_mut() {
                wait_or_kill(c, deadline, &slot.name);
            }
        }
        std::thread::sleep(Duration::from_millis(50));
        while let Ok((n, line)) = self.rx.try_recv() {
            outln!(out, "[{n}] {line}");
        }
    }
}

/// Whether process `pid` is stopped (SIGSTOP, a debugger: state `T` or `t` in
/// `/proc/<pid>/stat`); `false` when that cannot be read.
fn stopped(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .ok()
        .and_then(|s| {
            // The state follows the command name, which ends with the last ')'.
            let rest = s.get(s.rfind(')')? + 1..)?;
            rest.split_whitespace().next().map(|x| x == "T" || x == "t")
        })
        .unwrap_or(false)
}

/// Waits for `c` until `deadline`, then kills it.
fn wait_or_kill(c: &mut Child, deadline: Instant, name: &str) {
    loop {
        match c.try_wait() {
            Ok(Some(_)) => return,
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(10)),
            _ => {
                warn!(node = %name, "did not stop within 5 s of SIGTERM: killed");
                if let Err(e) = c.kill() {
                    tracing::debug!(node = %name, error = %e, "SIGKILL");
                }
                if let Err(e) = c.wait() {
                    tracing::debug!(node = %name, error = %e, "waiting after SIGKILL");
                }
                return;
            }
        }
    }
}
