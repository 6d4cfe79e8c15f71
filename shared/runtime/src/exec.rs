//! The cyclic executive of one node, free of IO and clocks: the technology objects a node
//! hosts, stepped at a time given by the caller, in the node cycle's fixed order
//! (docs/processes.md, "One cycle of a node"). `tandem sim` runs one executive that owns the whole cell on virtual
//! time; `tandem-node` runs one per process on the real clock and feeds it the samples of
//! leaders on other nodes.
//!
//! Leading values (docs/processes.md, "Leading values"): a follower of a leader with a
//! leading-value delay `D > 0` evaluates the leader at `t - D` from a buffer of timestamped
//! samples, whether the leader is stepped by the same executive or another process; a leader
//! with `D = 0` is read directly (it is stepped first).
//!
//! After [`Executive::new`], nothing here allocates: the log lines are formatted into the
//! caller's writer (a fixed ring in a node).

mod hyd_trace;
mod retain;

use crate::drives::Drives;
use crate::error::ExecError;
pub use crate::inputs::{InputDeviceStatus, InputSignalEdge, INPUT_EDGES};
pub use crate::notes::{seconds, Describe, IoNote, JobNote, Secs, NOTES};
pub use crate::outputs::{OutputDeviceStatus, OutputSwitch, LOOK_AHEAD_CYCLES, SWITCHES};
pub use crate::values::{InputSignalValue, SignalValue, ValueDeviceStatus, INPUT_VALUES};
pub use hyd_trace::{HYDRAULIC_COLUMNS, PRESSURE_COLUMNS};
pub use retain::{AdjustmentChange, RestoreError, Restored};

use crate::inputs::Inputs;
use crate::notes::keep;
use crate::objects::{cycle_motion, CycleMotion, Objects};
use crate::outputs::Outputs;
use crate::values::Values;
use std::io::{self, Write};
use std::sync::Arc;
use tandem_config::{
    AxisIndex, Cell, Coupling, EncoderIndex, EncoderSource, Leader, LEADING_BUFFER,
};
use tandem_motion::cam::{Cam, CamDefinition};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{axis_parameter, Axis, AxisStatus, CamId, Command};
use tandem_motion::objects::encoder::{EncoderStatus, ExternalEncoder};
use tandem_motion::objects::job::{Instruction, JobEvent, JobId};
use tandem_motion::objects::leading::{
    LeaderId, LeadingSample, LeadingValue, LeadingValueBuffer, Lookup, Missing, Rejected,
};
use tandem_motion::objects::rejoin::{Rejoin, Rejoined};
use tandem_motion::plant::sensor::InputEdge;

/// A rejoin after an extrapolation is logged when the step it removed exceeds this (in the
/// leader's unit; smaller ones are the rounding of an extrapolation at constant acceleration).
const REJOIN_LOGGED: f64 = 1e-6;

/// The parameter number of an MC_WriteParameter or MC_ReadParameter, for the log line.
fn parameter_of(action: Action) -> Option<u16> {
    match action {
        Action::Command(
            Command::WriteParameter { parameter, .. } | Command::ReadParameter { parameter },
        ) => Some(parameter),
        _ => None,
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
fn recursive(
    cell: &Cell,
    axes: &[Axis],
    owned: &[bool],
    follower: AxisIndex,
    leader: Leader,
) -> bool {
    let mut stack = vec![leader];
    let mut seen = vec![false; axes.len()];
    while let Some(l) = stack.pop() {
        // An external encoder follows nothing.
        let Some(i) = l.axis() else {
            continue;
        };
        if i == follower {
            return true;
        }
        if i.0 >= axes.len() || !owned[i.0] {
            // Another node's axis is not known here.
            continue;
        }
        if std::mem::replace(&mut seen[i.0], true) {
            continue;
        }
        for id in axes[i.0].leaders().into_iter().flatten() {
            if let Some(Leader::Axis(j)) = cell.leader(id) {
                stack.push(Leader::Axis(j));
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
    let note = JobNote {
        t_ns: ev.time_ns,
        object,
        job: ev.job,
        instruction: ev.instruction,
        kind: ev.kind,
    };
    keep(jobs, dropped, note);
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
    leader: Leader,
    coupling: Coupling,
    delay_ns: i64,
    tolerance_ns: i64,
    samples: Box<LeadingValueBuffer<LEADING_BUFFER>>,
    seq: u64,
    /// Why the value is missing since the last lookup (logged once per outage).
    missing: Option<Missing>,
    /// The outage was logged.
    logged: bool,
    /// The rejoin of an extrapolated value with the real one.
    rejoin: Rejoin,
    /// The rejoin that started this step, to log.
    rejoined: Option<Rejoined>,
}

/// How a follower reads one leader: the coupling, and the buffer of samples if it reads it
/// delayed or from another node.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LeaderSource {
    leader: Leader,
    coupling: Coupling,
    buffer: Option<usize>,
}

/// One leader an axis reads in its step: its id, and where its value comes from (`None`: a
/// leader id the cell does not have).
#[derive(Debug, Clone, Copy)]
struct LeaderRead {
    id: LeaderId,
    source: Option<LeaderSource>,
    /// The value is that of the read before it in the plan (the same leader read directly,
    /// which has not stepped since): known when planning, so the step compares no sources.
    again: bool,
}

/// One owned axis in the step order, with the leaders it reads: `reads` entries of
/// [`StepPlan::reads`] from `first` (12 bytes: the step reads the order of a thousand axes
/// every cycle, and most axes read no leader).
#[derive(Debug, Clone, Copy)]
struct Planned {
    axis: u32,
    first: u32,
    reads: u32,
}

/// The order in which the owned axes step, and where each reads its leaders, planned from the
/// axes' leaders; planned again when they change (a coupling starts or ends).
#[derive(Debug, Default)]
struct StepPlan {
    /// The leaders of every axis when the plan was made.
    leaders: Vec<[Option<LeaderId>; 2]>,
    /// Owned axes, leaders before their followers, with the leaders each reads.
    order: Vec<Planned>,
    /// The leaders the axes of `order` read, in that order.
    reads: Vec<LeaderRead>,
    /// Owned axes caught in a coupling loop: stepped last, without leading values.
    unreached: Vec<usize>,
    /// Per axis: taken into `order` (while planning).
    taken: Vec<bool>,
    /// A plan was made and every owned axis still has the leaders it was planned with (an
    /// axis' leaders change only when it steps or takes a command: [`StepPlan::note`]).
    valid: bool,
}

impl StepPlan {
    /// An empty plan with room for `n` axes, so that planning again does not allocate.
    fn with_capacity(n: usize) -> Self {
        Self {
            leaders: Vec::with_capacity(n),
            order: Vec::with_capacity(n),
            reads: Vec::with_capacity(2 * n),
            unreached: Vec::with_capacity(n),
            taken: vec![false; n],
            valid: false,
        }
    }

    /// Whether axis `i` still has the leaders it was planned with.
    fn planned_with(&self, i: usize, axis: &Axis) -> bool {
        self.leaders.get(i) == Some(&axis.leaders())
    }

    /// Notes the leaders of axis `i` after it stepped or took a command: the plan no longer
    /// holds when they are not those it was planned with.
    fn note(&mut self, i: usize, axis: &Axis) {
        if !self.planned_with(i, axis) {
            self.valid = false;
        }
    }
}

/// What applying a command did.
pub type Applied = Result<Option<JobId>, ErrorId>;

/// Which axes and encoders of the cell an executive steps.
#[derive(Debug)]
struct Owned {
    axes: Vec<bool>,
    encoders: Vec<bool>,
}

impl Owned {
    /// The objects of node `node` (all of the cell with `None`).
    fn of(cell: &Cell, node: Option<usize>) -> Self {
        Self {
            axes: cell
                .axes
                .iter()
                .map(|a| node.is_none_or(|n| a.node == n))
                .collect(),
            encoders: cell
                .encoders
                .iter()
                .map(|e| node.is_none_or(|n| e.node == n))
                .collect(),
        }
    }

    fn axis(&self, i: AxisIndex) -> bool {
        self.axes.get(i.0).copied().unwrap_or(false)
    }

    fn encoder(&self, k: EncoderIndex) -> bool {
        self.encoders.get(k.0).copied().unwrap_or(false)
    }

    fn leader(&self, l: Leader) -> bool {
        match l {
            Leader::Axis(a) => self.axis(a),
            Leader::Encoder(e) => self.encoder(e),
        }
    }
}

/// The engine's axes and encoders of the cell (every one is created, the owned ones are
/// stepped), or the first one it refuses.
fn engine_objects(cell: &Cell) -> Result<(Vec<Axis>, Vec<ExternalEncoder>), ExecError> {
    let mut axes = Vec::with_capacity(cell.axes.len());
    for a in &cell.axes {
        axes.push(
            Axis::new(a.config.clone()).map_err(|reason| ExecError::Axis {
                name: a.name.clone(),
                reason,
            })?,
        );
    }
    let mut encoders = Vec::with_capacity(cell.encoders.len());
    for e in &cell.encoders {
        encoders.push(
            ExternalEncoder::new(e.config).map_err(|reason| ExecError::Encoder {
                name: e.name.clone(),
                reason,
            })?,
        );
    }
    // Axes that lead by actual value run the extrapolation of their actual value.
    for a in &cell.axes {
        for (l, c) in a.leaders.iter().flatten() {
            if let (Coupling::Actual, Some(j)) = (*c, l.axis()) {
                if let Some(leader) = axes.get_mut(j.0) {
                    leader.set_actual_value_output(true);
                }
            }
        }
    }
    Ok((axes, encoders))
}

/// The period at which an executive of `node` steps: the greatest common divisor of the owned
/// nodes' cycles (the base tick if that does not divide them).
fn tick_of(cell: &Cell, node: Option<usize>) -> i64 {
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
    if owned_cycles.iter().all(|c| c % tick == 0) {
        tick
    } else {
        cell.base_tick_ns.max(1)
    }
}

/// Per axis: whether it has objects (output cams, cam tracks, measuring inputs) this executive
/// steps, and whether its cycle motion is needed (those, and axes that carry a sensor).
fn axes_with_objects(cell: &Cell, owned: &Owned) -> (Vec<bool>, Vec<bool>) {
    let has_objects: Vec<bool> = cell
        .axis_indices()
        .map(|i| {
            owned.axis(i)
                && (cell.output_cams.iter().any(|c| c.axis == i)
                    || cell.cam_tracks.iter().any(|c| c.axis == i)
                    || cell.measuring_inputs.iter().any(|c| c.axis == i)
                    || cell.digital_cam_switches.iter().any(|c| c.axis == i))
        })
        .collect();
    let needs_motion: Vec<bool> = cell
        .axis_indices()
        .map(|i| {
            owned.axis(i)
                && (has_objects[i.0]
                    || cell
                        .measuring_inputs
                        .iter()
                        .any(|m| m.sensor.is_some_and(|s| s.axis == i)))
        })
        .collect();
    (has_objects, needs_motion)
}

/// Buffers: each leader that a follower of this executive may read with a delay, and each
/// leader on another node that a follower here may follow.
fn leader_buffers(cell: &Cell, owned: &Owned) -> Vec<LeaderBuffer> {
    let mut buffers: Vec<LeaderBuffer> = Vec::new();
    for (f, a) in cell.axis_indices().zip(&cell.axes) {
        if !owned.axis(f) {
            continue;
        }
        let candidates: Vec<(Leader, Coupling)> = match &a.leaders {
            Some(list) => list.clone(),
            None => cell
                .leaders()
                .filter(|l| *l != Leader::Axis(f) && cell.coupling(f, *l).is_some())
                .map(|l| (l, Coupling::Setpoint))
                .collect(),
        };
        for (l, coupling) in candidates {
            let lv = cell.leading(l);
            let local = cell.leader_node(l) == Some(a.node);
            let coupling = if l.is_encoder() {
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
            samples.set_max_gap(cell.leader_cycle_ns(l) + lv.tolerance_ns);
            buffers.push(LeaderBuffer {
                leader: l,
                coupling,
                delay_ns: lv.delay_ns,
                tolerance_ns: lv.tolerance_ns,
                samples,
                seq: 0,
                missing: None,
                logged: false,
                rejoin: Rejoin::new(),
                rejoined: None,
            });
        }
    }
    buffers
}

/// The encoders and axes of the cell by name, sorted, for commands addressed by name.
#[derive(Debug)]
struct Names<'c> {
    encoders: Vec<(&'c str, usize)>,
    axes: Vec<(&'c str, usize)>,
}

impl<'c> Names<'c> {
    fn of(cell: &'c Cell) -> Self {
        let sorted = |names: Vec<&'c str>| {
            let mut v: Vec<(&'c str, usize)> = names.into_iter().zip(0..).collect();
            // Stable: of two objects with one name, the first in the cell comes first.
            v.sort_by(|a, b| a.0.cmp(b.0));
            v
        };
        Self {
            encoders: sorted(cell.encoders.iter().map(|e| e.name.as_str()).collect()),
            axes: sorted(cell.axes.iter().map(|a| a.name.as_str()).collect()),
        }
    }

    /// The index of the first object named `name` in `list`.
    fn find(list: &[(&str, usize)], name: &str) -> Option<usize> {
        let k = list.partition_point(|x| x.0 < name);
        list.get(k).filter(|x| x.0 == name).map(|x| x.1)
    }

    fn encoder(&self, name: &str) -> Option<usize> {
        Self::find(&self.encoders, name)
    }

    fn axis(&self, name: &str) -> Option<usize> {
        Self::find(&self.axes, name)
    }
}

/// The technology objects of one node (or of the whole cell), stepped by the caller.
#[derive(Debug)]
pub struct Executive<'c> {
    cell: &'c Cell,
    owned: Owned,
    names: Names<'c>,
    axes: Vec<Axis>,
    encoders: Vec<ExternalEncoder>,
    /// The cams as the jobs see them: MC_InterpolateCam replaces one (a job keeps its own).
    cams: Vec<(Arc<Cam>, CamDefinition)>,
    cycles: Vec<i64>,
    /// Per node of the cell: whether its cycle falls on the step's time.
    due: Vec<bool>,
    /// Per axis: the index of its node.
    node_of: Vec<usize>,
    tick: i64,
    objects: Objects,
    has_objects: Vec<bool>,
    needs_motion: Vec<bool>,
    /// The axes with `needs_motion`, in index order.
    motion_axes: Vec<usize>,
    /// The owned axes with objects or whose motion is needed, in index order (the others
    /// have nothing to do after their step).
    object_axes: Vec<usize>,
    motions: Vec<Option<CycleMotion>>,
    alarms_seen: Vec<[(u16, u16); 8]>,
    /// Per axis: its status after the last step, copied from the axis when first read (most
    /// steps nobody reads most of them).
    status: Vec<AxisStatus>,
    /// Per axis: `status` is older than the axis' last step (see [`Executive::snapshot`]).
    stale: Vec<bool>,
    /// The step copies each axis' status right after stepping it ([`Executive::want_status`]).
    copy_status: bool,
    /// Per axis: it may have job events or alarms to log (set when it steps with some, when it
    /// takes a command, and while alarms were seen); the others are not looked at.
    news: Vec<bool>,
    encoder_status: Vec<EncoderStatus>,
    /// The status at each axis' previous cycle (the start of its objects' motion).
    last_cycle: Vec<AxisStatus>,
    plan: StepPlan,
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
    /// The drives of the process image and the axes on them.
    drives: Drives,
    /// The digital outputs of the process image and the objects driving them.
    outputs: Outputs,
    /// The digital inputs of the process image, their stimuli and sensors.
    inputs: Inputs,
    /// The analog and counter terminals of the process image (`integer`, `float` signals).
    values: Values,
    /// The row of [`Executive::objects_row`] (its capacity kept from row to row).
    trace_row: String,
}

impl<'c> Executive<'c> {
    /// The objects of node `node` (all of the cell with `None`). Fails when the engine refuses
    /// an object's configuration.
    pub fn new(cell: &'c Cell, node: Option<usize>) -> Result<Self, ExecError> {
        let owned = Owned::of(cell, node);
        let (axes, encoders) = engine_objects(cell)?;
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
        let inputs = Inputs::new(cell, node, &owned.axes);
        let (has_objects, mut needs_motion) = axes_with_objects(cell, &owned);
        // An input signal's sensor sees the motion of the axis that carries its mark.
        for a in inputs.sensor_axes() {
            if let (Some(n), true) = (needs_motion.get_mut(a), owned.axes.get(a) == Some(&true)) {
                *n = true;
            }
        }
        let buffers = leader_buffers(cell, &owned);
        let object_axes = (0..needs_motion.len())
            .filter(|&i| owned.axes[i] && (has_objects[i] || needs_motion[i]))
            .collect();
        let drives = Drives::new(cell, &owned.axes)?;
        let mut axes = axes;
        for link in &drives.links {
            if let Some(a) = axes.get_mut(link.axis) {
                a.connect_drive();
                a.set_torque_interface(link.per_mille_per_load.is_some());
            }
        }
        for link in &drives.analog.links {
            if let Some(a) = axes.get_mut(link.axis) {
                a.connect_drive();
            }
        }
        let status: Vec<AxisStatus> = axes.iter().map(|a| *a.status()).collect();
        let encoder_status = encoders.iter().map(|e| *e.status()).collect();
        Ok(Self {
            drives,
            outputs: Outputs::new(cell, node),
            inputs,
            values: Values::new(cell, node),
            cell,
            objects: Objects::new(cell)?,
            owned,
            names: Names::of(cell),
            cams,
            tick: tick_of(cell, node),
            has_objects,
            motion_axes: (0..needs_motion.len())
                .filter(|&i| needs_motion[i])
                .collect(),
            object_axes,
            needs_motion,
            motions: (0..cell.axes.len()).map(|_| None).collect(),
            alarms_seen: vec![[(0, 0); 8]; axes.len()],
            last_cycle: status.clone(),
            status,
            stale: vec![false; cell.axes.len()],
            copy_status: false,
            news: vec![false; cell.axes.len()],
            encoder_status,
            plan: StepPlan::with_capacity(axes.len()),
            cycles,
            due: vec![false; cell.nodes.len()],
            node_of: cell.axes.iter().map(|a| a.node).collect(),
            axes,
            encoders,
            buffers,
            jobs: Vec::with_capacity(NOTES),
            notes_dropped: 0,
            extrapolated: 0,
            commands: 0,
            rejected: 0,
            trace_row: String::new(),
        })
    }

    /// The period at which [`Executive::step`] must be called (ns): the greatest common divisor
    /// of the owned nodes' cycles.
    pub fn tick_ns(&self) -> i64 {
        self.tick
    }

    /// Whether this executive steps axis `i`.
    pub fn owns_axis(&self, i: AxisIndex) -> bool {
        self.owned.axis(i)
    }

    /// The status of every axis of the cell after the last step (meaningful for the owned
    /// ones).
    pub fn status(&mut self) -> &[AxisStatus] {
        for i in 0..self.stale.len() {
            self.snapshot(i);
        }
        &self.status
    }

    /// The next step copies the status of each axis it steps right after the axis' step, while
    /// the axis is in the caches, instead of when [`Executive::status`] reads it: for a caller
    /// that reads every status after that step (a node's telemetry). The statuses are the same
    /// (a status is that of the step until read: commands and registrations copy it before
    /// they change the axis); only the time of the copy differs, and with a thousand axes the
    /// first axes' state has left the caches by the end of the step.
    pub fn want_status(&mut self) {
        self.copy_status = true;
    }

    /// The status of axis `i` after the last step, as [`Executive::status`] has it.
    pub fn axis_status(&mut self, i: AxisIndex) -> Option<&AxisStatus> {
        self.snapshot(i.0);
        self.status.get(i.0)
    }

    /// Copies the status of axis `i` after the last step, unless that is done: when it is read,
    /// and before a command changes the axis.
    fn snapshot(&mut self, i: usize) {
        if let (Some(stale @ true), Some(axis), Some(s)) = (
            self.stale.get_mut(i),
            self.axes.get(i),
            self.status.get_mut(i),
        ) {
            *s = axis.status_value();
            *stale = false;
        }
    }

    /// The status of every encoder of the cell (meaningful for the owned ones).
    pub fn encoder_status(&self) -> &[EncoderStatus] {
        &self.encoder_status
    }

    /// MC_ReadParameter on the owned axis `target`: the current value of parameter `number`
    /// (docs/parameters.md), or the ErrorID that refuses it (16#8002 for an object that is
    /// not an owned axis).
    pub fn read_parameter(&self, target: &str, number: u16) -> Result<f64, ErrorId> {
        let i = self
            .names
            .axis(target)
            .map(AxisIndex)
            .filter(|i| self.owned.axis(*i))
            .ok_or(ErrorId::IllegalObject)?;
        self.axes[i.0].read_parameter(number)
    }

    /// Writes the retained run-time parameters of owned axis `i` (docs/parameters.md) before
    /// the first step: all of them or, refused with the number and ErrorID, none.
    pub fn restore_parameters(
        &mut self,
        i: AxisIndex,
        values: &[(u16, f64)],
    ) -> Result<(), (u16, ErrorId)> {
        let refused = (0, ErrorId::IllegalObject);
        if !self.owned.axis(i) {
            return Err(refused);
        }
        self.axes
            .get_mut(i.0)
            .ok_or(refused)?
            .write_parameters(values)
    }

    /// The axis `i` (for its alarms and details).
    pub fn axis(&self, i: AxisIndex) -> Option<&Axis> {
        self.axes.get(i.0)
    }

    /// The columns of a trace row after the axes' and encoders': the hydraulic axes' signals
    /// ([`HYDRAULIC_COLUMNS`]), then the objects' (output cams, cam tracks, measuring inputs).
    pub fn objects_row(&mut self) -> &str {
        self.trace_row.clear();
        hyd_trace::row(
            self.cell,
            &self.axes,
            &self.drives.analog,
            &mut self.trace_row,
        );
        self.objects.row(&mut self.trace_row);
        &self.trace_row
    }

    /// Writes the column names of [`Executive::objects_row`] (each prefixed with `,`).
    pub fn objects_header(cell: &Cell, out: &mut impl Write) -> io::Result<()> {
        hyd_trace::header(cell, out)?;
        Objects::header(cell, out)
    }

    /// Axes with a pending technology alarm.
    pub fn axes_in_alarm(&self) -> usize {
        self.axes
            .iter()
            .enumerate()
            .filter(|(i, a)| self.owned.axes[*i] && a.alarms().next().is_some())
            .count()
    }

    /// Hands the executive a sample of `leader` published by another node (in the leader's
    /// `coupling`). A sample of a leader nobody here follows is ignored.
    pub fn feed(
        &mut self,
        leader: Leader,
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

    /// Samples of the leaders read from other nodes that never arrived: sequence gaps seen
    /// by their buffers. A follower reading inside such a gap gets the interpolant between
    /// the samples around it, exact only where the leader's motion is a polynomial of degree
    /// at most five across the gap.
    pub fn leading_lost(&self) -> u64 {
        self.buffers
            .iter()
            .filter(|b| !self.owned.leader(b.leader))
            .map(|b| b.samples.lost())
            .sum()
    }

    /// The leaders (and couplings) this executive reads from other nodes.
    pub fn remote_leaders(&self) -> impl Iterator<Item = (Leader, Coupling)> + '_ {
        self.buffers
            .iter()
            .filter(|b| !self.owned.leader(b.leader))
            .map(|b| (b.leader, b.coupling))
    }

    /// The current leading value of `leader` as this executive computed it in its last step,
    /// timestamped `t_ns` (for publishing to other nodes).
    pub fn sample(&self, leader: Leader, coupling: Coupling, t_ns: i64, seq: u64) -> LeadingSample {
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
    fn direct(&self, leader: Leader, coupling: Coupling) -> Option<LeadingValue> {
        match leader {
            Leader::Encoder(k) => self.encoders.get(k.0).and_then(|e| e.leading_value()),
            Leader::Axis(j) => {
                let axis = self.axes.get(j.0)?;
                Some(match coupling {
                    Coupling::Actual => axis.actual_leading_value(),
                    Coupling::Setpoint => axis.setpoint_leading_value(),
                })
            }
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
            Ok(_) => {
                if let Some(n) = parameter_of(action) {
                    let name = axis_parameter(n).map_or("?", |e| e.key);
                    let value = self.read_parameter(target, n).unwrap_or(f64::NAN);
                    writeln!(
                        log,
                        "t={} {target} {instruction}: {name} = {value}",
                        Secs(t)
                    )?;
                }
            }
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
            | Action::InputEdge { .. }
            | Action::DigitalCamSwitch { .. } => {
                if !cell.object_axis(target).is_some_and(|a| self.owned.axis(a)) {
                    return Err(ErrorId::IllegalObject);
                }
                return self.objects.apply(cell, target, t, action).map(|()| None);
            }
            Action::InterpolateCam { cam, from } => {
                return interpolate_cam(cell, &mut self.cams, cam, from).map(|()| None);
            }
            Action::SetInput { value, pulse_ns } => {
                let k = cell.signal(target).ok_or(ErrorId::IllegalObject)?;
                return self.inputs.set(k.0, t, value, pulse_ns).map(|()| None);
            }
            Action::SetInputValue { value } => {
                let k = cell.signal(target).ok_or(ErrorId::IllegalObject)?;
                return self.values.set(k.0, t, value).map(|()| None);
            }
            Action::SetOutputValue { value } => {
                let k = cell.signal(target).ok_or(ErrorId::IllegalObject)?;
                return self.values.set_output(k.0, t, value).map(|()| None);
            }
            Action::DriveFault { code } => {
                let d = cell.devices.iter().position(|d| d.name == target);
                let Some(d) = d.filter(|&d| self.drives.runs(d)) else {
                    return Err(ErrorId::IllegalObject);
                };
                // The model refuses only a fault without code, and code 0 removes the cause
                // instead: no refusal reaches here in practice.
                return self
                    .drives
                    .inject_fault(d, code)
                    .map(|()| None)
                    .map_err(|_| ErrorId::IllegalObject);
            }
            Action::FixedStop { min, max } => {
                let d = cell.devices.iter().position(|d| d.name == target);
                return match d {
                    Some(d) if self.drives.set_fixed_stops(d, min, max) => Ok(None),
                    _ => Err(ErrorId::IllegalObject),
                };
            }
        };
        if let Some(k) = self.names.encoder(target) {
            if !self.owned.encoders[k] {
                return Err(ErrorId::IllegalObject);
            }
            return self.encoders[k].command(&command).map(Some);
        }
        let Some(i) = self
            .names
            .axis(target)
            .map(AxisIndex)
            .filter(|i| self.owned.axis(*i))
        else {
            return Err(ErrorId::IllegalObject);
        };
        self.axis_command(i, command)
    }

    /// A command to owned axis `i`: synchronous operation only with a configured leader
    /// that does not follow `i`; MC_CamIn takes its own reference to the cam.
    fn axis_command(&mut self, i: AxisIndex, command: Command) -> Applied {
        let cell = self.cell;
        let master = match command {
            Command::GearIn { master, .. }
            | Command::GearInPos { master, .. }
            | Command::FlyingGear { master, .. }
            | Command::GearInVelocity { master, .. }
            | Command::CamIn { master, .. } => Some(master),
            _ => None,
        };
        if let Command::CamIn { cam, .. } = command {
            // The job takes its own reference to the interpolated cam.
            if let Some((c, _)) = usize::try_from(cam).ok().and_then(|c| self.cams.get(c)) {
                self.axes[i.0].provide_cam(cam, Arc::clone(c));
            }
        }
        let result = match master.map(|m| cell.leader(m)) {
            // A leader id the cell does not have.
            Some(None) => Err(ErrorId::IllegalObject),
            Some(Some(m)) if recursive(cell, &self.axes, &self.owned.axes, i, m) => {
                Err(ErrorId::RecursiveSyncChain)
            }
            // The leader must be one of the follower's configured leaders.
            Some(Some(m)) if cell.coupling(i, m).is_none() => Err(ErrorId::IllegalObject),
            _ => {
                // The status of the last step stays what it was until the next step.
                self.snapshot(i.0);
                let r = self.axes[i.0].command(&command).map(Some);
                self.plan.note(i.0, &self.axes[i.0]);
                self.news[i.0] = true;
                r
            }
        };
        if let (Ok(_), Command::Home { mode, .. }) = (&result, command) {
            self.objects.homing_started(cell, i, mode);
        }
        result
    }

    /// How follower `i` reads leader `l`: its coupling and the buffer of delayed samples, if
    /// any (found once per plan, not every cycle).
    fn leader_source(&self, i: AxisIndex, l: Leader) -> LeaderSource {
        let coupling = if l.is_encoder() {
            Coupling::Setpoint
        } else {
            self.cell.coupling(i, l).unwrap_or(Coupling::Setpoint)
        };
        LeaderSource {
            leader: l,
            coupling,
            buffer: self
                .buffers
                .iter()
                .position(|b| b.leader == l && b.coupling == coupling),
        }
    }

    /// The value a follower reads of the leader of `src` at time `t`.
    fn leading_value(&mut self, src: LeaderSource, t: i64) -> Option<LeadingValue> {
        let Some(b) = src.buffer.and_then(|k| self.buffers.get_mut(k)) else {
            return if self.owned.leader(src.leader) {
                self.direct(src.leader, src.coupling)
            } else {
                None
            };
        };
        let (lookup, rejoined) = b.rejoin.at(&b.samples, t - b.delay_ns, b.tolerance_ns);
        if rejoined.is_some() {
            b.rejoined = rejoined;
        }
        match lookup {
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
        }
    }

    /// Logs each leader whose value went missing this step, once per outage: which leader,
    /// why, and the newest sample's time; and each rejoin after an extrapolation that removed
    /// a step of more than [`REJOIN_LOGGED`].
    fn log_missing(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        for b in &mut self.buffers {
            let Some(r) = b.rejoined.take().filter(|r| r.dp.abs() > REJOIN_LOGGED) else {
                continue;
            };
            writeln!(
                log,
                "t={} leading value of {} rejoined after {} ms of extrapolation: a step of {:.6} \
                 ({:.6}/s) removed over {} ms",
                Secs(t),
                cell.leader_name(b.leader),
                r.extrapolated_ns as f64 * 1e-6,
                r.dp,
                r.dv,
                r.duration_ns as f64 * 1e-6
            )?;
        }
        for b in self.buffers.iter_mut().filter(|b| !b.logged) {
            let Some(m) = b.missing else {
                continue;
            };
            b.logged = true;
            write!(
                log,
                "t={} leading value of {} missing at t - D = {}: ",
                Secs(t),
                cell.leader_name(b.leader),
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
    /// cycle, then the output stage (the objects' edges to their digital outputs), then
    /// register corrections. Job events, alarms, output edges and measured values are written
    /// to `log`.
    pub fn step(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        self.step_encoders(t, log)?;
        self.record_samples(t, true);
        if self.inputs.any() {
            self.input_sample(t);
        }
        if self.values.any() {
            self.value_sample(t, log)?;
        }
        if self.drives.any() {
            self.drive_inputs(t);
        }
        self.step_axes(t);
        if self.drives.any() {
            self.drive_outputs(t);
        }
        self.record_samples(t, false);
        self.log_missing(t, log)?;
        self.axis_events(t, log)?;
        self.step_objects(t, log)?;
        self.outputs.step(t, &mut self.objects.out.output_edges);
        self.register_corrections(t, log)
    }

    /// The process image's digital inputs at the boundary `t`: the devices due are sampled
    /// and the axes on the simulated drive take their bound switches (the order in
    /// [`crate::inputs`]).
    fn input_sample(&mut self, t: i64) {
        self.inputs.sample(t);
        for k in 0..self.inputs.axes.len() {
            let (a, bound) = self.inputs.axes[k];
            let switches = self.inputs.switches(&bound);
            if let Some(axis) = self.axes.get_mut(a) {
                axis.set_switch_inputs(switches);
            }
        }
    }

    /// The process image's analog and counter inputs at the boundary `t`: the terminals due
    /// are sampled (with the digital inputs, before the axes step) and each change is logged
    /// (`t=<t> <signal> input = <value>`, the raw word in brackets). No object takes them
    /// ([`crate::values`]).
    fn value_sample(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        self.values.sample(t);
        for e in self.values.frame() {
            let name = (self.cell.signals.get(e.signal)).map_or("?", |s| s.name.as_str());
            match e.value {
                SignalValue::Float(v) => {
                    writeln!(log, "t={} {name} input = {v} [{}]", Secs(t), e.raw)?;
                }
                SignalValue::Integer(v) => writeln!(log, "t={} {name} input = {v}", Secs(t))?,
            }
        }
        let cell = self.cell;
        let mut result = Ok(());
        self.values.take_output_changes(|e| {
            let name = (cell.signals.get(e.signal)).map_or("?", |s| s.name.as_str());
            if result.is_ok() {
                result = writeln!(
                    log,
                    "t={} {name} output = {} [{}]",
                    Secs(e.sampled_ns),
                    e.value.as_f64(),
                    e.raw
                );
            }
        });
        result
    }

    /// Once the cycle motions are known: the input signals' sensors add their edges to the
    /// frame of `t`, each measuring input fed by a signal takes that signal's edges, and every
    /// edge of the frame is logged with its time.
    fn input_sense(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        self.inputs.sense(t, &self.motions);
        for k in 0..self.inputs.measuring.len() {
            let (m, signal) = self.inputs.measuring[k];
            for e in self.inputs.edges_of(signal) {
                self.objects.push_edge(m, e);
            }
        }
        for e in self.inputs.frame() {
            let name = self
                .cell
                .signals
                .get(e.signal)
                .map_or("?", |s| s.name.as_str());
            let level = if e.rising { "ON" } else { "OFF" };
            writeln!(log, "t={} {name} input {level}", Secs(e.time_ns))?;
        }
        Ok(())
    }

    /// The process image's drives at the boundary `t`: the devices run to `t` and are
    /// sampled, latch the last step's commands, and each axis on a drive reads its sample
    /// (the order in [`crate::drives`]).
    fn drive_inputs(&mut self, t: i64) {
        self.drives.analog.read(t, &mut self.axes);
        self.drives.exchange(t);
        for k in 0..self.drives.links.len() {
            let axis = self.drives.links[k].axis;
            if let (Some(inputs), Some(a)) = (self.drives.inputs(k, t), self.axes.get_mut(axis)) {
                a.set_drive_inputs(&inputs);
            }
            let Some(m) = self.drives.links[k].probe_input else {
                continue;
            };
            // A touch probe value: the measuring input's edge, at the position the drive
            // latched, in the axis's coordinate.
            let offset = self.axes.get(axis).map_or(0.0, Axis::position_offset);
            for latch in self.drives.probe_latches(k, t).into_iter().flatten() {
                let edge = InputEdge {
                    time_ns: t,
                    rising: latch.rising,
                    latched: Some(latch.position + offset),
                };
                self.objects.push_edge(m, edge);
            }
        }
    }

    /// The outputs of the axes on drives become the drives' commands, with touch probe 1
    /// armed while its measuring input has a job.
    fn drive_outputs(&mut self, t: i64) {
        self.drives.analog.write(t, &self.axes);
        for k in 0..self.drives.links.len() {
            let link = &mut self.drives.links[k];
            let axis = link.axis;
            if let Some(m) = link.probe_input {
                link.arm_probe(self.objects.measuring(m));
            }
            // In place where the axis stored them: no copy of the struct (a copy read them
            // back wider than they were stored, a store-forwarding stall per axis and cycle).
            match self.axes.get(axis).map(|a| (a.connected_outputs(), a)) {
                Some((Some(out), _)) => self.drives.command(k, t, out),
                Some((None, a)) => self.drives.command(k, t, &a.drive_outputs()),
                None => {}
            }
        }
    }

    /// Injects a fault with error code `code` (CiA 402 0x603F) into simulated drive `device`
    /// (index in [`Cell::devices`]), or removes the cause again with `code == 0`. Devices of
    /// other nodes are ignored.
    pub fn inject_drive_fault(
        &mut self,
        device: usize,
        code: u16,
    ) -> Result<(), tandem_motion::plant::servo::SimServoError> {
        self.drives.inject_fault(device, code)
    }

    /// The state of analog drive `device` (index in [`Cell::devices`]) and of its axis's link,
    /// if this executive runs it.
    pub fn analog_drive(&self, device: usize) -> Option<crate::drives::analog::AnalogDriveStatus> {
        self.drives.analog.status(device)
    }

    /// Puts the TxPDO of external drive `device` (index in [`Cell::devices`]: a CiA 402 drive
    /// on the node's EtherCAT segment) exchanged by the edge at the boundary of the next step;
    /// `false` when this executive runs no such drive.
    pub fn set_drive_feedback(
        &mut self,
        device: usize,
        feedback: &tandem_motion::plant::cia402::DriveFeedback,
    ) -> bool {
        self.drives.set_external_feedback(device, feedback)
    }

    /// The levels of input device `device` (index in [`Cell::devices`]: the inputs of a digital
    /// terminal on the node's EtherCAT segment) an edge read at the boundary `t`, bit `c - 1`
    /// for channel `c`: sampled by the step at `t` as a `sim_digital_input` is. `false` when
    /// this executive runs no such device.
    pub fn set_input_levels(&mut self, device: usize, t: i64, levels: u32) -> bool {
        self.inputs.set_levels(device, t, levels)
    }

    /// Channel `channel` (1-based) of analog terminal `device` reads `value` (V) from `t`:
    /// the node's EtherCAT segment sets an `aio` terminal's inputs with it before the step at
    /// `t`, which samples them as a simulated terminal's (quantized, logged, kept for
    /// [`Executive::drain_input_values`]). `false` when this executive runs no such terminal.
    pub fn set_input_value(&mut self, device: usize, channel: u8, t: i64, value: f64) -> bool {
        self.values.set_channel(device, channel, t, value)
    }

    /// The RxPDO the last step wrote for external drive `device`, which the edge sends at the
    /// next boundary; `None` when this executive runs no such drive.
    pub fn drive_command(
        &self,
        device: usize,
    ) -> Option<&tandem_motion::plant::cia402::DriveCommand> {
        self.drives.external_command(device)
    }

    /// The RxPDO the last step wrote for drive `device` (simulated or external), if this
    /// executive runs it.
    pub fn drive_rx(&self, device: usize) -> Option<&tandem_motion::plant::cia402::DriveCommand> {
        self.drives.command_of(device)
    }

    /// Moves the mechanical stops of simulated servo `device` (index in [`Cell::devices`]) to
    /// `min` / `max`, positions of its axis's load (`None` removes one: the stop gives way);
    /// `false` when this executive runs no such servo.
    pub fn set_fixed_stops(&mut self, device: usize, min: Option<f64>, max: Option<f64>) -> bool {
        self.drives.set_fixed_stops(device, min, max)
    }

    /// The TxPDO that drive `device` gave at the last boundary, if this executive runs it.
    pub fn drive_feedback(
        &self,
        device: usize,
    ) -> Option<&tandem_motion::plant::cia402::DriveFeedback> {
        self.drives.feedback(device)
    }

    /// The state of simulated digital output device `device` (index in [`Cell::devices`]), if
    /// this executive runs it: its channels' levels, the task it holds, its look-ahead and
    /// counters.
    pub fn output_device(&self, device: usize) -> Option<&OutputDeviceStatus> {
        self.outputs.status(device)
    }

    /// The state of simulated digital input device `device` (index in [`Cell::devices`]), if
    /// this executive runs it: its channels' levels and counters.
    pub fn input_device(&self, device: usize) -> Option<&InputDeviceStatus> {
        self.inputs.status(device)
    }

    /// The level of signal `signal` (an input at its last sample, an output as last
    /// switched), if its device is in this executive.
    pub fn signal_level(&self, signal: tandem_config::SignalIndex) -> Option<bool> {
        let s = self.cell.signals.get(signal.0)?;
        match s.direction {
            tandem_config::SignalDirection::Input => self.inputs.level(signal.0),
            tandem_config::SignalDirection::Output => {
                let levels = self.outputs.status(s.device.0)?.levels;
                Some(levels & (1u32 << (s.channel.saturating_sub(1) & 31)) != 0)
            }
        }
    }

    /// The reading of `integer` or `float` signal `signal` at the last sample (an analog
    /// output holds 0 V), if its terminal is in this executive.
    pub fn signal_value(&self, signal: tandem_config::SignalIndex) -> Option<SignalValue> {
        self.values.value(signal.0)
    }

    /// The state of simulated analog or counter terminal `device` (index in
    /// [`Cell::devices`]), if this executive runs it: its channels' readings and counters.
    pub fn value_device(&self, device: usize) -> Option<&ValueDeviceStatus> {
        self.values.status(device)
    }

    /// Hands each change of an `integer` or `float` input signal since the last call to `f`
    /// (in order of the boundaries that sampled them), then forgets them.
    pub fn drain_input_values(&mut self, f: impl FnMut(&InputSignalValue)) {
        self.values.drain(f);
    }

    /// Hands each edge of an input signal since the last call to `f` (what the process image
    /// sampled, in order of the boundaries that sampled them), then forgets them.
    pub fn drain_input_edges(&mut self, f: impl FnMut(&InputSignalEdge)) {
        self.inputs.drain(f);
    }

    /// Hands each switch of an output device's channel since the last call to `f` (what the
    /// device physically did, in order of the boundaries that processed them), then forgets
    /// them.
    pub fn drain_output_switches(&mut self, f: impl FnMut(&OutputSwitch)) {
        self.outputs.drain(f);
    }

    /// External encoders first: they lead and follow nothing. An encoder on an axis reads that
    /// axis' actual position of the previous cycle (one cycle of acquisition delay).
    fn step_encoders(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        let n_axes = self.axes.len();
        for (k, enc) in self.encoders.iter_mut().enumerate() {
            let entry = &cell.encoders[k];
            if !self.owned.encoders[k] || t % cell.nodes[entry.node].cycle_ns != 0 {
                continue;
            }
            let (p, v) = match &entry.source {
                EncoderSource::Axis { axis, scale } => {
                    let s = self.axes[axis.0].status();
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
                let (jobs, dropped) = (&mut self.jobs, &mut self.notes_dropped);
                job_event(jobs, dropped, log, &entry.name, n_axes + k, ev)?;
            }
            self.encoder_status[k] = *enc.status();
        }
        Ok(())
    }

    /// The owned axes, leaders before their followers: an axis steps once every leader it
    /// needs has, with the leading values of this step. The order is planned again when an
    /// axis' leaders changed since the last step.
    fn step_axes(&mut self, t: i64) {
        if !self.plan.valid {
            self.replan();
        }
        // Which nodes' cycles fall on `t` (one division per node, not per axis).
        for (due, node) in self.due.iter_mut().zip(&self.cell.nodes) {
            *due = t % node.cycle_ns == 0;
        }
        // The plan is read in place while the axes step (taken out, put back below).
        let mut plan = std::mem::take(&mut self.plan);
        // The value of the last leader read directly (without a buffer): the followers of one
        // leader come one after another and read it again (`LeaderRead::again`).
        let mut last: Option<LeadingValue> = None;
        let mut holds = true;
        // Every axis is due when every node is (one node, or the cycles meet).
        let all_due = self.due.iter().all(|d| *d);
        for p in &plan.order {
            let i = p.axis as usize;
            let (first, n) = (p.first as usize, p.reads as usize);
            let reads = match n {
                0 => &[],
                _ => plan.reads.get(first..first + n).unwrap_or(&[]),
            };
            for read in reads {
                let lv = match read.source {
                    _ if read.again => last,
                    Some(src) if src.buffer.is_none() => {
                        last = self.leading_value(src, t);
                        last
                    }
                    Some(src) => self.leading_value(src, t),
                    None => None,
                };
                if let Some(a) = self.axes.get_mut(i) {
                    a.set_leading_value(read.id, lv);
                }
            }
            if all_due || self.due[self.node_of[i]] {
                // An axis planned without leaders has none after its step: a step ends a
                // synchronous job or lets the pending one take over, only a command starts one
                // (and the plan notes it: `StepPlan::note`).
                holds &= self.step_axis(i, t, (n != 0).then_some(&plan));
            } else if let Some(stale) = self.stale.get_mut(i) {
                // Not stepped: its status is copied when read (a command may have changed it).
                *stale = true;
            }
        }
        // Not empty only with a coupling loop, which commands cannot create (16#8019): the
        // axis then runs without its leading value and raises "leader missing".
        for &i in &plan.unreached {
            if all_due || self.due[self.node_of[i]] {
                holds &= self.step_axis(i, t, Some(&plan));
            } else if let Some(stale) = self.stale.get_mut(i) {
                *stale = true;
            }
        }
        self.copy_status = false;
        plan.valid &= holds;
        self.plan = plan;
    }

    /// Steps owned axis `i` at `t` and notes what the step changed: job events or alarms to
    /// look at, its status (copied now when [`Executive::want_status`] asked, else stale: copied
    /// when read). Whether the axis still has the leaders `plan` was made with (not looked at
    /// without a plan).
    // Inlined into both loops of `step_axes` (called out of line it costs 20 instructions per
    // axis more: the loops' state spills around the call).
    #[inline(always)]
    fn step_axis(&mut self, i: usize, t: i64, plan: Option<&StepPlan>) -> bool {
        let Some(axis) = self.axes.get_mut(i) else {
            return true;
        };
        axis.step(t);
        self.news[i] |= axis.has_events() || axis.alarm_pending();
        if self.copy_status {
            self.status[i] = axis.status_value();
        }
        self.stale[i] = !self.copy_status;
        plan.is_none_or(|plan| plan.planned_with(i, axis))
    }

    /// Plans the order of the owned axes from their current leaders: passes over the axes in
    /// index order, each taking the axes whose owned leaders are already taken.
    fn replan(&mut self) {
        let cell = self.cell;
        let n_axes = self.axes.len();
        let mut plan = std::mem::take(&mut self.plan);
        plan.order.clear();
        plan.reads.clear();
        plan.unreached.clear();
        plan.leaders.clear();
        plan.leaders.extend(self.axes.iter().map(Axis::leaders));
        let mut taken = std::mem::take(&mut plan.taken);
        taken.fill(false);
        // The last leader read directly, as the step will see it (`LeaderRead::again`).
        let mut last: Option<LeaderSource> = None;
        for _pass in 0..=n_axes {
            let mut progress = false;
            for i in 0..n_axes {
                if taken[i] || !self.owned.axes[i] {
                    continue;
                }
                let needs = plan.leaders[i];
                let ready = needs.iter().flatten().all(|l| match cell.leader(*l) {
                    Some(Leader::Axis(j)) => !self.owned.axes[j.0] || taken[j.0],
                    _ => true,
                });
                if !ready {
                    continue;
                }
                // (Within the capacity of two reads per axis: no allocation. Indices of axes
                // and reads fit in u32: a cell's axes are counted in thousands.)
                let first = plan.reads.len() as u32;
                plan.reads.extend(needs.iter().flatten().map(|&id| {
                    let source = cell.leader(id).map(|j| self.leader_source(AxisIndex(i), j));
                    let again = source.is_some_and(|s| s.buffer.is_none() && last == Some(s));
                    if source.is_some_and(|s| s.buffer.is_none()) {
                        last = source;
                    }
                    LeaderRead { id, source, again }
                }));
                // The axis steps after its reads: a value read from it is new after that.
                if last.is_some_and(|s| s.leader == Leader::Axis(AxisIndex(i))) {
                    last = None;
                }
                plan.order.push(Planned {
                    axis: i as u32,
                    first,
                    reads: plan.reads.len() as u32 - first,
                });
                taken[i] = true;
                progress = true;
            }
            if !progress {
                break;
            }
        }
        plan.unreached
            .extend((0..n_axes).filter(|&i| self.owned.axes[i] && !taken[i]));
        plan.taken = taken;
        plan.valid = true;
        self.plan = plan;
    }

    /// The job events and new alarms of the owned axes (their status was marked in
    /// [`Executive::step_axes`]).
    fn axis_events(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        let mut from = 0;
        // Without job events nor a pending alarm since the last step, nor alarms seen then,
        // there is nothing to log: only the owned axes with news are looked at, found by a
        // tight scan of the two flag arrays.
        while let Some(i) = next_news(&self.news, &self.owned.axes, from) {
            from = i + 1;
            if let Some(news) = self.news.get_mut(i) {
                *news = false;
            }
            let Some(axis) = self.axes.get_mut(i) else {
                continue;
            };
            while let Some(ev) = axis.pop_event() {
                let name = &cell.axes[i].name;
                job_event(&mut self.jobs, &mut self.notes_dropped, log, name, i, ev)?;
            }
            // Without a pending alarm, nor one seen last step, there is nothing new to log.
            // (The slots are filled from the first: all are empty when the first is.)
            if !axis.alarm_pending() && self.alarms_seen[i][0] == (0, 0) {
                continue;
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
            // Looked at again next step while alarms are seen: they may go.
            self.news[i] = now[0] != (0, 0);
        }
        Ok(())
    }

    /// Output cams, cam tracks and measuring inputs: after their axis, every cycle of its
    /// node, with the motion of that cycle.
    fn step_objects(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        // Only the axes whose motion is needed have one (the others' stay `None`); their
        // previous cycle's status is kept for it.
        for k in 0..self.motion_axes.len() {
            let i = self.motion_axes[k];
            self.snapshot(i);
            self.motions[i] = (t % self.cycles[i] == 0).then(|| {
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
        if self.inputs.any() {
            self.input_sense(t, log)?;
        }
        for k in 0..self.object_axes.len() {
            let i = AxisIndex(self.object_axes[k]);
            if t % self.cycles[i.0] != 0 {
                continue;
            }
            if self.has_objects[i.0] {
                self.objects.step(cell, i, &self.motions, log)?;
                if self.objects.homing[i.0]
                    && !matches!(self.status[i.0].motion_job, Some((_, Instruction::Home)))
                {
                    self.objects.homing[i.0] = false;
                }
            }
            if self.needs_motion[i.0] {
                self.last_cycle[i.0] = self.status[i.0];
            }
        }
        Ok(())
    }

    /// Register corrections: MC_MoveSuperimposed, effective from the next cycle.
    fn register_corrections(&mut self, t: i64, log: &mut impl Write) -> io::Result<()> {
        let cell = self.cell;
        for k in 0..self.objects.out.corrections.len() {
            let (a, distance, input) = self.objects.out.corrections[k];
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
            // The status of this step stays what it was before the correction.
            self.snapshot(a.0);
            let r = self.axes[a.0].command(&command);
            self.plan.note(a.0, &self.axes[a.0]);
            self.news[a.0] = true;
            if let Err(id) = r {
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
        self.objects.out.corrections.clear();
        Ok(())
    }

    /// Hands each job event of the last step to `f`, then forgets them.
    pub fn drain_job_notes(&mut self, mut f: impl FnMut(&JobNote)) {
        self.jobs.iter().for_each(&mut f);
        self.jobs.clear();
    }

    /// Hands each output edge and measured value of the last step to `f`, then forgets them.
    pub fn drain_io_notes(&mut self, mut f: impl FnMut(&IoNote)) {
        self.objects.out.notes.iter().for_each(&mut f);
        self.objects.out.notes.clear();
    }

    /// Records the samples of owned leaders that were stepped at `t` into their buffers
    /// (encoders before the axes step, axes after).
    fn record_samples(&mut self, t: i64, encoders: bool) {
        for k in 0..self.buffers.len() {
            let l = self.buffers[k].leader;
            if l.is_encoder() != encoders || !self.owned.leader(l) {
                continue;
            }
            let cycle = match l {
                Leader::Axis(a) => self.cycles[a.0],
                Leader::Encoder(_) => self.cell.leader_cycle_ns(l),
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

/// The first axis from `from` on that is owned and has news (job events, a pending alarm or
/// alarms seen last step), in index order.
fn next_news(news: &[bool], owned: &[bool], from: usize) -> Option<usize> {
    let (news, owned) = (news.get(from..)?, owned.get(from..)?);
    news.iter()
        .zip(owned)
        .position(|(n, o)| *n && *o)
        .map(|k| from + k)
}
