//! tandem-node: one node of a cell as a process (design §3).
//!
//! The main thread is the cyclic executive. Cycle `k` starts at `epoch + k * T` on the cell
//! clock (CLOCK_REALTIME), so nodes with the same cycle on a host are phase-aligned; the engine
//! time of the cycle is `k * T`. Inside a cycle, in this order: read the leading values other
//! nodes published, apply queued commands and due script entries, step the technology objects,
//! publish this node's leading values, output edges, measured values and events, publish the
//! telemetry snapshot and record compute time and wake-up lateness. Nothing there allocates,
//! locks, logs to a file or blocks: commands arrive through a bounded queue from the command
//! thread, log lines go into a fixed ring and out as iceoryx2 events, trace rows go to the
//! recorder thread through a fixed pool.

use tandem_rt as rt;

use std::collections::VecDeque;
use std::io::{self, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::Arc;
use std::time::Duration;
use tandem_config::script::{split_command, ScriptEntry};
use tandem_config::{AxisIndex, Cell, Coupling, Leader};
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::AxisStatus;
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::names;
use tandem_protocol::wire::{
    job_code, AxisTelemetry, CommandReply, Event, IoEvent, LeadingValueSample, NodeHealth, Text,
    EVENT_JOB, EVENT_LOG, IO_MEASURED, IO_OUTPUT, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID,
    OUTCOME_REJECTED,
};
use tandem_runtime::exec::{Executive, Secs};
use tandem_runtime::sim::AXIS_COLUMNS;

/// How a node is started.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// The cell file.
    pub cell: PathBuf,
    /// The node's name in the cell.
    pub node: String,
    /// The cell clock's time of cycle 0 (ns); default: the next whole second.
    pub epoch_ns: Option<i64>,
    /// A script whose entries for this node's objects are applied at their times.
    pub script: Option<PathBuf>,
    /// Stop after this much engine time (s); default: the script's duration, else never.
    pub duration_s: Option<f64>,
    /// Write every cycle of the node's axes to this CSV file (the columns of `tandem sim`).
    pub trace: Option<PathBuf>,
    /// Write the node's log (job events, alarms, edges, measured values) to this file.
    pub log: Option<PathBuf>,
}

/// Lines the log ring holds between two cycles.
const LOG_LINES: usize = 128;

/// The cyclic thread's log: lines formatted into fixed buffers, published after the step.
struct LogRing {
    line: Vec<u8>,
    lines: VecDeque<Text>,
    dropped: u64,
}

impl LogRing {
    fn new() -> Self {
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

/// A command from the command thread: its id, what to apply.
struct Queued {
    id: u64,
    entry: ScriptEntry,
}

/// The result for command `id`.
struct Done {
    id: u64,
    reply: CommandReply,
}

/// Histogram of durations in 1 µs bins up to 50 ms (the last bin holds the rest).
#[derive(Debug, Clone)]
pub struct Histogram {
    bins: Vec<u32>,
    count: u64,
    max_ns: i64,
}

impl Default for Histogram {
    fn default() -> Self {
        Self {
            bins: vec![0; 50_001],
            count: 0,
            max_ns: 0,
        }
    }
}

impl Histogram {
    /// Records one duration.
    pub fn record(&mut self, ns: i64) {
        let i = usize::try_from(ns.max(0) / 1000)
            .unwrap_or(usize::MAX)
            .min(self.bins.len() - 1);
        self.bins[i] = self.bins[i].saturating_add(1);
        self.count += 1;
        self.max_ns = self.max_ns.max(ns);
    }

    /// The `q` quantile (0..=1) in µs (upper bin edge), or the max for `q = 1`.
    pub fn quantile_us(&self, q: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        if q >= 1.0 {
            return self.max_ns as f64 / 1000.0;
        }
        let target = (q * self.count as f64).ceil().max(1.0) as u64;
        let mut seen = 0u64;
        for (i, b) in self.bins.iter().enumerate() {
            seen += u64::from(*b);
            if seen >= target {
                return (i + 1) as f64;
            }
        }
        self.max_ns as f64 / 1000.0
    }

    /// Values recorded.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// `p50/p99/p99.9/max` in µs.
    pub fn summary(&self) -> String {
        format!(
            "p50 {:.0} / p99 {:.0} / p99.9 {:.0} / max {:.1} µs",
            self.quantile_us(0.5),
            self.quantile_us(0.99),
            self.quantile_us(0.999),
            self.quantile_us(1.0)
        )
    }
}

/// What a node run measured.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Cycles run.
    pub cycles: u64,
    /// Cycles that ended after the next one should have started.
    pub overruns: u64,
    /// Compute time per cycle.
    pub compute: Histogram,
    /// Wake-up lateness per cycle.
    pub lateness: Histogram,
    /// Wall time the cyclic thread ran (ns) and the CPU time it used (ns).
    pub wall_ns: i64,
    /// CPU time of the whole process over the run (ns).
    pub cpu_ns: i64,
    /// Resident memory at the end (bytes).
    pub resident_bytes: u64,
}

fn cpu_time_ns() -> i64 {
    // The process' user + system time, from /proc/self/stat (clock ticks).
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0;
    };
    let after = s.rsplit_once(')').map_or("", |x| x.1);
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks: i64 = f.get(11).and_then(|x| x.parse().ok()).unwrap_or(0)
        + f.get(12).and_then(|x| x.parse().ok()).unwrap_or(0);
    ticks * 10_000_000
}

/// Runs the node until SIGINT/SIGTERM or the end of its duration.
pub fn run(o: &Options) -> Result<Report, String> {
    let cell = Arc::new(tandem_config::load(&o.cell).map_err(|e| e.to_string())?);
    let n = cell.node(&o.node).ok_or_else(|| {
        let names: Vec<&str> = cell.nodes.iter().map(|x| x.name.as_str()).collect();
        format!(
            "{}: no node `{}`; the cell has: {}",
            o.cell.display(),
            o.node,
            names.join(", ")
        )
    })?;
    let script = match &o.script {
        Some(p) => {
            let src = std::fs::read_to_string(p)
                .map_err(|e| format!("{}: cannot read: {e}", p.display()))?;
            Some(
                tandem_config::script::parse_cell(&p.display().to_string(), &src, &cell)
                    .map_err(|e| e.to_string())?,
            )
        }
        None => None,
    };
    let end_ns = o
        .duration_s
        .map(|d| (d * 1e9) as i64)
        .or(script.as_ref().map(|s| s.duration_ns));
    rt::install_termination_handler();
    let rtc = cell.nodes[n].realtime;
    if rtc.lock_memory {
        if let Err(w) = rt::lock_memory() {
            eprintln!("tandem-node {}: warning: {w}", o.node);
        }
    }
    let host = &cell.hosts[cell.nodes[n].host];
    let cleaned = ipc::cleanup_dead_nodes(host);
    if cleaned > 0 {
        eprintln!(
            "tandem-node {}: removed the resources of {cleaned} crashed process(es)",
            o.node
        );
    }
    let stop = Arc::new(AtomicBool::new(false));
    let (cmd_tx, cmd_rx) = sync_channel::<Queued>(32);
    let (done_tx, done_rx) = sync_channel::<Done>(64);
    let commands = {
        let (cell, stop, node) = (Arc::clone(&cell), Arc::clone(&stop), o.node.clone());
        std::thread::Builder::new()
            .name("commands".into())
            .spawn(move || command_thread(&cell, &node, &stop, &cmd_tx, &done_rx))
            .map_err(|e| format!("cannot start the command thread: {e}"))?
    };
    let owned: Vec<usize> = (0..cell.axes.len())
        .filter(|i| cell.axes[*i].node == n)
        .collect();
    let (free_tx, free_rx) = sync_channel::<(i64, Vec<AxisStatus>)>(256);
    let (row_tx, row_rx) = sync_channel::<(i64, Vec<AxisStatus>)>(256);
    let recorder = if o.trace.is_some() || o.log.is_some() {
        // Trace rows only when a trace is written.
        for _ in 0..if o.trace.is_some() { 256 } else { 0 } {
            let _ = free_tx.try_send((0, Vec::with_capacity(owned.len())));
        }
        let (cell, stop, opts, owned) = (
            Arc::clone(&cell),
            Arc::clone(&stop),
            o.clone(),
            owned.clone(),
        );
        Some(
            std::thread::Builder::new()
                .name("recorder".into())
                .spawn(move || recorder_thread(&cell, &opts, &owned, &stop, &row_rx, &free_tx))
                .map_err(|e| format!("cannot start the recorder thread: {e}"))?,
        )
    } else {
        None
    };
    let result = cyclic(
        &cell,
        n,
        o,
        script.as_ref().map(|s| s.entries.as_slice()).unwrap_or(&[]),
        end_ns,
        &owned,
        &cmd_rx,
        &done_tx,
        (&free_rx, &row_tx, o.trace.is_some()),
    );
    stop.store(true, Ordering::SeqCst);
    let _ = commands.join();
    if let Some(r) = recorder {
        let _ = r.join();
    }
    let mut report = result?;
    report.resident_bytes = rt::resident_bytes().unwrap_or(0);
    Ok(report)
}

type Pool<'a> = (
    &'a Receiver<(i64, Vec<AxisStatus>)>,
    &'a SyncSender<(i64, Vec<AxisStatus>)>,
    bool,
);

/// The cyclic executive.
#[allow(clippy::too_many_arguments)]
fn cyclic(
    cell: &Cell,
    n: usize,
    o: &Options,
    script: &[ScriptEntry],
    end_ns: Option<i64>,
    owned: &[usize],
    cmd_rx: &Receiver<Queued>,
    done_tx: &SyncSender<Done>,
    pool: Pool<'_>,
) -> Result<Report, String> {
    let me = &cell.nodes[n];
    let host = &cell.hosts[me.host];
    let iox = ipc::node(&names::node(&cell.name, &me.name), host).map_err(|e| e.to_string())?;
    let mut exec = Executive::new(cell, Some(n)).map_err(|e| e.to_string())?;
    let history = |l: Leader| cell.leading_history(l);
    let names_of = cell.object_names();
    // Leading values this node publishes: the leaders here that followers elsewhere name.
    let mut publish = Vec::new();
    for f in cell.axes.iter().filter(|a| a.node != n) {
        for (l, c) in f.leaders.iter().flatten() {
            let c = if l.is_encoder() {
                Coupling::Setpoint
            } else {
                *c
            };
            if cell.leader_node(*l) == Some(n) && !publish.iter().any(|(x, y, _)| x == l && *y == c)
            {
                let svc = ipc::leading_values(
                    &iox,
                    &cell.name,
                    cell.leader_name(*l),
                    c == Coupling::Actual,
                    history(*l),
                )
                .map_err(|e| e.to_string())?;
                let p = svc
                    .publisher_builder()
                    .create()
                    .map_err(|e| format!("publisher for {}: {e}", cell.leader_name(*l)))?;
                publish.push((*l, c, p));
            }
        }
    }
    // Leading values of other nodes' leaders that followers here read.
    let mut subscribe = Vec::new();
    let remote: Vec<(Leader, Coupling)> = exec.remote_leaders().collect();
    for (l, c) in remote {
        let svc = ipc::leading_values(
            &iox,
            &cell.name,
            cell.leader_name(l),
            c == Coupling::Actual,
            history(l),
        )
        .map_err(|e| e.to_string())?;
        let s = svc
            .subscriber_builder()
            .buffer_size(history(l))
            .create()
            .map_err(|e| format!("subscriber for {}: {e}", cell.leader_name(l)))?;
        subscribe.push((l, c, s));
    }
    // A gateway waits on this event to forward the leading values at once.
    let published = if publish.is_empty() {
        None
    } else {
        let svc = ipc::published(&iox, &cell.name, &me.name).map_err(|e| e.to_string())?;
        Some(
            svc.notifier_builder()
                .create()
                .map_err(|e| format!("published notifier: {e}"))?,
        )
    };
    let telemetry = ipc::telemetry(&iox, &cell.name, &me.name).map_err(|e| e.to_string())?;
    let telemetry = telemetry
        .publisher_builder()
        .initial_max_slice_len(owned.len().max(1))
        .create()
        .map_err(|e| format!("telemetry publisher: {e}"))?;
    let events = ipc::events(&iox, &cell.name, &me.name).map_err(|e| e.to_string())?;
    let events = events
        .publisher_builder()
        .max_loaned_samples(4)
        .create()
        .map_err(|e| format!("event publisher: {e}"))?;
    let io_objects: Vec<(&str, AxisIndex)> = cell
        .output_cams
        .iter()
        .map(|c| (c.name.as_str(), c.axis))
        .chain(cell.cam_tracks.iter().map(|c| (c.name.as_str(), c.axis)))
        .chain(
            cell.measuring_inputs
                .iter()
                .map(|c| (c.name.as_str(), c.axis)),
        )
        .collect();
    let mut io_pubs = Vec::with_capacity(io_objects.len());
    for (name, axis) in &io_objects {
        io_pubs.push(if cell.axes[*axis].node == n {
            let svc = ipc::io(&iox, &cell.name, name).map_err(|e| e.to_string())?;
            Some(
                svc.publisher_builder()
                    .create()
                    .map_err(|e| format!("publisher for {name}: {e}"))?,
            )
        } else {
            None
        });
    }
    rt::no_timer_slack();
    if let Some(p) = me.realtime.priority {
        if let Err(w) = rt::set_fifo(p) {
            eprintln!("tandem-node {}: warning: {w}", me.name);
        }
    }
    if let Some(c) = me.realtime.cpu {
        if let Err(w) = rt::pin_to_cpu(c) {
            eprintln!("tandem-node {}: warning: {w}", me.name);
        }
    }

    let epoch = o.epoch_ns.unwrap_or_else(|| {
        let now = rt::now_ns();
        (now / 1_000_000_000 + 1) * 1_000_000_000
    });
    let cycle = me.cycle_ns;
    // The first cycle: the next one on the grid, at least 2 cycles from now.
    let mut k = ((rt::now_ns() - epoch + 2 * cycle).max(0) + cycle - 1) / cycle;
    let mut next = script.partition_point(|e| e.t_ns < k * cycle);
    let skipped = script[..next]
        .iter()
        .filter(|e| owns(cell, n, &e.axis, &e.action))
        .count();
    if skipped > 0 {
        eprintln!(
            "tandem-node {}: warning: starting at t={}, {skipped} script entr{} for this node's \
             objects before it are skipped (a restart, or a start after the epoch)",
            me.name,
            Secs(k * cycle),
            if skipped == 1 { "y" } else { "ies" }
        );
    }
    let mut log = LogRing::new();
    let mut report = Report::default();
    let mut health = NodeHealth {
        epoch_ns: epoch,
        cycle_ns: cycle,
        pid: std::process::id(),
        axes: owned.len() as u32,
        ..NodeHealth::default()
    };
    let mut seqs = vec![0u64; publish.len()];
    let (free_rx, row_tx, recording) = pool;
    eprintln!(
        "tandem-node {}: {} axes, cycle {} µs, first cycle {} at t={}; publishes {} leader(s), \
         follows {} remote leader(s)",
        me.name,
        owned.len(),
        cycle / 1000,
        k,
        Secs(k * cycle),
        publish.len(),
        subscribe.len()
    );
    // The run is measured from the start of its first cycle.
    let started = epoch + k * cycle;
    let mut cpu0 = None;
    loop {
        let t = k * cycle;
        if end_ns.is_some_and(|e| t > e) || rt::termination_requested() {
            break;
        }
        let start = epoch + t;
        rt::sleep_until(start);
        let wake = rt::now_ns();
        if wake < start {
            // A signal woke us early: look at the flag, then sleep again.
            continue;
        }
        if cpu0.is_none() {
            cpu0 = Some(cpu_time_ns());
        }
        let lateness = wake - start;
        // 1. Inputs: the samples other nodes published.
        for (l, c, s) in &subscribe {
            while let Ok(Some(sample)) = s.receive() {
                if exec.feed(*l, *c, sample.payload().to_sample()).is_err() {
                    health.samples_rejected += 1;
                }
            }
        }
        // 2. Commands and due script entries.
        while let Ok(q) = cmd_rx.try_recv() {
            let e = &q.entry;
            let applied = exec
                .apply(t, &e.axis, e.instruction, e.action, &mut log)
                .unwrap_or(Err(
                    tandem_motion::catalog::error_id::ErrorId::IllegalObject,
                ));
            let mut reply = CommandReply {
                outcome: OUTCOME_ACCEPTED,
                job: 0,
                error_id: 0,
                t_ns: t,
                message: Text::default(),
            };
            match applied {
                Ok(job) => reply.job = job.unwrap_or(0),
                Err(id) => {
                    reply.outcome = OUTCOME_REJECTED;
                    reply.error_id = u32::from(id.code());
                    reply.message = Text::new(id.description());
                }
            }
            let _ = done_tx.try_send(Done { id: q.id, reply });
        }
        while let Some(e) = script.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            if owns(cell, n, &e.axis, &e.action) {
                let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
            }
        }
        // 3. The engine.
        let _ = exec.step(t, &mut log);
        // 4. Outputs: leading values, edges and measured values, events.
        for ((l, c, p), seq) in publish.iter().zip(seqs.iter_mut()) {
            let s = exec.sample(*l, *c, t, *seq);
            *seq += 1;
            let _ = p.send_copy(LeadingValueSample::from_sample(cell.leader_id(*l), &s));
        }
        if let Some(n) = &published {
            let _ = n.notify();
        }
        exec.drain_io_notes(|x| {
            if let Some(Some(p)) = io_pubs.get(x.object) {
                let _ = p.send_copy(IoEvent {
                    t_ns: x.t_ns,
                    kind: if x.measured { IO_MEASURED } else { IO_OUTPUT },
                    counter: x.counter,
                    value: x.value,
                });
            }
        });
        exec.drain_job_notes(|j| {
            let (code, error_id) = job_code(j.kind);
            let mut ev = Event {
                t_ns: j.t_ns,
                kind: EVENT_JOB,
                object: j.object as u32,
                job: j.job,
                code,
                error_id,
                message: Text::default(),
            };
            let _ = core::fmt::Write::write_fmt(
                &mut TextWriter(&mut ev.message),
                format_args!(
                    "{} {} job {}: {}",
                    names_of.get(j.object).copied().unwrap_or("?"),
                    j.instruction.name(),
                    j.job,
                    tandem_runtime::exec::Describe(j.kind)
                ),
            );
            let _ = events.send_copy(ev);
        });
        while let Some(line) = log.lines.pop_front() {
            let _ = events.send_copy(Event {
                t_ns: t,
                kind: EVENT_LOG,
                object: u32::MAX,
                job: 0,
                code: 0,
                error_id: 0,
                message: line,
            });
        }
        // 5. Telemetry, trace row, timing.
        health.t_ns = t;
        health.lateness_ns = lateness;
        health.max_lateness_ns = health.max_lateness_ns.max(lateness);
        health.cycles += 1;
        health.extrapolated = exec.extrapolated;
        health.log_dropped = log.dropped + exec.notes_dropped;
        let status = exec.status();
        if let Ok(mut sample) = telemetry.loan_slice_uninit(owned.len()) {
            *sample.user_header_mut() = health;
            let sample = sample.write_from_fn(|i| {
                owned
                    .get(i)
                    .map(|a| AxisTelemetry::from_status(*a as u32, &status[*a]))
                    .unwrap_or_default()
            });
            let _ = sample.send();
        }
        if recording {
            if let Ok((_, mut row)) = free_rx.try_recv() {
                // Within the capacity the row was made with: no allocation.
                row.clear();
                row.extend(owned.iter().map(|a| status[*a]));
                let _ = row_tx.try_send((t, row));
            }
        }
        let end = rt::now_ns();
        let compute = end - wake;
        health.compute_ns = compute;
        health.max_compute_ns = health.max_compute_ns.max(compute);
        report.compute.record(compute);
        report.lateness.record(lateness);
        report.cycles += 1;
        if end > start + cycle {
            health.overruns += 1;
            report.overruns += 1;
        }
        k += 1;
    }
    report.wall_ns = rt::now_ns() - started;
    report.cpu_ns = cpu0.map_or(0, |c| cpu_time_ns() - c);
    eprintln!(
        "tandem-node {}: stopped after {} cycles ({} overruns, {} leading values extrapolated, {} \
         log lines dropped); compute {}; lateness {}",
        me.name,
        report.cycles,
        report.overruns,
        exec.extrapolated,
        health.log_dropped,
        report.compute.summary(),
        report.lateness.summary()
    );
    drop(iox);
    Ok(report)
}

/// Formats into a [`Text`] without allocating.
struct TextWriter<'a>(&'a mut Text);

impl core::fmt::Write for TextWriter<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        self.0.push(s);
        Ok(())
    }
}

/// Whether node `n` hosts the object a script entry addresses.
fn owns(cell: &Cell, n: usize, target: &str, action: &Action) -> bool {
    let axis_node = |a: AxisIndex| cell.axis(a).map(|x| x.node);
    let node = match action {
        Action::InterpolateCam { .. } => return true,
        Action::Command(_) => cell
            .axes
            .iter()
            .find(|a| a.name == target)
            .map(|a| a.node)
            .or_else(|| {
                cell.encoders
                    .iter()
                    .find(|e| e.name == target)
                    .map(|e| e.node)
            }),
        _ => cell
            .output_cam(target)
            .and_then(|i| axis_node(cell.output_cams[i].axis))
            .or_else(|| {
                cell.cam_track(target)
                    .and_then(|i| axis_node(cell.cam_tracks[i].axis))
            })
            .or_else(|| {
                cell.measuring_input(target)
                    .and_then(|i| axis_node(cell.measuring_inputs[i].axis))
            }),
    };
    node == Some(n)
}

/// Receives commands on the node's request-response service, parses them (off the cyclic
/// path), queues them for the cyclic thread and answers with its result.
fn command_thread(
    cell: &Cell,
    node: &str,
    stop: &AtomicBool,
    cmd_tx: &SyncSender<Queued>,
    done_rx: &Receiver<Done>,
) {
    let run = || -> Result<(), String> {
        let host = cell
            .node(node)
            .map_or("local", |n| cell.hosts[cell.nodes[n].host].as_str());
        let iox: IpcNode = ipc::node(&format!("{}/commands", names::node(&cell.name, node)), host)
            .map_err(|e| e.to_string())?;
        let service = ipc::commands(&iox, &cell.name, node).map_err(|e| e.to_string())?;
        let server = service
            .server_builder()
            .create()
            .map_err(|e| format!("command server: {e}"))?;
        let mut pending = Vec::new();
        let mut id = 0u64;
        let n = cell.node(node);
        while !stop.load(Ordering::SeqCst) && !rt::termination_requested() {
            while let Ok(Some(active)) = server.receive() {
                id += 1;
                let text = active.payload().text.as_str().to_string();
                let parsed = split_command(&text)
                    .map_err(|e| e.to_string())
                    .and_then(|c| {
                        let object = match c.object.split_once('/') {
                            Some((nn, o)) if Some(nn) == Some(node) => o.to_string(),
                            Some((nn, _)) => {
                                return Err(format!("this is node `{node}`, not `{nn}`"))
                            }
                            None => c.object,
                        };
                        tandem_config::script::parse_command(
                            cell,
                            &object,
                            &c.instruction,
                            &c.params,
                        )
                        .map_err(|e| e.to_string())
                    });
                let parsed = parsed.and_then(|e| {
                    if n.is_some_and(|n| owns(cell, n, &e.axis, &e.action)) {
                        Ok(e)
                    } else {
                        Err(format!("`{}` is not an object of node `{node}`", e.axis))
                    }
                });
                let reject = |outcome, msg: &str| CommandReply {
                    outcome,
                    job: 0,
                    error_id: 0,
                    t_ns: 0,
                    message: Text::new(msg),
                };
                match parsed {
                    Err(m) => {
                        let _ = active.send_copy(reject(OUTCOME_INVALID, &m));
                    }
                    Ok(entry) => match cmd_tx.try_send(Queued { id, entry }) {
                        Ok(()) => pending.push((id, active)),
                        Err(TrySendError::Full(_)) => {
                            let _ = active.send_copy(reject(
                                OUTCOME_BUSY,
                                "the node's command queue is full; try again",
                            ));
                        }
                        Err(TrySendError::Disconnected(_)) => return Ok(()),
                    },
                }
            }
            while let Ok(d) = done_rx.try_recv() {
                if let Some(i) = pending.iter().position(|(x, _)| *x == d.id) {
                    let (_, active) = pending.swap_remove(i);
                    let _ = active.send_copy(d.reply);
                }
            }
            // Commands are for people and supervisors: 5 ms is well below what they notice
            // and costs a fraction of a per cent of a core.
            std::thread::sleep(Duration::from_millis(5));
        }
        Ok(())
    };
    if let Err(e) = run() {
        eprintln!("tandem-node {node}: commands unavailable: {e}");
    }
}

/// Writes trace rows from the pool and the node's log lines from its event service.
fn recorder_thread(
    cell: &Cell,
    o: &Options,
    owned: &[usize],
    stop: &AtomicBool,
    rows: &Receiver<(i64, Vec<AxisStatus>)>,
    free: &SyncSender<(i64, Vec<AxisStatus>)>,
) {
    let run = || -> Result<(), String> {
        let open = |p: &PathBuf| {
            std::fs::File::create(p)
                .map(io::BufWriter::new)
                .map_err(|e| format!("{}: {e}", p.display()))
        };
        let mut trace = o.trace.as_ref().map(open).transpose()?;
        let mut log = o.log.as_ref().map(open).transpose()?;
        if let Some(w) = trace.as_mut() {
            let _ = write!(w, "time_s");
            for a in owned {
                for c in AXIS_COLUMNS {
                    let _ = write!(w, ",{}.{c}", cell.axes[*a].name);
                }
            }
            let _ = writeln!(w);
        }
        let host = cell
            .node(&o.node)
            .map_or("local", |n| cell.hosts[cell.nodes[n].host].as_str());
        let iox = ipc::node(
            &format!("{}/recorder", names::node(&cell.name, &o.node)),
            host,
        )
        .map_err(|e| e.to_string())?;
        let events = ipc::events(&iox, &cell.name, &o.node).map_err(|e| e.to_string())?;
        let sub = events
            .subscriber_builder()
            .buffer_size(1024)
            .create()
            .map_err(|e| format!("event subscriber: {e}"))?;
        loop {
            let stopping = stop.load(Ordering::SeqCst);
            while let Ok((t, row)) = rows.try_recv() {
                if let Some(w) = trace.as_mut() {
                    tandem_runtime::sim::write_row(w, t, &row, &[], "")
                        .map_err(|e| format!("trace: {e}"))?;
                }
                let _ = free.try_send((t, row));
            }
            while let Ok(Some(s)) = sub.receive() {
                let e = s.payload();
                if let Some(w) = log.as_mut() {
                    if e.kind == EVENT_LOG {
                        writeln!(w, "{}", e.message.as_str()).map_err(|e| format!("log: {e}"))?;
                    }
                }
            }
            if stopping {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        if let Some(w) = trace.as_mut() {
            w.flush().map_err(|e| format!("trace: {e}"))?;
        }
        if let Some(w) = log.as_mut() {
            w.flush().map_err(|e| format!("log: {e}"))?;
        }
        Ok(())
    };
    if let Err(e) = run() {
        eprintln!("tandem-node {}: recorder: {e}", o.node);
    }
}

/// The exit code for a failed run: 2 when the input (cell, node, script) is wrong, else 1.
pub fn exit_code(message: &str) -> u8 {
    // Config and script errors are located `file:line: key: ...`; node lookups name the file.
    if message.contains(".toml") {
        2
    } else {
        1
    }
}
