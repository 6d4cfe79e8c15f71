//! The inputs of a node's process image: the simulated digital input devices
//! (`kind = "sim_digital_input"`), what drives them (script stimuli and simulated sensors on an
//! axis's load) and what they feed (the switches of axes on the simulated drive, measuring
//! inputs on route `timer_di`).
//!
//! # Sampling at the cycle boundary
//!
//! A device of a node whose cycle falls on `t` is sampled at the boundary `t`: every stimulus
//! with a time at or before `t` acts on its channel, in time order.
//! - A **timestamped** device (like an EL1252: each edge latched with its time, Beckhoff EL1252
//!   documentation, 'Introduction') reports every edge with its own time (ns, cell clock), a
//!   pulse narrower than a cycle included.
//! - A **plain** device (like an EL1008) reports the level at `t`: a channel whose level at `t`
//!   differs from the one at the previous boundary has one edge, timed `t`; a pulse that ends
//!   within the cycle is not seen (counted in [`InputDeviceStatus::unseen`]).
//!
//! # The order within one step at `t`
//!
//! 1. ([`Inputs::sample`]) before the axes step: the devices due at `t` are sampled with the
//!    stimuli at or before `t` (script entries); the axes on the simulated drive read their
//!    bound switches from the levels.
//! 2. The axes step.
//! 3. ([`Inputs::sense`]) once the motion of each axis's cycle `[t - T, t]` is known: the
//!    simulated sensors add their edges of that cycle (at or before `t`) to the frame of `t`;
//!    then every measuring input bound to a signal takes the frame's edges of its signal and
//!    measures them in this step, with the exact edge time.
//!
//! So a measuring input sees an edge in the step of the boundary that sampled it. An axis
//! sees a script stimulus at or before `t` in the step at `t`, and a simulated sensor's edge of
//! the cycle `[t - T, t]` in the step at `t + T`. Inferred: the simulated load's position over
//! a cycle exists only once its axis stepped, so a switch driven by a sensor on the load runs
//! one cycle behind, as a real input does whose terminal samples at the boundary before the
//! controller's cycle.
//!
//! Nothing here allocates after [`Inputs::new`].

use tandem_config::{AxisInputs, Cell, DeviceKind, SignalDirection, SignalIndex};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::plant::link::SwitchInputs;
use tandem_motion::plant::sensor::{InputEdge, InputEdges, SimulatedSensor};

use crate::objects::CycleMotion;

/// Most input edges kept between two [`crate::exec::Executive::drain_input_edges`]; more are
/// counted in [`InputDeviceStatus::unreported`].
pub const INPUT_EDGES: usize = 1024;

/// Most pending stimuli of one device.
const PENDING_MAX: usize = 1024;

/// Most edges of one step (all devices); more are counted as dropped.
const FRAME_MAX: usize = 1024;

/// One edge of an input signal as the process image saw it.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct InputSignalEdge {
    /// The signal (index in [`Cell::signals`]).
    pub signal: usize,
    /// The device (index in [`Cell::devices`]).
    pub device: usize,
    /// The channel, 1-based.
    pub channel: u8,
    /// Rising (`true`) or falling.
    pub rising: bool,
    /// The edge's time (ns, cell clock): its own on a timestamped device, the boundary that
    /// saw it on a plain one.
    pub time_ns: i64,
    /// The boundary whose sample carried it.
    pub sampled_ns: i64,
}

/// The state of a simulated digital input device.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct InputDeviceStatus {
    /// The channels' levels at the last sample: bit `c - 1` is channel `c`.
    pub levels: u32,
    /// Edges reported so far.
    pub edges: u64,
    /// Plain device: changes that ended within one cycle and were not seen at a boundary.
    pub unseen: u64,
    /// Stimuli lost because the device's pending list was full, or edges because a step had
    /// more than fit.
    pub dropped: u64,
    /// Edges not kept for the caller (more than [`INPUT_EDGES`] between two drains).
    pub unreported: u64,
}

/// A level a channel takes at a time.
#[derive(Copy, Clone, Debug)]
struct Stimulus {
    at_ns: i64,
    channel: u8,
    on: bool,
}

/// A simulated digital input device of the process image.
#[derive(Debug)]
struct Terminal {
    /// Index in [`Cell::devices`].
    device: usize,
    cycle_ns: i64,
    timestamped: bool,
    /// Per channel (index `c - 1`): the signal bound to it.
    signals: [Option<usize>; 32],
    /// Stimuli not yet sampled, by time (equal times in arrival order).
    pending: Vec<Stimulus>,
    status: InputDeviceStatus,
}

/// A simulated sensor driving an input signal.
#[derive(Debug)]
struct Sensed {
    /// Index into [`Inputs::terminals`].
    terminal: usize,
    channel: u8,
    /// The axis whose load carries the mark.
    axis: usize,
    sensor: SimulatedSensor,
    edges: InputEdges,
}

/// The input devices of an executive, their stimuli and sensors, and their consumers.
#[derive(Debug)]
pub(crate) struct Inputs {
    terminals: Vec<Terminal>,
    /// Per signal of the cell: its terminal (index into `terminals`) and channel, if it is an
    /// input of a device here.
    slots: Vec<Option<(usize, u8)>>,
    sensors: Vec<Sensed>,
    /// The owned axes with bound switches.
    pub(crate) axes: Vec<(usize, AxisInputs)>,
    /// The measuring inputs fed by a signal: (measuring input, signal).
    pub(crate) measuring: Vec<(usize, usize)>,
    /// The edges of the current step.
    frame: Vec<InputSignalEdge>,
    /// The edges since the last drain.
    kept: Vec<InputSignalEdge>,
}

impl Inputs {
    /// The input devices of node `node` (all of the cell with `None`), the sensors on their
    /// signals and the consumers of `owned_axis` axes.
    pub(crate) fn new(cell: &Cell, node: Option<usize>, owned_axis: &[bool]) -> Self {
        let mut terminals = Vec::new();
        let mut of_device = vec![None; cell.devices.len()];
        for (i, d) in cell.devices.iter().enumerate() {
            let p = match &d.kind {
                DeviceKind::SimDigitalInput(p) => *p,
                // The inputs of a terminal on the node's EtherCAT segment: the edge sets their
                // levels ([`Inputs::set_levels`]).
                DeviceKind::EthercatDioInputs => tandem_config::DigitalInputParams {
                    channels: 8,
                    timestamped: false,
                },
                _ => continue,
            };
            if node.is_some_and(|n| n != d.node) {
                continue;
            }
            of_device[i] = Some(terminals.len());
            terminals.push(Terminal {
                device: i,
                cycle_ns: cell.nodes.get(d.node).map_or(1, |n| n.cycle_ns.max(1)),
                timestamped: p.timestamped,
                signals: [None; 32],
                pending: Vec::with_capacity(PENDING_MAX),
                status: InputDeviceStatus::default(),
            });
        }
        let mut slots = vec![None; cell.signals.len()];
        let mut sensors = Vec::new();
        for (k, s) in cell.signals.iter().enumerate() {
            let Some(t) = of_device.get(s.device.0).copied().flatten() else {
                continue;
            };
            if s.direction != SignalDirection::Input {
                continue;
            }
            slots[k] = Some((t, s.channel));
            if let Some(slot) = terminals[t]
                .signals
                .get_mut(usize::from(s.channel.saturating_sub(1)))
            {
                *slot = Some(k);
            }
            if let Some(x) = &s.sensor {
                sensors.push(Sensed {
                    terminal: t,
                    channel: s.channel,
                    axis: x.axis.0,
                    sensor: x.sensor(),
                    edges: InputEdges::default(),
                });
            }
        }
        let owned = |a: usize| owned_axis.get(a).copied().unwrap_or(false);
        let axes = (cell.inputs.axes.iter().enumerate())
            .filter(|(a, x)| owned(*a) && x.any())
            .map(|(a, x)| (a, *x))
            .collect();
        let measuring = (cell.inputs.measuring_inputs.iter().enumerate())
            .filter_map(|(m, s)| Some((m, (*s)?.0)))
            .filter(|(m, s)| {
                slots.get(*s).copied().flatten().is_some()
                    && cell
                        .measuring_inputs
                        .get(*m)
                        .is_some_and(|x| owned(x.axis.0))
            })
            .collect();
        Self {
            terminals,
            slots,
            sensors,
            axes,
            measuring,
            frame: Vec::with_capacity(FRAME_MAX),
            kept: Vec::with_capacity(INPUT_EDGES),
        }
    }

    /// Whether there is anything to do: input devices here.
    pub(crate) fn any(&self) -> bool {
        !self.terminals.is_empty()
    }

    /// The axes whose cycle motion the sensors need.
    pub(crate) fn sensor_axes(&self) -> impl Iterator<Item = usize> + '_ {
        self.sensors.iter().map(|s| s.axis)
    }

    /// Sets input signal `signal` to `value` from `at_ns`; with `pulse_ns > 0` back to
    /// `!value` at `at_ns + pulse_ns` (a script's `SetInput`). `Err` if the signal is not an
    /// input of a device here; a full pending list drops the stimulus (counted).
    pub(crate) fn set(
        &mut self,
        signal: usize,
        at_ns: i64,
        value: bool,
        pulse_ns: i64,
    ) -> Result<(), ErrorId> {
        let (t, channel) = self
            .slots
            .get(signal)
            .copied()
            .flatten()
            .ok_or(ErrorId::IllegalObject)?;
        let terminal = self.terminals.get_mut(t).ok_or(ErrorId::IllegalObject)?;
        terminal.push(Stimulus {
            at_ns,
            channel,
            on: value,
        });
        if pulse_ns > 0 {
            terminal.push(Stimulus {
                at_ns: at_ns.saturating_add(pulse_ns),
                channel,
                on: !value,
            });
        }
        Ok(())
    }

    /// The levels `levels` (bit `c - 1`: channel `c`) an edge read from input device `device`
    /// at the boundary `t`: each channel that differs from the device's last sample becomes a
    /// stimulus at `t`, sampled by the step at `t`. `false` when the device is not an input
    /// device here.
    pub(crate) fn set_levels(&mut self, device: usize, t: i64, levels: u32) -> bool {
        let Some(k) = self.terminals.iter().position(|d| d.device == device) else {
            return false;
        };
        let Some(d) = self.terminals.get_mut(k) else {
            return false;
        };
        let changed = levels ^ d.status.levels;
        for c in 0..32u8 {
            if changed & (1 << c) != 0 {
                d.push(Stimulus {
                    at_ns: t,
                    channel: c + 1,
                    on: levels & (1 << c) != 0,
                });
            }
        }
        true
    }

    /// Step 1 at `t`: samples the devices due at `t` with the stimuli at or before `t`, a new
    /// frame. The step's earlier edges are forgotten.
    pub(crate) fn sample(&mut self, t: i64) {
        self.frame.clear();
        for k in 0..self.terminals.len() {
            self.apply_due(k, t);
        }
    }

    /// The switches of axis `bound` from the levels of the last sample.
    pub(crate) fn switches(&self, bound: &AxisInputs) -> SwitchInputs {
        let level = |s: Option<SignalIndex>| self.level(s?.0);
        SwitchInputs {
            limit_positive: level(bound.limit_positive),
            limit_negative: level(bound.limit_negative),
            reference_cam: level(bound.reference_cam),
        }
    }

    /// The level of input signal `signal` at the last sample, if it is an input here.
    pub(crate) fn level(&self, signal: usize) -> Option<bool> {
        let (t, channel) = self.slots.get(signal).copied().flatten()?;
        let levels = self.terminals.get(t)?.status.levels;
        Some(levels & channel_bit(channel) != 0)
    }

    /// Step 3 at `t`: the sensors of the axes stepped at `t` add the edges of their cycle to
    /// the frame of `t`.
    pub(crate) fn sense(&mut self, t: i64, motions: &[Option<CycleMotion>]) {
        for k in 0..self.sensors.len() {
            let s = &mut self.sensors[k];
            let Some(m) = motions.get(s.axis).and_then(Option::as_ref) else {
                continue;
            };
            s.sensor.step(&m.actual, &mut s.edges);
            let (terminal, channel) = (s.terminal, s.channel);
            for e in s.edges.as_slice() {
                if let Some(d) = self.terminals.get_mut(terminal) {
                    d.push(Stimulus {
                        at_ns: e.time_ns,
                        channel,
                        on: e.rising,
                    });
                }
            }
            s.edges.clear();
            self.apply_due(terminal, t);
        }
    }

    /// The frame's edges of signal `signal`, as a measuring input takes them.
    pub(crate) fn edges_of(&self, signal: usize) -> impl Iterator<Item = InputEdge> + '_ {
        self.frame
            .iter()
            .filter(move |e| e.signal == signal)
            .map(|e| InputEdge {
                time_ns: e.time_ns,
                rising: e.rising,
                latched: None,
            })
    }

    /// The edges of the current step, in the order they were sampled.
    pub(crate) fn frame(&self) -> &[InputSignalEdge] {
        &self.frame
    }

    /// The state of input device `device` (index in [`Cell::devices`]), if it is here.
    pub(crate) fn status(&self, device: usize) -> Option<&InputDeviceStatus> {
        self.terminals
            .iter()
            .find(|d| d.device == device)
            .map(|d| &d.status)
    }

    /// Hands each edge since the last call to `f`, in order, then forgets them.
    pub(crate) fn drain(&mut self, f: impl FnMut(&InputSignalEdge)) {
        self.kept.iter().for_each(f);
        self.kept.clear();
    }

    /// Samples terminal `k` at `t` if its cycle falls on `t`: its stimuli at or before `t`
    /// become its levels and the frame's edges.
    fn apply_due(&mut self, k: usize, t: i64) {
        let Some(d) = self.terminals.get_mut(k) else {
            return;
        };
        if t % d.cycle_ns != 0 {
            return;
        }
        let n = d.pending.partition_point(|s| s.at_ns <= t);
        let before = d.status.levels;
        let mut levels = before;
        let mut changes = 0u64;
        for s in d.pending.drain(..n) {
            let bit = channel_bit(s.channel);
            let now = if s.on { levels | bit } else { levels & !bit };
            if now == levels {
                continue;
            }
            levels = now;
            changes += 1;
            if d.timestamped {
                let e = edge(d.device, &d.signals, s.channel, s.on, (s.at_ns, t));
                keep(&mut self.frame, &mut self.kept, &mut d.status, e);
            }
        }
        if !d.timestamped {
            let changed = levels ^ before;
            for c in 0..32u8 {
                if changed & (1 << c) == 0 {
                    continue;
                }
                let on = levels & (1 << c) != 0;
                let e = edge(d.device, &d.signals, c + 1, on, (t, t));
                keep(&mut self.frame, &mut self.kept, &mut d.status, e);
                changes = changes.saturating_sub(1);
            }
            d.status.unseen += changes;
        }
        d.status.levels = levels;
    }
}

impl Terminal {
    /// Adds a stimulus in time order; dropped (counted) when the list is full.
    fn push(&mut self, s: Stimulus) {
        if self.pending.len() == self.pending.capacity() {
            self.status.dropped += 1;
            return;
        }
        let at = self.pending.partition_point(|x| x.at_ns <= s.at_ns);
        // Within the capacity the list was made with: no allocation.
        self.pending.insert(at, s);
    }
}

/// The bit of channel `channel` (1-based) in a levels word.
fn channel_bit(channel: u8) -> u32 {
    1u32 << (channel.saturating_sub(1) & 31)
}

/// The edge of channel `channel` of `device` at `(time, sampled)`.
fn edge(
    device: usize,
    signals: &[Option<usize>; 32],
    channel: u8,
    rising: bool,
    (time_ns, sampled_ns): (i64, i64),
) -> InputSignalEdge {
    let signal = signals
        .get(usize::from(channel.saturating_sub(1)))
        .copied()
        .flatten()
        .unwrap_or(usize::MAX);
    InputSignalEdge {
        signal,
        device,
        channel,
        rising,
        time_ns,
        sampled_ns,
    }
}

/// Keeps edge `e` in the step's frame and for the next drain, within their capacities.
fn keep(
    frame: &mut Vec<InputSignalEdge>,
    kept: &mut Vec<InputSignalEdge>,
    status: &mut InputDeviceStatus,
    e: InputSignalEdge,
) {
    status.edges += 1;
    if frame.len() < frame.capacity() {
        frame.push(e);
    } else {
        status.dropped += 1;
    }
    if kept.len() < kept.capacity() {
        kept.push(e);
    } else {
        status.unreported += 1;
    }
}
