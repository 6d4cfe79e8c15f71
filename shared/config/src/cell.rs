//! The validated cell: nodes, axes, external encoders, cams, output cams, cam tracks and
//! measuring inputs, referred to by typed indices.

use core::ops::Index;
use tandem_motion::objects::axis::AxisConfig;
use tandem_motion::objects::leading::LeaderId;

/// Samples a leader's buffer holds at each follower: the delay plus the tolerance, in leader
/// cycles, must fit with a margin of four samples.
pub const LEADING_BUFFER: usize = 256;

/// An axis of the cell: its index in [`Cell::axes`] (name order).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct AxisIndex(pub usize);

/// An external encoder of the cell: its index in [`Cell::encoders`] (name order).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EncoderIndex(pub usize);

/// An object that can lead: an axis or an external encoder. Ordered axes first, then
/// encoders, as the leader ids of commands count them ([`Cell::leader_id`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Leader {
    /// An axis.
    Axis(AxisIndex),
    /// An external encoder.
    Encoder(EncoderIndex),
}

impl Leader {
    /// The axis, if the leader is one.
    pub fn axis(self) -> Option<AxisIndex> {
        match self {
            Leader::Axis(a) => Some(a),
            Leader::Encoder(_) => None,
        }
    }

    /// The encoder, if the leader is one.
    pub fn encoder(self) -> Option<EncoderIndex> {
        match self {
            Leader::Axis(_) => None,
            Leader::Encoder(e) => Some(e),
        }
    }

    /// Whether the leader is an external encoder (which leads by its value only, never by
    /// setpoint or actual value).
    pub fn is_encoder(self) -> bool {
        matches!(self, Leader::Encoder(_))
    }
}

impl Index<AxisIndex> for Vec<AxisEntry> {
    type Output = AxisEntry;
    fn index(&self, i: AxisIndex) -> &AxisEntry {
        &self[i.0]
    }
}

impl Index<AxisIndex> for [AxisEntry] {
    type Output = AxisEntry;
    fn index(&self, i: AxisIndex) -> &AxisEntry {
        &self[i.0]
    }
}

impl Index<EncoderIndex> for Vec<EncoderEntry> {
    type Output = EncoderEntry;
    fn index(&self, i: EncoderIndex) -> &EncoderEntry {
        &self[i.0]
    }
}

impl Index<EncoderIndex> for [EncoderEntry] {
    type Output = EncoderEntry;
    fn index(&self, i: EncoderIndex) -> &EncoderEntry {
        &self[i.0]
    }
}

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

/// Index of a device in [`Cell::devices`].
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DeviceIndex(pub usize);

/// A device of a node's process image.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceEntry {
    /// Name (unique among devices).
    pub name: String,
    /// Index into [`Cell::nodes`]: the node whose process image holds it.
    pub node: usize,
    /// What it is.
    pub kind: DeviceKind,
}

/// The kinds of device.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceKind {
    /// A simulated CiA 402 servo drive (`kind = "sim_servo"`).
    SimServo(tandem_motion::plant::servo::ServoParams),
    /// A simulated digital output terminal (`kind = "sim_digital_output"`).
    SimDigitalOutput(DigitalOutputParams),
    /// A simulated analog drive with its load encoder (`kind = "sim_analog_drive"`).
    SimAnalogDrive(tandem_motion::plant::analog::SimAnalogParams),
    /// A simulated proportional valve on an analog output with the cylinder it drives
    /// (`kind = "sim_valve_cylinder"`): the device of a hydraulic axis.
    SimValveCylinder(tandem_motion::plant::hydraulic::SimValveCylinderParams),
    /// A simulated digital input terminal (`kind = "sim_digital_input"`).
    SimDigitalInput(DigitalInputParams),
    /// A simulated analog input terminal (`kind = "sim_analog_input"`): `float` channels.
    SimAnalogInput(AnalogChannelParams),
    /// A simulated analog output terminal (`kind = "sim_analog_output"`): `float` channels.
    SimAnalogOutput(AnalogChannelParams),
    /// A simulated counter terminal (`kind = "sim_counter"`): `integer` channels, each a
    /// counter value register.
    SimCounter(CounterParams),
    /// A CiA 402 drive on the node's EtherCAT segment (`[[ethercat.subdevices]] role =
    /// "cia402"`): its process data are exchanged by the node.
    EthercatCia402(EthercatDriveParams),
    /// A digital input/output terminal on the node's EtherCAT segment (`role = "dio"`): its
    /// 8 outputs.
    EthercatDio,
    /// The 8 inputs of such a terminal (`inputs = "<name>"` of its SubDevice), a device of
    /// their own.
    EthercatDioInputs,
    /// An analog input/output terminal on the node's EtherCAT segment (`role = "aio"`): its 2
    /// ±10 V outputs ([`ETHERCAT_AIO_CHANNELS`]), `float` channels.
    EthercatAio,
    /// The 2 ±10 V inputs of such a terminal (`inputs = "<name>"` of its SubDevice), `float`
    /// channels of a device of their own.
    EthercatAioInputs,
    /// An incremental encoder terminal on the node's EtherCAT segment (`role = "enc"`): its
    /// 32-bit counter value as channel 1, an `integer` input read as a `sim_counter`'s.
    EthercatEnc,
}

/// The counter of an EtherCAT encoder terminal (`role = "enc"`): 1 channel, 32 bits.
pub const ETHERCAT_ENC_COUNTER: CounterParams = CounterParams {
    channels: 1,
    bits: 32,
};

/// The channels of an EtherCAT analog terminal (`role = "aio"`, both directions): 2 channels,
/// ±10 V, 16-bit signed words, 0x7FFF = +10 V (the EL31xx/EL41xx presentation).
pub const ETHERCAT_AIO_CHANNELS: AnalogChannelParams = AnalogChannelParams {
    channels: 2,
    range: 10.0,
    bits: 16,
};

/// What the configuration knows of a CiA 402 drive on an EtherCAT segment.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct EthercatDriveParams {
    /// Position actual value 0x6064 increments per motor revolution.
    pub increments_per_revolution: u32,
    /// Cycles from a setpoint to the actual value that shows it, through the node's exchange
    /// (2 to 8): the following error is formed against the setpoint this many cycles old.
    pub transport_cycles: u8,
}

/// The identity of a SubDevice (CiA 301 identity object 0x1018, as in its SII).
#[doc(alias = "0x1018")]
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct EthercatIdentity {
    /// Vendor ID 0x1018:01.
    pub vendor: u32,
    /// Product code 0x1018:02.
    pub product: u32,
    /// Revision number 0x1018:03.
    pub revision: u32,
}

impl core::fmt::Display for EthercatIdentity {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "vendor 0x{:08X}, product 0x{:08X}, revision 0x{:08X}",
            self.vendor, self.product, self.revision
        )
    }
}

/// The role of a SubDevice on a node's segment.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum EthercatRole {
    /// A CiA 402 drive, the drive of an axis (`[axes.<name>.drive] type = "cia402"`).
    Cia402,
    /// A digital input/output terminal (8 inputs, 8 outputs, one bit each).
    Dio,
    /// An analog input/output terminal (2 inputs, 2 outputs, ±10 V, 16-bit words).
    Aio,
    /// An incremental encoder terminal (a 32-bit counter value).
    Enc,
}

/// One expected SubDevice of a segment.
#[derive(Clone, Debug, PartialEq)]
pub struct EthercatSubDevice {
    /// Its name, that of its device in [`Cell::devices`].
    pub name: String,
    /// Its device.
    pub device: DeviceIndex,
    /// A `dio`'s inputs device, if its inputs are bound (`inputs = "<name>"`).
    pub inputs: Option<DeviceIndex>,
    /// The identity it must report.
    pub identity: EthercatIdentity,
    /// What it is.
    pub role: EthercatRole,
}

/// `[[ethercat]]`: the segment one node drives.
#[derive(Clone, Debug, PartialEq)]
pub struct EthercatSegment {
    /// Index into [`Cell::nodes`].
    pub node: usize,
    /// The network interface.
    pub interface: String,
    /// The expected SubDevices in bus order.
    pub subdevices: Vec<EthercatSubDevice>,
}

impl DeviceKind {
    /// The kind's name in the cell file.
    pub fn name(&self) -> &'static str {
        match self {
            DeviceKind::SimServo(_) => "sim_servo",
            DeviceKind::SimDigitalOutput(_) => "sim_digital_output",
            DeviceKind::SimAnalogDrive(_) => "sim_analog_drive",
            DeviceKind::SimValveCylinder(_) => "sim_valve_cylinder",
            DeviceKind::SimDigitalInput(_) => "sim_digital_input",
            DeviceKind::SimAnalogInput(_) => "sim_analog_input",
            DeviceKind::SimAnalogOutput(_) => "sim_analog_output",
            DeviceKind::SimCounter(_) => "sim_counter",
            DeviceKind::EthercatCia402(_) => "ethercat_cia402",
            DeviceKind::EthercatDio => "ethercat_dio",
            DeviceKind::EthercatDioInputs => "ethercat_dio_inputs",
            DeviceKind::EthercatAio => "ethercat_aio",
            DeviceKind::EthercatAioInputs => "ethercat_aio_inputs",
            DeviceKind::EthercatEnc => "ethercat_enc",
        }
    }

    /// The channels of a device with channels (digital inputs and outputs): their number,
    /// whether they are timestamped, and whether they are inputs.
    pub fn channels(&self) -> Option<(u8, bool, SignalDirection)> {
        match self {
            DeviceKind::SimServo(_)
            | DeviceKind::SimAnalogDrive(_)
            | DeviceKind::SimValveCylinder(_)
            | DeviceKind::EthercatCia402(_) => None,
            DeviceKind::EthercatDio => Some((8, false, SignalDirection::Output)),
            DeviceKind::EthercatDioInputs => Some((8, false, SignalDirection::Input)),
            DeviceKind::EthercatAio => Some((2, false, SignalDirection::Output)),
            DeviceKind::EthercatAioInputs => Some((2, false, SignalDirection::Input)),
            DeviceKind::EthercatEnc => Some((1, false, SignalDirection::Input)),
            DeviceKind::SimDigitalOutput(p) => {
                Some((p.channels, p.timestamped, SignalDirection::Output))
            }
            DeviceKind::SimDigitalInput(p) => {
                Some((p.channels, p.timestamped, SignalDirection::Input))
            }
            DeviceKind::SimAnalogInput(p) => Some((p.channels, false, SignalDirection::Input)),
            DeviceKind::SimAnalogOutput(p) => Some((p.channels, false, SignalDirection::Output)),
            DeviceKind::SimCounter(p) => Some((p.channels, false, SignalDirection::Input)),
        }
    }

    /// The type of the signals on the device's channels, for a device with channels.
    pub fn channel_type(&self) -> Option<SignalType> {
        match self {
            DeviceKind::SimServo(_)
            | DeviceKind::SimAnalogDrive(_)
            | DeviceKind::SimValveCylinder(_)
            | DeviceKind::EthercatCia402(_) => None,
            DeviceKind::EthercatDio | DeviceKind::EthercatDioInputs => Some(SignalType::Bool),
            DeviceKind::SimDigitalOutput(DigitalOutputParams { timestamped, .. })
            | DeviceKind::SimDigitalInput(DigitalInputParams { timestamped, .. }) => {
                Some(if *timestamped {
                    SignalType::TimestampedBool
                } else {
                    SignalType::Bool
                })
            }
            DeviceKind::SimAnalogInput(_)
            | DeviceKind::SimAnalogOutput(_)
            | DeviceKind::EthercatAio
            | DeviceKind::EthercatAioInputs => Some(SignalType::Float),
            DeviceKind::SimCounter(_) | DeviceKind::EthercatEnc => Some(SignalType::Integer),
        }
    }
}

/// A simulated analog terminal (`sim_analog_input`, `sim_analog_output`): `channels` values in
/// engineering units (V) over `±range`, quantized to `bits` of resolution including the sign,
/// the way an analog terminal presents them (inferred from the signed presentation of the
/// Beckhoff EL31xx/EL41xx terminals: full scale is `2^(bits-1) - 1`, 0x7FFF for 16 bits; an S7
/// analog module's nominal range ends at 27648 instead, with an overrange above it).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AnalogChannelParams {
    /// Number of channels, 1 to [`MAX_CHANNELS`].
    pub channels: u8,
    /// Full scale (V): the channels measure or drive `-range ..= range`.
    pub range: f64,
    /// Resolution including the sign, 2 to 24 bits.
    pub bits: u8,
}

impl AnalogChannelParams {
    /// The largest code, `2^(bits-1) - 1` (32767 for 16 bits): it stands for `range`.
    pub fn full_scale_code(&self) -> i32 {
        (1i32 << (u32::from(self.bits).clamp(2, 24) - 1)) - 1
    }

    /// `value` (V) as the terminal presents it: the code `round(value · full / range)`,
    /// clamped to `±full` (`full` = [`Self::full_scale_code`]), and that code back in V,
    /// `code · range / full`. Returns the code and the value.
    pub fn quantize(&self, value: f64) -> (i32, f64) {
        let full = self.full_scale_code();
        let code = (value * f64::from(full) / self.range)
            .round()
            .clamp(-f64::from(full), f64::from(full));
        // Exact: |code| <= full < 2^23 is an integer (`as` would map a NaN to 0).
        let code = code as i32;
        (code, f64::from(code) * self.range / f64::from(full))
    }
}

/// A simulated counter terminal (`sim_counter`): `channels` counter value registers of `bits`
/// bits, read as a signed integer (an S7 TM Count's DINT `COUNT_VALUE`, a TwinCAT counter
/// terminal's value as DINT): a value wraps modulo `2^bits` (inferred: the register overflows
/// as the hardware's does; S7 and TwinCAT both count through the wrap).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct CounterParams {
    /// Number of channels, 1 to [`MAX_CHANNELS`].
    pub channels: u8,
    /// The register's width: 16 or 32.
    pub bits: u8,
}

impl CounterParams {
    /// `value` as the register holds it: modulo `2^bits`, sign-extended.
    pub fn wrap(&self, value: i64) -> i64 {
        let shift = 64 - u32::from(self.bits).clamp(1, 64);
        value.wrapping_shl(shift).wrapping_shr(shift)
    }
}

/// A simulated digital input terminal: `channels` inputs, sampled at the cycle boundary, each
/// edge with its time to the ns (`timestamped`, like an EL1252 of the EtherCAT terminal range,
/// its latched `LatchPos`/`LatchNeg` times) or seen at the boundary only (like an EL1008).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DigitalInputParams {
    /// Number of channels, 1 to [`MAX_CHANNELS`].
    pub channels: u8,
    /// Each edge is reported with its time (ns); otherwise the level at the boundary.
    pub timestamped: bool,
}

/// Most channels of a digital output device.
pub const MAX_CHANNELS: u8 = 32;

/// A simulated digital output terminal: `channels` outputs, switched at a given time
/// (`timestamped`, like an EL2252 of the EtherCAT terminal range, its `StartTime`) or at the
/// cycle boundary (like an EL2008).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DigitalOutputParams {
    /// Number of channels, 1 to [`MAX_CHANNELS`].
    pub channels: u8,
    /// The channels switch at a given time (one switching event per cycle and terminal).
    pub timestamped: bool,
}

/// Index of a signal in [`Cell::signals`].
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SignalIndex(pub usize);

/// The type of a signal, given by its channel (`[signals.<name>] type` may state it, and must
/// then agree). A digital channel gives `Bool` or `TimestampedBool`, an analog channel `Float`,
/// a counter channel `Integer`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SignalType {
    /// A digital input sampled at, or output switched at, the cycle boundary.
    Bool,
    /// A digital input whose edges carry their time, or an output switched at a given time
    /// (the edge time goes with it).
    TimestampedBool,
    /// A counter value register (`sim_counter`), sampled at the boundary.
    Integer,
    /// An analog value in engineering units (`sim_analog_input`, `sim_analog_output`), sampled
    /// at the boundary and quantized as [`AnalogChannelParams::quantize`] says.
    Float,
}

impl SignalType {
    /// The type as `[signals.<name>] type` names it: `bool`, `integer` or `float`.
    pub fn key(self) -> &'static str {
        match self {
            SignalType::Bool | SignalType::TimestampedBool => "bool",
            SignalType::Integer => "integer",
            SignalType::Float => "float",
        }
    }

    /// Whether the signal carries a level (`bool`, timestamped or not).
    pub fn is_bool(self) -> bool {
        matches!(self, SignalType::Bool | SignalType::TimestampedBool)
    }
}

/// Whether a signal is an input or an output of the process image (its device says).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SignalDirection {
    /// Read by the node (a channel of a `sim_digital_input`).
    Input,
    /// Written by the node (a channel of a `sim_digital_output`).
    Output,
}

impl SignalDirection {
    /// `an input` or `an output`, for messages.
    pub fn name(self) -> &'static str {
        match self {
            SignalDirection::Input => "an input",
            SignalDirection::Output => "an output",
        }
    }
}

/// The input signals bound to an axis's switches (`[axes.<name>.inputs]`), for an axis on the
/// simulated drive (a CiA 402 drive gives them in 0x60FD).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct AxisInputs {
    /// `limit_positive`: the positive hardware limit switch (`PositionLimits_HW.MaxSwitch`).
    pub limit_positive: Option<SignalIndex>,
    /// `limit_negative`: the negative hardware limit switch (`PositionLimits_HW.MinSwitch`).
    pub limit_negative: Option<SignalIndex>,
    /// `reference_cam`: the homing switch (`Homing.DigitalInput`).
    pub reference_cam: Option<SignalIndex>,
}

impl AxisInputs {
    /// Whether any switch is bound.
    pub fn any(&self) -> bool {
        self.limit_positive.is_some()
            || self.limit_negative.is_some()
            || self.reference_cam.is_some()
    }
}

/// What the input signals feed: axes' switches and measuring inputs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputBindings {
    /// Per axis of [`Cell::axes`]: the signals of its switches.
    pub axes: Vec<AxisInputs>,
    /// Per measuring input of [`Cell::measuring_inputs`]: the timestamped input signal that
    /// gives its edges (`input = "<signal>"`, route `timer_di`).
    pub measuring_inputs: Vec<Option<SignalIndex>>,
}

/// A named signal of the cell (`[signals.<name>]`), bound to one channel of one device.
#[derive(Clone, Debug, PartialEq)]
pub struct SignalEntry {
    /// Name (unique among signals).
    pub name: String,
    /// The device.
    pub device: DeviceIndex,
    /// The channel, 1-based.
    pub channel: u8,
    /// Its type, from the channel.
    pub signal_type: SignalType,
    /// Input or output, from the device.
    pub direction: SignalDirection,
    /// An input's simulated sensor (`[signals.<name>.sensor]`): a mark on an axis's load.
    pub sensor: Option<SensorEntry>,
}

/// How an axis reaches its drive (`[axes.<name>.drive] type`).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum DriveConnection {
    /// `simulation`: the drive model inside the axis (`[axes.<name>.drive] model`).
    #[default]
    Simulation,
    /// `cia402`: a CiA 402 drive of the node's process image.
    Cia402(Box<Cia402Connection>),
    /// `analog`: an analog drive of the node's process image, tandem closing the position
    /// loop.
    Analog(Box<AnalogDriveConnection>),
}

/// An axis on an analog drive of the process image.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalogDriveConnection {
    /// The drive.
    pub device: DeviceIndex,
    /// The position controller, the enable timeout, the ready input, the encoder and the
    /// mechanics.
    pub params: tandem_motion::plant::analog::AnalogParams,
    /// A hydraulic axis' position controller and Finish (`[axes.<name>.hydraulic]`): the
    /// valve's output comes from them instead of the speed controller of `params`.
    pub hydraulic: Option<tandem_motion::hydraulic::controller::HydControllerParams>,
    /// A hydraulic axis' pressure inputs (`ScaleFactorA` … in `[axes.<name>.hydraulic]`).
    pub pressure: Option<tandem_motion::hydraulic::pressure::ForceScaling>,
    /// A hydraulic axis' characteristic curve (`characteristic_curve`): Finish linearises with
    /// it (`MC_AxRtFinishLinear_BkPlcMc`).
    pub characteristic_curve: Option<Box<tandem_motion::hydraulic::valve_table::ValveTable>>,
}

/// An axis on a CiA 402 drive of the process image.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Cia402Connection {
    /// The drive.
    pub device: DeviceIndex,
    /// Time allowed for each step of the enable sequence (ns).
    pub enable_timeout_ns: i64,
    /// Encoder and mechanics: the drive's increments to and from the axis's units.
    pub scaling: tandem_motion::plant::mechanics::Scaling,
    /// Torque feedforward 0x60B2 from the setpoint acceleration: the moment of inertia at the
    /// motor (motor plus load reflected to it, kg·m²) it is computed with; `None`: off
    /// (`[axes.<name>.drive] torque_precontrol`, `inertia`).
    #[doc(alias = "0x60B2")]
    pub torque_precontrol_inertia: Option<f64>,
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
    /// The leaders it may follow and how; `None`: any of its node, by setpoint.
    pub leaders: Option<Vec<(Leader, Coupling)>>,
    /// Its leading-value delay and tolerance, as a leader.
    pub leading: LeadingValueConfig,
    /// Its drive connection.
    pub drive: DriveConnection,
}

impl AxisEntry {
    /// How this axis reads leader `leader`, or `None` if it may not follow it.
    pub fn coupling(&self, leader: Leader) -> Option<Coupling> {
        match &self.leaders {
            None => Some(Coupling::Setpoint),
            Some(list) => list.iter().find(|(i, _)| *i == leader).map(|(_, c)| *c),
        }
    }
}

/// Where a simulated external encoder gets its position from.
#[derive(Clone, Debug, PartialEq)]
pub enum EncoderSource {
    /// The actual position of an axis times `scale`.
    Axis {
        /// The measured axis.
        axis: AxisIndex,
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
    /// Its leading-value delay and tolerance, as a leader.
    pub leading: LeadingValueConfig,
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
    /// The axis whose motion it follows.
    pub axis: AxisIndex,
    /// Engine configuration.
    pub config: tandem_motion::objects::output_cam::OutputCamConfig,
    /// The digital output signal it drives, if any.
    pub output: Option<SignalIndex>,
}

/// A cam track of the cell (`[[cam_tracks]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct CamTrackEntry {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose motion it follows.
    pub axis: AxisIndex,
    /// Engine configuration.
    pub config: tandem_motion::objects::cam_track::CamTrackConfig,
    /// Track data (reference, length, cams).
    pub data: tandem_motion::objects::cam_track::CamTrackData,
    /// The digital output signal its track output drives, if any.
    pub output: Option<SignalIndex>,
}

/// An MC_DigitalCamSwitch_BkPlcMc of the cell (`[[digital_cam_switches]]`): its switch and
/// track sets, checked by the engine.
#[derive(Clone, Debug, PartialEq)]
pub struct DigitalCamSwitchEntry {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose actual position and velocity switch it.
    pub axis: AxisIndex,
    /// `Switches`.
    pub switches: Vec<tandem_motion::objects::digital_cam_switch::CamSwitch>,
    /// `TrackOptions` (track `n` is element `n - 1`).
    pub tracks: Vec<tandem_motion::objects::digital_cam_switch::TrackOptions>,
    /// Per track: the digital output signal its bit drives, if any.
    pub outputs: Vec<Option<SignalIndex>>,
}

/// A simulated mark sensor on a measuring input.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SensorEntry {
    /// The axis that carries the mark.
    pub axis: AxisIndex,
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
    /// The axis whose motion it follows.
    pub axis: AxisIndex,
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
    /// The corrected axis.
    pub axis: AxisIndex,
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
    /// Commands per second each sender may send, sustained (`[cell] command_rate_hz`).
    pub command_rate_hz: f64,
    /// Commands a sender may send at once above that rate (`[cell] command_burst`).
    pub command_burst: u32,
    /// `tandem up` reports a process stalled after this silence (ns, `[cell] watchdog_ms`).
    pub watchdog_ns: i64,
    /// ... and restarts it after this one (ns, `[cell] watchdog_restart_ms`).
    pub watchdog_restart_ns: i64,
    /// The directory of the retained data: `[cell] retain_dir` (default `retain`), relative to
    /// the cell file's directory (to the current directory for a cell parsed from text).
    /// A node's records are in [`Cell::node_retain_dir`].
    pub retain_dir: std::path::PathBuf,
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Axes, in name order.
    pub axes: Vec<AxisEntry>,
    /// External encoders, in name order.
    pub encoders: Vec<EncoderEntry>,
    /// Cams, in name order (a cam's id is its index here).
    pub cams: Vec<CamEntry>,
    /// Output cams, in file order.
    pub output_cams: Vec<OutputCamEntry>,
    /// Cam tracks, in file order.
    pub cam_tracks: Vec<CamTrackEntry>,
    /// Measuring inputs, in file order.
    pub measuring_inputs: Vec<MeasuringInputEntry>,
    /// MC_DigitalCamSwitch_BkPlcMc objects, in file order.
    pub digital_cam_switches: Vec<DigitalCamSwitchEntry>,
    /// The devices of the nodes' process images, in name order.
    pub devices: Vec<DeviceEntry>,
    /// The named signals, in name order.
    pub signals: Vec<SignalEntry>,
    /// What the input signals feed.
    pub inputs: InputBindings,
    /// `[security]`: how the cell's Zenoh links are authenticated, who may do what.
    pub security: crate::security::Security,
    /// `[[ethercat]]`: the EtherCAT segments, at most one per node.
    pub ethercat: Vec<EthercatSegment>,
}

impl Cell {
    /// The directory of node `node`'s retained data (the absolute encoder adjustments of its
    /// axes): `<retain_dir>/<cell name>/<node name>/`, if the cell has the node.
    pub fn node_retain_dir(&self, node: usize) -> Option<std::path::PathBuf> {
        let n = self.nodes.get(node)?;
        Some(self.retain_dir.join(&self.name).join(&n.name))
    }

    /// The axis `i`, if the cell has it.
    pub fn axis(&self, i: AxisIndex) -> Option<&AxisEntry> {
        self.axes.get(i.0)
    }

    /// The encoder `k`, if the cell has it.
    pub fn encoder(&self, k: EncoderIndex) -> Option<&EncoderEntry> {
        self.encoders.get(k.0)
    }

    /// Every axis of the cell, in order.
    pub fn axis_indices(&self) -> impl Iterator<Item = AxisIndex> {
        (0..self.axes.len()).map(AxisIndex)
    }

    /// Every leader of the cell: the axes, then the encoders.
    pub fn leaders(&self) -> impl Iterator<Item = Leader> {
        (0..self.axes.len())
            .map(|i| Leader::Axis(AxisIndex(i)))
            .chain((0..self.encoders.len()).map(|k| Leader::Encoder(EncoderIndex(k))))
    }

    /// The id of `leader` in commands and on the wire: axes count first, then encoders (its
    /// index in [`Cell::object_names`]).
    pub fn leader_id(&self, leader: Leader) -> LeaderId {
        let flat = match leader {
            Leader::Axis(a) => a.0,
            Leader::Encoder(e) => self.axes.len() + e.0,
        };
        LeaderId::try_from(flat).unwrap_or(LeaderId::MAX)
    }

    /// The leader with id `id` (see [`Cell::leader_id`]), if the cell has it.
    pub fn leader(&self, id: LeaderId) -> Option<Leader> {
        let i = usize::try_from(id).ok()?;
        if i < self.axes.len() {
            Some(Leader::Axis(AxisIndex(i)))
        } else {
            let k = i - self.axes.len();
            (k < self.encoders.len()).then_some(Leader::Encoder(EncoderIndex(k)))
        }
    }

    /// The leader named `name` (an axis or an encoder).
    pub fn leader_named(&self, name: &str) -> Option<Leader> {
        match self.axes.iter().position(|a| a.name == name) {
            Some(i) => Some(Leader::Axis(AxisIndex(i))),
            None => self
                .encoders
                .iter()
                .position(|e| e.name == name)
                .map(|k| Leader::Encoder(EncoderIndex(k))),
        }
    }

    /// The name of `leader` (`?` if the cell does not have it).
    pub fn leader_name(&self, leader: Leader) -> &str {
        match leader {
            Leader::Axis(a) => self.axis(a).map(|x| x.name.as_str()),
            Leader::Encoder(e) => self.encoder(e).map(|x| x.name.as_str()),
        }
        .unwrap_or("?")
    }

    /// The leading-value delay and tolerance of `leader` (none if the cell does not have it).
    pub fn leading(&self, leader: Leader) -> LeadingValueConfig {
        match leader {
            Leader::Axis(a) => self.axis(a).map(|x| x.leading),
            Leader::Encoder(e) => self.encoder(e).map(|x| x.leading),
        }
        .unwrap_or(LeadingValueConfig {
            delay_ns: 0,
            tolerance_ns: 0,
        })
    }

    /// How axis `follower` reads `leader`, or `None` if it may not follow it. Without a
    /// `leaders` table an axis may follow any leader of its own node, by setpoint.
    pub fn coupling(&self, follower: AxisIndex, leader: Leader) -> Option<Coupling> {
        let f = self.axis(follower)?;
        match &f.leaders {
            Some(_) => f.coupling(leader),
            None => (self.leader_node(leader)? == f.node).then_some(Coupling::Setpoint),
        }
    }

    /// The node that hosts `leader`.
    pub fn leader_node(&self, leader: Leader) -> Option<usize> {
        match leader {
            Leader::Axis(a) => self.axis(a).map(|x| x.node),
            Leader::Encoder(e) => self.encoder(e).map(|x| x.node),
        }
    }

    /// The leaders of other nodes that followers on `node` may follow (sorted, unique).
    pub fn remote_leaders(&self, node: usize) -> Vec<Leader> {
        let mut out: Vec<Leader> = self
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
    pub fn published_leaders(&self, node: usize) -> Vec<Leader> {
        let mut out: Vec<Leader> = (0..self.nodes.len())
            .filter(|n| *n != node)
            .flat_map(|n| self.remote_leaders(n))
            .filter(|l| self.leader_node(*l) == Some(node))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The samples of `leader` its iceoryx2 service keeps for late joiners and each
    /// subscriber buffers: the delay plus the tolerance in leader cycles, plus four.
    pub fn leading_history(&self, leader: Leader) -> usize {
        let Some(node) = self.leader_node(leader) else {
            return 4;
        };
        let lv = self.leading(leader);
        let cycle = self.nodes.get(node).map_or(1_000_000, |n| n.cycle_ns);
        (((lv.delay_ns + lv.tolerance_ns) / cycle.max(1)) as usize + 4).min(LEADING_BUFFER)
    }

    /// The cycle (ns) of the node that hosts `leader` (0 if the cell does not have it).
    pub fn leader_cycle_ns(&self, leader: Leader) -> i64 {
        self.leader_node(leader)
            .and_then(|n| self.nodes.get(n))
            .map_or(0, |n| n.cycle_ns)
    }

    /// The index of the node named `name`.
    pub fn node(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }

    /// The names of all technology objects that can be addressed or lead: axes, then encoders
    /// (a leader's id is its index here, see [`Cell::leader_id`]).
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

    /// The signal named `name`.
    pub fn signal(&self, name: &str) -> Option<SignalIndex> {
        self.signals
            .iter()
            .position(|s| s.name == name)
            .map(SignalIndex)
    }

    /// The index of the measuring input named `name`.
    pub fn measuring_input(&self, name: &str) -> Option<usize> {
        self.measuring_inputs.iter().position(|c| c.name == name)
    }

    /// The index of the digital cam switch named `name`.
    pub fn digital_cam_switch(&self, name: &str) -> Option<usize> {
        self.digital_cam_switches
            .iter()
            .position(|c| c.name == name)
    }

    /// The axis of the output cam, cam track, measuring input or digital cam switch named
    /// `name`.
    pub fn object_axis(&self, name: &str) -> Option<AxisIndex> {
        self.output_cam(name)
            .map(|i| self.output_cams[i].axis)
            .or_else(|| self.cam_track(name).map(|i| self.cam_tracks[i].axis))
            .or_else(|| {
                self.measuring_input(name)
                    .map(|i| self.measuring_inputs[i].axis)
            })
            .or_else(|| {
                self.digital_cam_switch(name)
                    .map(|i| self.digital_cam_switches[i].axis)
            })
    }
}
