//! tandem-config: the cell file (TOML) to a validated, typed configuration.
//!
//! Every error names the file, the line and the key, and says what is wrong. The same module
//! parses instruction names and parameters (`command`) for the simulator script and the CLI.

pub mod command;
mod schema;
pub mod script;

use schema::{AxisSection, CellFile};
use std::path::Path;
use tandem_motion::catalog::alarm::Reaction;
use tandem_motion::kinematics::dynamics::{DynamicDefaults, DynamicLimits};
use tandem_motion::kinematics::extrapolation::{ExtrapolationConfig, VelocityMode};
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{
    AxisConfig, AxisKind, EncoderType, FollowingErrorMonitoring, HomingConfig, HomingMark,
    MotionType, PassiveDirection, PositioningMonitoring, Sense, SoftwareLimits, StandstillSignal,
};
use tandem_motion::plant::drive::{DriveModel, Plant, ZeroMark};

/// A problem in a configuration file, located.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// File (as given).
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// Dotted key path, when known.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: ", self.file, l)?,
            None => write!(f, "{}: ", self.file)?,
        }
        if self.key.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.key, self.message)
        }
    }
}

impl std::error::Error for ConfigError {}

/// A node of the cell: one process with one servo cycle.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Name.
    pub name: String,
    /// Servo cycle (ns).
    pub cycle_ns: i64,
    /// Index into [`Cell::hosts`].
    pub host: usize,
    /// Scheduling of the cyclic thread.
    pub realtime: Realtime,
}

/// Scheduling of a node's cyclic thread (`[nodes.realtime]`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Realtime {
    /// SCHED_FIFO priority 1..=99; `None`: normal scheduling.
    pub priority: Option<u8>,
    /// CPU the cyclic thread is pinned to.
    pub cpu: Option<usize>,
    /// Lock the process' memory.
    pub lock_memory: bool,
}

/// How followers receive a leader's values (`[axes.<name>.leading_value]`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct LeadingValueConfig {
    /// Leading-value delay D (ns): every follower evaluates the leader at `t - D`.
    pub delay_ns: i64,
    /// How long a late sample is bridged by extrapolation (ns).
    pub tolerance_ns: i64,
}

/// How a follower reads a leader.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Coupling {
    /// The leader's setpoint.
    Setpoint,
    /// The leader's actual value, filtered and extrapolated.
    Actual,
}

/// An axis of the cell, with the node that hosts it.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisEntry {
    /// Name (unique in the cell).
    pub name: String,
    /// Index into [`Cell::nodes`].
    pub node: usize,
    /// Engine configuration.
    pub config: AxisConfig,
    /// The leaders it may follow (index into [`Cell::axes`]) and how; `None`: any, by setpoint.
    pub leaders: Option<Vec<(usize, Coupling)>>,
}

impl AxisEntry {
    /// How this axis reads leader `leader`, or `None` if it may not follow it.
    pub fn coupling(&self, leader: usize) -> Option<Coupling> {
        match &self.leaders {
            None => Some(Coupling::Setpoint),
            Some(list) => list.iter().find(|(i, _)| *i == leader).map(|(_, c)| *c),
        }
    }
}

/// Where a simulated external encoder gets its position from.
#[derive(Clone, Debug, PartialEq)]
pub enum EncoderSource {
    /// The actual position of an axis (index into [`Cell::axes`]) times `scale`.
    Axis {
        /// The measured axis.
        axis: usize,
        /// Encoder units per axis unit.
        scale: f64,
    },
    /// A velocity profile: `(t s, v)` points, linear in between, constant after the last.
    Profile(Vec<(f64, f64)>),
}

impl EncoderSource {
    /// Position and velocity of a profile source at `t` (s), from 0 at t = 0.
    pub fn profile_at(points: &[(f64, f64)], t: f64) -> (f64, f64) {
        let mut p = 0.0;
        let mut prev = (0.0, points.first().map(|x| x.1).unwrap_or(0.0));
        for &(ti, vi) in points {
            if t <= ti {
                let span = ti - prev.0;
                let f = if span > 0.0 { (t - prev.0) / span } else { 1.0 };
                let v = prev.1 + (vi - prev.1) * f;
                return (p + 0.5 * (prev.1 + v) * (t - prev.0), v);
            }
            p += 0.5 * (prev.1 + vi) * (ti - prev.0);
            prev = (ti, vi);
        }
        (p + prev.1 * (t - prev.0), prev.1)
    }
}

/// An external encoder of the cell.
#[derive(Clone, Debug, PartialEq)]
pub struct EncoderEntry {
    /// Name (unique among axes and encoders).
    pub name: String,
    /// Index into [`Cell::nodes`].
    pub node: usize,
    /// Engine configuration.
    pub config: tandem_motion::objects::encoder::EncoderConfig,
    /// Simulated source.
    pub source: EncoderSource,
}

/// A cam of the cell, interpolated.
#[derive(Clone, Debug)]
pub struct CamEntry {
    /// Name.
    pub name: String,
    /// The interpolated cam, shared by every job that uses it.
    pub cam: std::sync::Arc<tandem_motion::cam::Cam>,
    /// Its definition (for MC_InterpolateCam at run time).
    pub definition: tandem_motion::cam::CamDefinition,
}

impl PartialEq for CamEntry {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name && std::sync::Arc::ptr_eq(&self.cam, &other.cam)
    }
}

/// An output cam of the cell (`[[output_cams]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct OutputCamEntry {
    /// Name (unique among all objects).
    pub name: String,
    /// Index into [`Cell::axes`].
    pub axis: usize,
    /// Engine configuration.
    pub config: tandem_motion::objects::output_cam::OutputCamConfig,
}

/// A cam track of the cell (`[[cam_tracks]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct CamTrackEntry {
    /// Name (unique among all objects).
    pub name: String,
    /// Index into [`Cell::axes`].
    pub axis: usize,
    /// Engine configuration.
    pub config: tandem_motion::objects::cam_track::CamTrackConfig,
    /// Track data (reference, length, cams).
    pub data: tandem_motion::objects::cam_track::CamTrackData,
}

/// A simulated mark sensor on a measuring input.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SensorEntry {
    /// The axis that carries the mark (index into [`Cell::axes`]).
    pub axis: usize,
    /// Mark start.
    pub position: f64,
    /// Mark width.
    pub width: f64,
    /// Dead time (s).
    pub dead_time: f64,
    /// Jitter (ns, uniform in ±).
    pub jitter_ns: i64,
    /// Seed of the jitter.
    pub seed: u64,
    /// Direction that produces edges.
    pub direction: tandem_motion::plant::sensor::SensorDirection,
}

impl SensorEntry {
    /// The engine's simulated sensor.
    pub fn sensor(&self) -> tandem_motion::plant::sensor::SimulatedSensor {
        tandem_motion::plant::sensor::SimulatedSensor::new(
            self.position,
            self.width,
            self.dead_time,
            self.jitter_ns,
            self.seed,
            self.direction,
        )
    }
}

/// A measuring input of the cell (`[[measuring_inputs]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuringInputEntry {
    /// Name (unique among all objects).
    pub name: String,
    /// Index into [`Cell::axes`].
    pub axis: usize,
    /// Engine configuration.
    pub config: tandem_motion::objects::measuring::MeasuringInputConfig,
    /// Optional simulated sensor producing the input's edges.
    pub sensor: Option<SensorEntry>,
    /// Optional register correction.
    pub registration: Option<Registration>,
}

/// Register correction of a measuring input: each new `MeasuredValue1` of a cyclic job moves
/// `axis` by `gain * (target - measured)`, reduced to ±half the measured axis' modulo length,
/// with `MC_MoveSuperimposed`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Registration {
    /// The corrected axis (index into [`Cell::axes`]).
    pub axis: usize,
    /// The register target.
    pub target: f64,
    /// Share of the error corrected per mark.
    pub gain: f64,
}

/// A validated cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Cell name.
    pub name: String,
    /// Base tick (ns).
    pub base_tick_ns: i64,
    /// Time budget of a leading value between two nodes of one host (ns).
    pub ipc_budget_ns: i64,
    /// Time budget of a leading value between nodes of different hosts (ns).
    pub network_budget_ns: i64,
    /// Host names (`local` when the file has no `[[hosts]]`).
    pub hosts: Vec<String>,
    /// Per host: the Zenoh endpoints its gateway listens on.
    pub host_listen: Vec<Vec<String>>,
    /// Telemetry rate of the gateways (Hz).
    pub telemetry_hz: f64,
    /// Clock-offset warning threshold, as a share of the smallest cross-host delay.
    pub clock_warning_fraction: f64,
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Axes, in name order.
    pub axes: Vec<AxisEntry>,
    /// External encoders, in name order. As leaders they are numbered after the axes.
    pub encoders: Vec<EncoderEntry>,
    /// Cams, in name order (a cam's id is its index here).
    pub cams: Vec<CamEntry>,
    /// Output cams, in file order.
    pub output_cams: Vec<OutputCamEntry>,
    /// Cam tracks, in file order.
    pub cam_tracks: Vec<CamTrackEntry>,
    /// Measuring inputs, in file order.
    pub measuring_inputs: Vec<MeasuringInputEntry>,
    /// Per leader (axes, then encoders, as in [`Cell::object_names`]): its leading-value delay
    /// and tolerance.
    pub leading: Vec<LeadingValueConfig>,
}

impl Cell {
    /// How axis `follower` reads leader `leader` (axes, then encoders), or `None` if it may not
    /// follow it. Without a `leaders` table an axis may follow any leader of its own node, by
    /// setpoint.
    pub fn coupling(&self, follower: usize, leader: usize) -> Option<Coupling> {
        let f = self.axes.get(follower)?;
        match &f.leaders {
            Some(_) => f.coupling(leader),
            None => (self.leader_node(leader)? == f.node).then_some(Coupling::Setpoint),
        }
    }

    /// The node that hosts leader `leader` (axes, then encoders).
    pub fn leader_node(&self, leader: usize) -> Option<usize> {
        match self.axes.get(leader) {
            Some(a) => Some(a.node),
            None => self
                .encoders
                .get(leader.checked_sub(self.axes.len())?)
                .map(|e| e.node),
        }
    }

    /// The leaders of other nodes that followers on `node` may follow (sorted, unique).
    pub fn remote_leaders(&self, node: usize) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .axes
            .iter()
            .filter(|a| a.node == node)
            .flat_map(|a| a.leaders.iter().flatten().map(|(l, _)| *l))
            .filter(|l| self.leader_node(*l) != Some(node))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The leaders on `node` that followers on other nodes may follow (sorted, unique).
    pub fn published_leaders(&self, node: usize) -> Vec<usize> {
        let mut out: Vec<usize> = (0..self.nodes.len())
            .filter(|n| *n != node)
            .flat_map(|n| self.remote_leaders(n))
            .filter(|l| self.leader_node(*l) == Some(node))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The samples of leader `leader` its iceoryx2 service keeps for late joiners and each
    /// subscriber buffers: the delay plus the tolerance in leader cycles, plus four.
    pub fn leading_history(&self, leader: usize) -> usize {
        let Some(lv) = self.leading.get(leader) else {
            return 4;
        };
        let cycle = self
            .leader_node(leader)
            .map_or(1_000_000, |n| self.nodes[n].cycle_ns);
        (((lv.delay_ns + lv.tolerance_ns) / cycle.max(1)) as usize + 4).min(LEADING_BUFFER)
    }

    /// The index of the node named `name`.
    pub fn node(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }

    /// The names of all technology objects that can be addressed or lead: axes, then encoders
    /// (a leader's id is its index here).
    pub fn object_names(&self) -> Vec<&str> {
        self.axes
            .iter()
            .map(|a| a.name.as_str())
            .chain(self.encoders.iter().map(|e| e.name.as_str()))
            .collect()
    }

    /// The index of the output cam named `name`.
    pub fn output_cam(&self, name: &str) -> Option<usize> {
        self.output_cams.iter().position(|c| c.name == name)
    }

    /// The index of the cam track named `name`.
    pub fn cam_track(&self, name: &str) -> Option<usize> {
        self.cam_tracks.iter().position(|c| c.name == name)
    }

    /// The index of the measuring input named `name`.
    pub fn measuring_input(&self, name: &str) -> Option<usize> {
        self.measuring_inputs.iter().position(|c| c.name == name)
    }
}

/// A name that can stand in a file name, an iceoryx2 service name and a Zenoh key expression.
fn plain_name(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
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
    Some(src[..span.start.min(src.len())].matches('\n').count() + 1)
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
    let offset = span?.start;
    Some(src[..offset.min(src.len())].matches('\n').count() + 1)
}

fn line_of_toml_error(e: &toml::de::Error, src: &str) -> Option<usize> {
    e.span()
        .map(|s| src[..s.start.min(src.len())].matches('\n').count() + 1)
}

/// Loads and validates a cell file (cam CSV files are read relative to it).
pub fn load(path: &Path) -> Result<Cell, ConfigError> {
    let file = path.display().to_string();
    let src = std::fs::read_to_string(path).map_err(|e| ConfigError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read: {e}"),
    })?;
    parse_in(&file, &src, path.parent())
}

/// Parses and validates cell source text; `file` is used in error messages. Cam CSV files are
/// read relative to the current directory.
pub fn parse(file: &str, src: &str) -> Result<Cell, ConfigError> {
    parse_in(file, src, None)
}

fn parse_in(file: &str, src: &str, dir: Option<&Path>) -> Result<Cell, ConfigError> {
    let raw: CellFile = toml::from_str(src).map_err(|e| ConfigError {
        file: file.into(),
        line: line_of_toml_error(&e, src),
        key: String::new(),
        message: e.message().to_string(),
    })?;
    let err = |path: &[&str], message: String| ConfigError {
        file: file.into(),
        line: locate(src, path),
        key: path.join("."),
        message,
    };
    if raw.cell.base_tick_us == 0 {
        return Err(err(
            &["cell", "base_tick_us"],
            "must be at least 1 µs".into(),
        ));
    }
    let base = raw.cell.base_tick_us;
    if !(raw.cell.telemetry_hz.is_finite()
        && raw.cell.telemetry_hz > 0.0
        && raw.cell.telemetry_hz <= 1000.0)
    {
        return Err(err(
            &["cell", "telemetry_hz"],
            "must be a rate in Hz, above 0 and at most 1000".into(),
        ));
    }
    if !(raw.cell.clock_warning_fraction > 0.0 && raw.cell.clock_warning_fraction <= 1.0) {
        return Err(err(
            &["cell", "clock_warning_fraction"],
            "must be a share above 0 and at most 1".into(),
        ));
    }
    let mut hosts: Vec<String> = Vec::new();
    for (i, h) in raw.hosts.iter().enumerate() {
        if hosts.contains(&h.name) || !plain_name(&h.name) {
            return Err(ConfigError {
                file: file.into(),
                line: locate_in_array(src, "hosts", i, "name"),
                key: format!("hosts[{i}].name"),
                message: format!("host `{}` is defined twice, empty or contains `/`", h.name),
            });
        }
        hosts.push(h.name.clone());
    }
    if hosts.is_empty() {
        hosts.push("local".into());
    }
    let mut nodes = Vec::new();
    for (i, n) in raw.nodes.iter().enumerate() {
        let at = |key: &str, message: String| ConfigError {
            file: file.into(),
            line: locate_in_array(src, "nodes", i, key),
            key: format!("nodes[{i}].{key}"),
            message,
        };
        if !plain_name(&n.name) {
            return Err(at(
                "name",
                format!(
                    "`{}`: a node name is a plain name (letters, digits, `_`, `-`; it names services and keys)",
                    n.name
                ),
            ));
        }
        let host = match &n.host {
            Some(h) => hosts.iter().position(|x| x == h).ok_or_else(|| {
                at(
                    "host",
                    format!("unknown host `{h}`; the cell has: {}", hosts.join(", ")),
                )
            })?,
            None if hosts.len() == 1 => 0,
            None => {
                return Err(at(
                    "host",
                    format!(
                        "node `{}` needs `host = ...`: the cell has several hosts",
                        n.name
                    ),
                ))
            }
        };
        if let Some(p) = n.realtime.priority {
            if !(1..=99).contains(&p) {
                return Err(at(
                    "realtime",
                    format!("priority = {p}: SCHED_FIFO priorities are 1 to 99"),
                ));
            }
        }
        if n.cycle_us == 0 || n.cycle_us % base != 0 {
            return Err(err(
                &["nodes"],
                format!(
                    "node `{}`: cycle_us = {} is not a positive multiple of the base tick ({base} µs)",
                    n.name, n.cycle_us
                ),
            ));
        }
        if nodes.iter().any(|x: &Node| x.name == n.name) {
            return Err(err(
                &["nodes"],
                format!("node `{}` is defined twice", n.name),
            ));
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
    let mut axes = Vec::new();
    for (name, a) in &raw.axes {
        let node = nodes.iter().position(|n| n.name == a.node).ok_or_else(|| {
            err(
                &["axes", name, "node"],
                format!("unknown node `{}` (define it in [[nodes]])", a.node),
            )
        })?;
        let cycle = nodes[node].cycle_ns as f64 * 1e-9;
        let config = axis_config(a, cycle).map_err(|(k, m)| err(&["axes", name, k], m))?;
        config.validate().map_err(|e| {
            let parts: Vec<&str> = e.field.split('.').collect();
            let mut path = vec!["axes", name.as_str()];
            path.extend(parts.iter().copied());
            let mut located = err(&path, e.problem.to_string());
            if located.line.is_none() {
                // The key is absent (a default); point at the axis table.
                located.line = locate(src, &["axes", name]);
            }
            located
        })?;
        axes.push(AxisEntry {
            name: name.clone(),
            node,
            config,
            leaders: None,
        });
    }
    // Leader tables refer to axes and encoders by name: resolve them once all are known.
    let names: Vec<String> = axes
        .iter()
        .map(|a| a.name.clone())
        .chain(raw.encoders.keys().cloned())
        .collect();
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
                err(
                    &path,
                    format!(
                        "unknown leader `{leader}`; the cell has: {}",
                        names.join(", ")
                    ),
                )
            })?;
            if leader == name {
                return Err(err(&path, "an axis cannot lead itself".into()));
            }
            if let Some(n) = leader_node {
                let hosted = match raw.axes.get(leader) {
                    Some(x) => &x.node,
                    None => raw.encoders.get(leader).map(|e| &e.node).unwrap_or(&a.node),
                };
                if hosted != n {
                    return Err(err(
                        &path,
                        format!("`{leader}` is on node `{hosted}`, not `{n}`"),
                    ));
                }
            }
            let coupling = match kind.as_str() {
                "setpoint" => Coupling::Setpoint,
                "actual" => Coupling::Actual,
                other => {
                    return Err(err(
                        &path,
                        format!("`{other}` is not one of setpoint, actual"),
                    ));
                }
            };
            list.push((idx, coupling));
        }
        entry.leaders = Some(list);
    }
    let mut encoders = Vec::new();
    for (name, e) in &raw.encoders {
        if raw.axes.contains_key(name) {
            return Err(err(
                &["encoders", name],
                format!("`{name}` is also an axis: names must be unique"),
            ));
        }
        let node = nodes.iter().position(|n| n.name == e.node).ok_or_else(|| {
            err(
                &["encoders", name, "node"],
                format!("unknown node `{}` (define it in [[nodes]])", e.node),
            )
        })?;
        let encoder = pick(
            "encoder",
            &e.encoder,
            &[
                ("incremental", EncoderType::Incremental),
                ("absolute", EncoderType::Absolute),
            ],
        )
        .map_err(|(k, m)| err(&["encoders", name, k], m))?;
        let source = match e.source.as_str() {
            "axis" => {
                let axis_name = e.axis.as_deref().ok_or_else(|| {
                    err(
                        &["encoders", name, "source"],
                        "source = \"axis\" needs `axis = \"<name>\"`".into(),
                    )
                })?;
                let axis = axes
                    .iter()
                    .position(|a| a.name == axis_name)
                    .ok_or_else(|| {
                        err(
                            &["encoders", name, "axis"],
                            format!("unknown axis `{axis_name}`"),
                        )
                    })?;
                if !(e.scale.is_finite() && e.scale != 0.0) {
                    return Err(err(
                        &["encoders", name, "scale"],
                        "must be a non-zero number".into(),
                    ));
                }
                EncoderSource::Axis {
                    axis,
                    scale: e.scale,
                }
            }
            "profile" => {
                let pts = e.profile.as_ref().ok_or_else(|| {
                    err(
                        &["encoders", name, "source"],
                        "source = \"profile\" needs `profile = [[t, v], ...]`".into(),
                    )
                })?;
                let mut last = 0.0;
                for [t, v] in pts {
                    if !(t.is_finite() && v.is_finite() && *t >= last) {
                        return Err(err(
                            &["encoders", name, "profile"],
                            "points must be finite [time, velocity] pairs with times rising from 0"
                                .into(),
                        ));
                    }
                    last = *t;
                }
                EncoderSource::Profile(pts.iter().map(|[t, v]| (*t, *v)).collect())
            }
            other => {
                return Err(err(
                    &["encoders", name, "source"],
                    format!("`{other}` is not one of axis, profile"),
                ));
            }
        };
        let x = &e.extrapolation;
        let config = tandem_motion::objects::encoder::EncoderConfig {
            cycle: nodes[node].cycle_ns as f64 * 1e-9,
            modulo: e.modulo.as_ref().map(|m| Modulo {
                start: m.start,
                length: m.length,
            }),
            encoder,
            extrapolation: ExtrapolationConfig {
                position_t1: x.position_t1,
                position_t2: x.position_t2,
                velocity_t1: x.velocity_t1,
                velocity_t2: x.velocity_t2,
                velocity_tolerance: x.velocity_tolerance,
                hysteresis: x.hysteresis,
                following_time: x.following_time,
                acquisition_time: x.acquisition_time,
                system_defined: x.system_defined,
                velocity_mode: pick(
                    "extrapolation.velocity_mode",
                    &x.velocity_mode,
                    &[
                        ("filtered", VelocityMode::Filtered),
                        ("differentiation", VelocityMode::Differentiation),
                    ],
                )
                .map_err(|(k, m)| err(&["encoders", name, k], m))?,
            },
        };
        if let Some(m) = config.modulo {
            if !(m.length.is_finite() && m.length > 0.0 && m.start.is_finite()) {
                return Err(err(
                    &["encoders", name, "modulo"],
                    "length must be positive".into(),
                ));
            }
        }
        encoders.push(EncoderEntry {
            name: name.clone(),
            node,
            config,
            source,
        });
    }
    let mut cams = Vec::new();
    for (name, c) in &raw.cams {
        let (cam, definition) = cam_from(c, dir).map_err(|(key, message)| {
            let mut path = vec!["cams", name.as_str()];
            if !key.is_empty() {
                path.push(key);
            }
            let mut e = err(&path, message);
            if e.line.is_none() {
                e.line = locate(src, &["cams", name]);
            }
            e
        })?;
        cams.push(CamEntry {
            name: name.clone(),
            cam: std::sync::Arc::new(cam),
            definition,
        });
    }
    let leading = leading_values(file, src, &raw, &axes, &encoders, &nodes)?;
    let objects = objects(file, src, &raw, &axes, &nodes)?;
    Ok(Cell {
        name: raw.cell.name,
        base_tick_ns: base as i64 * 1000,
        ipc_budget_ns: raw.cell.ipc_budget_us as i64 * 1000,
        network_budget_ns: raw.cell.network_budget_us as i64 * 1000,
        host_listen: if raw.hosts.is_empty() {
            vec![Vec::new()]
        } else {
            raw.hosts.iter().map(|h| h.listen.clone()).collect()
        },
        telemetry_hz: raw.cell.telemetry_hz,
        clock_warning_fraction: raw.cell.clock_warning_fraction,
        hosts,
        leading,
        nodes,
        axes,
        encoders,
        cams,
        output_cams: objects.0,
        cam_tracks: objects.1,
        measuring_inputs: objects.2,
    })
}

/// Samples a leader's buffer holds at each follower: the delay plus the tolerance, in leader
/// cycles, must fit with a margin of four samples.
pub const LEADING_BUFFER: usize = 256;

/// The leading-value delay and tolerance of every leader, checked against the links its
/// followers need: a follower on another node needs `D >= leader cycle + link budget +
/// follower cycle` (design §4), the link being `ipc_budget_us` on one host and
/// `network_budget_us` between hosts.
fn leading_values(
    file: &str,
    src: &str,
    raw: &CellFile,
    axes: &[AxisEntry],
    encoders: &[EncoderEntry],
    nodes: &[Node],
) -> Result<Vec<LeadingValueConfig>, ConfigError> {
    let err = |path: &[&str], message: String| {
        let line = locate(src, path).or_else(|| locate(src, &path[..2]));
        ConfigError {
            file: file.into(),
            line,
            key: path.join("."),
            message,
        }
    };
    let sections = raw
        .axes
        .iter()
        .map(|(n, a)| ("axes", n, a.leading_value.as_ref()))
        .chain(
            raw.encoders
                .iter()
                .map(|(n, e)| ("encoders", n, e.leading_value.as_ref())),
        );
    let leader_nodes = axes
        .iter()
        .map(|a| a.node)
        .chain(encoders.iter().map(|e| e.node));
    let mut out = Vec::new();
    for ((table, name, section), node) in sections.zip(leader_nodes) {
        let cycle = nodes[node].cycle_ns;
        let delay_ns = section.map_or(0, |s| s.delay_us as i64 * 1000);
        let tolerance_ns = section
            .and_then(|s| s.tolerance_us)
            .map_or(2 * cycle, |t| t as i64 * 1000);
        let depth = (delay_ns + tolerance_ns) / cycle + 4;
        if depth > LEADING_BUFFER as i64 {
            return Err(err(
                &[table, name, "leading_value", "delay_us"],
                format!(
                    "delay plus tolerance span {} cycles of node `{}`; at most {} fit the buffer",
                    depth - 4,
                    nodes[node].name,
                    LEADING_BUFFER - 4
                ),
            ));
        }
        out.push(LeadingValueConfig {
            delay_ns,
            tolerance_ns,
        });
    }
    let ipc = raw.cell.ipc_budget_us as i64 * 1000;
    let net = raw.cell.network_budget_us as i64 * 1000;
    let names: Vec<(&str, &String)> = raw
        .axes
        .keys()
        .map(|n| ("axes", n))
        .chain(raw.encoders.keys().map(|n| ("encoders", n)))
        .collect();
    for (follower, f) in axes.iter().enumerate() {
        for (leader, _) in f.leaders.iter().flatten() {
            let l_node = if *leader < axes.len() {
                axes[*leader].node
            } else {
                encoders[*leader - axes.len()].node
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
            let (table, lname) = names[*leader];
            if out[*leader].delay_ns < need {
                return Err(err(
                    &[table, lname, "leading_value", "delay_us"],
                    format!(
                        "leading-value delay {} µs is shorter than the link to follower `{}` on node `{}` needs: {} µs (leader cycle {} + {budget} {} + follower cycle {})",
                        out[*leader].delay_ns / 1000,
                        axes[follower].name,
                        nodes[f.node].name,
                        need / 1000,
                        nodes[l_node].cycle_ns / 1000,
                        link / 1000,
                        nodes[f.node].cycle_ns / 1000,
                    ),
                ));
            }
        }
    }
    Ok(out)
}

type Objects = (
    Vec<OutputCamEntry>,
    Vec<CamTrackEntry>,
    Vec<MeasuringInputEntry>,
);

fn position_type(v: &str) -> Result<tandem_motion::objects::output_cam::PositionType, FieldError> {
    use tandem_motion::objects::output_cam::PositionType;
    pick(
        "position",
        v,
        &[
            ("setpoint", PositionType::Setpoint),
            ("actual", PositionType::Actual),
        ],
    )
}

fn range(r: Option<[f64; 2]>) -> Result<Option<(f64, f64)>, FieldError> {
    match r {
        None => Ok(None),
        Some([lo, hi]) if lo.is_finite() && hi.is_finite() && lo < hi => Ok(Some((lo, hi))),
        Some(_) => Err((
            "working_range",
            "must be [min, max] with finite min < max".into(),
        )),
    }
}

fn parameters(
    on: f64,
    off: f64,
    h: f64,
) -> Result<tandem_motion::objects::output_cam::OutputCamParameters, FieldError> {
    if !(0.0..=1e9).contains(&on) {
        return Err(("on_compensation", "must be 0..1e9 seconds".into()));
    }
    if !(0.0..=1e9).contains(&off) {
        return Err(("off_compensation", "must be 0..1e9 seconds".into()));
    }
    if !(0.0..=1e12).contains(&h) {
        return Err(("hysteresis", "must be 0..1e12".into()));
    }
    Ok(tandem_motion::objects::output_cam::OutputCamParameters {
        on_compensation: on,
        off_compensation: off,
        hysteresis: h,
    })
}

/// The output cams, cam tracks and measuring inputs (after the axes and encoders).
fn objects(
    file: &str,
    src: &str,
    raw: &CellFile,
    axes: &[AxisEntry],
    nodes: &[Node],
) -> Result<Objects, ConfigError> {
    use tandem_motion::objects::cam_track::{
        CamTrackConfig, CamTrackData, CamTrackType, TrackCam, TrackOutputInterface, MAX_CAMS,
    };
    use tandem_motion::objects::measuring::{MeasuringInputConfig, MeasuringRoute};
    use tandem_motion::objects::output_cam::{OutputCamConfig, OutputCamType};
    use tandem_motion::plant::sensor::SensorDirection;
    let err = |array: &str, i: usize, key: &str, message: String| ConfigError {
        file: file.into(),
        line: locate_in_array(src, array, i, key),
        key: if key.is_empty() {
            format!("{array}[{i}]")
        } else {
            format!("{array}[{i}].{key}")
        },
        message,
    };
    let mut names: Vec<String> = axes
        .iter()
        .map(|a| a.name.clone())
        .chain(raw.encoders.keys().cloned())
        .collect();
    let mut unique = |array: &str, i: usize, name: &str| -> Result<(), ConfigError> {
        if name.is_empty() || names.iter().any(|n| n == name) {
            return Err(err(
                array,
                i,
                "name",
                format!("`{name}` is empty or already used: names must be unique"),
            ));
        }
        names.push(name.to_string());
        Ok(())
    };
    let axis_of = |array: &str, i: usize, name: &str| {
        axes.iter().position(|a| a.name == name).ok_or_else(|| {
            err(
                array,
                i,
                "axis",
                format!(
                    "unknown axis `{name}`; the cell has: {}",
                    axes.iter()
                        .map(|a| a.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })
    };
    let kinds = [("distance", 0u8), ("time", 1u8)];
    let mut output_cams = Vec::new();
    for (i, c) in raw.output_cams.iter().enumerate() {
        let a = "output_cams";
        unique(a, i, &c.name)?;
        let axis = axis_of(a, i, &c.axis)?;
        let f = |(k, m): FieldError| err(a, i, k, m);
        let cam_type = match pick("type", &c.kind, &kinds).map_err(f)? {
            0 => OutputCamType::Distance,
            _ => OutputCamType::Time,
        };
        let mut config = OutputCamConfig::new(cam_type);
        config.position_type = position_type(&c.position).map_err(f)?;
        config.parameters =
            parameters(c.on_compensation, c.off_compensation, c.hysteresis).map_err(f)?;
        config.working_range = range(c.working_range).map_err(f)?;
        config.arming_cycles = c.arming_cycles;
        output_cams.push(OutputCamEntry {
            name: c.name.clone(),
            axis,
            config,
        });
    }
    let mut cam_tracks = Vec::new();
    for (i, c) in raw.cam_tracks.iter().enumerate() {
        let a = "cam_tracks";
        unique(a, i, &c.name)?;
        let axis = axis_of(a, i, &c.axis)?;
        let f = |(k, m): FieldError| err(a, i, k, m);
        let track_type = match pick("type", &c.kind, &kinds).map_err(f)? {
            0 => CamTrackType::Distance,
            _ => CamTrackType::Time,
        };
        let mut config = CamTrackConfig::new(track_type);
        config.position_type = position_type(&c.position).map_err(f)?;
        config.working_range = range(c.working_range).map_err(f)?;
        config.interface = pick(
            "interface",
            &c.interface,
            &[
                ("software", TrackOutputInterface::Software),
                ("timer_dq", TrackOutputInterface::TimerDq),
                ("dq_module", TrackOutputInterface::DqModule),
            ],
        )
        .map_err(f)?;
        if !(c.track_length.is_finite() && (0.001..=1e12).contains(&c.track_length)) {
            return Err(err(a, i, "track_length", "must be 0.001..1e12".into()));
        }
        if !(c.reference_position.is_finite() && c.reference_position.abs() <= 1e12) {
            return Err(err(
                a,
                i,
                "reference_position",
                "must be within ±1e12".into(),
            ));
        }
        if c.cams.len() > MAX_CAMS {
            return Err(err(a, i, "cams", format!("at most {MAX_CAMS} cams")));
        }
        let mut data = CamTrackData::new(c.reference_position, c.track_length);
        data.masking = c.masking;
        data.parameters =
            parameters(c.on_compensation, c.off_compensation, c.hysteresis).map_err(f)?;
        for (j, cam) in c.cams.iter().enumerate() {
            let bad = |m: &str| err(a, i, "cams", format!("cam {}: {m}", j + 1));
            if !(cam.on.is_finite() && (0.0..=1e12).contains(&cam.on)) {
                return Err(bad("`on` must be 0..1e12 (relative to the track start)"));
            }
            let tc = match track_type {
                CamTrackType::Distance => {
                    let off = cam
                        .off
                        .ok_or_else(|| bad("`off` is required on a distance track"))?;
                    if cam.duration.is_some() {
                        return Err(bad("`duration` is for time tracks"));
                    }
                    if !(off.is_finite() && off >= cam.on && off <= 1e12) {
                        return Err(bad("`off` must be >= `on`"));
                    }
                    TrackCam::distance(cam.on, off)
                }
                CamTrackType::Time => {
                    let d = cam
                        .duration
                        .ok_or_else(|| bad("`duration` (s) is required on a time track"))?;
                    if cam.off.is_some() {
                        return Err(bad("`off` is for distance tracks"));
                    }
                    if !(1e-6..=1e9).contains(&d) {
                        return Err(bad("`duration` must be 1e-6..1e9 s"));
                    }
                    TrackCam::time(cam.on, d)
                }
            };
            data = data.with_cam(j, tc);
        }
        if let Err(e) = tandem_motion::objects::cam_track::CamTrack::new(config, data) {
            return Err(err(a, i, "", format!("rejected by the cam track: {e}")));
        }
        cam_tracks.push(CamTrackEntry {
            name: c.name.clone(),
            axis,
            config,
            data,
        });
    }
    let mut measuring_inputs = Vec::new();
    for (i, m) in raw.measuring_inputs.iter().enumerate() {
        let a = "measuring_inputs";
        unique(a, i, &m.name)?;
        let axis = axis_of(a, i, &m.axis)?;
        let f = |(k, msg): FieldError| err(a, i, k, msg);
        let cycle_ns = nodes[axes[axis].node].cycle_ns;
        let mut config = MeasuringInputConfig::timer_di(cycle_ns);
        config.route = pick(
            "route",
            &m.route,
            &[
                ("timer_di", MeasuringRoute::TimerDi),
                ("central_probe", MeasuringRoute::CentralProbe),
                ("profidrive", MeasuringRoute::Profidrive),
            ],
        )
        .map_err(f)?;
        if !(m.correction_time.is_finite() && m.correction_time.abs() <= 1.0) {
            return Err(err(a, i, "correction_time", "must be within ±1 s".into()));
        }
        if !(m.additional_activation_time.is_finite()
            && (0.0..=1.0).contains(&m.additional_activation_time))
        {
            return Err(err(
                a,
                i,
                "additional_activation_time",
                "must be 0..1 s".into(),
            ));
        }
        config.correction_time = m.correction_time;
        config.additional_activation_time = m.additional_activation_time;
        config.apply_activation_time = m.apply_activation_time;
        let sensor = match &m.sensor {
            None => None,
            Some(s) => {
                let k = |key: &str| format!("sensor.{key}");
                if !(s.position.is_finite() && s.position.abs() <= 1e12) {
                    return Err(err(a, i, &k("position"), "must be within ±1e12".into()));
                }
                if !(s.width.is_finite() && s.width > 0.0) {
                    return Err(err(a, i, &k("width"), "must be a positive number".into()));
                }
                if !(s.dead_time.is_finite() && (0.0..=1.0).contains(&s.dead_time)) {
                    return Err(err(a, i, &k("dead_time"), "must be 0..1 s".into()));
                }
                if !(s.jitter.is_finite() && (0.0..=1.0).contains(&s.jitter)) {
                    return Err(err(a, i, &k("jitter"), "must be 0..1 s".into()));
                }
                let direction = pick(
                    "sensor.direction",
                    &s.direction,
                    &[
                        ("positive", SensorDirection::Positive),
                        ("negative", SensorDirection::Negative),
                        ("both", SensorDirection::Both),
                    ],
                )
                .map_err(f)?;
                let axis = match &s.axis {
                    None => axis,
                    Some(n) => {
                        let j = axis_of(a, i, n).map_err(|mut e| {
                            e.key = format!("{a}[{i}].sensor.axis");
                            e
                        })?;
                        if axes[j].node != axes[axis].node {
                            return Err(err(
                                a,
                                i,
                                &k("axis"),
                                format!("`{n}` must be on the node of `{}`", m.axis),
                            ));
                        }
                        j
                    }
                };
                Some(SensorEntry {
                    axis,
                    position: s.position,
                    width: s.width,
                    dead_time: s.dead_time,
                    jitter_ns: (s.jitter * 1e9).round() as i64,
                    seed: s.seed,
                    direction,
                })
            }
        };
        let registration = match &m.registration {
            None => None,
            Some(r) => {
                let j = axis_of(a, i, &r.axis).map_err(|mut e| {
                    e.key = format!("{a}[{i}].registration.axis");
                    e
                })?;
                if !(r.target.is_finite() && r.target.abs() <= 1e12) {
                    return Err(err(
                        a,
                        i,
                        "registration.target",
                        "must be within ±1e12".into(),
                    ));
                }
                if !(r.gain > 0.0 && r.gain <= 1.0) {
                    return Err(err(a, i, "registration.gain", "must be in (0, 1]".into()));
                }
                Some(Registration {
                    axis: j,
                    target: r.target,
                    gain: r.gain,
                })
            }
        };
        if let Err(e) = tandem_motion::objects::measuring::MeasuringInput::new(config) {
            return Err(err(
                a,
                i,
                "",
                format!("rejected by the measuring input: {e}"),
            ));
        }
        measuring_inputs.push(MeasuringInputEntry {
            name: m.name.clone(),
            axis,
            config,
            sensor,
            registration,
        });
    }
    Ok((output_cams, cam_tracks, measuring_inputs))
}

type FieldError = (&'static str, String);

/// Builds and interpolates a cam (`MC_InterpolateCam` at load time).
fn cam_from(
    c: &schema::CamSection,
    dir: Option<&Path>,
) -> Result<(tandem_motion::cam::Cam, tandem_motion::cam::CamDefinition), FieldError> {
    use tandem_motion::cam::{
        BoundaryCondition, Cam, CamDefinition, Interpolation, MotionLaw, SegmentDef,
    };
    let interpolation = Interpolation::from_name(&c.interpolation).ok_or((
        "interpolation",
        format!(
            "`{}` is not one of linear, cubic_spline, bezier",
            c.interpolation
        ),
    ))?;
    let boundary = BoundaryCondition::from_name(&c.boundary).ok_or((
        "boundary",
        format!(
            "`{}` is not one of none, equal_first_derivative",
            c.boundary
        ),
    ))?;
    let mut points: Vec<(f64, f64)> = c.points.iter().map(|[x, y]| (*x, *y)).collect();
    if let Some(csv) = &c.points_csv {
        let path = dir
            .map(|d| d.join(csv))
            .unwrap_or_else(|| Path::new(csv).to_path_buf());
        let text = std::fs::read_to_string(&path)
            .map_err(|e| ("points_csv", format!("cannot read {}: {e}", path.display())))?;
        let more = tandem_motion::cam::parse_csv(&text)
            .map_err(|e| ("points_csv", format!("{}: {e}", path.display())))?;
        points.extend(more);
    }
    let mut segments = Vec::new();
    for (i, seg) in c.segments.iter().enumerate() {
        let [x0, x1] = seg.x;
        let def = match seg.kind.as_str() {
            "law" => {
                let name = seg
                    .law
                    .as_deref()
                    .ok_or(("segments", format!("segment {i}: `law` is required")))?;
                let law = MotionLaw::from_name(name, seg.parameter).ok_or((
                    "segments",
                    format!("segment {i}: unknown law `{name}` or bad parameter"),
                ))?;
                let [y0, y1] = seg.y.ok_or((
                    "segments",
                    format!("segment {i}: `y = [y0, y1]` is required"),
                ))?;
                SegmentDef::Law {
                    law,
                    x0,
                    x1,
                    y0,
                    y1,
                }
            }
            "polynomial" => {
                let coeffs = seg
                    .coeffs
                    .as_deref()
                    .filter(|c| !c.is_empty() && c.len() <= 8)
                    .ok_or((
                        "segments",
                        format!("segment {i}: `coeffs` (1 to 8 numbers) is required"),
                    ))?;
                SegmentDef::polynomial(x0, x1, coeffs)
            }
            "s7_polynomial" => {
                let a_in = seg.a.as_deref().unwrap_or(&[]);
                if a_in.len() > 7 {
                    return Err((
                        "segments",
                        format!("segment {i}: `a` has at most 7 coefficients"),
                    ));
                }
                let mut a = [0.0; 7];
                a[..a_in.len()].copy_from_slice(a_in);
                let (amp, period, phase) = seg
                    .sine
                    .as_ref()
                    .map(|s| (s.amplitude, s.period, s.phase))
                    .unwrap_or((0.0, 1.0, 0.0));
                SegmentDef::S7Polynomial {
                    xmin: x0,
                    xmax: x1,
                    a,
                    sine_amplitude: amp,
                    sine_period: period,
                    sine_phase: phase,
                }
            }
            other => {
                return Err((
                    "segments",
                    format!(
                        "segment {i}: type `{other}` is not one of law, polynomial, s7_polynomial"
                    ),
                ))
            }
        };
        segments.push(def);
    }
    let def = CamDefinition {
        points,
        segments,
        interpolation,
        boundary,
    };
    let cam = Cam::interpolate(&def)
        .map_err(|e| ("", format!("cannot interpolate: {e:?} ({})", e.error_id())))?;
    Ok((cam, def))
}

fn pick<T: Copy>(key: &'static str, value: &str, options: &[(&str, T)]) -> Result<T, FieldError> {
    options
        .iter()
        .find(|(n, _)| *n == value)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
            (key, format!("`{value}` is not one of {}", names.join(", ")))
        })
}

fn axis_config(a: &AxisSection, cycle: f64) -> Result<AxisConfig, FieldError> {
    let kind = pick(
        "kind",
        &a.kind,
        &[
            ("speed", AxisKind::Speed),
            ("positioning", AxisKind::Positioning),
            ("synchronous", AxisKind::Synchronous),
        ],
    )?;
    let motion_type = pick(
        "motion_type",
        &a.motion_type,
        &[
            ("linear", MotionType::Linear),
            ("rotary", MotionType::Rotary),
        ],
    )?;
    let encoder = pick(
        "encoder",
        &a.encoder,
        &[
            ("incremental", EncoderType::Incremental),
            ("absolute", EncoderType::Absolute),
        ],
    )?;
    let marks = [
        ("zero_mark", HomingMark::ZeroMark),
        ("cam_and_zero_mark", HomingMark::CamAndZeroMark),
        ("digital_input", HomingMark::DigitalInput),
    ];
    let senses = [("positive", Sense::Positive), ("negative", Sense::Negative)];
    let h = &a.homing;
    let homing = HomingConfig {
        active_mark: pick("homing.active_mark", &h.active_mark, &marks)?,
        passive_mark: pick("homing.passive_mark", &h.passive_mark, &marks)?,
        approach_direction: pick("homing.approach_direction", &h.approach_direction, &senses)?,
        homing_direction: pick("homing.homing_direction", &h.homing_direction, &senses)?,
        passive_direction: pick(
            "homing.passive_direction",
            &h.passive_direction,
            &[
                ("positive", PassiveDirection::Positive),
                ("negative", PassiveDirection::Negative),
                ("current", PassiveDirection::Current),
            ],
        )?,
        approach_velocity: h.approach_velocity,
        referencing_velocity: h.referencing_velocity,
        home_position: h.home_position,
        home_position_offset: h.home_position_offset,
        auto_reversal: h.auto_reversal,
    };
    let d = &a.drive;
    let drive = match d.model.as_str() {
        "position_loop" => DriveModel::PositionLoop {
            kv: d.kv,
            kpc: d.kpc / 100.0,
            t_vtc: d.t_vtc,
        },
        "delay" => DriveModel::Delay { delay: d.delay },
        other => {
            return Err((
                "drive.model",
                format!("`{other}` is not one of position_loop, delay"),
            ));
        }
    };
    let dy = &a.dynamics;
    let hw = a.hw_limits.as_ref();
    let leader_missing_reaction = match &a.leader_missing_reaction {
        None => None,
        Some(r) => Some(pick(
            "leader_missing_reaction",
            r,
            &[
                ("stop_current_dynamics", Reaction::StopCurrentDynamics),
                ("stop_max_dynamics", Reaction::StopMaxDynamics),
                ("emergency_stop", Reaction::EmergencyStop),
                ("remove_enable", Reaction::RemoveEnable),
            ],
        )?),
    };
    Ok(AxisConfig {
        leader_missing_reaction,
        kind,
        motion_type,
        modulo: a.modulo.as_ref().map(|m| Modulo {
            start: m.start,
            length: m.length,
        }),
        encoder,
        virtual_axis: a.virtual_axis,
        cycle,
        limits: DynamicLimits {
            max_velocity: dy.max_velocity,
            max_acceleration: dy.max_acceleration,
            max_deceleration: dy.max_deceleration,
            max_jerk: dy.max_jerk,
        },
        defaults: DynamicDefaults {
            velocity: dy.velocity,
            acceleration: dy.acceleration,
            deceleration: dy.deceleration,
            jerk: dy.jerk,
            emergency_deceleration: dy.emergency_deceleration,
        },
        sw_limits: a.sw_limits.as_ref().map(|s| SoftwareLimits {
            min: s.min,
            max: s.max,
        }),
        hw_limits_active: hw.map(|h| h.active).unwrap_or(false),
        positioning: PositioningMonitoring {
            window: a.positioning.window,
            tolerance_time: a.positioning.tolerance_time,
            min_dwell_time: a.positioning.min_dwell_time,
        },
        following_error: FollowingErrorMonitoring {
            enable: a.following_error.enable,
            min_value: a.following_error.min_value,
            max_value: a.following_error.max_value,
            min_velocity: a.following_error.min_velocity,
            warning_level: a.following_error.warning_level,
        },
        standstill: StandstillSignal {
            velocity_threshold: a.standstill.velocity_threshold,
            min_dwell_time: a.standstill.min_dwell_time,
        },
        homing,
        drive,
        plant: Plant {
            reference_cam: a.plant.reference_cam.map(|[lo, hi]| (lo, hi)),
            zero_mark: a.plant.zero_mark_period.map(|period| ZeroMark {
                period,
                offset: a.plant.zero_mark_offset,
            }),
            hw_limit_min: hw.and_then(|h| h.min),
            hw_limit_max: hw.and_then(|h| h.max),
        },
        initial_position: a.initial_position,
        extrapolation: ExtrapolationConfig {
            position_t1: a.extrapolation.position_t1,
            position_t2: a.extrapolation.position_t2,
            velocity_t1: a.extrapolation.velocity_t1,
            velocity_t2: a.extrapolation.velocity_t2,
            velocity_tolerance: a.extrapolation.velocity_tolerance,
            hysteresis: a.extrapolation.hysteresis,
            following_time: a.extrapolation.following_time,
            acquisition_time: a.extrapolation.acquisition_time,
            system_defined: a.extrapolation.system_defined,
            velocity_mode: pick(
                "extrapolation.velocity_mode",
                &a.extrapolation.velocity_mode,
                &[
                    ("filtered", VelocityMode::Filtered),
                    ("differentiation", VelocityMode::Differentiation),
                ],
            )?,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[axes.x]
node = "n"

[axes.x.dynamics]
max_velocity = 100.0
max_acceleration = 1000.0
max_deceleration = 1000.0
max_jerk = 10000.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0
emergency_deceleration = 2000.0
"#;

    #[test]
    fn parses_a_minimal_cell() {
        let c = parse("cell.toml", GOOD).unwrap();
        assert_eq!(c.axes.len(), 1);
        assert_eq!(c.nodes[0].cycle_ns, 1_000_000);
        assert_eq!(c.axes[0].config.cycle, 0.001);
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let bad = GOOD.replace("max_velocity = 100.0", "max_velocity = 0.0");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.key, "axes.x.dynamics.max_velocity");
        assert_eq!(e.line, Some(13));
        assert!(e
            .to_string()
            .starts_with("cell.toml:13: axes.x.dynamics.max_velocity: must be"));
        let bad = GOOD.replace("node = \"n\"", "node = \"m\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!((e.key.as_str(), e.line), ("axes.x.node", Some(10)));
        assert!(e.message.contains("unknown node `m`"));
        let bad = GOOD.replace("cycle_us = 1000", "cycle_us = 1100");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert!(
            e.message
                .contains("not a positive multiple of the base tick"),
            "{e}"
        );
        let bad = GOOD.replace("max_jerk = 10000.0", "max_jerk = 10000.0\nmax_jrk = 1.0");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.line, Some(17));
        assert!(e.message.contains("unknown field `max_jrk`"), "{e}");
        let bad = GOOD.replace("node = \"n\"", "node = \"n\"\nkind = \"servo\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.key, "axes.x.kind");
        assert!(e
            .message
            .contains("`servo` is not one of speed, positioning"));
    }

    #[test]
    fn output_cams_cam_tracks_and_measuring_inputs_are_validated_by_key() {
        let objects = format!(
            "{GOOD}\n[[output_cams]]\nname = \"cam\"\naxis = \"x\"\ntype = \"time\"\n\n[[cam_tracks]]\nname = \"track\"\naxis = \"x\"\ntrack_length = 100.0\ncams = [{{ on = 10.0, off = 20.0 }}]\n\n[[measuring_inputs]]\nname = \"mark\"\naxis = \"x\"\ncorrection_time = 0.001\n\n[measuring_inputs.sensor]\nposition = 5.0\nwidth = 1.0\njitter = 0.000002\n"
        );
        let c = parse("cell.toml", &objects).unwrap();
        assert_eq!(c.output_cams.len(), 1);
        assert_eq!(
            c.output_cams[0].config.cam_type,
            tandem_motion::objects::output_cam::OutputCamType::Time
        );
        assert_eq!(c.cam_tracks[0].data.cams[0].off_position, 20.0);
        assert!(!c.cam_tracks[0].data.cams[1].existent);
        assert_eq!(c.measuring_inputs[0].config.correction_time, 0.001);
        assert_eq!(c.measuring_inputs[0].config.servo_cycle_ns, 1_000_000);
        assert_eq!(c.measuring_inputs[0].sensor.unwrap().jitter_ns, 2000);
        let line_of =
            |src: &str, pat: &str| src.lines().position(|l| l.starts_with(pat)).unwrap() + 1;
        // A misspelt key names itself.
        let bad = objects.replace("type = \"time\"", "tipe = \"time\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert!(e.message.contains("unknown field `tipe`"), "{e}");
        assert_eq!(e.line, Some(line_of(&bad, "tipe")));
        // Bad values name the array entry and the key, with its line.
        for (from, to, key, msg) in [
            (
                "type = \"time\"",
                "type = \"switch\"",
                "output_cams[0].type",
                "`switch` is not one of distance, time",
            ),
            (
                "axis = \"x\"\ntype",
                "axis = \"y\"\ntype",
                "output_cams[0].axis",
                "unknown axis `y`",
            ),
            (
                "track_length = 100.0",
                "track_length = 0.0",
                "cam_tracks[0].track_length",
                "must be 0.001..1e12",
            ),
            (
                "off = 20.0",
                "off = 5.0",
                "cam_tracks[0].cams",
                "cam 1: `off` must be >= `on`",
            ),
            (
                "width = 1.0",
                "width = 0.0",
                "measuring_inputs[0].sensor.width",
                "must be a positive number",
            ),
            (
                "name = \"mark\"",
                "name = \"x\"",
                "measuring_inputs[0].name",
                "names must be unique",
            ),
        ] {
            let bad = objects.replacen(from, to, 1);
            let e = parse("cell.toml", &bad).unwrap_err();
            assert_eq!(e.key, key, "{e}");
            assert!(e.message.contains(msg), "{e}");
            assert!(e.to_string().contains(&format!("{key}: ")), "{e}");
            assert!(e.line.is_some(), "{e}");
        }
        let bad = objects.replacen("track_length = 100.0", "track_length = 0.0", 1);
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.line, Some(line_of(&bad, "track_length")));
        // Register correction.
        let reg = format!(
            "{objects}\n[measuring_inputs.registration]\naxis = \"x\"\ntarget = 5.0\ngain = 0.5\n"
        );
        let c = parse("cell.toml", &reg).unwrap();
        let r = c.measuring_inputs[0].registration.unwrap();
        assert_eq!((r.axis, r.target, r.gain), (0, 5.0, 0.5));
        let e = parse("cell.toml", &reg.replace("gain = 0.5", "gain = 2.0")).unwrap_err();
        assert_eq!(e.key, "measuring_inputs[0].registration.gain", "{e}");
        let e = parse(
            "cell.toml",
            &reg.replace("axis = \"x\"\ntarget", "axis = \"w\"\ntarget"),
        )
        .unwrap_err();
        assert_eq!(e.key, "measuring_inputs[0].registration.axis", "{e}");
        assert!(e.message.contains("unknown axis `w`"), "{e}");
    }
}
