//! tandem-node: one node of a cell as a process (docs/processes.md, "One cycle of a node").
//!
//! The main thread is the cyclic executive ([`cycle`]). Cycle `k` starts at `epoch + k * T`
//! on the cell clock (CLOCK_REALTIME), so nodes with the same cycle on a host are
//! phase-aligned; the engine time of the cycle is `k * T`. A cycle runs its stages in a fixed
//! order: receive the leading values other nodes published, apply queued commands and due
//! script entries, step the technology objects, publish this node's leading values, output
//! edges, measured values and events, and record the health, telemetry and timing. Nothing
//! there allocates, locks, logs or blocks: commands arrive through a bounded queue from the
//! command thread ([`commands`]), log lines and job events go to the recorder thread
//! ([`recorder`]) as fixed-size records, which it writes and emits through `tracing`, trace
//! rows go to it through a fixed pool, changed absolute encoder adjustments go to it through
//! the records' channel and it stores them as retained data ([`retain`]; restored before the
//! first cycle). Every iceoryx2 port of the cycle is opened in one place ([`ports`]).
//!
//! ```no_run
//! // Runs node `press` of a cell for 2 s of engine time.
//! let o = tandem_node::Options {
//!     cell: "config/press.toml".into(),
//!     node: "press".into(),
//!     duration_s: Some(2.0),
//!     ..Default::default()
//! };
//! match tandem_node::run(&o) {
//!     Ok(report) => println!("{} cycles, compute {}", report.cycles, report.compute.summary()),
//!     Err(e) => eprintln!("error: {e} (exit code {})", e.exit_code()),
//! }
//! ```

mod audit;
mod commands;
mod cycle;
mod error;
pub mod ethercat;
mod logring;
mod lvhealth;
mod parameters;
mod ports;
mod recorder;
mod report;
mod retain;

pub use error::NodeError;
pub use report::{Histogram, Report, Stages};

use commands::{command_thread, CommandLinks, Done, Queued};
use cycle::{Clock, CycleParts, Links, NodeCycle};
use logring::{Record, DIAG_RECORDS};
use ports::{PortPlan, Ports};
use recorder::{recorder_thread, Lost, RecorderPlan};
use recorder::{Row, RowPool};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::sync::Arc;
use std::thread::JoinHandle;
use tandem_config::script::Script;
use tandem_config::{AxisIndex, Cell, Coupling, Leader};
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::AxisStatus;
use tandem_protocol::ipc;
use tandem_rt as rt;
use tandem_rt::retain::RetainStore;
use tandem_runtime::exec::{Executive, Secs};
use tracing::{error, info, info_span, warn, Span};

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

/// Trace rows in the pool between the cyclic and the recorder thread, at least: the recorder
/// may fall this many cycles behind (a busy disk) before a row is dropped (`trace_dropped`).
const TRACE_ROWS_MIN: usize = 256;

/// Trace rows in the pool, at most (4 s of 1 ms cycles).
const TRACE_ROWS_MAX: usize = 4096;

/// The memory the pool may take, where more than [`TRACE_ROWS_MIN`] rows fit in it.
const TRACE_POOL_BYTES: usize = 16 << 20;

/// The rows of the trace pool of a node with `axes` axes: as many as [`TRACE_POOL_BYTES`] hold,
/// within [`TRACE_ROWS_MIN`] and [`TRACE_ROWS_MAX`] (the hour's soak of the line cell dropped
/// 923 rows of a one-axis node with 256 while builds kept the disk busy; 4,096 rows of one axis
/// take 0.7 MB, and a node of 1,024 axes keeps its 256 rows, 36 MB).
fn trace_rows(axes: usize) -> usize {
    let row = axes.max(1) * std::mem::size_of::<AxisStatus>() + std::mem::size_of::<Row>();
    (TRACE_POOL_BYTES / row).clamp(TRACE_ROWS_MIN, TRACE_ROWS_MAX)
}

/// Runs the node until SIGINT/SIGTERM or the end of its duration, in a `node` span.
pub fn run(o: &Options) -> Result<Report, NodeError> {
    let span = info_span!("node", node = %o.node);
    let _in = span.enter();
    let cell = Arc::new(tandem_config::load(&o.cell).map_err(NodeError::Cell)?);
    let n = cell.node(&o.node).ok_or_else(|| NodeError::UnknownNode {
        cell: o.cell.clone(),
        node: o.node.clone(),
        nodes: cell.nodes.iter().map(|x| x.name.clone()).collect(),
    })?;
    let script = load_script(o, &cell)?;
    rt::install_termination_handler();
    prepare_process(&cell, n);
    let owned: Vec<usize> = (0..cell.axes.len())
        .filter(|i| cell.axes[*i].node == n)
        .collect();
    let stop = Arc::new(AtomicBool::new(false));
    let retained = retain::open(&cell, n);
    let params = parameters::open(&cell, n);
    let stores = (retained.clone(), params.clone());
    let (threads, links) = start_threads(&cell, o, &owned, &stop, stores)?;
    let lost = Arc::clone(&links.lost);
    let start = Start {
        script: script.as_ref(),
        retained: retained.as_deref(),
        parameters: params.as_deref(),
    };
    let result = cyclic(&cell, n, o, start, owned, links);
    stop.store(true, Ordering::SeqCst);
    for (name, t) in threads {
        // The recorder may be parked for its idle turn: it sees `stop` at once.
        t.thread().unpark();
        if t.join().is_err() {
            error!(thread = name, "the thread panicked");
        }
    }
    let mut report = result?;
    report.resident_bytes = rt::resident_bytes().unwrap_or(0);
    recording_lost(&lost, &mut report);
    Ok(report)
}

/// After the recorder ended: what it could not write to the disk, into the report, and a
/// warning when anything was lost (the end report's `recording ...` line).
fn recording_lost(lost: &Lost, report: &mut Report) {
    report.trace_rows_lost = lost.rows.load(Ordering::Relaxed);
    report.log_lines_lost = lost.lines.load(Ordering::Relaxed);
    if report.trace_rows_lost + report.log_lines_lost > 0 {
        warn!(
            trace_rows_lost = report.trace_rows_lost,
            log_lines_lost = report.log_lines_lost,
            "recording lost {} trace rows and {} log lines to the disk in this run",
            report.trace_rows_lost,
            report.log_lines_lost
        );
    }
}

/// The script of `o`, parsed against the cell.
fn load_script(o: &Options, cell: &Cell) -> Result<Option<Script>, NodeError> {
    let Some(p) = &o.script else {
        return Ok(None);
    };
    tandem_config::script::load(p, cell)
        .map(Some)
        .map_err(NodeError::Script)
}

/// Locks the memory if the node asks for it, and removes what crashed processes of the host
/// left in iceoryx2.
fn prepare_process(cell: &Cell, n: usize) {
    if cell.nodes[n].realtime.lock_memory {
        if let Err(w) = rt::lock_memory() {
            warn!("{w}");
        }
    }
    let cleaned = ipc::cleanup_dead_nodes(&cell.hosts[cell.nodes[n].host]);
    if cleaned > 0 {
        info!("removed the resources of {cleaned} crashed process(es)");
    }
}

/// A started thread of the node and its name.
type Thread = (&'static str, JoinHandle<()>);

/// Spawns a named thread in the current span.
fn spawn(name: &'static str, f: impl FnOnce() + Send + 'static) -> Result<Thread, NodeError> {
    let span = Span::current();
    std::thread::Builder::new()
        .name(name.into())
        .spawn(move || span.in_scope(f))
        .map(|t| (name, t))
        .map_err(|source| NodeError::Thread {
            thread: name,
            source,
        })
}

/// Starts the command and recorder threads (the recorder stores the retained data into
/// `retained`); returns them and the cyclic thread's links.
fn start_threads(
    cell: &Arc<Cell>,
    o: &Options,
    owned: &[usize],
    stop: &Arc<AtomicBool>,
    (retained, params): (Option<Arc<RetainStore>>, Option<Arc<RetainStore>>),
) -> Result<(Vec<Thread>, Links), NodeError> {
    let (cmd_tx, cmd_rx) = sync_channel::<Queued>(32);
    let (done_tx, done_rx) = sync_channel::<Done>(64);
    let (diag_tx, diag_rx) = sync_channel::<Record>(DIAG_RECORDS);
    let pool = trace_rows(owned.len());
    let (free_tx, free_rx) = sync_channel::<Row>(pool);
    let (row_tx, row_rx) = sync_channel::<Row>(pool);
    // Trace rows only when a trace is written; the pool's channel holds them all.
    let rows = if o.trace.is_some() { pool } else { 0 };
    for _ in 0..rows {
        if free_tx
            .try_send((0, Vec::with_capacity(owned.len())))
            .is_err()
        {
            break;
        }
    }
    let mut threads = Vec::new();
    let lost = Arc::new(Lost::default());
    let (c, s, node) = (Arc::clone(cell), Arc::clone(stop), o.node.clone());
    let links = CommandLinks {
        queue: cmd_tx,
        done: done_rx,
        parameters: params,
    };
    threads.push(spawn("commands", move || {
        command_thread(&c, &node, &s, &links)
    })?);
    let plan = RecorderPlan {
        trace: o.trace.clone(),
        log: o.log.clone(),
        owned: owned.to_vec(),
        rows: (row_rx, free_tx),
        diag: diag_rx,
        retained,
        lost: Arc::clone(&lost),
    };
    let (c, s) = (Arc::clone(cell), Arc::clone(stop));
    let recorder = spawn("recorder", move || recorder_thread(&c, &plan, &s))?;
    let wake = recorder::Wake::new(recorder.1.thread().clone());
    threads.push(recorder);
    let links = Links {
        lost,
        wake,
        commands: cmd_rx,
        done: done_tx,
        diag: diag_tx,
        rows: o.trace.is_some().then_some(RowPool {
            free: free_rx,
            full: row_tx,
        }),
    };
    Ok((threads, links))
}

/// Real-time settings of the cyclic thread: no timer slack, SCHED_FIFO and CPU as configured
/// (a refusal is a warning: the node runs without).
fn realtime(cell: &Cell, n: usize) {
    let me = &cell.nodes[n];
    rt::no_timer_slack();
    if let Some(p) = me.realtime.priority {
        if let Err(w) = rt::set_fifo(p) {
            warn!("{w}");
        }
    }
    if let Some(c) = me.realtime.cpu {
        if let Err(w) = rt::pin_to_cpu(c) {
            warn!("{w}");
        }
    }
}

/// Cycles between two telemetry snapshots of node `n`: the snapshots come at twice the rate
/// observers sample them (`cell.telemetry_hz`, the gateways' state rate, default 50 Hz), so a
/// sample is never more than half an observer's period old; every cycle when the node's cycle
/// is longer than that. A snapshot of a whole node costs about 65 instructions per axis: at
/// 1 ms and 50 Hz this publishes every 10th cycle.
fn telemetry_every(cell: &Cell, n: usize) -> u64 {
    let period_ns = 1e9 / (2.0 * cell.telemetry_hz);
    let cycle_ns = cell.nodes[n].cycle_ns.max(1) as f64;
    if period_ns.is_finite() && period_ns > cycle_ns {
        (period_ns / cycle_ns).floor() as u64
    } else {
        1
    }
}

/// What the cyclic executive starts from besides the cell: the script, the retained data.
struct Start<'a> {
    /// The script, if any.
    script: Option<&'a Script>,
    /// The node's retained data, if it has any.
    retained: Option<&'a RetainStore>,
    /// The node's retained run-time parameters, if it has a directory for them.
    parameters: Option<&'a RetainStore>,
}

/// Restores the retained data, opens the ports, then runs the cyclic executive on this
/// thread until the end of the duration (`o`'s, else the script's) or a signal.
fn cyclic(
    cell: &Cell,
    n: usize,
    o: &Options,
    start: Start<'_>,
    owned: Vec<usize>,
    links: Links,
) -> Result<Report, NodeError> {
    let end_ns = o
        .duration_s
        .map(|d| (d * 1e9) as i64)
        .or(start.script.map(|s| s.duration_ns));
    let script = start.script.map_or(&[][..], |s| s.entries.as_slice());
    // The segment in OP before the clock starts (opening it takes seconds).
    let ethercat = ethercat::open(cell, n).map_err(NodeError::Ethercat)?;
    let mut exec = Executive::new(cell, Some(n)).map_err(|e| NodeError::Engine(e.into()))?;
    retain::restore(&mut exec, cell, start.retained);
    parameters::restore(&mut exec, cell, n, start.parameters);
    let remote: Vec<(Leader, Coupling)> = exec.remote_leaders().collect();
    let ports = Ports::open(PortPlan {
        cell,
        node: n,
        remote: &remote,
        axes: owned.len(),
    })?;
    realtime(cell, n);
    let me = &cell.nodes[n];
    let epoch = o
        .epoch_ns
        .unwrap_or_else(|| (rt::now_ns() / 1_000_000_000 + 1) * 1_000_000_000);
    let clock = Clock::starting_now(epoch, me.cycle_ns, end_ns);
    let axes = owned.len();
    let parts = CycleParts {
        cell,
        node: n,
        exec,
        ports,
        owned,
        script,
        links,
        telemetry_every: telemetry_every(cell, n),
        ethercat,
    };
    let node = NodeCycle::new(parts, &clock);
    let t0 = Secs(clock.first * clock.cycle);
    let skipped = node.skipped();
    if skipped > 0 {
        warn!(
            "starting at t={t0}, {skipped} script entr{} for this node's objects before it are \
             skipped (a restart, or a start after the epoch)",
            if skipped == 1 { "y" } else { "ies" }
        );
    }
    let (publishes, follows) = node.links_count();
    info!(
        axes,
        cycle_us = clock.cycle / 1000,
        first_cycle = clock.first,
        publishes,
        follows,
        "{axes} axes, cycle {} µs, first cycle {} at t={t0}; publishes {publishes} leader(s), \
         follows {follows} remote leader(s)",
        clock.cycle / 1000,
        clock.first
    );
    let (report, h) = node.run(&clock);
    info!(
        cycles = report.cycles,
        overruns = report.overruns,
        extrapolated = h.extrapolated,
        lv_lost = h.lv_lost,
        samples_rejected = h.samples_rejected,
        log_dropped = h.log_dropped,
        sends_failed = h.sends_failed,
        commands_unanswered = h.commands_unanswered,
        script_rejected = h.script_rejected,
        step_errors = h.step_errors,
        diag_dropped = h.diag_dropped,
        trace_dropped = h.trace_dropped,
        "stopped after {} cycles ({} overruns, {} leading values extrapolated, {} leading-value \
         samples lost, {} refused, {} log lines dropped); compute {}; lateness {}",
        report.cycles,
        report.overruns,
        h.extrapolated,
        h.lv_lost,
        h.samples_rejected,
        h.log_dropped,
        report.compute.summary(),
        report.lateness.summary()
    );
    Ok(report)
}

/// Whether node `n` hosts the object a script entry addresses.
pub(crate) fn owns(cell: &Cell, n: usize, target: &str, action: &Action) -> bool {
    let axis_node = |a: AxisIndex| cell.axis(a).map(|x| x.node);
    let node = match action {
        Action::InterpolateCam { .. } => return true,
        Action::DriveFault { .. } => cell
            .devices
            .iter()
            .find(|d| d.name == target)
            .map(|d| d.node),
        Action::SetInput { .. } | Action::SetInputValue { .. } | Action::SetOutputValue { .. } => {
            cell.signal(target)
                .and_then(|k| cell.signals.get(k.0))
                .and_then(|s| cell.devices.get(s.device.0))
                .map(|d| d.node)
        }
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
            })
            .or_else(|| {
                cell.digital_cam_switch(target)
                    .and_then(|i| axis_node(cell.digital_cam_switches[i].axis))
            }),
    };
    node == Some(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trace_pool_holds_more_rows_for_small_nodes_within_its_bounds() {
        assert_eq!(trace_rows(1), TRACE_ROWS_MAX);
        assert_eq!(trace_rows(0), TRACE_ROWS_MAX);
        assert_eq!(trace_rows(1024), TRACE_ROWS_MIN);
        let mut last = usize::MAX;
        for axes in [1, 8, 16, 32, 64, 128, 256, 512, 1024, 4096] {
            let rows = trace_rows(axes);
            assert!((TRACE_ROWS_MIN..=TRACE_ROWS_MAX).contains(&rows));
            assert!(rows <= last, "{axes} axes: {rows} rows");
            last = rows;
        }
        eprintln!(
            "AxisStatus {} bytes; 1 axis: {} rows; 1,024 axes: {} rows",
            std::mem::size_of::<AxisStatus>(),
            trace_rows(1),
            trace_rows(1024)
        );
    }
}
