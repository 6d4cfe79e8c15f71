//! The analog drives of a node's process image (`[devices.<name>] kind = "sim_analog_drive"`)
//! and the links of the axes on them (`[axes.<name>.drive] type = "analog"`): the drive's
//! process data (enable DO and output word out, ready DI and encoder raw word in) and the
//! axis's [`AnalogConnection`], in the same order of a cycle as the CiA 402 drives
//! ([`crate::drives`]): devices run to `t` and are sampled, latch the previous step's command;
//! the axes read their sample; the axes step; their outputs become the command latched at the
//! next boundary.

use tandem_config::{AnalogDriveConnection, Cell, DeviceKind, DriveConnection};
use tandem_motion::hydraulic::controller::HydController;
use tandem_motion::objects::axis::Axis;
use tandem_motion::plant::analog::{
    Amplifier, AnalogCommand, AnalogConnection, AnalogConnectionError, AnalogFeedback,
    AnalogStatus, SimAnalogDrive, SimAnalogParams,
};
use tandem_motion::plant::hydraulic::SimValveCylinder;
use tandem_motion::plant::link::{DriveInputs, DriveOutputs};

use crate::error::ExecError;

/// A simulated device on an analog output: a speed-controlled drive, or a proportional valve
/// with its cylinder (a hydraulic axis).
#[derive(Debug)]
enum AnalogDevice {
    Motor(SimAnalogDrive),
    Cylinder(SimValveCylinder),
}

impl AnalogDevice {
    fn exchange(&mut self, c: &AnalogCommand) {
        match self {
            Self::Motor(d) => d.exchange(c),
            Self::Cylinder(d) => d.exchange(c),
        }
    }

    fn advance(&mut self, dt_ns: i64) {
        match self {
            Self::Motor(d) => d.advance(dt_ns),
            Self::Cylinder(d) => d.advance(dt_ns),
        }
    }

    fn feedback(&self) -> AnalogFeedback {
        match self {
            Self::Motor(d) => d.feedback(),
            Self::Cylinder(d) => d.feedback(),
        }
    }

    fn amplifier(&self) -> &Amplifier {
        match self {
            Self::Motor(d) => d.amplifier(),
            Self::Cylinder(d) => d.amplifier(),
        }
    }

    fn amplifier_mut(&mut self) -> &mut Amplifier {
        match self {
            Self::Motor(d) => d.amplifier_mut(),
            Self::Cylinder(d) => d.amplifier_mut(),
        }
    }

    /// The load's position and velocity (units, units/s).
    fn motion(&self) -> (f64, f64) {
        match self {
            Self::Motor(d) => (d.position(), d.velocity()),
            Self::Cylinder(d) => (d.state().position, d.state().velocity),
        }
    }
}

/// A simulated analog drive with its process data.
#[derive(Debug)]
struct AnalogSlot {
    drive: AnalogDevice,
    /// Its node's cycle (ns).
    cycle_ns: i64,
    /// The command written by the last step, latched at the next boundary.
    command: AnalogCommand,
    /// The inputs sampled at the last boundary.
    feedback: AnalogFeedback,
    /// Whether the device has been sampled once.
    started: bool,
}

/// The link of one axis to its analog drive.
#[derive(Debug)]
pub struct AnalogLink {
    /// The axis (index in the cell).
    pub axis: usize,
    /// The device (index in the cell).
    device: usize,
    /// Encoder, handshake and position controller.
    connection: AnalogConnection,
}

impl AnalogLink {
    /// The link of axis `axis` over connection `c`, the axis with the simulated plant's
    /// switches `plant` at physical position `p0`.
    pub fn new(
        axis: usize,
        c: &AnalogDriveConnection,
        plant: tandem_motion::plant::drive::Plant,
        p0: f64,
    ) -> Result<Self, AnalogConnectionError> {
        let connection = match c.hydraulic {
            Some(h) => AnalogConnection::hydraulic(
                c.params,
                HydController::new(h, c.characteristic_curve.as_deref().cloned())
                    .map_err(AnalogConnectionError::Hydraulic)?,
                plant,
                p0,
            )?,
            None => AnalogConnection::new(c.params, plant, p0)?,
        };
        let connection = match c.pressure {
            Some(s) => connection.with_pressure_inputs(s)?,
            None => connection,
        };
        Ok(Self {
            axis,
            device: c.device.0,
            connection,
        })
    }

    /// The connection (encoder, handshake, controller).
    pub fn connection(&self) -> &AnalogConnection {
        &self.connection
    }
}

/// What an analog drive and its link show (for traces and tests).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AnalogDriveStatus {
    /// The link's last cycle: handshake, enable DO, ready DI, command, control difference.
    pub link: AnalogStatus,
    /// The command the drive latched at the last boundary.
    pub latched: AnalogCommand,
    /// The drive's sample at the last boundary.
    pub feedback: AnalogFeedback,
    /// The load's position (units, physical) and velocity (units/s) now.
    pub position: f64,
    /// The load's velocity (units/s).
    pub velocity: f64,
    /// The drive is in fault.
    pub in_fault: bool,
}

/// The analog drives of the process image and the links of the axes on them.
#[derive(Debug, Default)]
pub(crate) struct AnalogDrives {
    /// Per device of the cell; `None` for devices that are not analog drives of owned axes.
    slots: Vec<Option<AnalogSlot>>,
    /// The owned axes on an analog drive.
    pub(crate) links: Vec<AnalogLink>,
}

impl AnalogDrives {
    /// The analog drives of the owned axes (`owned[i]`) and their links.
    pub(crate) fn new(cell: &Cell, owned: &[bool]) -> Result<Self, ExecError> {
        let mut slots: Vec<Option<AnalogSlot>> = cell.devices.iter().map(|_| None).collect();
        let mut links = Vec::new();
        for (i, a) in cell.axes.iter().enumerate() {
            let DriveConnection::Analog(c) = &a.drive else {
                continue;
            };
            if !owned.get(i).copied().unwrap_or(false) {
                continue;
            }
            let Some(dev) = cell.devices.get(c.device.0) else {
                continue;
            };
            let refused = |reason| ExecError::AnalogDrive {
                name: dev.name.clone(),
                reason,
            };
            let scaling = c.params.scaling;
            let p0 = a.config.initial_position;
            // The load starts where the axis's initial position puts it.
            let drive = match &dev.kind {
                DeviceKind::SimAnalogDrive(params) => AnalogDevice::Motor(
                    SimAnalogDrive::new(
                        SimAnalogParams {
                            initial_revolutions: SimAnalogDrive::revolutions_at(&scaling, p0),
                            ..*params
                        },
                        scaling,
                    )
                    .map_err(|e| refused(AnalogConnectionError::Params(e)))?,
                ),
                DeviceKind::SimValveCylinder(params) => AnalogDevice::Cylinder(
                    SimValveCylinder::new(*params, scaling, p0)
                        .map_err(|e| refused(AnalogConnectionError::Cylinder(e)))?,
                ),
                // Refused by the configuration: an analog axis's device is an analog drive.
                _ => continue,
            };
            if let Some(slot) = slots.get_mut(c.device.0) {
                *slot = Some(AnalogSlot {
                    drive,
                    cycle_ns: cell.nodes[dev.node].cycle_ns,
                    command: AnalogCommand::default(),
                    feedback: AnalogFeedback::default(),
                    started: false,
                });
            }
            links.push(AnalogLink::new(i, c, a.config.plant, p0).map_err(refused)?);
        }
        Ok(Self { slots, links })
    }

    /// Whether any axis is on an analog drive.
    pub(crate) fn any(&self) -> bool {
        !self.links.is_empty()
    }

    /// Every due drive runs to `t`, is sampled, and latches the command of the previous step.
    pub(crate) fn exchange(&mut self, t: i64) {
        for link in &self.links {
            let Some(Some(slot)) = self.slots.get_mut(link.device) else {
                continue;
            };
            if t % slot.cycle_ns != 0 {
                continue;
            }
            if slot.started {
                slot.drive.advance(slot.cycle_ns);
            }
            slot.started = true;
            slot.feedback = slot.drive.feedback();
            slot.drive.exchange(&slot.command);
        }
    }

    /// The sample of `t` for link `k`'s axis, or `None` when its drive's node is not due.
    pub(crate) fn inputs(&mut self, k: usize, t: i64) -> Option<DriveInputs> {
        let link = self.links.get_mut(k)?;
        let slot = self.slots.get(link.device)?.as_ref()?;
        if t % slot.cycle_ns != 0 {
            return None;
        }
        Some(link.connection.inputs(t, &slot.feedback))
    }

    /// The outputs of link `k`'s axis become its drive's command.
    pub(crate) fn command(&mut self, k: usize, t: i64, out: &DriveOutputs) {
        let Some(link) = self.links.get_mut(k) else {
            return;
        };
        let Some(Some(slot)) = self.slots.get_mut(link.device) else {
            return;
        };
        if t % slot.cycle_ns == 0 {
            slot.command = link.connection.command(out);
        }
    }

    /// Whether this executive runs analog drive `device`.
    pub(crate) fn runs(&self, device: usize) -> bool {
        matches!(self.slots.get(device), Some(Some(_)))
    }

    /// A fault in analog drive `device` (`code != 0`; an analog drive reports no code, only
    /// its ready output drops), or its cause removed (`code == 0`).
    pub(crate) fn inject_fault(&mut self, device: usize, code: u16) {
        if let Some(Some(slot)) = self.slots.get_mut(device) {
            let amplifier = slot.drive.amplifier_mut();
            if code == 0 {
                amplifier.clear_fault_cause();
            } else {
                amplifier.inject_fault();
            }
        }
    }

    /// The state of analog drive `device` and its link.
    /// The last cycle of the link of axis `axis` (an owned axis on an analog drive).
    pub(crate) fn link_status(&self, axis: usize) -> Option<&AnalogStatus> {
        self.links
            .iter()
            .find(|l| l.axis == axis)
            .map(|l| l.connection.status())
    }

    pub(crate) fn status(&self, device: usize) -> Option<AnalogDriveStatus> {
        let slot = self.slots.get(device)?.as_ref()?;
        let link = self.links.iter().find(|l| l.device == device)?;
        let (position, velocity) = slot.drive.motion();
        Some(AnalogDriveStatus {
            link: *link.connection.status(),
            latched: *slot.drive.amplifier().command(),
            feedback: slot.feedback,
            position,
            velocity,
            in_fault: slot.drive.amplifier().in_fault(),
        })
    }
}

impl AnalogDrives {
    /// Steps 1 to 3 of the order for the analog drives at `t`: every due drive runs to `t`,
    /// is sampled and latches the last command; each axis on one reads its sample.
    pub(crate) fn read(&mut self, t: i64, axes: &mut [Axis]) {
        self.exchange(t);
        for k in 0..self.links.len() {
            let Some(axis) = self.links.get(k).map(|l| l.axis) else {
                continue;
            };
            if let (Some(inputs), Some(a)) = (self.inputs(k, t), axes.get_mut(axis)) {
                a.set_drive_inputs(&inputs);
                if let Some(f) = self.links.get(k).and_then(|l| l.connection.actual_force()) {
                    a.set_hydraulic_actual(f);
                }
            }
        }
    }

    /// Step 5 for the analog drives: each axis's outputs become its drive's command.
    pub(crate) fn write(&mut self, t: i64, axes: &[Axis]) {
        for k in 0..self.links.len() {
            let Some(out) = self
                .links
                .get(k)
                .and_then(|l| axes.get(l.axis))
                .map(Axis::drive_outputs)
            else {
                continue;
            };
            self.command(k, t, &out);
        }
    }
}
