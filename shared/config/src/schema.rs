//! The serde schema of the cell file, as written by people. Every key is documented in
//! `config/example-cell.toml`; defaults follow the references' typical values.

use serde::Deserialize;
use std::collections::BTreeMap;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellFile {
    /// `[cell]`.
    pub cell: CellSection,
    /// `[[hosts]]`: the controllers of the cell; without it, one host named `local`.
    #[serde(default)]
    pub hosts: Vec<HostSection>,
    /// `[[nodes]]`.
    #[serde(default)]
    pub nodes: Vec<NodeSection>,
    /// `[axes.<name>]`.
    #[serde(default)]
    pub axes: BTreeMap<String, AxisSection>,
    /// `[encoders.<name>]`.
    #[serde(default)]
    pub encoders: BTreeMap<String, EncoderSection>,
    /// `[cams.<name>]`.
    #[serde(default)]
    pub cams: BTreeMap<String, CamSection>,
    /// `[[output_cams]]`.
    #[serde(default)]
    pub output_cams: Vec<OutputCamSection>,
    /// `[[cam_tracks]]`.
    #[serde(default)]
    pub cam_tracks: Vec<CamTrackSection>,
    /// `[[measuring_inputs]]`.
    #[serde(default)]
    pub measuring_inputs: Vec<MeasuringInputSection>,
    /// `[[digital_cam_switches]]`: MC_DigitalCamSwitch_BkPlcMc objects.
    #[serde(default)]
    pub digital_cam_switches: Vec<DigitalCamSwitchSection>,
    /// `[devices.<name>]`: the devices of the nodes' process images.
    #[serde(default)]
    pub devices: BTreeMap<String, DeviceSection>,
    /// `[signals.<name>]`: named signals, each bound to a channel of a device.
    #[serde(default)]
    pub signals: BTreeMap<String, SignalSection>,
    /// `[security]`: how the Zenoh links are authenticated (docs/security.md).
    pub security: Option<SecuritySection>,
    /// `[[ethercat]]`: the EtherCAT segment a node drives (docs/ethercat.md).
    #[serde(default)]
    pub ethercat: Vec<EthercatSection>,
}

/// `[security]`: mTLS with the cell's certificates (default), or plain Zenoh written out.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SecuritySection {
    /// `mtls` (default) or `plain`.
    pub mode: Option<String>,
    /// The cell CA's certificate (PEM), relative to the cell file; default `pki/ca.pem`.
    pub ca: Option<String>,
    /// Each host's certificate, `{host}` standing for its name; default `pki/host-{host}.pem`.
    pub certificate: Option<String>,
    /// Each host's private key; default `pki/host-{host}.key`.
    pub private_key: Option<String>,
    /// The operators' names: certificates with CN `operator:<name>` may command.
    #[serde(default)]
    pub operators: Vec<String>,
    /// The observers' names: certificates with CN `observer:<name>` may observe.
    #[serde(default)]
    pub observers: Vec<String>,
    /// Zenoh's multicast scouting; default false.
    #[serde(default)]
    pub multicast_scouting: bool,
}

/// `[devices.<name>]`: a device in a node's process image. Its kind says which keys it has;
/// every parameter has a default.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceSection {
    /// The node whose process image holds it.
    pub node: String,
    /// `sim_servo`: a simulated CiA 402 servo drive; `sim_analog_drive`: a simulated drive with
    /// a ±10 V speed setpoint, enable input, ready output and a load encoder;
    /// `sim_digital_output`: a simulated digital output terminal; `sim_digital_input`: a
    /// simulated digital input terminal.
    pub kind: String,
    /// sim_servo: increments per motor revolution of its position actual value (0x6064).
    pub increments_per_revolution: Option<u32>,
    /// sim_servo: rated torque (N·m), the 1000 ‰ of the torque objects.
    pub rated_torque: Option<f64>,
    /// sim_servo: torque limit (‰ of the rated torque, 0x6072).
    pub max_torque: Option<u16>,
    /// sim_servo: motor inertia plus the load's, seen at the motor (kg·m²).
    pub inertia: Option<f64>,
    /// sim_servo: viscous friction (N·m·s/rad).
    pub viscous_friction: Option<f64>,
    /// sim_servo: Coulomb friction (N·m).
    pub coulomb_friction: Option<f64>,
    /// sim_servo: gain of the drive's position loop in CSP (1/s).
    pub kv: Option<f64>,
    /// sim_servo: proportional gain of the drive's velocity loop (N·m·s/rad).
    pub velocity_gain: Option<f64>,
    /// sim_servo: integral time of the drive's velocity loop (s).
    pub velocity_integral_time: Option<f64>,
    /// sim_servo: quick-stop deceleration (rad/s², 0x6085).
    pub quick_stop_deceleration: Option<f64>,
    /// sim_servo: quick stop option code (0x605A, 0..8).
    pub quick_stop_option: Option<i16>,
    /// sim_servo: following error window (increments, 0x6065) beyond which the drive faults
    /// with 0x8611.
    pub following_error_window: Option<u32>,
    /// sim_servo: increment offset of the encoder zero pulse within a revolution.
    pub zero_pulse_offset: Option<u32>,
    /// sim_analog_drive: motor speed at 10 V, 100 % of the command (1/min, default 3000).
    pub reference_speed: Option<f64>,
    /// sim_analog_drive: the drive's speed limit (1/min, default 3300).
    pub max_speed: Option<f64>,
    /// sim_analog_drive: its speed loop as a first-order lag (s, default 0.004).
    pub time_constant: Option<f64>,
    /// sim_analog_drive: time of its stop ramp from the reference speed to 0, without enable
    /// or in a fault (s, default 0.1).
    pub ramp_down_time: Option<f64>,
    /// sim_analog_drive: time from its enable input to its ready output (s, default 0.01).
    pub ready_delay: Option<f64>,
    /// sim_analog_drive: offset of its analog input (V, -10 to 10, default 0).
    pub offset: Option<f64>,
    /// sim_digital_output, sim_digital_input, sim_analog_input, sim_analog_output,
    /// sim_counter: the number of channels, 1 to 32 (required).
    pub channels: Option<u32>,
    /// sim_digital_output: `true` switches each channel at a given time (a timestamped output
    /// like an EL2252, one switching event per cycle); `false` (default) at the cycle boundary.
    /// sim_digital_input: `true` reports each edge with its time (like an EL1252); `false`
    /// (default) the level at the cycle boundary.
    pub timestamped: Option<bool>,
    /// sim_analog_input, sim_analog_output: full scale (V, default 10): the channels span
    /// `-range ..= range`.
    pub range: Option<f64>,
    /// sim_analog_input, sim_analog_output: resolution including the sign (2 to 24, default
    /// 16); sim_counter: the register's width (16 or 32, default 32).
    pub bits: Option<u32>,
    /// sim_valve_cylinder: a constant external load on the piston (N, against positive
    /// motion; default 0).
    pub load: Option<f64>,
    /// sim_valve_cylinder: `[devices.<name>.cylinder]`, the valve and the cylinder.
    pub cylinder: Option<CylinderSection>,
    /// sim_valve_cylinder: the pressure sensors' range (bar at 10 V, input word 27648;
    /// default 250).
    pub pressure_range: Option<f64>,
    /// sim_valve_cylinder: how the valve's amplifier takes its command: `voltage` (±10 V,
    /// default), `two_coil`, `one_coil`, or `current` (the magnitude with direction valves).
    pub valve_input: Option<String>,
}

/// `[devices.<name>.cylinder]` of a `sim_valve_cylinder`: a proportional valve and a
/// differential cylinder. Every key has a default: a 63/45 mm cylinder of 500 mm stroke with
/// 200 kg on a 40 l/min valve at 100 bar.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSection {
    /// Piston area, chamber A (mm²).
    pub area_a: Option<f64>,
    /// Annulus area, chamber B (mm²).
    pub area_b: Option<f64>,
    /// Stroke (mm): the piston moves between 0 and the stroke.
    pub stroke: Option<f64>,
    /// Dead volume of each chamber with its line (mm³).
    pub dead_volume: Option<f64>,
    /// Moving mass (kg).
    pub mass: Option<f64>,
    /// Bulk modulus of the oil (bar).
    pub bulk_modulus: Option<f64>,
    /// Viscous friction (N per mm/s).
    pub viscous: Option<f64>,
    /// Coulomb friction (N).
    pub coulomb: Option<f64>,
    /// Supply pressure (bar).
    pub supply: Option<f64>,
    /// Tank pressure (bar).
    pub tank: Option<f64>,
    /// Nominal flow of one control edge of chamber A at full opening (l/min).
    pub nominal_flow: Option<f64>,
    /// Nominal flow of chamber B's edges relative to A's (1: a symmetric valve).
    pub flow_ratio_b: Option<f64>,
    /// Pressure drop per edge of the nominal flow (bar).
    pub nominal_drop: Option<f64>,
    /// Overlap: spool travel (0..1) before an edge opens.
    pub overlap: Option<f64>,
    /// Zero offset of the spool (normalised, within ±0.2).
    pub offset: Option<f64>,
    /// Opening (0..1) of the flow curve's bend.
    pub bend_opening: Option<f64>,
    /// Flow (0..1 of nominal) at the bend.
    pub bend_flow: Option<f64>,
    /// Response time of the spool (s).
    pub response_time: Option<f64>,
}

/// `[axes.<name>.hydraulic]` of a `kind = "hydraulic"` axis: the members of the Beckhoff
/// TwinCAT PLC Hydraulic Positioning library's `ST_TcHydAxParam`, under the library's names.
/// Every key has the library's default.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub struct HydraulicSection {
    /// Reference velocity (mm/s): the velocity at 100 % (10 V) output.
    pub fRefVelo: Option<f64>,
    /// Highest velocity of a command (mm/s).
    pub fMaxVelo: Option<f64>,
    /// Acceleration of the start ramp (mm/s²).
    pub fAcc: Option<f64>,
    /// Highest acceleration (mm/s²).
    pub fMaxAcc: Option<f64>,
    /// Deceleration of the braking ramp (mm/s²).
    pub fDec: Option<f64>,
    /// Highest deceleration (mm/s²).
    pub fMaxDec: Option<f64>,
    /// Creep velocity, positive direction (mm/s).
    pub fCreepSpeedP: Option<f64>,
    /// Creep velocity, negative direction (with `bAsymmetricalTargeting`).
    pub fCreepSpeedM: Option<f64>,
    /// Creep distance, positive direction (mm).
    pub fCreepDistanceP: Option<f64>,
    /// Creep distance, negative direction.
    pub fCreepDistanceM: Option<f64>,
    /// Braking distance, positive direction (mm).
    pub fBrakeDistanceP: Option<f64>,
    /// Braking distance, negative direction.
    pub fBrakeDistanceM: Option<f64>,
    /// Brake dead time, positive direction (s).
    pub fBrakeDeadTimeP: Option<f64>,
    /// Brake dead time, negative direction.
    pub fBrakeDeadTimeM: Option<f64>,
    /// The `…M` approach parameters serve the negative direction.
    pub bAsymmetricalTargeting: Option<bool>,
    /// Stop ramp (s from `fRefVelo` to 0).
    pub fStopRamp: Option<f64>,
    /// Emergency ramp (s from `fRefVelo` to 0).
    pub fEmergencyRamp: Option<f64>,
    /// Automatic repositioning beyond this distance from the target (mm; 0: off).
    pub fReposDistance: Option<f64>,
    /// Velocity of slow manual travel, MC_MoveJog_BkPlcMc's MC_JOGMODE_STANDARD_SLOW (mm/s).
    pub fJogVeloSlow: Option<f64>,
    /// Velocity of fast manual travel, MC_JOGMODE_STANDARD_FAST (mm/s).
    pub fJogVeloFast: Option<f64>,
    /// Target clamping: the output (V, 0..10) pressing towards the target once there, in place
    /// of the position controller (0: off).
    pub fTargetClamping: Option<f64>,
    /// Position range of the target window monitoring (mm).
    pub fMonPositionRange: Option<f64>,
    /// Target range (mm).
    pub fMonTargetRange: Option<f64>,
    /// Filter time of the target range (s).
    pub fMonTargetFilter: Option<f64>,
    /// P gain of the position controller (mm/s per mm).
    pub fLagAmp: Option<f64>,
    /// Output limit of the position controller (normalised; 0: none).
    pub fLagAmpOutL: Option<f64>,
    /// Gain of the position controller's I part, used as Ki (mm/s per mm and s; 0: no I part).
    pub fLagAmpTi: Option<f64>,
    /// Response window of the I part (mm): it grows only beyond this lag.
    pub fLagAmpDx: Option<f64>,
    /// Limit of the I part (normalised; 0: full scale).
    pub fLagAmpWuL: Option<f64>,
    /// tandem's: the position controller, `default` (`MC_AxRtController_BkPlcMc`) or
    /// `extended` (`MC_AxRtPosPiControllerEx_BkPlcMc`: the D part and condition feedback).
    pub position_controller: Option<String>,
    /// Extended controller: the D part's gain on the velocity error (1; 0: no D part).
    pub fLagAmpTd: Option<f64>,
    /// Extended controller: the D part's damping time (s).
    pub fLagAmpTdd: Option<f64>,
    /// Extended controller: the weight of the actual velocity feedback (1; 0: none).
    pub fLagAmpCfb_kV: Option<f64>,
    /// Extended controller: the filter time of the actual velocity feedback (s).
    pub fLagAmpCfb_tV: Option<f64>,
    /// Extended controller: the weight of the actual acceleration feedback (s; 0: none).
    pub fLagAmpCfb_kA: Option<f64>,
    /// Extended controller: the filter time of the actual acceleration feedback (s).
    pub fLagAmpCfb_tA: Option<f64>,
    /// MC_Home_BkPlcMc's method in its default mode (`E_TcMcHomingType`):
    /// `iTcMc_HomingOnBlock` (default), `iTcMc_HomingOnIndex`, `iTcMc_HomingOnSync`,
    /// `iTcMc_HomingOnMultiSync`, `iTcMc_HomingOnExec`.
    pub nEnc_HomingType: Option<String>,
    /// Homing: the control value of the search for the cam, a fraction of `fRefVelo` (0..1,
    /// default 0.1).
    pub fEnc_RefIndexVelo: Option<f64>,
    /// Homing: that of the search for the cam's end and the zero pulse (0..1, default 0.1).
    pub fEnc_RefSyncVelo: Option<f64>,
    /// Homing: the cam is searched in the positive direction (default false).
    pub bEnc_RefIndexPositive: Option<bool>,
    /// Homing: the cam's end and the zero pulse are searched positive (default false).
    pub bEnc_RefSyncPositive: Option<bool>,
    /// Homing: the reference position when MC_Home_BkPlcMc is given none (mm, default 0).
    pub fEnc_DefaultHomePosition: Option<f64>,
    /// Homing on block: the time without movement (s, >= 0, default 2; below the cycle: 2).
    pub fBlockDetectDelay: Option<f64>,
    /// Weight of the set velocity in the output (1.0: full feed forward).
    pub fFeedForward: Option<f64>,
    /// Area ratio A:B (velocity ratio of the two directions).
    pub fAreaRatio: Option<f64>,
    /// Overlap compensation, positive direction (normalised).
    pub fValve_OverlapCompP: Option<f64>,
    /// Overlap compensation, negative direction (normalised).
    pub fValve_OverlapCompM: Option<f64>,
    /// Velocity (normalised) of the flow curve's bend point.
    pub fValve_BendPointVelo: Option<f64>,
    /// Output (normalised) of the flow curve's bend point.
    pub fValve_BendPointOutput: Option<f64>,
    /// Zero (offset) compensation (V).
    pub fZeroCompensation: Option<f64>,
    /// The lowest velocity (mm/s) for the characteristic curve, positive direction; below it
    /// the straight line from the zero point.
    pub Valve_LinLimitP: Option<f64>,
    /// The same for the negative direction.
    pub Valve_LinLimitM: Option<f64>,
    /// tandem's: the form of the valve output after Finish (`MC_AxRtDrive_BkPlcMc`):
    /// `voltage` (±10 V, default), `two_coil` or `one_coil`.
    pub valve_output: Option<String>,
    /// The output as a magnitude, the direction on `bMovePos` / `bMoveNeg` (a current valve;
    /// with `valve_output = "voltage"` only).
    pub bDrive_AbsoluteOutput: Option<bool>,
    /// The output negated.
    pub bDrive_Reversed: Option<bool>,
    /// tandem's: a file with the valve's characteristic curve (the library's ASCII table
    /// format, one "velocity output" pair per line, both normalised), relative to the cell
    /// file; given, Finish linearises with it (`MC_AxRtFinishLinear_BkPlcMc`).
    pub characteristic_curve: Option<String>,
    /// The pressure inputs (`MC_AxRtReadForceDiff_BkPlcMc`): chamber A's pressure per input
    /// increment (bar). Given, the axis reads its two pressure inputs every cycle.
    pub ScaleFactorA: Option<f64>,
    /// Chamber A's pressure at input word 0 (bar; default 0).
    pub ScaleOffsetA: Option<f64>,
    /// Chamber B's pressure per input increment (bar; default `ScaleFactorA`).
    pub ScaleFactorB: Option<f64>,
    /// Chamber B's pressure at input word 0 (bar; default 0).
    pub ScaleOffsetB: Option<f64>,
    /// The piston area for the force (mm²; default 1: the pressure).
    pub ScaleArreaA: Option<f64>,
    /// The annulus area for the force (mm²; default 1).
    pub ScaleArreaB: Option<f64>,
    /// The generator of the positionings (`E_TcMcProfileType`): the library's name
    /// (`iTcMc_ProfileCtrlBased`, the default; `iTcMc_ProfileJerkBased`;
    /// `iTcMc_ProfileConstAcc`, the old name of the first) or its number (3, 5, 0).
    pub nProfileType: Option<ProfileTypeValue>,
    /// The jerk of the jerk-based generator (mm/s³; default 1000).
    pub fMaxJerk: Option<f64>,
    /// Which transitions of the jerk-based profile are jerk-limited (a WORD; default
    /// `0x0101`): `0x0001` the build-up of the acceleration, `0x0002` its reduction,
    /// `0x0100` the end into the target.
    pub nJerkEnabled: Option<i64>,
    /// The time-based mode: the profile runs in time on the set position and the position
    /// controller acts during the move (default false: displacement-based).
    pub bTimeBased: Option<bool>,
}

/// `nProfileType`: the library's enumeration name or its number.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum ProfileTypeValue {
    /// A name of `E_TcMcProfileType`.
    Name(String),
    /// Its number.
    Number(i64),
}

/// `[signals.<name>]`: a named signal on a channel of a device. Its type comes from the
/// channel: `bool` on a plain digital channel, `timestamped bool` on a timestamped one,
/// `float` on an analog channel, `integer` on a counter channel; `type` may state it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SignalSection {
    /// The device (`[devices.<name>]`).
    pub device: String,
    /// The channel, 1-based.
    pub channel: u32,
    /// `bool`, `integer` or `float`: the type the signal is meant to have; refused unless its
    /// channel has it (default: the channel's).
    #[serde(rename = "type")]
    pub signal_type: Option<String>,
    /// `[signals.<name>.sensor]`: an input's simulated sensor, a mark on an axis's load
    /// (`axis` required).
    pub sensor: Option<SensorSection>,
}

/// `[axes.<name>.inputs]`: input signals (`[signals.<name>]`) as the axis's switches, for an
/// axis on the simulated drive.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisInputsSection {
    /// The positive hardware limit switch (`PositionLimits_HW.MaxSwitch`).
    pub limit_positive: Option<String>,
    /// The negative hardware limit switch (`PositionLimits_HW.MinSwitch`).
    pub limit_negative: Option<String>,
    /// The reference cam (homing switch).
    pub reference_cam: Option<String>,
}

/// `encoder`: the encoder type alone (`encoder = "absolute"`), or the table
/// `[axes.<name>.encoder]` with the measuring system of a drive behind the process image.
#[derive(Debug)]
pub enum EncoderSpec {
    /// `encoder = "<type>"`.
    Type(String),
    /// `[axes.<name>.encoder]`.
    Table(EncoderTable),
}

impl EncoderSpec {
    /// The encoder type's name.
    pub fn type_name(&self) -> &str {
        match self {
            Self::Type(t) => t,
            Self::Table(t) => &t.kind,
        }
    }
}

impl<'de> Deserialize<'de> for EncoderSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = toml::Value::deserialize(d)?;
        match v {
            toml::Value::String(s) => Ok(Self::Type(s)),
            toml::Value::Table(_) => EncoderTable::deserialize(v)
                .map(Self::Table)
                .map_err(serde::de::Error::custom),
            other => Err(serde::de::Error::custom(format!(
                "expected an encoder type (\"incremental\", \"absolute\", \"cyclic_absolute\") \
                 or a table, found a {}",
                other.type_str()
            ))),
        }
    }
}

impl Default for EncoderSpec {
    fn default() -> Self {
        Self::Type(default_encoder())
    }
}

/// `[axes.<name>.encoder]`: the encoder of a drive behind the process image (S7-1500T
/// `Sensor[1]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderTable {
    /// `incremental` (default), `absolute` or `cyclic_absolute`.
    #[serde(rename = "type", default = "default_encoder")]
    pub kind: String,
    /// `Parameter.StepsPerRevolution` (default: the increments per revolution of the drive's
    /// position actual value, for a simulated servo its `increments_per_revolution`).
    pub steps_per_revolution: Option<u32>,
    /// `Parameter.FineResolutionXist1` (bits, default 0).
    #[serde(default)]
    pub fine_resolution_bits: u8,
    /// `Parameter.DeterminableRevolutions` of an absolute encoder (default 1: single turn).
    #[serde(default = "d_one_u32")]
    pub determinable_revolutions: u32,
    /// Width of the raw position word (default 32, the drive's 0x6064).
    #[serde(default = "d_raw_bits")]
    pub raw_bits: u8,
    /// `InverseDirection` of the actual value.
    #[serde(default)]
    pub inverse: bool,
    /// `MountingMode`: `motor_shaft` (default), `load_side` or `external`.
    #[serde(default = "d_mounting")]
    pub mounting: String,
    /// `Parameter.DistancePerRevolution` of an external measuring system.
    pub distance_per_revolution: Option<f64>,
}

impl EncoderTable {
    /// The table of an encoder given by its type alone (`encoder = "<type>"`) on a drive of the
    /// process image: the drive's own motor encoder, its position actual value in increments.
    pub fn of_drive(kind: &str) -> Self {
        Self {
            kind: kind.into(),
            steps_per_revolution: None,
            fine_resolution_bits: 0,
            determinable_revolutions: 1,
            raw_bits: d_raw_bits(),
            inverse: false,
            mounting: d_mounting(),
            distance_per_revolution: None,
        }
    }

    /// The encoder type (checked by the axis's `encoder` key: `incremental`, `absolute` or
    /// `cyclic_absolute`).
    pub fn encoder_kind(&self) -> tandem_motion::plant::mechanics::EncoderKind {
        use tandem_motion::plant::mechanics::EncoderKind;
        match self.kind.as_str() {
            "absolute" => EncoderKind::Absolute,
            "cyclic_absolute" => EncoderKind::CyclicAbsolute,
            _ => EncoderKind::Incremental,
        }
    }
}

fn d_one_u32() -> u32 {
    1
}
fn d_raw_bits() -> u8 {
    32
}
fn d_mounting() -> String {
    "motor_shaft".into()
}

/// `[axes.<name>.mechanics]`: gear, leadscrew and inversion between the motor and the load.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MechanicsSection {
    /// `LoadGear.Numerator/Denominator`: motor revolutions : load revolutions (default
    /// `[1, 1]`).
    #[serde(default = "d_gear")]
    pub load_gear: [u32; 2],
    /// `LeadScrew`: units per load revolution of a linear axis; without it a load revolution is
    /// 360 units.
    pub leadscrew_pitch: Option<f64>,
    /// `Actor.InverseDirection`: the setpoint is inverted.
    #[serde(default)]
    pub inverse_drive: bool,
    /// `Actor.Efficiency` of gear and leadscrew (0 < e <= 1, default 1), for torques.
    #[serde(default = "d_efficiency")]
    pub efficiency: f64,
}

fn d_efficiency() -> f64 {
    1.0
}

fn d_gear() -> [u32; 2] {
    [1, 1]
}

fn d_distance() -> String {
    "distance".into()
}
fn d_setpoint() -> String {
    "setpoint".into()
}
fn d_arming() -> u32 {
    2
}

/// `[[output_cams]]`: an output cam technology object (MC_OutputCam).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputCamSection {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose position it refers to.
    pub axis: String,
    /// `distance` (default) or `time`.
    #[serde(rename = "type", default = "d_distance")]
    pub kind: String,
    /// `setpoint` (default) or `actual`.
    #[serde(default = "d_setpoint")]
    pub position: String,
    /// Lead time of the on edge (s).
    #[serde(default)]
    pub on_compensation: f64,
    /// Lead time of the off edge (s).
    #[serde(default)]
    pub off_compensation: f64,
    /// Hysteresis (position units).
    #[serde(default)]
    pub hysteresis: f64,
    /// `[min, max]` operating range of a linear axis (hysteresis cap).
    pub working_range: Option<[f64; 2]>,
    /// Time cams: cycles after the enable before a start crossing switches (default 2).
    #[serde(default = "d_arming")]
    pub arming_cycles: u32,
    /// The digital output signal it drives (`[signals.<name>]`), if any.
    pub output: Option<String>,
}

fn d_software() -> String {
    "software".into()
}
fn d_masking() -> u32 {
    0xFFFF_FFFF
}

/// `[[cam_tracks]]`: a cam track technology object (MC_CamTrack).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CamTrackSection {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose position it refers to.
    pub axis: String,
    /// `distance` (default) or `time`.
    #[serde(rename = "type", default = "d_distance")]
    pub kind: String,
    /// `setpoint` (default) or `actual`.
    #[serde(default = "d_setpoint")]
    pub position: String,
    /// `ReferencePosition`.
    #[serde(default)]
    pub reference_position: f64,
    /// `CamTrackLength`.
    pub track_length: f64,
    /// `CamMasking` (bit i = cam i + 1; default all).
    #[serde(default = "d_masking")]
    pub masking: u32,
    /// `software` (default), `timer_dq` or `dq_module`.
    #[serde(default = "d_software")]
    pub interface: String,
    /// Lead time of the on edge (s).
    #[serde(default)]
    pub on_compensation: f64,
    /// Lead time of the off edge (s).
    #[serde(default)]
    pub off_compensation: f64,
    /// Hysteresis (position units).
    #[serde(default)]
    pub hysteresis: f64,
    /// `[min, max]` operating range of a linear axis (hysteresis cap).
    pub working_range: Option<[f64; 2]>,
    /// The cams (up to 32), relative to the track start.
    #[serde(default)]
    pub cams: Vec<TrackCamSection>,
    /// The digital output signal its track output drives (`[signals.<name>]`), if any.
    pub output: Option<String>,
}

/// One cam of a track.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackCamSection {
    /// `OnPosition`.
    pub on: f64,
    /// `OffPosition` (distance tracks).
    pub off: Option<f64>,
    /// `Duration` (s, time tracks).
    pub duration: Option<f64>,
}

/// `[[digital_cam_switches]]`: the switches and tracks of an MC_DigitalCamSwitch_BkPlcMc of
/// the Beckhoff hydraulic library, on the actual position of an axis.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DigitalCamSwitchSection {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose actual position and velocity switch it.
    pub axis: String,
    /// `TrackOptions`: track `n` is entry `n - 1` (up to 32), driving bit `n - 1`.
    #[serde(default)]
    pub tracks: Vec<DcsTrackSection>,
    /// `Switches`.
    #[serde(default)]
    pub switches: Vec<DcsSwitchSection>,
}

/// One track of a digital cam switch (`MC_TRACK_REFTYPE_BkPlcMc`) and the signal it drives.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DcsTrackSection {
    /// `OnCompensation` (s): positive delays, negative gives early.
    #[serde(default)]
    pub on_compensation: f64,
    /// `OffCompensation` (s).
    #[serde(default)]
    pub off_compensation: f64,
    /// `Hysteresis` (position units).
    #[serde(default)]
    pub hysteresis: f64,
    /// The digital output signal the track's bit drives (`[signals.<name>]`), if any.
    pub output: Option<String>,
}

/// One switch of a digital cam switch (`MC_CAMSWITCH_REFTYPE_BkPlcMc`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DcsSwitchSection {
    /// `TrackNumber` (1-based).
    pub track_number: i64,
    /// `FirstOnPosition`.
    pub first_on_position: f64,
    /// `LastOnPosition` (position switches).
    pub last_on_position: Option<f64>,
    /// `AxisDirection`: 0 both (default), 1 positive, 2 negative.
    #[serde(default)]
    pub axis_direction: i64,
    /// `CamSwitchMode`: 0 position (default), 1 time.
    #[serde(default)]
    pub cam_switch_mode: i64,
    /// `Duration` (s, time switches).
    pub duration: Option<f64>,
}

fn d_timer_di() -> String {
    "timer_di".into()
}
fn t() -> bool {
    true
}
fn d_both() -> String {
    "both".into()
}

/// `[[measuring_inputs]]`: a measuring input technology object.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuringInputSection {
    /// Name (unique among all objects).
    pub name: String,
    /// The axis whose actual position is measured.
    pub axis: String,
    /// `timer_di` (default), `central_probe` or `profidrive`.
    #[serde(default = "d_timer_di")]
    pub route: String,
    /// `CorrectionTime` (s): the position is taken at the edge time minus this.
    #[serde(default)]
    pub correction_time: f64,
    /// `AdditionalActivationTime` (s).
    #[serde(default)]
    pub additional_activation_time: f64,
    /// Apply the activation time after a job start (default true).
    #[serde(default = "t")]
    pub apply_activation_time: bool,
    /// `[measuring_inputs.sensor]`: a simulated sensor.
    pub sensor: Option<SensorSection>,
    /// A timestamped input signal (`[signals.<name>]`) whose edges the input measures (route
    /// `timer_di`).
    pub input: Option<String>,
    /// `[measuring_inputs.registration]`: register correction from each new measured value.
    pub registration: Option<RegistrationSection>,
}

/// Register correction: each new MeasuredValue1 of a cyclic job moves `axis` by
/// `gain * (target - measured)` (reduced to ±half the modulo length) with MC_MoveSuperimposed.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegistrationSection {
    /// The corrected axis.
    pub axis: String,
    /// The register target (the measured value when in register).
    pub target: f64,
    /// Share of the error corrected per mark (0 < gain <= 1, default 1).
    #[serde(default = "one")]
    pub gain: f64,
}

/// A simulated mark sensor.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSection {
    /// The axis that carries the mark (default: the input's axis; same node).
    pub axis: Option<String>,
    /// Start of the mark (position units; every revolution on a modulo axis).
    pub position: f64,
    /// Width of the mark (> 0).
    pub width: f64,
    /// `positive`, `negative` or `both` (default).
    #[serde(default = "d_both")]
    pub direction: String,
    /// Dead time (s) from the crossing to the edge.
    #[serde(default)]
    pub dead_time: f64,
    /// Jitter (s): uniform in `[-jitter, jitter]`.
    #[serde(default)]
    pub jitter: f64,
    /// Seed of the jitter generator.
    #[serde(default = "one_u64")]
    pub seed: u64,
}

fn one_u64() -> u64 {
    1
}

/// `[cams.<name>]`: a cam, interpolated when the cell is loaded.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CamSection {
    /// `linear`, `cubic_spline` (default) or `bezier`.
    #[serde(default = "d_interp")]
    pub interpolation: String,
    /// `none` (default) or `equal_first_derivative`.
    #[serde(default = "d_boundary")]
    pub boundary: String,
    /// Interpolation points `[x, y]`.
    #[serde(default)]
    pub points: Vec<[f64; 2]>,
    /// A CSV file of points (`x,y` lines), relative to the cell file.
    pub points_csv: Option<String>,
    /// `[[cams.<name>.segments]]`.
    #[serde(default)]
    pub segments: Vec<CamSegmentSection>,
}

fn d_interp() -> String {
    "cubic_spline".into()
}
fn d_boundary() -> String {
    "none".into()
}

/// One cam segment.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CamSegmentSection {
    /// `law`, `polynomial` or `s7_polynomial`.
    #[serde(rename = "type")]
    pub kind: String,
    /// `[x0, x1]`.
    pub x: [f64; 2],
    /// `law`: `[y0, y1]`.
    pub y: Option<[f64; 2]>,
    /// `law`: the VDI 2143 law name (`poly5`, `cycloid`, ...).
    pub law: Option<String>,
    /// `law`: the parameter of `inclined_sine` (v) or `modified_acceleration_trapezoid` (lambda).
    pub parameter: Option<f64>,
    /// `polynomial`: coefficients in `u = (x - x0) / (x1 - x0)`, up to 8.
    pub coeffs: Option<Vec<f64>>,
    /// `s7_polynomial`: `a0..a6` in absolute x.
    pub a: Option<Vec<f64>>,
    /// `s7_polynomial`: the sine term.
    pub sine: Option<SineSection>,
}

/// The sine term of an S7 polynomial segment.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SineSection {
    /// Amplitude.
    #[serde(default)]
    pub amplitude: f64,
    /// Period (rad).
    #[serde(default = "one")]
    pub period: f64,
    /// Phase (rad).
    #[serde(default)]
    pub phase: f64,
}

/// `[encoders.<name>]`: an external encoder with a simulated source.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderSection {
    /// The node that hosts it.
    pub node: String,
    /// `incremental` or `absolute`.
    #[serde(default = "default_encoder")]
    pub encoder: String,
    /// `[encoders.<name>.modulo]`.
    pub modulo: Option<ModuloSection>,
    /// `axis` (measures another axis' actual position) or `profile` (a velocity profile).
    pub source: String,
    /// With `source = "axis"`: the axis it measures.
    pub axis: Option<String>,
    /// With `source = "axis"`: encoder units per axis unit (measuring gear).
    #[serde(default = "one")]
    pub scale: f64,
    /// With `source = "profile"`: `[time s, velocity]` points, velocity linear in between and
    /// constant after the last.
    pub profile: Option<Vec<[f64; 2]>>,
    /// `[encoders.<name>.extrapolation]`.
    #[serde(default)]
    pub extrapolation: ExtrapolationSection,
    /// `[encoders.<name>.leading_value]`: this encoder as a leader.
    pub leading_value: Option<LeadingValueSection>,
}

fn one() -> f64 {
    1.0
}

/// `[cell]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellSection {
    /// Cell name (used in key expressions later).
    pub name: String,
    /// Base tick of the cell clock in µs: every node cycle is a multiple of it.
    #[serde(default = "default_base_tick_us")]
    pub base_tick_us: u64,
    /// The time a leading value needs from the leader's node to a follower's node on the same
    /// host (publish, iceoryx2, wake-up), in µs: part of the minimum leading-value delay.
    #[serde(default = "default_ipc_budget_us")]
    pub ipc_budget_us: u64,
    /// The same between nodes of different hosts (gateway, Zenoh, network), in µs.
    #[serde(default = "default_network_budget_us")]
    pub network_budget_us: u64,
    /// Telemetry rate of the gateways on Zenoh (per TO state), in Hz.
    #[serde(default = "default_telemetry_hz")]
    pub telemetry_hz: f64,
    /// The gateway warns when the clock offset to another host exceeds this share of the
    /// smallest leading-value delay of a coupling between them.
    #[serde(default = "default_clock_warning")]
    pub clock_warning_fraction: f64,
    /// The directory of the retained data (docs/io.md, "Retained data"), relative to the cell
    /// file's directory; default `retain`. Each node keeps its records in
    /// `<retain_dir>/<cell name>/<node name>/`.
    pub retain_dir: Option<String>,
    /// Commands each sender may send per second, sustained (docs/gateway.md, "Command
    /// rate"); more get the reply `busy`. Default 20.
    #[serde(default = "default_command_rate_hz")]
    pub command_rate_hz: f64,
    /// Commands a sender may send at once above the sustained rate. Default 40.
    #[serde(default = "default_command_burst")]
    pub command_burst: u32,
    /// `tandem up`'s watchdog (docs/processes.md, "Watchdog"), in ms: a node whose cycles
    /// stop advancing (or a gateway that stops answering) for this long is reported as
    /// stalled. Default 500, from 10 to 3600000.
    #[serde(default = "default_watchdog_ms")]
    pub watchdog_ms: u64,
    /// The silence after which `tandem up` restarts a stalled process (kill -9, then start),
    /// in ms; at least `watchdog_ms`, at most 3600000. Default 2000.
    #[serde(default = "default_watchdog_restart_ms")]
    pub watchdog_restart_ms: u64,
}

fn default_watchdog_ms() -> u64 {
    500
}

fn default_watchdog_restart_ms() -> u64 {
    2000
}

fn default_command_rate_hz() -> f64 {
    20.0
}

fn default_command_burst() -> u32 {
    40
}

fn default_telemetry_hz() -> f64 {
    50.0
}

fn default_clock_warning() -> f64 {
    0.25
}

fn default_network_budget_us() -> u64 {
    2000
}

fn default_ipc_budget_us() -> u64 {
    200
}

/// `[[hosts]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HostSection {
    /// Host name (`tandem up --host <name>`).
    pub name: String,
    /// Zenoh endpoints its gateway listens on (`tls/10.0.0.1:7447`), exactly these; the other
    /// hosts' gateways connect to them. Empty: it listens nowhere (it only dials); multicast
    /// scouting only with `[security] multicast_scouting = true`.
    #[serde(default)]
    pub listen: Vec<String>,
}

/// `[nodes.realtime]`: scheduling of the node's cyclic thread.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RealtimeSection {
    /// SCHED_FIFO priority 1..=99; absent: normal scheduling.
    pub priority: Option<u8>,
    /// Pin the cyclic thread to this CPU.
    pub cpu: Option<usize>,
    /// Lock the process' memory (mlockall).
    #[serde(default)]
    pub lock_memory: bool,
}

/// `[axes.<name>.leading_value]` / `[encoders.<name>.leading_value]`: how followers receive this
/// leader's values.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeadingValueSection {
    /// Leading-value delay D (µs): every follower, local or remote, evaluates the leader at
    /// `t - D`.
    #[serde(default)]
    pub delay_us: u64,
    /// How long a late sample is bridged by extrapolation (µs); default: two leader cycles.
    pub tolerance_us: Option<u64>,
}

fn default_base_tick_us() -> u64 {
    250
}

/// `[[nodes]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSection {
    /// Node name.
    pub name: String,
    /// Servo cycle in µs.
    pub cycle_us: u64,
    /// The host that runs it (`[[hosts]]`); may be left out when the cell has one host.
    pub host: Option<String>,
    /// `[nodes.realtime]`.
    #[serde(default)]
    pub realtime: RealtimeSection,
}

/// `[axes.<name>]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSection {
    /// The node that hosts the axis.
    pub node: String,
    /// `speed`, `positioning`, `synchronous` or `hydraulic`.
    #[serde(default = "default_kind")]
    pub kind: String,
    /// `linear` or `rotary`.
    #[serde(default = "default_motion_type")]
    pub motion_type: String,
    /// `incremental`, `absolute` or `cyclic_absolute`, or the table with the measuring system.
    #[serde(default)]
    pub encoder: EncoderSpec,
    /// `[axes.<name>.mechanics]`: for a drive behind the process image.
    pub mechanics: Option<MechanicsSection>,
    /// Virtual axis / simulation mode.
    #[serde(default, rename = "virtual")]
    pub virtual_axis: bool,
    /// Physical position at start.
    #[serde(default)]
    pub initial_position: f64,
    /// `[axes.<name>.modulo]`.
    pub modulo: Option<ModuloSection>,
    /// `[axes.<name>.dynamics]`.
    pub dynamics: DynamicsSection,
    /// `[axes.<name>.sw_limits]`.
    pub sw_limits: Option<SwLimitsSection>,
    /// `[axes.<name>.hw_limits]`.
    pub hw_limits: Option<HwLimitsSection>,
    /// `[axes.<name>.inputs]`: input signals as the limit switches and reference cam.
    pub inputs: Option<AxisInputsSection>,
    /// `[axes.<name>.positioning]`.
    #[serde(default)]
    pub positioning: PositioningSection,
    /// `[axes.<name>.following_error]`.
    #[serde(default)]
    pub following_error: FollowingErrorSection,
    /// `[axes.<name>.standstill]`.
    #[serde(default)]
    pub standstill: StandstillSection,
    /// `[axes.<name>.homing]`.
    #[serde(default)]
    pub homing: HomingSection,
    /// `[axes.<name>.drive]`.
    #[serde(default)]
    pub drive: DriveSection,
    /// `[axes.<name>.plant]`.
    #[serde(default)]
    pub plant: PlantSection,
    /// `[axes.<name>.extrapolation]`: preparation of this axis' actual value for followers
    /// coupled by actual value.
    #[serde(default)]
    pub extrapolation: ExtrapolationSection,
    /// `[axes.<name>.leaders]`: the leaders this axis may follow, `name = "setpoint"` or
    /// `"actual"` (the coupling); a leader is named `to` or `"node/to"`. Without the table any
    /// axis of the same node may lead, by setpoint.
    pub leaders: Option<BTreeMap<String, String>>,
    /// `[axes.<name>.leading_value]`: this axis as a leader.
    pub leading_value: Option<LeadingValueSection>,
    /// The reaction to alarm 601 (leading value missing): `stop_current_dynamics`,
    /// `stop_max_dynamics` (default, the table value), `emergency_stop`, `remove_enable`.
    pub leader_missing_reaction: Option<String>,
    /// `[axes.<name>.hydraulic]`: the parameters of a `kind = "hydraulic"` axis.
    pub hydraulic: Option<HydraulicSection>,
    /// `[axes.<name>.torque_limiting]`.
    #[serde(default)]
    pub torque_limiting: TorqueLimitingSection,
    /// `[axes.<name>.clamping]`.
    #[serde(default)]
    pub clamping: ClampingSection,
}

/// `[axes.<name>.extrapolation]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtrapolationSection {
    /// `PositionFilter.T1` (s).
    #[serde(default)]
    pub position_t1: f64,
    /// `PositionFilter.T2` (s).
    #[serde(default)]
    pub position_t2: f64,
    /// `VelocityFilter.T1` (s).
    #[serde(default)]
    pub velocity_t1: f64,
    /// `VelocityFilter.T2` (s).
    #[serde(default)]
    pub velocity_t2: f64,
    /// `VelocityTolerance.Range`.
    #[serde(default)]
    pub velocity_tolerance: f64,
    /// `Hysteresis.Value`.
    #[serde(default)]
    pub hysteresis: f64,
    /// `FollowingAxisDependentTime` (s).
    #[serde(default)]
    pub following_time: f64,
    /// Actual value acquisition time (s).
    #[serde(default)]
    pub acquisition_time: f64,
    /// `Settings.SystemDefinedExtrapolation`.
    #[serde(default = "yes")]
    pub system_defined: bool,
    /// `filtered` or `differentiation`.
    #[serde(default = "d_vmode")]
    pub velocity_mode: String,
}

fn d_vmode() -> String {
    "filtered".into()
}

impl Default for ExtrapolationSection {
    fn default() -> Self {
        Self {
            position_t1: 0.0,
            position_t2: 0.0,
            velocity_t1: 0.0,
            velocity_t2: 0.0,
            velocity_tolerance: 0.0,
            hysteresis: 0.0,
            following_time: 0.0,
            acquisition_time: 0.0,
            system_defined: true,
            velocity_mode: d_vmode(),
        }
    }
}

fn default_kind() -> String {
    "positioning".into()
}
fn default_motion_type() -> String {
    "linear".into()
}
fn default_encoder() -> String {
    "incremental".into()
}

/// Modulo.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuloSection {
    /// `Modulo.StartValue`.
    #[serde(default)]
    pub start: f64,
    /// `Modulo.Length`.
    pub length: f64,
}

/// Dynamic limits and defaults.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSection {
    /// `DynamicLimits.MaxVelocity`.
    pub max_velocity: f64,
    /// `DynamicLimits.MaxAcceleration`.
    pub max_acceleration: f64,
    /// `DynamicLimits.MaxDeceleration`.
    pub max_deceleration: f64,
    /// `DynamicLimits.MaxJerk`.
    pub max_jerk: f64,
    /// `DynamicDefaults.Velocity`.
    pub velocity: f64,
    /// `DynamicDefaults.Acceleration`.
    pub acceleration: f64,
    /// `DynamicDefaults.Deceleration`.
    pub deceleration: f64,
    /// `DynamicDefaults.Jerk`.
    pub jerk: f64,
    /// `DynamicDefaults.EmergencyDeceleration`.
    pub emergency_deceleration: f64,
}

/// Software limit switches.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwLimitsSection {
    /// `PositionLimits_SW.MinPosition`.
    pub min: f64,
    /// `PositionLimits_SW.MaxPosition`.
    pub max: f64,
}

/// Hardware limit switches (positions of the simulated switches, physical coordinates).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HwLimitsSection {
    /// `PositionLimits_HW.Active`.
    #[serde(default = "yes")]
    pub active: bool,
    /// Negative switch position.
    pub min: Option<f64>,
    /// Positive switch position.
    pub max: Option<f64>,
}

fn yes() -> bool {
    true
}

/// Positioning monitoring.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositioningSection {
    /// `PositioningMonitoring.Window`.
    #[serde(default = "d_window")]
    pub window: f64,
    /// `PositioningMonitoring.ToleranceTime` (s).
    #[serde(default = "d_tol")]
    pub tolerance_time: f64,
    /// `PositioningMonitoring.MinDwellTime` (s).
    #[serde(default)]
    pub min_dwell_time: f64,
}

fn d_window() -> f64 {
    0.01
}
fn d_tol() -> f64 {
    1.0
}

impl Default for PositioningSection {
    fn default() -> Self {
        Self {
            window: d_window(),
            tolerance_time: d_tol(),
            min_dwell_time: 0.0,
        }
    }
}

/// Following-error monitoring.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FollowingErrorSection {
    /// `FollowingError.EnableMonitoring`.
    #[serde(default = "yes")]
    pub enable: bool,
    /// `FollowingError.MinValue`.
    #[serde(default = "d_fe_min")]
    pub min_value: f64,
    /// `FollowingError.MaxValue`.
    #[serde(default = "d_fe_max")]
    pub max_value: f64,
    /// `FollowingError.MinVelocity`.
    #[serde(default = "d_fe_minv")]
    pub min_velocity: f64,
    /// `FollowingError.WarningLevel` (%).
    #[serde(default = "d_fe_warn")]
    pub warning_level: f64,
}

fn d_fe_min() -> f64 {
    1.0
}
fn d_fe_max() -> f64 {
    10.0
}
fn d_fe_minv() -> f64 {
    10.0
}
fn d_fe_warn() -> f64 {
    90.0
}

impl Default for FollowingErrorSection {
    fn default() -> Self {
        Self {
            enable: true,
            min_value: d_fe_min(),
            max_value: d_fe_max(),
            min_velocity: d_fe_minv(),
            warning_level: d_fe_warn(),
        }
    }
}

/// Standstill signal.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StandstillSection {
    /// `StandstillSignal.VelocityThreshold`.
    #[serde(default = "d_ss_v")]
    pub velocity_threshold: f64,
    /// `StandstillSignal.MinDwellTime` (s).
    #[serde(default = "d_ss_t")]
    pub min_dwell_time: f64,
}

fn d_ss_v() -> f64 {
    0.1
}
fn d_ss_t() -> f64 {
    0.01
}

impl Default for StandstillSection {
    fn default() -> Self {
        Self {
            velocity_threshold: d_ss_v(),
            min_dwell_time: d_ss_t(),
        }
    }
}

/// Homing.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomingSection {
    /// `zero_mark`, `cam_and_zero_mark` or `digital_input`.
    #[serde(default = "d_mark")]
    pub active_mark: String,
    /// Same, for passive homing.
    #[serde(default = "d_mark")]
    pub passive_mark: String,
    /// `positive` or `negative`.
    #[serde(default = "d_pos")]
    pub approach_direction: String,
    /// `positive` or `negative`.
    #[serde(default = "d_pos")]
    pub homing_direction: String,
    /// `positive`, `negative` or `current`.
    #[serde(default = "d_current")]
    pub passive_direction: String,
    /// `Homing.ApproachVelocity`.
    #[serde(default = "d_app_v")]
    pub approach_velocity: f64,
    /// `Homing.ReferencingVelocity`.
    #[serde(default = "d_ref_v")]
    pub referencing_velocity: f64,
    /// `Homing.HomePosition`.
    #[serde(default)]
    pub home_position: f64,
    /// `HomePositionOffset`.
    #[serde(default)]
    pub home_position_offset: f64,
    /// `Homing.AutoReversal`.
    #[serde(default = "yes")]
    pub auto_reversal: bool,
}

fn d_mark() -> String {
    "cam_and_zero_mark".into()
}
fn d_pos() -> String {
    "positive".into()
}
fn d_current() -> String {
    "current".into()
}
fn d_app_v() -> f64 {
    10.0
}
fn d_ref_v() -> f64 {
    2.0
}

impl Default for HomingSection {
    fn default() -> Self {
        Self {
            active_mark: d_mark(),
            passive_mark: d_mark(),
            approach_direction: d_pos(),
            homing_direction: d_pos(),
            passive_direction: d_current(),
            approach_velocity: d_app_v(),
            referencing_velocity: d_ref_v(),
            home_position: 0.0,
            home_position_offset: 0.0,
            auto_reversal: true,
        }
    }
}

/// `[axes.<name>.drive]`: the drive connection; the simulated drive model by default.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSection {
    /// `simulation` (default: the drive model inside the axis), `cia402` (a CiA 402 drive
    /// of the process image, `device`) or `analog` (a drive with a ±10 V speed setpoint and an
    /// encoder of its own, `device`; tandem closes the position loop).
    #[serde(rename = "type", default = "d_drive_type")]
    pub kind: String,
    /// cia402, analog: the device (`[devices.<name>]`).
    pub device: Option<String>,
    /// cia402: time allowed for each step of the enable sequence; analog: for the ready input
    /// after the enable output (s, default 1).
    pub enable_timeout: Option<f64>,
    /// cia402: torque feedforward 0x60B2 from the setpoint acceleration (default false).
    pub torque_precontrol: Option<bool>,
    /// cia402: the moment of inertia at the motor the torque feedforward uses (kg·m², motor
    /// plus load reflected to the motor; default: the simulated drive's `inertia`).
    pub inertia: Option<f64>,
    /// analog: the load's velocity at 100 % of the command, 10 V (units/s, required): S7's
    /// `ReferenceSpeed` through the mechanics.
    pub reference_velocity: Option<f64>,
    /// analog: the drive's ready output is wired to an input (default `true`); without it
    /// MC_Power's Status comes with the enable output.
    pub ready: Option<bool>,
    /// analog: `DynamicAxisModel.AdditionalPositionTimeConstant` (s, default 0).
    pub t_addptc: Option<f64>,
    /// simulation: `position_loop` or `delay`.
    #[serde(default = "d_model")]
    pub model: String,
    /// `PositionControl.Kv` (1/s).
    #[serde(default = "d_kv")]
    pub kv: f64,
    /// `PositionControl.Kpc` (%).
    #[serde(default = "d_kpc")]
    pub kpc: f64,
    /// `DynamicAxisModel.VelocityTimeConstant` (s).
    #[serde(default = "d_tvtc")]
    pub t_vtc: f64,
    /// `T_t` of the delay model (s).
    #[serde(default = "d_delay")]
    pub delay: f64,
}

fn d_model() -> String {
    "position_loop".into()
}
fn d_kv() -> f64 {
    100.0
}
fn d_kpc() -> f64 {
    100.0
}
fn d_tvtc() -> f64 {
    0.002
}
fn d_delay() -> f64 {
    0.003
}

fn d_drive_type() -> String {
    "simulation".into()
}

impl Default for DriveSection {
    fn default() -> Self {
        Self {
            kind: d_drive_type(),
            device: None,
            enable_timeout: None,
            torque_precontrol: None,
            inertia: None,
            reference_velocity: None,
            ready: None,
            t_addptc: None,
            model: d_model(),
            kv: d_kv(),
            kpc: d_kpc(),
            t_vtc: d_tvtc(),
            delay: d_delay(),
        }
    }
}

/// Simulated plant sensors (physical coordinates).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantSection {
    /// Reference cam `[low, high]`.
    pub reference_cam: Option<[f64; 2]>,
    /// Distance between encoder zero marks.
    pub zero_mark_period: Option<f64>,
    /// Position of one zero mark.
    #[serde(default)]
    pub zero_mark_offset: f64,
    /// A mechanical stop the load cannot pass below (simulated CiA 402 servo only).
    pub fixed_stop_min: Option<f64>,
    /// A mechanical stop the load cannot pass above (simulated CiA 402 servo only).
    pub fixed_stop_max: Option<f64>,
}

/// `[axes.<name>.torque_limiting]`: S7's `TorqueLimiting.*`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueLimitingSection {
    /// `LimitDefaults.Torque` / `.Force` (N·m, or N on a linear axis): MC_TorqueLimiting's
    /// limit for `Limit` < 0; none: such a job is refused.
    pub limit_default: Option<f64>,
    /// `PositionBasedMonitorings` = 1: following error and positioning monitoring stay on
    /// under torque limits.
    #[serde(default)]
    pub keep_position_monitorings: bool,
    /// Metres per position unit of a linear axis, for forces in N (default 0.001: mm).
    #[serde(default = "d_position_unit_m")]
    pub position_unit_m: f64,
}

impl Default for TorqueLimitingSection {
    fn default() -> Self {
        Self {
            limit_default: None,
            keep_position_monitorings: false,
            position_unit_m: d_position_unit_m(),
        }
    }
}

fn d_position_unit_m() -> f64 {
    0.001
}

/// `[axes.<name>.clamping]`: S7's `Clamping.*` (fixed stop detection).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampingSection {
    /// `FollowingErrorDeviation` (position units): the following error that detects the stop.
    #[serde(default = "d_clamping_deviation")]
    pub following_error_deviation: f64,
    /// `PositionTolerance` (position units): the clamping window.
    #[serde(default = "d_clamping_tolerance")]
    pub position_tolerance: f64,
}

impl Default for ClampingSection {
    fn default() -> Self {
        Self {
            following_error_deviation: d_clamping_deviation(),
            position_tolerance: d_clamping_tolerance(),
        }
    }
}

fn d_clamping_deviation() -> f64 {
    1.0
}

fn d_clamping_tolerance() -> f64 {
    0.1
}

/// `[[ethercat]]`: the EtherCAT segment one node drives as its MainDevice.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EthercatSection {
    /// The node that drives the segment.
    pub node: String,
    /// The network interface the segment hangs on (e.g. `enp2s0`).
    pub interface: String,
    /// The expected SubDevices, in bus order.
    #[serde(default)]
    pub subdevices: Vec<SubDeviceSection>,
}

/// `[[ethercat.subdevices]]`: one expected SubDevice.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SubDeviceSection {
    /// Its name: a device of the node's process image.
    pub name: String,
    /// The identity it must report (SII / 0x1018).
    pub identity: IdentitySection,
    /// `cia402` (a drive) or `dio` (a digital input/output terminal).
    pub role: String,
    /// `cia402`: position actual value 0x6064 per motor revolution (default 2^20).
    pub increments_per_revolution: Option<u32>,
    /// `cia402`: cycles from a setpoint to the actual value that shows it (default 4).
    pub transport_cycles: Option<u8>,
    /// `dio`: the name of a device of its own for the terminal's 8 inputs.
    pub inputs: Option<String>,
}

/// `identity = { vendor, product, revision }`: CiA 301 identity object 0x1018:01..03.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdentitySection {
    /// Vendor ID 0x1018:01.
    pub vendor: u32,
    /// Product code 0x1018:02.
    pub product: u32,
    /// Revision number 0x1018:03.
    pub revision: u32,
}
