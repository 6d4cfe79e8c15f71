//! The outputs of a node's process image: the simulated digital output devices
//! (`kind = "sim_digital_output"`) and the stage that takes each output cam's and cam track's
//! edges of a step to the channel of the signal it drives (`output = "<signal>"`).
//!
//! # Switching ahead: the edge time is the switching time
//!
//! A device can only switch what it was told before: the process image writes outputs at the
//! boundary after the step that computed them, `t + T`. S7-1500T therefore computes the exact
//! switching time two position-control cycles before the output, and shifts setpoint cams so
//! that they fire when the setpoint reaches the drive (S7-1500T Measuring input and cam
//! functions V5.0 function manual, 3.2 'Output cam technology object'). tandem does the same:
//! an output cam or cam track that drives a signal is stepped at `t` with the motion of
//! `[t - T + Λ, t + Λ]` predicted from its cycle `[t - T, t]`
//! ([`tandem_motion::objects::output_cam::SwitchingAhead`], set up by [`switching_ahead`]),
//! with the object's look-ahead
//!
//! ```text
//! Λ = (2 + ceil(c / T)) · T
//! ```
//!
//! `c` the larger of its on and off compensations ([`OutputDeviceStatus::look_ahead_ns`]
//! reports the largest `Λ` of a device's node). A setpoint cam's motion is its setpoint
//! shifted by the setpoint's transport delay to the load `D` = [`SETPOINT_DELAY_CYCLES`]
//! cycles and extrapolated the remaining `Λ - D`; an actual-value cam's is its actual value
//! extrapolated `Λ` with the actual velocity and acceleration. Objects that drive no signal
//! step with the cycle just computed, as before. The edge times the object reports (log, trace, [`ObjectEdge`]) are the times
//! its output must switch, and an edge at `e` is due on its channel at exactly `e`. With
//! `e >= t - T + Λ - c >= t + T` no edge is due before the boundary that writes it. An edge
//! that is due already (the second edge within one cycle on a timestamped device, or an edge
//! held back to its predecessor's time by the object) switches at once at the next boundary,
//! counted as late, never lost.
//!
//! A digital cam switch (the hydraulic library's MC_DigitalCamSwitch_BkPlcMc) drives one signal
//! per track (`tracks[n - 1].output`) without look-ahead: the library evaluates its cams once
//! per cycle, so a track bit computed in the step at `t` is an edge due at `t + T`, written at
//! that boundary.
//!
//! # The order within one step at `t`, after the objects stepped
//!
//! 1. Every device whose node's cycle falls on `t` reaches the boundary `t`:
//!    - a timestamped device executes the task it holds if its `StartTime` is at or before `t`
//!      (at exactly that time), then the frame of `t` carries its next task: the earliest
//!      pending switching instant with every channel due at that instant (one switching event
//!      per cycle and terminal: Beckhoff EL2252 documentation, 'Introduction'; a task it holds
//!      with a later `StartTime` is overwritten, its events stay pending). An instant already
//!      past (a second edge within one cycle of the first) switches at once, at `t` (the
//!      `ForceWhenLate` option of Beckhoff's `XFC_EL2252_V2`): at most one cycle late, never
//!      lost.
//!    - a plain device writes every edge due at or before `t`: each channel switches at `t` to
//!      the level of its last edge; a channel whose edges cancel within the cycle does not
//!      switch (the last one written wins, S7-1500T Measuring input and cam functions V5.0
//!      function manual, 3.3 'Cam track technology object', DQ module).
//! 2. The step's edges join their devices' pending events, due at their time `e`.
//!
//! Every switch is recorded ([`OutputSwitch`]) with the instant the channel changed, for tests
//! and traces. Nothing here allocates after [`Outputs::new`].

use tandem_config::{Cell, DeviceKind, SignalIndex};
use tandem_motion::objects::output_cam::{
    OutputCamParameters, PositionType, SwitchingAhead, EDGE_CAPACITY,
};

/// Cycles of look-ahead without compensation: S7 computes switching times two
/// position-control cycles before the output.
pub const LOOK_AHEAD_CYCLES: i64 = 2;

/// Cycles from a setpoint computed to the load moving by it: the transport delay of a drive of
/// the process image ([`crate::drives`]: a setpoint computed at `t` acts from `t + T` and shows
/// in the actual value read at `t + 2T`). Setpoint cams are shifted by it. Inferred: the same
/// two cycles for an axis on the simulated drive model and for a virtual axis, so that an
/// uncompensated setpoint cam switches at the same instants on every kind of axis.
pub const SETPOINT_DELAY_CYCLES: i64 = 2;

/// Most switches kept between two [`crate::exec::Executive::drain_output_switches`]; more are
/// counted in [`OutputDeviceStatus::unreported`].
pub const SWITCHES: usize = 1024;

/// Most pending events of one device.
const QUEUE_MAX: usize = 4096;

/// One switching of a channel of a simulated digital output: what the device physically did.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct OutputSwitch {
    /// The device (index in [`Cell::devices`]).
    pub device: usize,
    /// The channel, 1-based.
    pub channel: u8,
    /// Switched on (`true`) or off.
    pub on: bool,
    /// The instant the channel switched (ns, cell clock).
    pub time_ns: i64,
    /// The edge time the object computed (ns), compensation applied: the time the output
    /// must switch.
    pub edge_ns: i64,
    /// The instant it was due (the `StartTime` a timestamped device is given): `edge_ns`.
    pub scheduled_ns: i64,
    /// The boundary whose frame carried it to the device.
    pub written_ns: i64,
    /// Switched later than the device could: after `scheduled_ns` on a timestamped device,
    /// a cycle or more after it on a plain one.
    pub late: bool,
}

/// The state of a simulated digital output device.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct OutputDeviceStatus {
    /// The channels' levels: bit `c - 1` is channel `c`.
    pub levels: u32,
    /// Timestamped: the `StartTime` of the task the device holds, not yet executed.
    #[doc(alias = "StartTime")]
    pub task_start_ns: Option<i64>,
    /// The largest look-ahead `Λ` of its node's objects that drive a signal (ns): how far
    /// ahead of the cycle just computed they predict their switching times.
    pub look_ahead_ns: i64,
    /// Switches so far.
    pub switches: u64,
    /// Switches later than the device could (see [`OutputSwitch::late`]).
    pub late: u64,
    /// Edges overwritten by a later edge of their channel in the same write.
    pub superseded: u64,
    /// Edges lost because the device's pending events were full.
    pub dropped: u64,
    /// Switches not kept for the caller (more than [`SWITCHES`] between two drains).
    pub unreported: u64,
}

/// An edge due on a channel.
#[derive(Copy, Clone, Debug)]
struct Event {
    /// When it is due: the edge time.
    at_ns: i64,
    edge_ns: i64,
    channel: u8,
    on: bool,
}

/// The task a timestamped device holds.
#[derive(Copy, Clone, Debug)]
struct Task {
    start_ns: i64,
    written_ns: i64,
}

/// A simulated digital output device of the process image.
#[derive(Debug)]
struct Terminal {
    /// Index in [`Cell::devices`].
    device: usize,
    cycle_ns: i64,
    timestamped: bool,
    /// Pending events, by due time (equal times in arrival order).
    queue: Vec<Event>,
    task: Option<Task>,
    status: OutputDeviceStatus,
}

/// What one write of a device's channels switches: the channels' new levels and, per channel,
/// the last edge written.
struct Write {
    levels: u32,
    last: [Option<Event>; 32],
    events: u64,
}

impl Terminal {
    /// Applies the events due at or before `upto` (a prefix of the queue) in one write at
    /// `time`, carried by the frame of `written`.
    fn write(&mut self, upto: i64, time: i64, written: i64, out: &mut Vec<OutputSwitch>) {
        let n = self.queue.partition_point(|e| e.at_ns <= upto);
        let mut w = Write {
            levels: self.status.levels,
            last: [None; 32],
            events: 0,
        };
        for e in self.queue.drain(..n) {
            let bit = 1u32 << ((e.channel.saturating_sub(1)) & 31);
            if e.on {
                w.levels |= bit;
            } else {
                w.levels &= !bit;
            }
            if let Some(slot) = w.last.get_mut(usize::from(e.channel.saturating_sub(1))) {
                *slot = Some(e);
            }
            w.events += 1;
        }
        let changed = w.levels ^ self.status.levels;
        let mut switched = 0;
        for (c, last) in w.last.iter().enumerate() {
            let Some(e) = last.filter(|_| changed & (1 << c) != 0) else {
                continue;
            };
            let late = if self.timestamped {
                time > e.at_ns
            } else {
                time - e.at_ns >= self.cycle_ns
            };
            self.status.late += u64::from(late);
            switched += 1;
            let s = OutputSwitch {
                device: self.device,
                channel: e.channel,
                on: e.on,
                time_ns: time,
                edge_ns: e.edge_ns,
                scheduled_ns: e.at_ns,
                written_ns: written,
                late,
            };
            if out.len() < out.capacity() {
                out.push(s);
            } else {
                self.status.unreported += 1;
            }
        }
        self.status.switches += switched;
        self.status.superseded += w.events - switched;
        self.status.levels = w.levels;
    }

    /// The boundary `t` (step 1 of the module's order).
    fn boundary(&mut self, t: i64, out: &mut Vec<OutputSwitch>) {
        if !self.timestamped {
            self.write(t, t, t, out);
            return;
        }
        // The task held executes at its StartTime.
        if let Some(task) = self.task.filter(|x| x.start_ns <= t) {
            self.task = None;
            self.write(task.start_ns, task.start_ns, task.written_ns, out);
        }
        // The frame of `t` carries the earliest pending instant.
        let Some(head) = self.queue.first().map(|e| e.at_ns) else {
            self.task = None;
            self.status.task_start_ns = None;
            return;
        };
        if head <= t {
            // Due already (a second event within one cycle): switched at once.
            self.task = None;
            self.write(head, t, t, out);
        } else if self.task.is_none_or(|x| x.start_ns != head) {
            self.task = Some(Task {
                start_ns: head,
                written_ns: t,
            });
        }
        self.status.task_start_ns = self.task.map(|x| x.start_ns);
    }

    /// Queues `e` by its due time, after the events due at the same time.
    fn queue(&mut self, e: Event) {
        if self.queue.len() >= self.queue.capacity() {
            self.status.dropped += 1;
            return;
        }
        let k = self.queue.partition_point(|x| x.at_ns <= e.at_ns);
        self.queue.insert(k, e);
    }
}

/// The output stage: the simulated digital output devices of the owned nodes and which
/// channel each object's edges go to.
#[derive(Debug)]
pub(crate) struct Outputs {
    terminals: Vec<Terminal>,
    /// Per device of the cell: its terminal here.
    of_device: Vec<Option<usize>>,
    /// Per object (output cams, then cam tracks): its terminal and channel.
    bindings: Vec<Option<(usize, u8)>>,
    /// The object number of the first digital cam switch (after the measuring inputs).
    first_switch: usize,
    /// Per digital cam switch, per track: its terminal and channel.
    switch_bindings: Vec<[Option<(usize, u8)>; 32]>,
    /// The switches since the last drain.
    switches: Vec<OutputSwitch>,
}

/// The outputs of an EtherCAT digital terminal (`role = "dio"`): 8 channels, switched with
/// the cycle's exchange.
const ETHERCAT_DIO_OUTPUTS: tandem_config::DigitalOutputParams =
    tandem_config::DigitalOutputParams {
        channels: 8,
        timestamped: false,
    };

/// An output edge of an output cam or cam track, for the output stage.
#[derive(Copy, Clone, Debug)]
pub(crate) struct ObjectEdge {
    /// The object, numbered as [`crate::notes::IoNote::object`] (output cams, then cam tracks,
    /// measuring inputs, digital cam switches; a digital cam switch's track is `edge.cam + 1`).
    pub(crate) object: usize,
    /// The edge, with its exact time.
    pub(crate) edge: tandem_motion::objects::output_cam::Edge,
}

/// The look-ahead of an output cam or cam track on `position_type` that drives `output`: `Λ`
/// of the node of the output's device (see the module documentation), or `None` when it
/// drives no digital output (it then steps with the cycle just computed).
pub(crate) fn switching_ahead(
    cell: &Cell,
    output: Option<SignalIndex>,
    position_type: PositionType,
    parameters: &OutputCamParameters,
) -> Option<SwitchingAhead> {
    let signal = cell.signals.get(output?.0)?;
    let device = cell.devices.get(signal.device.0)?;
    if !matches!(
        device.kind,
        DeviceKind::SimDigitalOutput(_) | DeviceKind::EthercatDio
    ) {
        return None;
    }
    let cycle = cell.nodes.get(device.node).map_or(1, |n| n.cycle_ns.max(1));
    Some(SwitchingAhead::new(
        position_type,
        look_ahead_of(lead(parameters), cycle),
        SETPOINT_DELAY_CYCLES.saturating_mul(cycle),
    ))
}

/// An object's largest compensation (s).
fn lead(p: &OutputCamParameters) -> f64 {
    p.on_compensation.max(p.off_compensation)
}

/// `Λ` (ns) for compensation `c` (s) on a cycle of `cycle` ns: [`LOOK_AHEAD_CYCLES`] plus `c`
/// in whole cycles.
fn look_ahead_of(c: f64, cycle: i64) -> i64 {
    // Compensations are at most 1e9 s (checked by the configuration): the cycles fit an i64.
    let c_cycles = (c * 1e9 / cycle as f64).ceil() as i64;
    LOOK_AHEAD_CYCLES
        .saturating_add(c_cycles.max(0))
        .saturating_mul(cycle)
}

/// The look-ahead of node `node` (ns): the largest of its objects that drive a signal
/// ([`LOOK_AHEAD_CYCLES`] plus the largest compensation, in whole cycles).
fn look_ahead(cell: &Cell, node: usize) -> i64 {
    let cycle = cell.nodes.get(node).map_or(1, |n| n.cycle_ns.max(1));
    let on_node = |s: Option<SignalIndex>| {
        s.and_then(|s| cell.signals.get(s.0))
            .and_then(|s| cell.devices.get(s.device.0))
            .is_some_and(|d| d.node == node)
    };
    let c = cell
        .output_cams
        .iter()
        .filter(|c| on_node(c.output))
        .map(|c| lead(&c.config.parameters))
        .chain(
            cell.cam_tracks
                .iter()
                .filter(|c| on_node(c.output))
                .map(|c| lead(&c.data.parameters)),
        )
        .fold(0.0, f64::max);
    look_ahead_of(c, cycle)
}

impl Outputs {
    /// The output devices of node `node` (all of the cell with `None`) and the objects bound
    /// to their channels.
    pub(crate) fn new(cell: &Cell, node: Option<usize>) -> Self {
        let mut terminals = Vec::new();
        let mut of_device = vec![None; cell.devices.len()];
        for (i, d) in cell.devices.iter().enumerate() {
            let p = match &d.kind {
                DeviceKind::SimDigitalOutput(p) => *p,
                // The outputs of a digital terminal on the node's EtherCAT segment: their
                // levels go out with the node's next exchange.
                DeviceKind::EthercatDio => ETHERCAT_DIO_OUTPUTS,
                _ => continue,
            };
            if node.is_some_and(|n| n != d.node) {
                continue;
            }
            let cycle_ns = cell.nodes.get(d.node).map_or(1, |n| n.cycle_ns.max(1));
            let look_ahead_ns = look_ahead(cell, d.node);
            // Room for every edge its objects can make within the look-ahead and one cycle.
            let objects = cell
                .output_cams
                .iter()
                .map(|c| c.output)
                .chain(cell.cam_tracks.iter().map(|c| c.output))
                .chain(
                    cell.digital_cam_switches
                        .iter()
                        .flat_map(|c| c.outputs.iter().copied()),
                )
                .flatten()
                .filter(|s| cell.signals.get(s.0).is_some_and(|s| s.device.0 == i))
                .count();
            let cycles = usize::try_from(look_ahead_ns / cycle_ns + 2).unwrap_or(usize::MAX);
            let room = objects
                .saturating_mul(EDGE_CAPACITY)
                .saturating_mul(cycles)
                .min(QUEUE_MAX);
            of_device[i] = Some(terminals.len());
            terminals.push(Terminal {
                device: i,
                cycle_ns,
                timestamped: p.timestamped,
                queue: Vec::with_capacity(room),
                task: None,
                status: OutputDeviceStatus {
                    look_ahead_ns,
                    ..OutputDeviceStatus::default()
                },
            });
        }
        let bind = |s: Option<SignalIndex>| {
            let s = cell.signals.get(s?.0)?;
            let k = of_device.get(s.device.0).copied().flatten()?;
            Some((k, s.channel))
        };
        let bindings = cell
            .output_cams
            .iter()
            .map(|c| bind(c.output))
            .chain(cell.cam_tracks.iter().map(|c| bind(c.output)))
            .collect();
        let switch_bindings = cell
            .digital_cam_switches
            .iter()
            .map(|c| {
                let mut b = [None; 32];
                for (slot, s) in b.iter_mut().zip(&c.outputs) {
                    *slot = bind(*s);
                }
                b
            })
            .collect();
        Self {
            terminals,
            of_device,
            bindings,
            first_switch: cell.output_cams.len()
                + cell.cam_tracks.len()
                + cell.measuring_inputs.len(),
            switch_bindings,
            switches: Vec::with_capacity(SWITCHES),
        }
    }

    /// The stage at step `t`, after the objects stepped: the devices reach the boundary `t`,
    /// then the step's `edges` (taken, the list is left empty) join their devices' pending
    /// events.
    pub(crate) fn step(&mut self, t: i64, edges: &mut Vec<ObjectEdge>) {
        for term in &mut self.terminals {
            if t % term.cycle_ns == 0 {
                term.boundary(t, &mut self.switches);
            }
        }
        for e in edges.iter() {
            let bound = match e.object.checked_sub(self.first_switch) {
                // A digital cam switch: the edge's `cam` is its track - 1.
                Some(s) => self
                    .switch_bindings
                    .get(s)
                    .and_then(|b| b.get(usize::from(e.edge.cam)))
                    .copied()
                    .flatten(),
                None => self.bindings.get(e.object).copied().flatten(),
            };
            let Some((k, channel)) = bound else {
                continue;
            };
            if let Some(term) = self.terminals.get_mut(k) {
                term.queue(Event {
                    at_ns: e.edge.time_ns,
                    edge_ns: e.edge.time_ns,
                    channel,
                    on: e.edge.on,
                });
            }
        }
        edges.clear();
    }

    /// The state of device `device`, if it is an output device of this stage.
    pub(crate) fn status(&self, device: usize) -> Option<&OutputDeviceStatus> {
        let k = self.of_device.get(device).copied().flatten()?;
        self.terminals.get(k).map(|t| &t.status)
    }

    /// Hands each switch since the last drain to `f`, then forgets them.
    pub(crate) fn drain(&mut self, mut f: impl FnMut(&OutputSwitch)) {
        self.switches.iter().for_each(&mut f);
        self.switches.clear();
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    const T: i64 = 1_000_000;

    fn terminal(timestamped: bool) -> Terminal {
        Terminal {
            device: 0,
            cycle_ns: T,
            timestamped,
            queue: Vec::with_capacity(16),
            task: None,
            status: OutputDeviceStatus::default(),
        }
    }

    fn event(at_ns: i64, channel: u8, on: bool) -> Event {
        Event {
            at_ns,
            edge_ns: at_ns,
            channel,
            on,
        }
    }

    /// (time, channel, on, late) of the switches of boundaries `from..=to`.
    fn run(term: &mut Terminal, from: i64, to: i64) -> Vec<(i64, u8, bool, bool)> {
        let mut out = Vec::with_capacity(16);
        for k in from..=to {
            term.boundary(k * T, &mut out);
        }
        out.iter()
            .map(|s| (s.time_ns, s.channel, s.on, s.late))
            .collect()
    }

    #[test]
    fn channels_due_at_one_instant_switch_in_one_task() {
        let mut term = terminal(true);
        term.queue(event(3 * T + 400, 1, true));
        term.queue(event(3 * T + 400, 4, true));
        assert_eq!(run(&mut term, 1, 3), []);
        assert_eq!(term.status.task_start_ns, Some(3 * T + 400));
        assert_eq!(
            run(&mut term, 4, 4),
            [(3 * T + 400, 1, true, false), (3 * T + 400, 4, true, false)]
        );
        assert_eq!(term.status.levels, 0b1001);
        assert_eq!(term.status.task_start_ns, None);
    }

    #[test]
    fn an_earlier_event_overwrites_the_task_held_and_both_switch_on_time() {
        let mut term = terminal(true);
        term.queue(event(6 * T + 100, 2, true));
        assert_eq!(run(&mut term, 1, 1), []);
        assert_eq!(term.status.task_start_ns, Some(6 * T + 100));
        // Computed later, due earlier (a larger compensation on another channel).
        term.queue(event(3 * T + 700, 1, true));
        assert_eq!(run(&mut term, 2, 3), []);
        assert_eq!(term.status.task_start_ns, Some(3 * T + 700));
        assert_eq!(
            run(&mut term, 4, 7),
            [(3 * T + 700, 1, true, false), (6 * T + 100, 2, true, false)]
        );
    }

    #[test]
    fn a_second_event_within_a_cycle_switches_at_the_next_boundary() {
        let mut term = terminal(true);
        term.queue(event(3 * T + 200, 1, true));
        term.queue(event(3 * T + 900, 2, true));
        term.queue(event(3 * T + 950, 1, false));
        assert_eq!(
            run(&mut term, 2, 6),
            [
                (3 * T + 200, 1, true, false),
                (4 * T, 2, true, true),
                (5 * T, 1, false, true),
            ]
        );
        assert_eq!(term.status.late, 2);
    }

    #[test]
    fn a_plain_output_writes_the_last_level_at_the_boundary() {
        let mut term = terminal(false);
        term.queue(event(3 * T + 200, 1, true));
        term.queue(event(3 * T + 900, 1, false));
        term.queue(event(3 * T + 950, 2, true));
        term.queue(event(5 * T, 2, false));
        assert_eq!(
            run(&mut term, 2, 6),
            [(4 * T, 2, true, false), (5 * T, 2, false, false)]
        );
        assert_eq!((term.status.superseded, term.status.switches), (2, 2));
    }

    #[test]
    fn an_edge_already_past_switches_at_the_next_boundary_and_is_counted() {
        // Timestamped: due before the boundary that carries it: at once, late, not lost.
        let mut term = terminal(true);
        term.queue(event(3 * T - 300, 1, true));
        assert_eq!(run(&mut term, 3, 3), [(3 * T, 1, true, true)]);
        assert_eq!((term.status.late, term.status.switches), (1, 1));
        // Plain: at the first boundary at or after it; late only a cycle or more after it.
        let mut term = terminal(false);
        term.queue(event(3 * T - 300, 1, true));
        term.queue(event(4 * T - T, 2, true));
        assert_eq!(
            run(&mut term, 3, 3),
            [(3 * T, 1, true, false), (3 * T, 2, true, false)]
        );
        term.queue(event(3 * T, 1, false));
        assert_eq!(run(&mut term, 4, 4), [(4 * T, 1, false, true)]);
        assert_eq!(term.status.late, 1);
    }

    #[test]
    fn a_full_queue_counts_what_it_drops() {
        let mut term = terminal(true);
        term.queue = Vec::with_capacity(1);
        term.queue(event(3 * T, 1, true));
        term.queue(event(4 * T, 1, false));
        assert_eq!(term.status.dropped, 1);
    }
}
