//! `[[ethercat]]`: the EtherCAT segment a node drives as its MainDevice, with the SubDevices
//! expected on it in bus order. Each SubDevice becomes a device of the node's process image
//! under its name, so an axis's `[axes.<name>.drive] device` names it as it names a simulated
//! drive.

use super::{line_at, plain_name, Ctx};
use crate::cell::{
    DeviceEntry, DeviceIndex, DeviceKind, EthercatDriveParams, EthercatIdentity, EthercatRole,
    EthercatSegment, EthercatSubDevice, Node,
};
use crate::error::{ConfigError, Problem};
use crate::schema::{CellFile, EthercatSection, SubDeviceSection};

/// The roles by name (room for the timestamped output terminal).
const ROLES: [(&str, EthercatRole); 4] = [
    ("cia402", EthercatRole::Cia402),
    ("dio", EthercatRole::Dio),
    ("aio", EthercatRole::Aio),
    ("enc", EthercatRole::Enc),
];

/// The increments per revolution of a drive without `increments_per_revolution`: 2^20, those
/// of `tandem-ecat-sim`'s drive (a 20-bit motor encoder).
const DEFAULT_INCREMENTS: u32 = 1 << 20;

/// Cycles from a setpoint to its actual value on an EtherCAT drive without `transport_cycles`:
/// the setpoint of the step at `t` goes out with the exchange at `t + cycle`, the drive acts on
/// it until its next exchange, which samples it, and the node reads that sample a cycle later
/// (measured on `tandem-ecat-sim`'s drive, whose inputs are one exchange behind; inferred the
/// same for a drive that samples at SYNC0 before the frame).
const DEFAULT_TRANSPORT_CYCLES: u8 = 4;

/// The longest interface name Linux takes (IFNAMSIZ 16 with the terminating NUL).
const MAX_INTERFACE: usize = 15;

/// The most SubDevices one segment may expect (inferred: far above any machine of one node;
/// bounds the PDI the node allocates).
const MAX_SUBDEVICES: usize = 64;

/// A SubDevice as read: name, identity, role, the name of its inputs device.
type Sub = (String, EthercatIdentity, EthercatRole, Option<String>);

/// A segment as read so far: its node, its interface, its SubDevices.
type Expected = (usize, String, Vec<Sub>);

impl Ctx<'_> {
    /// An error at `key` of `[[ethercat]]` `i`'s SubDevice `j` (the SubDevice's table when
    /// `key` is empty).
    fn in_subdevice(&self, i: usize, j: usize, key: &str, problem: Problem) -> ConfigError {
        let mut path = format!("ethercat[{i}].subdevices[{j}]");
        if !key.is_empty() {
            path.push('.');
            path.push_str(key);
        }
        ConfigError {
            file: self.file.into(),
            line: locate_subdevice(self.src, i, j, key),
            key: path,
            problem: Box::new(problem),
        }
    }
}

/// The 1-based line of `key` in SubDevice `j` of segment `i` (of its table when `key` is
/// absent), best effort.
fn locate_subdevice(src: &str, i: usize, j: usize, key: &str) -> Option<usize> {
    let doc = toml_edit::ImDocument::parse(src).ok()?;
    let seg = doc.get("ethercat")?.as_array_of_tables()?.get(i)?;
    let sub = seg.get("subdevices")?;
    let table = match sub.as_array_of_tables() {
        Some(a) => a.get(j)?.clone().into_inline_table(),
        None => sub.as_array()?.get(j)?.as_inline_table()?.clone(),
    };
    let span = match table.get_key_value(key) {
        Some((k, _)) if !key.is_empty() => k.span(),
        _ => None,
    }
    .or_else(|| table.span())
    .or_else(|| sub.span())?;
    Some(line_at(src, span.start))
}

/// Every `[[ethercat]]` checked; the SubDevices added to `devices` (which stay in name order).
/// Refuses an unknown node, a second segment on one node, an interface name Linux cannot
/// have, a segment without SubDevices, a SubDevice name that is not plain or is taken, an
/// unknown role and `increments_per_revolution` where it does not belong.
pub(super) fn segments(
    cx: Ctx<'_>,
    raw: &CellFile,
    nodes: &[Node],
    mut devices: Vec<DeviceEntry>,
) -> Result<(Vec<DeviceEntry>, Vec<EthercatSegment>), ConfigError> {
    let mut expected: Vec<Expected> = Vec::new();
    for (i, e) in raw.ethercat.iter().enumerate() {
        let node = segment_node(cx, i, e, nodes, &expected)?;
        let mut subs: Vec<Sub> = Vec::new();
        for (j, s) in e.subdevices.iter().enumerate() {
            let taken = name_taken(&devices, &expected, &subs, &s.name);
            let (kind, role, identity) = subdevice(cx, i, j, s, taken)?;
            devices.push(DeviceEntry {
                name: s.name.clone(),
                node,
                kind,
            });
            if let Some(inputs) = &s.inputs {
                let problem = if matches!(role, EthercatRole::Cia402 | EthercatRole::Enc) {
                    Some(Problem::Invalid(
                        "only for `role = \"dio\"` or `role = \"aio\"`",
                    ))
                } else if !plain_name(inputs) {
                    Some(Problem::BadName {
                        what: "device",
                        name: inputs.clone(),
                    })
                } else if name_taken(&devices, &expected, &subs, inputs) {
                    Some(Problem::NameTaken(inputs.clone()))
                } else {
                    None
                };
                if let Some(p) = problem {
                    return Err(cx.in_subdevice(i, j, "inputs", p));
                }
                devices.push(DeviceEntry {
                    name: inputs.clone(),
                    node,
                    kind: if role == EthercatRole::Aio {
                        DeviceKind::EthercatAioInputs
                    } else {
                        DeviceKind::EthercatDioInputs
                    },
                });
            }
            subs.push((s.name.clone(), identity, role, s.inputs.clone()));
        }
        expected.push((node, e.interface.clone(), subs));
    }
    devices.sort_by(|a, b| a.name.cmp(&b.name));
    let index = |name: &str| DeviceIndex(devices.iter().position(|d| d.name == name).unwrap_or(0));
    let segments = expected
        .into_iter()
        .map(|(node, interface, subs)| EthercatSegment {
            node,
            interface,
            subdevices: subs
                .into_iter()
                .map(|(name, identity, role, inputs)| EthercatSubDevice {
                    device: index(&name),
                    inputs: inputs.as_deref().map(index),
                    name,
                    identity,
                    role,
                })
                .collect(),
        })
        .collect();
    Ok((devices, segments))
}

/// Whether `name` is a device's already, or a SubDevice's or its inputs' read so far.
fn name_taken(devices: &[DeviceEntry], expected: &[Expected], subs: &[Sub], name: &str) -> bool {
    devices.iter().any(|d| d.name == name)
        || expected
            .iter()
            .flat_map(|x| x.2.iter())
            .chain(subs.iter())
            .any(|x| x.0 == name || x.3.as_deref() == Some(name))
}

/// Segment `i`'s node (known, without another segment) after checking its interface and that
/// it expects SubDevices.
fn segment_node(
    cx: Ctx<'_>,
    i: usize,
    e: &EthercatSection,
    nodes: &[Node],
    before: &[Expected],
) -> Result<usize, ConfigError> {
    let node = nodes
        .iter()
        .position(|n| n.name == e.node)
        .ok_or_else(|| cx.in_array("ethercat", i, "node", Problem::UnknownNode(e.node.clone())))?;
    if before.iter().any(|b| b.0 == node) {
        return Err(cx.in_array(
            "ethercat",
            i,
            "node",
            Problem::Invalid(
                "a node drives one EtherCAT segment: another [[ethercat]] names this node",
            ),
        ));
    }
    let bad_interface = e.interface.is_empty()
        || e.interface.len() > MAX_INTERFACE
        || e.interface
            .chars()
            .any(|c| c == '/' || c == ':' || c.is_whitespace() || c.is_control());
    if bad_interface {
        return Err(cx.in_array(
            "ethercat",
            i,
            "interface",
            Problem::Invalid(
                "must name a network interface: 1 to 15 characters, without '/', ':' or white space",
            ),
        ));
    }
    if e.subdevices.is_empty() || e.subdevices.len() > MAX_SUBDEVICES {
        return Err(cx.in_array(
            "ethercat",
            i,
            "subdevices",
            Problem::Invalid("must list 1 to 64 expected SubDevices in bus order"),
        ));
    }
    Ok(node)
}

/// SubDevice `j` of segment `i`: its device kind, role and identity.
fn subdevice(
    cx: Ctx<'_>,
    i: usize,
    j: usize,
    s: &SubDeviceSection,
    taken: bool,
) -> Result<(DeviceKind, EthercatRole, EthercatIdentity), ConfigError> {
    if !plain_name(&s.name) {
        return Err(cx.in_subdevice(
            i,
            j,
            "name",
            Problem::BadName {
                what: "device",
                name: s.name.clone(),
            },
        ));
    }
    if taken {
        return Err(cx.in_subdevice(i, j, "name", Problem::NameTaken(s.name.clone())));
    }
    let role =
        super::pick("role", &s.role, &ROLES).map_err(|(k, p)| cx.in_subdevice(i, j, k, p))?;
    let kind = match role {
        EthercatRole::Cia402 => {
            let steps = s.increments_per_revolution.unwrap_or(DEFAULT_INCREMENTS);
            if steps == 0 {
                return Err(cx.in_subdevice(
                    i,
                    j,
                    "increments_per_revolution",
                    Problem::Invalid("must be at least 1"),
                ));
            }
            let transport_cycles = s.transport_cycles.unwrap_or(DEFAULT_TRANSPORT_CYCLES);
            if !(2..=8).contains(&transport_cycles) {
                return Err(cx.in_subdevice(
                    i,
                    j,
                    "transport_cycles",
                    Problem::Invalid("must be from 2 to 8 cycles"),
                ));
            }
            DeviceKind::EthercatCia402(EthercatDriveParams {
                increments_per_revolution: steps,
                transport_cycles,
            })
        }
        EthercatRole::Dio | EthercatRole::Aio | EthercatRole::Enc => {
            let drive_key = if s.increments_per_revolution.is_some() {
                Some("increments_per_revolution")
            } else if s.transport_cycles.is_some() {
                Some("transport_cycles")
            } else {
                None
            };
            if let Some(key) = drive_key {
                return Err(cx.in_subdevice(
                    i,
                    j,
                    key,
                    Problem::Invalid("only for `role = \"cia402\"`"),
                ));
            }
            match role {
                EthercatRole::Aio => DeviceKind::EthercatAio,
                EthercatRole::Enc => DeviceKind::EthercatEnc,
                _ => DeviceKind::EthercatDio,
            }
        }
    };
    let identity = EthercatIdentity {
        vendor: s.identity.vendor,
        product: s.identity.product,
        revision: s.identity.revision,
    };
    Ok((kind, role, identity))
}
