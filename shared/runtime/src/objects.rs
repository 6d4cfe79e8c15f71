//! Output cams, cam tracks and measuring inputs of an executive: stepped after their axis with
//! the motion of its last cycle.

use crate::exec::{Describe, IoNote, Secs, NOTES};
use std::io::{self, Write};
use tandem_config::Cell;
use tandem_motion::catalog::alarm::AlarmInstance;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::profile::State;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::AxisStatus;
use tandem_motion::objects::cam_track::{CamTrack, CamTrackMode, McCamTrack};
use tandem_motion::objects::job::{JobEventKind, JobId};
use tandem_motion::objects::measuring::{
    MeasuringInput, MeasuringJobKind, MeasuringState, MeasuringWindow,
};
use tandem_motion::objects::output_cam::{
    CamDirection, CamEdges, McOutputCam, OutputCam, OutputCamMode, PositionType,
};
use tandem_motion::plant::sensor::{InputEdge, InputEdges, SimulatedSensor};

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
#[derive(Debug)]
pub(crate) struct CycleMotion {
    pub(crate) setpoint: AxisMotion,
    pub(crate) actual: AxisMotion,
}

/// The motion from `prev` to `now` (continuous positions). A homing jump is detected only
/// while `homing` (an MC_Home job of the axis runs): the part of the position change that the
/// cycle's (p, v, a) samples do not explain is the jump.
pub(crate) fn cycle_motion(
    prev: &AxisStatus,
    now: &AxisStatus,
    t0: i64,
    t1: i64,
    modulo: Option<tandem_motion::kinematics::modulo::Modulo>,
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
    let enabled = now.has(tandem_motion::catalog::alarm::status_bit::ENABLE);
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
#[derive(Debug)]
pub(crate) struct SimInput {
    input: MeasuringInput,
    sensor: Option<SimulatedSensor>,
    edges: InputEdges,
    job: Option<JobId>,
    logged: (u32, i64, u32, i64, bool),
}

/// The output cams, cam tracks and measuring inputs of a run.
#[derive(Debug)]
pub(crate) struct Objects {
    pub(crate) cams: Vec<OutputCam>,
    pub(crate) cam_last_edge: Vec<Option<i64>>,
    pub(crate) tracks: Vec<CamTrack>,
    pub(crate) track_last_edge: Vec<Option<i64>>,
    pub(crate) inputs: Vec<SimInput>,
    /// Per axis: an MC_Home job was started and has not ended.
    pub(crate) homing: Vec<bool>,
    pub(crate) edges: CamEdges,
    pub(crate) row: String,
    /// Output edges and measured values of the current step.
    pub(crate) notes: Vec<IoNote>,
    /// Notes dropped (more than [`NOTES`] in one step).
    pub(crate) notes_dropped: u64,
    /// Register corrections due: (axis, distance, measuring input).
    pub(crate) corrections: Vec<(usize, f64, usize)>,
    /// The alarm last logged per object: output cams, then cam tracks, then measuring inputs.
    pub(crate) alarms: Vec<Option<AlarmInstance>>,
}

/// Keeps `n` unless the step already has [`NOTES`] notes.
fn note(notes: &mut Vec<IoNote>, dropped: &mut u64, n: IoNote) {
    if notes.len() < NOTES {
        notes.push(n);
    } else {
        *dropped += 1;
    }
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
            Secs(t),
            a.id,
            a.supplement,
            a.spec().text
        )?;
    }
    *last = now;
    Ok(())
}

pub(crate) fn invalid(what: &str, name: &str, e: impl std::fmt::Display) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, format!("{what} {name}: {e}"))
}

impl Objects {
    pub(crate) fn new(cell: &Cell) -> io::Result<Self> {
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
            corrections: Vec::with_capacity(cell.measuring_inputs.len()),
            notes: Vec::with_capacity(NOTES),
            notes_dropped: 0,
            alarms: vec![None; n_objects],
        })
    }

    pub(crate) fn header(cell: &Cell, out: &mut impl Write) -> io::Result<()> {
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
    pub(crate) fn apply(
        &mut self,
        cell: &Cell,
        target: &str,
        t_ns: i64,
        action: Action,
    ) -> Result<(), ErrorId> {
        use tandem_motion::objects::measuring::{CyclicMode, MeasuringContext, OneTimeMode};
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
    pub(crate) fn homing_started(&mut self, cell: &Cell, axis: usize, mode: u8) {
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
    pub(crate) fn step(
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
                note(
                    &mut self.notes,
                    &mut self.notes_dropped,
                    IoNote {
                        object: i,
                        t_ns: e.time_ns,
                        measured: false,
                        counter: 0,
                        value: f64::from(u8::from(e.on)),
                    },
                );
                writeln!(
                    log,
                    "t={} {} output {}",
                    Secs(e.time_ns),
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
                note(
                    &mut self.notes,
                    &mut self.notes_dropped,
                    IoNote {
                        object: cell.output_cams.len() + i,
                        t_ns: e.time_ns,
                        measured: false,
                        counter: e.cam as u32 + 1,
                        value: f64::from(u8::from(e.on)),
                    },
                );
                writeln!(
                    log,
                    "t={} {} output {} (cam {})",
                    Secs(e.time_ns),
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
                note(
                    &mut self.notes,
                    &mut self.notes_dropped,
                    IoNote {
                        object: cell.output_cams.len() + cell.cam_tracks.len() + k,
                        t_ns: js.edge_time1_ns,
                        measured: true,
                        counter: js.counter1,
                        value: js.measured_value1,
                    },
                );
                writeln!(
                    log,
                    "t={} {} MeasuredValue1 = {} (counter {})",
                    Secs(js.edge_time1_ns),
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
                    Secs(js.edge_time2_ns),
                    e.name,
                    js.measured_value2,
                    js.counter2
                )?;
            }
            let end = js.done || js.error || js.command_aborted;
            if end && !ended {
                let kind = if js.done {
                    JobEventKind::Done
                } else if js.error {
                    JobEventKind::Error(js.error_id)
                } else {
                    JobEventKind::CommandAborted
                };
                writeln!(
                    log,
                    "t={} {} {} job {job}: {}",
                    Secs(motion.actual.t1_ns),
                    e.name,
                    if one_time {
                        "MC_MeasuringInput"
                    } else {
                        "MC_MeasuringInputCyclic"
                    },
                    Describe(kind)
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
    pub(crate) fn row(&mut self) -> &str {
        use std::fmt::Write as _;
        let r = &mut self.row;
        r.clear();
        let last = |x: Option<i64>| x.map(crate::exec::seconds).unwrap_or_default();
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
