//! `[signals.<name>]`, the `output` of `[[output_cams]]` and `[[cam_tracks]]`, the `input` of
//! `[[measuring_inputs]]` and `[axes.<name>.inputs]`: which channel of which device each named
//! signal is, which object drives an output, and what an input feeds.
//!
//! Bindings refused, each naming the key: an unknown device or a device without channels
//! (`signals.<name>.device`), a channel the device does not have or one already bound to
//! another signal (`signals.<name>.channel`), a sensor on an output or on an axis of another
//! node (`signals.<name>.sensor`), an unknown signal, a signal of another node than the
//! object's axis, an input where an output is needed or the reverse, a signal another object
//! already drives (`<array>[i].output`), a plain input for a measuring input, an input bound
//! twice (`measuring_inputs[i].input`, `axes.<name>.inputs.<switch>`), and a switch given both
//! as a signal and as a simulated position (`axes.<name>.hw_limits.max`, ...).

use super::Ctx;
use crate::cell::{
    AxisEntry, AxisIndex, AxisInputs, CamTrackEntry, DeviceEntry, DeviceIndex, DriveConnection,
    InputBindings, MeasuringInputEntry, Node, OutputCamEntry, SignalDirection, SignalEntry,
    SignalIndex, SignalType,
};
use crate::error::{ConfigError, Problem};
use crate::schema::{CellFile, SensorSection};
use tandem_motion::objects::measuring::MeasuringRoute;

/// `[signals.<name>]`: each signal on an existing channel of a digital input or output device,
/// one signal per channel; an input may have a simulated sensor on an axis of its node.
pub(super) fn signals(
    cx: Ctx<'_>,
    raw: &CellFile,
    devices: &[DeviceEntry],
    axes: &[AxisEntry],
) -> Result<Vec<SignalEntry>, ConfigError> {
    let mut out: Vec<SignalEntry> = Vec::new();
    for (name, s) in &raw.signals {
        let at = |k: &str, p| cx.at(&["signals", name.as_str(), k], p);
        let k = devices
            .iter()
            .position(|d| d.name == s.device)
            .ok_or_else(|| {
                let known = devices.iter().map(|d| d.name.clone()).collect();
                at(
                    "device",
                    Problem::Unknown {
                        what: "device",
                        name: s.device.clone(),
                        known: Some(known),
                    },
                )
            })?;
        let dev = &devices[k];
        let (Some((channels, _, direction)), Some(signal_type)) =
            (dev.kind.channels(), dev.kind.channel_type())
        else {
            let problem = Problem::DeviceKind {
                device: dev.name.clone(),
                kind: dev.kind.name(),
                needs: "a device with channels (`sim_digital_output`, `sim_digital_input`, \
                        `sim_analog_input`, `sim_analog_output`, `sim_counter`, an EtherCAT `dio`, `aio` or `enc`)",
            };
            return Err(at("device", problem));
        };
        if let Some(declared) = &s.signal_type {
            declared_type(declared, signal_type, (name, dev)).map_err(|p| at("type", p))?;
        }
        let channel = u8::try_from(s.channel)
            .ok()
            .filter(|c| (1..=channels).contains(c))
            .ok_or_else(|| {
                let problem = Problem::ChannelRange {
                    device: dev.name.clone(),
                    channel: s.channel,
                    channels,
                };
                at("channel", problem)
            })?;
        if let Some(other) = out
            .iter()
            .find(|x| x.device == DeviceIndex(k) && x.channel == channel)
        {
            let problem = Problem::ChannelTaken {
                device: dev.name.clone(),
                channel,
                signal: other.name.clone(),
            };
            return Err(at("channel", problem));
        }
        let sensor = match &s.sensor {
            None => None,
            Some(_) if !signal_type.is_bool() => {
                let problem = Problem::ChannelType {
                    signal: name.clone(),
                    is: format!("`{}`", signal_type.key()),
                    needs: "a `bool` input to carry a simulated sensor (a mark switches it)".into(),
                };
                return Err(cx.at(&["signals", name.as_str(), "sensor"], problem));
            }
            Some(x) => Some(sensor(cx, name, x, direction, (dev, axes))?),
        };
        out.push(SignalEntry {
            name: name.clone(),
            device: DeviceIndex(k),
            channel,
            signal_type,
            direction,
            sensor,
        });
    }
    Ok(out)
}

/// The signal types `[signals.<name>] type` names.
const SIGNAL_TYPES: [&str; 3] = ["bool", "integer", "float"];

/// `[signals.<name>] type = declared` against the type `has` of its channel on device `dev`:
/// an unknown type, or one the channel does not have (a `float` signal on a digital channel,
/// a `bool` one on an analog channel, ...), is refused.
fn declared_type(
    declared: &str,
    has: SignalType,
    (name, dev): (&str, &DeviceEntry),
) -> Result<(), Problem> {
    if !SIGNAL_TYPES.contains(&declared) {
        return Err(Problem::Unknown {
            what: "signal type",
            name: declared.into(),
            known: Some(SIGNAL_TYPES.iter().map(|t| t.to_string()).collect()),
        });
    }
    if declared == has.key() {
        return Ok(());
    }
    Err(Problem::ChannelType {
        signal: name.into(),
        is: format!(
            "declared `{declared}`, but device `{}` is a `{}` with `{}` channels",
            dev.name,
            dev.kind.name(),
            has.key()
        ),
        needs: format!(
            "a device with `{declared}` channels ({})",
            kinds_of(declared)
        ),
    })
}

/// The device kinds whose channels have signal type `t` (a name of [`SIGNAL_TYPES`]).
fn kinds_of(t: &str) -> &'static str {
    match t {
        "integer" => "`sim_counter`, an EtherCAT `enc`",
        "float" => "`sim_analog_input`, `sim_analog_output`, an EtherCAT `aio`",
        _ => "`sim_digital_input`, `sim_digital_output`",
    }
}

/// A `bool` signal is needed where signal `s` is bound: refused unless it is one.
fn needs_bool(s: &SignalEntry, needs: &str) -> Result<(), Problem> {
    if s.signal_type.is_bool() {
        return Ok(());
    }
    Err(Problem::ChannelType {
        signal: s.name.clone(),
        is: format!("`{}`", s.signal_type.key()),
        needs: format!("a `bool` signal: {needs}"),
    })
}

/// `[signals.<name>.sensor]`: a mark on an axis of the node of the input's device `dev`.
fn sensor(
    cx: Ctx<'_>,
    name: &str,
    x: &SensorSection,
    direction: SignalDirection,
    (dev, axes): (&DeviceEntry, &[AxisEntry]),
) -> Result<crate::cell::SensorEntry, ConfigError> {
    let at = |k: &str, p| cx.at_or_table(&["signals", name, "sensor", k], p);
    if direction == SignalDirection::Output {
        return Err(cx.at(
            &["signals", name, "sensor"],
            Problem::SignalDirection {
                signal: name.into(),
                is: direction.name(),
                needs: "an input to carry a simulated sensor",
            },
        ));
    }
    let axis_name = x.axis.as_deref().ok_or_else(|| {
        cx.at(
            &["signals", name, "sensor"],
            Problem::Missing("axis (the axis whose load carries the mark)"),
        )
    })?;
    let a = axes
        .iter()
        .position(|a| a.name == axis_name)
        .ok_or_else(|| {
            at(
                "axis",
                Problem::Unknown {
                    what: "axis",
                    name: axis_name.into(),
                    known: Some(axes.iter().map(|a| a.name.clone()).collect()),
                },
            )
        })?;
    if axes[a].node != dev.node {
        return Err(at(
            "axis",
            Problem::SensorNode {
                sensor_axis: axis_name.into(),
                axis: format!("the device `{}`", dev.name),
            },
        ));
    }
    super::objects::mark(x, AxisIndex(a)).map_err(|(k, p)| {
        let key = k.strip_prefix("sensor.").unwrap_or(k);
        at(key, p)
    })
}

/// What the `output` keys are checked against.
pub(super) struct Bindings<'a> {
    /// The cell's nodes, axes, devices and signals.
    pub(super) nodes: &'a [Node],
    pub(super) axes: &'a [AxisEntry],
    pub(super) devices: &'a [DeviceEntry],
    pub(super) signals: &'a [SignalEntry],
}

impl Bindings<'_> {
    /// The signal named `name` for the object named `object` on axis node `node`, the `output`
    /// of entry `i` of `array`; `by[k]` names the object already driving signal `k`.
    fn bind(
        &self,
        cx: Ctx<'_>,
        (array, i): (&str, usize),
        (object, node): (&str, usize),
        name: &str,
        by: &mut [Option<String>],
    ) -> Result<SignalIndex, ConfigError> {
        let at = |p| cx.in_array(array, i, "output", p);
        let k = self
            .signals
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| {
                at(Problem::Unknown {
                    what: "signal",
                    name: name.into(),
                    known: Some(self.signals.iter().map(|s| s.name.clone()).collect()),
                })
            })?;
        let device_node = self
            .signals
            .get(k)
            .and_then(|s| self.devices.get(s.device.0))
            .map_or(node, |d| d.node);
        if device_node != node {
            let node_name = |n: usize| self.nodes.get(n).map(|x| x.name.clone());
            return Err(at(Problem::SignalNode {
                signal: name.into(),
                signal_node: node_name(device_node).unwrap_or_default(),
                object_node: node_name(node).unwrap_or_default(),
            }));
        }
        if let Some(x) = self
            .signals
            .get(k)
            .filter(|x| x.direction != SignalDirection::Output)
        {
            return Err(at(Problem::SignalDirection {
                signal: name.into(),
                is: x.direction.name(),
                needs: "an output (a channel of a `sim_digital_output`)",
            }));
        }
        if let Some(x) = self.signals.get(k) {
            needs_bool(x, "an output cam or cam track switches a digital output").map_err(at)?;
        }
        if let Some(Some(other)) = by.get(k) {
            return Err(at(Problem::SignalDriven {
                signal: name.into(),
                by: other.clone(),
            }));
        }
        if let Some(slot) = by.get_mut(k) {
            *slot = Some(object.into());
        }
        Ok(SignalIndex(k))
    }

    /// The node of axis `a`'s entry (0 if the cell does not have it: checked before).
    fn node_of(&self, a: crate::cell::AxisIndex) -> usize {
        self.axes.get(a.0).map_or(0, |x| x.node)
    }
}

/// The `output` of every output cam and cam track: a signal of the object's node that no other
/// object drives.
pub(super) fn outputs(
    cx: Ctx<'_>,
    raw: &CellFile,
    b: &Bindings<'_>,
    output_cams: &mut [OutputCamEntry],
    cam_tracks: &mut [CamTrackEntry],
) -> Result<(), ConfigError> {
    let mut by: Vec<Option<String>> = vec![None; b.signals.len()];
    for (i, (entry, s)) in output_cams.iter_mut().zip(&raw.output_cams).enumerate() {
        if let Some(name) = &s.output {
            let object = (entry.name.as_str(), b.node_of(entry.axis));
            entry.output = Some(b.bind(cx, ("output_cams", i), object, name, &mut by)?);
        }
    }
    for (i, (entry, s)) in cam_tracks.iter_mut().zip(&raw.cam_tracks).enumerate() {
        if let Some(name) = &s.output {
            let object = (entry.name.as_str(), b.node_of(entry.axis));
            entry.output = Some(b.bind(cx, ("cam_tracks", i), object, name, &mut by)?);
        }
    }
    Ok(())
}

/// The `output` of every track of every digital cam switch (`tracks[j].output`): a signal of
/// the object's node that no other object drives (named `<object>.track<n>` as its driver).
pub(super) fn switch_outputs(
    cx: Ctx<'_>,
    raw: &CellFile,
    b: &Bindings<'_>,
    switches: &mut [crate::cell::DigitalCamSwitchEntry],
) -> Result<(), ConfigError> {
    let mut by: Vec<Option<String>> = vec![None; b.signals.len()];
    // The signals output cams and cam tracks drive (checked before): not a second time.
    let driven = raw
        .output_cams
        .iter()
        .filter_map(|c| c.output.as_ref().map(|o| (o, &c.name)))
        .chain(
            raw.cam_tracks
                .iter()
                .filter_map(|c| c.output.as_ref().map(|o| (o, &c.name))),
        );
    for (o, name) in driven {
        if let Some(slot) = b
            .signals
            .iter()
            .position(|s| &s.name == o)
            .and_then(|k| by.get_mut(k))
        {
            *slot = Some(name.clone());
        }
    }
    let a = "digital_cam_switches";
    for (i, (entry, s)) in switches
        .iter_mut()
        .zip(&raw.digital_cam_switches)
        .enumerate()
    {
        let node = b.node_of(entry.axis);
        for (j, (slot, t)) in entry.outputs.iter_mut().zip(&s.tracks).enumerate() {
            let Some(name) = &t.output else {
                continue;
            };
            let object = format!("{}.track{}", entry.name, j + 1);
            let bound = b.bind(cx, (a, i), (&object, node), name, &mut by);
            *slot = Some(bound.map_err(|mut e| {
                e.key = format!("{a}[{i}].tracks[{j}].output");
                e
            })?);
        }
    }
    Ok(())
}

/// Where an input signal is bound, for [`Bindings::input`].
struct InputUse<'k> {
    /// The node the consumer runs on.
    node: usize,
    /// The binding's key, as an error names it and a second binding quotes it.
    key: &'k str,
    /// The consumer needs a timestamped input (a measuring input).
    timestamped: bool,
}

impl Bindings<'_> {
    /// The input signal named `name` for a consumer `u`; `at` locates errors; `by[k]` names
    /// the key already binding signal `k`.
    fn input(
        &self,
        name: &str,
        u: &InputUse<'_>,
        at: &dyn Fn(Problem) -> ConfigError,
        by: &mut [Option<String>],
    ) -> Result<SignalIndex, ConfigError> {
        let k = self
            .signals
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| {
                at(Problem::Unknown {
                    what: "signal",
                    name: name.into(),
                    known: Some(self.signals.iter().map(|s| s.name.clone()).collect()),
                })
            })?;
        let s = &self.signals[k];
        if s.direction != SignalDirection::Input {
            return Err(at(Problem::SignalDirection {
                signal: name.into(),
                is: s.direction.name(),
                needs: "an input (a channel of a `sim_digital_input`)",
            }));
        }
        needs_bool(
            s,
            "a measuring input and an axis's switches take a digital input",
        )
        .map_err(at)?;
        if u.timestamped && s.signal_type != SignalType::TimestampedBool {
            return Err(at(Problem::SignalType {
                signal: name.into(),
                needs: "a timestamped input (`timestamped = true` on its device): a measuring \
                        input takes each edge's time",
            }));
        }
        let device_node = self.devices.get(s.device.0).map_or(u.node, |d| d.node);
        if device_node != u.node {
            let node_name = |n: usize| self.nodes.get(n).map(|x| x.name.clone());
            return Err(at(Problem::SignalNode {
                signal: name.into(),
                signal_node: node_name(device_node).unwrap_or_default(),
                object_node: node_name(u.node).unwrap_or_default(),
            }));
        }
        if let Some(Some(other)) = by.get(k) {
            return Err(at(Problem::InputBound {
                signal: name.into(),
                by: other.clone(),
            }));
        }
        if let Some(slot) = by.get_mut(k) {
            *slot = Some(u.key.into());
        }
        Ok(SignalIndex(k))
    }
}

/// What the input signals feed: the `input` of every measuring input (a timestamped input of
/// its axis's node, route `timer_di`, no sensor of its own) and `[axes.<name>.inputs]` (inputs
/// of the axis's node, on the simulated drive, each switch given once). An input signal is
/// bound at most once. A bound limit switch activates the hardware limit monitoring
/// (`PositionLimits_HW.Active`) unless `[axes.<name>.hw_limits] active = false`.
pub(super) fn inputs(
    cx: Ctx<'_>,
    raw: &CellFile,
    b: &Bindings<'_>,
    measuring: &[MeasuringInputEntry],
) -> Result<InputBindings, ConfigError> {
    let mut by: Vec<Option<String>> = vec![None; b.signals.len()];
    let mut out = InputBindings {
        axes: vec![AxisInputs::default(); b.axes.len()],
        measuring_inputs: vec![None; measuring.len()],
    };
    for (i, (entry, s)) in measuring.iter().zip(&raw.measuring_inputs).enumerate() {
        let Some(name) = &s.input else {
            continue;
        };
        let at = |p| cx.in_array("measuring_inputs", i, "input", p);
        if entry.config.route != MeasuringRoute::TimerDi {
            return Err(at(Problem::Invalid(
                "an input signal is measured on route `timer_di` (a timestamped digital input)",
            )));
        }
        if s.sensor.is_some() {
            let other = format!(
                "`input = \"{name}\"`: the input's edges come from the signal; a simulated \
                 sensor goes on the signal (`[signals.{name}.sensor]`)"
            );
            return Err(cx.in_array("measuring_inputs", i, "sensor", Problem::Conflict { other }));
        }
        let key = format!("measuring_inputs[{i}].input");
        let u = InputUse {
            node: b.node_of(entry.axis),
            key: &key,
            timestamped: true,
        };
        out.measuring_inputs[i] = Some(b.input(name, &u, &at, &mut by)?);
    }
    for (i, (entry, (axis, a))) in b.axes.iter().zip(raw.axes.iter()).enumerate() {
        let Some(t) = &a.inputs else {
            continue;
        };
        out.axes[i] = axis_inputs(cx, b, (axis, a, entry), t, &mut by)?;
    }
    Ok(out)
}

/// A limit switch bound to an input signal activates the axis's hardware limit monitoring
/// (`PositionLimits_HW.Active`) unless its `[axes.<name>.hw_limits]` says otherwise.
pub(super) fn activate_limits(raw: &CellFile, inputs: &InputBindings, axes: &mut [AxisEntry]) {
    for ((entry, a), bound) in axes.iter_mut().zip(raw.axes.values()).zip(&inputs.axes) {
        if (bound.limit_positive.is_some() || bound.limit_negative.is_some())
            && a.hw_limits.is_none()
        {
            entry.config.hw_limits_active = true;
        }
    }
}

/// `[axes.<name>.inputs]` of one axis: each switch an input of the axis's node, given neither
/// by the drive nor as a simulated position.
fn axis_inputs(
    cx: Ctx<'_>,
    b: &Bindings<'_>,
    (axis, a, entry): (&str, &crate::schema::AxisSection, &AxisEntry),
    t: &crate::schema::AxisInputsSection,
    by: &mut [Option<String>],
) -> Result<AxisInputs, ConfigError> {
    if matches!(entry.drive, DriveConnection::Cia402(_)) {
        let other = "`drive.type = \"cia402\"`: the drive's digital inputs (0x60FD) give the \
                     limit switches and the reference cam"
            .to_string();
        return Err(cx.at(&["axes", axis, "inputs"], Problem::Conflict { other }));
    }
    let hw = a.hw_limits.as_ref();
    let simulated = [
        (
            "limit_positive",
            hw.and_then(|h| h.max).map(|_| ["hw_limits", "max"]),
        ),
        (
            "limit_negative",
            hw.and_then(|h| h.min).map(|_| ["hw_limits", "min"]),
        ),
        (
            "reference_cam",
            a.plant.reference_cam.map(|_| ["plant", "reference_cam"]),
        ),
    ];
    let given = [&t.limit_positive, &t.limit_negative, &t.reference_cam];
    let mut bound = [None; 3];
    for (k, ((switch, position), name)) in simulated.iter().zip(given).enumerate() {
        let Some(name) = name else {
            continue;
        };
        if let Some([table, key]) = position {
            let other = format!("`inputs.{switch} = \"{name}\"`: the switch is that input signal");
            return Err(cx.at(&["axes", axis, table, key], Problem::Conflict { other }));
        }
        let key = format!("axes.{axis}.inputs.{switch}");
        let at = |p| cx.at(&["axes", axis, "inputs", switch], p);
        let u = InputUse {
            node: entry.node,
            key: &key,
            timestamped: false,
        };
        bound[k] = Some(b.input(name, &u, &at, by)?);
    }
    Ok(AxisInputs {
        limit_positive: bound[0],
        limit_negative: bound[1],
        reference_cam: bound[2],
    })
}
