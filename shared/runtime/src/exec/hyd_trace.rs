//! The hydraulic axes' columns of a trace: the signals the Beckhoff TwinCAT PLC Hydraulic
//! Positioning library recommends to record at commissioning ("FAQ #15: Which axis variables
//! should be logged with the Scope?" and 5.8.1 of its commissioning chapter): the generator's
//! state, the target position, the position controller's output `fLagCtrlOutput`, the output
//! `fOutput`, and with pressure inputs `fActPressureA`, `fActPressureB`, `fActForce`. The
//! actual and set positions and velocities (`fActPos`, `fSetPos`, `fActVelo`, `fSetVelo`) are
//! the axis' own columns.

use crate::drives::analog::AnalogDrives;
use std::fmt::Write as _;
use std::io::{self, Write};
use tandem_config::{Cell, DriveConnection};
use tandem_motion::objects::axis::Axis;

/// The columns of each hydraulic axis (prefixed with `<axis>.`): `hyd_state` is the library's
/// `E_TcHydAxState` name (`iTcHydStateConstVeloP`, ...), `target_position` `fTargetPos`,
/// `lag_ctrl_output` `fLagCtrlOutput` in velocity units (the normalised output times
/// `fRefVelo`, as the library shows it), `output` `fOutput` normalised (±1.0 = ±10 V, after
/// Finish and the drive's inversion).
pub const HYDRAULIC_COLUMNS: &[&str] =
    &["hyd_state", "target_position", "lag_ctrl_output", "output"];

/// The columns a hydraulic axis with pressure inputs adds (bar, bar, N).
pub const PRESSURE_COLUMNS: &[&str] = &["pressure_a", "pressure_b", "force"];

/// Each hydraulic axis of `cell`: its index, name, `fRefVelo` and whether it reads pressures.
fn hydraulic_axes(cell: &Cell) -> impl Iterator<Item = (usize, &str, f64, bool)> {
    cell.axes
        .iter()
        .enumerate()
        .filter_map(|(i, a)| match &a.drive {
            DriveConnection::Analog(c) => c
                .hydraulic
                .as_ref()
                .map(|h| (i, a.name.as_str(), h.finish.ref_velo, c.pressure.is_some())),
            _ => None,
        })
}

/// Writes the column names (each prefixed with `,`).
pub(crate) fn header(cell: &Cell, out: &mut impl Write) -> io::Result<()> {
    for (_, name, _, pressure) in hydraulic_axes(cell) {
        for c in HYDRAULIC_COLUMNS {
            write!(out, ",{name}.{c}")?;
        }
        if pressure {
            for c in PRESSURE_COLUMNS {
                write!(out, ",{name}.{c}")?;
            }
        }
    }
    Ok(())
}

/// Appends the columns of the last step to `row` (empty fields for an axis another node runs).
pub(crate) fn row(cell: &Cell, axes: &[Axis], analog: &AnalogDrives, row: &mut String) {
    for (i, _, ref_velo, pressure) in hydraulic_axes(cell) {
        let hyd = axes.get(i).and_then(Axis::hydraulic_status);
        let link = analog.link_status(i);
        match (hyd, link) {
            (Some(h), Some(l)) => {
                // Writing into a String cannot fail.
                let _ = write!(
                    row,
                    ",{},{},{},{}",
                    h.state.name(h.positive),
                    h.target,
                    l.lag_ctrl_output * ref_velo,
                    l.normalized
                );
                if pressure {
                    let a = h.actual.unwrap_or_default();
                    // Writing into a String cannot fail.
                    let _ = write!(row, ",{},{},{}", a.pressure_a, a.pressure_b, a.force);
                }
            }
            _ => {
                let n = HYDRAULIC_COLUMNS.len() + if pressure { PRESSURE_COLUMNS.len() } else { 0 };
                for _ in 0..n {
                    row.push(',');
                }
            }
        }
    }
}
