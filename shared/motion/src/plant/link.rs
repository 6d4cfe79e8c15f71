//! The connection of an axis to its drive and sensors: what the axis reads at the start of its
//! cycle ([`DriveInputs`]) and what it writes at the end ([`DriveOutputs`]), whatever is behind
//! them.
//!
//! Two kinds of connection, as in S7-1500T (S7-1500T Motion Control V4.0 function manual, 'Drive
//! and encoder connection' and 'Simulated/virtual actual value'):
//! - [`DriveLink::Simulation`]: the axis in simulation. The drive model and the sensors of the
//!   plant ([`SimPlant`]) are inside the axis and stepped with it; no process image.
//! - [`DriveLink::Connected`]: a drive behind the node's process image (a CiA 402 drive, real or
//!   simulated, or an analog output with an encoder). The node's drive adapter fills
//!   [`DriveInputs`] from the image before the axis steps ([`crate::objects::axis::Axis::set_drive_inputs`])
//!   and turns [`DriveOutputs`] into the drive's command after it.
//!
//! Positions here are physical: the drive's own coordinate, before the axis adds its homing
//! offset.

use super::drive::{Actual, DriveModel, Plant, SimDrive};

/// The axis's input signals of one cycle, in physical coordinates (S7-1500T: hardware limit
/// switches, the reference cam and the encoder zero mark, sampled with the drive's actual
/// values in the servo process image partition).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AxisSignals {
    /// Positive hardware limit switch active (`PositionLimits_HW.MaxSwitch`).
    pub limit_positive: bool,
    /// Negative hardware limit switch active (`PositionLimits_HW.MinSwitch`).
    pub limit_negative: bool,
    /// The reference cam (homing switch) is active.
    pub reference_cam: bool,
    /// The reference cam went inactive since the last cycle, at this physical position (its
    /// edge, latched by the drive's measuring input as the homing mark "digital input").
    pub reference_cam_left: Option<f64>,
    /// An encoder zero mark was passed since the last cycle, at this physical position.
    pub zero_mark: Option<f64>,
}

impl AxisSignals {
    /// The simulated plant's switches at physical position `p` and the edges passed since
    /// `prev` (the reference cam left, at its edge; a zero mark), as a drive's measuring input
    /// would latch them.
    pub fn of_plant(plant: &Plant, prev: f64, p: f64) -> Self {
        let on_cam = |x: f64| plant.on_reference_cam(x);
        let reference_cam_left = match plant.reference_cam {
            Some((lo, hi)) if on_cam(prev) && !on_cam(p) => Some(if p > prev { hi } else { lo }),
            _ => None,
        };
        Self {
            limit_positive: plant.at_positive_limit(p),
            limit_negative: plant.at_negative_limit(p),
            reference_cam: on_cam(p),
            reference_cam_left,
            zero_mark: plant.zero_mark.and_then(|z| z.crossed(prev, p)),
        }
    }
}

/// The state of the drive as the axis sees it.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum DriveState {
    /// Ready, not enabled (no torque).
    #[default]
    Disabled,
    /// The enable sequence runs; `step` names the step it waits for (drive-specific numbering,
    /// documented with the drive connection).
    Enabling {
        /// The step waited for.
        step: u8,
    },
    /// Enabled: the drive follows the setpoints.
    Operational,
    /// The drive reports a fault with this error code (CiA 402 0x603F; 0 when the drive gives
    /// none).
    Fault {
        /// The drive's error code.
        code: u16,
    },
    /// The enable sequence did not complete in time: `step` names the step that did not.
    EnableTimedOut {
        /// The step that did not complete.
        step: u8,
    },
    /// Enable removed with a stop on the drive's own ramp: the drive is braking (CiA 402: quick
    /// stop active, the ramp of 0x605A / 0x6085 not finished). Not enabled, as
    /// [`DriveState::Disabled`].
    #[doc(alias = "QuickStopActive")]
    Stopping,
}

/// A mark the homing job waits for, to be latched by the drive (its touch probe) while the
/// axis asks for it ([`DriveOutputs::homing_latch`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HomingLatch {
    /// The encoder zero mark (CiA 402 touch probe source: the zero pulse).
    ZeroMark,
    /// The reference cam's edge where the axis leaves the cam (the home switch on the touch
    /// probe input, its falling edge).
    ReferenceCamEdge,
}

/// What the axis reads at the start of its cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct DriveInputs {
    /// Actual position and velocity (physical) and the balanced setpoint, the reference of
    /// the following error.
    pub actual: Actual,
    /// Limit switches, reference cam, zero mark.
    pub signals: AxisSignals,
    /// The drive's state.
    pub state: DriveState,
    /// The drive works at one of its own limits (CiA 402 statusword 0x6041 bit 11 "internal
    /// limit active", e.g. its torque limit): the axis shows StatusWord X27 "InLimitation".
    #[doc(alias = "InLimitation")]
    pub in_limitation: bool,
    /// The drive's actual torque (CiA 402 torque actual value 0x6077) at the load, in the
    /// axis's torque or force unit (N·m, or N on a linear axis); 0 for a drive without one
    /// (`StatusTorqueData.ActualTorque`).
    #[doc(alias = "ActualTorque")]
    pub torque_actual: f64,
}

/// What the axis writes at the end of its cycle: the setpoint for the next cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct DriveOutputs {
    /// Position setpoint (physical).
    pub position: f64,
    /// Velocity setpoint (precontrol).
    pub velocity: f64,
    /// The enable: the drive is to be (or stay) operational.
    pub enable: bool,
    /// Position-controlled operation (`false`: the velocity setpoint alone acts).
    pub position_controlled: bool,
    /// Acknowledge a drive fault (MC_Reset): set for the one cycle of the reset.
    pub fault_reset: bool,
    /// Acceleration setpoint (physical units/s²), for a torque feedforward.
    pub acceleration: f64,
    /// With `enable` false: the enable was removed to stop on the drive's own ramp (MC_Power
    /// StopMode 1 "immediate stop" and the alarm reactions "remove enable" and "track
    /// setpoints": setpoint 0, the drive brakes on its own). A CiA 402 drive gets quick stop
    /// until it stands still. `false`: the axis has braked itself; the enable goes at once.
    #[doc(alias = "QuickStop")]
    pub quick_stop: bool,
    /// The homing job waits for this mark: the drive is to latch it (armed only while set).
    pub homing_latch: Option<HomingLatch>,
    /// A hydraulic axis' values for its valve's Finish stage (zero for other axes).
    pub hydraulic: HydValveOutputs,
    /// The torque limits and the additive torque (MC_TorqueLimiting, MC_TorqueRange,
    /// MC_TorqueAdditive), at the load; none without those jobs.
    pub torque: TorqueOutputs,
}

/// What the torque instructions give the drive, at the load in the axis's torque or force unit
/// (N·m, or N on a linear axis: S7-1500T Motion Control V4.0, 'Force/torque limiting'); the
/// drive link converts them through the mechanics to the drive's per mille of the rated
/// torque. In the axis's sense of direction (the link inverts them with the drive's
/// direction).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct TorqueOutputs {
    /// MC_TorqueLimiting: the force/torque limit (>= 0), the same in both directions.
    #[doc(alias = "MC_TorqueLimiting")]
    pub limit: Option<f64>,
    /// MC_TorqueRange: the upper and the lower torque limit (upper > lower).
    #[doc(alias = "MC_TorqueRange")]
    pub range: Option<(f64, f64)>,
    /// MC_TorqueAdditive: the additive torque (0 without the job).
    #[doc(alias = "MC_TorqueAdditive")]
    pub additive: f64,
}

/// What a hydraulic axis gives its valve's Finish stage besides the setpoint (Beckhoff TwinCAT
/// PLC Hydraulic Positioning library, members of `ST_TcHydAxRtData` and `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct HydValveOutputs {
    /// `fClampingOutput` (V): the generator's pressing output at the target (target clamping).
    pub clamping_output: f64,
    /// `fZeroCompensation` (V) as `MC_AxCtrlAutoZero_BkPlcMc` has set it; `None`: the
    /// configured one.
    pub zero_compensation: Option<f64>,
    /// The valve output is suppressed (0) while an emergency or immediate stop holds its lock
    /// (`bLocked_Estop` of `MC_EmergencyStop_BkPlcMc` / `MC_ImmediateStop_BkPlcMc`).
    #[doc(alias = "bLocked_Estop")]
    pub locked: bool,
    /// The control value of `MC_AxRtSetDirectOutput_BkPlcMc` (normalised, ±1.0 = full scale):
    /// Finish takes it in place of the set velocity and the position controller's output.
    /// `None`: none runs.
    #[doc(alias = "MC_AxRtSetDirectOutput_BkPlcMc")]
    pub direct_output: Option<f64>,
}

/// Switch levels read from input signals of the node's process image, in place of the
/// plant's simulated switch positions (`None`: the plant's own switch).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct SwitchInputs {
    /// The positive hardware limit switch.
    pub limit_positive: Option<bool>,
    /// The negative hardware limit switch.
    pub limit_negative: Option<bool>,
    /// The reference cam.
    pub reference_cam: Option<bool>,
}

/// The simulated drive and the sensors of its plant (the axis in simulation).
#[derive(Clone, Debug)]
pub struct SimPlant {
    drive: SimDrive,
    plant: Plant,
    /// The physical position of the last sample, for the edges since then.
    last: f64,
    /// Switches from input signals, set before each sample.
    inputs: SwitchInputs,
    /// The reference cam's level at the last sample (for an input signal's edge).
    cam_level: bool,
    /// Neither the plant nor an input signal gives a switch or a mark: every sample's
    /// signals are all off (set with the plant and the inputs, so a sample skips the sensors).
    no_sensors: bool,
}

impl SimPlant {
    /// `PositionControl.Kv` and `.Kpc` (fraction) of a position-loop drive model, from the next
    /// sample (MC_WriteParameter); the other models have none.
    pub fn set_gains(&mut self, kv: f64, kpc: f64) {
        self.drive.set_gains(kv, kpc);
    }

    /// A drive at rest at physical position `p0` on a servo cycle of `cycle` s, braking on
    /// `stop_deceleration` without its enable.
    pub fn new(
        model: DriveModel,
        plant: Plant,
        cycle: f64,
        stop_deceleration: f64,
        p0: f64,
    ) -> Self {
        Self {
            drive: SimDrive::new(model, cycle, stop_deceleration, p0),
            last: p0,
            inputs: SwitchInputs::default(),
            cam_level: false,
            no_sensors: Self::without_sensors(&plant, &SwitchInputs::default()),
            plant,
        }
    }

    /// Whether `plant` and `inputs` give no switch and no mark at all.
    fn without_sensors(plant: &Plant, inputs: &SwitchInputs) -> bool {
        *plant == Plant::default() && *inputs == SwitchInputs::default()
    }

    /// Takes the switches given as input signals for the coming samples.
    pub fn set_switch_inputs(&mut self, s: SwitchInputs) {
        self.inputs = s;
        self.no_sensors = Self::without_sensors(&self.plant, &s);
    }

    /// Whether the reference cam is active now: its input signal, or the plant's cam at the
    /// drive's position.
    pub fn reference_cam_now(&self) -> bool {
        self.inputs
            .reference_cam
            .unwrap_or_else(|| self.plant.on_reference_cam(self.drive.actual().p))
    }

    /// The sensors of the plant (reference cam, zero marks, hardware limits).
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// Actual values now, without taking a sample.
    pub fn actual(&self) -> Actual {
        self.drive.actual()
    }

    /// Samples the drive and the sensors: the inputs of this cycle. The edges are those since
    /// the previous sample.
    pub fn sample(&mut self) -> DriveInputs {
        let actual = self.drive.actual();
        let (prev, p) = (self.last, actual.p);
        self.last = p;
        if self.no_sensors {
            // No switch and no mark: what `of_plant` gives for a plant without sensors.
            self.cam_level = false;
            return DriveInputs {
                actual,
                signals: AxisSignals::default(),
                state: DriveState::Operational,
                in_limitation: false,
                torque_actual: 0.0,
            };
        }
        let inputs = self.inputs;
        let mut signals = AxisSignals::of_plant(&self.plant, prev, p);
        if let Some(level) = inputs.reference_cam {
            // Inferred: an input signal's edge is known to the sample; the position is that
            // of the sample at which the level is first seen low.
            signals.reference_cam_left = (self.cam_level && !level).then_some(p);
            signals.reference_cam = level;
        }
        self.cam_level = signals.reference_cam;
        if let Some(on) = inputs.limit_positive {
            signals.limit_positive = on;
        }
        if let Some(on) = inputs.limit_negative {
            signals.limit_negative = on;
        }
        DriveInputs {
            actual,
            signals,
            state: DriveState::Operational,
            in_limitation: false,
            torque_actual: 0.0,
        }
    }

    /// Applies the setpoint for one cycle and moves the plant to the start of the next.
    pub fn apply(&mut self, out: &DriveOutputs) {
        self.drive.step(
            out.position,
            out.velocity,
            out.enable,
            out.position_controlled,
        );
    }
}

/// How an axis reaches its drive.
#[derive(Clone, Debug)]
pub enum DriveLink {
    /// The axis in simulation: drive model and plant inside the axis.
    Simulation(SimPlant),
    /// A drive behind the process image: the inputs as last set, the outputs as last written.
    Connected {
        /// Set by the node before the axis steps.
        inputs: DriveInputs,
        /// Written by the axis; read by the node after the axis stepped.
        outputs: DriveOutputs,
    },
}
