//! Output cams, cam tracks, measuring inputs and digital cam switches of an executive: stepped
//! after their axis with the motion of its last cycle.

use crate::error::ExecError;
use crate::notes::{keep, seconds, Describe, IoNote, Secs, NOTES};
use crate::outputs::ObjectEdge;
use std::io::{self, Write};
use tandem_config::{
    AxisIndex, CamTrackEntry, Cell, DigitalCamSwitchEntry, MeasuringInputEntry, OutputCamEntry,
};
use tandem_motion::catalog::alarm::AlarmInstance;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::profile::State;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::AxisStatus;
use tandem_motion::objects::cam_track::{CamTrack, CamTrackMode, McCamTrack};
use tandem_motion::objects::digital_cam_switch::{DigitalCamSwitch, McDigitalCamSwitch};
use tandem_motion::objects::job::{JobEventKind, JobId};
use tandem_motion::objects::measuring::{
    MeasuringInput, MeasuringJobKind, MeasuringState, MeasuringWindow,
};
use tandem_motion::objects::output_cam::{
    CamDirection, CamEdges, McOutputCam, OutputCam, OutputCamMode, PositionType, SwitchingAhead,
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

/// The per-digital-cam-switch columns of the trace, in order (prefixed with `<name>.`):
/// `OutputBits` (bit `n - 1` is track `n`) and `InOperation`.
pub const DIGITAL_CAM_SWITCH_COLUMNS: &[&str] = &["outputs", "in_operation"];

/// The FB instance the script's calls come from.
const INSTANCE: u32 = 1;

/// The motion of an axis' setpoint and actual value over its last cycle.
#[derive(Debug)]
pub(crate) struct CycleMotion {
    pub(crate) setpoint: AxisMotion,
    pub(crate) actual: AxisMotion,
}

impl CycleMotion {
    /// The setpoint or actual motion, as an object's position type says.
    fn of(&self, p: PositionType) -> &AxisMotion {
        match p {
            PositionType::Setpoint => &self.setpoint,
            PositionType::Actual => &self.actual,
        }
    }
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

/// An output cam of the executive, the time of its last edge and, when it drives an output,
/// its look-ahead.
#[derive(Debug)]
pub(crate) struct SimCam {
    cam: OutputCam,
    last_edge: Option<i64>,
    ahead: Option<SwitchingAhead>,
}

/// A cam track of the executive, the time of its last edge and, when it drives an output, its
/// look-ahead.
#[derive(Debug)]
pub(crate) struct SimTrack {
    track: CamTrack,
    last_edge: Option<i64>,
    ahead: Option<SwitchingAhead>,
}

/// An MC_DigitalCamSwitch_BkPlcMc of the executive and its output bits of the last cycle.
#[derive(Debug)]
pub(crate) struct SimSwitch {
    dcs: DigitalCamSwitch,
    bits: u32,
}

/// The motion an object on `position_type` steps with: the cycle's, or, for an object that
/// drives an output, the motion predicted over its look-ahead (its edges are then the times
/// the output switches; see [`crate::outputs`]).
fn switching_motion(
    motion: &CycleMotion,
    position_type: PositionType,
    ahead: Option<SwitchingAhead>,
) -> AxisMotion {
    let m = motion.of(position_type);
    ahead.map_or(*m, |a| a.predict(m))
}

/// A measuring input of the executive: the engine object, its sensor, the scripted edges and
/// what was last logged.
#[derive(Debug)]
pub(crate) struct SimInput {
    input: MeasuringInput,
    sensor: Option<SimulatedSensor>,
    edges: InputEdges,
    job: Option<JobId>,
    logged: (u32, i64, u32, i64, bool),
}

/// What the objects' steps produce besides the log, shared by all objects of a step.
#[derive(Debug)]
pub(crate) struct StepOutput {
    /// The edges of the output cam or cam track being stepped.
    edges: CamEdges,
    /// The output edges of every object stepped since the output stage last took them (room
    /// for one step of every output cam and cam track).
    pub(crate) output_edges: Vec<ObjectEdge>,
    /// Output edges and measured values of the current step.
    pub(crate) notes: Vec<IoNote>,
    /// Notes dropped (more than [`NOTES`] in one step).
    pub(crate) notes_dropped: u64,
    /// Register corrections due: (axis, distance, measuring input).
    pub(crate) corrections: Vec<(AxisIndex, f64, usize)>,
    /// The alarm last logged per object: output cams, then cam tracks, then measuring inputs.
    alarms: Vec<Option<AlarmInstance>>,
}

/// The output cams, cam tracks, measuring inputs and digital cam switches of an executive.
#[derive(Debug)]
pub(crate) struct Objects {
    cams: Vec<SimCam>,
    tracks: Vec<SimTrack>,
    inputs: Vec<SimInput>,
    switches: Vec<SimSwitch>,
    /// Per axis: an MC_Home job was started and has not ended.
    pub(crate) homing: Vec<bool>,
    /// Notes, corrections and alarms of the current step.
    pub(crate) out: StepOutput,
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

/// What an object's report works with: the cell, which object, the motion of the cycle and
/// where its notes and corrections go.
struct Report<'a> {
    cell: &'a Cell,
    /// The object's id in [`IoNote::object`].
    object: usize,
    /// Its index among the objects of its kind.
    index: usize,
    motion: &'a CycleMotion,
    edges: &'a CamEdges,
    notes: &'a mut Vec<IoNote>,
    notes_dropped: &'a mut u64,
    corrections: &'a mut Vec<(AxisIndex, f64, usize)>,
}

impl Report<'_> {
    /// Keeps an I/O note of this object.
    fn note(&mut self, t_ns: i64, measured: bool, counter: u32, value: f64) {
        let object = self.object;
        keep(
            self.notes,
            self.notes_dropped,
            IoNote {
                object,
                t_ns,
                measured,
                counter,
                value,
            },
        );
    }
}

/// One kind of object stepped after its axis with the motion of the axis' cycle: step it, log
/// a new alarm, then report what it did.
trait CycleObject {
    /// Its entry in the cell.
    type Entry;
    /// The axis whose motion it follows.
    fn axis(e: &Self::Entry) -> AxisIndex;
    /// Its name.
    fn name(e: &Self::Entry) -> &str;
    /// Steps it with `motion` (`motions`: every axis' motion of this step; a cam's edges go to
    /// `edges`). Returns the time its alarm is logged at.
    fn step(
        &mut self,
        e: &Self::Entry,
        motion: &CycleMotion,
        motions: &[Option<CycleMotion>],
        edges: &mut CamEdges,
    ) -> i64;
    /// Its pending alarm.
    fn alarm(&self) -> Option<AlarmInstance>;
    /// Reports the step: notes, log lines, register corrections.
    fn report(
        &mut self,
        e: &Self::Entry,
        r: &mut Report<'_>,
        log: &mut impl Write,
    ) -> io::Result<()>;
}

/// The log's word for an output state.
fn on_off(on: bool) -> &'static str {
    if on {
        "ON"
    } else {
        "OFF"
    }
}

impl CycleObject for SimCam {
    type Entry = OutputCamEntry;
    fn axis(e: &OutputCamEntry) -> AxisIndex {
        e.axis
    }
    fn name(e: &OutputCamEntry) -> &str {
        &e.name
    }
    fn step(
        &mut self,
        e: &OutputCamEntry,
        motion: &CycleMotion,
        _: &[Option<CycleMotion>],
        edges: &mut CamEdges,
    ) -> i64 {
        edges.clear();
        let m = switching_motion(motion, e.config.position_type, self.ahead);
        self.cam.step(&m, edges);
        motion.setpoint.t1_ns
    }
    fn alarm(&self) -> Option<AlarmInstance> {
        self.cam.status().alarm
    }
    fn report(
        &mut self,
        e: &OutputCamEntry,
        r: &mut Report<'_>,
        log: &mut impl Write,
    ) -> io::Result<()> {
        for edge in r.edges.as_slice() {
            self.last_edge = Some(edge.time_ns);
            r.note(edge.time_ns, false, 0, f64::from(u8::from(edge.on)));
            writeln!(
                log,
                "t={} {} output {}",
                Secs(edge.time_ns),
                e.name,
                on_off(edge.on)
            )?;
        }
        Ok(())
    }
}

impl CycleObject for SimTrack {
    type Entry = CamTrackEntry;
    fn axis(e: &CamTrackEntry) -> AxisIndex {
        e.axis
    }
    fn name(e: &CamTrackEntry) -> &str {
        &e.name
    }
    fn step(
        &mut self,
        e: &CamTrackEntry,
        motion: &CycleMotion,
        _: &[Option<CycleMotion>],
        edges: &mut CamEdges,
    ) -> i64 {
        edges.clear();
        let m = switching_motion(motion, e.config.position_type, self.ahead);
        self.track.step(&m, edges);
        motion.setpoint.t1_ns
    }
    fn alarm(&self) -> Option<AlarmInstance> {
        self.track.status().alarm
    }
    fn report(
        &mut self,
        e: &CamTrackEntry,
        r: &mut Report<'_>,
        log: &mut impl Write,
    ) -> io::Result<()> {
        for edge in r.edges.as_slice() {
            self.last_edge = Some(edge.time_ns);
            r.note(
                edge.time_ns,
                false,
                edge.cam as u32 + 1,
                f64::from(u8::from(edge.on)),
            );
            writeln!(
                log,
                "t={} {} output {} (cam {})",
                Secs(edge.time_ns),
                e.name,
                on_off(edge.on),
                edge.cam + 1
            )?;
        }
        Ok(())
    }
}

impl CycleObject for SimInput {
    type Entry = MeasuringInputEntry;
    fn axis(e: &MeasuringInputEntry) -> AxisIndex {
        e.axis
    }
    fn name(e: &MeasuringInputEntry) -> &str {
        &e.name
    }
    fn step(
        &mut self,
        e: &MeasuringInputEntry,
        motion: &CycleMotion,
        motions: &[Option<CycleMotion>],
        _: &mut CamEdges,
    ) -> i64 {
        // A measuring input measures the actual value; its sensor sees the actual value of
        // the axis that carries the mark.
        if let (Some(s), Some(src)) = (
            self.sensor.as_mut(),
            e.sensor
                .and_then(|x| motions.get(x.axis.0))
                .and_then(Option::as_ref),
        ) {
            s.step(&src.actual, &mut self.edges);
        }
        self.input.step(&motion.actual, self.edges.as_slice());
        self.edges.clear();
        motion.actual.t1_ns
    }
    fn alarm(&self) -> Option<AlarmInstance> {
        self.input.status().alarm
    }
    fn report(
        &mut self,
        e: &MeasuringInputEntry,
        r: &mut Report<'_>,
        log: &mut impl Write,
    ) -> io::Result<()> {
        let Some(job) = self.job else {
            return Ok(());
        };
        let Some(js) = self.input.job_status(job).copied() else {
            return Ok(());
        };
        let (c1, t1, c2, t2, ended) = self.logged;
        let one_time = matches!(js.kind, MeasuringJobKind::OneTime(_));
        // A one-time job counts no captures: a new edge time is a new value.
        if (js.counter1 != c1 || (one_time && js.edge_time1_ns != t1)) && js.edge_time1_ns != 0 {
            r.note(js.edge_time1_ns, true, js.counter1, js.measured_value1);
            writeln!(
                log,
                "t={} {} MeasuredValue1 = {} (counter {})",
                Secs(js.edge_time1_ns),
                e.name,
                js.measured_value1,
                js.counter1
            )?;
            if let (Some(reg), false) = (e.registration, one_time) {
                let mut error = reg.target - js.measured_value1;
                if let Some(md) = r.cell.axes[e.axis].config.modulo {
                    error -= md.length * (error / md.length).round();
                }
                r.corrections.push((reg.axis, reg.gain * error, r.index));
            }
        }
        if (js.counter2 != c2 || (one_time && js.edge_time2_ns != t2)) && js.edge_time2_ns != 0 {
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
                Secs(r.motion.actual.t1_ns),
                e.name,
                if one_time {
                    "MC_MeasuringInput"
                } else {
                    "MC_MeasuringInputCyclic"
                },
                Describe(kind)
            )?;
        }
        self.logged = (
            js.counter1,
            js.edge_time1_ns,
            js.counter2,
            js.edge_time2_ns,
            end,
        );
        Ok(())
    }
}

impl CycleObject for SimSwitch {
    type Entry = DigitalCamSwitchEntry;
    fn axis(e: &DigitalCamSwitchEntry) -> AxisIndex {
        e.axis
    }
    fn name(e: &DigitalCamSwitchEntry) -> &str {
        &e.name
    }
    /// One evaluation on the actual position and velocity at the end of the cycle. A changed
    /// bit is an edge of its track (`Edge::cam` = track - 1) at the next boundary, `t + T`:
    /// the library's outputs are written by the process image after the cycle that computed
    /// them (no look-ahead, no exact crossing time: its resolution is the cycle).
    fn step(
        &mut self,
        _: &DigitalCamSwitchEntry,
        motion: &CycleMotion,
        _: &[Option<CycleMotion>],
        edges: &mut CamEdges,
    ) -> i64 {
        edges.clear();
        let m = &motion.actual;
        let dt_ns = m.t1_ns - m.t0_ns;
        let bits = self.dcs.step(m.end.p, m.end.v, dt_ns as f64 * 1e-9);
        let changed = bits ^ self.bits;
        self.bits = bits;
        for track in 0..32u8 {
            if changed & (1 << track) != 0 {
                edges.push(tandem_motion::objects::output_cam::Edge {
                    time_ns: m.t1_ns.saturating_add(dt_ns),
                    on: bits & (1 << track) != 0,
                    cam: track,
                });
            }
        }
        m.t1_ns
    }
    fn alarm(&self) -> Option<AlarmInstance> {
        None
    }
    fn report(
        &mut self,
        e: &DigitalCamSwitchEntry,
        r: &mut Report<'_>,
        log: &mut impl Write,
    ) -> io::Result<()> {
        for edge in r.edges.as_slice() {
            writeln!(
                log,
                "t={} {} track {} {}",
                Secs(edge.time_ns),
                e.name,
                edge.cam + 1,
                on_off(edge.on)
            )?;
        }
        Ok(())
    }
}

/// The step of the objects of one axis: the cell, the axis and every axis' motion of its
/// last cycle.
struct AxisCycle<'a> {
    cell: &'a Cell,
    axis: AxisIndex,
    motions: &'a [Option<CycleMotion>],
}

/// The objects of one kind on the axis, in cell order: each is stepped with the axis' motion,
/// logs a new alarm (slot `first + k`) and reports. `first` is the kind's first object id.
fn step_kind<T: CycleObject>(
    c: &AxisCycle<'_>,
    objects: &mut [T],
    entries: &[T::Entry],
    first: usize,
    out: &mut StepOutput,
    log: &mut impl Write,
) -> io::Result<()> {
    let Some(motion) = c.motions.get(c.axis.0).and_then(Option::as_ref) else {
        return Ok(());
    };
    for (k, (o, e)) in objects.iter_mut().zip(entries).enumerate() {
        if T::axis(e) != c.axis {
            continue;
        }
        out.edges.clear();
        let t_alarm = o.step(e, motion, c.motions, &mut out.edges);
        if let Some(last) = out.alarms.get_mut(first + k) {
            log_alarm(log, t_alarm, T::name(e), last, o.alarm())?;
        }
        let mut r = Report {
            cell: c.cell,
            object: first + k,
            index: k,
            motion,
            edges: &out.edges,
            notes: &mut out.notes,
            notes_dropped: &mut out.notes_dropped,
            corrections: &mut out.corrections,
        };
        o.report(e, &mut r, log)?;
        // The edges go to the output stage; there is room for one step of every object.
        for &edge in out.edges.as_slice() {
            if out.output_edges.len() < out.output_edges.capacity() {
                let object = first + k;
                out.output_edges.push(ObjectEdge { object, edge });
            }
        }
    }
    Ok(())
}

/// The error of an object of kind `kind` named `name` that the engine refuses.
fn refused<'n>(
    kind: &'static str,
    name: &'n str,
) -> impl FnOnce(tandem_motion::objects::measuring::MeasuringConfigError) -> ExecError + 'n {
    move |reason| ExecError::Object {
        kind,
        name: name.to_string(),
        reason,
    }
}

impl Objects {
    /// The objects of `cell`, or the first one the engine refuses.
    pub(crate) fn new(cell: &Cell) -> Result<Self, ExecError> {
        let mut cams = Vec::new();
        for c in &cell.output_cams {
            cams.push(SimCam {
                cam: OutputCam::new(c.config).map_err(refused("output cam", &c.name))?,
                last_edge: None,
                ahead: crate::outputs::switching_ahead(
                    cell,
                    c.output,
                    c.config.position_type,
                    &c.config.parameters,
                ),
            });
        }
        let mut tracks = Vec::new();
        for c in &cell.cam_tracks {
            tracks.push(SimTrack {
                track: CamTrack::new(c.config, c.data).map_err(refused("cam track", &c.name))?,
                last_edge: None,
                ahead: crate::outputs::switching_ahead(
                    cell,
                    c.output,
                    c.config.position_type,
                    &c.data.parameters,
                ),
            });
        }
        let n_objects =
            cell.output_cams.len() + cell.cam_tracks.len() + cell.measuring_inputs.len();
        let mut inputs = Vec::new();
        for m in &cell.measuring_inputs {
            // On a drive's touch probe the sensor is a mark in front of the drive's probe
            // input (crate::drives), not evaluated here.
            let on_probe = crate::drives::on_touch_probe(cell, m);
            inputs.push(SimInput {
                input: MeasuringInput::new(m.config)
                    .map_err(refused("measuring input", &m.name))?,
                sensor: m.sensor.filter(|_| !on_probe).map(|s| s.sensor()),
                edges: InputEdges::default(),
                job: None,
                logged: (0, 0, 0, 0, false),
            });
        }
        let mut switches = Vec::new();
        for c in &cell.digital_cam_switches {
            let dcs = DigitalCamSwitch::new(&c.switches, &c.tracks).map_err(|reason| {
                ExecError::CamSwitch {
                    name: c.name.clone(),
                    reason,
                }
            })?;
            switches.push(SimSwitch { dcs, bits: 0 });
        }
        Ok(Self {
            cams,
            tracks,
            inputs,
            switches,
            homing: vec![false; cell.axes.len()],
            out: StepOutput {
                edges: CamEdges::default(),
                output_edges: Vec::with_capacity(
                    (cell.output_cams.len() + cell.cam_tracks.len())
                        * tandem_motion::objects::output_cam::EDGE_CAPACITY
                        + cell.digital_cam_switches.len() * 32,
                ),
                corrections: Vec::with_capacity(cell.measuring_inputs.len()),
                notes: Vec::with_capacity(NOTES),
                notes_dropped: 0,
                alarms: vec![None; n_objects],
            },
        })
    }

    /// Whether measuring input `i` has a job waiting for edges.
    pub(crate) fn measuring(&self, i: usize) -> bool {
        self.inputs
            .get(i)
            .is_some_and(|x| x.input.active_job().is_some())
    }

    /// An edge for measuring input `i` (a drive's touch probe latch), evaluated in its next
    /// step. Dropped (and counted by the input) when its list is full.
    pub(crate) fn push_edge(&mut self, i: usize, edge: InputEdge) {
        if let Some(x) = self.inputs.get_mut(i) {
            x.edges.push(edge);
        }
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
        for c in &cell.digital_cam_switches {
            for col in DIGITAL_CAM_SWITCH_COLUMNS {
                write!(out, ",{}.{col}", c.name)?;
            }
        }
        Ok(())
    }

    /// Applies a script action addressed to an output cam, cam track, measuring input or
    /// digital cam switch.
    /// `Err` is an ErrorID to log as a rejection.
    pub(crate) fn apply(
        &mut self,
        cell: &Cell,
        target: &str,
        t_ns: i64,
        action: Action,
    ) -> Result<(), ErrorId> {
        match action {
            Action::DriveFault { .. }
            | Action::FixedStop { .. }
            | Action::SetInput { .. }
            | Action::SetInputValue { .. }
            | Action::SetOutputValue { .. } => Err(ErrorId::IllegalObject),
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
                let fb = self.cams[i].cam.call(INSTANCE, &input);
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
                let fb = self.tracks[i].track.call(INSTANCE, &input);
                if fb.error && fb.error_id != ErrorId::None {
                    return Err(fb.error_id);
                }
                Ok(())
            }
            Action::MeasuringInput {
                cyclic,
                mode,
                window,
            } => self.measuring_input(cell, target, cyclic, mode, window),
            Action::DigitalCamSwitch {
                enable,
                enable_mask,
            } => {
                let i = cell
                    .digital_cam_switch(target)
                    .ok_or(ErrorId::IllegalObject)?;
                let s = self.switches.get_mut(i).ok_or(ErrorId::IllegalObject)?;
                s.dcs.call(McDigitalCamSwitch {
                    enable,
                    enable_mask,
                });
                // Enable FALSE clears the outputs at once: their edges go with the next step.
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
                    latched: None,
                });
                Ok(())
            }
            Action::ResetObject { restart } => {
                if let Some(i) = cell.output_cam(target) {
                    self.cams[i].cam.reset();
                } else if let Some(i) = cell.cam_track(target) {
                    self.tracks[i].track.reset();
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

    /// MC_MeasuringInput or MC_MeasuringInputCyclic on the measuring input `target`.
    fn measuring_input(
        &mut self,
        cell: &Cell,
        target: &str,
        cyclic: bool,
        mode: i32,
        window: Option<(f64, f64)>,
    ) -> Result<(), ErrorId> {
        use tandem_motion::objects::measuring::{CyclicMode, MeasuringContext, OneTimeMode};
        let i = cell.measuring_input(target).ok_or(ErrorId::IllegalObject)?;
        let window = window.map(|(start, end)| MeasuringWindow { start, end });
        let ctx = MeasuringContext {
            encoder_valid: true,
            homing_active: self.homing[cell.measuring_inputs[i].axis.0],
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

    /// MC_Home started on axis `axis` with `mode`.
    pub(crate) fn homing_started(&mut self, cell: &Cell, axis: AxisIndex, mode: u8) {
        if let Some(h) = self.homing.get_mut(axis.0) {
            *h = true;
        }
        for (m, e) in self.inputs.iter_mut().zip(&cell.measuring_inputs) {
            if e.axis == axis {
                m.input.axis_homing(mode);
            }
        }
    }

    /// Steps the objects of axis `axis` with the motion of its last cycle, logging edges and
    /// measured values: its output cams, then its cam tracks, then its measuring inputs.
    pub(crate) fn step(
        &mut self,
        cell: &Cell,
        axis: AxisIndex,
        motions: &[Option<CycleMotion>],
        log: &mut impl Write,
    ) -> io::Result<()> {
        let c = AxisCycle {
            cell,
            axis,
            motions,
        };
        let out = &mut self.out;
        let n_cams = cell.output_cams.len();
        let first = n_cams + cell.cam_tracks.len();
        step_kind(&c, &mut self.cams, &cell.output_cams, 0, out, log)?;
        step_kind(&c, &mut self.tracks, &cell.cam_tracks, n_cams, out, log)?;
        step_kind(
            &c,
            &mut self.inputs,
            &cell.measuring_inputs,
            first,
            out,
            log,
        )?;
        let first_switch = first + cell.measuring_inputs.len();
        step_kind(
            &c,
            &mut self.switches,
            &cell.digital_cam_switches,
            first_switch,
            out,
            log,
        )
    }

    /// Appends the objects' part of a trace row to `r`.
    pub(crate) fn row(&self, r: &mut String) {
        use std::fmt::Write as _;
        let last = |x: Option<i64>| x.map(seconds).unwrap_or_default();
        for c in &self.cams {
            // Writing into a String cannot fail.
            let _ = write!(
                r,
                ",{},{}",
                u8::from(c.cam.status().cam_output),
                last(c.last_edge)
            );
        }
        for c in &self.tracks {
            let s = c.track.status();
            // Writing into a String cannot fail.
            let _ = write!(
                r,
                ",{},{},{},{}",
                u8::from(s.track_output),
                last(c.last_edge),
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
            // Writing into a String cannot fail.
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
        for c in &self.switches {
            let s = c.dcs.status();
            // Writing into a String cannot fail.
            let _ = write!(r, ",{},{}", s.output_bits, u8::from(s.in_operation));
        }
    }
}
