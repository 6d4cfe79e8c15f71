//! `[signals.<name>]` and the `output` of `[[output_cams]]` and `[[cam_tracks]]`: which channel
//! of which device each named signal is, and which object drives it.
//!
//! Bindings refused, each naming the key: an unknown device or a device without channels
//! (`signals.<name>.device`), a channel the device does not have or one already bound to
//! another signal (`signals.<name>.channel`), an unknown signal, a signal of another node than
//! the object's axis, or a signal another object already drives (`<array>[i].output`).

use super::Ctx;
use crate::cell::{
    AxisEntry, CamTrackEntry, DeviceEntry, DeviceIndex, DeviceKind, Node, OutputCamEntry,
    SignalEntry, SignalIndex, SignalType,
};
use crate::error::{ConfigError, Problem};
use crate::schema::CellFile;

/// `[signals.<name>]`: each signal on an existing channel of a digital output device, one
/// signal per channel.
pub(super) fn signals(
    cx: Ctx<'_>,
    raw: &CellFile,
    devices: &[DeviceEntry],
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
        let DeviceKind::SimDigitalOutput(p) = &dev.kind else {
            let problem = Problem::DeviceKind {
                device: dev.name.clone(),
                kind: dev.kind.name(),
                needs: "a device with channels (`sim_digital_output`)",
            };
            return Err(at("device", problem));
        };
        let channel = u8::try_from(s.channel)
            .ok()
            .filter(|c| (1..=p.channels).contains(c))
            .ok_or_else(|| {
                let problem = Problem::ChannelRange {
                    device: dev.name.clone(),
                    channel: s.channel,
                    channels: p.channels,
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
        out.push(SignalEntry {
            name: name.clone(),
            device: DeviceIndex(k),
            channel,
            signal_type: if p.timestamped {
                SignalType::TimestampedBool
            } else {
                SignalType::Bool
            },
        });
    }
    Ok(out)
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
