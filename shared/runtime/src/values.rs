//! The value channels of a node's process image: `float` signals on simulated analog terminals
//! (`kind = "sim_analog_input"`, `"sim_analog_output"`) and `integer` signals on simulated
//! counter terminals (`kind = "sim_counter"`).
//!
//! # Sampling at the cycle boundary
//!
//! A terminal of a node whose cycle falls on `t` is sampled at the boundary `t`, as the
//! digital inputs are ([`crate::inputs`]): every value a script set at or before `t` acts on
//! its channel in time order, so the channel reads the last of them. A value set between two
//! boundaries and replaced before the next one is not seen (counted in
//! [`ValueDeviceStatus::unseen`]).
//! - A **float** channel reads what its terminal presents:
//!   [`tandem_config::AnalogChannelParams::quantize`], the code `round(v · full / range)`
//!   clamped to `±full` (`full = 2^(bits-1) - 1`, 32767 for a ±10 V 16-bit terminal), and
//!   back in V as `code · range / full`. A value beyond the range reads full scale (counted in
//!   [`ValueDeviceStatus::clipped`]).
//! - An **integer** channel reads its register: the value modulo `2^bits`, signed
//!   ([`tandem_config::CounterParams::wrap`]).
//!
//! A channel whose reading differs from the one at its previous boundary gives one
//! [`InputSignalValue`], timed by that boundary: it is logged, kept for
//! [`crate::exec::Executive::drain_input_values`] and published over Zenoh by a node. No
//! technology object of S7-1500T Motion Control V4.0 takes an analog or counter value as an
//! input (the manual's actual values come from the drive and encoder connection, 'Drive and
//! encoder connection'), so the values go to the log, the status and the signal events only.
//!
//! An analog output terminal holds 0 V until a script's `SetOutput` sets a channel
//! ([`Values::set_output`]): the channel takes the value as it quantizes it at once, the
//! change is logged (`output = <v> [<code>]`) at the next boundary and kept for the drain as
//! an input's is. No technology object writes a float output (an analog drive's setpoint is
//! its own device's word). An EtherCAT `aio` terminal's inputs are set by the node's segment
//! at each boundary ([`Values::set_channel`]) and read as a simulated terminal's.
//!
//! Nothing here allocates after [`Values::new`].

use tandem_config::{
    AnalogChannelParams, Cell, CounterParams, DeviceKind, SignalDirection, ETHERCAT_AIO_CHANNELS,
    ETHERCAT_ENC_COUNTER,
};
use tandem_motion::catalog::error_id::ErrorId;

/// Most value changes kept between two [`crate::exec::Executive::drain_input_values`]; more
/// are counted in [`ValueDeviceStatus::unreported`].
pub const INPUT_VALUES: usize = 1024;

/// Most pending values of one terminal.
const PENDING_MAX: usize = 256;

/// Most value changes of one step (all terminals); more are counted as dropped.
const FRAME_MAX: usize = 256;

/// Most channels of a terminal.
const CHANNELS: usize = tandem_config::MAX_CHANNELS as usize;

/// The value of an `integer` or `float` signal.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum SignalValue {
    /// A counter register's value, signed.
    Integer(i64),
    /// An analog value in its channel's units (V), quantized.
    Float(f64),
}

impl SignalValue {
    /// The value as a float (an integer of at most 32 bits is exact).
    pub fn as_f64(self) -> f64 {
        match self {
            SignalValue::Integer(v) => v as f64,
            SignalValue::Float(v) => v,
        }
    }
}

/// A change of an `integer` or `float` input signal as the process image sampled it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct InputSignalValue {
    /// The signal (index in [`Cell::signals`]).
    pub signal: usize,
    /// The device (index in [`Cell::devices`]).
    pub device: usize,
    /// The channel, 1-based.
    pub channel: u8,
    /// The new reading.
    pub value: SignalValue,
    /// The raw word: an analog channel's code, a counter's register value.
    pub raw: i64,
    /// The boundary whose sample carried it (ns, cell clock).
    pub sampled_ns: i64,
}

/// The state of a simulated analog or counter terminal.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ValueDeviceStatus {
    /// The channels' readings at the last sample: index `c - 1` is channel `c`.
    pub values: [SignalValue; CHANNELS],
    /// Changes reported so far.
    pub changes: u64,
    /// Values set and replaced between two boundaries, never read.
    pub unseen: u64,
    /// Values beyond an analog channel's range, read as full scale.
    pub clipped: u64,
    /// Values lost because the terminal's pending list was full, or changes because a step
    /// had more than fit.
    pub dropped: u64,
    /// Changes not kept for the caller (more than [`INPUT_VALUES`] between two drains).
    pub unreported: u64,
}

/// How a terminal's channels read a value.
#[derive(Copy, Clone, Debug)]
enum Reading {
    Analog(AnalogChannelParams),
    Counter(CounterParams),
}

impl Reading {
    /// `v` as a channel reads it, its raw word, and whether it was clipped.
    fn read(&self, v: f64) -> (SignalValue, i64, bool) {
        match self {
            Reading::Analog(p) => {
                let (code, value) = p.quantize(v);
                let full = f64::from(p.full_scale_code());
                let clipped = (v * full / p.range).round().abs() > full;
                (SignalValue::Float(value), i64::from(code), clipped)
            }
            Reading::Counter(p) => {
                // Whole and within ±2^53 (the script's check): exact.
                let w = p.wrap(v as i64);
                (SignalValue::Integer(w), w, false)
            }
        }
    }

    /// A channel's reading before any value was set: 0.
    fn zero(&self) -> SignalValue {
        match self {
            Reading::Analog(_) => SignalValue::Float(0.0),
            Reading::Counter(_) => SignalValue::Integer(0),
        }
    }
}

/// A value a channel takes from a time.
#[derive(Copy, Clone, Debug)]
struct Stimulus {
    at_ns: i64,
    channel: u8,
    value: f64,
}

/// A simulated analog or counter terminal of the process image.
#[derive(Debug)]
struct Terminal {
    /// Index in [`Cell::devices`].
    device: usize,
    cycle_ns: i64,
    reading: Reading,
    /// Per channel (index `c - 1`): the input signal bound to it.
    signals: [Option<usize>; CHANNELS],
    /// Values not yet sampled, by time (equal times in arrival order).
    pending: Vec<Stimulus>,
    /// Per channel: the raw word at the last sample.
    raw: [i64; CHANNELS],
    status: ValueDeviceStatus,
}

/// The analog and counter terminals of an executive.
#[derive(Debug)]
pub(crate) struct Values {
    terminals: Vec<Terminal>,
    /// Per signal of the cell: its terminal (index into `terminals`) and channel, if it is a
    /// value signal of a terminal here.
    slots: Vec<Option<(usize, u8)>>,
    /// Per signal: whether it is an input (the script may set it).
    input: Vec<bool>,
    /// The changes of the current step.
    frame: Vec<InputSignalValue>,
    /// The changes since the last drain.
    kept: Vec<InputSignalValue>,
    /// The output changes not logged yet.
    out_changes: Vec<InputSignalValue>,
}

impl Values {
    /// The analog and counter terminals of node `node` (all of the cell with `None`).
    pub(crate) fn new(cell: &Cell, node: Option<usize>) -> Self {
        let mut terminals = Vec::new();
        let mut of_device = vec![None; cell.devices.len()];
        for (i, d) in cell.devices.iter().enumerate() {
            let reading = match &d.kind {
                DeviceKind::SimAnalogInput(p) | DeviceKind::SimAnalogOutput(p) => {
                    Reading::Analog(*p)
                }
                DeviceKind::SimCounter(p) => Reading::Counter(*p),
                DeviceKind::EthercatAio | DeviceKind::EthercatAioInputs => {
                    Reading::Analog(ETHERCAT_AIO_CHANNELS)
                }
                DeviceKind::EthercatEnc => Reading::Counter(ETHERCAT_ENC_COUNTER),
                _ => continue,
            };
            if node.is_some_and(|n| n != d.node) {
                continue;
            }
            of_device[i] = Some(terminals.len());
            terminals.push(Terminal {
                device: i,
                cycle_ns: cell.nodes.get(d.node).map_or(1, |n| n.cycle_ns.max(1)),
                reading,
                signals: [None; CHANNELS],
                pending: Vec::with_capacity(PENDING_MAX),
                raw: [0; CHANNELS],
                status: ValueDeviceStatus {
                    values: [reading.zero(); CHANNELS],
                    changes: 0,
                    unseen: 0,
                    clipped: 0,
                    dropped: 0,
                    unreported: 0,
                },
            });
        }
        let mut slots = vec![None; cell.signals.len()];
        let mut input = vec![false; cell.signals.len()];
        for (k, s) in cell.signals.iter().enumerate() {
            let Some(t) = of_device.get(s.device.0).copied().flatten() else {
                continue;
            };
            slots[k] = Some((t, s.channel));
            input[k] = s.direction == SignalDirection::Input;
            if let Some(slot) = terminals[t]
                .signals
                .get_mut(usize::from(s.channel.saturating_sub(1)))
            {
                *slot = Some(k);
            }
        }
        Self {
            terminals,
            slots,
            input,
            frame: Vec::with_capacity(FRAME_MAX),
            kept: Vec::with_capacity(INPUT_VALUES),
            out_changes: Vec::with_capacity(FRAME_MAX),
        }
    }

    /// Whether there is anything to do: value terminals here.
    pub(crate) fn any(&self) -> bool {
        !self.terminals.is_empty()
    }

    /// Sets input signal `signal` to `value` from `at_ns` (a script's `SetInput` with a
    /// number). `Err` if the signal is not a value input of a terminal here; a full pending
    /// list drops the value (counted).
    pub(crate) fn set(&mut self, signal: usize, at_ns: i64, value: f64) -> Result<(), ErrorId> {
        let (t, channel) = self
            .slots
            .get(signal)
            .copied()
            .flatten()
            .filter(|_| self.input.get(signal).copied().unwrap_or(false))
            .ok_or(ErrorId::IllegalObject)?;
        if !value.is_finite() {
            return Err(ErrorId::IllegalObject);
        }
        let d = self.terminals.get_mut(t).ok_or(ErrorId::IllegalObject)?;
        if d.pending.len() == d.pending.capacity() {
            d.status.dropped += 1;
            return Ok(());
        }
        let at = d.pending.partition_point(|x| x.at_ns <= at_ns);
        // Within the capacity the list was made with: no allocation.
        d.pending.insert(
            at,
            Stimulus {
                at_ns,
                channel,
                value,
            },
        );
        Ok(())
    }

    /// Sets channel `channel` (1-based) of terminal `device` (index in [`Cell::devices`]) to
    /// `value` from `at_ns`, as a script's `SetInput` sets its signal (the node's EtherCAT
    /// segment: an `aio` terminal's input words). `false` if the terminal is not here or the
    /// value is not finite; a full pending list drops the value (counted).
    pub(crate) fn set_channel(
        &mut self,
        device: usize,
        channel: u8,
        at_ns: i64,
        value: f64,
    ) -> bool {
        let Some(d) = self.terminals.iter_mut().find(|d| d.device == device) else {
            return false;
        };
        if !value.is_finite() || channel == 0 || usize::from(channel) > CHANNELS {
            return false;
        }
        if d.pending.len() == d.pending.capacity() {
            d.status.dropped += 1;
            return true;
        }
        let at = d.pending.partition_point(|x| x.at_ns <= at_ns);
        // Within the capacity the list was made with: no allocation.
        d.pending.insert(
            at,
            Stimulus {
                at_ns,
                channel,
                value,
            },
        );
        true
    }

    /// Sets `float` output signal `signal` to `value` at `at_ns` (a script's `SetOutput`):
    /// its channel takes the quantized value at once. `Err` if the signal is not an analog
    /// output of a terminal here or the value is not finite.
    pub(crate) fn set_output(
        &mut self,
        signal: usize,
        at_ns: i64,
        value: f64,
    ) -> Result<(), ErrorId> {
        let (t, channel) = self
            .slots
            .get(signal)
            .copied()
            .flatten()
            .filter(|_| !self.input.get(signal).copied().unwrap_or(true))
            .ok_or(ErrorId::IllegalObject)?;
        let d = self.terminals.get_mut(t).ok_or(ErrorId::IllegalObject)?;
        if !value.is_finite() || !matches!(d.reading, Reading::Analog(_)) {
            return Err(ErrorId::IllegalObject);
        }
        let (read, raw, clipped) = d.reading.read(value);
        d.status.clipped += u64::from(clipped);
        let c = usize::from(channel.saturating_sub(1));
        let (Some(old), Some(slot)) = (d.raw.get_mut(c), d.status.values.get_mut(c)) else {
            return Err(ErrorId::IllegalObject);
        };
        if *old == raw {
            return Ok(());
        }
        *old = raw;
        *slot = read;
        d.status.changes += 1;
        let e = InputSignalValue {
            signal,
            device: d.device,
            channel,
            value: read,
            raw,
            sampled_ns: at_ns,
        };
        d.status.dropped += u64::from(!push_within_capacity(&mut self.out_changes, e));
        d.status.unreported += u64::from(!push_within_capacity(&mut self.kept, e));
        Ok(())
    }

    /// The output changes since the last call (to log), then forgotten.
    pub(crate) fn take_output_changes(&mut self, f: impl FnMut(&InputSignalValue)) {
        self.out_changes.iter().for_each(f);
        self.out_changes.clear();
    }

    /// Samples the terminals due at `t` with the values set at or before `t`: a new frame.
    pub(crate) fn sample(&mut self, t: i64) {
        self.frame.clear();
        for d in &mut self.terminals {
            if t % d.cycle_ns != 0 {
                continue;
            }
            let n = d.pending.partition_point(|s| s.at_ns <= t);
            // Per channel: the last value set, in time order.
            let mut last: [Option<f64>; CHANNELS] = [None; CHANNELS];
            for s in d.pending.drain(..n) {
                if let Some(slot) = last.get_mut(usize::from(s.channel.saturating_sub(1))) {
                    d.status.unseen += u64::from(slot.is_some());
                    *slot = Some(s.value);
                }
            }
            for (c, v) in last.iter().enumerate() {
                let Some(v) = *v else {
                    continue;
                };
                let (value, raw, clipped) = d.reading.read(v);
                d.status.clipped += u64::from(clipped);
                let (Some(old), Some(slot)) = (d.raw.get_mut(c), d.status.values.get_mut(c)) else {
                    continue;
                };
                if *old == raw {
                    continue;
                }
                *old = raw;
                *slot = value;
                let e = InputSignalValue {
                    signal: d.signals.get(c).copied().flatten().unwrap_or(usize::MAX),
                    device: d.device,
                    channel: c as u8 + 1,
                    value,
                    raw,
                    sampled_ns: t,
                };
                d.status.changes += 1;
                d.status.dropped += u64::from(!push_within_capacity(&mut self.frame, e));
                d.status.unreported += u64::from(!push_within_capacity(&mut self.kept, e));
            }
        }
    }

    /// The changes of the current step, in the order they were sampled.
    pub(crate) fn frame(&self) -> &[InputSignalValue] {
        &self.frame
    }

    /// The reading of value signal `signal` at the last sample, if its terminal is here.
    pub(crate) fn value(&self, signal: usize) -> Option<SignalValue> {
        let (t, channel) = self.slots.get(signal).copied().flatten()?;
        let d = self.terminals.get(t)?;
        d.status
            .values
            .get(usize::from(channel.saturating_sub(1)))
            .copied()
    }

    /// The state of terminal `device` (index in [`Cell::devices`]), if it is here.
    pub(crate) fn status(&self, device: usize) -> Option<&ValueDeviceStatus> {
        self.terminals
            .iter()
            .find(|d| d.device == device)
            .map(|d| &d.status)
    }

    /// Hands each change since the last call to `f`, in order, then forgets them.
    pub(crate) fn drain(&mut self, f: impl FnMut(&InputSignalValue)) {
        self.kept.iter().for_each(f);
        self.kept.clear();
    }
}

/// Pushes `e` if `v` has room for it without growing (the cyclic path does not allocate);
/// whether it did.
fn push_within_capacity(v: &mut Vec<InputSignalValue>, e: InputSignalValue) -> bool {
    let room = v.len() < v.capacity();
    if room {
        v.push(e);
    }
    room
}
