//! The cell file to a validated [`Cell`]: one function per section of the file, in the order
//! the sections depend on each other (cell, hosts, nodes, axes, leaders, encoders, cams,
//! leading values, output cams, cam tracks, measuring inputs, the signals they drive).

mod axis;
mod cam;
mod device;
mod encoder;
mod ethercat;
mod hydraulic;
mod names;
mod objects;
mod security;
mod signal;

use crate::cell::{
    AxisEntry, AxisIndex, Cell, Coupling, DriveConnection, Leader, LeadingValueConfig, Node,
};
use crate::cell::{EncoderIndex, Realtime, LEADING_BUFFER};
use crate::error::{ConfigError, DelayShortfall, Problem};
use crate::schema::CellFile;
use std::path::Path;

/// A problem with one key of a section: the key (relative to the section) and the problem.
pub(crate) type FieldError = (&'static str, Problem);

/// The file being parsed: its name and source, to locate errors.
#[derive(Copy, Clone)]
pub(crate) struct Ctx<'a> {
    file: &'a str,
    src: &'a str,
}

impl Ctx<'_> {
    /// An error at a dotted key path, with the line of the key.
    fn at(&self, path: &[&str], problem: Problem) -> ConfigError {
        ConfigError {
            file: self.file.into(),
            line: locate(self.src, path),
            key: path.join("."),
            problem: Box::new(problem),
        }
    }

    /// An error at a dotted key path; an absent key (a default) points at its table
    /// (`<section>.<name>`).
    fn at_or_table(&self, path: &[&str], problem: Problem) -> ConfigError {
        let mut e = self.at(path, problem);
        if e.line.is_none() {
            e.line = locate(self.src, &path[..path.len().min(2)]);
        }
        e
    }

    /// An error at `key` of table `i` of the array of tables `array` (the table itself when
    /// `key` is empty).
    fn in_array(&self, array: &str, i: usize, key: &str, problem: Problem) -> ConfigError {
        ConfigError {
            file: self.file.into(),
            line: locate_in_array(self.src, array, i, key),
            key: if key.is_empty() {
                format!("{array}[{i}]")
            } else {
                format!("{array}[{i}].{key}")
            },
            problem: Box::new(problem),
        }
    }
}

/// The directory of the retained data, relative to the cell file's, without `[cell] retain_dir`.
const DEFAULT_RETAIN_DIR: &str = "retain";

/// A name that can stand in a file name, an iceoryx2 service name and a Zenoh key expression.
fn plain_name(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// The value named `value` among `options`, or [`Problem::NotOneOf`] at `key`.
pub(crate) fn pick<T: Copy>(
    key: &'static str,
    value: &str,
    options: &[(&'static str, T)],
) -> Result<T, FieldError> {
    options
        .iter()
        .find(|(n, _)| *n == value)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            (
                key,
                Problem::NotOneOf {
                    value: value.into(),
                    options: options.iter().map(|(n, _)| *n).collect(),
                },
            )
        })
}

/// The 1-based line of byte `offset` in `src`.
fn line_at(src: &str, offset: usize) -> usize {
    src[..offset.min(src.len())].matches('\n').count() + 1
}

/// Finds the 1-based line of `key` in table `index` of the array of tables `array` (or of the
/// table itself when `key` is empty), best effort.
pub fn locate_in_array(src: &str, array: &str, index: usize, key: &str) -> Option<usize> {
    let doc = toml_edit::ImDocument::parse(src).ok()?;
    let table = doc.get(array)?.as_array_of_tables()?.get(index)?;
    let span = if key.is_empty() {
        table.span()
    } else {
        match table.get_key_value(key) {
            Some((k, _)) => k.span(),
            None => table.span(),
        }
    }?;
    Some(line_at(src, span.start))
}

/// Finds the 1-based line of a dotted key path in TOML source (best effort).
pub fn locate(src: &str, path: &[&str]) -> Option<usize> {
    let doc = toml_edit::ImDocument::parse(src).ok()?;
    let mut item: &toml_edit::Item = doc.as_item();
    let mut span = None;
    for k in path {
        let table = item.as_table_like()?;
        let (key, next) = table.get_key_value(k)?;
        span = key.span().or(span);
        item = next;
    }
    Some(line_at(src, span?.start))
}

/// Loads and validates a cell file (cam CSV files and characteristic curves are read relative
/// to it).
pub fn load(path: &Path) -> Result<Cell, ConfigError> {
    let src = crate::read::read_text(path, crate::read::CELL_FILE_MAX)?;
    parse_in(&path.display().to_string(), &src, path.parent())
}

/// Parses and validates cell source text; `file` is used in error messages. Cam CSV files are
/// read relative to the current directory.
pub fn parse(file: &str, src: &str) -> Result<Cell, ConfigError> {
    parse_in(file, src, None)
}

/// Parses the TOML, then each section in turn.
fn parse_in(file: &str, src: &str, dir: Option<&Path>) -> Result<Cell, ConfigError> {
    let raw: CellFile = toml::from_str(src).map_err(|e| ConfigError {
        file: file.into(),
        line: e.span().map(|s| line_at(src, s.start)),
        key: String::new(),
        problem: Box::new(Problem::Syntax(e.message().to_string())),
    })?;
    let cx = Ctx { file, src };
    check_cell_section(cx, &raw)?;
    names::check(cx, &raw)?;
    let hosts = hosts(cx, &raw)?;
    let nodes = nodes(cx, &raw, &hosts)?;
    let devices = device::devices(cx, &raw, &nodes)?;
    let (devices, ethercat) = ethercat::segments(cx, &raw, &nodes, devices)?;
    let mut axes = axes(cx, &raw, &nodes)?;
    device::drives(cx, &raw, &mut axes, &devices, dir)?;
    leaders(cx, &raw, &mut axes)?;
    let mut encoders = encoder::encoders(cx, &raw, &axes, &nodes)?;
    let cams = cam::cams(cx, &raw, dir)?;
    leading_values(cx, &raw, &mut axes, &mut encoders, &nodes)?;
    let signals = signal::signals(cx, &raw, &devices, &axes)?;
    let mut objects = objects::objects(cx, &raw, &axes, &nodes)?;
    let bindings = signal::Bindings {
        nodes: &nodes,
        axes: &axes,
        devices: &devices,
        signals: &signals,
    };
    signal::outputs(
        cx,
        &raw,
        &bindings,
        &mut objects.output_cams,
        &mut objects.cam_tracks,
    )?;
    signal::switch_outputs(cx, &raw, &bindings, &mut objects.digital_cam_switches)?;
    let inputs = signal::inputs(cx, &raw, &bindings, &objects.measuring_inputs)?;
    signal::activate_limits(&raw, &inputs, &mut axes);
    let security = security::security(cx, &raw, dir)?;
    let base_tick_ns = us_to_ns(cx, &["cell", "base_tick_us"], raw.cell.base_tick_us)?;
    let ipc_budget_ns = us_to_ns(cx, &["cell", "ipc_budget_us"], raw.cell.ipc_budget_us)?;
    let network_budget_ns = us_to_ns(
        cx,
        &["cell", "network_budget_us"],
        raw.cell.network_budget_us,
    )?;
    Ok(Cell {
        name: raw.cell.name,
        base_tick_ns,
        ipc_budget_ns,
        network_budget_ns,
        host_listen: if raw.hosts.is_empty() {
            vec![Vec::new()]
        } else {
            raw.hosts.iter().map(|h| h.listen.clone()).collect()
        },
        telemetry_hz: raw.cell.telemetry_hz,
        clock_warning_fraction: raw.cell.clock_warning_fraction,
        command_rate_hz: raw.cell.command_rate_hz,
        command_burst: raw.cell.command_burst,
        // Range-checked in `check_cell_section` (at most one hour): no overflow.
        watchdog_ns: raw.cell.watchdog_ms as i64 * 1_000_000,
        watchdog_restart_ns: raw.cell.watchdog_restart_ms as i64 * 1_000_000,
        retain_dir: dir
            .unwrap_or(Path::new(""))
            .join(raw.cell.retain_dir.as_deref().unwrap_or(DEFAULT_RETAIN_DIR)),
        hosts,
        nodes,
        axes,
        encoders,
        cams,
        output_cams: objects.output_cams,
        cam_tracks: objects.cam_tracks,
        measuring_inputs: objects.measuring_inputs,
        digital_cam_switches: objects.digital_cam_switches,
        devices,
        signals,
        inputs,
        security,
        ethercat,
    })
}

/// `[cell]`: the base tick, the telemetry rate, the clock warning threshold and the retained
/// data's directory.
fn check_cell_section(cx: Ctx<'_>, raw: &CellFile) -> Result<(), ConfigError> {
    let c = &raw.cell;
    if c.base_tick_us == 0 {
        return Err(cx.at(
            &["cell", "base_tick_us"],
            Problem::Invalid("must be at least 1 µs"),
        ));
    }
    if !(c.telemetry_hz.is_finite() && c.telemetry_hz > 0.0 && c.telemetry_hz <= 1000.0) {
        return Err(cx.at(
            &["cell", "telemetry_hz"],
            Problem::Invalid("must be a rate in Hz, above 0 and at most 1000"),
        ));
    }
    if !(c.clock_warning_fraction > 0.0 && c.clock_warning_fraction <= 1.0) {
        return Err(cx.at(
            &["cell", "clock_warning_fraction"],
            Problem::Invalid("must be a share above 0 and at most 1"),
        ));
    }
    if !(c.command_rate_hz.is_finite() && c.command_rate_hz > 0.0 && c.command_rate_hz <= 10_000.0)
    {
        return Err(cx.at(
            &["cell", "command_rate_hz"],
            Problem::Invalid("must be a rate in Hz, above 0 and at most 10000"),
        ));
    }
    if !(1..=100_000).contains(&c.command_burst) {
        return Err(cx.at(
            &["cell", "command_burst"],
            Problem::Invalid("must be a number of commands from 1 to 100000"),
        ));
    }
    if !(MIN_WATCHDOG_MS..=MAX_MS).contains(&c.watchdog_ms) {
        return Err(cx.at(
            &["cell", "watchdog_ms"],
            Problem::Invalid("must be from 10 to 3600000 ms (one hour)"),
        ));
    }
    if !(c.watchdog_ms..=MAX_MS).contains(&c.watchdog_restart_ms) {
        return Err(cx.at(
            &["cell", "watchdog_restart_ms"],
            Problem::Invalid("must be at least watchdog_ms and at most 3600000 ms (one hour)"),
        ));
    }
    if c.retain_dir.as_deref().is_some_and(|d| d.trim().is_empty()) {
        return Err(cx.at(
            &["cell", "retain_dir"],
            Problem::Invalid("must name a directory"),
        ));
    }
    Ok(())
}

/// `[[hosts]]`: unique plain names (`local` when there are none).
fn hosts(cx: Ctx<'_>, raw: &CellFile) -> Result<Vec<String>, ConfigError> {
    let mut hosts: Vec<String> = Vec::new();
    for (i, h) in raw.hosts.iter().enumerate() {
        if hosts.contains(&h.name) || !plain_name(&h.name) {
            return Err(cx.in_array("hosts", i, "name", Problem::BadHostName(h.name.clone())));
        }
        hosts.push(h.name.clone());
    }
    if hosts.is_empty() {
        hosts.push("local".into());
    }
    Ok(hosts)
}

/// `[[nodes]]`: names, hosts, real-time settings and cycles (multiples of the base tick).
fn nodes(cx: Ctx<'_>, raw: &CellFile, hosts: &[String]) -> Result<Vec<Node>, ConfigError> {
    let base = raw.cell.base_tick_us;
    let mut nodes: Vec<Node> = Vec::new();
    for (i, n) in raw.nodes.iter().enumerate() {
        let at = |key: &str, problem| cx.in_array("nodes", i, key, problem);
        if !plain_name(&n.name) {
            return Err(at("name", Problem::BadNodeName(n.name.clone())));
        }
        let host = match &n.host {
            Some(h) => hosts.iter().position(|x| x == h).ok_or_else(|| {
                at(
                    "host",
                    Problem::Unknown {
                        what: "host",
                        name: h.clone(),
                        known: Some(hosts.to_vec()),
                    },
                )
            })?,
            None if hosts.len() == 1 => 0,
            None => return Err(at("host", Problem::HostRequired(n.name.clone()))),
        };
        if let Some(p) = n.realtime.priority.filter(|p| !(1..=99).contains(p)) {
            return Err(at("realtime", Problem::Priority(p)));
        }
        if n.cycle_us > MAX_US || n.cycle_us == 0 || n.cycle_us % base != 0 {
            return Err(cx.at(
                &["nodes"],
                Problem::Cycle {
                    node: n.name.clone(),
                    cycle_us: n.cycle_us,
                    base_us: base,
                },
            ));
        }
        if nodes.iter().any(|x| x.name == n.name) {
            return Err(cx.at(&["nodes"], Problem::DuplicateNode(n.name.clone())));
        }
        nodes.push(Node {
            name: n.name.clone(),
            cycle_ns: n.cycle_us as i64 * 1000,
            host,
            realtime: Realtime {
                priority: n.realtime.priority,
                cpu: n.realtime.cpu,
                lock_memory: n.realtime.lock_memory,
            },
        });
    }
    Ok(nodes)
}

/// The index of the node named `name`, or [`Problem::UnknownNode`] at `path`.
fn node_named(
    cx: Ctx<'_>,
    nodes: &[Node],
    name: &str,
    path: &[&str],
) -> Result<usize, ConfigError> {
    nodes
        .iter()
        .position(|n| n.name == name)
        .ok_or_else(|| cx.at(path, Problem::UnknownNode(name.into())))
}

/// `[axes.<name>]`: each axis' node and engine configuration, validated by the engine. Leaders
/// and leading values follow once every leader is known.
fn axes(cx: Ctx<'_>, raw: &CellFile, nodes: &[Node]) -> Result<Vec<AxisEntry>, ConfigError> {
    let mut axes = Vec::new();
    for (name, a) in &raw.axes {
        let node = node_named(cx, nodes, &a.node, &["axes", name, "node"])?;
        let cycle = nodes[node].cycle_ns as f64 * 1e-9;
        let config = axis::axis_config(a, cycle).map_err(|(k, p)| {
            if k.contains('.') {
                let mut path = vec!["axes", name.as_str()];
                path.extend(k.split('.'));
                cx.at_or_table(&path, p)
            } else {
                cx.at(&["axes", name, k], p)
            }
        })?;
        config.validate().map_err(|e| {
            let mut path = vec!["axes", name.as_str()];
            path.extend(e.field.split('.'));
            cx.at_or_table(&path, Problem::Axis(e.problem))
        })?;
        axes.push(AxisEntry {
            name: name.clone(),
            node,
            config,
            leaders: None,
            leading: LeadingValueConfig {
                delay_ns: 0,
                tolerance_ns: 0,
            },
            drive: DriveConnection::Simulation,
        });
    }
    Ok(axes)
}

/// `[axes.<name>.leaders]`: the leaders each axis may follow, by name (axes and encoders),
/// and how it reads them.
fn leaders(cx: Ctx<'_>, raw: &CellFile, axes: &mut [AxisEntry]) -> Result<(), ConfigError> {
    let names: Vec<String> = axes
        .iter()
        .map(|a| a.name.clone())
        .chain(raw.encoders.keys().cloned())
        .collect();
    let n_axes = axes.len();
    for (entry, (name, a)) in axes.iter_mut().zip(raw.axes.iter()) {
        let Some(table) = &a.leaders else {
            continue;
        };
        let mut list = Vec::new();
        for (key, kind) in table {
            let path = ["axes", name.as_str(), "leaders", key.as_str()];
            // `node/to` names the leader's node too; it must be the node that hosts it.
            let (leader_node, leader) = match key.split_once('/') {
                Some((n, to)) => (Some(n), to),
                None => (None, key.as_str()),
            };
            let idx = names.iter().position(|n| n == leader).ok_or_else(|| {
                cx.at(
                    &path,
                    Problem::Unknown {
                        what: "leader",
                        name: leader.into(),
                        known: Some(names.clone()),
                    },
                )
            })?;
            if leader == name {
                return Err(cx.at(&path, Problem::SelfLeader));
            }
            if let Some(n) = leader_node {
                let hosted = match raw.axes.get(leader) {
                    Some(x) => &x.node,
                    None => raw.encoders.get(leader).map(|e| &e.node).unwrap_or(&a.node),
                };
                if hosted != n {
                    let problem = Problem::LeaderNode {
                        leader: leader.into(),
                        hosted: hosted.clone(),
                        named: n.into(),
                    };
                    return Err(cx.at(&path, problem));
                }
            }
            let coupling = pick(
                "",
                kind,
                &[
                    ("setpoint", Coupling::Setpoint),
                    ("actual", Coupling::Actual),
                ],
            )
            .map_err(|(_, p)| cx.at(&path, p))?;
            let leader = if idx < n_axes {
                Leader::Axis(AxisIndex(idx))
            } else {
                Leader::Encoder(EncoderIndex(idx - n_axes))
            };
            list.push((leader, coupling));
        }
        entry.leaders = Some(list);
    }
    Ok(())
}

/// The leading-value delay and tolerance of every leader (`[axes.<name>.leading_value]`,
/// `[encoders.<name>.leading_value]`), checked against the buffer and against the links its
/// followers need.
fn leading_values(
    cx: Ctx<'_>,
    raw: &CellFile,
    axes: &mut [AxisEntry],
    encoders: &mut [crate::cell::EncoderEntry],
    nodes: &[Node],
) -> Result<(), ConfigError> {
    let sections = raw
        .axes
        .iter()
        .map(|(n, a)| ("axes", n, a.leading_value.as_ref()))
        .chain(
            raw.encoders
                .iter()
                .map(|(n, e)| ("encoders", n, e.leading_value.as_ref())),
        );
    let slots = axes
        .iter_mut()
        .map(|a| (a.node, &mut a.leading))
        .chain(encoders.iter_mut().map(|e| (e.node, &mut e.leading)));
    for ((table, name, section), (node, slot)) in sections.zip(slots) {
        let cycle = nodes[node].cycle_ns;
        let key = |k: &'static str| [table, name.as_str(), "leading_value", k];
        let delay_ns = match section {
            Some(s) => us_to_ns(cx, &key("delay_us"), s.delay_us)?,
            None => 0,
        };
        let tolerance_ns = match section.and_then(|s| s.tolerance_us) {
            Some(t) => us_to_ns(cx, &key("tolerance_us"), t)?,
            None => 2 * cycle,
        };
        let depth = (delay_ns + tolerance_ns) / cycle + 4;
        if depth > LEADING_BUFFER as i64 {
            let problem = Problem::LeadingBuffer {
                cycles: depth - 4,
                node: nodes[node].name.clone(),
                max: LEADING_BUFFER - 4,
            };
            return Err(cx.at_or_table(&[table, name, "leading_value", "delay_us"], problem));
        }
        *slot = LeadingValueConfig {
            delay_ns,
            tolerance_ns,
        };
    }
    check_links(cx, raw, axes, encoders, nodes)
}

/// The longest time a `*_us` key may give: one hour. Larger values (up to 2^64 - 1 in the
/// file) would wrap when turned into nanoseconds; no cycle, delay or budget is that long.
const MAX_US: u64 = 3_600_000_000;

/// The longest time a `*_ms` key may give: one hour.
const MAX_MS: u64 = 3_600_000;

/// The shortest watchdog: 10 ms (`tandem up` looks at its processes every few ms; the nodes
/// publish their health at twice `telemetry_hz`).
const MIN_WATCHDOG_MS: u64 = 10;

/// A `*_us` key's value in ns, or the error naming the key at `path` when it is over
/// [`MAX_US`].
fn us_to_ns(cx: Ctx<'_>, path: &[&str], us: u64) -> Result<i64, ConfigError> {
    if us > MAX_US {
        return Err(cx.at_or_table(
            path,
            Problem::Invalid("must be at most 3600000000 µs (one hour)"),
        ));
    }
    // At most 3.6e12 ns: no overflow.
    Ok(us as i64 * 1000)
}

/// A follower on another node than its leader needs `D >= leader cycle + link budget +
/// follower cycle`, the link being `ipc_budget_us` on one host and `network_budget_us`
/// between hosts (the leading-value delay, docs/processes.md).
fn check_links(
    cx: Ctx<'_>,
    raw: &CellFile,
    axes: &[AxisEntry],
    encoders: &[crate::cell::EncoderEntry],
    nodes: &[Node],
) -> Result<(), ConfigError> {
    // Checked against MAX_US when the cell was built (`us_to_ns`); saturating here only so that
    // this function cannot overflow on its own.
    let ipc = (raw.cell.ipc_budget_us.min(MAX_US) as i64).saturating_mul(1000);
    let net = (raw.cell.network_budget_us.min(MAX_US) as i64).saturating_mul(1000);
    let axis_names: Vec<&String> = raw.axes.keys().collect();
    let encoder_names: Vec<&String> = raw.encoders.keys().collect();
    for f in axes {
        for (leader, _) in f.leaders.iter().flatten() {
            let (table, lname, l_node, lv) = match *leader {
                Leader::Axis(a) => ("axes", axis_names[a.0], axes[a.0].node, axes[a.0].leading),
                Leader::Encoder(e) => (
                    "encoders",
                    encoder_names[e.0],
                    encoders[e.0].node,
                    encoders[e.0].leading,
                ),
            };
            if l_node == f.node {
                continue;
            }
            let (link, budget) = if nodes[l_node].host == nodes[f.node].host {
                (ipc, "ipc_budget_us")
            } else {
                (net, "network_budget_us")
            };
            let need = nodes[l_node].cycle_ns + link + nodes[f.node].cycle_ns;
            if lv.delay_ns < need {
                let problem = Problem::DelayTooShort(DelayShortfall {
                    delay_us: lv.delay_ns / 1000,
                    follower: f.name.clone(),
                    node: nodes[f.node].name.clone(),
                    need_us: need / 1000,
                    leader_cycle_us: nodes[l_node].cycle_ns / 1000,
                    budget,
                    link_us: link / 1000,
                    follower_cycle_us: nodes[f.node].cycle_ns / 1000,
                });
                return Err(cx.at_or_table(&[table, lname, "leading_value", "delay_us"], problem));
            }
        }
    }
    Ok(())
}
