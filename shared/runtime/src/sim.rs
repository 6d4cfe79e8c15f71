//! The deterministic simulator: every axis of a cell steps at its node's cycle on a virtual
//! clock; script commands are applied between cycles at their times; every signal of every
//! axis is written to CSV every base tick. The same inputs give byte-identical output.

use std::io::{self, Write};
use std::sync::Arc;
use tandem_config::script::{Action, Script};
use tandem_config::{Cell, Coupling, EncoderSource};
use tandem_motion::alarm::AlarmInstance;
use tandem_motion::axis::{Axis, AxisStatus, CamId, Command};
use tandem_motion::cam::{Cam, CamDefinition};
use tandem_motion::cam_track::{CamTrack, CamTrackMode, McCamTrack};
use tandem_motion::encoder::{EncoderStatus, ExternalEncoder};
use tandem_motion::error_id::ErrorId;
use tandem_motion::job::JobEventKind;
use tandem_motion::job::{Instruction, JobId};
use tandem_motion::leading::LeaderId;
use tandem_motion::measuring::{
    AxisMotion, InputEdge, InputEdges, MeasuringInput, MeasuringJobKind, MeasuringState,
    MeasuringWindow, SimulatedSensor,
};
use tandem_motion::output_cam::{
    CamDirection, CamEdges, McOutputCam, OutputCam, OutputCamMode, PositionType,
};
use tandem_motion::profile::State;

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
    objects: &str,
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
    writeln!(out, "{objects}")
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
    Objects::header(cell, trace)?;
    writeln!(trace)?;
    let mut objects = Objects::new(cell)?;
    let has_objects: Vec<bool> = (0..cell.axes.len())
        .map(|i| {
            cell.output_cams.iter().any(|c| c.axis == i)
                || cell.cam_tracks.iter().any(|c| c.axis == i)
                || cell.measuring_inputs.iter().any(|c| c.axis == i)
        })
        .collect();
    // Axes whose cycle motion is needed: those with objects and those that carry a sensor.
    let needs_motion: Vec<bool> = (0..cell.axes.len())
        .map(|i| {
            has_objects[i]
                || cell
                    .measuring_inputs
                    .iter()
                    .any(|m| m.sensor.is_some_and(|s| s.axis == i))
        })
        .collect();
    let mut motions: Vec<Option<CycleMotion>> = (0..cell.axes.len()).map(|_| None).collect();

    let mut summary = Summary::default();
    let mut next = 0;
    let mut alarms_seen: Vec<Vec<(u16, u16)>> = vec![Vec::new(); axes.len()];
    let mut status: Vec<AxisStatus> = axes.iter().map(|a| *a.status()).collect();
    // The status at each axis' previous cycle (the start of its objects' motion).
    let mut last_cycle: Vec<AxisStatus> = status.clone();
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
                Action::OutputCam { .. }
                | Action::CamTrack { .. }
                | Action::MeasuringInput { .. }
                | Action::AbortMeasuringInput
                | Action::ResetObject { .. }
                | Action::InputEdge { .. } => {
                    summary.commands += 1;
                    let applied = objects.apply(cell, &e.axis, e.t_ns, e.action);
                    if applied.is_ok() && matches!(e.action, Action::ResetObject { .. }) {
                        writeln!(log, "t={} {} MC_Reset: Done", seconds(t), e.axis)?;
                    }
                    if let Err(id) = applied {
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
            if let (Ok(_), Command::Home { mode, .. }) = (&result, command) {
                objects.homing_started(cell, i, mode);
            }
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
        // Output cams, cam tracks and measuring inputs: after their axis, every cycle of its
        // node, with the motion of that cycle.
        for (i, m) in motions.iter_mut().enumerate() {
            *m = (t % cycles[i] == 0 && needs_motion[i]).then(|| {
                cycle_motion(
                    &last_cycle[i],
                    &status[i],
                    t - cycles[i],
                    t,
                    cell.axes[i].config.modulo,
                    objects.homing[i],
                )
            });
        }
        for i in 0..axes.len() {
            if t % cycles[i] != 0 {
                continue;
            }
            if has_objects[i] {
                objects.step(cell, i, &motions, log)?;
                if objects.homing[i]
                    && !matches!(status[i].motion_job, Some((_, Instruction::Home)))
                {
                    objects.homing[i] = false;
                }
            }
            last_cycle[i] = status[i];
        }
        // Register corrections: MC_MoveSuperimposed, effective from the next cycle.
        for (a, distance, input) in objects.corrections.drain(..) {
            let command = Command::MoveSuperimposed {
                distance,
                dynamics: tandem_motion::dynamics::Dynamics::DEFAULT,
            };
            summary.commands += 1;
            writeln!(
                log,
                "t={} {} registration: {} MC_MoveSuperimposed distance {}",
                seconds(t),
                cell.measuring_inputs[input].name,
                cell.axes[a].name,
                distance
            )?;
            if let Err(id) = axes[a].command(&command) {
                summary.rejected += 1;
                writeln!(
                    log,
                    "t={} {} MC_MoveSuperimposed rejected: {id} ({})",
                    seconds(t),
                    cell.axes[a].name,
                    id.description()
                )?;
            }
        }
        let enc_status: Vec<EncoderStatus> = encoders.iter().map(|e| *e.status()).collect();
        write_row(trace, t, &status, &enc_status, objects.row())?;
        summary.rows += 1;
        k += 1;
    }
    summary.axes_in_alarm = axes.iter().filter(|a| a.alarms().next().is_some()).count();
    Ok(summary)
}

// ---------------------------------------------------------------------------------------------
// Output cams, cam tracks and measuring inputs
// ---------------------------------------------------------------------------------------------

/// The per-output-cam columns of the trace, in order (prefixed with `<output cam>.`).
pub const OUTPUT_CAM_COLUMNS: &[&str] = &["output", "last_edge_s"];

/// The per-cam-track columns of the trace, in order (prefixed with `<cam track>.`).
pub const CAM_TRACK_COLUMNS: &[&str] = &[
    "output",
    "last_edge_s",
    "single_cam_state",
    "track_position",
];

/// The per-measuring-input columns of the trace, in order (prefixed with `<input>.`).
pub const MEASURING_INPUT_COLUMNS: &[&str] = &[
    "state",
    "measured_value1",
    "measured_value2",
    "counter1",
    "counter2",
    "lost_edge_counter1",
];

/// The FB instance the script's calls come from.
const INSTANCE: u32 = 1;

/// The motion of an axis' setpoint and actual value over its last cycle.
struct CycleMotion {
    setpoint: AxisMotion,
    actual: AxisMotion,
}

/// The motion from `prev` to `now` (continuous positions). A homing jump is detected only
/// while `homing` (an MC_Home job of the axis runs): the part of the position change that the
/// cycle's (p, v, a) samples do not explain is the jump.
fn cycle_motion(
    prev: &AxisStatus,
    now: &AxisStatus,
    t0: i64,
    t1: i64,
    modulo: Option<tandem_motion::modulo::Modulo>,
    homing: bool,
) -> CycleMotion {
    let dt = (t1 - t0) as f64 * 1e-9;
    let build = |s0: State, s1: State, valid: bool| {
        // Exact for constant jerk (a cubic) over the cycle.
        let expected = dt * (s0.v + s1.v) / 2.0 + dt * dt * (s0.a - s1.a) / 12.0;
        let resid = (s1.p - s0.p) - expected;
        let jump = homing && resid.abs() > 1e-6 + 1e-3 * (s1.p - s0.p).abs().max(expected.abs());
        let start = if jump {
            State {
                p: s0.p + resid,
                ..s0
            }
        } else {
            s0
        };
        let m = AxisMotion::new(t0, t1, start, s1)
            .with_modulo(modulo)
            .with_valid(valid);
        if jump {
            m.with_jump(resid)
        } else {
            m
        }
    };
    let enabled = now.has(tandem_motion::alarm::status_bit::ENABLE);
    let setpoint = build(
        State {
            p: prev.position_unwrapped,
            v: prev.velocity,
            a: prev.acceleration,
        },
        State {
            p: now.position_unwrapped,
            v: now.velocity,
            a: now.acceleration,
        },
        enabled,
    );
    // The actual value has no acceleration: the velocity's slope over the cycle at both ends.
    let a = if dt > 0.0 {
        (now.actual_velocity - prev.actual_velocity) / dt
    } else {
        0.0
    };
    let actual = build(
        State {
            p: prev.actual_position_unwrapped,
            v: prev.actual_velocity,
            a,
        },
        State {
            p: now.actual_position_unwrapped,
            v: now.actual_velocity,
            a,
        },
        true,
    );
    CycleMotion { setpoint, actual }
}

/// A measuring input of the simulator: the engine object, its sensor, the scripted edges and
/// what was last logged.
struct SimInput {
    input: MeasuringInput,
    sensor: Option<SimulatedSensor>,
    edges: InputEdges,
    job: Option<JobId>,
    logged: (u32, i64, u32, i64, bool),
}

/// The output cams, cam tracks and measuring inputs of a run.
struct Objects {
    cams: Vec<OutputCam>,
    cam_last_edge: Vec<Option<i64>>,
    tracks: Vec<CamTrack>,
    track_last_edge: Vec<Option<i64>>,
    inputs: Vec<SimInput>,
    /// Per axis: an MC_Home job was started and has not ended.
    homing: Vec<bool>,
    edges: CamEdges,
    row: String,
    /// Register corrections due: (axis, distance, measuring input).
    corrections: Vec<(usize, f64, usize)>,
    /// The alarm last logged per object: output cams, then cam tracks, then measuring inputs.
    alarms: Vec<Option<AlarmInstance>>,
}

/// Logs `now` if it is a new alarm of `name` (and remembers it).
fn log_alarm(
    log: &mut impl Write,
    t: i64,
    name: &str,
    last: &mut Option<AlarmInstance>,
    now: Option<AlarmInstance>,
) -> io::Result<()> {
    if let Some(a) = now.filter(|a| Some(*a) != *last) {
        writeln!(
            log,
            "t={} {name} alarm {} (supplement {}): {}",
            seconds(t),
            a.id,
            a.supplement,
            a.spec().text
        )?;
    }
    *last = now;
    Ok(())
}

fn invalid(what: &str, name: &str, e: impl std::fmt::Display) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, format!("{what} {name}: {e}"))
}

impl Objects {
    fn new(cell: &Cell) -> io::Result<Self> {
        let mut cams = Vec::new();
        for c in &cell.output_cams {
            cams.push(OutputCam::new(c.config).map_err(|e| invalid("output cam", &c.name, e))?);
        }
        let mut tracks = Vec::new();
        for c in &cell.cam_tracks {
            tracks.push(
                CamTrack::new(c.config, c.data).map_err(|e| invalid("cam track", &c.name, e))?,
            );
        }
        let n_objects =
            cell.output_cams.len() + cell.cam_tracks.len() + cell.measuring_inputs.len();
        let mut inputs = Vec::new();
        for m in &cell.measuring_inputs {
            inputs.push(SimInput {
                input: MeasuringInput::new(m.config)
                    .map_err(|e| invalid("measuring input", &m.name, e))?,
                sensor: m.sensor.map(|s| s.sensor()),
                edges: InputEdges::default(),
                job: None,
                logged: (0, 0, 0, 0, false),
            });
        }
        Ok(Self {
            cam_last_edge: vec![None; cams.len()],
            cams,
            track_last_edge: vec![None; tracks.len()],
            tracks,
            inputs,
            homing: vec![false; cell.axes.len()],
            edges: CamEdges::default(),
            row: String::new(),
            corrections: Vec::new(),
            alarms: vec![None; n_objects],
        })
    }

    fn header(cell: &Cell, out: &mut impl Write) -> io::Result<()> {
        for c in &cell.output_cams {
            for col in OUTPUT_CAM_COLUMNS {
                write!(out, ",{}.{col}", c.name)?;
            }
        }
        for c in &cell.cam_tracks {
            for col in CAM_TRACK_COLUMNS {
                write!(out, ",{}.{col}", c.name)?;
            }
        }
        for c in &cell.measuring_inputs {
            for col in MEASURING_INPUT_COLUMNS {
                write!(out, ",{}.{col}", c.name)?;
            }
        }
        Ok(())
    }

    /// Applies a script action addressed to an output cam, cam track or measuring input.
    /// `Err` is an ErrorID to log as a rejection.
    fn apply(
        &mut self,
        cell: &Cell,
        target: &str,
        t_ns: i64,
        action: Action,
    ) -> Result<(), ErrorId> {
        use tandem_motion::measuring::{CyclicMode, MeasuringContext, OneTimeMode};
        match action {
            Action::OutputCam {
                enable,
                on_position,
                off_position,
                duration,
                mode,
                direction,
            } => {
                let i = cell.output_cam(target).ok_or(ErrorId::IllegalObject)?;
                let input = McOutputCam {
                    enable,
                    on_position,
                    off_position,
                    duration,
                    mode: OutputCamMode::from_code(mode)?,
                    direction: CamDirection::from_code(direction)?,
                };
                let fb = self.cams[i].call(INSTANCE, &input);
                if fb.error && fb.error_id != ErrorId::None {
                    return Err(fb.error_id);
                }
                Ok(())
            }
            Action::CamTrack {
                enable,
                mode,
                invert_output,
            } => {
                let i = cell.cam_track(target).ok_or(ErrorId::IllegalObject)?;
                let input = McCamTrack {
                    enable,
                    mode: CamTrackMode::from_code(mode)?,
                    invert_output,
                };
                let fb = self.tracks[i].call(INSTANCE, &input);
                if fb.error && fb.error_id != ErrorId::None {
                    return Err(fb.error_id);
                }
                Ok(())
            }
            Action::MeasuringInput {
                cyclic,
                mode,
                window,
            } => {
                let i = cell.measuring_input(target).ok_or(ErrorId::IllegalObject)?;
                let window = window.map(|(start, end)| MeasuringWindow { start, end });
                let ctx = MeasuringContext {
                    encoder_valid: true,
                    homing_active: self.homing[cell.measuring_inputs[i].axis],
                };
                let m = &mut self.inputs[i];
                let job = if cyclic {
                    m.input
                        .measuring_input_cyclic(CyclicMode::from_code(mode)?, window, ctx)?
                } else {
                    m.input
                        .measuring_input(OneTimeMode::from_code(mode)?, window, ctx)?
                };
                m.job = Some(job);
                m.logged = (0, 0, 0, 0, false);
                Ok(())
            }
            Action::AbortMeasuringInput => {
                let i = cell.measuring_input(target).ok_or(ErrorId::IllegalObject)?;
                self.inputs[i].input.abort_measuring_input()?;
                Ok(())
            }
            Action::InputEdge { rising } => {
                let i = cell.measuring_input(target).ok_or(ErrorId::IllegalObject)?;
                self.inputs[i].edges.push(InputEdge {
                    time_ns: t_ns,
                    rising,
                });
                Ok(())
            }
            Action::ResetObject { restart } => {
                if let Some(i) = cell.output_cam(target) {
                    self.cams[i].reset();
                } else if let Some(i) = cell.cam_track(target) {
                    self.tracks[i].reset();
                } else if let Some(i) = cell.measuring_input(target) {
                    self.inputs[i].input.reset(restart);
                } else {
                    return Err(ErrorId::IllegalObject);
                }
                Ok(())
            }
            Action::Command(_) | Action::InterpolateCam { .. } => Err(ErrorId::IllegalObject),
        }
    }

    /// MC_Home started on axis `axis` with `mode`.
    fn homing_started(&mut self, cell: &Cell, axis: usize, mode: u8) {
        if let Some(h) = self.homing.get_mut(axis) {
            *h = true;
        }
        for (m, e) in self.inputs.iter_mut().zip(&cell.measuring_inputs) {
            if e.axis == axis {
                m.input.axis_homing(mode);
            }
        }
    }

    /// Steps the objects of axis `axis` with the motion of its last cycle, logging edges and
    /// measured values.
    fn step(
        &mut self,
        cell: &Cell,
        axis: usize,
        motions: &[Option<CycleMotion>],
        log: &mut impl Write,
    ) -> io::Result<()> {
        let Some(motion) = motions.get(axis).and_then(Option::as_ref) else {
            return Ok(());
        };
        let pick = |p: PositionType| match p {
            PositionType::Setpoint => &motion.setpoint,
            PositionType::Actual => &motion.actual,
        };
        for (i, c) in cell.output_cams.iter().enumerate() {
            if c.axis != axis {
                continue;
            }
            self.edges.clear();
            self.cams[i].step(pick(c.config.position_type), &mut self.edges);
            if let Some(last) = self.alarms.get_mut(i) {
                log_alarm(
                    log,
                    motion.setpoint.t1_ns,
                    &c.name,
                    last,
                    self.cams[i].status().alarm,
                )?;
            }
            for e in self.edges.as_slice() {
                self.cam_last_edge[i] = Some(e.time_ns);
                writeln!(
                    log,
                    "t={} {} output {}",
                    seconds(e.time_ns),
                    c.name,
                    if e.on { "ON" } else { "OFF" }
                )?;
            }
        }
        for (i, c) in cell.cam_tracks.iter().enumerate() {
            if c.axis != axis {
                continue;
            }
            self.edges.clear();
            self.tracks[i].step(pick(c.config.position_type), &mut self.edges);
            if let Some(last) = self.alarms.get_mut(cell.output_cams.len() + i) {
                log_alarm(
                    log,
                    motion.setpoint.t1_ns,
                    &c.name,
                    last,
                    self.tracks[i].status().alarm,
                )?;
            }
            for e in self.edges.as_slice() {
                self.track_last_edge[i] = Some(e.time_ns);
                writeln!(
                    log,
                    "t={} {} output {} (cam {})",
                    seconds(e.time_ns),
                    c.name,
                    if e.on { "ON" } else { "OFF" },
                    e.cam + 1
                )?;
            }
        }
        for (k, (m, e)) in self
            .inputs
            .iter_mut()
            .zip(&cell.measuring_inputs)
            .enumerate()
        {
            if e.axis != axis {
                continue;
            }
            // A measuring input measures the actual value; its sensor sees the actual value of
            // the axis that carries the mark.
            if let (Some(s), Some(src)) = (
                m.sensor.as_mut(),
                e.sensor
                    .and_then(|x| motions.get(x.axis))
                    .and_then(Option::as_ref),
            ) {
                s.step(&src.actual, &mut m.edges);
            }
            m.input.step(&motion.actual, m.edges.as_slice());
            m.edges.clear();
            let slot = cell.output_cams.len() + cell.cam_tracks.len() + k;
            if let Some(last) = self.alarms.get_mut(slot) {
                log_alarm(
                    log,
                    motion.actual.t1_ns,
                    &e.name,
                    last,
                    m.input.status().alarm,
                )?;
            }
            let Some(job) = m.job else {
                continue;
            };
            let Some(js) = m.input.job_status(job).copied() else {
                continue;
            };
            let (c1, t1, c2, t2, ended) = m.logged;
            let one_time = matches!(js.kind, MeasuringJobKind::OneTime(_));
            // A one-time job counts no captures: a new edge time is a new value.
            if (js.counter1 != c1 || (one_time && js.edge_time1_ns != t1)) && js.edge_time1_ns != 0
            {
                writeln!(
                    log,
                    "t={} {} MeasuredValue1 = {} (counter {})",
                    seconds(js.edge_time1_ns),
                    e.name,
                    js.measured_value1,
                    js.counter1
                )?;
                if let (Some(r), false) = (e.registration, one_time) {
                    let mut error = r.target - js.measured_value1;
                    if let Some(md) = cell.axes[e.axis].config.modulo {
                        error -= md.length * (error / md.length).round();
                    }
                    self.corrections.push((r.axis, r.gain * error, k));
                }
            }
            if (js.counter2 != c2 || (one_time && js.edge_time2_ns != t2)) && js.edge_time2_ns != 0
            {
                writeln!(
                    log,
                    "t={} {} MeasuredValue2 = {} (counter {})",
                    seconds(js.edge_time2_ns),
                    e.name,
                    js.measured_value2,
                    js.counter2
                )?;
            }
            let end = js.done || js.error || js.command_aborted;
            if end && !ended {
                let what = if js.done {
                    "Done".to_string()
                } else if js.error {
                    format!("Error {}", js.error_id)
                } else {
                    "CommandAborted".to_string()
                };
                writeln!(
                    log,
                    "t={} {} {} job {job}: {what}",
                    seconds(motion.actual.t1_ns),
                    e.name,
                    if one_time {
                        "MC_MeasuringInput"
                    } else {
                        "MC_MeasuringInputCyclic"
                    }
                )?;
            }
            m.logged = (
                js.counter1,
                js.edge_time1_ns,
                js.counter2,
                js.edge_time2_ns,
                end,
            );
        }
        Ok(())
    }

    /// The objects' part of a trace row.
    fn row(&mut self) -> &str {
        use std::fmt::Write as _;
        let r = &mut self.row;
        r.clear();
        let last = |x: Option<i64>| x.map(seconds).unwrap_or_default();
        for (c, e) in self.cams.iter().zip(&self.cam_last_edge) {
            let _ = write!(r, ",{},{}", u8::from(c.status().cam_output), last(*e));
        }
        for (c, e) in self.tracks.iter().zip(&self.track_last_edge) {
            let s = c.status();
            let _ = write!(
                r,
                ",{},{},{},{}",
                u8::from(s.track_output),
                last(*e),
                s.single_cam_state,
                s.track_position
            );
        }
        for m in &self.inputs {
            let s = m.input.status();
            let state = match s.state {
                MeasuringState::Inactive => "INACTIVE",
                MeasuringState::WaitingForTrigger => "WAITING_FOR_TRIGGER",
                MeasuringState::TriggerOccurred => "TRIGGER_OCCURRED",
                MeasuringState::MeasuringError => "MEASURING_ERROR",
            };
            let _ = write!(
                r,
                ",{},{},{},{},{},{}",
                state,
                s.measured_value1,
                s.measured_value2,
                s.counter1,
                s.counter2,
                s.lost_edge_counter1
            );
        }
        &self.row
    }
}
