//! The names of a cell: every name stands in iceoryx2 service names, Zenoh key expressions,
//! file names and trace column headers, so each is a plain name (1 to 64 letters, digits, `_`
//! or `-`), and a node may not take a name that is a key segment of the protocol at the same
//! place (`tandem/<cell>/lv/...` would otherwise be both a node's keys and the leading values).
//! Checked before anything uses a name, so that `tandem check` refuses what `tandem up` would
//! fail on.

use super::{plain_name, Ctx};
use crate::error::{ConfigError, Problem};
use crate::schema::CellFile;

/// Node names taken by the protocol's keys `tandem/<cell>/<segment>/...` (shared/protocol
/// `keys`): leading values, gateways, clock watches and the hosts' liveliness tokens.
pub(crate) const RESERVED_NODE_NAMES: [&str; 4] = ["lv", "gateway", "clock", "alive"];

/// Checks the cell's name and the names of its axes, encoders, cams, devices, signals and
/// objects (hosts and nodes are checked with their sections), and the reserved node names.
pub(super) fn check(cx: Ctx<'_>, raw: &CellFile) -> Result<(), ConfigError> {
    if !plain_name(&raw.cell.name) {
        return Err(cx.at(&["cell", "name"], bad("cell", &raw.cell.name)));
    }
    let tables = [
        ("axes", "axis", raw.axes.keys().collect::<Vec<_>>()),
        ("encoders", "encoder", raw.encoders.keys().collect()),
        ("cams", "cam", raw.cams.keys().collect()),
        ("devices", "device", raw.devices.keys().collect()),
        ("signals", "signal", raw.signals.keys().collect()),
    ];
    for (table, what, names) in tables {
        if let Some(n) = names.into_iter().find(|n| !plain_name(n)) {
            return Err(cx.at(&[table, n], bad(what, n)));
        }
    }
    let arrays = [
        (
            "output_cams",
            "output cam",
            raw.output_cams.iter().map(|o| &o.name).collect::<Vec<_>>(),
        ),
        (
            "cam_tracks",
            "cam track",
            raw.cam_tracks.iter().map(|o| &o.name).collect(),
        ),
        (
            "measuring_inputs",
            "measuring input",
            raw.measuring_inputs.iter().map(|o| &o.name).collect(),
        ),
        (
            "digital_cam_switches",
            "digital cam switch",
            raw.digital_cam_switches.iter().map(|o| &o.name).collect(),
        ),
    ];
    for (array, what, names) in arrays {
        if let Some((i, n)) = names.into_iter().enumerate().find(|(_, n)| !plain_name(n)) {
            return Err(cx.in_array(array, i, "name", bad(what, n)));
        }
    }
    for (i, n) in raw.nodes.iter().enumerate() {
        if RESERVED_NODE_NAMES.contains(&n.name.as_str()) {
            return Err(cx.in_array(
                "nodes",
                i,
                "name",
                Problem::ReservedName {
                    name: n.name.clone(),
                    reserved: &RESERVED_NODE_NAMES,
                },
            ));
        }
    }
    Ok(())
}

fn bad(what: &'static str, name: &str) -> Problem {
    Problem::BadName {
        what,
        name: name.into(),
    }
}
