//! `[devices.<name>]` (simulated servo drives, analog drives and digital outputs) and the drive
//! connection of each axis (`[axes.<name>.drive]`, `[axes.<name>.encoder]`, `[axes.<name>.mechanics]`): which
//! device of which node's process image drives the axis, and how the drive's increments become
//! the axis's units.

use super::{node_named, pick, Ctx};
use crate::cell::{
    AnalogChannelParams, AnalogDriveConnection, AxisEntry, Cia402Connection, CounterParams,
    DeviceEntry, DeviceIndex, DeviceKind, DigitalInputParams, DigitalOutputParams, DriveConnection,
    Node, MAX_CHANNELS,
};
use crate::error::{ConfigError, Problem};
use crate::schema::{
    AxisSection, CellFile, DeviceSection, EncoderSpec, EncoderTable, HydraulicSection,
};
use tandem_motion::hydraulic::controller::HydControllerParams;
use tandem_motion::plant::analog::{
    AnalogParams, AnalogParamsError, ControllerParams, SimAnalogParams,
};
use tandem_motion::plant::cia402::QuickStopOption;
use tandem_motion::plant::mechanics::{
    EncoderConfig, EncoderKind, Mechanics, MechanicsError, MechanicsField, Mounting, Scaling,
};
use tandem_motion::plant::servo::{ServoParams, SimServo};

/// The kinds of device.
#[derive(Copy, Clone)]
enum Kind {
    Servo,
    DigitalOutput,
    Analog,
    DigitalInput,
    AnalogInput,
    AnalogOutput,
    Counter,
    ValveCylinder,
}

/// The device kinds by name.
const DEVICE_KINDS: [(&str, Kind); 8] = [
    ("sim_servo", Kind::Servo),
    ("sim_digital_output", Kind::DigitalOutput),
    ("sim_analog_drive", Kind::Analog),
    ("sim_valve_cylinder", Kind::ValveCylinder),
    ("sim_digital_input", Kind::DigitalInput),
    ("sim_analog_input", Kind::AnalogInput),
    ("sim_analog_output", Kind::AnalogOutput),
    ("sim_counter", Kind::Counter),
];

/// Default full scale of an analog terminal (V).
const ANALOG_RANGE_V: f64 = 10.0;

/// Default resolution of an analog terminal (bits including the sign).
const ANALOG_BITS: u32 = 16;

/// Default width of a counter register (bits).
const COUNTER_BITS: u32 = 32;

/// How an axis reaches its drive (`[axes.<name>.drive] type`).
#[derive(Copy, Clone, PartialEq, Eq)]
enum DriveType {
    Simulation,
    Cia402,
    Analog,
}

/// The drive connections by name.
const DRIVE_TYPES: [(&str, DriveType); 3] = [
    ("simulation", DriveType::Simulation),
    ("cia402", DriveType::Cia402),
    ("analog", DriveType::Analog),
];

/// The encoder mountings by name (S7 `Sensor[n].MountingMode` 0, 1, 2).
const MOUNTINGS: [(&str, ()); 3] = [("motor_shaft", ()), ("load_side", ()), ("external", ())];

/// Default time allowed for each step of a drive's enable sequence (s).
const ENABLE_TIMEOUT_S: f64 = 1.0;

/// `[devices.<name>]`: each device, on its node, with its parameters checked.
pub(super) fn devices(
    cx: Ctx<'_>,
    raw: &CellFile,
    nodes: &[Node],
) -> Result<Vec<DeviceEntry>, ConfigError> {
    let mut out = Vec::new();
    for (name, d) in &raw.devices {
        let node = node_named(cx, nodes, &d.node, &["devices", name, "node"])?;
        let at = |k: &str, p| cx.at(&["devices", name, k], p);
        let picked = pick("kind", &d.kind, &DEVICE_KINDS).map_err(|(k, p)| at(k, p))?;
        if !matches!(picked, Kind::ValveCylinder) {
            let given = [
                ("load", d.load.is_some()),
                ("cylinder", d.cylinder.is_some()),
            ];
            if let Some((k, _)) = given.into_iter().find(|(_, g)| *g) {
                return Err(at(k, Problem::NotForKind("sim_valve_cylinder")));
            }
        }
        let kind = match picked {
            Kind::ValveCylinder => {
                let foreign = servo_key_given(d)
                    .or_else(|| output_key_given(d))
                    .or_else(|| analog_key_given(d).filter(|k| *k != "ready_delay"));
                if let Some(k) = foreign {
                    return Err(at(k, Problem::NotForKind("sim_servo or sim_analog_drive")));
                }
                let params = super::hydraulic::valve_cylinder(d).map_err(|(k, p)| {
                    // The device's own keys; the rest are `[devices.<name>.cylinder]`'s.
                    if ["ready_delay", "load", "pressure_range", "valve_input"].contains(&k) {
                        at(k, p)
                    } else {
                        cx.at_or_table(&["devices", name, "cylinder", k], p)
                    }
                })?;
                DeviceKind::SimValveCylinder(params)
            }
            Kind::Servo => {
                if let Some(k) = output_key_given(d).or_else(|| analog_key_given(d)) {
                    return Err(at(k, Problem::NotForKind("sim_servo")));
                }
                let params = servo_params(d, nodes[node].cycle_ns).map_err(|(k, p)| at(k, p))?;
                SimServo::new(params).map_err(|e| {
                    cx.at_or_table(
                        &["devices", name, servo_key(e.field)],
                        Problem::Servo(Box::new(e)),
                    )
                })?;
                DeviceKind::SimServo(params)
            }
            Kind::DigitalOutput => {
                if let Some(k) = (servo_key_given(d).or_else(|| analog_key_given(d)))
                    .or_else(|| value_key_given(d))
                {
                    return Err(at(k, Problem::NotForKind("sim_digital_output")));
                }
                DeviceKind::SimDigitalOutput(
                    output_params(d).map_err(|(k, p)| cx.at_or_table(&["devices", name, k], p))?,
                )
            }
            Kind::Analog => {
                if let Some(k) = servo_key_given(d).or_else(|| output_key_given(d)) {
                    return Err(at(k, Problem::NotForKind("sim_analog_drive")));
                }
                let params = analog_device_params(d);
                params.validate().map_err(|e| {
                    cx.at_or_table(
                        &["devices", name, e.field],
                        Problem::Invalid(e.problem.text()),
                    )
                })?;
                DeviceKind::SimAnalogDrive(params)
            }
            Kind::DigitalInput => {
                if let Some(k) = (servo_key_given(d).or_else(|| analog_key_given(d)))
                    .or_else(|| value_key_given(d))
                {
                    return Err(at(k, Problem::NotForKind("sim_digital_input")));
                }
                // The same keys as an output terminal: `channels` and `timestamped`.
                let p =
                    output_params(d).map_err(|(k, p)| cx.at_or_table(&["devices", name, k], p))?;
                DeviceKind::SimDigitalInput(DigitalInputParams {
                    channels: p.channels,
                    timestamped: p.timestamped,
                })
            }
            k @ (Kind::AnalogInput | Kind::AnalogOutput | Kind::Counter) => {
                value_device(d, k).map_err(|(key, p)| cx.at_or_table(&["devices", name, key], p))?
            }
        };
        out.push(DeviceEntry {
            name: name.clone(),
            node,
            kind,
        });
    }
    Ok(out)
}

/// An analog input or output terminal or a counter terminal (`kind`), its keys checked.
fn value_device(d: &DeviceSection, kind: Kind) -> Result<DeviceKind, super::FieldError> {
    let name = match kind {
        Kind::AnalogInput => "sim_analog_input",
        Kind::AnalogOutput => "sim_analog_output",
        _ => "sim_counter",
    };
    if let Some(k) = value_device_foreign_key(d, kind) {
        return Err((k, Problem::NotForKind(name)));
    }
    Ok(match kind {
        Kind::AnalogInput => DeviceKind::SimAnalogInput(analog_channel_params(d)?),
        Kind::AnalogOutput => DeviceKind::SimAnalogOutput(analog_channel_params(d)?),
        _ => DeviceKind::SimCounter(counter_params(d)?),
    })
}

/// The parameters of a simulated digital output: `channels` (required, 1 to
/// [`MAX_CHANNELS`]) and `timestamped` (default `false`).
fn output_params(d: &DeviceSection) -> Result<DigitalOutputParams, super::FieldError> {
    let channels = channel_count(d)?;
    Ok(DigitalOutputParams {
        channels,
        timestamped: d.timestamped.unwrap_or(false),
    })
}

/// The first key of a digital output given on a servo drive.
fn output_key_given(d: &DeviceSection) -> Option<&'static str> {
    if d.channels.is_some() {
        Some("channels")
    } else if d.timestamped.is_some() {
        Some("timestamped")
    } else {
        value_key_given(d)
    }
}

/// The first key of an analog or counter terminal (`range`, `bits`) given on another kind.
fn value_key_given(d: &DeviceSection) -> Option<&'static str> {
    if d.range.is_some() {
        Some("range")
    } else if d.bits.is_some() {
        Some("bits")
    } else {
        None
    }
}

/// A device with value channels (analog terminals, counters) of kind `kind`: the first key
/// it does not have (a servo's, an analog drive's, `timestamped`, and `range` on a counter).
fn value_device_foreign_key(d: &DeviceSection, kind: Kind) -> Option<&'static str> {
    servo_key_given(d)
        .or_else(|| analog_key_given(d))
        .or_else(|| d.timestamped.map(|_| "timestamped"))
        .or_else(|| match kind {
            Kind::Counter => d.range.map(|_| "range"),
            _ => None,
        })
}

/// The parameters of a simulated analog terminal: `channels` (required), `range` (V, finite,
/// > 0, default 10) and `bits` (2 to 24, default 16).
fn analog_channel_params(d: &DeviceSection) -> Result<AnalogChannelParams, super::FieldError> {
    let channels = channel_count(d)?;
    let range = d.range.unwrap_or(ANALOG_RANGE_V);
    if !(range.is_finite() && range > 0.0) {
        return Err((
            "range",
            Problem::Invalid("must be a positive full scale (V)"),
        ));
    }
    let bits = u8::try_from(d.bits.unwrap_or(ANALOG_BITS))
        .ok()
        .filter(|b| (2..=24).contains(b))
        .ok_or((
            "bits",
            Problem::Invalid("must be 2 to 24 (resolution including the sign)"),
        ))?;
    Ok(AnalogChannelParams {
        channels,
        range,
        bits,
    })
}

/// The parameters of a simulated counter terminal: `channels` (required) and `bits` (16 or 32,
/// default 32).
fn counter_params(d: &DeviceSection) -> Result<CounterParams, super::FieldError> {
    let channels = channel_count(d)?;
    let bits = match d.bits.unwrap_or(COUNTER_BITS) {
        16 => 16,
        32 => 32,
        _ => {
            return Err((
                "bits",
                Problem::Invalid("must be 16 or 32 (the register's width)"),
            ))
        }
    };
    Ok(CounterParams { channels, bits })
}

/// `channels` of a device with channels: required, 1 to [`MAX_CHANNELS`].
fn channel_count(d: &DeviceSection) -> Result<u8, super::FieldError> {
    let n = d
        .channels
        .ok_or(("channels", Problem::Missing("channels")))?;
    u8::try_from(n)
        .ok()
        .filter(|n| (1..=MAX_CHANNELS).contains(n))
        .ok_or(("channels", Problem::Invalid("must be 1 to 32")))
}

/// The first key of a servo drive given on another kind of device.
fn servo_key_given(d: &DeviceSection) -> Option<&'static str> {
    [
        (
            "increments_per_revolution",
            d.increments_per_revolution.is_some(),
        ),
        ("rated_torque", d.rated_torque.is_some()),
        ("max_torque", d.max_torque.is_some()),
        ("inertia", d.inertia.is_some()),
        ("viscous_friction", d.viscous_friction.is_some()),
        ("coulomb_friction", d.coulomb_friction.is_some()),
        ("kv", d.kv.is_some()),
        ("velocity_gain", d.velocity_gain.is_some()),
        ("velocity_integral_time", d.velocity_integral_time.is_some()),
        (
            "quick_stop_deceleration",
            d.quick_stop_deceleration.is_some(),
        ),
        ("quick_stop_option", d.quick_stop_option.is_some()),
        ("following_error_window", d.following_error_window.is_some()),
        ("zero_pulse_offset", d.zero_pulse_offset.is_some()),
    ]
    .into_iter()
    .find(|(_, given)| *given)
    .map(|(k, _)| k)
}

/// The first key of a simulated analog drive given on another kind of device.
fn analog_key_given(d: &DeviceSection) -> Option<&'static str> {
    [
        ("reference_speed", d.reference_speed.is_some()),
        ("max_speed", d.max_speed.is_some()),
        ("time_constant", d.time_constant.is_some()),
        ("ramp_down_time", d.ramp_down_time.is_some()),
        ("ready_delay", d.ready_delay.is_some()),
        ("offset", d.offset.is_some()),
    ]
    .into_iter()
    .find(|(_, given)| *given)
    .map(|(k, _)| k)
}

/// The parameters of a simulated analog drive: the section's values over the defaults
/// ([`SimAnalogParams::example`]); checked by the caller. Each field is named as its key.
fn analog_device_params(d: &DeviceSection) -> SimAnalogParams {
    let p = SimAnalogParams::example();
    SimAnalogParams {
        reference_speed: d.reference_speed.unwrap_or(p.reference_speed),
        max_speed: d.max_speed.unwrap_or(p.max_speed),
        time_constant: d.time_constant.unwrap_or(p.time_constant),
        ramp_down_time: d.ramp_down_time.unwrap_or(p.ramp_down_time),
        ready_delay: d.ready_delay.unwrap_or(p.ready_delay),
        offset: d.offset.unwrap_or(p.offset),
        ..p
    }
}

/// The key of `[devices.<name>]` that sets a [`ServoParams`] field.
fn servo_key(field: &'static str) -> &'static str {
    match field {
        "max_torque_per_mille" => "max_torque",
        "velocity_loop_gain" => "velocity_gain",
        "velocity_loop_integral_time" => "velocity_integral_time",
        "cycle_ns" => "node",
        other => other,
    }
}

/// The parameters of a simulated servo: the section's values over the defaults
/// ([`ServoParams::example`] for the node's cycle).
fn servo_params(d: &DeviceSection, cycle_ns: i64) -> Result<ServoParams, super::FieldError> {
    let p = ServoParams::example(cycle_ns);
    let quick_stop_option = match d.quick_stop_option {
        Some(code) => QuickStopOption::try_from(code).map_err(|_| {
            (
                "quick_stop_option",
                Problem::Invalid("must be a 0x605A code, 0 to 8"),
            )
        })?,
        None => p.quick_stop_option,
    };
    Ok(ServoParams {
        cycle_ns,
        increments_per_revolution: d
            .increments_per_revolution
            .unwrap_or(p.increments_per_revolution),
        rated_torque: d.rated_torque.unwrap_or(p.rated_torque),
        max_torque_per_mille: d.max_torque.unwrap_or(p.max_torque_per_mille),
        inertia: d.inertia.unwrap_or(p.inertia),
        viscous_friction: d.viscous_friction.unwrap_or(p.viscous_friction),
        coulomb_friction: d.coulomb_friction.unwrap_or(p.coulomb_friction),
        kv: d.kv.unwrap_or(p.kv),
        velocity_loop_gain: d.velocity_gain.unwrap_or(p.velocity_loop_gain),
        velocity_loop_integral_time: d
            .velocity_integral_time
            .unwrap_or(p.velocity_loop_integral_time),
        quick_stop_deceleration: d
            .quick_stop_deceleration
            .unwrap_or(p.quick_stop_deceleration),
        quick_stop_option,
        following_error_window: d.following_error_window.unwrap_or(p.following_error_window),
        zero_pulse_offset: d.zero_pulse_offset.unwrap_or(p.zero_pulse_offset),
        ..p
    })
}

/// `[axes.<name>.drive]` of every axis: the simulated drive, or a CiA 402 or analog drive of the
/// axis's node, bound to one axis only, with its encoder and mechanics.
pub(super) fn drives(
    cx: Ctx<'_>,
    raw: &CellFile,
    axes: &mut [AxisEntry],
    devices: &[DeviceEntry],
    dir: Option<&std::path::Path>,
) -> Result<(), ConfigError> {
    let mut taken: Vec<Option<usize>> = vec![None; devices.len()];
    for (i, (entry, (name, a))) in axes.iter_mut().zip(raw.axes.iter()).enumerate() {
        let at = |key: &[&str], p: Problem| {
            let mut path = vec!["axes", name.as_str()];
            path.extend_from_slice(key);
            cx.at_or_table(&path, p)
        };
        let ty = pick("drive.type", &a.drive.kind, &DRIVE_TYPES)
            .map_err(|(_, p)| at(&["drive", "type"], p))?;
        if ty == DriveType::Simulation {
            only_with_a_drive(a).map_err(|k| at(k, Problem::OnlyWithDrive))?;
            continue;
        }
        if ty == DriveType::Cia402 {
            if let Some(k) = analog_drive_key_given(a) {
                return Err(at(k, Problem::Invalid("only for `type = \"analog\"`")));
            }
        }
        if ty == DriveType::Analog {
            if let Some(k) = cia402_drive_key_given(a) {
                return Err(at(k, Problem::Invalid("only for `type = \"cia402\"`")));
            }
        }
        if a.virtual_axis {
            return Err(at(&["virtual"], Problem::VirtualWithDrive));
        }
        let want = match ty {
            DriveType::Analog if a.kind == super::hydraulic::HYDRAULIC_KIND => Wanted {
                needs: "a valve (`sim_valve_cylinder`) or an analog drive (`sim_analog_drive`)",
                kind_ok: |k| {
                    matches!(
                        k,
                        DeviceKind::SimAnalogDrive(_) | DeviceKind::SimValveCylinder(_)
                    )
                },
            },
            DriveType::Analog => Wanted {
                needs: "an analog drive (`sim_analog_drive`)",
                kind_ok: |k| matches!(k, DeviceKind::SimAnalogDrive(_)),
            },
            _ => Wanted {
                needs: "a drive (`sim_servo` or an EtherCAT `cia402` SubDevice)",
                kind_ok: |k| matches!(k, DeviceKind::SimServo(_) | DeviceKind::EthercatCia402(_)),
            },
        };
        let bound = Bound {
            raw,
            devices,
            taken: &taken,
        };
        let k = bound.device(a, entry, want, &at)?;
        taken[k] = Some(i);
        let timeout = a.drive.enable_timeout.unwrap_or(ENABLE_TIMEOUT_S);
        if !(timeout.is_finite() && timeout > 0.0 && timeout <= 60.0) {
            return Err(at(
                &["drive", "enable_timeout"],
                Problem::Invalid("must be greater than 0 and at most 60 s"),
            ));
        }
        let enable_timeout_ns = (timeout * 1e9).round() as i64;
        if let EncoderSpec::Table(t) = &a.encoder {
            pick("encoder.mounting", &t.mounting, &MOUNTINGS)
                .map_err(|(_, p)| at(&["encoder", "mounting"], p))?;
        }
        let cycle_ns = (entry.config.cycle * 1e9).round() as i64;
        if let Some(c) = connection(
            a,
            &devices[k].kind,
            DeviceIndex(k),
            (cycle_ns, enable_timeout_ns),
            &at,
        )? {
            entry.drive = c;
        }
        if let (DriveConnection::Analog(c), Some(h)) = (&mut entry.drive, &a.hydraulic) {
            if c.hydraulic.is_some() {
                c.characteristic_curve = super::hydraulic::characteristic_curve(h, dir)
                    .map_err(|(k, p)| at(&["hydraulic", k], p))?;
            }
        }
    }
    Ok(())
}

/// The drive connection of axis section `a` on device `device` (of kind `kind`), with its
/// cycle and enable timeout (ns); `None` for a device that is no drive (refused before, by
/// `Bound::device`).
fn connection(
    a: &AxisSection,
    kind: &DeviceKind,
    device: DeviceIndex,
    (cycle_ns, enable_timeout_ns): (i64, i64),
    at: &dyn Fn(&[&str], Problem) -> ConfigError,
) -> Result<Option<DriveConnection>, ConfigError> {
    Ok(Some(match kind {
        DeviceKind::SimAnalogDrive(_) | DeviceKind::SimValveCylinder(_) => {
            let hydraulic = hydraulic_controller(a, kind, at)?;
            let pressure = match (&a.hydraulic, hydraulic.is_some()) {
                (Some(h), true) => super::hydraulic::pressure_inputs(h)
                    .map_err(|(k, p)| at(&["hydraulic", k], p))?,
                _ => None,
            };
            let params = analog_params(a, cycle_ns, enable_timeout_ns, at)?;
            DriveConnection::Analog(Box::new(AnalogDriveConnection {
                device,
                params,
                hydraulic,
                pressure,
                characteristic_curve: None,
            }))
        }
        DeviceKind::SimServo(servo) => {
            let steps = servo.increments_per_revolution;
            let scaling = scaling(a, steps, Some(steps))
                .map_err(|(key, e)| at(&key, Problem::Mechanics(Box::new(e))))?;
            let inertia = a.drive.inertia.unwrap_or(servo.inertia);
            if !(inertia.is_finite() && inertia > 0.0) {
                return Err(at(
                    &["drive", "inertia"],
                    Problem::Invalid("must be a positive moment of inertia (kg·m²)"),
                ));
            }
            DriveConnection::Cia402(Box::new(Cia402Connection {
                device,
                enable_timeout_ns,
                scaling,
                torque_precontrol_inertia: a
                    .drive
                    .torque_precontrol
                    .unwrap_or(false)
                    .then_some(inertia),
            }))
        }
        DeviceKind::EthercatCia402(p) => {
            if a.drive.torque_precontrol.is_some() || a.drive.inertia.is_some() {
                let key = if a.drive.torque_precontrol.is_some() {
                    "torque_precontrol"
                } else {
                    "inertia"
                };
                return Err(at(
                    &["drive", key],
                    Problem::Invalid(
                        "not for a drive on an EtherCAT segment (its PDO has no torque offset 0x60B2)",
                    ),
                ));
            }
            let steps = p.increments_per_revolution;
            let scaling = scaling(a, steps, Some(steps))
                .map_err(|(key, e)| at(&key, Problem::Mechanics(Box::new(e))))?;
            DriveConnection::Cia402(Box::new(Cia402Connection {
                device,
                enable_timeout_ns,
                scaling,
                torque_precontrol_inertia: None,
            }))
        }
        DeviceKind::EthercatDio
        | DeviceKind::EthercatDioInputs
        | DeviceKind::EthercatAio
        | DeviceKind::EthercatAioInputs
        | DeviceKind::EthercatEnc
        | DeviceKind::SimDigitalOutput(_)
        | DeviceKind::SimDigitalInput(_)
        | DeviceKind::SimAnalogInput(_)
        | DeviceKind::SimAnalogOutput(_)
        | DeviceKind::SimCounter(_) => return Ok(None),
    }))
}

/// The kind of device a drive type needs.
#[derive(Copy, Clone)]
struct Wanted {
    /// In words, for the error.
    needs: &'static str,
    /// Whether a device is of that kind.
    kind_ok: fn(&DeviceKind) -> bool,
}

/// The devices and the axes they are bound to so far.
struct Bound<'a> {
    raw: &'a CellFile,
    devices: &'a [DeviceEntry],
    /// Per device, the axis bound to it.
    taken: &'a [Option<usize>],
}

impl Bound<'_> {
    /// The device `[axes.<name>.drive] device` of axis `a` names: known, of the kind `want`,
    /// on the axis's node, not bound to another axis.
    fn device(
        &self,
        a: &AxisSection,
        entry: &AxisEntry,
        want: Wanted,
        at: &dyn Fn(&[&str], Problem) -> ConfigError,
    ) -> Result<usize, ConfigError> {
        let (raw, devices, taken) = (self.raw, self.devices, self.taken);
        let (needs, kind_ok) = (want.needs, want.kind_ok);
        let dev_name = a
            .drive
            .device
            .as_deref()
            .ok_or_else(|| at(&["drive"], Problem::Missing("device")))?;
        let k = devices
            .iter()
            .position(|d| d.name == dev_name)
            .ok_or_else(|| {
                let known = devices.iter().map(|d| d.name.clone()).collect();
                at(
                    &["drive", "device"],
                    Problem::Unknown {
                        what: "device",
                        name: dev_name.into(),
                        known: Some(known),
                    },
                )
            })?;
        let dev = &devices[k];
        if !kind_ok(&dev.kind) {
            return Err(at(
                &["drive", "device"],
                Problem::DeviceKind {
                    device: dev.name.clone(),
                    kind: dev.kind.name(),
                    needs,
                },
            ));
        }
        if dev.node != entry.node {
            return Err(at(
                &["drive", "device"],
                Problem::DeviceNode {
                    device: dev.name.clone(),
                    axis_node: entry.node,
                    device_node: dev.node,
                },
            ));
        }
        if let Some(other) = taken.get(k).copied().flatten() {
            return Err(at(
                &["drive", "device"],
                Problem::DeviceTaken {
                    device: dev.name.clone(),
                    axis: raw.axes.keys().nth(other).cloned().unwrap_or_default(),
                },
            ));
        }
        Ok(k)
    }
}

/// The first key of an analog drive connection given on another type: its key path.
fn analog_drive_key_given(a: &AxisSection) -> Option<&'static [&'static str]> {
    if a.drive.reference_velocity.is_some() {
        Some(&["drive", "reference_velocity"])
    } else if a.drive.ready.is_some() {
        Some(&["drive", "ready"])
    } else if a.drive.t_addptc.is_some() {
        Some(&["drive", "t_addptc"])
    } else {
        None
    }
}

/// The first key of a CiA 402 drive connection (torque precontrol) given on another type: its
/// key path.
fn cia402_drive_key_given(a: &AxisSection) -> Option<&'static [&'static str]> {
    if a.drive.torque_precontrol.is_some() {
        Some(&["drive", "torque_precontrol"])
    } else if a.drive.inertia.is_some() {
        Some(&["drive", "inertia"])
    } else {
        None
    }
}

/// The analog drive connection of axis `a` on a node of cycle `cycle_ns`: its position
/// controller (`kv`, `kpc`, `t_vtc`, `t_addptc`, `reference_velocity`), the ready input, and
/// its encoder, which must be given as a table (`[axes.<name>.encoder]`, with
/// `steps_per_revolution`: the drive has no encoder of its own) and be incremental. An error
/// names the key.
fn analog_params(
    a: &AxisSection,
    cycle_ns: i64,
    enable_timeout_ns: i64,
    at: &dyn Fn(&[&str], Problem) -> ConfigError,
) -> Result<AnalogParams, ConfigError> {
    let d = &a.drive;
    // A hydraulic axis' reference velocity is its `fRefVelo`.
    let hydraulic_ref = a
        .hydraulic
        .as_ref()
        .and_then(|h| h.fRefVelo)
        .filter(|_| a.kind == super::hydraulic::HYDRAULIC_KIND);
    let reference_velocity = d
        .reference_velocity
        .or(hydraulic_ref)
        .ok_or_else(|| at(&["drive"], Problem::Missing("reference_velocity")))?;
    let controller = ControllerParams {
        cycle_ns,
        kv: d.kv,
        kpc_percent: d.kpc,
        velocity_time_constant: d.t_vtc,
        additional_position_time_constant: d.t_addptc.unwrap_or(0.0),
        reference_velocity,
    };
    controller.validate().map_err(|e: AnalogParamsError| {
        let problem = Problem::Invalid(e.problem.text());
        match e.field {
            "kpc_percent" => at(&["drive", "kpc"], problem),
            "velocity_time_constant" => at(&["drive", "t_vtc"], problem),
            "additional_position_time_constant" => at(&["drive", "t_addptc"], problem),
            "cycle_ns" => at(&["node"], problem),
            other => at(&["drive", other], problem),
        }
    })?;
    let EncoderSpec::Table(t) = &a.encoder else {
        return Err(at(
            &["encoder"],
            Problem::Missing("[axes.<name>.encoder] steps_per_revolution"),
        ));
    };
    let steps = t
        .steps_per_revolution
        .ok_or_else(|| at(&["encoder"], Problem::Missing("steps_per_revolution")))?;
    if t.encoder_kind() != EncoderKind::Incremental {
        return Err(at(
            &["encoder", "type"],
            Problem::Invalid("an analog drive's encoder is incremental (absolute: not yet)"),
        ));
    }
    let scaling =
        scaling(a, steps, None).map_err(|(key, e)| at(&key, Problem::Mechanics(Box::new(e))))?;
    Ok(AnalogParams {
        controller,
        enable_timeout_ns,
        ready: d.ready.unwrap_or(true),
        scaling,
    })
}

/// The position controller and Finish of a hydraulic axis on an analog output (`None` for an
/// electric axis); a `sim_valve_cylinder` drives only a hydraulic axis.
fn hydraulic_controller(
    a: &AxisSection,
    kind: &DeviceKind,
    at: &dyn Fn(&[&str], Problem) -> ConfigError,
) -> Result<Option<HydControllerParams>, ConfigError> {
    if a.kind != super::hydraulic::HYDRAULIC_KIND {
        if matches!(kind, DeviceKind::SimValveCylinder(_)) {
            return Err(at(
                &["drive", "device"],
                Problem::Invalid("a `sim_valve_cylinder` drives an axis of `kind = \"hydraulic\"`"),
            ));
        }
        return Ok(None);
    }
    let section = a.hydraulic.as_ref();
    let default = HydraulicSection::default();
    super::hydraulic::controller(section.unwrap_or(&default))
        .map(Some)
        .map_err(|(k, p)| at(&["hydraulic", k], p))
}

/// On a simulated drive the keys of a drive of the process image are refused: the key path of
/// the first one given.
fn only_with_a_drive(a: &AxisSection) -> Result<(), &'static [&'static str]> {
    if a.drive.device.is_some() {
        return Err(&["drive", "device"]);
    }
    if a.drive.enable_timeout.is_some() {
        return Err(&["drive", "enable_timeout"]);
    }
    if let Some(k) = analog_drive_key_given(a) {
        return Err(k);
    }
    if let Some(k) = cia402_drive_key_given(a) {
        return Err(k);
    }
    if matches!(a.encoder, EncoderSpec::Table(_)) {
        return Err(&["encoder"]);
    }
    if a.mechanics.is_some() {
        return Err(&["mechanics"]);
    }
    Ok(())
}

/// The axis's encoder and mechanics, validated: `steps` per revolution unless the encoder
/// table gives them, and the drive's position increments per motor revolution
/// (`drive_increments`, a CiA 402 drive's; `None` for an analog drive). An error names the key.
fn scaling(
    a: &AxisSection,
    steps: u32,
    drive_increments: Option<u32>,
) -> Result<Scaling, (Vec<&'static str>, MechanicsError)> {
    let default_table;
    let table = match &a.encoder {
        EncoderSpec::Table(t) => t,
        EncoderSpec::Type(kind) => {
            default_table = EncoderTable::of_drive(kind);
            &default_table
        }
    };
    let kind = table.encoder_kind();
    let mounting = match table.mounting.as_str() {
        "load_side" => Mounting::LoadSide,
        "external" => Mounting::External {
            // Checked by `Scaling::new` (finite, > 0); a missing value is refused there too.
            distance_per_revolution: table.distance_per_revolution.unwrap_or(f64::NAN),
        },
        _ => Mounting::MotorShaft,
    };
    let encoder = EncoderConfig {
        kind,
        steps_per_revolution: table.steps_per_revolution.unwrap_or(steps),
        fine_resolution_bits: table.fine_resolution_bits,
        determinable_revolutions: table.determinable_revolutions,
        raw_bits: table.raw_bits,
        inverse: table.inverse,
        mounting,
    };
    let m = a.mechanics.as_ref();
    let mechanics = Mechanics {
        load_gear_numerator: m.map_or(1, |m| m.load_gear[0]),
        load_gear_denominator: m.map_or(1, |m| m.load_gear[1]),
        leadscrew_pitch: m.and_then(|m| m.leadscrew_pitch),
        inverse_drive: m.is_some_and(|m| m.inverse_drive),
        efficiency: m.map_or(1.0, |m| m.efficiency),
        drive_increments_per_revolution: drive_increments,
    };
    Scaling::new(&encoder, &mechanics).map_err(|e| (field_key(e.field), e))
}

/// The key path of a mechanics field under `[axes.<name>]`.
fn field_key(f: MechanicsField) -> Vec<&'static str> {
    let key = match f {
        MechanicsField::StepsPerRevolution => "steps_per_revolution",
        MechanicsField::FineResolutionBits => "fine_resolution_bits",
        MechanicsField::DeterminableRevolutions => "determinable_revolutions",
        MechanicsField::RawBits => "raw_bits",
        MechanicsField::DistancePerRevolution => "distance_per_revolution",
        MechanicsField::LoadGearNumerator | MechanicsField::LoadGearDenominator => {
            return vec!["mechanics", "load_gear"]
        }
        MechanicsField::LeadscrewPitch => return vec!["mechanics", "leadscrew_pitch"],
        MechanicsField::Efficiency => return vec!["mechanics", "efficiency"],
        MechanicsField::DriveIncrementsPerRevolution => return vec!["drive", "device"],
    };
    vec!["encoder", key]
}
