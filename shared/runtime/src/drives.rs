//! The drives of a node's process image: the devices with their process data (the CiA 402
//! RxPDO and TxPDO of each drive), the stage that exchanges them at the cycle boundary, and the
//! link between an axis (its [`DriveInputs`] and [`DriveOutputs`]) and its CiA 402 drive.
//!
//! The order within one step at `t` (docs/io.md, "The cycle"):
//! 1. every device of a node whose cycle falls on `t` runs the last cycle to `t` with the
//!    command it latched at the previous boundary, and its inputs are sampled at `t` (the
//!    simulated plant sets the drive's digital inputs, limit switches and home switch, first);
//! 2. each device latches the command the previous step wrote (the outputs are written at the
//!    boundary after the step that computed them);
//! 3. each axis on a drive reads the sample of `t` ([`Cia402Link::inputs`]): actual values
//!    through its encoder and mechanics, the drive's state through the enable sequence;
//! 4. the axes step;
//! 5. each axis's outputs become its drive's command ([`Cia402Link::command`]), latched at
//!    `t + cycle`.
//!
//! So a setpoint computed at `t` acts from `t + cycle` and shows in the actual values read at
//! `t + 2 cycles`: two cycles of transport delay, what the following error is formed against.

use tandem_config::{Cell, Cia402Connection, DeviceKind, DriveConnection};
use tandem_motion::objects::measuring::MeasuringRoute;
use tandem_motion::plant::cia402::{
    digital_inputs, statusword, touch_probe, Cia402State, DeviceCommand, DriveCommand,
    DriveFeedback, EnableSequence, EnableStatus, EnableStep, ModeOfOperation, PowerRequest,
};
use tandem_motion::plant::drive::{Actual, Plant};
use tandem_motion::plant::link::{AxisSignals, DriveInputs, DriveOutputs, DriveState, HomingLatch};
use tandem_motion::plant::mechanics::{EncoderKind, RawCounter, Scaling};
use tandem_motion::plant::servo::{ServoParams, SimServo, SimServoError};

use crate::error::ExecError;

pub mod analog;

/// Cycles between a setpoint and the actual value that shows it (see the module's order).
const TRANSPORT_CYCLES: usize = 2;

/// The most cycles between a setpoint and its actual value a drive may take (the exchange of
/// an external drive adds to [`TRANSPORT_CYCLES`]).
pub const MAX_TRANSPORT_CYCLES: usize = 8;

/// A device of the process image.
#[derive(Debug)]
enum Device {
    /// A simulated CiA 402 servo drive.
    SimServo(Box<SimServo>),
    /// A drive whose process data the edge exchanges (a CiA 402 drive on the node's EtherCAT
    /// segment): the edge puts the TxPDO of `t` in with [`Drives::set_external_feedback`]
    /// before the step at `t` and takes the RxPDO the step wrote with
    /// [`Drives::external_command`] after it.
    External,
}

/// One device with its process data.
#[derive(Debug)]
struct Slot {
    device: Device,
    /// Its node's cycle (ns).
    cycle_ns: i64,
    /// The command written by the last step, latched at the next boundary.
    command: DriveCommand,
    /// The inputs sampled at the last boundary.
    feedback: DriveFeedback,
    /// Whether the device has been sampled once (the first boundary has no cycle before it).
    started: bool,
}

/// The link of one axis to its CiA 402 drive: between the axis's [`DriveInputs`] /
/// [`DriveOutputs`] and the drive's TxPDO / RxPDO.
#[derive(Debug)]
pub struct Cia402Link {
    /// The axis (index in the cell).
    pub axis: usize,
    /// The device (index in the cell).
    device: usize,
    scaling: Scaling,
    enable: EnableSequence,
    /// The raw position word extended, from the first sample on.
    counter: Option<RawCounter>,
    /// The controlword decided with this cycle's inputs, sent with this cycle's command.
    controlword: u16,
    /// The axis's request of the last cycle (enable, fault reset).
    request: PowerRequest,
    /// The position setpoints of the last [`TRANSPORT_CYCLES`] cycles (physical), newest at
    /// `head`: at the next cycle the oldest is the one the actual value shows.
    setpoints: [f64; MAX_TRANSPORT_CYCLES],
    head: usize,
    /// Cycles from a setpoint to the actual value that shows it: [`TRANSPORT_CYCLES`] on a
    /// simulated drive, the device's on an external one (1 to [`MAX_TRANSPORT_CYCLES`]).
    transport: usize,
    /// The simulated plant around the drive (limit switches, reference cam), physical.
    plant: Plant,
    /// The measuring input on the drive's touch probe 1 (index in the cell), if any.
    pub probe_input: Option<usize>,
    /// Arm touch probe 1 with the next command.
    probe_armed: bool,
    /// The touch probe status of the last sample (0x60B9), to see new values.
    probe_status: u16,
    /// What is retained of the axis, if its encoder is absolute or cyclic absolute.
    pub(crate) retention: Option<Retention>,
    /// The axis asked to stop on the drive's ramp (its last [`DriveOutputs::quick_stop`]).
    quick_stop: bool,
    /// The enable sequence reported the drive enabled at the last sample.
    operational: bool,
    /// The statusword 0x6041 of the last sample.
    statusword: u16,
    /// Torque feedforward 0x60B2 in per mille of the rated torque 0x6076 per drive
    /// increment/s² of the setpoint acceleration; `None`: off.
    torque_per_acceleration: Option<f64>,
    /// The torque interface (MC_TorqueLimiting, MC_TorqueAdditive, MC_TorqueRange,
    /// `ActualTorque`): per mille of the rated torque 0x6076 per unit of the axis's torque or
    /// force at the load (through the gear, leadscrew, efficiency and the drive's inversion;
    /// a linear axis's N through `position_unit_m`); `None`: the drive's rated torque is not
    /// known, the axis has no torque interface.
    pub(crate) per_mille_per_load: Option<f64>,
    /// The touch probe homing latches with: 2 when probe 1 serves a measuring input, else 1.
    homing_probe: u8,
    /// The homing mark the homing probe is armed for (as last commanded).
    homing_armed: Option<HomingLatch>,
}

/// The torque objects of one command (per mille of the rated torque; 0: not limited).
#[derive(Copy, Clone, Debug, Default)]
struct TorqueObjects {
    /// Max torque 0x6072.
    max_torque: u16,
    /// Positive torque limit value 0x60E0.
    positive: u16,
    /// Negative torque limit value 0x60E1.
    negative: u16,
    /// Added to the torque offset 0x60B2.
    additive: f64,
}

/// Whether measuring input `m` measures through its axis's drive's touch probe: route
/// PROFIdrive ("the drive latches the position") on an axis with a CiA 402 drive.
pub fn on_touch_probe(cell: &Cell, m: &tandem_config::MeasuringInputEntry) -> bool {
    m.config.route == MeasuringRoute::Profidrive
        && cell
            .axis(m.axis)
            .is_some_and(|a| matches!(a.drive, DriveConnection::Cia402(_)))
}

/// A latch of touch probe 1, for the measuring input on it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ProbeLatch {
    /// Rising (0x60BA) or falling (0x60BB) edge.
    pub rising: bool,
    /// The latched position (physical, units).
    pub position: f64,
}

/// What is retained of an axis on a drive with an absolute or cyclic absolute encoder (its
/// absolute encoder adjustment and, for a cyclic absolute encoder, the count of traversed
/// ranges; S7-1500T Motion Control V4.0 function manual, 'Drive and encoder connection', actual
/// value types), and what was last handed over to be retained ([`crate::exec::AdjustmentChange`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Retention {
    /// A cyclic absolute encoder: its count is retained too, and resumed after a restart.
    pub(crate) cyclic: bool,
    /// The fingerprint an adjustment of this link is made under ([`adjustment_fingerprint`]).
    pub(crate) fingerprint: u64,
    /// The axis's `AbsoluteOffset::changes` last handed over (or restored).
    pub(crate) changes: u32,
    /// The count last handed over (or restored).
    pub(crate) count: i64,
    /// The retained count a cyclic absolute encoder's counter resumes from at the first sample.
    pub(crate) resume: Option<i64>,
}

/// The fingerprint of the configuration an absolute encoder adjustment on a drive of the
/// process image is made under: the encoder's ([`Scaling::fingerprint`]: kind, raw word,
/// multiturn range, inversion, counts to units) and the drive's increments to units (its
/// increments per revolution, the load gear, the leadscrew, `Actor.InverseDirection`), since
/// the axis reads its actual position in the drive's increments. Inferred: S7 voids the
/// adjustment on an encoder configuration change ('When Homed is lost'); a change of the
/// mechanics between the encoder and the load moves the axis's coordinate just as much. FNV-1a
/// over the encoder's fingerprint and the drive's fields.
pub(crate) fn adjustment_fingerprint(s: &Scaling) -> u64 {
    let m = s.mechanics();
    let words = [
        s.fingerprint(),
        m.drive_increments_per_revolution.map_or(0, u64::from),
        u64::from(m.load_gear_numerator),
        u64::from(m.load_gear_denominator),
        m.leadscrew_pitch.map_or(0, f64::to_bits),
        u64::from(m.inverse_drive),
    ];
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in words.iter().flat_map(|w| w.to_le_bytes()) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

impl Retention {
    /// The retention of an axis on connection `c`: `None` for an incremental encoder.
    fn of(c: &Cia402Connection) -> Option<Self> {
        let cyclic = match c.scaling.encoder().kind {
            EncoderKind::Incremental => return None,
            EncoderKind::Absolute => false,
            EncoderKind::CyclicAbsolute => true,
        };
        Some(Self {
            cyclic,
            fingerprint: adjustment_fingerprint(&c.scaling),
            changes: 0,
            count: 0,
            resume: None,
        })
    }
}

/// The devices of the process image and the links of the axes on them.
#[derive(Debug, Default)]
pub(crate) struct Drives {
    /// Per device of the cell; `None` for devices of other nodes.
    slots: Vec<Option<Slot>>,
    /// The owned axes on a drive.
    pub(crate) links: Vec<Cia402Link>,
    /// The analog drives and the owned axes on them.
    pub(crate) analog: analog::AnalogDrives,
}

/// The drive's enable step as [`DriveState`] numbers it (the supplement of alarm 421).
fn step_number(step: EnableStep) -> u8 {
    match step {
        EnableStep::LeaveFault => 0,
        EnableStep::Shutdown => 1,
        EnableStep::SwitchOn => 2,
        EnableStep::EnableOperation => 3,
    }
}

/// Wires the simulated plant into a simulated servo at its physical positions, in the drive's
/// increments: the axis' mechanical stops, its reference cam (on the homing probe's input as
/// well) and the mark of a measuring input on touch probe 1.
fn wire_sim_servo(
    servo: &mut SimServo,
    cell: &Cell,
    a: &tandem_config::AxisEntry,
    c: &Cia402Connection,
    link: &Cia402Link,
) {
    let at = |x: f64| f64::from(c.scaling.drive_increments(x));
    let (lo, hi) = (
        a.config.plant.fixed_stop_min.map(at),
        a.config.plant.fixed_stop_max.map(at),
    );
    // The drive's increments run the other way with an inverted drive.
    let (lo, hi) = if c.scaling.mechanics().inverse_drive {
        (hi, lo)
    } else {
        (lo, hi)
    };
    servo.set_fixed_stops(lo, hi);
    if let Some((lo, hi)) = a.config.plant.reference_cam {
        // The home switch is wired to the homing probe's input as well (the simulated plant's
        // reference cam, at its physical position).
        let (lo, hi) = (at(lo), at(hi));
        // Probe 1 or 2 exists: refused only for another probe number.
        let _ = servo.set_probe_mark(link.homing_probe, Some((lo.min(hi), lo.max(hi))));
    }
    let mark = link
        .probe_input
        .and_then(|k| cell.measuring_inputs.get(k))
        .and_then(|m| m.sensor);
    if let Some(sensor) = mark {
        // The mark at its physical position (the axis's coordinate at start).
        let (lo, hi) = (at(sensor.position), at(sensor.position + sensor.width));
        // Probe 1 exists: refused only for another probe number.
        let _ = servo.set_probe_mark(1, Some((lo.min(hi), lo.max(hi))));
    }
}

impl Drives {
    /// The devices of the owned nodes and the links of the owned axes (`owned[i]`) on them.
    pub(crate) fn new(cell: &Cell, owned: &[bool]) -> Result<Self, ExecError> {
        let mut slots: Vec<Option<Slot>> = cell.devices.iter().map(|_| None).collect();
        let mut links = Vec::new();
        for (i, a) in cell.axes.iter().enumerate() {
            let DriveConnection::Cia402(c) = &a.drive else {
                continue;
            };
            if !owned.get(i).copied().unwrap_or(false) {
                continue;
            }
            let Some(dev) = cell.devices.get(c.device.0) else {
                continue;
            };
            let (device, params) = match &dev.kind {
                DeviceKind::SimServo(params) => {
                    // The motor starts where the axis's initial position puts it.
                    let start = f64::from(c.scaling.drive_increments(a.config.initial_position));
                    let servo = SimServo::new(ServoParams {
                        initial_position: start,
                        ..*params
                    })
                    .map_err(|reason| ExecError::Device {
                        name: dev.name.clone(),
                        reason,
                    })?;
                    (Device::SimServo(Box::new(servo)), Some(*params))
                }
                DeviceKind::EthercatCia402(_) => (Device::External, None),
                // Refused by the configuration: an axis's drive is a servo.
                _ => continue,
            };
            if let Some(slot) = slots.get_mut(c.device.0) {
                *slot = Some(Slot {
                    device,
                    cycle_ns: cell.nodes[dev.node].cycle_ns,
                    command: DriveCommand::default(),
                    feedback: DriveFeedback::default(),
                    started: false,
                });
            }
            let mut link = Cia402Link::new(i, c, a.config.plant, a.config.initial_position)?;
            if let DeviceKind::EthercatCia402(p) = &dev.kind {
                link.transport = usize::from(p.transport_cycles).clamp(1, MAX_TRANSPORT_CYCLES);
            }
            link.probe_input = cell
                .measuring_inputs
                .iter()
                .position(|m| m.axis.0 == i && on_touch_probe(cell, m));
            // Homing latches with touch probe 2 when probe 1 serves a measuring input.
            link.homing_probe = if link.probe_input.is_some() { 2 } else { 1 };
            // 0x60B2 per increment/s²: J · 2π / (increments per revolution) N·m, in per mille
            // of the rated torque 0x6076.
            link.torque_per_acceleration =
                c.torque_precontrol_inertia.zip(params).map(|(j, params)| {
                    j * core::f64::consts::TAU
                        / f64::from(params.increments_per_revolution)
                        / params.rated_torque
                        * 1e3
                });
            link.per_mille_per_load = params.map(|params| {
                let unit = if c.scaling.mechanics().leadscrew_pitch.is_some() {
                    a.config.torque.position_unit_m
                } else {
                    1.0
                };
                unit / c.scaling.torque_factor() / params.rated_torque * 1e3
            });
            if let Some(Some(Slot {
                device: Device::SimServo(servo),
                ..
            })) = slots.get_mut(c.device.0)
            {
                wire_sim_servo(servo, cell, a, c, &link);
            }
            links.push(link);
        }
        let analog = analog::AnalogDrives::new(cell, owned)?;
        Ok(Self {
            slots,
            links,
            analog,
        })
    }

    /// Whether any axis is on a drive of the process image.
    pub(crate) fn any(&self) -> bool {
        !self.links.is_empty() || self.analog.any()
    }

    /// Steps 1 and 2 of the order: every due device runs to `t`, is sampled, and latches the
    /// command written by the previous step.
    pub(crate) fn exchange(&mut self, t: i64) {
        for link in &self.links {
            let Some(Some(slot)) = self.slots.get_mut(link.device) else {
                continue;
            };
            if t % slot.cycle_ns != 0 {
                continue;
            }
            let Device::SimServo(servo) = &mut slot.device else {
                // An external drive's sample of `t` is what the edge put in.
                continue;
            };
            if slot.started {
                servo.advance(slot.cycle_ns);
            }
            slot.started = true;
            servo.set_digital_inputs(link.plant_inputs(servo.position()));
            slot.feedback = servo.feedback();
            // The transition taken is the drive's own business; its state is in the statusword.
            let _ = servo.exchange(&slot.command);
        }
    }

    /// The sample of `t` for link `k`'s axis (step 3), or `None` when its drive's node is not
    /// due.
    pub(crate) fn inputs(&mut self, k: usize, t: i64) -> Option<DriveInputs> {
        let link = self.links.get_mut(k)?;
        let slot = self.slots.get(link.device)?.as_ref()?;
        if t % slot.cycle_ns != 0 {
            return None;
        }
        Some(link.inputs(t, &slot.feedback))
    }

    /// The new touch probe 1 values of link `k`'s drive in the sample of `t`.
    pub(crate) fn probe_latches(&mut self, k: usize, t: i64) -> [Option<ProbeLatch>; 2] {
        let Some(link) = self.links.get_mut(k) else {
            return [None; 2];
        };
        match self.slots.get(link.device) {
            Some(Some(slot)) if t % slot.cycle_ns == 0 => link.probe_latches(&slot.feedback),
            _ => [None; 2],
        }
    }

    /// Step 5: the outputs of link `k`'s axis become its drive's command.
    pub(crate) fn command(&mut self, k: usize, t: i64, out: &DriveOutputs) {
        let Some(link) = self.links.get_mut(k) else {
            return;
        };
        let Some(Some(slot)) = self.slots.get_mut(link.device) else {
            return;
        };
        if t % slot.cycle_ns == 0 {
            slot.command = link.command(out);
        }
    }

    /// Whether this executive runs device `device`.
    pub(crate) fn runs(&self, device: usize) -> bool {
        matches!(self.slots.get(device), Some(Some(_))) || self.analog.runs(device)
    }

    /// Injects a fault with error code `code` into device `device` (a simulated drive), or
    /// removes its cause with `code == 0`.
    pub(crate) fn inject_fault(&mut self, device: usize, code: u16) -> Result<(), SimServoError> {
        if self.analog.runs(device) {
            self.analog.inject_fault(device, code);
            return Ok(());
        }
        let Some(Some(slot)) = self.slots.get_mut(device) else {
            return Ok(());
        };
        let Device::SimServo(servo) = &mut slot.device else {
            // A drive on a fieldbus faults on its own, not on command.
            return Ok(());
        };
        if code == 0 {
            servo.clear_fault_cause();
            Ok(())
        } else {
            servo.inject_fault(code)
        }
    }

    /// Puts the TxPDO the edge exchanged at boundary `t` into external drive `device`: the
    /// sample of `t` its axis reads in the next step. `false` when this executive does not run
    /// an external drive `device`.
    pub(crate) fn set_external_feedback(
        &mut self,
        device: usize,
        feedback: &DriveFeedback,
    ) -> bool {
        match self.slots.get_mut(device) {
            Some(Some(slot)) if matches!(slot.device, Device::External) => {
                slot.feedback = *feedback;
                true
            }
            _ => false,
        }
    }

    /// The RxPDO the last step wrote for external drive `device`: what the edge sends at the
    /// next boundary.
    pub(crate) fn external_command(&self, device: usize) -> Option<&DriveCommand> {
        match self.slots.get(device) {
            Some(Some(slot)) if matches!(slot.device, Device::External) => Some(&slot.command),
            _ => None,
        }
    }

    /// The last feedback of device `device` (for traces and tests).
    pub(crate) fn feedback(&self, device: usize) -> Option<&DriveFeedback> {
        self.slots.get(device)?.as_ref().map(|s| &s.feedback)
    }

    /// The last command to device `device`, simulated or external (for traces and tests).
    pub(crate) fn command_of(&self, device: usize) -> Option<&DriveCommand> {
        self.slots.get(device)?.as_ref().map(|s| &s.command)
    }

    /// Moves the mechanical stops of simulated servo `device` to `min` and `max`, positions of
    /// its axis's load (`None`: no stop there, e.g. the stop gave way); `false` when this
    /// executive runs no such servo.
    pub(crate) fn set_fixed_stops(
        &mut self,
        device: usize,
        min: Option<f64>,
        max: Option<f64>,
    ) -> bool {
        let Some(link) = self.links.iter().find(|l| l.device == device) else {
            return false;
        };
        let at = |x: Option<f64>| x.map(|x| f64::from(link.scaling.drive_increments(x)));
        let (lo, hi) = if link.scaling.mechanics().inverse_drive {
            (at(max), at(min))
        } else {
            (at(min), at(max))
        };
        match self.slots.get_mut(device) {
            Some(Some(Slot {
                device: Device::SimServo(servo),
                ..
            })) => {
                servo.set_fixed_stops(lo, hi);
                true
            }
            _ => false,
        }
    }
}

impl Cia402Link {
    /// The link of axis `axis` (its index in the cell) over connection `c`, with the simulated
    /// plant's switches `plant` and the axis's initial physical position `p0`.
    pub fn new(
        axis: usize,
        c: &Cia402Connection,
        plant: Plant,
        p0: f64,
    ) -> Result<Self, ExecError> {
        let enable = EnableSequence::new(c.enable_timeout_ns).map_err(ExecError::EnableTimeout)?;
        Ok(Self {
            axis,
            device: c.device.0,
            scaling: c.scaling,
            enable,
            counter: None,
            controlword: 0,
            request: PowerRequest::default(),
            setpoints: [p0; MAX_TRANSPORT_CYCLES],
            head: 0,
            transport: TRANSPORT_CYCLES,
            plant,
            probe_input: None,
            probe_armed: false,
            probe_status: 0,
            retention: Retention::of(c),
            quick_stop: false,
            operational: false,
            statusword: 0,
            torque_per_acceleration: None,
            per_mille_per_load: None,
            homing_probe: 1,
            homing_armed: None,
        })
    }

    /// Arms (or disarms) touch probe 1 with the next command: enabled on the probe input,
    /// first event, both edges. A new arming after a disarmed cycle clears what it stored.
    pub fn arm_probe(&mut self, armed: bool) {
        self.probe_armed = armed;
    }

    /// The new values of touch probe 1 in sample `fb` (positive edge first), as physical
    /// positions; call once per sample, after [`Cia402Link::inputs`].
    pub fn probe_latches(&mut self, fb: &DriveFeedback) -> [Option<ProbeLatch>; 2] {
        let status = fb.touch_probe_status;
        let previous = self.probe_status;
        let new = |bit: u16| status & bit != 0 && previous & bit == 0;
        let (pos, neg) = (
            new(touch_probe::STATUS_POSITIVE_STORED),
            new(touch_probe::STATUS_NEGATIVE_STORED),
        );
        self.probe_status = status;
        let at = |raw: i32| {
            let count = self
                .counter
                .map_or(i64::from(raw), |c| c.nearest(raw as u32));
            self.scaling.drive_position(count)
        };
        [
            pos.then(|| ProbeLatch {
                rising: true,
                position: at(fb.touch_probe_1_positive),
            }),
            neg.then(|| ProbeLatch {
                rising: false,
                position: at(fb.touch_probe_1_negative),
            }),
        ]
    }

    /// The drive's digital inputs 0x60FD as the simulated plant's switches see the load at
    /// motor position `increments`.
    fn plant_inputs(&self, increments: f64) -> u32 {
        let p = self.scaling.drive_position(increments.round() as i64);
        let mut bits = 0;
        for (on, bit) in [
            (
                self.plant.at_negative_limit(p),
                digital_inputs::NEGATIVE_LIMIT,
            ),
            (
                self.plant.at_positive_limit(p),
                digital_inputs::POSITIVE_LIMIT,
            ),
            (self.plant.on_reference_cam(p), digital_inputs::HOME_SWITCH),
        ] {
            if on {
                bits |= bit;
            }
        }
        bits
    }

    /// What the axis reads of its drive at `t`: the position actual value 0x6064 and the
    /// velocity actual value 0x606C in the drive's increments (those of its target 0x607A)
    /// through the mechanics, the balanced setpoint (the setpoint of [`TRANSPORT_CYCLES`]
    /// ago), the switches of 0x60FD, and the state of the enable sequence, stepped here with
    /// the axis's last request.
    pub fn inputs(&mut self, t: i64, fb: &DriveFeedback) -> DriveInputs {
        let raw = fb.position_actual as u32;
        let count = match &mut self.counter {
            Some(c) => c.update(raw),
            None => {
                let c = self.first_counter(raw);
                let n = c.map_or(i64::from(fb.position_actual), |c| c.count());
                self.counter = c;
                n
            }
        };
        let out = self
            .enable
            .step(t, self.power_request(fb.statusword), fb.statusword);
        self.controlword = out.controlword;
        self.operational = out.status == EnableStatus::Enabled;
        self.statusword = fb.statusword;
        let state = match out.status {
            EnableStatus::QuickStopping => DriveState::Stopping,
            EnableStatus::Enabled => DriveState::Operational,
            EnableStatus::Enabling { step } => DriveState::Enabling {
                step: step_number(step),
            },
            EnableStatus::TimedOut { step, .. } => DriveState::EnableTimedOut {
                step: step_number(step),
            },
            EnableStatus::Fault => DriveState::Fault {
                code: fb.error_code,
            },
            EnableStatus::Disabled | EnableStatus::Disabling | EnableStatus::Lost { .. } => {
                DriveState::Disabled
            }
        };
        // `(head + 1) % transport` without an integer division (`head < transport`).
        let next = if self.head + 1 >= self.transport {
            0
        } else {
            self.head + 1
        };
        let oldest = self.setpoints.get(next).copied().unwrap_or_default();
        let di = fb.digital_inputs;
        let (zero_mark, reference_cam_left) = self.homing_marks(fb);
        DriveInputs {
            actual: Actual {
                p: self.scaling.drive_position(count),
                v: self.scaling.drive_position(i64::from(fb.velocity_actual)),
                balanced: oldest,
            },
            signals: AxisSignals {
                limit_negative: di & digital_inputs::NEGATIVE_LIMIT != 0,
                limit_positive: di & digital_inputs::POSITIVE_LIMIT != 0,
                reference_cam: di & digital_inputs::HOME_SWITCH != 0,
                reference_cam_left,
                zero_mark,
            },
            state,
            in_limitation: self.operational
                && fb.statusword & statusword::INTERNAL_LIMIT_ACTIVE != 0,
            torque_actual: self
                .per_mille_per_load
                .map_or(0.0, |k| f64::from(fb.torque_actual) / k),
        }
    }

    /// The request to the enable sequence with statusword `sw`: the axis's, except while the
    /// axis has removed the enable to stop on the drive's ramp ([`DriveOutputs::quick_stop`])
    /// and the drive still moves: quick stop 0x0002 (transition 11) while it is in operation
    /// enabled or brakes in quick stop active; once it stands still (bit 10 "target reached" in
    /// quick stop active) or has left on its own (0x605A 1..4: transition 12), the enable goes
    /// (disable voltage 0x0000: transition 12 for the options 5..8 that stay in quick stop
    /// active). Inferred: S7's "the drive brakes on its own ramp" is the CiA 402 quick stop
    /// (0x6085 with 0x605A), not disable voltage, under which the motor coasts.
    fn power_request(&self, sw: u16) -> PowerRequest {
        let braking = self.quick_stop
            && !self.request.enable
            && match Cia402State::from_statusword(sw) {
                Some(Cia402State::OperationEnabled) => true,
                Some(Cia402State::QuickStopActive) => sw & statusword::TARGET_REACHED == 0,
                _ => false,
            };
        if braking {
            PowerRequest {
                enable: true,
                quick_stop: true,
                ..self.request
            }
        } else {
            self.request
        }
    }

    /// The homing probe's latch in sample `fb`, while it is armed for a homing mark: the zero
    /// mark (positive edge of the zero pulse) or the reference cam's edge (negative edge of the
    /// home switch), each a physical position through the raw counter and the mechanics, as
    /// [`Cia402Link::probe_latches`] converts a measuring input's.
    ///
    /// The value is given in every sample from the one that first shows it until the axis
    /// disarms the probe (its homing job took the mark and moved on), not only once: the
    /// axis takes a mark only in a cycle where its own conditions hold (e.g. the home switch
    /// bit of 0x60FD already off, which the plant's rounding to whole increments may show a
    /// cycle after the latch). A first-event latch holds the first edge after arming, so a
    /// repeated value is the same mark.
    fn homing_marks(&self, fb: &DriveFeedback) -> (Option<f64>, Option<f64>) {
        let Some(armed) = self.homing_armed else {
            // Not armed for a mark (every cycle but a homing job's): nothing to look at.
            return (None, None);
        };
        let second = self.homing_probe == 2;
        let shift = if second {
            touch_probe::PROBE_2_SHIFT
        } else {
            0
        };
        let status = (fb.touch_probe_status >> shift) & 0x00FF;
        let stored = |bit: u16| status & touch_probe::STATUS_ENABLED != 0 && status & bit != 0;
        let (positive, negative) = if second {
            (fb.touch_probe_2_positive, fb.touch_probe_2_negative)
        } else {
            (fb.touch_probe_1_positive, fb.touch_probe_1_negative)
        };
        let at = |raw: i32| {
            let count = self
                .counter
                .map_or(i64::from(raw), |c| c.nearest(raw as u32));
            self.scaling.drive_position(count)
        };
        match armed {
            HomingLatch::ZeroMark if stored(touch_probe::STATUS_POSITIVE_STORED) => {
                (Some(at(positive)), None)
            }
            HomingLatch::ReferenceCamEdge if stored(touch_probe::STATUS_NEGATIVE_STORED) => {
                (None, Some(at(negative)))
            }
            _ => (None, None),
        }
    }

    /// The touch probe function bits of the homing probe for the axis's request `wanted`
    /// (touch probe 1 positions): first event, the zero pulse's positive edge or the probe
    /// input's (the home switch's) negative edge. A change from one mark to the other passes
    /// through one disarmed command, so that the drive clears what it stored.
    fn homing_function(&mut self, wanted: Option<HomingLatch>) -> u16 {
        self.homing_armed = match (self.homing_armed, wanted) {
            (Some(armed), Some(w)) if armed != w => None,
            _ => wanted,
        };
        match self.homing_armed {
            None => 0,
            Some(HomingLatch::ZeroMark) => {
                touch_probe::ENABLE | touch_probe::SOURCE_ZERO_PULSE | touch_probe::SAMPLE_POSITIVE
            }
            Some(HomingLatch::ReferenceCamEdge) => {
                touch_probe::ENABLE | touch_probe::SOURCE_INPUT | touch_probe::SAMPLE_NEGATIVE
            }
        }
    }

    /// The counter of the first sample: 0x6064 (an INT32) read as signed; for a cyclic absolute
    /// encoder its raw word of `raw_bits`, resumed from the retained count if one was restored
    /// (the count moves from it by the shortest path to the raw value now).
    fn first_counter(&self, raw: u32) -> Option<RawCounter> {
        match self.retention {
            Some(Retention {
                cyclic: true,
                resume,
                ..
            }) => {
                let bits = self.scaling.encoder().raw_bits;
                match resume {
                    Some(retained) => RawCounter::resume(bits, retained, raw),
                    None => RawCounter::new_signed(bits, raw),
                }
                .ok()
            }
            _ => RawCounter::new_signed(32, raw).ok(),
        }
    }

    /// Whether the drive was sampled (the axis has run on it).
    pub(crate) fn started(&self) -> bool {
        self.counter.is_some()
    }

    /// The extended count of the drive's position, from the first sample on.
    pub(crate) fn count(&self) -> Option<i64> {
        self.counter.map(|c| c.count())
    }

    /// Whether the count moved far enough from `retained` to be retained again
    /// ([`RawCounter::retain_due`]).
    pub(crate) fn count_due(&self, retained: i64) -> bool {
        self.counter.is_some_and(|c| c.retain_due(retained))
    }

    /// The drive's command for the axis's outputs and the controlword of the enable sequence:
    /// - position-controlled (and while not enabled): CSP (8) with the position setpoint
    ///   0x607A and the velocity as feedforward 0x60B1;
    /// - not position-controlled (MC_Power StartMode 0, MC_MoveVelocity / MC_MoveJog with
    ///   PositionControlled FALSE) once the drive is enabled: CSV (9) with the velocity as
    ///   target velocity 0x60FF (the position setpoint still in 0x607A);
    /// - in both, with torque precontrol configured, the setpoint acceleration times the
    ///   inertia as torque offset 0x60B2 (per mille of the rated torque 0x6076);
    /// - touch probe 0x60B8: probe 1 for the measuring input while it has a job, the homing
    ///   probe while a homing job waits for its mark.
    pub fn command(&mut self, out: &DriveOutputs) -> DriveCommand {
        self.request = PowerRequest {
            enable: out.enable,
            quick_stop: false,
            fault_reset: out.fault_reset,
        };
        self.quick_stop = out.quick_stop;
        if self.power_request(self.statusword).quick_stop {
            // The stop on the drive's ramp goes out with the command of the cycle that removed
            // the enable (the sequence decides the same at the next sample), so the drive never
            // follows the setpoint that tracks the actual value.
            self.controlword = DeviceCommand::QuickStop.controlword();
        }
        // `(head + 1) % transport` without an integer division (`head < transport`).
        self.head = if self.head + 1 >= self.transport {
            0
        } else {
            self.head + 1
        };
        if let Some(s) = self.setpoints.get_mut(self.head) {
            *s = out.position;
        }
        let v = self.scaling.drive_increments_per_second_i32(out.velocity);
        let mut probe = if self.probe_armed {
            touch_probe::ENABLE
                | touch_probe::SOURCE_INPUT
                | touch_probe::SAMPLE_POSITIVE
                | touch_probe::SAMPLE_NEGATIVE
        } else {
            0
        };
        let homing = self.homing_function(out.homing_latch);
        probe |= if self.homing_probe == 2 {
            homing << touch_probe::PROBE_2_SHIFT
        } else {
            homing
        };
        let torque = self.torque_per_acceleration.map_or(0.0, |k| {
            k * self.scaling.drive_increments_per_second(out.acceleration)
        });
        let limits = self.torque_limits(out);
        let torque_offset = (torque + limits.additive)
            .round()
            .clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16;
        let velocity_mode = !out.position_controlled && self.operational;
        DriveCommand {
            controlword: self.controlword,
            mode: if velocity_mode {
                ModeOfOperation::CyclicSynchronousVelocity
            } else {
                ModeOfOperation::CyclicSynchronousPosition
            } as i8,
            target_position: self.scaling.drive_increments(out.position),
            target_velocity: if velocity_mode { v } else { 0 },
            velocity_offset: if velocity_mode { 0 } else { v },
            torque_offset,
            max_torque: limits.max_torque,
            positive_torque_limit: limits.positive,
            negative_torque_limit: limits.negative,
            touch_probe_function: probe,
            ..DriveCommand::default()
        }
    }

    /// The torque objects for the axis's torque jobs (see docs/io.md, 'Torque limits and
    /// additive torque'): MC_TorqueLimiting's limit as max torque 0x6072, MC_TorqueRange's
    /// limits as 0x60E0 / 0x60E1 (swapped with an inverted drive), MC_TorqueAdditive's torque
    /// added to the torque offset 0x60B2, all in per mille of the rated torque. A limit rounds
    /// to at least 1 ‰: 0 in these objects means "no limit from the controller".
    fn torque_limits(&self, out: &DriveOutputs) -> TorqueObjects {
        let Some(k) = self.per_mille_per_load else {
            return TorqueObjects::default();
        };
        let per_mille = |x: f64| x.round().clamp(1.0, f64::from(u16::MAX)) as u16;
        let t = &out.torque;
        let (positive, negative) = t.range.map_or((0, 0), |(upper, lower)| {
            let (a, b) = (upper * k, lower * k);
            let (hi, lo) = (a.max(b), a.min(b));
            (per_mille(hi), per_mille(-lo))
        });
        TorqueObjects {
            max_torque: t.limit.map_or(0, |l| per_mille((l * k).abs())),
            positive,
            negative,
            additive: t.additive * k,
        }
    }
}
