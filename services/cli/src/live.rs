//! What the commands on a running cell share (the cell file, the host's nodes, an iceoryx2
//! node of the command, an observer of the nodes' telemetry and the axis table), and the two
//! that only observe: `status` and `watch`.

use crate::error::CliError;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use tandem_config::Cell;
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::wire::{AxisTelemetry, Event, NodeHealth};
use tandem_rt as rt;

type TelemetrySub = iceoryx2::port::subscriber::Subscriber<
    iceoryx2::prelude::ipc::Service,
    [AxisTelemetry],
    NodeHealth,
>;
type EventSub = iceoryx2::port::subscriber::Subscriber<iceoryx2::prelude::ipc::Service, Event, ()>;

/// The cell of file `path`.
pub(crate) fn load(path: &Path) -> Result<Cell, CliError> {
    Ok(tandem_config::load(path)?)
}

/// The cell file of `status`, `watch` and `cmd`: `--cell`, else `$TANDEM_CELL`.
pub fn cell_path(given: Option<&PathBuf>) -> Result<PathBuf, CliError> {
    given
        .cloned()
        .or_else(|| std::env::var_os("TANDEM_CELL").map(PathBuf::from))
        .ok_or(CliError::NoCell)
}

/// The nodes of `host` (by name; the only host when `None`).
pub(crate) fn host_nodes(
    cell: &Cell,
    host: Option<&str>,
) -> Result<(String, Vec<usize>), CliError> {
    let h = match host {
        Some(h) => cell
            .hosts
            .iter()
            .position(|x| x == h)
            .ok_or_else(|| CliError::UnknownHost {
                cell: cell.name.clone(),
                host: h.to_string(),
                hosts: cell.hosts.clone(),
            })?,
        None if cell.hosts.len() == 1 => 0,
        None => {
            return Err(CliError::HostRequired {
                cell: cell.name.clone(),
                hosts: cell.hosts.clone(),
            })
        }
    };
    let nodes = (0..cell.nodes.len())
        .filter(|n| cell.nodes[*n].host == h)
        .collect();
    Ok((cell.hosts[h].clone(), nodes))
}

/// An iceoryx2 node of this command in the domain of `host`.
pub(crate) fn cli_node(cell: &Cell, what: &str, host: &str) -> Result<IpcNode, CliError> {
    Ok(ipc::node(
        &format!("tandem/{}/{what}-{}", cell.name, std::process::id()),
        host,
    )?)
}

/// What an observer holds of the cell's nodes.
pub(crate) struct Observer {
    telemetry: Vec<(usize, TelemetrySub)>,
    events: Vec<(usize, EventSub)>,
    last: Vec<Option<(NodeHealth, Vec<AxisTelemetry>, Instant)>>,
}

impl Observer {
    pub(crate) fn new(
        iox: &IpcNode,
        cell: &Cell,
        nodes: &[usize],
        events: bool,
    ) -> Result<Self, CliError> {
        let mut telemetry = Vec::new();
        let mut ev = Vec::new();
        for n in nodes {
            let name = &cell.nodes[*n].name;
            let svc = ipc::telemetry(iox, &cell.name, name)?;
            let sub = svc
                .subscriber_builder()
                .buffer_size(4)
                .create()
                .map_err(CliError::port(format!("telemetry of {name}")))?;
            telemetry.push((*n, sub));
            if events {
                let svc = ipc::events(iox, &cell.name, name)?;
                let sub = svc
                    .subscriber_builder()
                    .buffer_size(1024)
                    .create()
                    .map_err(CliError::port(format!("events of {name}")))?;
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
    pub(crate) fn poll(&mut self) {
        for (n, sub) in &self.telemetry {
            while let Ok(Some(s)) = sub.receive() {
                self.last[*n] = Some((*s.user_header(), s.payload().to_vec(), Instant::now()));
            }
        }
    }

    /// Log lines and job events since the last call: (node, event).
    pub(crate) fn events(&mut self) -> Vec<(usize, Event)> {
        let mut out = Vec::new();
        for (n, sub) in &self.events {
            while let Ok(Some(s)) = sub.receive() {
                out.push((*n, *s.payload()));
            }
        }
        out
    }

    /// The newest health node `n` published, if any.
    pub(crate) fn health(&self, n: usize) -> Option<&NodeHealth> {
        self.last.get(n)?.as_ref().map(|(h, _, _)| h)
    }

    /// Whether node `n` published within the last second.
    fn alive(&self, n: usize) -> bool {
        self.last[n]
            .as_ref()
            .is_some_and(|(_, _, at)| at.elapsed() < Duration::from_secs(1))
    }
}

/// The header of the axis table of `status`, `watch` and `up`.
pub(crate) const HEADER: &str = "node         axis           state                    position    velocity sync      alarm  job";

/// One row of the axis table.
pub(crate) fn table_row(
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
pub(crate) fn render(
    cell: &Cell,
    obs: &Observer,
    nodes: &[usize],
    pattern: Option<&str>,
) -> String {
    let mut s = format!("{HEADER}\n");
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
                    s.push_str(&table_row(
                        name,
                        axis,
                        a.state_name(),
                        (a.position, a.velocity),
                        sync_name(a.sync_function),
                        a.alarm,
                        a.job,
                    ));
                    s.push('\n');
                }
            }
            _ => s.push_str(&format!("{name:<12} (not running)\n")),
        }
    }
    for n in nodes {
        if let (Some((h, _, _)), true) = (&obs.last[*n], obs.alive(*n)) {
            s.push_str(&format!(
                "{:<12} pid {:<7} t={:<14} cycle {} µs, compute {} µs (max {}), lateness {} µs (max {}), overruns {}, skipped cycles {}\n",
                cell.nodes[*n].name,
                h.pid,
                tandem_runtime::exec::Secs(h.t_ns),
                h.cycle_ns / 1000,
                h.compute_ns / 1000,
                h.max_compute_ns / 1000,
                h.lateness_ns / 1000,
                h.max_lateness_ns / 1000,
                h.overruns,
                h.skipped_cycles
            ));
            s.push_str(&recording_lost(h));
        }
    }
    s
}

/// The health line's note of what the node's recorder lost to the disk, if anything:
/// `  recording lost 1234 trace rows, 0 log lines (disk full or write errors)`.
fn recording_lost(h: &NodeHealth) -> String {
    if h.trace_rows_lost == 0 && h.log_lines_lost == 0 {
        return String::new();
    }
    format!(
        "{:<12} recording lost {} trace rows, {} log lines (disk full or write errors)\n",
        "", h.trace_rows_lost, h.log_lines_lost
    )
}

/// `tandem status`: one snapshot of the host's nodes. Exit 0 when every node runs, 3 if not.
pub fn status(cell_path: &Path, host: Option<&str>, out: &mut impl Write) -> Result<(), CliError> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, host)?;
    let _span = tracing::info_span!("status", cell = %cell.name, host = %host).entered();
    let iox = cli_node(&cell, "status", &host)?;
    let mut obs = Observer::new(&iox, &cell, &nodes, false)?;
    let deadline = Instant::now() + Duration::from_millis(1500);
    while Instant::now() < deadline && !nodes.iter().all(|n| obs.alive(*n)) {
        obs.poll();
        std::thread::sleep(Duration::from_millis(10));
    }
    out!(out, "{}", render(&cell, &obs, &nodes, None));
    let down: Vec<String> = nodes
        .iter()
        .filter(|n| !obs.alive(**n))
        .map(|n| cell.nodes[*n].name.clone())
        .collect();
    if down.is_empty() {
        Ok(())
    } else {
        Err(CliError::NotRunning {
            nodes: down,
            cell: cell_path.to_path_buf(),
        })
    }
}

/// `tandem watch`: the live table until Ctrl-C (or `count` refreshes).
pub fn watch(
    cell_path: &Path,
    host: Option<&str>,
    pattern: Option<&str>,
    count: Option<u64>,
    out: &mut impl Write,
) -> Result<(), CliError> {
    let cell = load(cell_path)?;
    let (host, nodes) = host_nodes(&cell, host)?;
    let _span = tracing::info_span!("watch", cell = %cell.name, host = %host).entered();
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
            out!(out, "\x1b[H\x1b[2J");
        }
        outln!(out, "{}", render(&cell, &obs, &nodes, pattern));
        crate::output::flush(out);
        shown += 1;
    }
    Ok(())
}
