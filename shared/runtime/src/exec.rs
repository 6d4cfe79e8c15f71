//! The cyclic executive of one node (design §3), free of IO and clocks: the technology objects a
//! node hosts, stepped at a time given by the caller. `tandem sim` runs one executive that owns
//! the whole cell on virtual time; `tandem-node` runs one per process on the real clock and
//! feeds it the samples of leaders on other nodes.
//!
//! Leading values follow design §4: a follower of a leader with a leading-value delay `D > 0`
//! evaluates the leader at `t - D` from a buffer of timestamped samples, whether the leader is
//! stepped by the same executive or another process; a leader with `D = 0` is read directly
//! (it is stepped first).
//!
//! After [`Executive::new`], nothing here allocates: the log lines are formatted into the
//! caller's writer (a fixed ring in a node).

use crate::objects::{cycle_motion, invalid, CycleMotion, Objects};
use std::fmt;
use std::io::{self, Write};
use std::sync::Arc;
use tandem_config::{Cell, Coupling, EncoderSource, LEADING_BUFFER};
use tandem_motion::cam::{Cam, CamDefinition};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{Axis, AxisStatus, CamId, Command};
use tandem_motion::objects::encoder::{EncoderStatus, ExternalEncoder};
use tandem_motion::objects::job::{Instruction, JobEvent, JobEventKind, JobId};
use tandem_motion::objects::leading::{
    LeaderId, LeadingSample, LeadingValue, LeadingValueBuffer, Lookup, Missing, Rejected,
};

/// Formats ns as seconds with 9 decimals, exactly.
pub fn seconds(t_ns: i64) -> String {
    Secs(t_ns).to_string()
}

/// ns shown as seconds with 9 decimals, exactly, without allocating.
#[derive(Copy, Clone, Debug)]
pub struct Secs(pub i64);

impl fmt::Display for Secs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sign = if self.0 < 0 { "-" } else { "" };
        let t = self.0.unsigned_abs();
        write!(f, "{sign}{}.{:09}", t / 1_000_000_000, t % 1_000_000_000)
    }
}

/// A job event kind as the log shows it.
#[derive(Copy, Clone, Debug)]
pub struct Describe(pub JobEventKind);

impl fmt::Display for Describe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            JobEventKind::Error(e) => write!(f, "Error {e}"),
            JobEventKind::Status(on) => write!(f, "Status {}", if on { "TRUE" } else { "FALSE" }),
            other => write!(f, "{other:?}"),
        }
    }
}

fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
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

/// Whether `follower` appears in the leader chain of `leader` (a recursive coupling). Only the
/// chain through this executive's axes is seen; a chain through another node is not.
fn recursive(axes: &[Axis], owned: &[bool], follower: usize, leader: usize) -> bool {
    let mut stack = vec![leader];
    let mut seen = vec![false; axes.len()];
    while let Some(i) = stack.pop() {
        if i == follower {
            return true;
        }
        if i >= axes.len() || !owned[i] {
            // An external encoder follows nothing; another node's axis is not known here.
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

/// Keeps a job event of `object` as a note (unless the step already has [`NOTES`]) and logs it.
fn job_event(
    jobs: &mut Vec<JobNote>,
    dropped: &mut u64,
    log: &mut impl Write,
    name: &str,
    object: usize,
    ev: JobEvent,
) -> io::Result<()> {
    if jobs.len() < NOTES {
        jobs.push(JobNote {
            t_ns: ev.time_ns,
            object,
            job: ev.job,
            instruction: ev.instruction,
            kind: ev.kind,
        });
    } else {
        *dropped += 1;
    }
    writeln!(
        log,
        "t={} {name} {} job {}: {}",
        Secs(ev.time_ns),
        ev.instruction.name(),
        ev.job,
        Describe(ev.kind)
    )
}

/// The samples of one leader (in one coupling) that followers read at `t - D`.
#[derive(Debug)]
struct LeaderBuffer {
    leader: usize,
    coupling: Coupling,
    delay_ns: i64,
    tolerance_ns: i64,
    samples: Box<LeadingValueBuffer<LEADING_BUFFER>>,
    seq: u64,
    /// Why the value is missing since the last lookup (logged once per outage).
    missing: Option<Missing>,
    /// The outage was logged.
    logged: bool,
}

/// A job event of an axis or encoder, for the node to publish.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JobNote {
    /// When (ns).
    pub t_ns: i64,
    /// The object (index in [`Cell::object_names`]: axes, then encoders).
    pub object: usize,
    /// The job.
    pub job: JobId,
    /// The instruction.
    pub instruction: Instruction,
    /// What happened.
    pub kind: JobEventKind,
}

/// What an output cam, cam track or measuring input did, for the node to publish.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct IoNote {
    /// The object: output cams, then cam tracks, then measuring inputs, in cell order.
    pub object: usize,
    /// The exact time (ns).
    pub t_ns: i64,
    /// `false`: an output edge (`value` 1 on, 0 off); `true`: a measured value.
    pub measured: bool,
    /// The cam number of a cam track's edge (1-based), or the measurement counter.
    pub counter: u32,
    /// 1/0, or the measured position.
    pub value: f64,
}

/// Notes kept per step for the caller; more are dropped (and counted).
pub const NOTES: usize = 256;

/// What applying a command did.
pub type Applied = Result<Option<JobId>, ErrorId>;

/// The technology objects of one node (or of the whole cell), stepped by the caller.
#[derive(Debug)]
pub struct Executive<'c> {
    cell: &'c Cell,
    owned_axes: Vec<bool>,
    owned_encoders: Vec<bool>,
    axes: Vec<Axis>,
    encoders: Vec<ExternalEncoder>,
    /// The cams as the jobs see them: MC_InterpolateCam replaces one (a job keeps its own).
    cams: Vec<(Arc<Cam>, CamDefinition)>,
    cycles: Vec<i64>,
    tick: i64,
    objects: Objects,
    has_objects: Vec<bool>,
    needs_motion: Vec<bool>,
    motions: Vec<Option<CycleMotion>>,
    alarms_seen: Vec<[(u16, u16); 8]>,
    status: Vec<AxisStatus>,
    encoder_status: Vec<EncoderStatus>,
    /// The status at each axis' previous cycle (the start of its objects' motion).
    last_cycle: Vec<AxisStatus>,
    stepped: Vec<bool>,
    buffers: Vec<LeaderBuffer>,
    jobs: Vec<JobNote>,
    /// Notes dropped because more than [`NOTES`] came in one step.
    pub notes_dropped: u64,
    /// Leading values bridged by extrapolation (a late sample).
    pub extrapolated: u64,
    /// Commands applied and rejected (script, CLI and register corrections).
    pub commands: usize,
    /// Commands rejected with an ErrorID.
    pub rejected: usize,
}

impl<'c> Executive<'c> {
    /// The objects of node `node` (all of the cell with `None`). Fails when an object's
    /// configuration is refused by the engine.
    pub fn new(cell: &'c Cell, node: Option<usize>) -> io::Result<Self> {
        let owned_axes: Vec<bool> = cell
            .axes
            .iter()
            .map(|a| node.is_none_or(|n| a.node == n))
            .collect();
        let owned_encoders: Vec<bool> = cell
            .encoders
            .iter()
            .map(|e| node.is_none_or(|n| e.node == n))
            .collect();
        let mut axes = Vec::with_capacity(cell.axes.len());
        for a in &cell.axes {
            axes.push(Axis::new(a.config.clone()).map_err(|e| invalid("axis", &a.name, e))?);
        }
        let mut encoders = Vec::with_capacity(cell.encoders.len());
        for e in &cell.encoders {
            encoders
                .push(ExternalEncoder::new(e.config).map_err(|x| invalid("encoder", &e.name, x))?);
        }
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
        let cams = cell
            .cams
            .iter()
            .map(|c| (Arc::clone(&c.cam), c.definition.clone()))
            .collect();
        let cycles: Vec<i64> = cell
            .axes
            .iter()
            .map(|a| cell.nodes[a.node].cycle_ns)
            .collect();
        let owned_cycles: Vec<i64> = cell
            .nodes
            .iter()
            .enumerate()
            .filter(|(i, _)| node.is_none_or(|n| n == *i))
            .map(|(_, n)| n.cycle_ns)
            .collect();
        let tick = owned_cycles
            .iter()
            .copied()
            .fold(0, gcd)
            .max(cell.base_tick_ns.max(1));
        let tick = if owned_cycles.iter().all(|c| c % tick == 0) {
            tick
        } else {
            cell.base_tick_ns.max(1)
        };
        let has_objects: Vec<bool> = (0..cell.axes.len())
            .map(|i| {
                owned_axes[i]
                    && (cell.output_cams.iter().any(|c| c.axis == i)
                        || cell.cam_tracks.iter().any(|c| c.axis == i)
                        || cell.measuring_inputs.iter().any(|c| c.axis == i))
            })
            .collect();
        // Axes whose cycle motion is needed: those with objects and those that carry a sensor.
        let needs_motion: Vec<bool> = (0..cell.axes.len())
            .map(|i| {
                owned_axes[i]
                    && (has_objects[i]
                        || cell
                            .measuring_inputs
                            .iter()
                            .any(|m| m.sensor.is_some_and(|s| s.axis == i)))
            })
            .collect();
        // Buffers: each leader that a follower of this executive may read with a delay, and
        // each leader on another node that a follower here may follow.
        let mut buffers: Vec<LeaderBuffer> = Vec::new();
        for (f, a) in cell.axes.iter().enumerate() {
            if !owned_axes[f] {
                continue;
            }
            let candidates: Vec<(usize, Coupling)> = match &a.leaders {
                Some(list) => list.clone(),
                None => (0..cell.axes.len() + cell.encoders.len())
                    .filter(|l| *l != f && cell.coupling(f, *l).is_some())
                    .map(|l| (l, Coupling::Setpoint))
                    .collect(),
            };
            for (l, coupling) in candidates {
                let lv = cell.leading[l];
                let local = cell.leader_node(l) == Some(a.node);
                let coupling = if l >= cell.axes.len() {
                    Coupling::Setpoint
                } else {
                    coupling
                };
                if (local && lv.delay_ns == 0)
                    || buffers
                        .iter()
                        .any(|b| b.leader == l && b.coupling == coupling)
                {
                    continue;
                }
                let mut samples = Box::new(LeadingValueBuffer::new());
                let leader_cycle = cell.leader_node(l).map_or(0, |n| cell.nodes[n].cycle_ns);
                samples.set_max_gap(leader_cycle + lv.tolerance_ns);
                buffers.push(LeaderBuffer {
                    leader: l,
                    coupling,
                    delay_ns: lv.delay_ns,
                    tolerance_ns: lv.tolerance_ns,
                    samples,
                    seq: 0,
                    missing: None,
                    logged: false,
                });
            }
        }
        let status: Vec<AxisStatus> = axes.iter().map(|a| *a.status()).collect();
        let encoder_status = encoders.iter().map(|e| *e.status()).collect();
        Ok(Self {
            cell,
            objects: Objects::new(cell)?,
            owned_axes,
            owned_encoders,
            cams,
            tick,
            has_objects,
            needs_motion,
            motions: (0..cell.axes.len()).map(|_| None).collect(),
            alarms_seen: vec![[(0, 0); 8]; axes.len()],
            last_cycle: status.clone(),
            status,
            encoder_status,
            stepped: vec![false; axes.len()],
            cycles,
            axes,
            encoders,
            buffers,
            jobs: Vec::with_capacity(NOTES),
            notes_dropped: 0,
            extrapolated: 0,
            commands: 0,
            rejected: 0,
        })
    }

    /// The period at which [`Executive::step`] must be called (ns): the greatest common divisor
    /// of the owned nodes' cycles.
    pub fn tick_ns(&self) -> i64 {
        self.tick
    }

    /// Whether this executive steps axis `i`.
    pub fn owns_axis(&self, i: usize) -> bool {
        self.owned_axes.get(i).copied().unwrap_or(false)
    }

    /// The status of every axis of the cell (meaningful for the owned ones).
    pub fn status(&self) -> &[AxisStatus] {
        &self.status
    }

    /// The status of every encoder of the cell (meaningful for the owned ones).
    pub fn encoder_status(&self) -> &[EncoderStatus] {
        &self.encoder_status
    }

    /// The axis `i` (for its alarms and details).
    pub fn axis(&self, i: usize) -> Option<&Axis> {
        self.axes.get(i)
    }

    /// The objects' columns of a trace row (output cams, cam tracks, measuring inputs).
    pub fn objects_row(&mut self) -> &str {
        self.objects.row()
    }

    /// Writes the objects' trace column names (each prefixed with `,`).
    pub fn objects_header(cell: &Cell, out: &mut impl Write) -> io::Result<()> {
        Objects::header(cell, out)
    }

    /// Axes with a pending technology alarm.
    pub fn axes_in_alarm(&self) -> usize {
        self.axes
            .iter()
            .enumerate()
            .filter(|(i, a)| self.owned_axes[*i] && a.alarms().next().is_some())
            .count()
    }

    /// Hands the executive a sample of leader `leader` published by another node (in the
    /// leader's `coupling`). A sample of a leader nobody here follows is ignored.
    pub fn feed(
        &mut self,
        leader: usize,
        coupling: Coupling,
        sample: LeadingSample,
    ) -> Result<(), Rejected> {
        match self
            .buffers
            .iter_mut()
            .find(|b| b.leader == leader && b.coupling == coupling)
        {
            Some(b) => b.samples.push(sample),
            None => Ok(()),
        }
    }

    /// The leaders (and couplings) this executive reads from other nodes.
    pub fn remote_leaders(&self) -> impl Iterator<Item = (usize, Coupling)> + '_ {
        self.buffers
            .iter()
            .filter(|b| !self.owns_leader(b.leader))
            .map(|b| (b.leader, b.coupling))
    }

    fn owns_leader(&self, l: usize) -> bool {
        match self.owned_axes.get(l) {
            Some(o) => *o,
            None => self
                .owned_encoders
                .get(l - self.axes.len())
                .copied()
                .unwrap_or(false),
        }
    }

    /// The current leading value of leader `leader` as this executive computed it in its last
    /// step, timestamped `t_ns` (for publishing to other nodes).
    pub fn sample(&self, leader: usize, coupling: Coupling, t_ns: i64, seq: u64) -> LeadingSample {
        let lv = self.direct(leader, coupling);
        LeadingSample {
            t_ns,
            seq,
            p: lv.map_or(0.0, |x| x.p),
            v: lv.map_or(0.0, |x| x.v),
            a: lv.map_or(0.0, |x| x.a),
            modulo: lv.and_then(|x| x.modulo),
            valid: lv.is_some(),
        }
    }

    /// The value of an owned leader as stepped this cycle.
    fn direct(&self, j: usize, coupling: Coupling) -> Option<LeadingValue> {
        if j >= self.axes.len() {
            self.encoders
                .get(j - self.axes.len())
                .and_then(|e| e.leading_value())
        } else {
            Some(match coupling {
                Coupling::Actual => self.axes[j].actual_leading_value(),
                Coupling::Setpoint => self.axes[j].setpoint_leading_value(),
            })
        }
    }

    /// Applies an instruction addressed to `target` at time `t` (between two steps): the job id
    /// of an Execute-type instruction, `None` for the others, or the ErrorID that rejected it
    /// (also written to `log`). Counts it in [`Executive::commands`] / [`Executive::rejected`].
    pub fn apply(
        &mut self,
        t: i64,
        target: &str,
        instruction: &str,
        action: Action,
        log: &mut impl Write,
    ) -> io::Result<Applied> {
        self.apply_at(t, t, target, instruction, action, log)
    }

    /// Applies an action whose own time `at_ns` differs from the step time `t` (an input
    /// edge between two steps); otherwise as [`Executive::apply`].
    pub fn apply_at(
        &mut self,
        t: i64,
        at_ns: i64,
        target: &str,
        instruction: &str,
        action: Action,
        log: &mut impl Write,
    ) -> io::Result<Applied> {
        self.commands += 1;
        let result = self.apply_inner(at_ns, target, action);
        match result {
            Ok(_) if matches!(action, Action::ResetObject { .. }) => {
                writeln!(log, "t={} {target} MC_Reset: Done", Secs(t))?;
            }
            Ok(_) if matches!(action, Action::InterpolateCam { .. }) => {
                writeln!(log, "t={} {target} MC_InterpolateCam: Done", Secs(t))?;
            }
            Ok(_) => {}
            Err(id) => {
                self.rejected += 1;
                writeln!(
                    log,
                    "t={} {target} {instruction} rejected: {id} ({})",
                    Secs(t),
                    id.description()
                )?;
            }
        }
        Ok(result)
    }

    fn apply_inner(&mut self, t: i64, target: &str, action: Action) -> Applied {
        let cell = self.cell;
        let command = match action {
            Action::Command(c) => c,
            Action::OutputCam { .. }
            | Action::CamTrack { .. }
            | Action::MeasuringInput { .. }
            | Action::AbortMeasuringInput
            | Action::ResetObject { .. }
            | Action::InputEdge { .. } => {
                let axis = cell
                    .output_cam(target)
                    .map(|i| cell.output_cams[i].axis)
                    .or_else(|| cell.cam_track(target).map(|i| cell.cam_tracks[i].axis))
                    .or_else(|| {
                        cell.measuring_input(target)
                            .map(|i| cell.measuring_inputs[i].axis)
                    });
                if !axis.is_some_and(|a| self.owned_axes[a]) {
                    return Err(ErrorId::IllegalObject);
                }
                return self.objects.apply(cell, target, t, action).map(|()| None);
            }
            Action::InterpolateCam { cam, from } => {
                return interpolate_cam(cell, &mut self.cams, cam, from).map(|()| None);
            }
        };
        if let Some(k) = cell.encoders.iter().position(|x| x.name == target) {
            if !self.owned_encoders[k] {
                return Err(ErrorId::IllegalObject);
            }
            return self.encoders[k].command(&command).map(Some);
        }
        let Some(i) = cell
            .axes
            .iter()
            .position(|a| a.name == target)
            .filter(|i| self.owned_axes[*i])
        else {
            return Err(ErrorId::IllegalObject);
        };
        let master = match command {
            Command::GearIn { master, .. }
            | Command::GearInPos { master, .. }
            | Command::GearInVelocity { master, .. }
            | Command::CamIn { master, .. } => Some(master),
            _ => None,
        };
        if let Command::CamIn { cam, .. } = command {
            // The job takes its own reference to the interpolated cam.
            if let Some((c, _)) = usize::try_from(cam).ok().and_then(|c| self.cams.get(c)) {
                self.axes[i].provide_cam(cam, Arc::clone(c));
            }
        }
        let result = match master.and_then(|m| usize::try_from(m).ok()) {
            Some(m) if recursive(&self.axes, &self.owned_axes, i, m) => {
                Err(ErrorId::RecursiveSyncChain)
            }
            // The leader must be one of the follower's configured leaders.
            Some(m) if cell.coupling(i, m).is_none() => Err(ErrorId::IllegalObject),
            _ => self.axes[i].command(&command).map(Some),
        };
        if let (Ok(_), Command::Home { mode, .. }) = (&result, command) {
            self.objects.homing_started(cell, i, mode);
        }
        result
    }

    /// The value follower `i` reads of leader `l` at time `t`.
    fn leading_value(&mut self, i: usize, l: usize, t: i64) -> Option<LeadingValue> {
        let coupling = if l >= self.axes.len() {
            Coupling::Setpoint
        } else {
            self.cell.coupling(i, l).unwrap_or(Coupling::Setpoint)
        };
        let owned = self.owns_leader(l);
        match self
            .buffers
            .iter_mut()
            .find(|b| b.leader == l && b.coupling == coupling)
        {
            Some(b) => match b.samples.at(t - b.delay_ns, b.tolerance_ns) {
                Lookup::Interpolated(v) => {
                    b.missing = None;
                    b.logged = false;
                    Some(v)
                }
                Lookup::Extrapolated { value, .. } => {
                    b.missing = None;
                    b.logged = false;
                    self.extrapolated += 1;
                    Some(value)
                }
                Lookup::Missing(m) => {
                    b.missing = Some(m);
                    None
                }
            },
            None if owned => self.direct(l, coupling),
            None => None,
        }
    }

    /// Logs each leader whose value went missing this step, once per outage: which leader,
    /// why, and the newest sample's time.
    fn log_missing(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let names = &self.cell.axes;
        for b in self.buffers.iter_mut().filter(|b| !b.logged) {
            let Some(m) = b.missing else {
                continue;
            };
            b.logged = true;
            let leader = match names.get(b.leader) {
                Some(a) => a.name.as_str(),
                None => self
                    .cell
                    .encoders
                    .get(b.leader - names.len())
                    .map_or("?", |e| e.name.as_str()),
            };
            write!(
                log,
                "t={} leading value of {leader} missing at t - D = {}: ",
                Secs(t),
                Secs(t - b.delay_ns)
            )?;
            match m {
                Missing::Empty => writeln!(log, "no sample received yet")?,
                Missing::TooOld { oldest_ns } => writeln!(
                    log,
                    "t - D is before the oldest sample ({})",
                    Secs(oldest_ns)
                )?,
                Missing::Late { newest_ns } => writeln!(
                    log,
                    "newest sample t={}, later than the tolerance {} ms allows",
                    Secs(newest_ns),
                    b.tolerance_ns as f64 * 1e-6
                )?,
                Missing::Invalid => writeln!(log, "the leader marks its value invalid")?,
            }
        }
        Ok(())
    }

    /// One step at time `t` (a multiple of [`Executive::tick_ns`]): encoders, then axes in
    /// dependency order (leaders first), then the objects of each axis with the motion of its
    /// cycle, then register corrections. Job events, alarms, output edges and measured values
    /// are written to `log`.
    pub fn step(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        let n_axes = self.axes.len();
        // External encoders first: they lead and follow nothing. An encoder on an axis reads
        // that axis' actual position of the previous cycle (one cycle of acquisition delay).
        for (k, enc) in self.encoders.iter_mut().enumerate() {
            if !self.owned_encoders[k] || t % cell.nodes[cell.encoders[k].node].cycle_ns != 0 {
                continue;
            }
            let (p, v) = match &cell.encoders[k].source {
                EncoderSource::Axis { axis, scale } => {
                    let s = self.axes[*axis].status();
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
                let name = &cell.encoders[k].name;
                job_event(
                    &mut self.jobs,
                    &mut self.notes_dropped,
                    log,
                    name,
                    n_axes + k,
                    ev,
                )?;
            }
            self.encoder_status[k] = *enc.status();
        }
        self.record_samples(t, true);
        // Leaders before their followers: an axis steps once every leader it needs has.
        self.stepped.fill(false);
        for _pass in 0..=n_axes {
            let mut progress = false;
            for i in 0..n_axes {
                if self.stepped[i] || !self.owned_axes[i] {
                    continue;
                }
                let needs: [Option<LeaderId>; 2] = self.axes[i].leaders();
                let ready = needs.iter().flatten().all(|l| {
                    usize::try_from(*l)
                        .ok()
                        .map(|j| j >= n_axes || !self.owned_axes[j] || self.stepped[j])
                        .unwrap_or(true)
                });
                if !ready {
                    continue;
                }
                for l in needs.into_iter().flatten() {
                    let lv = usize::try_from(l)
                        .ok()
                        .and_then(|j| self.leading_value(i, j, t));
                    self.axes[i].set_leading_value(l, lv);
                }
                if t % self.cycles[i] == 0 {
                    self.axes[i].step(t);
                }
                self.stepped[i] = true;
                progress = true;
            }
            if !progress {
                break;
            }
        }
        // Not reached only with a coupling loop, which commands cannot create (16#8019): the
        // axis then runs without its leading value and raises "leader missing".
        for (i, axis) in self.axes.iter_mut().enumerate() {
            if self.owned_axes[i] && !self.stepped[i] && t % self.cycles[i] == 0 {
                axis.step(t);
            }
        }
        self.record_samples(t, false);
        self.log_missing(t, log)?;
        for (i, axis) in self.axes.iter_mut().enumerate() {
            if !self.owned_axes[i] {
                continue;
            }
            while let Some(ev) = axis.pop_event() {
                let name = &cell.axes[i].name;
                job_event(&mut self.jobs, &mut self.notes_dropped, log, name, i, ev)?;
            }
            let mut now = [(0u16, 0u16); 8];
            for (slot, a) in now.iter_mut().zip(axis.alarms()) {
                *slot = (a.id.number(), a.supplement);
                if !self.alarms_seen[i].contains(slot) {
                    writeln!(
                        log,
                        "t={} {} alarm {} (supplement {}, reaction {:?}): {}",
                        Secs(t),
                        cell.axes[i].name,
                        a.id,
                        a.supplement,
                        a.reaction,
                        a.spec().text
                    )?;
                }
            }
            self.alarms_seen[i] = now;
            self.status[i] = *axis.status();
        }
        // Output cams, cam tracks and measuring inputs: after their axis, every cycle of its
        // node, with the motion of that cycle.
        for (i, m) in self.motions.iter_mut().enumerate() {
            *m = (t % self.cycles[i] == 0 && self.needs_motion[i]).then(|| {
                cycle_motion(
                    &self.last_cycle[i],
                    &self.status[i],
                    t - self.cycles[i],
                    t,
                    cell.axes[i].config.modulo,
                    self.objects.homing[i],
                )
            });
        }
        for i in 0..n_axes {
            if !self.owned_axes[i] || t % self.cycles[i] != 0 {
                continue;
            }
            if self.has_objects[i] {
                self.objects.step(cell, i, &self.motions, log)?;
                if self.objects.homing[i]
                    && !matches!(self.status[i].motion_job, Some((_, Instruction::Home)))
                {
                    self.objects.homing[i] = false;
                }
            }
            self.last_cycle[i] = self.status[i];
        }
        // Register corrections: MC_MoveSuperimposed, effective from the next cycle.
        for k in 0..self.objects.corrections.len() {
            let (a, distance, input) = self.objects.corrections[k];
            let command = Command::MoveSuperimposed {
                distance,
                dynamics: tandem_motion::kinematics::dynamics::Dynamics::DEFAULT,
            };
            self.commands += 1;
            writeln!(
                log,
                "t={} {} registration: {} MC_MoveSuperimposed distance {}",
                Secs(t),
                cell.measuring_inputs[input].name,
                cell.axes[a].name,
                distance
            )?;
            if let Err(id) = self.axes[a].command(&command) {
                self.rejected += 1;
                writeln!(
                    log,
                    "t={} {} MC_MoveSuperimposed rejected: {id} ({})",
                    Secs(t),
                    cell.axes[a].name,
                    id.description()
                )?;
            }
        }
        self.objects.corrections.clear();
        Ok(())
    }

    /// Hands each job event of the last step to `f`, then forgets them.
    pub fn drain_job_notes(&mut self, mut f: impl FnMut(&JobNote)) {
        self.jobs.iter().for_each(&mut f);
        self.jobs.clear();
    }

    /// Hands each output edge and measured value of the last step to `f`, then forgets them.
    pub fn drain_io_notes(&mut self, mut f: impl FnMut(&IoNote)) {
        self.objects.notes.iter().for_each(&mut f);
        self.objects.notes.clear();
    }

    /// Records the samples of owned leaders that were stepped at `t` into their buffers
    /// (encoders before the axes step, axes after).
    fn record_samples(&mut self, t: i64, encoders: bool) {
        let n_axes = self.axes.len();
        for k in 0..self.buffers.len() {
            let l = self.buffers[k].leader;
            if (l >= n_axes) != encoders || !self.owns_leader(l) {
                continue;
            }
            let cycle = if l < n_axes {
                self.cycles[l]
            } else {
                self.cell.nodes[self.cell.encoders[l - n_axes].node].cycle_ns
            };
            if t % cycle != 0 {
                continue;
            }
            let b = &self.buffers[k];
            let s = self.sample(l, b.coupling, t, b.seq);
            let b = &mut self.buffers[k];
            b.seq += 1;
            // A refused sample (a non-finite value) leaves a gap that followers bridge or
            // report as missing.
            let _ = b.samples.push(s);
        }
    }
}
