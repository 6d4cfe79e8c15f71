//! The deterministic simulator: every axis of a cell steps at its node's cycle on a virtual
//! clock; script commands are applied between cycles at their times; every signal of every
//! axis is written to CSV every base tick. The same inputs give byte-identical output.

use std::io::{self, Write};
use std::sync::Arc;
use tandem_config::script::{Action, Script};
use tandem_config::{Cell, Coupling, EncoderSource};
use tandem_motion::axis::{Axis, AxisStatus, CamId, Command};
use tandem_motion::cam::{Cam, CamDefinition};
use tandem_motion::encoder::{EncoderStatus, ExternalEncoder};
use tandem_motion::error_id::ErrorId;
use tandem_motion::job::JobEventKind;
use tandem_motion::leading::LeaderId;

/// The per-axis columns of the trace, in order (prefixed with `<axis>.`).
pub const AXIS_COLUMNS: &[&str] = &[
    "state",
    "position",
    "velocity",
    "acceleration",
    "actual_position",
    "actual_velocity",
    "following_error",
    "status_word",
    "error_word",
    "warning_word",
    "alarm",
    "override",
    "job",
];

/// The per-encoder columns of the trace, in order (prefixed with `<encoder>.`).
pub const ENCODER_COLUMNS: &[&str] = &[
    "state",
    "position",
    "velocity",
    "extrapolated_position",
    "extrapolated_velocity",
    "status_word",
];

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// Trace rows written.
    pub rows: u64,
    /// Script commands applied.
    pub commands: usize,
    /// Script commands rejected with an ErrorID.
    pub rejected: usize,
    /// Axes with a pending technology alarm at the end.
    pub axes_in_alarm: usize,
}

fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Formats ns as seconds with 9 decimals, exactly.
pub fn seconds(t_ns: i64) -> String {
    let sign = if t_ns < 0 { "-" } else { "" };
    let t = t_ns.unsigned_abs();
    format!("{sign}{}.{:09}", t / 1_000_000_000, t % 1_000_000_000)
}

fn write_row(
    out: &mut impl Write,
    t_ns: i64,
    status: &[AxisStatus],
    encoders: &[EncoderStatus],
) -> io::Result<()> {
    write!(out, "{}", seconds(t_ns))?;
    for s in status {
        let job = s
            .motion_job
            .or(s.sync_job)
            .map(|(_, i)| i.name())
            .unwrap_or("");
        write!(
            out,
            ",{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.state.name(),
            s.position,
            s.velocity,
            s.acceleration,
            s.actual_position,
            s.actual_velocity,
            s.following_error,
            s.status_word,
            s.error_word,
            s.warning_word,
            s.error_detail.number,
            s.override_velocity,
            job
        )?;
    }
    for e in encoders {
        let state = if e.has(tandem_motion::alarm::status_bit::ENABLE) {
            "Enabled"
        } else {
            "Disabled"
        };
        write!(
            out,
            ",{},{},{},{},{},{}",
            state,
            e.position,
            e.velocity,
            e.extrapolated.position,
            e.extrapolated.velocity,
            e.status_word
        )?;
    }
    writeln!(out)
}

/// MC_InterpolateCam: the definition of `from` interpolated into `cam`, refused while a job
/// holds the cam (16#80AB). In a node this runs off the cyclic path; the swap of the reference is
/// the atomic switch, and running jobs keep the cam they started with.
fn interpolate_cam(
    cell: &Cell,
    cams: &mut [(Arc<Cam>, CamDefinition)],
    cam: CamId,
    from: CamId,
) -> Result<(), ErrorId> {
    let (Ok(c), Ok(f)) = (usize::try_from(cam), usize::try_from(from)) else {
        return Err(ErrorId::IllegalObject);
    };
    let def = cams
        .get(f)
        .map(|x| x.1.clone())
        .ok_or(ErrorId::IllegalObject)?;
    let slot = cams.get_mut(c).ok_or(ErrorId::IllegalObject)?;
    // The table holds one reference (and the cell a second while the cam is the loaded one);
    // any other is a job's.
    let held = 1 + usize::from(
        cell.cams
            .get(c)
            .is_some_and(|x| Arc::ptr_eq(&x.cam, &slot.0)),
    );
    if Arc::strong_count(&slot.0) > held {
        return Err(ErrorId::CamInUse);
    }
    let new = Cam::interpolate(&def).map_err(|e| e.error_id())?;
    *slot = (Arc::new(new), def);
    Ok(())
}

/// Whether `follower` appears in the leader chain of `leader` (a recursive coupling).
fn recursive(axes: &[Axis], follower: usize, leader: usize) -> bool {
    let mut stack = vec![leader];
    let mut seen = vec![false; axes.len()];
    while let Some(i) = stack.pop() {
        if i == follower {
            return true;
        }
        if i >= axes.len() {
            // An external encoder follows nothing.
            continue;
        }
        if std::mem::replace(&mut seen[i], true) {
            continue;
        }
        for l in axes[i].leaders().into_iter().flatten() {
            if let Some(j) = usize::try_from(l).ok().filter(|j| *j < axes.len()) {
                stack.push(j);
            }
        }
    }
    false
}

fn describe(kind: JobEventKind) -> String {
    match kind {
        JobEventKind::Error(e) => format!("Error {e}"),
        JobEventKind::Status(on) => format!("Status {}", if on { "TRUE" } else { "FALSE" }),
        other => format!("{other:?}"),
    }
}

/// Runs `script` on `cell`, writing the CSV trace to `trace` and a log of job events,
/// rejections and alarms to `log`.
pub fn run(
    cell: &Cell,
    script: &Script,
    trace: &mut impl Write,
    log: &mut impl Write,
) -> io::Result<Summary> {
    let mut axes = Vec::with_capacity(cell.axes.len());
    for a in &cell.axes {
        let axis = Axis::new(a.config.clone()).map_err(|e| {
            io::Error::new(io::ErrorKind::InvalidInput, format!("axis {}: {e}", a.name))
        })?;
        axes.push(axis);
    }
    let mut encoders = Vec::with_capacity(cell.encoders.len());
    for e in &cell.encoders {
        let enc = ExternalEncoder::new(e.config).map_err(|x| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("encoder {}: {x}", e.name),
            )
        })?;
        encoders.push(enc);
    }
    let n_axes = axes.len();
    // Axes that lead by actual value run the extrapolation of their actual value.
    for a in &cell.axes {
        for (j, c) in a.leaders.iter().flatten() {
            if *c == Coupling::Actual {
                if let Some(leader) = axes.get_mut(*j) {
                    leader.set_actual_value_output(true);
                }
            }
        }
    }
    // The cams as the jobs see them: MC_InterpolateCam replaces one (a job keeps its own).
    let mut cams: Vec<(Arc<Cam>, CamDefinition)> = cell
        .cams
        .iter()
        .map(|c| (Arc::clone(&c.cam), c.definition.clone()))
        .collect();
    let cycles: Vec<i64> = cell
        .axes
        .iter()
        .map(|a| cell.nodes[a.node].cycle_ns)
        .collect();
    let tick = cycles
        .iter()
        .copied()
        .fold(0, gcd)
        .max(cell.base_tick_ns.max(1));
    let tick = if cycles.iter().all(|c| c % tick == 0) {
        tick
    } else {
        cell.base_tick_ns.max(1)
    };

    write!(trace, "time_s")?;
    for a in &cell.axes {
        for c in AXIS_COLUMNS {
            write!(trace, ",{}.{c}", a.name)?;
        }
    }
    for e in &cell.encoders {
        for c in ENCODER_COLUMNS {
            write!(trace, ",{}.{c}", e.name)?;
        }
    }
    writeln!(trace)?;

    let mut summary = Summary::default();
    let mut next = 0;
    let mut alarms_seen: Vec<Vec<(u16, u16)>> = vec![Vec::new(); axes.len()];
    let mut status: Vec<AxisStatus> = axes.iter().map(|a| *a.status()).collect();
    let mut k: i64 = 0;
    loop {
        let t = k * tick;
        if t > script.duration_ns {
            break;
        }
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let command = match e.action {
                Action::Command(c) => c,
                Action::InterpolateCam { cam, from } => {
                    summary.commands += 1;
                    match interpolate_cam(cell, &mut cams, cam, from) {
                        Ok(()) => {
                            writeln!(log, "t={} {} MC_InterpolateCam: Done", seconds(t), e.axis)?
                        }
                        Err(id) => {
                            summary.rejected += 1;
                            writeln!(
                                log,
                                "t={} {} MC_InterpolateCam rejected: {id} ({})",
                                seconds(t),
                                e.axis,
                                id.description()
                            )?;
                        }
                    }
                    continue;
                }
            };
            if let Some(k) = cell.encoders.iter().position(|x| x.name == e.axis) {
                summary.commands += 1;
                if let Err(id) = encoders[k].command(&command) {
                    summary.rejected += 1;
                    writeln!(
                        log,
                        "t={} {} {} rejected: {id} ({})",
                        seconds(t),
                        e.axis,
                        e.instruction,
                        id.description()
                    )?;
                }
                continue;
            }
            let Some(i) = cell.axes.iter().position(|a| a.name == e.axis) else {
                continue;
            };
            summary.commands += 1;
            let master = match command {
                Command::GearIn { master, .. }
                | Command::GearInPos { master, .. }
                | Command::GearInVelocity { master, .. }
                | Command::CamIn { master, .. } => Some(master),
                _ => None,
            };
            if let Command::CamIn { cam, .. } = command {
                // The job takes its own reference to the interpolated cam.
                if let Some((c, _)) = usize::try_from(cam).ok().and_then(|c| cams.get(c)) {
                    axes[i].provide_cam(cam, std::sync::Arc::clone(c));
                }
            }
            let result = match master.and_then(|m| usize::try_from(m).ok()) {
                Some(m) if recursive(&axes, i, m) => Err(ErrorId::RecursiveSyncChain),
                // The leader must be one of the follower's configured leaders.
                Some(m) if cell.axes[i].coupling(m).is_none() => Err(ErrorId::IllegalObject),
                _ => axes[i].command(&command),
            };
            if let Err(id) = result {
                summary.rejected += 1;
                writeln!(
                    log,
                    "t={} {} {} rejected: {id} ({})",
                    seconds(t),
                    e.axis,
                    e.instruction,
                    id.description()
                )?;
            }
        }
        // External encoders first: they lead and follow nothing. An encoder on an axis reads
        // that axis' actual position of the previous cycle (one cycle of acquisition delay).
        for (k, enc) in encoders.iter_mut().enumerate() {
            if t % cell.nodes[cell.encoders[k].node].cycle_ns != 0 {
                continue;
            }
            let (p, v) = match &cell.encoders[k].source {
                EncoderSource::Axis { axis, scale } => {
                    let s = axes[*axis].status();
                    (
                        s.actual_position_unwrapped * scale,
                        s.actual_velocity * scale,
                    )
                }
                EncoderSource::Profile(points) => {
                    EncoderSource::profile_at(points, t as f64 * 1e-9)
                }
            };
            enc.step(t, p, v);
            while let Some(ev) = enc.pop_event() {
                writeln!(
                    log,
                    "t={} {} {} job {}: {}",
                    seconds(ev.time_ns),
                    cell.encoders[k].name,
                    ev.instruction.name(),
                    ev.job,
                    describe(ev.kind)
                )?;
            }
        }
        // Leaders before their followers: an axis steps once every leader it needs has.
        let mut stepped = vec![false; axes.len()];
        for _pass in 0..=axes.len() {
            for i in 0..axes.len() {
                if stepped[i] {
                    continue;
                }
                let needs: [Option<LeaderId>; 2] = axes[i].leaders();
                let ready = needs.iter().flatten().all(|l| {
                    usize::try_from(*l)
                        .ok()
                        .map(|j| j >= axes.len() || stepped[j])
                        .unwrap_or(true)
                });
                if !ready {
                    continue;
                }
                for l in needs.into_iter().flatten() {
                    let lv = usize::try_from(l).ok().and_then(|j| {
                        if j >= n_axes {
                            encoders.get(j - n_axes).and_then(|e| e.leading_value())
                        } else if j < n_axes {
                            Some(match cell.axes[i].coupling(j) {
                                Some(Coupling::Actual) => axes[j].actual_leading_value(),
                                _ => axes[j].setpoint_leading_value(),
                            })
                        } else {
                            None
                        }
                    });
                    axes[i].set_leading_value(l, lv);
                }
                if t % cycles[i] == 0 {
                    axes[i].step(t);
                }
                stepped[i] = true;
            }
        }
        // Not reached only with a coupling loop, which commands cannot create (16#8019): the
        // axis then runs without its leading value and raises "leader missing".
        for (i, axis) in axes.iter_mut().enumerate() {
            if !stepped[i] && t % cycles[i] == 0 {
                axis.step(t);
            }
        }
        for (i, axis) in axes.iter_mut().enumerate() {
            while let Some(ev) = axis.pop_event() {
                writeln!(
                    log,
                    "t={} {} {} job {}: {}",
                    seconds(ev.time_ns),
                    cell.axes[i].name,
                    ev.instruction.name(),
                    ev.job,
                    describe(ev.kind)
                )?;
            }
            let now: Vec<(u16, u16)> = axis
                .alarms()
                .map(|a| (a.id.number(), a.supplement))
                .collect();
            for a in axis.alarms() {
                if !alarms_seen[i].contains(&(a.id.number(), a.supplement)) {
                    writeln!(
                        log,
                        "t={} {} alarm {} (supplement {}, reaction {:?}): {}",
                        seconds(t),
                        cell.axes[i].name,
                        a.id,
                        a.supplement,
                        a.id.reaction(),
                        a.spec().text
                    )?;
                }
            }
            alarms_seen[i] = now;
            status[i] = *axis.status();
        }
        let enc_status: Vec<EncoderStatus> = encoders.iter().map(|e| *e.status()).collect();
        write_row(trace, t, &status, &enc_status)?;
        summary.rows += 1;
        k += 1;
    }
    summary.axes_in_alarm = axes.iter().filter(|a| a.alarms().next().is_some()).count();
    Ok(summary)
}
